//! Garments in the recording: the seams at `cloth/seams` (open seams' pairs and welded
//! seams' edges, coloured by state) and the panel colours of `--colour-by panel`.

use std::sync::Arc;

use rerun::external::arrow::array::{StringArray, UInt32Array};

use super::{SeamSegment, convert};
use crate::math::Vector;

/// What the triangles of `cloth/mesh` are coloured by (their class ids).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ColourBy {
    /// The refinement level ([`super::LEVEL_PALETTE`]): class id = level.
    #[default]
    Level,
    /// The garment panel ([`PANEL_PALETTE`]): class id = panel index; a cloth without
    /// panels is one panel named `cloth`.
    Panel,
    /// The criterion's ratio ([`super::decisions::RATIO_PALETTE`]): class id =
    /// [`super::decisions::decision_class`], labelled with the ratio band, term and state.
    Ratio,
    /// The decision state ([`super::decisions::STATE_PALETTE`]): the classes of
    /// [`ColourBy::Ratio`], coloured by state.
    State,
}

/// Colour of each panel, sRGB, repeated from the start past the eighth panel.
///
/// | panel | colour | hex |
/// |---|---|---|
/// | 0 | steel blue | `#4682B4` |
/// | 1 | rose | `#EC407A` |
/// | 2 | violet | `#7E57C2` |
/// | 3 | sand | `#D7B377` |
/// | 4 | sky blue | `#4FC3F7` |
/// | 5 | brown | `#8D6E63` |
/// | 6 | slate grey | `#78909C` |
/// | 7 | pink | `#F8BBD0` |
///
/// None is orange or green, the colours of the seams.
pub const PANEL_PALETTE: [[u8; 3]; 8] = [
    [0x46, 0x82, 0xB4],
    [0xEC, 0x40, 0x7A],
    [0x7E, 0x57, 0xC2],
    [0xD7, 0xB3, 0x77],
    [0x4F, 0xC3, 0xF7],
    [0x8D, 0x6E, 0x63],
    [0x78, 0x90, 0x9C],
    [0xF8, 0xBB, 0xD0],
];

/// Names of the panel colours, in [`PANEL_PALETTE`] order (for the legend).
pub(super) const PANEL_COLOUR_NAMES: [&str; 8] = [
    "steel blue",
    "rose",
    "violet",
    "sand",
    "sky blue",
    "brown",
    "slate grey",
    "pink",
];

/// The panel name of a cloth without panels.
pub const SINGLE_PANEL_NAME: &str = "cloth";

/// Colour of an open seam's segments (orange `#FF9800`).
pub const SEAM_OPEN_RGB: [u8; 3] = [0xFF, 0x98, 0x00];
/// Colour of a welded seam's edges (green `#00C853`).
pub const SEAM_WELDED_RGB: [u8; 3] = [0x00, 0xC8, 0x53];
/// Class id of an open seam's segments at `cloth/seams` (label `open seam`).
pub const SEAM_CLASS_OPEN: u16 = 0;
/// Class id of a welded seam's edges at `cloth/seams` (label `welded seam`).
pub const SEAM_CLASS_WELDED: u16 = 1;

/// Component name of the seam name of each `cloth/seams` segment (UTF-8, one per segment).
pub const SEAM_COMPONENT: &str = "seam";
/// Component name of the vertex pair of each `cloth/seams` segment (two `u32` per segment,
/// flattened).
pub const SEAM_VERTICES_COMPONENT: &str = "seam_vertices";

/// Line width of the seams on screen, UI points: wider than the edges (0.75) so the
/// seams stand out on the cloth.
const SEAM_RADIUS_UI: f32 = 2.0;

/// The colour of panel `p` ([`PANEL_PALETTE`], repeated).
pub fn panel_rgb(p: u16) -> [u8; 3] {
    PANEL_PALETTE[usize::from(p) % PANEL_PALETTE.len()]
}

/// The annotation context of the panels: class id `p` = the panel's name, in its colour.
pub(super) fn panel_annotations(names: &[String]) -> rerun::AnnotationContext {
    rerun::AnnotationContext::new(names.iter().enumerate().map(|(p, name)| {
        let p = u16::try_from(p).unwrap_or(u16::MAX);
        let [r, g, b] = panel_rgb(p);
        (p, name.as_str(), rerun::Rgba32::from_rgb(r, g, b))
    }))
}

/// The static parts of `cloth/seams`: its annotation context (`open seam` orange, `welded
/// seam` green) and the line width shared by every frame's segments, labels hidden.
pub(super) fn seam_static() -> (rerun::AnnotationContext, rerun::LineStrips3D) {
    let [r0, g0, b0] = SEAM_OPEN_RGB;
    let [r1, g1, b1] = SEAM_WELDED_RGB;
    let context = rerun::AnnotationContext::new([
        (
            SEAM_CLASS_OPEN,
            "open seam",
            rerun::Rgba32::from_rgb(r0, g0, b0),
        ),
        (
            SEAM_CLASS_WELDED,
            "welded seam",
            rerun::Rgba32::from_rgb(r1, g1, b1),
        ),
    ]);
    // The class labels would be drawn at every segment, dozens per seam on a
    // refined garment: the colours say open or welded, the legend says which.
    let width = rerun::LineStrips3D::update_fields()
        .with_radii([rerun::Radius::new_ui_points(SEAM_RADIUS_UI)])
        .with_show_labels(false);
    (context, width)
}

/// One frame's `cloth/seams` row: a two-point strip per segment with its class id (open or
/// welded), and as data each segment's seam name and vertex pair. All of them every frame,
/// so a seam that welds loses its open segments at the frame of the weld. Indices must have
/// been checked by the caller.
pub(super) fn seam_row(
    positions: &[Vector],
    seams: &[SeamSegment],
) -> (rerun::LineStrips3D, rerun::AnyValues) {
    let strips = rerun::LineStrips3D::new(
        seams
            .iter()
            .map(|s| s.vertices.map(|v| convert::f32x3(positions[v as usize]))),
    )
    .with_class_ids(seams.iter().map(|s| {
        rerun::components::ClassId::from(if s.welded {
            SEAM_CLASS_WELDED
        } else {
            SEAM_CLASS_OPEN
        })
    }));
    let names: StringArray = seams.iter().map(|s| Some(s.seam)).collect();
    let pairs: UInt32Array = seams.iter().flat_map(|s| s.vertices).collect();
    let data = rerun::AnyValues::default()
        .with_component_from_data(SEAM_COMPONENT, Arc::new(names))
        .with_component_from_data(SEAM_VERTICES_COMPONENT, Arc::new(pairs));
    (strips, data)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panel_colours_repeat_and_avoid_the_seam_colours() {
        assert_eq!(panel_rgb(0), PANEL_PALETTE[0]);
        assert_eq!(panel_rgb(9), PANEL_PALETTE[1]);
        assert!(
            PANEL_PALETTE
                .iter()
                .all(|c| *c != SEAM_OPEN_RGB && *c != SEAM_WELDED_RGB)
        );
    }
}
