//! How a rigid obstacle moves: not at all, at a constant velocity and spin, or
//! along keyframes.
//!
//! Every motion gives, at any time `t`, the rigid map from the obstacle's
//! placement at rest (its `position` and `rotation`) to its placement at `t`:
//! a rotation `R(t)` about the obstacle's origin and the origin's position
//! `c(t)`, with the exact velocity `c'(t)` and angular velocity `w(t)` of that
//! map. Continuous collision detection reads the poses at the two ends of a
//! step, friction the velocity of the surface point under a vertex, so both
//! see the same motion.
//!
//! # Keyframes
//!
//! A key holds a time, a translation of the origin and a rotation about it
//! (Euler angles in degrees, about x, then y, then z, as `rotation`), both
//! relative to the obstacle's placement at rest. Between two keys the
//! translation is interpolated linearly and the rotation along the shortest
//! arc (spherical linear interpolation of the keys' quaternions, the sign of
//! the second chosen so that the arc is at most half a turn), both with the
//! same parameter `s(u)` of the fraction `u` of the interval that has passed:
//!
//! - `linear`: `s = u`, a constant velocity and spin in each interval, which
//!   jump at the keys;
//! - `smooth`: `s = 3u^2 - 2u^3`, which eases in and out of every key: the
//!   velocity is zero at the keys and continuous everywhere (C1).
//!
//! With `s(u)`, `q(t) = q_a * exp(s * log(q_a^-1 q_b))`, so the angular velocity
//! is `q_a * (axis * angle) * ds/dt` in world coordinates, and the velocity of the
//! origin is `(p_b - p_a) * ds/dt`: exact, not finite differences.
//!
//! Before the first key the obstacle stays at the first key. After the last
//! it holds the last key (`hold`), or the keys repeat with the period from the
//! first key to the last (`loop`), which needs the last key's pose to equal the
//! first's so that nothing jumps where the loop wraps around.

use std::sync::Arc;

use glam::DQuat;

use super::skeleton::Skeleton;

use crate::math::{Scalar, Vector, rotation_from_euler_deg};
use crate::spec::{Keyframe, KeyframeAfter, KeyframeEasing, ObstacleMotion};

/// The obstacle's motion relative to its placement at rest.
#[derive(Debug, Clone, PartialEq)]
pub enum Motion {
    /// It does not move.
    Fixed,
    /// Translated at `velocity` and spun at `omega` (axis times rad/s) about
    /// its moving origin.
    Constant {
        /// Velocity of the origin, m/s.
        velocity: Vector,
        /// Angular velocity, rad/s (world axis times rate).
        omega: Vector,
    },
    /// Along keyframes.
    Keyframed(Track),
    /// As one part of an articulated body (forward kinematics, `skeleton.rs`).
    Articulated {
        /// The body's joint hierarchy and root motion, shared by its parts.
        skeleton: Arc<Skeleton>,
        /// Which part.
        part: usize,
    },
}

/// Where the obstacle is at one time, relative to its placement at rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidState {
    /// Displacement of the origin, m.
    pub shift: Vector,
    /// Rotation about the origin.
    pub rotation: DQuat,
    /// Velocity of the origin, m/s.
    pub velocity: Vector,
    /// Angular velocity, rad/s (world axis times rate).
    pub omega: Vector,
}

impl RigidState {
    /// Where the body point at `rest` (world position with the body at rest)
    /// is in this state, the body turning about its origin `origin` at rest.
    pub fn place(&self, origin: Vector, rest: Vector) -> Vector {
        origin + self.shift + self.rotation * (rest - origin)
    }

    /// Velocity of the body's material point at world position `x` in this
    /// state (`origin`: the body's origin at rest): the same for contact,
    /// friction and attached pins.
    pub fn point_velocity(&self, origin: Vector, x: Vector) -> Vector {
        self.velocity + self.omega.cross(x - (origin + self.shift))
    }
}

/// Keyframes ready to interpolate.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    times: Vec<Scalar>,
    shifts: Vec<Vector>,
    rotations: Vec<DQuat>,
    easing: KeyframeEasing,
    after: KeyframeAfter,
}

impl Track {
    /// The track of validated keyframes (at least two, times strictly
    /// increasing: the scene's validation guarantees it).
    pub fn new(keys: &[Keyframe], easing: KeyframeEasing, after: KeyframeAfter) -> Track {
        let mut rotations: Vec<DQuat> = Vec::with_capacity(keys.len());
        for k in keys {
            let mut q = DQuat::from_mat3(&rotation_from_euler_deg(k.rotation)).normalize();
            // Each key on the same side as the one before: the shortest arc.
            if rotations.last().is_some_and(|p| p.dot(q) < 0.0) {
                q = -q;
            }
            rotations.push(q);
        }
        Track {
            times: keys.iter().map(|k| k.time).collect(),
            shifts: keys
                .iter()
                .map(|k| Vector::from_array(k.translation))
                .collect(),
            rotations,
            easing,
            after,
        }
    }

