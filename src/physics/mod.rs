//! The physical model and the stepper.
//!
//! [`Model`] is the resolved, immutable physics of a scene; [`Stepper`] holds the
//! force elements derived from the current mesh plus all scratch memory, and
//! advances a [`World`] by one step of a model it is given with the model's
//! integrator (the caller owns the model: the stepper holds no physics and no
//! simulation state).

pub mod bending;
pub mod block;
pub mod cholesky;
pub mod elements;
pub mod explicit;
pub mod forces;
pub mod implicit;
pub mod kinds;
pub mod laplacian;
pub mod membrane;
pub mod multirate;
/// Pinned vertices (a top-level module, [`crate::pins`], so that `world` needs nothing
/// from `physics`); kept reachable here.
pub mod sewing;
pub mod shape;
pub mod timestep;
pub mod work;

pub use crate::spec::{BendingMatrix, Preconditioner, Refactor, Solver};
pub use elements::{Elements, Holding, MaterialParams};
pub use forces::{Energy, ExternalForces, WindForce};
pub use implicit::SolveFailure;
pub use kinds::{Hinge, Spring};
pub use membrane::{Membrane, MembraneTriangle, Orthotropic};
pub use sewing::SpringCap;
pub use shape::{SHAPE_SLOTS, ShapeTriangle};

use crate::math::{Scalar, Vector};
use crate::spec::Integrator;
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
    /// Linear solver and Newton settings (implicit only).
    pub solver: SolverSettings,
    /// How each of the garment's attachments pulls (in the order of the
    /// mesh's holds, [`crate::mesh::Mesh::holds`]) and when it lets go.
    pub attachments: Vec<crate::spec::Attachment>,
}

impl Model {
    /// True when an attachment's release time lies in `(from, to]`: the
    /// elements built before it hold a side that is let go at `to`.
    pub fn releases_between(&self, from: Scalar, to: Scalar) -> bool {
        self.attachments
            .iter()
            .any(|a| a.holds_at(from) && !a.holds_at(to))
    }

    /// True while an attachment holds at time `t`.
    pub fn holds_at(&self, t: Scalar) -> bool {
        self.attachments.iter().any(|a| a.holds_at(t))
    }
}

/// The model's attachments at the world's time.
fn holding<'a>(model: &'a Model, world: &World) -> Holding<'a> {
    Holding {
        attachments: &model.attachments,
        time: world.time,
    }
}

/// How the implicit integrator solves its equations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// The linear solver.
    pub solver: Solver,
    /// Direct solver: the cost of one factorization counted in conjugate-gradient
    /// iterations, weighed against the iterations an older factor costs
    /// (`implicit::refactor` module docs).
    pub refactor_iterations: u32,
    /// Direct solver: when it factors anew.
    pub refactor: Refactor,
    /// Direct solver: what it factors as its preconditioner.
    pub preconditioner: Preconditioner,
    /// Direct solver: which of the shape triangles' bending blocks its matrix
    /// holds (the others lumped on the diagonal).
    pub bending_matrix: BendingMatrix,
    /// Newton iterations per step (1: Baraff and Witkin's linearised step).
    pub newton_iterations: u32,
    /// Relative residual at which Newton iterations stop.
    pub newton_tolerance: Scalar,
    /// Iterations after which an unconverged quasi-Newton step fails.
    pub quasi_newton_iterations: u32,
}

impl Default for SolverSettings {
    /// The scene defaults: direct solver, a factorization worth 7 iterations, one
    /// Newton step.
    fn default() -> SolverSettings {
        SolverSettings {
            solver: Solver::Direct,
            refactor_iterations: 7,
            refactor: Refactor::Cost,
            preconditioner: Preconditioner::Factor,
            bending_matrix: BendingMatrix::Exact,
            newton_iterations: 1,
            newton_tolerance: 1e-3,
            quasi_newton_iterations: 200,
        }
    }
}

/// Whether `model`'s direct solver lumps the shape triangles' second-ring
/// blocks ([`BendingMatrix::FirstRing`]; the CG solver's products and the
/// explicit integrators never read the blocks).
fn lumps(model: &Model) -> bool {
    model.solver.bending_matrix == BendingMatrix::FirstRing
}

