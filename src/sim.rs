//! One simulation as three values, in the manner of rapier's parameters, sets and
//! pipeline:
//!
//! - [`Setup`]: what is fixed for the run: the physics ([`Model`]: material,
//!   external forces, integrator, solver settings), the obstacles and the
//!   [`Settings`] (step size, multirate stepping, self-collision, adaptivity).
//!   Every call that advances a state is given it.
//! - [`SimState`]: everything a run's result depends on that changes as it runs
//!   (mesh, positions, velocities, time, pins, the adaptive hierarchy, the resting
//!   contacts, the implicit solver's warm start, the work ledger and the counters).
//!   It is one cloneable value, so a frame retry or a rollback is one `clone_from`
//!   and one restore.
//! - [`Pipeline`]: the machinery that advances a state by a step
//!   ([`Pipeline::step`]`(&setup, &mut state, h)`) or a frame
//!   ([`Pipeline::advance_frame`]): the element tables derived from the mesh, the
//!   collision passes' scratch, the direct solver's stored factorization and scratch memory.
//!   It holds no simulation state and no settings: it can be dropped and rebuilt from the setup and
//!   the state at any step ([`Pipeline::new`]). Only the stored factorization (the
//!   direct solver's preconditioner, refreshed when an older factor's
//!   iterations outweigh a factorization) is lost then; the next solve factors afresh and its result differs
//!   within the solve's tolerance (`simulation.cg_tolerance`), not beyond it. With
//!   `solver = "cg"` or an explicit integrator a rebuilt pipeline continues
//!   bit-identically (test `sim::a_rebuilt_pipeline_continues_a_run_bit_identically`).
//!
//! A step is a short list of named phases, in [`Pipeline::step`]:
//! **forces + integrate** (the stepper), **collide** (obstacles, then self-collision),
//! **account** (the work of wind, pins and moving obstacles), **health check**
//! (finite, energy below its bound), **rollback** (paper A: redo the step on a
//! refined mesh), **adapt** (the remeshing pass).

mod bound;
mod pipeline;
mod setup;
mod state;
pub mod step_control;

pub use bound::{EXPLOSION_FACTOR, EnergyBound, StepFailure};
pub use pipeline::{
    ENERGY_GAIN_TOLERANCE, FrameFailed, FrameFailure, MAX_ENERGY_HALVINGS, MAX_STEP_HALVINGS,
    Pipeline, StepError, StepOutcome, WeldEvent,
};
pub use setup::{Settings, Setup, StepSize};
pub use state::{Effort, Ledger, RefusedSteps, SeamState, SimState};
pub use step_control::{
    AdaptiveStep, DEFAULT_MIN_STEP, DEFAULT_STEP_PENETRATION, DEFAULT_STEP_TOLERANCE, StepControl,
};

use crate::adapt::Adapter;
use crate::collide::{CollideError, Inside, Obstacles};
use crate::math::{Scalar, Vector};
use crate::physics::Model;
use crate::spec::{ClothSpec, ObstacleSpec, Pin};
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
    pub obstacles: Vec<ObstacleSpec>,
    /// Step size, multirate stepping, self-collision and adaptivity.
    pub settings: Settings,
    /// Area density, kg/m^2 (the remesher's mass transfer).
    pub density: Scalar,
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
    /// A garment panel starts inside an obstacle.
    #[error(
        "panel `{panel}` starts inside {obstacle}: a vertex at [{x:.3}, {y:.3}, {z:.3}] m is \
         {depth_mm:.1} mm below its surface; place the panels around the body"
    )]
    PanelInsideBody {
        /// The panel.
        panel: String,
        /// The obstacle (and part).
        obstacle: String,
        /// The vertex's position, m.
        x: Scalar,
        /// y, m.
        y: Scalar,
        /// z, m.
        z: Scalar,
        /// How deep inside, mm.
        depth_mm: Scalar,
    },
    /// The adaptive method cannot work on this mesh.
    #[error("{0}")]
    Adapt(#[from] crate::adapt::AdaptSetupError),
}

