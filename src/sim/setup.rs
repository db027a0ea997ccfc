//! [`Setup`]: what a run holds fixed — the physics, the obstacles and the
//! [`Settings`] — given to every call that advances a state.

use crate::adapt::AdaptConfig;
use crate::collide::Obstacles;
use crate::math::Scalar;
use crate::physics::Model;
use crate::spec::SelfCollision;

use super::step_control::AdaptiveStep;

/// Everything a run holds fixed (`docs/architecture.md`, "The simulation as
/// three values"): given to every call that advances a state, next to the
/// state (`pipeline.step(&setup, &mut state, h)`), so that the state holds only
/// what changes and the pipeline only scratch.
#[derive(Debug)]
pub struct Setup {
    /// The physics: material, external forces, and the integrator and solver
    /// settings the stepper reads.
    pub model: Model,
    /// The rigid obstacles (none: no obstacle pass runs).
    pub obstacles: Obstacles,
    /// How the pipeline steps, collides and adapts.
    pub settings: Settings,
}

/// How a run is stepped, besides the physics' integrator and solver settings:
/// the step size, multirate stepping, self-collision and adaptivity.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// The step size.
    pub step: StepSize,
    /// Paper A's multirate stepping (explicit integrators, adaptive meshes).
    pub multirate: bool,
    /// Self-collision, when the scene turns it on.
    pub self_collision: Option<SelfCollision>,
    /// Adaptivity, when the scene adapts.
    pub adapt: Option<AdaptConfig>,
}

/// How the step size is chosen (`simulation.dt`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepSize {
    /// The stepper's estimate for the current mesh (`dt = "auto"`).
    Auto,
    /// This many seconds.
    Fixed(Scalar),
    /// Error control (`dt = "adaptive"`, [`super::step_control`]).
    Adaptive(AdaptiveStep),
}
