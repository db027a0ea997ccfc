//! The refinement decisions at `cloth/mesh`: per triangle, the criterion's value against its
//! threshold (`decision_ratio`, refining above 1), the term that set it (`decision_term`) and
//! what holds the triangle (`decision_state`), logged every frame; and the classes, colours
//! and labels of `--colour-by ratio` and `--colour-by state`, under which hovering a triangle
//! shows all three.

use std::fmt::Write;
use std::sync::Arc;

use rerun::external::arrow::array::{Float32Array, UInt8Array};

use crate::adapt::{Term, TriangleState};

/// Component name of each triangle's criterion ratio on `cloth/mesh` (`f32`, one per
/// triangle; the triangle refines above 1).
pub const RATIO_COMPONENT: &str = "decision_ratio";
/// Component name of each triangle's criterion term on `cloth/mesh` (`u8`, one per triangle:
/// the index in [`TERM_NAMES`]).
pub const TERM_COMPONENT: &str = "decision_term";
/// Component name of each triangle's state on `cloth/mesh` (`u8`, one per triangle: the
/// index in [`STATE_NAMES`]).
pub const STATE_COMPONENT: &str = "decision_state";

/// Whether a recording holds the refinement decisions (`drape run --no-decisions` leaves
/// them out).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DecisionData {
    /// `decision_ratio`, `decision_term` and `decision_state` on `cloth/mesh` every frame of
    /// an adaptive run.
    #[default]
    Recorded,
    /// None of them.
    Off,
}

/// The names of the terms, by code.
pub const TERM_NAMES: [&str; 4] = [
    Term::ALL[0].name(),
    Term::ALL[1].name(),
    Term::ALL[2].name(),
    Term::ALL[3].name(),
];
/// The names of the states, by code.
pub const STATE_NAMES: [&str; 5] = [
    TriangleState::ALL[0].name(),
    TriangleState::ALL[1].name(),
    TriangleState::ALL[2].name(),
    TriangleState::ALL[3].name(),
    TriangleState::ALL[4].name(),
];

/// The upper ends of the ratio bands of `--colour-by ratio` (a ratio above the last is in the
/// last band): band `k` holds the ratios above `RATIO_BANDS[k - 1]` up to `RATIO_BANDS[k]`.
pub const RATIO_BANDS: [f32; 6] = [0.25, 0.5, 0.75, 1.0, 1.5, 2.0];

/// Colour of each ratio band, sRGB: cool below 1, warm above.
///
/// | band | ratio | colour | hex |
/// |---|---|---|---|
/// | 0 | up to 0.25 | dark slate | `#37474F` |
/// | 1 | 0.25 to 0.5 | blue | `#1E88E5` |
/// | 2 | 0.5 to 0.75 | teal | `#26A69A` |
/// | 3 | 0.75 to 1 | light green | `#9CCC65` |
/// | 4 | 1 to 1.5 | yellow | `#FDD835` |
/// | 5 | 1.5 to 2 | orange | `#FB8C00` |
/// | 6 | above 2 | red | `#E53935` |
pub const RATIO_PALETTE: [[u8; 3]; 7] = [
    [0x37, 0x47, 0x4F],
    [0x1E, 0x88, 0xE5],
    [0x26, 0xA6, 0x9A],
    [0x9C, 0xCC, 0x65],
    [0xFD, 0xD8, 0x35],
    [0xFB, 0x8C, 0x00],
    [0xE5, 0x39, 0x35],
];

/// Colour of each state, sRGB, by code.
///
/// | state | colour | hex |
/// |---|---|---|
/// | free | blue grey | `#90A4AE` |
/// | at max_level | red | `#E53935` |
/// | at min_edge_length | orange | `#FB8C00` |
/// | kept by level rule | violet | `#7E57C2` |
/// | held by rollback | rose | `#EC407A` |
pub const STATE_PALETTE: [[u8; 3]; 5] = [
    [0x90, 0xA4, 0xAE],
    [0xE5, 0x39, 0x35],
    [0xFB, 0x8C, 0x00],
    [0x7E, 0x57, 0xC2],
    [0xEC, 0x40, 0x7A],
];

/// The band of a ratio in [`RATIO_BANDS`] (a NaN ratio is in band 0).
pub fn ratio_band(ratio: f32) -> usize {
    RATIO_BANDS.iter().filter(|&&b| ratio > b).count()
}

