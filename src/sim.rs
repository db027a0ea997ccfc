//! One simulation as two values, in the manner of rapier's sets and pipeline:
//!
//! - [`SimState`]: everything a run's result depends on that changes as it runs
//!   (mesh, positions, velocities, time, pins, the adaptive hierarchy, the resting
//!   contacts, the work ledger and the counters). It is one cloneable value, so a
//!   frame retry or a rollback is one `clone_from` and one restore.
//! - [`Pipeline`]: the machinery that advances a state by a step
//!   ([`Pipeline::step`]) or a frame ([`Pipeline::advance_frame`]): the force model
//!   and its element tables, the collision passes, the solver's factorization and
//!   scratch memory. It holds no simulation state: it can be dropped and rebuilt
//!   from the model and the state at any step ([`Pipeline::new`]). Only the implicit
//!   solver's warm start and stored factorization are lost then; the next solve
//!   starts cold and the result differs within the solve's tolerance
//!   (`simulation.cg_tolerance`), not beyond it.
//!
//! A step is a short list of named phases, in [`Pipeline::step`]:
//! **forces + integrate** (the stepper), **collide** (obstacles, then self-collision),
//! **account** (the work of wind, pins and moving obstacles), **health check**
//! (finite, energy below its bound), **rollback** (paper A: redo the step on a
//! refined mesh), **adapt** (the remeshing pass).

mod bound;
mod pipeline;
mod state;

pub use bound::{EXPLOSION_FACTOR, EnergyBound, StepFailure};
pub use pipeline::{
    ENERGY_GAIN_TOLERANCE, FrameFailed, MAX_ENERGY_HALVINGS, MAX_STEP_HALVINGS, Pipeline,
};
pub use state::{Effort, Ledger, SimState};

use crate::adapt::{AdaptConfig, Adapter};
use crate::collide::{CollideError, Collider};
use crate::math::Scalar;
use crate::physics::Model;
use crate::spec::{ClothSpec, Obstacle, Pin, SelfCollision};
use crate::world::{BuildError, World};

/// Everything a simulation is built from: a scene resolved into the engine's
/// specifications ([`crate::scene::Scene::resolve`]).
#[derive(Debug, Clone)]
pub struct SimSpec {
    /// The cloth's rest mesh and placement.
    pub cloth: ClothSpec,
    /// The pinned regions.
    pub pins: Vec<Pin>,
    /// Material, external forces, integrator and solver settings.
    pub model: Model,
    /// The rigid obstacles.
    pub obstacles: Vec<Obstacle>,
    /// Self-collision, when the scene turns it on.
    pub self_collision: Option<SelfCollision>,
    /// Adaptivity, when the scene adapts.
    pub adapt: Option<AdaptConfig>,
    /// Paper A's multirate stepping (explicit integrators, adaptive meshes).
    pub multirate: bool,
    /// Area density, kg/m^2 (the remesher's mass transfer).
    pub density: Scalar,
    /// The fixed step, s (`None`: automatic).
    pub fixed_dt: Option<Scalar>,
}

/// Why a specification could not become a simulation.
#[derive(Debug, thiserror::Error)]
pub enum SimBuildError {
    /// The cloth, its pins or its mesh could not be built.
    #[error("{0}")]
    Build(#[from] BuildError),
    /// The obstacles could not be built.
    #[error("{0}")]
    Collide(#[from] CollideError),
}

/// Builds the initial state and the pipeline of a specification. This is where a
/// bad OBJ file or a pin that selects nothing is found, before any output is opened.
pub fn build(spec: &SimSpec) -> Result<(SimState, Pipeline), SimBuildError> {
    let world = World::from_spec(&spec.cloth, &spec.pins)?;
    let adapter = spec.adapt.map(|c| Adapter::new(c, &world, spec.density));
    let collider = Collider::new(&spec.obstacles, spec.self_collision.as_ref())?;
    let pipeline = Pipeline::new(
        spec.model.clone(),
        &world,
        collider,
        spec.fixed_dt,
        spec.multirate,
    );
    let state = SimState::new(world, adapter, &pipeline);
    Ok((state, pipeline))
}