    /// The state at time `t`.
    pub fn state(&self, t: Scalar) -> RigidState {
        let n = self.times.len();
        let (first, last) = (self.times[0], self.times[n - 1]);
        let t = match self.after {
            KeyframeAfter::Loop if t > last => first + (t - first).rem_euclid(last - first),
            _ => t,
        };
        if t < first || t >= last {
            let i = if t < first { 0 } else { n - 1 };
            return RigidState {
                shift: self.shifts[i],
                rotation: self.rotations[i],
                velocity: Vector::ZERO,
                omega: Vector::ZERO,
            };
        }
        // The interval [times[i], times[i + 1]) holding t.
        let i = self.times.partition_point(|&k| k <= t) - 1;
        let dt = self.times[i + 1] - self.times[i];
        let u = (t - self.times[i]) / dt;
        let (s, ds) = match self.easing {
            KeyframeEasing::Linear => (u, 1.0 / dt),
            KeyframeEasing::Smooth => (u * u * (3.0 - 2.0 * u), 6.0 * u * (1.0 - u) / dt),
        };
        let (pa, pb) = (self.shifts[i], self.shifts[i + 1]);
        let (qa, qb) = (self.rotations[i], self.rotations[i + 1]);
        let (axis, angle) = (qa.inverse() * qb).to_axis_angle();
        RigidState {
            shift: pa + (pb - pa) * s,
            rotation: (qa * DQuat::from_axis_angle(axis, angle * s)).normalize(),
            velocity: (pb - pa) * ds,
            omega: qa * (axis * (angle * ds)),
        }
    }
}

impl Motion {
    /// True when the obstacle moves at some time.
    pub fn is_moving(&self) -> bool {
        match self {
            Motion::Fixed => false,
            Motion::Constant { velocity, omega } => {
                *velocity != Vector::ZERO || *omega != Vector::ZERO
            }
            Motion::Keyframed(_) => true,
            Motion::Articulated { skeleton, part } => skeleton.is_moving(*part),
        }
    }

    /// For `drape check`: empty when fixed, else `, moving ...`.
    pub fn describe(&self) -> String {
        match self {
            Motion::Fixed => String::new(),
            Motion::Constant { .. } => ", moving at a constant velocity and spin".into(),
            Motion::Keyframed(track) => format!(
                ", keyframed: {} keys from {} s to {} s, {:?} easing, then {:?}",
                track.times.len(),
                track.times[0],
                track.times[track.times.len() - 1],
                track.easing,
                track.after
            )
            .to_lowercase(),
            Motion::Articulated { skeleton, part } => format!(
                ", part `{}` of {} of an articulated body (forward kinematics){}",
                skeleton.name(*part),
                skeleton.len(),
                if skeleton.is_moving(*part) {
                    ", moving"
                } else {
                    ""
                }
            ),
        }
    }

    /// The state at time `t`.
    pub fn state(&self, t: Scalar) -> RigidState {
        match self {
            Motion::Fixed => RigidState {
                shift: Vector::ZERO,
                rotation: DQuat::IDENTITY,
                velocity: Vector::ZERO,
                omega: Vector::ZERO,
            },
            Motion::Constant { velocity, omega } => RigidState {
                shift: *velocity * t,
                rotation: DQuat::from_axis_angle(omega.normalize_or(Vector::Z), omega.length() * t),
                velocity: *velocity,
                omega: *omega,
            },
            Motion::Keyframed(track) => track.state(t),
            Motion::Articulated { skeleton, part } => skeleton.state(*part, t),
        }
    }
}

/// The motion an obstacle's keys ask for: keyframes, else a constant velocity
/// and spin about its axis (normalised; a zero axis spins nothing), else none.
pub fn obstacle_motion(motion: &ObstacleMotion) -> Motion {
    match motion {
        ObstacleMotion::Still => Motion::Fixed,
        ObstacleMotion::Keyframed {
            keyframes,
            easing,
            after_last,
        } => Motion::Keyframed(Track::new(keyframes, *easing, *after_last)),
        ObstacleMotion::Constant {
            velocity,
            angular_velocity,
            axis,
        } => {
            let velocity = Vector::from_array(*velocity);
            let omega = Vector::from_array(*axis).normalize_or_zero() * *angular_velocity;
            if velocity == Vector::ZERO && omega == Vector::ZERO {
                Motion::Fixed
            } else {
                Motion::Constant { velocity, omega }
            }
        }
    }
}
