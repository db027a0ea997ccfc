//! Where the recording's 3D views look from: the scene's `[camera]` table, resolved into the
//! eye of the default blueprint once the first frame shows where the cloth is.

use serde::Deserialize;

use crate::math::Vector;

use super::blueprint::Eye;

/// How far a side eye stands from the centre of the cloth's bounding sphere, in radii: a
/// sphere fills the view's height at about 2.2 radii with rerun's default field of view, so
/// 3 leaves a margin for the cloth to swing into.
const SIDE_DISTANCE_RADII: f64 = 3.0;
/// The smallest distance of a side eye from the cloth's centre, m, so that a cloth that
/// starts as a point or a line is still seen from a sensible distance.
const SIDE_DISTANCE_MIN: f64 = 0.5;
/// How much a side eye looks down: the height of its offset per unit of horizontal offset.
const SIDE_ELEVATION: f64 = 0.35;

/// Where the 3D views look from.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Camera {
    /// Rerun's default eye, which follows the cloth as it moves (the default).
    #[default]
    Follow,
    /// From one side of the cloth, slightly above it, at a distance that frames its first
    /// recorded frame; the eye stays where it is while the cloth moves.
    Side(CameraSide),
    /// From a point in the world, looking at another (metres).
    At {
        /// The eye's position.
        eye: Vector,
        /// The point the eye looks at and orbits around.
        look_at: Vector,
    },
}

/// A named side to look from, in the world frame (z up; a body in drape's scenes faces -y).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CameraSide {
    /// From -y: the side a body in the shipped scenes faces.
    Front,
    /// From +y: behind such a body (capes, the backs of garments).
    Back,
    /// From -x.
    Left,
    /// From +x.
    Right,
    /// From above, looking down (slightly tilted so that +z stays up on screen).
    Top,
}

impl CameraSide {
    /// The unit offset from the look-at point towards the eye.
    fn direction(self) -> Vector {
        let (x, y, z) = match self {
            CameraSide::Front => (0.0, -1.0, SIDE_ELEVATION),
            CameraSide::Back => (0.0, 1.0, SIDE_ELEVATION),
            CameraSide::Left => (-1.0, 0.0, SIDE_ELEVATION),
            CameraSide::Right => (1.0, 0.0, SIDE_ELEVATION),
            CameraSide::Top => (0.0, -0.25, 1.0),
        };
        Vector::new(x, y, z).normalize()
    }
}

/// The eye of a 3D view for `camera`, given the cloth's first recorded positions: a
/// [`Camera::Follow`] eye tracks `tracked` (an entity path); the others are fixed.
pub(super) fn eye(camera: Camera, positions: &[Vector], tracked: &str) -> Eye {
    let (eye, look_at) = match camera {
        Camera::Follow => return Eye::Tracking(tracked.to_owned()),
        Camera::At { eye, look_at } => (eye, look_at),
        Camera::Side(side) => {
            let (centre, radius) = bounding_sphere(positions);
            let distance = (SIDE_DISTANCE_RADII * radius).max(SIDE_DISTANCE_MIN);
            (centre + side.direction() * distance, centre)
        }
    };
    Eye::Fixed {
        position: [eye.x as f32, eye.y as f32, eye.z as f32],
        look_target: [look_at.x as f32, look_at.y as f32, look_at.z as f32],
    }
}

/// The centre of the axis-aligned bounding box of `positions` and the half length of its
/// diagonal (the origin and 0 for no positions).
fn bounding_sphere(positions: &[Vector]) -> (Vector, f64) {
    let Some(first) = positions.first() else {
        return (Vector::ZERO, 0.0);
    };
    let (lo, hi) = positions
        .iter()
        .fold((*first, *first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    ((lo + hi) * 0.5, (hi - lo).length() * 0.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_back_eye_stands_behind_the_cloth_and_looks_at_its_centre() {
        let cloth = [Vector::new(-0.5, 0.0, 1.0), Vector::new(0.5, 0.2, 2.0)];
        let Eye::Fixed {
            position,
            look_target,
        } = eye(Camera::Side(CameraSide::Back), &cloth, "/cloth/mesh")
        else {
            panic!("a side camera gives a fixed eye");
        };
        assert_eq!(look_target, [0.0, 0.1, 1.5]);
        assert!(position[1] > 1.0, "behind (+y): {position:?}");
        assert!(
            position[2] > look_target[2],
            "above the centre: {position:?}"
        );
        assert!(position[0].abs() < 1e-6, "not to a side: {position:?}");
    }

    #[test]
    fn the_default_camera_follows_the_cloth() {
        let e = eye(Camera::Follow, &[Vector::ZERO], "/cloth/mesh");
        assert!(matches!(e, Eye::Tracking(ref p) if p == "/cloth/mesh"));
    }

    #[test]
    fn a_point_cloth_is_seen_from_the_smallest_distance() {
        let Eye::Fixed { position, .. } = eye(
            Camera::Side(CameraSide::Left),
            &[Vector::ZERO],
            "/cloth/mesh",
        ) else {
            panic!("a side camera gives a fixed eye");
        };
        let d = position.iter().map(|c| c * c).sum::<f32>().sqrt();
        assert!((d - SIDE_DISTANCE_MIN as f32).abs() < 1e-6, "{d}");
    }
}
