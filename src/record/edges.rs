//! Per-edge dihedral angles at `cloth/edges`: line segments coloured by angle, with the angle
//! as data (one value per segment).

use std::sync::Arc;

use rerun::external::arrow::array::UInt32Array;

use super::convert;
use crate::math::Vector;

/// Which edges are drawn at `cloth/edges`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum EdgeDisplay {
    /// No `cloth/edges` entity at all.
    Off,
    /// The edges a reviewer needs to follow refinement decisions: those strictly above the
    /// scene's coarsen threshold (every edge that can trigger or block a refinement or keep
    /// a region from coarsening); see [`EdgeDisplay::resolve`]. Left out: the edges at or
    /// below it (flat hinges and boundary edges), which only ever allow coarsening.
    #[default]
    Review,
    /// Every edge of the mesh, boundary edges (angle 0) included.
    All,
    /// Only the edges whose angle is strictly above this many degrees (the others are left
    /// out of the frame's data too).
    Above(f64),
}

/// The threshold [`EdgeDisplay::Review`] uses for a scene without adaptivity (or when it
/// was not resolved): the default coarsen threshold of the scene files, paper B's
/// beta_min = 1.5 deg.
pub const REVIEW_DEFAULT_DEG: f64 = 1.5;

impl EdgeDisplay {
    /// [`EdgeDisplay::Review`] as the threshold it stands for: `Above(coarsen_angle)` for an
    /// adaptive scene, `Above(`[`REVIEW_DEFAULT_DEG`]`)` without adaptivity (`None`); every
    /// other choice is returned as it is.
    pub fn resolve(self, coarsen_angle: Option<f64>) -> EdgeDisplay {
        match self {
            EdgeDisplay::Review => EdgeDisplay::Above(coarsen_angle.unwrap_or(REVIEW_DEFAULT_DEG)),
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

/// Line width of the edges on screen, UI points.
const EDGE_RADIUS_UI: f32 = 0.75;

/// Component name of the per-edge angle data (degrees, one per segment).
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
    }
}

/// The archetypes of one frame's `cloth/edges` row: the segments (`LineStrips3D`, coloured by
/// angle) and the data (`dihedral_angle_deg` per segment, `edge_vertices` as vertex pairs).
/// `None` when edges are off. Lengths and indices must have been checked by the caller.
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
    .with_colors(keep.iter().map(|&i| {
        let [r, g, b] = angle_rgb(angles[i]);
        rerun::Rgba32::from_rgb(r, g, b)
    }))
    .with_radii([rerun::Radius::new_ui_points(EDGE_RADIUS_UI)]);
    let pairs: UInt32Array = keep.iter().flat_map(|&i| edges[i]).collect();
    let data = rerun::AnyValues::default()
        .with_component::<rerun::components::Scalar>(
            ANGLE_COMPONENT,
            keep.iter().map(|&i| angles[i]),
        )
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
    fn threshold_keeps_edges_strictly_above() {
        let angles = [0.0, 5.0, 5.1, 30.0];
        assert_eq!(kept(EdgeDisplay::Above(5.0), &angles), vec![2, 3]);
        assert_eq!(kept(EdgeDisplay::All, &angles).len(), 4);
        assert!(kept(EdgeDisplay::Off, &angles).is_empty());
        assert_eq!(kept(EdgeDisplay::Review, &angles), vec![1, 2, 3]);
        assert_eq!(
            EdgeDisplay::Review.resolve(Some(5.0)),
            EdgeDisplay::Above(5.0)
        );
        assert_eq!(EdgeDisplay::All.resolve(Some(5.0)), EdgeDisplay::All);
    }
}
