//! How bodies move: keyframed and constant rigid motion ([`motion`]), joint
//! hierarchies ([`skeleton`]), a mesh skinned to its joints ([`skin`]), and
//! what carries an attached pin ([`carrier`]). Below both the pins and the
//! collision code, which read the same motions: a pin riding on a body and
//! the body's surface move by one function.

pub mod carrier;
pub mod motion;
pub mod skeleton;
pub mod skin;

/// Why a moving body could not be built from its scene keys.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KinematicsError {
    /// The joint hierarchy of an articulated obstacle is invalid (validation
    /// normally catches this first).
    #[error("obstacle {index}: {reason}")]
    Hierarchy {
        /// Obstacle index.
        index: usize,
        /// What is wrong.
        reason: String,
    },
}
