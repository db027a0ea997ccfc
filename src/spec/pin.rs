//! `[[pin]]`: a pinned region of the cloth and how it moves.

use serde::Deserialize;

use super::{Keyframe, KeyframeAfter, KeyframeEasing, default_axis};

/// `[[pin]]`: a pinned region of the cloth, selected in material space.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Pin {
    /// `corner:top_left|top_right|bottom_left|bottom_right`, `edge:top|bottom|left|right`,
    /// `box` (with `box_min`/`box_max`), `disk` (with `disk_radius`) or `all`.
    pub region: String,
    /// Lower corner of a `box` region in material coordinates (m).
    pub box_min: Option<[f64; 2]>,
    /// Upper corner of a `box` region in material coordinates (m).
    pub box_max: Option<[f64; 2]>,
    /// Centre of a `disk` region in material coordinates (m; absent: the origin).
    pub disk_center: Option<[f64; 2]>,
    /// Radius of a `disk` region (m).
    pub disk_radius: Option<f64>,
    /// How the pinned vertices move (without `attach`).
    #[serde(default)]
    pub motion: PinMotion,
    /// Velocity in m/s for `linear` motion.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Acceleration in m/s^2 for `linear` motion.
    #[serde(default)]
    pub acceleration: [f64; 3],
    /// A point on the rotation axis (world, m) for `circular` motion.
    #[serde(default)]
    pub center: [f64; 3],
    /// Rotation axis for `circular` motion (normalised; must not be zero).
    #[serde(default = "default_axis")]
    pub axis: [f64; 3],
    /// Angular velocity in rad/s for `circular` motion (right-handed about `axis`).
    #[serde(default)]
    pub angular_velocity: f64,
    /// Time in s at which the pin lets go (absent: never).
    pub release_time: Option<f64>,
    /// `motion = "keyframed"`: the held cloth's pose at increasing times
    /// (translation, and rotation about `center`), relative to where it starts.
    #[serde(default)]
    pub keyframes: Vec<Keyframe>,
    /// `motion = "keyframed"`: how poses between keys are interpolated.
    #[serde(default)]
    pub easing: KeyframeEasing,
    /// `motion = "keyframed"`: what the pin does after its last key.
    #[serde(default)]
    pub after_last: KeyframeAfter,
    /// Instead of `motion`: the obstacle (`"NAME"`) or the part of an
    /// articulated obstacle (`"NAME/PART"`) that carries the pinned vertices,
    /// which keep their place in its frame as of t = 0.
    pub attach: Option<String>,
}

/// How a pin moves.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum PinMotion {
    /// Held in place.
    #[default]
    Fixed,
    /// `x(t) = x0 + velocity t + acceleration t^2 / 2`.
    Linear,
    /// Rotation about `axis` through `center` at `angular_velocity`.
    Circular,
    /// Along `keyframes`: moved by each key's translation and turned by its
    /// rotation about `center` (see `src/kinematics/motion.rs`).
    Keyframed,
}
