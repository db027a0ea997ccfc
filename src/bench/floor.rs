//! The comparison's sensitivity floors: the reference run again with a change
//! that no rung's setting resolves, compared with the reference like a rung.
//!
//! * **The lift**: the cloth started [`FLOOR_LIFT`] higher (against gravity),
//!   moved back down by the lift before comparing. A smooth problem answers
//!   with about nothing; a chaotic one (a sheet falling onto an obstacle and
//!   folding) amplifies the lift.
//! * **The mesh** (`--mesh-floor N`, off by default; rectangles only): the
//!   reference's settings with `cloth.resolution = N`, near its own. On
//!   a problem that converges with the mesh this is the difference between
//!   two nearly equal resolutions, a small part of the reference's own error;
//!   where the mesh decides where folds form, it is as large as the distance
//!   between any two fine meshes, and the rungs' errors against the reference
//!   are that distance, not their own error. `N` is the user's: a resolution
//!   that moves a pin's box edge, a clamp line, the sheet's centre or the
//!   line under an obstacle's edge off the grid lines they sit on changes the
//!   problem, not only the mesh (an odd count puts the centre in a cell's
//!   middle and turns the corners' diagonals; the cantilever's clamp edge is
//!   on a line only at multiples of 5 segments, the tablecloth's table edges
//!   only at multiples of 16). Measured (`docs/speed-vs-error-history.md`, "The mesh
//!   floor" and "Tenth sitting"): against uniform 96 on `drape_sphere` (2.5
//!   s), uniform 94 and 98 are 0.765 % and 0.762 % of the diagonal from it,
//!   95 and 97 0.686 % and 0.698 %, where uniform 64 is 0.602 % and the lift
//!   gives 0.038 %; on `tablecloth` (2 s) 112 is 0.200 %, uniform 64 0.606 %
//!   (98, which moves the table's edges into cells, 0.548 %). On the
//!   cantilever 122 against 120 (the clamp edge off its line) gave 0.326 %,
//!   thirteen times uniform 40's error.
//!
//! * **The pattern** (`--pattern-floor`, off by default; rectangles with
//!   alternating diagonals): the reference's settings with every grid
//!   square's diagonal turned (`cloth.diagonals = "alternating_flipped"`,
//!   the checkerboard's other parity), at the reference's own resolution:
//!   an equally isotropic triangulation of the same grid. Where a sheet
//!   buckles, the triangulation may seed where its folds form; this floor
//!   says how much, with the material unchanged. Measured
//!   (`docs/speed-vs-error-history.md`, thirteenth sitting): on `drape_sphere`'s
//!   contact (to 0.533 s) uniform 192 flipped is 0.025 % of the diagonal
//!   from uniform 192, as far as uniform 176 (the mesh floor), and uniform
//!   64 and 128 flipped 0.138 % and 0.038 % (unflipped 0.139 % and 0.040
//!   %): there the triangulation seeds nothing. Tried first and dropped as
//!   the floor: regular diagonals (every square split the same way). They
//!   are another material, not another seed: uniform 192 regular is 0.397 %
//!   from the reference there, ten times uniform 128's error, and on
//!   `hanging_sheet_rest` at rest uniform 128 regular is 0.974 % away
//!   (0.862 % of it a shift of the whole sheet) against 0.094 % for uniform
//!   128, so a floor made of them would call every comparison undecided for
//!   a reason no adaptive mesh with alternating children shares in full.
//!
//! Errors of runs closer than the larger floor are not told apart by the
//! comparison; the target table marks a check as decided only where the
//! adaptive run's error and 1.1 times the uniform run's are more than 2.1
//! times the larger floor apart (`report::floor_decides`).

use super::reference::Reference;
use super::sampling;
use super::{Compare, Scene};
use crate::math::{Scalar, Vector};
use crate::scene::{ClothShape, DiagonalPattern};

/// How far the lift floor's run starts from the reference's, m: the cloth
/// lifted 1 micrometre against gravity, a change no mesh or step setting
/// resolves.
pub const FLOOR_LIFT: Scalar = 1e-6;

/// The label of the lift floor's rows in `SCENE-frames.csv`.
pub const FLOOR_LABEL: &str = "reference lifted 1 um";

