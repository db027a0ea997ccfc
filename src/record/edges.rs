//! Per-edge dihedral angles at `cloth/edges`: line segments coloured by angle, with the angle
//! as data (one value per segment).

use std::sync::Arc;

use rerun::external::arrow::array::{Float32Array, UInt32Array};

use super::convert;
use crate::math::Vector;

/// Which edges are drawn at `cloth/edges`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum EdgeDisplay {
    /// No `cloth/edges` entity at all.
    Off,
    /// The edges a reviewer needs to follow refinement decisions: those whose angle is near
    /// the scene's refine threshold, within a factor [`REVIEW_BAND`] of it either way (an edge
    /// just above it is split, unless its triangles are at the finest level; one just below it
    /// is not); see [`EdgeDisplay::resolve`]. Left out: the flatter edges (which only allow or
    /// block coarsening) and the sharper ones (fold crests, at the finest level already).
    #[default]
    Review,
    /// Every edge of the mesh, boundary edges (angle 0) included.
    All,
    /// Only the edges whose angle is strictly above this many degrees (the others are left
    /// out of the frame's data too).
    Above(f64),
    /// Only the edges whose angle lies in `[low, high]` degrees (what [`EdgeDisplay::Review`]
    /// resolves to).
    Between(f64, f64),
}

/// The refine threshold [`EdgeDisplay::Review`] uses for a scene without adaptivity (or
/// when it was not resolved): the default refine threshold of the scene files, paper B's
/// beta_max = 15 deg.
pub const REVIEW_DEFAULT_DEG: f64 = 15.0;

/// How near the refine threshold an edge must be for [`EdgeDisplay::Review`]: its angle
/// within `refine / REVIEW_BAND` to `refine * REVIEW_BAND` (12.5 to 18 deg for 15 deg).
pub const REVIEW_BAND: f64 = 1.2;

impl EdgeDisplay {
    /// [`EdgeDisplay::Review`] as the band it stands for: `Between(refine / REVIEW_BAND,
    /// refine * REVIEW_BAND)` with the scene's `refine_angle` (`None`: a scene without
    /// adaptivity, [`REVIEW_DEFAULT_DEG`]); every other choice is returned as it is.
    pub fn resolve(self, refine_angle: Option<f64>) -> EdgeDisplay {
        match self {
            EdgeDisplay::Review => {
                let r = refine_angle.unwrap_or(REVIEW_DEFAULT_DEG);
                EdgeDisplay::Between(r / REVIEW_BAND, r * REVIEW_BAND)
            }
            other => other,
        }
    }
}

/// Angle (degrees) at which the colour scale saturates; larger angles get the last colour.
pub const ANGLE_SCALE_DEG: f64 = 45.0;

/// Colour stops of the angle scale, sRGB: `(angle in degrees, colour)`, linear in between.
///
/// | angle | colour |
/// |---|---|
/// | 0 deg (flat) | dark slate `#37474F` |
/// | 5 deg | violet `#7E57C2` |
/// | 15 deg | orange `#FB8C00` |
/// | 45 deg and more | yellow `#FFEB3B` |
pub const ANGLE_STOPS: [(f64, [u8; 3]); 4] = [
    (0.0, [0x37, 0x47, 0x4F]),
    (5.0, [0x7E, 0x57, 0xC2]),
    (15.0, [0xFB, 0x8C, 0x00]),
    (ANGLE_SCALE_DEG, [0xFF, 0xEB, 0x3B]),
];

/// Angle classes of the edges: class id `c` stands for the angles from `c` to `c + 1`
/// degrees, drawn in the colour of the scale at `c + 0.5` deg; the last class, `45`, for
/// [`ANGLE_SCALE_DEG`] and more. The annotation context at `cloth/edges` names them.
pub const ANGLE_CLASSES: u16 = ANGLE_SCALE_DEG as u16 + 1;

/// Line width of the edges on screen, UI points.
const EDGE_RADIUS_UI: f32 = 0.75;

/// Component name of the per-edge angle data (degrees as `f32`, one per segment).
pub const ANGLE_COMPONENT: &str = "dihedral_angle_deg";
/// Component name of the per-edge vertex pair (two `u32` per segment, flattened).
pub const EDGE_VERTICES_COMPONENT: &str = "edge_vertices";

/// The colour of an angle on the scale of [`ANGLE_STOPS`].
pub fn angle_rgb(angle_deg: f64) -> [u8; 3] {
    let a = if angle_deg.is_finite() {
        angle_deg.max(0.0)
    } else {
        ANGLE_SCALE_DEG
    };
    for pair in ANGLE_STOPS.windows(2) {
        let ((a0, c0), (a1, c1)) = (pair[0], pair[1]);
        if a <= a1 {
            let s = ((a - a0) / (a1 - a0)).clamp(0.0, 1.0);
            let mix = |i: usize| {
                (f64::from(c0[i]) + s * (f64::from(c1[i]) - f64::from(c0[i]))).round() as u8
            };
            return [mix(0), mix(1), mix(2)];
        }
    }
    ANGLE_STOPS[ANGLE_STOPS.len() - 1].1
}

/// The edges kept by `display`, as indices into `angles`.
fn kept(display: EdgeDisplay, angles: &[f64]) -> Vec<usize> {
    match display {
        EdgeDisplay::Off => Vec::new(),
        EdgeDisplay::All => (0..angles.len()).collect(),
        EdgeDisplay::Review => kept(EdgeDisplay::Review.resolve(None), angles),
        EdgeDisplay::Above(t) => (0..angles.len()).filter(|&i| angles[i] > t).collect(),
        EdgeDisplay::Between(low, high) => (0..angles.len())
            .filter(|&i| (low..=high).contains(&angles[i]))
            .collect(),
    }
}