/// A garment must start outside every body: one starting inside would be
/// thrown out by the first collision pass.
fn garment_outside_bodies(world: &World, obstacles: &Obstacles) -> Result<(), SimBuildError> {
    match inside(world, obstacles).into_iter().next() {
        None => Ok(()),
        Some(p) => Err(SimBuildError::PanelInsideBody {
            obstacle: p.inside.obstacle,
            x: p.position.x,
            y: p.position.y,
            z: p.position.z,
            depth_mm: 1e3 * p.inside.depth,
            panel: p.panel,
        }),
    }
}

/// A garment panel that starts inside an obstacle ([`panels_inside`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PanelInside {
    /// The panel's name.
    pub panel: String,
    /// Its vertex deepest inside an obstacle.
    pub inside: Inside,
    /// That vertex's position, m.
    pub position: Vector,
    /// The panel's unit normal as placed: its triangles' area-weighted mean
    /// (either side; a panel starts flat).
    pub panel_normal: Vector,
}

/// The garment panels of `spec` that start inside an obstacle, deepest first;
/// empty for a cloth that is not a garment. What [`build`] refuses, for a
/// caller that places the panels (`drape garment`).
pub fn panels_inside(spec: &SimSpec) -> Result<Vec<PanelInside>, SimBuildError> {
    let world = World::from_spec(&spec.cloth, &spec.pins, &spec.obstacles)?;
    Ok(inside(&world, &Obstacles::new(&spec.obstacles)?))
}

fn inside(world: &World, obstacles: &Obstacles) -> Vec<PanelInside> {
    let Some(panels) = world.mesh.panels() else {
        return Vec::new();
    };
    let deepest =
        obstacles.deepest_inside(&world.x, world.time, &panels.of_vertex, panels.names.len());
    let mut normals = vec![Vector::ZERO; panels.names.len()];
    for (t, &p) in world.mesh.triangles.iter().zip(&panels.of_triangle) {
        let [a, b, c] = t.map(|i| world.x[i as usize]);
        normals[p as usize] += (b - a).cross(c - a);
    }
    let mut out: Vec<PanelInside> = deepest
        .into_iter()
        .zip(normals)
        .enumerate()
        .filter_map(|(k, (d, n))| {
            d.map(|inside| PanelInside {
                panel: panels.names[k].clone(),
                position: world.x[inside.vertex],
                inside,
                panel_normal: n.normalize_or_zero(),
            })
        })
        .collect();
    out.sort_by(|a, b| b.inside.depth.total_cmp(&a.inside.depth));
    out
}

/// A simulation ready to run: what it holds fixed, its initial state and the
/// pipeline that advances it (`pipeline.step(&setup, &mut state, h)`).
pub struct SimParts {
    /// The physics, the obstacles and the settings, fixed for the run.
    pub setup: Setup,
    /// The state, at the start of the run.
    pub state: SimState,
    /// The machinery that advances the state (scratch only).
    pub pipeline: Pipeline,
}

/// Builds the setup, the initial state and the pipeline of a specification. This
/// is where a bad OBJ file or a pin that selects nothing is found, before any
/// output is opened.
pub fn build(spec: &SimSpec) -> Result<SimParts, SimBuildError> {
    let world = World::from_spec(&spec.cloth, &spec.pins, &spec.obstacles)?;
    let adapter = spec
        .settings
        .adapt
        .as_ref()
        .map(|c| Adapter::new(c, &world, spec.density))
        .transpose()?;
    let setup = Setup {
        model: spec.model.clone(),
        obstacles: Obstacles::new(&spec.obstacles)?,
        settings: spec.settings.clone(),
    };
    garment_outside_bodies(&world, &setup.obstacles)?;
    let pipeline = Pipeline::new(&setup, &world);
    let state = SimState::new(&setup, world, adapter, &pipeline);
    Ok(SimParts {
        setup,
        state,
        pipeline,
    })
}
