//! What carries an attached pin (`[[pin]] attach`): a rigid obstacle, the
//! root frame of an articulated one (`NAME`), or one of its parts
//! (`NAME/PART`).
//!
//! Every such body moves by a rigid map from its placement at rest: a point
//! at `x` at rest is at `c(t) + R(t) (x - o)` at time `t`, with the body's
//! origin `o` at rest, `c(t) = o + shift(t)` and the rotation `R(t)` of its
//! [`RigidState`]. The held vertices keep their place in the body's frame as
//! of t = 0: a vertex at `x0` then is at
//!
//! ```text
//! x(t) = c(t) + R(t) R(0)^-1 (x0 - c(0))
//! ```
//!
//! and moves at the velocity of the body's material point there, from the
//! same function friction and continuous detection use
//! ([`RigidState::point_velocity`]), so it is exact.
//!
//! A `mesh_sequence` has no rigid frame and cannot carry pins. An
//! articulated body can, whether it meets the cloth as rigid parts or as a
//! skinned mesh: each vertex of the skin follows its part rigidly, so a pin
//! attached to the part moves with the skin over it.

use std::sync::Arc;

use super::motion::{Motion, RigidState, obstacle_motion};
use super::skeleton::Skeleton;
use crate::math::{Scalar, Vector};
use crate::spec::{Geometry, ObstacleSpec};

/// Why an `attach` value names nothing that can carry pins.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
pub enum AttachError {
    /// An empty obstacle or part name (`""`, `"/torso"`, `"body/"`).
    #[error(
        "`{attach}` is not of the form \"NAME\" (an obstacle) or \"NAME/PART\" (a part of an articulated obstacle)"
    )]
    Syntax {
        /// The value.
        attach: String,
    },
    /// No obstacle has the name.
    #[error("no obstacle is named `{name}`")]
    UnknownObstacle {
        /// The name.
        name: String,
    },
    /// A part of an obstacle that has no parts.
    #[error(
        "obstacle `{obstacle}` is a {shape}, which has no parts: attach to \"{obstacle}\" itself"
    )]
    NoParts {
        /// The obstacle's name.
        obstacle: String,
        /// Its shape.
        shape: &'static str,
    },
    /// The articulated obstacle has no part of that name.
    #[error("obstacle `{obstacle}` has no part named `{part}`")]
    UnknownPart {
        /// The obstacle's name.
        obstacle: String,
        /// The part's name.
        part: String,
    },
    /// A shape without a rigid frame.
    #[error(
        "obstacle `{obstacle}` is a mesh sequence: its frames deform it, with no rigid frame to carry pins; \
         pins attach to a rigid obstacle (sphere, box, plane, capsule, cylinder, mesh), to an articulated \
         obstacle's root frame or to one of its parts"
    )]
    NoRigidFrame {
        /// The obstacle's name.
        obstacle: String,
    },
    /// The articulated obstacle's hierarchy is unusable (validation normally
    /// catches this first).
    #[error("obstacle `{obstacle}`: {reason}")]
    Body {
        /// The obstacle's name.
        obstacle: String,
        /// What is wrong.
        reason: String,
    },
}

/// Where an `attach` value points: obstacle `obstacle`, and part `part` of
/// it when it names one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AttachTarget {
    /// Index of the `[[obstacle]]`.
    pub obstacle: usize,
    /// Index of the part (`None`: the obstacle's own frame).
    pub part: Option<usize>,
}