/// The angle class of an angle (see [`ANGLE_CLASSES`]): whole degrees, saturating.
pub fn angle_class(angle_deg: f64) -> u16 {
    if angle_deg.is_finite() {
        // In range by the clamp, so the cast neither wraps nor saturates.
        angle_deg.clamp(0.0, f64::from(ANGLE_CLASSES - 1)).floor() as u16
    } else {
        ANGLE_CLASSES - 1
    }
}

/// The static annotation context of `cloth/edges`: each angle class with its label
/// (`12-13 deg`, the last `45+ deg`) and colour.
pub(super) fn angle_annotations() -> rerun::AnnotationContext {
    let last = ANGLE_CLASSES - 1;
    let labels: Vec<(u16, String)> = (0..ANGLE_CLASSES)
        .map(|c| {
            let label = if c == last {
                format!("{c}+ deg")
            } else {
                format!("{c}-{} deg", c + 1)
            };
            (c, label)
        })
        .collect();
    rerun::AnnotationContext::new(labels.iter().map(|(c, label)| {
        let centre = if *c == last {
            ANGLE_SCALE_DEG
        } else {
            f64::from(*c) + 0.5
        };
        let [r, g, b] = angle_rgb(centre);
        (*c, label.as_str(), rerun::Rgba32::from_rgb(r, g, b))
    }))
}

/// The archetypes of one frame's `cloth/edges` row: the segments (`LineStrips3D`, coloured by
/// angle class through the annotation context) and the data (`dihedral_angle_deg` per segment
/// as `f32`, `edge_vertices` as vertex pairs). `None` when edges are off. Lengths and indices
/// must have been checked by the caller.
pub(super) fn edge_row(
    display: EdgeDisplay,
    positions: &[Vector],
    edges: &[[u32; 2]],
    angles: &[f64],
) -> Option<(rerun::LineStrips3D, rerun::AnyValues)> {
    if display == EdgeDisplay::Off {
        return None;
    }
    let keep = kept(display, angles);
    let strips = rerun::LineStrips3D::new(keep.iter().map(|&i| {
        let [a, b] = edges[i];
        [
            convert::f32x3(positions[a as usize]),
            convert::f32x3(positions[b as usize]),
        ]
    }))
    .with_class_ids(
        keep.iter()
            .map(|&i| rerun::components::ClassId::from(angle_class(angles[i]))),
    )
    .with_radii([rerun::Radius::new_ui_points(EDGE_RADIUS_UI)]);
    let pairs: UInt32Array = keep.iter().flat_map(|&i| edges[i]).collect();
    // f32 like the positions: 1e-7 relative is far below any threshold's meaning.
    let degrees: Float32Array = keep.iter().map(|&i| angles[i] as f32).collect();
    let data = rerun::AnyValues::default()
        .with_component_from_data(ANGLE_COMPONENT, Arc::new(degrees))
        .with_component_from_data(EDGE_VERTICES_COMPONENT, Arc::new(pairs));
    Some((strips, data))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_hits_its_stops_and_saturates() {
        for (a, c) in ANGLE_STOPS {
            assert_eq!(angle_rgb(a), c);
        }
        assert_eq!(angle_rgb(90.0), ANGLE_STOPS[3].1);
        assert_eq!(angle_rgb(-1.0), ANGLE_STOPS[0].1);
        assert_eq!(angle_rgb(f64::NAN), ANGLE_STOPS[3].1);
        let mid = angle_rgb(10.0);
        assert_ne!(mid, ANGLE_STOPS[1].1);
        assert_ne!(mid, ANGLE_STOPS[2].1);
    }

    #[test]
    fn angle_classes_are_whole_degrees_saturating() {
        assert_eq!(angle_class(0.0), 0);
        assert_eq!(angle_class(12.99), 12);
        assert_eq!(angle_class(13.0), 13);
        assert_eq!(angle_class(44.9), 44);
        assert_eq!(angle_class(90.0), ANGLE_CLASSES - 1);
        assert_eq!(angle_class(-1.0), 0);
        assert_eq!(angle_class(f64::NAN), ANGLE_CLASSES - 1);
    }

    #[test]
    fn threshold_keeps_edges_strictly_above() {
        let angles = [0.0, 5.0, 5.1, 30.0];
        assert_eq!(kept(EdgeDisplay::Above(5.0), &angles), vec![2, 3]);
        assert_eq!(kept(EdgeDisplay::All, &angles).len(), 4);
        assert!(kept(EdgeDisplay::Off, &angles).is_empty());
        let EdgeDisplay::Between(low, high) = EdgeDisplay::Review.resolve(Some(6.0)) else {
            panic!("review resolves to a band");
        };
        assert!((low - 5.0).abs() < 1e-12 && (high - 7.2).abs() < 1e-12);
        assert_eq!(kept(EdgeDisplay::Between(3.2, 5.0), &angles), vec![1]);
        assert_eq!(
            kept(EdgeDisplay::Review, &[12.4, 12.6, 15.0, 17.9, 18.1]),
            vec![1, 2, 3]
        );
        assert_eq!(EdgeDisplay::All.resolve(Some(5.0)), EdgeDisplay::All);
    }
}
