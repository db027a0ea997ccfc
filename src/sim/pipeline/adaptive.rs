//! The pipeline's adaptive stepping (`dt = "adaptive"`): a frame's steps under
//! error control ([`crate::sim::step_control`] for the estimate and the
//! controller).

use super::{Pipeline, StepError, evened_step};
use crate::math::{Scalar, deterministic_sum2};
use crate::sim::step_control::{self, AdaptiveStep, Refusal, StepMeasure, Verdict};
use crate::sim::{Setup, SimState, StepFailure};

impl Pipeline {
    /// Steps through `frame_interval` under error control, the largest step
    /// divided by `2^halving` (a retried frame). Stops at the first step that
    /// fails at the smallest size.
    pub(super) fn adaptive_steps_through(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        frame_interval: Scalar,
        halving: u32,
        control: &AdaptiveStep,
    ) -> Result<(), StepError> {
        let shrink = (1u64 << halving) as Scalar;
        let largest = (control.largest(frame_interval) / shrink).max(control.min);
        let mut done = 0.0;
        while done < frame_interval * (1.0 - 1e-12) {
            let remaining = frame_interval - done;
            let h = self.controlled_step(setup, state, remaining, largest, control)?;
            state.effort.min_dt = state.effort.min_dt.min(h);
            state.effort.max_dt = state.effort.max_dt.max(h);
            self.last_step = Some(h);
            done += h;
        }
        Ok(())
    }

    /// One accepted step within `remaining` seconds of the frame: the state's
    /// proposal, evened out to the frame's end, refused and retried smaller
    /// until the controller accepts it. Returns its size.
    fn controlled_step(
        &mut self,
        setup: &Setup,
        state: &mut SimState,
        remaining: Scalar,
        largest: Scalar,
        control: &AdaptiveStep,
    ) -> Result<Scalar, StepError> {
        let mut proposed = state.step_control.next.min(largest);
        loop {
            let h = evened_step(remaining, proposed);
            match self.judged_step(setup, state, h, Some((control, proposed, largest))) {
                Ok(_) => return Ok(h),
                Err(StepError::Refused { reason, retry }) => {
                    let refused = &mut state.effort.refused;
                    match reason {
                        Refusal::Error(_) => refused.error += 1,
                        Refusal::Penetration(_) => refused.penetration += 1,
                        Refusal::Failed => refused.failed += 1,
                    }
                    proposed = retry;
                }
                Err(e) => return Err(e),
            }
        }
    }

    /// The controller's verdict on an attempted step of `h` seconds taken on
    /// the proposal `proposed` (`attempted`: whether the attempt's phases
    /// succeeded). Accepted: the next proposal. Refused: the state is put back
    /// at the step's start and [`StepError::Refused`] says what to try; at the
    /// smallest step the failure is the frame's.
    pub(super) fn judge(
        &mut self,
        control: &AdaptiveStep,
        state: &mut SimState,
        h: Scalar,
        proposed: Scalar,
        largest: Scalar,
        attempted: Result<(), StepFailure>,
    ) -> Result<Scalar, StepError> {
        let mut error = 0.0;
        let verdict = match attempted {
            Ok(()) => {
                error = self.measure_step_error(state, h);
                let measure = StepMeasure {
                    error,
                    penetration: state.ledger.collision.last_penetration,
                };
                step_control::judge(control, proposed, h, measure, largest)
            }
            Err(failure) => match step_control::after_failure(control, h) {
                Some(retry) => Verdict::Refuse {
                    reason: Refusal::Failed,
                    retry,
                },
                None => return Err(StepError::Rejected(failure)),
            },
        };
        match verdict {
            Verdict::Accept { next } => {
                state.effort.largest_step_error = state.effort.largest_step_error.max(error);
                Ok(next)
            }
            Verdict::Refuse { reason, .. } if step_control::at_minimum(control, h) => {
                Err(StepError::Rejected(StepFailure::AboveTolerance(reason)))
            }
            Verdict::Refuse { reason, retry } => {
                self.restore_step_start(state);
                Err(StepError::Refused { reason, retry })
            }
        }
    }

    /// The step's error estimate ([`step_control`] module docs): the
    /// mass-weighted root mean square of `|x1 - x0 - h v0| / 2` over the
    /// vertices no pin held at the step's start, `x0`, `v0` the step's start
    /// and `x1` where the step (collisions included) left them.
    pub(super) fn measure_step_error(&mut self, state: &SimState, h: Scalar) -> Scalar {
        let n = state.world.x.len();
        self.held.clear();
        self.held.resize(n, false);
        let (_, _, t0) = self.step_start_motion();
        state.world.pins.held_at(t0, &mut self.held);
        let (x0, v0, _) = self.step_start_motion();
        let (held, x1) = (&self.held, &state.world.x);
        let mass = &self.stepper.elements.mass;
        debug_assert_eq!(x0.len(), n, "the step's start was not saved");
        debug_assert_eq!(mass.len(), n, "the elements are not the state's mesh's");
        let n = n.min(x0.len()).min(mass.len());
        let (weighted, free_mass) = deterministic_sum2(n, |i| {
            if held[i] {
                (0.0, 0.0)
            } else {
                let e = x1[i] - x0[i] - v0[i] * h;
                (mass[i] * e.length_squared(), mass[i])
            }
        });
        if free_mass > 0.0 {
            0.5 * (weighted / free_mass).sqrt()
        } else {
            0.0
        }
    }
}
