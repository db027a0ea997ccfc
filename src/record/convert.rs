//! Engine -> Rerun conversions, all in one place.
//!
//! The engine computes in `f64` with glam 0.33 ([`crate::math::Vector`]); rerun 0.36 stores
//! `f32` and uses glam 0.30. Vectors cross the boundary as plain arrays (`to_array()`), cast
//! to `f32` here and nowhere else, so no glam type of either version leaks across.

use rerun::components::{Position3D, Vector3D};
use rerun::datatypes::Rgba32;

use crate::math::Vector;

/// Colour per refinement level, see [`super::LEVEL_PALETTE`] for the documented table.
///
/// Levels past the end of the palette reuse its last (hottest) colour.
#[inline]
pub(crate) fn level_rgb(level: u8) -> [u8; 3] {
    let last = super::LEVEL_PALETTE.len() - 1;
    super::LEVEL_PALETTE[usize::from(level).min(last)]
}

/// An engine vector as three `f32`s (metres stay metres).
#[inline]
pub(crate) fn f32x3(v: Vector) -> [f32; 3] {
    v.to_array().map(|c| c as f32)
}

/// An engine point as a rerun position.
#[inline]
pub(crate) fn position(v: Vector) -> Position3D {
    Position3D::from(f32x3(v))
}

/// An engine direction (e.g. a unit normal) as a rerun vector.
#[inline]
pub(crate) fn vector(v: Vector) -> Vector3D {
    Vector3D::from(f32x3(v))
}

/// The annotation context entries: `(class id, label, colour)` for every level up to
/// [`super::ANNOTATED_LEVELS`] (exclusive).
pub(crate) fn level_annotations() -> rerun::AnnotationContext {
    let labels: Vec<String> = (0..super::ANNOTATED_LEVELS)
        .map(|l| format!("level {l}"))
        .collect();
    rerun::AnnotationContext::new(labels.iter().enumerate().map(|(l, label)| {
        let level = u8::try_from(l).unwrap_or(u8::MAX);
        let [r, g, b] = level_rgb(level);
        (u16::from(level), label.as_str(), Rgba32::from_rgb(r, g, b))
    }))
}
