//! A frame: its steps through the frame's time, retried from the frame's
//! start with halved steps while a step is rejected or the frame gains
//! energy.

use super::{FrameFailed, FrameFailure, Pipeline, StepError, evened_step};
use crate::math::Scalar;
use crate::physics::Energy;
use crate::sim::{Setup, SimState, StepFailure, StepSize};

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

impl Pipeline {
    /// Advances one frame; on a rejected step (non-finite state, energy explosion,
    /// solver failure) restores the frame's start (mesh included) and retries with
    /// the step halved (up to [`MAX_STEP_HALVINGS`] times). A frame whose energy rose
    /// above its bound by more than [`ENERGY_GAIN_TOLERANCE`] energy scales is
    /// retried the same way, up to [`MAX_ENERGY_HALVINGS`] times and only while
    /// halving helps (the gain at least halves), then accepted. Returns the number
    /// of halvings spent.
    pub fn advance_frame(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        frame_interval: Scalar,
    ) -> Result<u64, FrameFailed> {
        self.advance_frame_from(setup, state, frame_interval, None)
    }

    /// [`Pipeline::advance_frame`] given the energy of `state` as it is, when
    /// the caller has measured it ([`Stepper::energy`]; the frame loop does so
    /// for its statistics): the frame then does not measure it again. The
    /// result is the same either way.
    pub fn advance_frame_from(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        frame_interval: Scalar,
        start_energy: Option<Energy>,
    ) -> Result<u64, FrameFailed> {
        self.frame_end_energy = None;
        debug_assert!(
            start_energy.is_none_or(|e| e == self.stepper.energy(&setup.model, &state.world)),
            "the start energy given is not the state's"
        );
        let start = match self.frame_start.take() {
            Some(mut saved) => {
                saved.clone_from(state);
                saved
            }
            None => state.clone(),
        };
        let result = self.retry_frame(setup, state, &start, frame_interval, start_energy);
        self.frame_start = Some(start);
        result
    }

    /// The frame's steps, retried from `start` with halved steps while a step is
    /// rejected or the frame gains energy ([`Pipeline::advance_frame`]).
    fn retry_frame(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        start: &SimState,
        frame_interval: Scalar,
        start_energy: Option<Energy>,
    ) -> Result<u64, FrameFailed> {
        let t0 = state.world.time;
        let model = &setup.model;
        // E - W at the frame start: without numerical error it can only fall.
        let energy_start = start_energy.unwrap_or_else(|| self.stepper.energy(model, &state.world));
        let balance_start = energy_start.total() - state.ledger.work();
        let mut last_gain = Scalar::INFINITY;
        // Set by every rejected attempt: the last halving always ends in one.
        let mut failure = StepFailure::NonFinite;
        for halving in 0..=MAX_STEP_HALVINGS {
            let stepped = match setup.settings.step {
                StepSize::Adaptive(control) => {
                    self.adaptive_steps_through(setup, state, frame_interval, halving, &control)
                }
                _ => self.steps_through(setup, state, frame_interval, halving),
            };
            let healthy = match stepped {
                Ok(()) => true,
                // Halving the largest adaptive step cannot help a step that
                // fails its tolerances at the smallest.
                Err(StepError::Rejected(why @ StepFailure::AboveTolerance(_))) => {
                    failure = why;
                    state.restore(start);
                    self.mesh_changed(setup, state);
                    break;
                }
                Err(StepError::Rejected(why)) => {
                    failure = why;
                    false
                }
                Err(StepError::Refused { .. }) => {
                    unreachable!("the adaptive frame loop retries refused steps itself")
                }
                Err(StepError::Remesh(e)) => return Err(FrameFailed::Remesh(e)),
            };
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
                    if !self.adapt_at_frame_end(setup, state)? {
                        self.frame_end_energy = Some(energy_end);
                    }
                    return Ok(halving as u64);
                }
                last_gain = gain;
                state.effort.energy_retries += 1;
            }
            state.restore(start);
            self.mesh_changed(setup, state);
        }
        let last_dt = match setup.settings.step {
            StepSize::Adaptive(control) => control.min,
            _ => self.step_size(setup, &state.world) / (1u64 << MAX_STEP_HALVINGS) as Scalar,
        };
        Err(FrameFailed::Steps(FrameFailure {
            last_dt,
            failure,
            step: state.ledger.steps_done + 1,
        }))
    }

    /// Steps through `frame_interval` with the current mesh's step divided by
    /// `2^halving`, the last steps evened out so the frame ends exactly on its time.
    /// Stops at the first step not accepted.
    fn steps_through(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        frame_interval: Scalar,
        halving: u32,
    ) -> Result<(), StepError> {
        let shrink = (1u64 << halving) as Scalar;
        let mut done = 0.0;
        while done < frame_interval * (1.0 - 1e-12) {
            let remaining = frame_interval - done;
            let h = evened_step(remaining, self.step_size(setup, &state.world) / shrink);
            self.step(setup, state, h)?;
            state.effort.min_dt = state.effort.min_dt.min(h);
            state.effort.max_dt = state.effort.max_dt.max(h);
            self.last_step = Some(h);
            done += h;
        }
        Ok(())
    }
}