/// Counters of what the stepper did.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct StepStats {
    /// Steps taken (including steps of frames that were retried).
    pub steps: u64,
    /// Conjugate-gradient iterations over all implicit linear solves (with the direct
    /// solver: iterations preconditioned by a factorization).
    pub cg_iterations: u64,
    /// Linear solves that reached `cg_max_iterations` without converging (each one
    /// failed its step, which was retried).
    pub cg_capped: u64,
    /// Implicit steps that failed: an unconverged linear solve, a matrix that was not
    /// positive definite, or Newton iterations that did not converge.
    pub failed_solves: u64,
    /// Newton iterations (linear solves) over all implicit steps; with the
    /// quasi-Newton solver, one per step.
    pub newton_iterations: u64,
    /// L-BFGS iterations of the quasi-Newton solver over all implicit steps.
    pub quasi_newton_iterations: u64,
    /// Symbolic analyses (orderings) of the sparse system: one per mesh topology.
    pub symbolic_analyses: u64,
    /// Numerical Cholesky factorizations.
    pub factorizations: u64,
    /// Of those, the ones of the full matrix, hinge tip-tip blocks included (the
    /// direct solver switches to it where the reduced factor needs too many
    /// iterations: `physics::implicit`'s direct solver, "Which factor").
    pub full_factorizations: u64,
    /// Solves with a Cholesky factor (one per preconditioned iteration, plus one per
    /// solve to start it).
    pub factor_solves: u64,
    /// Wall time spent assembling the system matrix and right-hand side, s
    /// (a new mesh's block pattern counts in `rebuild_s`).
    pub assembly_s: f64,
    /// Wall time spent in symbolic analyses and numerical factorizations, s
    /// (a new mesh's ordering and first factorization count in `rebuild_s`).
    pub factorization_s: f64,
    /// Wall time spent in the iterations of the linear solves, s.
    pub solve_s: f64,
    /// Wall time in the remeshing passes (the criterion, the operations and the
    /// transfer of the state onto the new mesh, rollbacks' refinements
    /// included), s.
    pub remesh_s: f64,
    /// Wall time rebuilding after the mesh changed (a remesh, a rollback, a
    /// seam weld or a restored start), s: the force elements, the fold splits'
    /// factor, and with the direct solver the new block pattern, its ordering
    /// and the new mesh's first factorization.
    pub rebuild_s: f64,
}

impl StepStats {
    /// One clause for the run summary: the implicit solver's work and failures.
    pub fn describe(&self) -> String {
        if self.newton_iterations == 0 && self.failed_solves == 0 {
            return "no implicit solves".to_string();
        }
        let mut s = if self.quasi_newton_iterations > 0 {
            format!(
                "{} quasi-Newton solves, {} quasi-Newton iterations",
                self.newton_iterations, self.quasi_newton_iterations
            )
        } else {
            format!(
                "{} linear solves, {} CG iterations",
                self.newton_iterations, self.cg_iterations
            )
        };
        if self.factorizations > 0 {
            let full = match self.full_factorizations {
                0 => String::new(),
                n => format!("{n} of every block, "),
            };
            s += &format!(
                ", {} factorizations ({full}{} orderings); assembly {:.2} s, factorization {:.2} s, solves {:.2} s",
                self.factorizations,
                self.symbolic_analyses,
                self.assembly_s,
                self.factorization_s,
                self.solve_s
            );
        }
        if self.remesh_s > 0.0 || self.rebuild_s > 0.0 {
            s += &format!(
                "; remeshing {:.2} s, rebuilding after it {:.2} s",
                self.remesh_s, self.rebuild_s
            );
        }
        s + &format!(", {} failed solves", self.failed_solves)
    }
}

/// A vertex resting against an obstacle, as the collision pass left it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Contact {
    /// The obstacle's outward unit normal at the contact, or zero for no contact.
    pub normal: Vector,
    /// The obstacle surface's velocity along `normal` there, m/s.
    pub normal_speed: Scalar,
    /// True when the step's implicit solve held the vertex against this
    /// surface and the surface pushed (a compressive contact force): the next
    /// step holds it again whatever its right-hand side says, and releases it
    /// only once the surface would have to pull ([`crate::physics::implicit`],
    /// "Pins and contacts").
    pub pressed: bool,
}

