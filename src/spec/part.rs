//! `[[obstacle.part]]`: one rigid part of an articulated obstacle (a body made
//! of primitives in a joint hierarchy, e.g. a mannequin).

use serde::Deserialize;

use super::{Keyframe, KeyframeAfter, KeyframeEasing, ObstacleShape};

/// One part of an `articulated` obstacle: a primitive shape fixed in the
/// part's frame, which hangs from its parent's frame at a joint.
///
/// The part's frame sits at `joint` in the parent's frame (the obstacle's own
/// frame, placed by its `position`, `rotation` and `keyframes`, for a part
/// without a parent), turned by `rotation` at rest and further by the joint
/// rotation its `keyframes` give at each time. The shape sits at `center` in
/// the part's frame, with its axes along the part's (round shapes along local
/// z). See `src/kinematics/skeleton.rs`.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Part {
    /// The part's name, unique within its obstacle.
    pub name: String,
    /// The name of the part it hangs from; absent: the obstacle's own frame.
    pub parent: Option<String>,
    /// The primitive: `sphere`, `capsule` or `box`.
    pub shape: ObstacleShape,
    /// Radius in m (sphere, capsule).
    pub radius: Option<f64>,
    /// Half the length of a capsule's segment, m.
    pub half_height: Option<f64>,
    /// Half the size of a box along the part's x, y, z, m.
    pub half_extents: Option<[f64; 3]>,
    /// Position of the joint (the part frame's origin) in the parent's frame, m.
    #[serde(default)]
    pub joint: [f64; 3],
    /// The part frame's rotation at rest relative to the parent's frame:
    /// Euler angles in degrees (about x, then y, then z).
    #[serde(default)]
    pub rotation: [f64; 3],
    /// Position of the shape's centre in the part's frame, m.
    #[serde(default)]
    pub center: [f64; 3],
    /// Joint rotations at increasing times (at least two; none: the joint
    /// stays at rest), relative to `rotation`; a key's translation must be zero.
    #[serde(default)]
    pub keyframes: Vec<Keyframe>,
    /// How joint rotations between keys are interpolated.
    #[serde(default)]
    pub easing: KeyframeEasing,
    /// What the joint does after its last key.
    #[serde(default)]
    pub after_last: KeyframeAfter,
}
