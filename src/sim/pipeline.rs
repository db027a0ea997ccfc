//! [`Pipeline`]: advances a [`SimState`] by a step or a frame; holds only scratch.

use super::bound::is_finite;
use super::step_control::{self, AdaptiveStep, Refusal};
use super::{Setup, SimState, StepFailure, StepSize};
use crate::collide::{Collider, StepCloth};
use crate::math::Scalar;
use crate::mesh::MeshError;
use crate::physics::{Energy, Model, StepStats, Stepper};
use crate::world::World;

mod adaptive;
mod frame;
mod remesh;
mod sew;

pub use frame::{ENERGY_GAIN_TOLERANCE, MAX_ENERGY_HALVINGS, MAX_STEP_HALVINGS};
use remesh::StepStart;
pub use sew::WeldEvent;

/// What an accepted step did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepOutcome {
    /// Times the step was undone and redone on a refined mesh (paper A's
    /// rollback).
    pub rollbacks: u32,
    /// True when the adaptation pass or a weld after the step changed the mesh.
    pub remeshed: bool,
}

/// Why a step was not accepted.
#[derive(Debug, thiserror::Error)]
pub enum StepError {
    /// The step was rejected (the frame retries it with a smaller step); the
    /// state is left as the failed attempt made it.
    #[error("{0}")]
    Rejected(StepFailure),
    /// The adaptive step's controller refused the step (`dt = "adaptive"`);
    /// the state is back at the step's start.
    #[error("the step was refused: {reason:?}; retry with {retry:.3e} s")]
    Refused {
        /// Why.
        reason: Refusal,
        /// The step to try instead, s.
        retry: Scalar,
    },
    /// Remeshing produced an invalid mesh (a bug: please report it).
    #[error("adaptive remeshing: {0}")]
    Remesh(#[from] MeshError),
}

impl From<StepFailure> for StepError {
    fn from(why: StepFailure) -> StepError {
        StepError::Rejected(why)
    }
}

/// Every step size tried for a frame failed; the state is back at the
/// frame's start.
#[derive(Debug, Clone, Copy, thiserror::Error)]
#[error("all step sizes failed, down to {last_dt:.3e} s: {failure}")]
pub struct FrameFailure {
    /// The last step tried, s.
    pub last_dt: Scalar,
    /// What went wrong with it.
    pub failure: StepFailure,
    /// The step (counted from the start of the run) that failed.
    pub step: u64,
}

/// Why a frame could not be advanced.
#[derive(Debug, thiserror::Error)]
pub enum FrameFailed {
    /// Remeshing produced an invalid mesh (a bug: please report it).
    #[error("adaptive remeshing: {0}")]
    Remesh(#[from] MeshError),
    /// Every step size tried failed; the state is back at the frame's start.
    #[error("{0}")]
    Steps(#[from] FrameFailure),
}

/// The machinery that advances a [`SimState`]: the stepper (force model, element
/// tables, integrators and solver scratch), the collision passes, and buffers for
/// restoring a rejected step or frame. See the [module docs](super) for what it may
/// and may not hold.
pub struct Pipeline {
    stepper: Stepper,
    /// Obstacle and self-collision passes (`None`: the scene has neither).
    collider: Option<Collider>,
    /// Cache: the automatic step for the current mesh (refinement lowers the
    /// explicit stability limit, so a remesh forgets it).
    auto_dt: Option<Scalar>,
    /// Cache: the air's power at the end of the last step, W (the start of the next).
    air_power: Option<Scalar>,
    /// The frame's start, kept for a retry (buffers reused frame to frame).
    frame_start: Option<SimState>,
    /// The step's start, kept for paper A's rollback.
    step_start: StepStart,
    /// The edge angles of the state as the rollback check last measured it
    /// (buffer reused step to step).
    angles: Vec<Scalar>,
    /// True while `angles` are those of the state's current positions and mesh
    /// (the adaptation pass after an accepted step then reuses them).
    angles_fresh: bool,
    /// Per vertex, the tangent plane of the nearest obstacle point, measured for
    /// the adaptation pass's obstacle term (buffer reused pass to pass).
    obstacle_planes: Vec<crate::collide::ObstaclePlane>,
    /// The size of the last accepted step (for the recording's step plot).
    last_step: Option<Scalar>,
    /// The energy of the state as the last successful frame left it, when the
    /// frame measured it (its energy check, the adaptation after it having left
    /// the mesh as it was); taken by [`Pipeline::take_frame_end_energy`].
    frame_end_energy: Option<Energy>,
    /// Per vertex, held by a pin at the step's start (buffer for the error
    /// estimate).
    held: Vec<bool>,
}

impl Pipeline {
    /// The pipeline of a run with `setup` on `world`'s mesh. The pipeline does
    /// not keep the setup: every call that advances a state is given it.
    pub fn new(setup: &Setup, world: &World) -> Pipeline {
        let settings = &setup.settings;
        let mut stepper = Stepper::new(&setup.model, world);
        stepper.multirate = settings.multirate;
        Pipeline {
            stepper,
            collider: Collider::new(&setup.obstacles, settings.self_collision.as_ref()),
            auto_dt: None,
            air_power: None,
            frame_start: None,
            step_start: StepStart::default(),
            angles: Vec::new(),
            last_step: None,
            angles_fresh: false,
            obstacle_planes: Vec::new(),
            frame_end_energy: None,
            held: Vec::new(),
        }
    }

    /// The energy of the state as the last successful [`Pipeline::advance_frame`]
    /// left it, when that frame measured it: its energy check measures the state
    /// at the frame's end, which is the state it returns unless the adaptation
    /// after the check changed the mesh (then `None`, as before any frame and
    /// after a failed one). Taking it clears it, so it is never read for a later
    /// state. Equal to the bit to [`Stepper::energy`] on that state: the frame
    /// loop reads it instead of measuring the same state again (measuring the
    /// energy costs about as much as a force evaluation).
    pub fn take_frame_end_energy(&mut self) -> Option<Energy> {
        self.frame_end_energy.take()
    }

    /// The stepper: force model, element tables (masses), energies.
    pub fn stepper(&self) -> &Stepper {
        &self.stepper
    }

    /// The collision passes (`None`: the scene has neither obstacles nor self-collision).
    pub fn collider(&self) -> Option<&Collider> {
        self.collider.as_ref()
    }

    /// The step the run takes, for display: the last accepted step (the current
    /// mesh's step evened out so that the frame ends on its time, and halved
    /// on a retried frame), or before the first step the one a frame of
    /// `frame_interval` seconds will take.
    pub fn step_taken(&mut self, setup: &Setup, world: &World, frame_interval: Scalar) -> Scalar {
        if let Some(h) = self.last_step {
            return h;
        }
        evened_step(frame_interval, self.step_size(setup, world))
    }

    /// The step for the current mesh: the fixed one, or the stepper's automatic
    /// estimate for `setup`'s model.
    pub fn step_size(&mut self, setup: &Setup, world: &World) -> Scalar {
        match setup.settings.step {
            StepSize::Fixed(dt) => dt,
            StepSize::Adaptive(_) => step_control::FIRST_STEP,
            StepSize::Auto => *self
                .auto_dt
                .get_or_insert_with(|| self.stepper.auto_dt(&setup.model, world)),
        }
    }

    /// One step of `h` seconds, in phases: forces + integrate, collide, account,
    /// health check (together [`Pipeline::attempt`]), rollback (paper A: redo the
    /// step on a refined mesh when it bent past the upper threshold), adapt.
    /// A rejected step ([`StepError::Rejected`], with why) leaves the state as
    /// the failed attempt made it (the frame retry restores it). With
    /// `adapt.every = "frame"` the adaptation pass is not part of the step: it
    /// runs in [`Pipeline::advance_frame`], once the frame's steps are accepted.
    pub fn step(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        h: Scalar,
    ) -> Result<StepOutcome, StepError> {
        self.judged_step(setup, state, h, None)
    }

    /// [`Pipeline::step`], judged by the adaptive step's controller when
    /// `control` is given (`(settings, proposed step, largest step)`): a step it
    /// refuses returns [`StepError::Refused`] with the state back at the step's
    /// start; an accepted one sets the state's next proposal.
    fn judged_step(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        h: Scalar,
        control: Option<(&AdaptiveStep, Scalar, Scalar)>,
    ) -> Result<StepOutcome, StepError> {
        debug_assert_eq!(
            self.stepper.elements.mass.len(),
            state.world.x.len(),
            "the pipeline's elements are not those of the state's mesh: call mesh_changed"
        );
        let rollback = setup.settings.adapt.as_ref().is_some_and(|a| a.rollback);
        let start = state.world.time;
        let mut rollbacks = 0;
        let mut next = None;
        loop {
            self.angles_fresh = false;
            if rollback || control.is_some() {
                self.remember_step_start(state);
            }
            let attempted = self.attempt(setup, state, h);
            if let Some((settings, proposed, largest)) = control {
                next = Some(self.judge(settings, state, h, proposed, largest, attempted)?);
            } else {
                attempted?;
            }
            if rollback && self.rollback(setup, state, &mut rollbacks)? {
                continue;
            }
            break;
        }
        if let Some(next) = next {
            state.step_control.next = next;
        }
        state.ledger.steps_done += 1;
        let remeshed = self.adapt(setup, state)?;
        let remeshed = self.weld_closed_seams(setup, state)? || remeshed;
        let remeshed = self.release_attachments(setup, state, start) || remeshed;
        Ok(StepOutcome {
            rollbacks,
            remeshed,
        })
    }

    /// The phases of one attempt at a step: forces + integrate, collide, account,
    /// health check. The contacts the last step ended in go to the implicit solve
    /// (filtered there, see [`crate::physics::implicit`]).
    fn attempt(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        h: Scalar,
    ) -> Result<(), StepFailure> {
        let model = &setup.model;
        let air0 = match self.air_power.take() {
            Some(p) => p,
            None => self.stepper.air_power(model, &state.world),
        };
        let pinned = self.stepper.pinned_start(model, &state.world);
        self.integrate(model, state, h)?;
        self.collide(setup, state, h)?;
        // Account: the work of the air (trapezoid over the step) and of moving pins.
        let air1 = self.stepper.air_power(model, &state.world);
        self.air_power = Some(air1);
        state.ledger.external_work +=
            0.5 * h * (air0 + air1) + self.stepper.pin_work(&pinned, &state.world, h);
        // Health check.
        state
            .ledger
            .bound
            .check(&state.world, &self.stepper, model, state.ledger.work())
    }

    /// Forces + integrate: the stepper's step from the state's positions, velocities,
    /// resting contacts and warm start; its counters go to the state's
    /// [`super::Effort`].
    fn integrate(
        &mut self,
        model: &Model,
        state: &mut SimState,
        h: Scalar,
    ) -> Result<(), StepFailure> {
        if let Some(c) = self.collider.as_mut() {
            c.begin_step(&state.world);
            // Resting contacts from the last step: the vertices are on the surface now.
            self.stepper.contacts.clear();
            self.stepper.contacts.extend_from_slice(&state.contacts);
        }
        let solved = self
            .stepper
            .step(model, &mut state.world, &mut state.warm_start, h);
        absorb(&mut state.effort.solver, &mut self.stepper.stats);
        solved.map_err(StepFailure::Solver)?;
        if !is_finite(&state.world.x) {
            return Err(StepFailure::NonFinite);
        }
        Ok(())
    }

    /// Collide: obstacles, then self-collision; the contacts found become the
    /// state's resting contacts.
    fn collide(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        h: Scalar,
    ) -> Result<(), StepFailure> {
        let Some(c) = self.collider.as_mut() else {
            return Ok(());
        };
        // An exploding state (finite but huge) must not reach the geometry code.
        let work = state.ledger.work();
        state
            .ledger
            .bound
            .check(&state.world, &self.stepper, &setup.model, work)?;
        let cloth = StepCloth {
            pushed: &self.stepper.contact_push,
            mass: &self.stepper.elements.mass,
        };
        let (world, contacts) = (&mut state.world, &mut state.contacts);
        let stats = &mut state.ledger.collision;
        c.end_step(&setup.obstacles, world, h, cloth, contacts, stats);
        Ok(())
    }

    /// Makes the pipeline that of `state`'s mesh under `setup`: rebuilds the element
    /// tables and forgets every cache (step size, air power, stored factorization).
    /// The state is not touched, so a state saved from another pipeline continues
    /// exactly as it would have there (its contacts and warm start are its own).
    /// Call it before stepping a state this pipeline was not built for.
    pub fn attach(&mut self, setup: &Setup, state: &SimState) {
        self.stepper.rebuild(&setup.model, &state.world);
        self.auto_dt = None;
        self.air_power = None;
        self.angles_fresh = false;
    }

    /// After the state's mesh changed (remeshing, or a restored start): rebuilds
    /// `setup`'s force elements and, with `dt = "auto"`, the new mesh's step
    /// (timed together as the state's `rebuild_s`), and forgets the air power
    /// and the state's (now stale) contacts and warm start. The pipeline calls
    /// it after its own remeshing and restores; call it after changing a
    /// state's mesh outside the pipeline (for a state saved elsewhere, whose
    /// contacts and warm start still fit its mesh, [`Pipeline::attach`] keeps
    /// them).
    pub fn mesh_changed(&mut self, setup: &Setup, state: &mut SimState) {
        let started = std::time::Instant::now();
        self.attach(setup, state);
        if setup.settings.step == StepSize::Auto {
            // The step depends on the mesh and its elements alone: the value
            // the next step would compute, computed here to count as rebuilding.
            self.step_size(setup, &state.world);
        }
        state.effort.solver.rebuild_s += started.elapsed().as_secs_f64();
        state.contacts.clear();
        state.warm_start.clear();
    }
}

/// Adds a step's solver counters to the run's and clears them.
fn absorb(total: &mut StepStats, step: &mut StepStats) {
    let StepStats {
        steps,
        cg_iterations,
        cg_capped,
        failed_solves,
        newton_iterations,
        quasi_newton_iterations,
        symbolic_analyses,
        factorizations,
        full_factorizations,
        factor_solves,
        assembly_s,
        factorization_s,
        solve_s,
        remesh_s,
        rebuild_s,
    } = std::mem::take(step);
    total.steps += steps;
    total.cg_iterations += cg_iterations;
    total.cg_capped += cg_capped;
    total.failed_solves += failed_solves;
    total.newton_iterations += newton_iterations;
    total.quasi_newton_iterations += quasi_newton_iterations;
    total.symbolic_analyses += symbolic_analyses;
    total.factorizations += factorizations;
    total.full_factorizations += full_factorizations;
    total.factor_solves += factor_solves;
    total.assembly_s += assembly_s;
    total.factorization_s += factorization_s;
    total.solve_s += solve_s;
    total.remesh_s += remesh_s;
    total.rebuild_s += rebuild_s;
}

/// The step at most `target` long (to a relative 1e-12) that divides `span`
/// into whole steps: the steps of a frame end exactly on its time.
fn evened_step(span: Scalar, target: Scalar) -> Scalar {
    span / (span / target * (1.0 - 1e-12)).ceil().max(1.0)
}
