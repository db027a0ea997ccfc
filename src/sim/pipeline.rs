//! [`Pipeline`]: advances a [`SimState`] by a step or a frame; holds only scratch.

use super::bound::is_finite;
use super::{SimState, StepFailure};
use crate::collide::{Collider, StepCloth};
use crate::math::Scalar;
use crate::mesh::MeshError;
use crate::physics::{Energy, Model, StepStats, Stepper};
use crate::world::World;

mod remesh;
use remesh::StepStart;

/// How often a failing frame is retried with half the step before giving up.
pub const MAX_STEP_HALVINGS: u32 = 4;

/// A frame whose energy minus external work rose by more than this share of the
/// run's energy scale ([`super::EnergyBound`]) is retried with halved steps: large
/// steps through an impact (one vertex stopped, its neighbours still moving)
/// stretch the springs and create energy that smaller steps do not (a tablecloth at
/// 4 ms steps gained 1.48 J, at 1 ms none).
pub const ENERGY_GAIN_TOLERANCE: Scalar = 0.01;

/// The most halvings spent on an energy gain (the frame is then accepted).
pub const MAX_ENERGY_HALVINGS: u32 = 3;

/// Why a frame could not be advanced.
#[derive(Debug, thiserror::Error)]
pub enum FrameFailed {
    /// Remeshing produced an invalid mesh (a bug: please report it).
    #[error("adaptive remeshing: {0}")]
    Remesh(#[from] MeshError),
    /// Every step size tried failed; the state is back at the frame's start.
    #[error("all step sizes failed, down to {last_dt:.3e} s: {failure}")]
    Steps {
        /// The last step tried, s.
        last_dt: Scalar,
        /// What went wrong with it.
        failure: StepFailure,
        /// The step (counted from the start of the run) that failed.
        step: u64,
    },
}

/// The machinery that advances a [`SimState`]: the stepper (force model, element
/// tables, integrators and solver scratch), the collision passes, and buffers for
/// restoring a rejected step or frame. See the [module docs](super) for what it may
/// and may not hold.
pub struct Pipeline {
    stepper: Stepper,
    /// Obstacle and self-collision passes (`None`: the scene has neither).
    collider: Option<Collider>,
    /// The user's fixed step, or `None` for `dt = "auto"`.
    fixed_dt: Option<Scalar>,
    /// Cache: the automatic step for the current mesh (refinement lowers the
    /// explicit stability limit, so a remesh forgets it).
    auto_dt: Option<Scalar>,
    /// Cache: the air's power at the end of the last step, W (the start of the next).
    air_power: Option<Scalar>,
    /// Why the last rejected step failed.
    failure: StepFailure,
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
    obstacle_planes: Vec<crate::adapt::proximity::ObstaclePlane>,
    /// The size of the last accepted step (for the recording's step plot).
    last_step: Option<Scalar>,
    /// The energy of the state as the last successful frame left it, when the
    /// frame measured it (its energy check, the adaptation after it having left
    /// the mesh as it was); taken by [`Pipeline::take_frame_end_energy`].
    frame_end_energy: Option<Energy>,
}

impl Pipeline {
    /// The pipeline of a run with `model` on `world`'s mesh. `fixed_dt`: the
    /// scene's step (`None`: automatic); `multirate`: paper A's multirate stepping.
    /// The pipeline does not keep the model: every call that advances a state is
    /// given it.
    pub fn new(
        model: &Model,
        world: &World,
        collider: Option<Collider>,
        fixed_dt: Option<Scalar>,
        multirate: bool,
    ) -> Pipeline {
        let mut stepper = Stepper::new(model, world);
        stepper.multirate = multirate;
        Pipeline {
            stepper,
            collider,
            fixed_dt,
            auto_dt: None,
            air_power: None,
            failure: StepFailure::NonFinite,
            frame_start: None,
            step_start: StepStart::default(),
            angles: Vec::new(),
            last_step: None,
            angles_fresh: false,
            obstacle_planes: Vec::new(),
            frame_end_energy: None,
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

    /// Why the last rejected step failed.
    pub fn failure(&self) -> StepFailure {
        self.failure
    }

    /// Advances one frame; on a rejected step (non-finite state, energy explosion,
    /// solver failure) restores the frame's start (mesh included) and retries with
    /// the step halved (up to [`MAX_STEP_HALVINGS`] times). A frame whose energy rose
    /// above its bound by more than [`ENERGY_GAIN_TOLERANCE`] energy scales is
    /// retried the same way, up to [`MAX_ENERGY_HALVINGS`] times and only while
    /// halving helps (the gain at least halves), then accepted. Returns the number
    /// of halvings spent.
    pub fn advance_frame(
        &mut self,
        model: &Model,
        state: &mut SimState,
        frame_interval: Scalar,
    ) -> Result<u64, FrameFailed> {
        self.advance_frame_from(model, state, frame_interval, None)
    }

    /// [`Pipeline::advance_frame`] given the energy of `state` as it is, when
    /// the caller has measured it ([`Stepper::energy`]; the frame loop does so
    /// for its statistics): the frame then does not measure it again. The
    /// result is the same either way.
    pub fn advance_frame_from(
        &mut self,
        model: &Model,
        state: &mut SimState,
        frame_interval: Scalar,
        start_energy: Option<Energy>,
    ) -> Result<u64, FrameFailed> {
        self.frame_end_energy = None;
        debug_assert!(
            start_energy.is_none_or(|e| e == self.stepper.energy(model, &state.world)),
            "the start energy given is not the state's"
        );
        let start = match self.frame_start.take() {
            Some(mut saved) => {
                saved.clone_from(state);
                saved
            }
            None => state.clone(),
        };
        let result = self.retry_frame(model, state, &start, frame_interval, start_energy);
        self.frame_start = Some(start);
        result
    }

    fn retry_frame(
        &mut self,
        model: &Model,
        state: &mut SimState,
        start: &SimState,
        frame_interval: Scalar,
        start_energy: Option<Energy>,
    ) -> Result<u64, FrameFailed> {
        let t0 = state.world.time;
        // E - W at the frame start: without numerical error it can only fall.
        let energy_start = start_energy.unwrap_or_else(|| self.stepper.energy(model, &state.world));
        let balance_start = energy_start.total() - state.ledger.work();
        let mut last_gain = Scalar::INFINITY;
        for halving in 0..=MAX_STEP_HALVINGS {
            let healthy = self.steps_through(model, state, frame_interval, halving)?;
            state.world.time = t0 + frame_interval;
            if healthy {
                let energy_end = self.stepper.energy(model, &state.world);
                let balance = energy_end.total() - state.ledger.work();
                let gain = balance - balance_start;
                let retry = gain > ENERGY_GAIN_TOLERANCE * state.ledger.bound.scale
                    && halving < MAX_ENERGY_HALVINGS
                    && gain < 0.75 * last_gain;
                if !retry {
                    let excess = balance - state.ledger.bound.initial;
                    state.ledger.excess_max = state.ledger.excess_max.max(excess);
                    state.effort.step_halvings += halving as u64;
                    if !self.adapt_at_frame_end(model, state)? {
                        self.frame_end_energy = Some(energy_end);
                    }
                    return Ok(halving as u64);
                }
                last_gain = gain;
                state.effort.energy_retries += 1;
            }
            state.restore(start);
            self.mesh_changed(model, state);
        }
        let last_dt = self.step_size(model, &state.world) / (1u64 << MAX_STEP_HALVINGS) as Scalar;
        Err(FrameFailed::Steps {
            last_dt,
            failure: self.failure,
            step: state.ledger.steps_done + 1,
        })
    }

    /// Steps through `frame_interval` with the current mesh's step divided by
    /// `2^halving`, the last steps evened out so the frame ends exactly on its time.
    /// False when a step was rejected.
    fn steps_through(
        &mut self,
        model: &Model,
        state: &mut SimState,
        frame_interval: Scalar,
        halving: u32,
    ) -> Result<bool, MeshError> {
        let shrink = (1u64 << halving) as Scalar;
        let mut done = 0.0;
        while done < frame_interval * (1.0 - 1e-12) {
            let remaining = frame_interval - done;
            let h = evened_step(remaining, self.step_size(model, &state.world) / shrink);
            if !self.step(model, state, h)? {
                return Ok(false);
            }
            state.effort.min_dt = state.effort.min_dt.min(h);
            self.last_step = Some(h);
            done += h;
        }
        Ok(true)
    }

    /// The step the run takes, for display: the last accepted step (the current
    /// mesh's step evened out so that the frame ends on its time, and halved
    /// on a retried frame), or before the first step the one a frame of
    /// `frame_interval` seconds will take.
    pub fn step_taken(&mut self, model: &Model, world: &World, frame_interval: Scalar) -> Scalar {
        if let Some(h) = self.last_step {
            return h;
        }
        evened_step(frame_interval, self.step_size(model, world))
    }

    /// The step for the current mesh: the fixed one, or `model`'s automatic estimate.
    pub fn step_size(&mut self, model: &Model, world: &World) -> Scalar {
        if let Some(dt) = self.fixed_dt {
            return dt;
        }
        *self
            .auto_dt
            .get_or_insert_with(|| self.stepper.auto_dt(model, world))
    }

    /// One step of `h` seconds, in phases: forces + integrate, collide, account,
    /// health check (together [`Pipeline::attempt`]), rollback (paper A: redo the
    /// step on a refined mesh when it bent past the upper threshold), adapt.
    /// Returns false when the step was rejected ([`Pipeline::failure`] says why);
    /// the state is then not restored (the frame retry does that). With
    /// `adapt.every = "frame"` the adaptation pass is not part of the step: it
    /// runs in [`Pipeline::advance_frame`], once the frame's steps are accepted.
    pub fn step(
        &mut self,
        model: &Model,
        state: &mut SimState,
        h: Scalar,
    ) -> Result<bool, MeshError> {
        debug_assert_eq!(
            self.stepper.elements.mass.len(),
            state.world.x.len(),
            "the pipeline's elements are not those of the state's mesh: call mesh_changed"
        );
        let rollback = state.adapter.as_ref().is_some_and(|a| a.config.rollback);
        let mut tries = 0;
        loop {
            self.angles_fresh = false;
            if rollback {
                self.remember_step_start(state);
            }
            if let Err(why) = self.attempt(model, state, h) {
                self.failure = why;
                return Ok(false);
            }
            if rollback && self.rollback(model, state, &mut tries)? {
                continue;
            }
            break;
        }
        state.ledger.steps_done += 1;
        self.adapt(model, state)?;
        Ok(true)
    }

    /// The phases of one attempt at a step: forces + integrate, collide, account,
    /// health check. The contacts the last step ended in go to the implicit solve
    /// (filtered there, see [`crate::physics::implicit`]).
    fn attempt(
        &mut self,
        model: &Model,
        state: &mut SimState,
        h: Scalar,
    ) -> Result<(), StepFailure> {
        let air0 = match self.air_power.take() {
            Some(p) => p,
            None => self.stepper.air_power(model, &state.world),
        };
        let pinned = self.stepper.pinned_start(model, &state.world);
        self.integrate(model, state, h)?;
        self.collide(model, state, h)?;
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
        model: &Model,
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
            .check(&state.world, &self.stepper, model, work)?;
        let cloth = StepCloth {
            pushed: &self.stepper.contact_push,
            mass: &self.stepper.elements.mass,
        };
        let (world, contacts) = (&mut state.world, &mut state.contacts);
        c.end_step(world, h, cloth, contacts, &mut state.ledger.collision);
        Ok(())
    }

    /// Makes the pipeline that of `state`'s mesh under `model`: rebuilds the element
    /// tables and forgets every cache (step size, air power, stored factorization).
    /// The state is not touched, so a state saved from another pipeline continues
    /// exactly as it would have there (its contacts and warm start are its own).
    /// Call it before stepping a state this pipeline was not built for.
    pub fn attach(&mut self, model: &Model, state: &SimState) {
        self.stepper.rebuild(model, &state.world);
        self.auto_dt = None;
        self.air_power = None;
        self.angles_fresh = false;
    }

    /// After the state's mesh changed (remeshing, or a restored start): rebuilds
    /// `model`'s force elements and forgets the step size, the air power, and the
    /// state's (now stale) contacts and warm start. The pipeline calls it after its
    /// own remeshing and restores; call it after changing a state's mesh outside the
    /// pipeline (for a state saved elsewhere, whose contacts and warm start still
    /// fit its mesh, [`Pipeline::attach`] keeps them).
    pub fn mesh_changed(&mut self, model: &Model, state: &mut SimState) {
        self.attach(model, state);
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
        symbolic_analyses,
        factorizations,
        full_factorizations,
        factor_solves,
        assembly_s,
        factorization_s,
        solve_s,
    } = std::mem::take(step);
    total.steps += steps;
    total.cg_iterations += cg_iterations;
    total.cg_capped += cg_capped;
    total.failed_solves += failed_solves;
    total.newton_iterations += newton_iterations;
    total.symbolic_analyses += symbolic_analyses;
    total.factorizations += factorizations;
    total.full_factorizations += full_factorizations;
    total.factor_solves += factor_solves;
    total.assembly_s += assembly_s;
    total.factorization_s += factorization_s;
    total.solve_s += solve_s;
}

/// The step at most `target` long (to a relative 1e-12) that divides `span`
/// into whole steps: the steps of a frame end exactly on its time.
fn evened_step(span: Scalar, target: Scalar) -> Scalar {
    span / (span / target * (1.0 - 1e-12)).ceil().max(1.0)
}
