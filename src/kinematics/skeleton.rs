//! Forward kinematics of an articulated obstacle: rigid parts in a joint
//! hierarchy, each turned at its joint by keyframed rotations.
//!
//! The root frame is the obstacle's own: placed by its `position` and
//! `rotation` and moved by its [`Motion`] (fixed, constant or keyframed). Each
//! part's frame hangs from its parent's frame (the root frame for a part
//! without a parent) at the joint `j` (in the parent's frame), turned by the
//! rest rotation `B` and the joint rotation `J(t)` of its keys (a [`Track`]).
//! With the parent's world rotation `R_p`, position `p_p`, velocity `v_p` and
//! angular velocity `w_p`, and `r = R_p j`:
//!
//! ```text
//! R = R_p B J(t)          p = p_p + r
//! w = w_p + R_p B w_J     v = v_p + w_p x r
//! ```
//!
//! where `w_J` is the joint track's angular velocity (in the frame `B` turns
//! it into), exact like the track's. A part's surface point `x` then moves at
//! `v + w x (x - p)`.
//!
//! The part's placement *at rest* is its frame with the root at its
//! placement at rest and every joint at its rest rotation; its [`RigidState`]
//! at `t` is the rigid map from that placement to its frame at `t`, as for any
//! obstacle, so contact, friction and recording treat each part as one rigid
//! obstacle (`obstacle.rs`).

use glam::DQuat;

use super::KinematicsError;
use super::motion::{Motion, RigidState, Track};
use crate::math::{Scalar, Vector, rotation_from_euler_deg};
use crate::spec::{Geometry, ObstacleSpec, PartSpec};

/// A part's frame in the world at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// The joint's (frame origin's) world position, m.
    pub position: Vector,
    /// The frame's world rotation.
    pub rotation: DQuat,
    /// Velocity of the origin, m/s.
    pub velocity: Vector,
    /// Angular velocity, rad/s (world axis times rate).
    pub omega: Vector,
}

/// One joint of the hierarchy.
#[derive(Debug, Clone, PartialEq)]
struct Joint {
    /// The parent part's index; `None`: the root frame.
    parent: Option<usize>,
    /// The joint's position in the parent's frame, m.
    offset: Vector,
    /// Rotation at rest relative to the parent's frame.
    rest: DQuat,
    /// The joint rotation's keys; `None`: it stays at rest.
    track: Option<Track>,
}

/// The joint hierarchy of an articulated obstacle, with the root's motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    /// The root frame's origin at rest (the obstacle's `position`), m.
    origin: Vector,
    /// The root frame's rotation at rest (the obstacle's `rotation`).
    orientation: DQuat,
    /// How the root frame moves from its placement at rest.
    root: Motion,
    /// The joints, in the parts' order.
    joints: Vec<Joint>,
    /// The parts' names, for messages.
    names: Vec<String>,
    /// Each part's frame at rest.
    rest: Vec<Frame>,
}

impl Skeleton {
    /// The hierarchy of `o`'s parts (obstacle `index`), whose root moves as
    /// `root` says. Fails on an obstacle that is not articulated, a parent that
    /// names no part or a cycle (validation normally catches the last two first).
    pub fn new(index: usize, o: &ObstacleSpec, root: Motion) -> Result<Skeleton, KinematicsError> {
        let Geometry::Articulated { parts, .. } = &o.geometry else {
            return Err(KinematicsError::Hierarchy {
                index,
                reason: format!("a {} has no parts", o.geometry.kind().name()),
            });
        };
        let names: Vec<String> = parts.iter().map(|p| p.name.clone()).collect();
        let joints = parts
            .iter()
            .map(|p| joint(index, p, &names))
            .collect::<Result<Vec<_>, _>>()?;
        let mut sk = Skeleton {
            origin: Vector::from_array(o.position),
            orientation: DQuat::from_mat3(&rotation_from_euler_deg(o.rotation)).normalize(),
            root: Motion::Fixed,
            joints,
            names,
            rest: Vec::new(),
        };
        for start in 0..sk.joints.len() {
            let mut at = start;
            for _ in 0..=sk.joints.len() {
                match sk.joints[at].parent {
                    Some(p) => at = p,
                    None => break,
                }
            }
            if sk.joints[at].parent.is_some() {
                return Err(KinematicsError::Hierarchy {
                    index,
                    reason: format!(
                        "the chain of parents from part `{}` never reaches the root: the hierarchy has a cycle",
                        sk.names[start]
                    ),
                });
            }
        }
        sk.rest = (0..sk.joints.len()).map(|i| sk.at_rest(i)).collect();
        sk.root = root;
        Ok(sk)
    }