/// Force elements of the current mesh plus scratch memory; no simulation state
/// and no model (every call that needs the physics is given the [`Model`]).
#[derive(Debug, Clone)]
pub struct Stepper {
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
    pub fn new(model: &Model, world: &World) -> Stepper {
        let mut elements = Elements::default();
        elements.rebuild_but_deferred(
            &world.mesh,
            &model.material,
            &world.pins.clamped(world.mesh.vertex_count()),
            holding(model, world),
        );
        let deferred = elements.deferred();
        elements.install(deferred);
        elements.kinds.shapes.lump_second_ring = lumps(model);
        Stepper {
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

    /// Rebuilds the force elements of `model` after the world's mesh changed
    /// (incrementally: [`Elements::rebuild`]).
    ///
    /// With the direct solver, the new mesh's block pattern and its ordering
    /// are made here too, on one thread while the kinds' deferred parts (the
    /// fold splits' system) are made on another (both only read the rebuilt
    /// elements, so the results do not depend on the thread count).
    pub fn rebuild(&mut self, model: &Model, world: &World) {
        let clamped = world.pins.clamped(world.mesh.vertex_count());
        (self.elements).rebuild_but_deferred(
            &world.mesh,
            &model.material,
            &clamped,
            holding(model, world),
        );
        self.elements.kinds.shapes.lump_second_ring = lumps(model);
        self.held.resize(world.mesh.vertex_count(), false);
        self.contacts.clear();
        self.contact_push.clear();
        self.implicit.mesh_changed();
        self.levels = None;
        let direct =
            model.integrator == Integrator::Implicit && model.solver.solver == Solver::Direct;
        let (elements, implicit) = (&self.elements, &mut self.implicit);
        let (deferred, ()) = rayon::join(
            || elements.deferred(),
            || {
                if direct {
                    implicit.prepare_direct(elements, model.solver.preconditioner);
                }
            },
        );
        self.elements.install(deferred);
    }

    /// Advances `world` by `dt` seconds with `model`'s integrator. `warm_start`: the
    /// implicit solver's first guess for the velocity change, one per vertex (the
    /// last step's solution, part of the simulation state; empty: start cold; of
    /// another length: a bug, asserted in debug builds); the step leaves its own
    /// solution there. Explicit integrators leave it untouched. An implicit step whose equations could not
    /// be solved returns the reason; the world is then left in an unspecified
    /// state and must be restored by the caller.
    pub fn step(
        &mut self,
        model: &Model,
        world: &mut World,
        warm_start: &mut Vec<Vector>,
        dt: Scalar,
    ) -> Result<(), SolveFailure> {
        self.stats.steps += 1;
        match model.integrator {
            Integrator::SymplecticEuler if self.multirate => {
                multirate::symplectic_multirate(self, model, world, dt)
            }
            Integrator::SymplecticEuler => explicit::symplectic_euler(self, model, world, dt),
            Integrator::Rk4 if self.multirate => multirate::rk4_multirate(self, model, world, dt),
            Integrator::Rk4 => explicit::rk4(self, model, world, dt),
            Integrator::Implicit => {
                if let Err(failure) = implicit::backward_euler(self, model, world, warm_start, dt) {
                    self.stats.failed_solves += 1;
                    if matches!(failure, SolveFailure::NotConverged { .. }) {
                        self.stats.cg_capped += 1;
                    }
                    return Err(failure);
                }
            }
        }
        world.time += dt;
        Ok(())
    }

    /// Linearises an implicit step of `dt` at the world's current state and
    /// assembles its linear system without solving it: what a step counts as
    /// assembly ([`StepStats::assembly_s`], which this adds to). With the direct
    /// solver that is the element terms, the block matrix and its projection;
    /// with conjugate gradients the element terms alone. The world is not
    /// changed. A hook for benchmarks of the assembly alone; a step does the
    /// same on its own.
    pub fn assemble_implicit(&mut self, model: &Model, world: &World, dt: Scalar) {
        implicit::assemble(self, model, world, dt);
    }

    /// Energies of the world's current state under `model`.
    pub fn energy(&self, model: &Model, world: &World) -> Energy {
        forces::energy(&self.elements, &model.external, &world.x, &world.v)
    }

    /// The automatic time step for `model` on the current mesh (the macro step
    /// when multirate).
    pub fn auto_dt(&self, model: &Model, world: &World) -> Scalar {
        if self.multirate && model.integrator != Integrator::Implicit {
            let drag = model.external.drag.unwrap_or(0.0);
            let macro_dt = multirate::Levels::build(&world.mesh, &self.elements, drag).macro_dt;
            // RK4's stability region reaches about 1.39 times further (timestep.rs).
            let reach = if model.integrator == Integrator::Rk4 {
                1.39
            } else {
                1.0
            };
            return reach * macro_dt;
        }
        timestep::auto_dt(
            model.integrator,
            &world.mesh,
            &self.elements,
            model.external.drag.unwrap_or(0.0),
        )
    }
}