/// What a floor's run changes from the reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FloorChange {
    /// The cloth started this much higher, m (taken out before comparing).
    Lift(Scalar),
    /// The reference's settings at this many segments (`--mesh-floor`).
    Resolution(u32),
    /// The reference's settings with these diagonals (`--pattern-floor`).
    Pattern(DiagonalPattern),
}

impl FloorChange {
    /// The label of the floor's rows in `SCENE-frames.csv`.
    pub fn label(&self) -> String {
        match self {
            FloorChange::Lift(_) => FLOOR_LABEL.to_owned(),
            FloorChange::Resolution(n) => mesh_label(*n),
            FloorChange::Pattern(p) => pattern_label(*p),
        }
    }
}

/// The label of the pattern floor's rows in `SCENE-frames.csv`: `reference
/// with alternating_flipped diagonals` (or alternating).
pub fn pattern_label(pattern: DiagonalPattern) -> String {
    format!("reference with {} diagonals", pattern_name(pattern))
}

/// The scene-file name of a diagonal pattern.
pub(super) fn pattern_name(pattern: DiagonalPattern) -> &'static str {
    match pattern {
        DiagonalPattern::Regular => "regular",
        DiagonalPattern::Alternating => "alternating",
        DiagonalPattern::AlternatingFlipped => "alternating_flipped",
    }
}

/// The label of the mesh floor's rows in `SCENE-frames.csv`: `reference at N
/// segments`.
pub fn mesh_label(resolution: u32) -> String {
    format!("reference at {resolution} segments")
}

/// True for a label [`FloorChange::label`] gives (a floor's rows, not a rung's).
pub fn is_floor_label(label: &str) -> bool {
    label == FLOOR_LABEL
        || [
            DiagonalPattern::Regular,
            DiagonalPattern::Alternating,
            DiagonalPattern::AlternatingFlipped,
        ]
        .iter()
        .any(|&p| label == pattern_label(p))
        || label
            .strip_prefix("reference at ")
            .and_then(|s| s.strip_suffix(" segments"))
            .is_some_and(|n| n.parse::<u32>().is_ok())
}

/// A sensitivity floor: the reference run again with one change, compared
/// with the reference like a rung (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Floor {
    /// What the run changes.
    pub change: FloorChange,
    /// The run's first frame against the reference's, as it started (a lift
    /// not taken out), relative to the diagonal: the lift itself, or zero for
    /// the mesh (a flat start is sampled exactly on any mesh).
    pub start: Scalar,
    /// `(time, error)` at every recorded frame, relative to the diagonal (a
    /// lift taken out).
    pub errors: Vec<(Scalar, Scalar)>,
    /// The error compared like the rungs': the mean over the frames, or the
    /// last frame's at rest.
    pub error: Scalar,
    /// The shadow's relative difference from the reference's
    /// ([`super::shadow`]), compared like `error` (`NaN` where there is none).
    pub shadow_error: Scalar,
    /// Each sample point's error ([`sampling::sample_errors`], compared like
    /// `error`).
    pub sample_errors: Vec<Scalar>,
    /// True when the run came from the cache.
    pub cache_hit: bool,
}

/// The lift for `scene`: [`FLOOR_LIFT`] against gravity, or along +z without
/// gravity.
pub(super) fn lift(scene: &Scene) -> Vector {
    let g = Vector::from(scene.simulation.gravity);
    (-g).try_normalize().unwrap_or(Vector::Z) * FLOOR_LIFT
}

/// The `cloth.position` override that starts `scene`'s cloth `lift` away.
pub(super) fn lifted_position(scene: &Scene, lift: Vector) -> String {
    let p = Vector::from(scene.cloth.position) + lift;
    format!("cloth.position=[{:e}, {:e}, {:e}]", p.x, p.y, p.z)
}

