//! The physical model and the stepper.
//!
//! [`Model`] is the resolved, immutable physics of a scene; [`Stepper`] holds the
//! force elements derived from the current mesh plus all scratch memory, and
//! advances a [`World`] by one step with the chosen integrator.

pub mod bending;
pub mod elements;
pub mod explicit;
pub mod forces;
pub mod implicit;
pub mod multirate;
pub mod pins;
pub mod shape;
pub mod timestep;
pub mod work;

pub use elements::{Elements, Hinge, MaterialParams, Spring};
pub use forces::{Energy, ExternalForces, WindForce};
pub use shape::{SHAPE_SLOTS, ShapeTriangle};

use crate::math::{Scalar, Vector};
use crate::scene::Integrator;
use crate::world::World;

/// The resolved physics of a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// Fabric parameters.
    pub material: MaterialParams,
    /// Declared external forces.
    pub external: ExternalForces,
    /// Time integrator.
    pub integrator: Integrator,
    /// Relative residual at which CG stops (implicit only).
    pub cg_tolerance: Scalar,
    /// CG iteration cap (implicit only).
    pub cg_max_iterations: u32,
}

/// Counters of what the stepper did.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct StepStats {
    /// Steps taken.
    pub steps: u64,
    /// CG iterations over all implicit steps.
    pub cg_iterations: u64,
    /// Implicit steps whose CG stopped at the iteration cap.
    pub cg_capped: u64,
}

/// A vertex resting against an obstacle, as the collision pass left it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Contact {
    /// The obstacle's outward unit normal at the contact, or zero for no contact.
    pub normal: Vector,
    /// The obstacle surface's velocity along `normal` there, m/s.
    pub normal_speed: Scalar,
}

/// Force elements of the current mesh plus scratch memory; no simulation state.
#[derive(Debug, Clone)]
pub struct Stepper {
    /// The physics being integrated.
    pub model: Model,
    /// Springs, hinges and masses of the current mesh.
    pub elements: Elements,
    /// What has been done so far.
    pub stats: StepStats,
    /// Paper A's multirate stepping (explicit integrators): each step is a
    /// macro step in which every level takes its own substeps.
    pub multirate: bool,
    /// Obstacle contacts at the start of the next step, one per vertex (or empty),
    /// set by the collision pass; the implicit integrator filters them (see
    /// [`implicit`]). Cleared whenever the mesh changes.
    pub contacts: Vec<Contact>,
    /// Per vertex, after an implicit step: the normal velocity change its contact
    /// filter imposed (m/s, >= 0; empty or zeros when none); the collision pass uses
    /// it as the normal impulse for Coulomb friction.
    pub contact_push: Vec<Scalar>,
    held: Vec<bool>,
    forces: forces::ForceScratch,
    rk4: explicit::Rk4Scratch,
    implicit: implicit::ImplicitScratch,
    levels: Option<multirate::Levels>,
    rk4_multirate: multirate::Rk4MultirateScratch,
}

impl Stepper {
    /// A stepper for `model` on the world's current mesh.
    pub fn new(model: Model, world: &World) -> Stepper {
        let elements = Elements::build_clamped(
            &world.mesh,
            &model.material,
            &world.pins.clamped(world.mesh.vertex_count()),
        );
        Stepper {
            model,
            elements,
            stats: StepStats::default(),
            multirate: false,
            contacts: Vec::new(),
            contact_push: Vec::new(),
            held: vec![false; world.mesh.vertex_count()],
            forces: Default::default(),
            rk4: Default::default(),
            implicit: Default::default(),
            levels: None,
            rk4_multirate: Default::default(),
        }
    }

    /// Rebuilds the force elements after the world's mesh changed.
    pub fn rebuild(&mut self, world: &World) {
        self.elements = Elements::build_clamped(
            &world.mesh,
            &self.model.material,
            &world.pins.clamped(world.mesh.vertex_count()),
        );
        self.held.resize(world.mesh.vertex_count(), false);
        self.contacts.clear();
        self.contact_push.clear();
        self.implicit.warm = false;
        self.levels = None;
    }

    /// Advances `world` by `dt` seconds with the model's integrator.
    pub fn step(&mut self, world: &mut World, dt: Scalar) {
        match self.model.integrator {
            Integrator::SymplecticEuler if self.multirate => {
                multirate::symplectic_multirate(self, world, dt)
            }
            Integrator::SymplecticEuler => explicit::symplectic_euler(self, world, dt),
            Integrator::Rk4 if self.multirate => multirate::rk4_multirate(self, world, dt),
            Integrator::Rk4 => explicit::rk4(self, world, dt),
            Integrator::Implicit => {
                let iterations = implicit::backward_euler(self, world, dt);
                self.stats.cg_iterations += iterations as u64;
                if iterations >= self.model.cg_max_iterations {
                    self.stats.cg_capped += 1;
                }
            }
        }
        world.time += dt;
        self.stats.steps += 1;
    }

    /// Energies of the world's current state.
    pub fn energy(&self, world: &World) -> Energy {
        forces::energy(&self.elements, &self.model.external, &world.x, &world.v)
    }

    /// The automatic time step for this model on the current mesh (the macro
    /// step when multirate).
    pub fn auto_dt(&self, world: &World) -> Scalar {
        if self.multirate && self.model.integrator != Integrator::Implicit {
            let drag = self.model.external.drag.unwrap_or(0.0);
            let macro_dt = multirate::Levels::build(&world.mesh, &self.elements, drag).macro_dt;
            // RK4's stability region reaches about 1.39 times further (timestep.rs).
            let reach = if self.model.integrator == Integrator::Rk4 {
                1.39
            } else {
                1.0
            };
            return reach * macro_dt;
        }
        timestep::auto_dt(
            self.model.integrator,
            &world.mesh,
            &self.elements,
            self.model.external.drag.unwrap_or(0.0),
        )
    }
}