    /// The number of parts.
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// True when there are no parts.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Part `i`'s name.
    pub fn name(&self, i: usize) -> &str {
        &self.names[i]
    }

    /// Part `i`'s frame at rest.
    pub fn rest(&self, i: usize) -> Frame {
        self.rest[i]
    }

    /// True when part `i` moves at some time: the root moves, or a joint on
    /// its chain has keys.
    pub fn is_moving(&self, i: usize) -> bool {
        let mut at = Some(i);
        while let Some(j) = at {
            if self.joints[j].track.is_some() {
                return true;
            }
            at = self.joints[j].parent;
        }
        self.root.is_moving()
    }

    /// The root frame at time `t`.
    pub fn root(&self, t: Scalar) -> Frame {
        let s = self.root.state(t);
        Frame {
            position: self.origin + s.shift,
            rotation: (s.rotation * self.orientation).normalize(),
            velocity: s.velocity,
            omega: s.omega,
        }
    }

    /// Part `i`'s frame at time `t` (forward kinematics, module docs).
    pub fn frame(&self, i: usize, t: Scalar) -> Frame {
        let j = &self.joints[i];
        let p = match j.parent {
            Some(k) => self.frame(k, t),
            None => self.root(t),
        };
        let (turn, spin) = j
            .track
            .as_ref()
            .map_or((DQuat::IDENTITY, Vector::ZERO), |tr| {
                let s = tr.state(t);
                (s.rotation, s.omega)
            });
        let r = p.rotation * j.offset;
        Frame {
            position: p.position + r,
            rotation: (p.rotation * j.rest * turn).normalize(),
            velocity: p.velocity + p.omega.cross(r),
            omega: p.omega + p.rotation * (j.rest * spin),
        }
    }

    /// Part `i`'s rigid map from its placement at rest to its frame at `t`
    /// (module docs): the rotation about the rest joint position, and the
    /// joint's displacement, velocity and angular velocity.
    pub fn state(&self, i: usize, t: Scalar) -> RigidState {
        let now = self.frame(i, t);
        let rest = self.rest[i];
        RigidState {
            shift: now.position - rest.position,
            rotation: (now.rotation * rest.rotation.inverse()).normalize(),
            velocity: now.velocity,
            omega: now.omega,
        }
    }

    /// Part `i`'s frame with the root at rest and every joint at its rest
    /// rotation.
    fn at_rest(&self, i: usize) -> Frame {
        let j = &self.joints[i];
        let p = match j.parent {
            Some(k) => self.at_rest(k),
            None => Frame {
                position: self.origin,
                rotation: self.orientation,
                velocity: Vector::ZERO,
                omega: Vector::ZERO,
            },
        };
        Frame {
            position: p.position + p.rotation * j.offset,
            rotation: (p.rotation * j.rest).normalize(),
            velocity: Vector::ZERO,
            omega: Vector::ZERO,
        }
    }
}

/// Part `p`'s joint, its parent looked up among `names`.
fn joint(index: usize, p: &PartSpec, names: &[String]) -> Result<Joint, KinematicsError> {
    let parent = match &p.parent {
        None => None,
        Some(name) => Some(names.iter().position(|n| n == name).ok_or_else(|| {
            KinematicsError::Hierarchy {
                index,
                reason: format!("part `{}` names an unknown parent `{name}`", p.name),
            }
        })?),
    };
    let track = (!p.keyframes.is_empty()).then(|| Track::new(&p.keyframes, p.easing, p.after_last));
    Ok(Joint {
        parent,
        offset: Vector::from_array(p.joint),
        rest: DQuat::from_mat3(&rotation_from_euler_deg(p.rotation)).normalize(),
        track,
    })
}