/// The `cloth.resolution` override of the mesh floor's run at `resolution`
/// segments for the reference `scene`; `Err` says why it does not apply.
pub(super) fn mesh_override(
    scene: &Scene,
    resolution: u32,
    time_ladder: bool,
) -> Result<String, String> {
    if time_ladder {
        return Err(
            "the time-step ladder keeps one mesh; the mesh floor is for the spatial ladder".into(),
        );
    }
    match scene.cloth.shape {
        ClothShape::Rectangle => {}
        ClothShape::Obj => return Err("an OBJ cloth has no resolution to change".into()),
        ClothShape::Disk => {
            return Err("a disk's outline, and so the sample points, change with its resolution; the mesh floor needs a rectangle".into());
        }
    }
    if scene.cloth.resolution == Some(resolution) {
        return Err(format!(
            "{resolution} segments is the reference's own mesh; give another resolution"
        ));
    }
    Ok(format!("cloth.resolution={resolution}"))
}

/// The `cloth.diagonals` override of the pattern floor's run for the
/// reference `scene` (its checkerboard with every diagonal turned), with
/// that pattern; `Err` says why it does not apply.
pub(super) fn pattern_override(
    scene: &Scene,
    time_ladder: bool,
) -> Result<(String, DiagonalPattern), String> {
    // The reference's pattern and the one whose every diagonal is turned.
    // Turning a regular grid's would mirror it (another problem where the
    // scene is not mirror-symmetric), so only the checkerboard is turned.
    if time_ladder {
        return Err(
            "the time-step ladder keeps one mesh; the pattern floor is for the spatial ladder"
                .into(),
        );
    }
    if scene.cloth.shape != ClothShape::Rectangle {
        return Err(
            "only a rectangle's grid squares have diagonals to turn; the pattern floor needs a rectangle".into(),
        );
    }
    let other = match scene.cloth.diagonals {
        DiagonalPattern::Regular => {
            return Err("the reference has regular diagonals; the pattern floor turns an alternating checkerboard's (give the reference cloth.diagonals = \"alternating\")".into());
        }
        DiagonalPattern::Alternating => DiagonalPattern::AlternatingFlipped,
        DiagonalPattern::AlternatingFlipped => DiagonalPattern::Alternating,
    };
    Ok((format!("cloth.diagonals={}", pattern_name(other)), other))
}

/// The floor from its run's samples (`run`) and the reference's, compared as
/// `compare` says; a lift is taken out first.
pub(super) fn floor_of(
    run: &Reference,
    reference: &Reference,
    change: FloorChange,
    lift: Vector,
    compare: Compare,
) -> Floor {
    let start = match (run.frames.first(), reference.frames.first()) {
        (Some(a), Some(b)) => {
            sampling::frame_error(a, b, reference.diagonal).unwrap_or(Scalar::NAN)
        }
        _ => Scalar::NAN,
    };
    let lowered: Vec<sampling::FrameSamples> = run
        .frames
        .iter()
        .map(|f| sampling::FrameSamples {
            positions: f
                .positions
                .iter()
                .map(|p| p.map(|q| (Vector::from_array(q) - lift).to_array()))
                .collect(),
            ..f.clone()
        })
        .collect();
    let errors = sampling::run_errors(&lowered, &reference.frames, reference.diagonal);
    let error = compare.of(errors.iter().map(|e| e.1));
    let cell = reference.diagonal / super::shadow::CELLS_PER_DIAGONAL;
    let shadows = super::shadow::shadow_errors(&lowered, &reference.frames, cell);
    let shadow_error = match shadows.len() == errors.len() && !errors.is_empty() {
        true => compare.of(shadows.iter().map(|e| e.1)),
        false => Scalar::NAN,
    };
    let at_rest = compare == Compare::Rest;
    let sample_errors =
        sampling::sample_errors(&lowered, &reference.frames, reference.diagonal, at_rest);
    Floor {
        change,
        start,
        errors,
        error,
        shadow_error,
        sample_errors,
        cache_hit: false,
    }
}

/// The larger of the floors' errors: `None` without any, or when one is NaN
/// (a floor that could not be compared is not taken as no floor).
pub fn largest<'a>(floors: impl IntoIterator<Item = &'a Floor>) -> Option<Scalar> {
    largest_error(floors.into_iter().map(|f| f.error))
}

/// [`largest`] of bare floor errors (as `--replot` reads them back).
pub fn largest_error(errors: impl IntoIterator<Item = Scalar>) -> Option<Scalar> {
    let mut largest: Option<Scalar> = None;
    for e in errors {
        if e.is_nan() {
            return None;
        }
        largest = Some(largest.map_or(e, |m| m.max(e)));
    }
    largest
}