/// Finds what `attach` (`"NAME"` or `"NAME/PART"`) names among `obstacles`.
pub fn locate(obstacles: &[ObstacleSpec], attach: &str) -> Result<AttachTarget, AttachError> {
    let (name, part) = match attach.split_once('/') {
        Some((n, p)) => (n, Some(p)),
        None => (attach, None),
    };
    if name.is_empty() || part.is_some_and(str::is_empty) {
        return Err(AttachError::Syntax {
            attach: attach.to_owned(),
        });
    }
    let index = obstacles
        .iter()
        .position(|o| o.name.as_deref() == Some(name))
        .ok_or_else(|| AttachError::UnknownObstacle { name: name.into() })?;
    let o = &obstacles[index];
    if matches!(o.geometry, Geometry::MeshSequence { .. }) {
        return Err(AttachError::NoRigidFrame {
            obstacle: name.into(),
        });
    }
    let Some(part) = part else {
        return Ok(AttachTarget {
            obstacle: index,
            part: None,
        });
    };
    let Geometry::Articulated { parts, .. } = &o.geometry else {
        return Err(AttachError::NoParts {
            obstacle: name.into(),
            shape: o.geometry.kind().name(),
        });
    };
    let found = parts.iter().position(|p| p.name == part);
    found
        .map(|p| AttachTarget {
            obstacle: index,
            part: Some(p),
        })
        .ok_or_else(|| AttachError::UnknownPart {
            obstacle: name.into(),
            part: part.into(),
        })
}

/// Every value `attach` may take with `obstacles`, quoted, for messages:
/// each named obstacle with a rigid frame, and each part of the articulated ones.
pub fn targets(obstacles: &[ObstacleSpec]) -> Vec<String> {
    let mut out = Vec::new();
    for o in obstacles {
        let Some(name) = &o.name else { continue };
        match &o.geometry {
            Geometry::MeshSequence { .. } => continue,
            Geometry::Articulated { parts, .. } => {
                out.push(format!("\"{name}\""));
                out.extend(parts.iter().map(|p| format!("\"{name}/{}\"", p.name)));
            }
            _ => out.push(format!("\"{name}\"")),
        }
    }
    out
}

/// A rigid body that carries pinned vertices (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Carrier {
    /// The body's origin at rest, the centre its rotation turns about, m.
    origin: Vector,
    /// How it moves from its placement at rest.
    motion: Motion,
    /// Its state at t = 0.
    start: RigidState,
    /// What it is, for `drape check`: the `attach` value.
    label: String,
}

impl Carrier {
    /// The body `attach` names among `obstacles` (see [`locate`]).
    pub fn new(obstacles: &[ObstacleSpec], attach: &str) -> Result<Carrier, AttachError> {
        let target = locate(obstacles, attach)?;
        let o = &obstacles[target.obstacle];
        let root = obstacle_motion(&o.motion);
        let (origin, motion) = match target.part {
            None => (Vector::from_array(o.position), root),
            Some(part) => {
                let skeleton =
                    Skeleton::new(target.obstacle, o, root).map_err(|e| AttachError::Body {
                        obstacle: o.name.clone().unwrap_or_default(),
                        reason: e.to_string(),
                    })?;
                let origin = skeleton.rest(part).position;
                let skeleton = Arc::new(skeleton);
                (origin, Motion::Articulated { skeleton, part })
            }
        };
        Ok(Carrier {
            origin,
            start: motion.state(0.0),
            motion,
            label: attach.to_owned(),
        })
    }

    /// Position and velocity at time `t` of the body point that is at `x0`
    /// at t = 0 (module docs).
    pub fn follow(&self, x0: Vector, t: Scalar) -> (Vector, Vector) {
        let s0 = &self.start;
        let rest = self.origin + s0.rotation.inverse() * (x0 - (self.origin + s0.shift));
        let s = self.motion.state(t);
        let x = s.place(self.origin, rest);
        (x, s.point_velocity(self.origin, x))
    }

    /// True when the body moves at some time.
    pub fn is_moving(&self) -> bool {
        self.motion.is_moving()
    }

    /// For `drape check`: what carries the pin and how it moves.
    pub fn describe(&self) -> String {
        format!(
            "attached to `{}`{}",
            self.label,
            if self.is_moving() {
                ", moving with it"
            } else {
                " (which does not move)"
            }
        )
    }
}