/// The class id of a triangle under `--colour-by ratio` and `--colour-by state`: its ratio
/// band, state and term together, so that the label names all three.
pub fn decision_class(ratio: f32, term: u8, state: u8) -> u16 {
    let per_band = (STATE_NAMES.len() * TERM_NAMES.len()) as u16;
    ratio_band(ratio) as u16 * per_band
        + u16::from(state) * TERM_NAMES.len() as u16
        + u16::from(term)
}

/// The ratio band, state and term of a [`decision_class`].
fn class_parts(class: u16) -> (usize, usize, usize) {
    let c = usize::from(class);
    let per_band = STATE_NAMES.len() * TERM_NAMES.len();
    (
        c / per_band,
        (c % per_band) / TERM_NAMES.len(),
        c % TERM_NAMES.len(),
    )
}

/// The colour of a [`decision_class`]: its band's with `by_state` false, its state's with it
/// true.
pub(super) fn class_rgb(class: u16, by_state: bool) -> [u8; 3] {
    let (band, state, _) = class_parts(class);
    match by_state {
        false => RATIO_PALETTE[band.min(RATIO_PALETTE.len() - 1)],
        true => STATE_PALETTE[state.min(STATE_PALETTE.len() - 1)],
    }
}

/// The label of a band: `ratio 0.75-1`, `ratio > 2`.
fn band_label(band: usize) -> String {
    match band {
        0 => format!("ratio <= {}", RATIO_BANDS[0]),
        b if b >= RATIO_BANDS.len() => format!("ratio > {}", RATIO_BANDS[RATIO_BANDS.len() - 1]),
        b => format!("ratio {}-{}", RATIO_BANDS[b - 1], RATIO_BANDS[b]),
    }
}

/// The annotation context of every [`decision_class`]: label `ratio 0.75-1, curvature, at
/// max_level`, coloured by band (or by state with `by_state`).
pub(super) fn decision_annotations(by_state: bool) -> rerun::AnnotationContext {
    let count = (RATIO_BANDS.len() + 1) * STATE_NAMES.len() * TERM_NAMES.len();
    let entries: Vec<(u16, String)> = (0..count as u16)
        .map(|c| {
            let (band, state, term) = class_parts(c);
            let label = format!(
                "{}, {}, {}",
                band_label(band),
                TERM_NAMES[term],
                STATE_NAMES[state]
            );
            (c, label)
        })
        .collect();
    rerun::AnnotationContext::new(entries.iter().map(|(c, label)| {
        let [r, g, b] = class_rgb(*c, by_state);
        (*c, label.as_str(), rerun::Rgba32::from_rgb(r, g, b))
    }))
}

/// The legend's part for the cloth under `--colour-by ratio` (or `state`, `by_state`).
pub(super) fn legend(by_state: bool) -> String {
    let mut s = String::new();
    if by_state {
        s.push_str("**cloth: decision state**\n\n");
        for (name, c) in STATE_NAMES.iter().zip(STATE_PALETTE) {
            let _ = writeln!(s, "- {name}: `{}`", super::layout::hex(c));
        }
    } else {
        s.push_str("**cloth: criterion ratio** (refines above 1)\n\n");
        for (band, c) in RATIO_PALETTE.iter().enumerate() {
            let _ = writeln!(s, "- {}: `{}`", band_label(band), super::layout::hex(*c));
        }
    }
    s
}

/// The decision components of one frame's `cloth/mesh` row.
pub(super) fn decision_row(ratio: &[f32], term: &[u8], state: &[u8]) -> rerun::AnyValues {
    rerun::AnyValues::default()
        .with_component_from_data(
            RATIO_COMPONENT,
            Arc::new(Float32Array::from(ratio.to_vec())),
        )
        .with_component_from_data(TERM_COMPONENT, Arc::new(UInt8Array::from(term.to_vec())))
        .with_component_from_data(STATE_COMPONENT, Arc::new(UInt8Array::from(state.to_vec())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_decision_class_names_its_band_term_and_state() {
        let c = decision_class(1.2, Term::Strain.code(), TriangleState::AtMaxLevel.code());
        assert_eq!(class_parts(c), (4, 1, 2));
        assert_eq!(class_rgb(c, false), RATIO_PALETTE[4]);
        assert_eq!(class_rgb(c, true), STATE_PALETTE[1]);
        assert_eq!(ratio_band(1.0), 3, "a ratio of 1 does not refine");
        assert_eq!(ratio_band(7.0), 6);
        assert_eq!(band_label(3), "ratio 0.75-1");
    }
}
