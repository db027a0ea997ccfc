//! Adaptive time stepping (`dt = "adaptive"`): error control for the implicit
//! integrator.
//!
//! # The error estimate
//! Backward Euler's local error in position is `h^2 / 2 |x''|` to leading
//! order. The step measures it as half the distance between where the step
//! left each free vertex (collisions included) and where the vertex's start
//! velocity alone would have carried it (the forward Euler predictor
//! `x0 + h v0`), `e_i = |x1_i - x0_i - h v0_i| / 2`, and takes the
//! mass-weighted root mean square over the vertices no pin holds,
//! `e = sqrt(sum m_i e_i^2 / sum m_i)`: the error of the cloth as a whole, the
//! same on a refined mesh as on a coarse one. A resting cloth measures about
//! zero, a cloth in free fall `h^2 g / 2`, a swinging or sliding cloth its
//! accelerations, a landing cloth how far its vertices would have gone on
//! into the obstacle.
//!
//! Two choices the measurements made:
//! - Not the largest `e_i`: where the cloth lands, each vertex that stops
//!   yanks its neighbours whatever the step, and the largest `e_i` held the
//!   step of a sheet landing on a ball near 0.25 ms for a 0.5 mm tolerance.
//! - The positions after the collision passes, not the solve's: friction acts
//!   in the collision response, so the solve alone lets a cloth resting on a
//!   ball slide by `g h^2` a step, which the response then undoes, and the
//!   solve's estimate stayed near 0.3 mm a step on a sheet long at rest.
//!
//! Contact is held to its own tolerance as well: the largest depth below an
//! obstacle surface the step ends with.

//! # The controller
//! A step whose estimate exceeds `tolerance`, whose penetration exceeds
//! `penetration`, or whose solve fails is refused: the state returns to the
//! step's start and the step is tried again smaller. The next step is
//! proposed from the last estimate by the error's order,
//! `h' = h * clamp(0.9 sqrt(tolerance / e), 1/4, 2)`, between `min` and `max`:
//! a refused penetration or solve quarters it. A proposed growth below 25 %
//! keeps the step as it is (the direct solver's stored factor is that of
//! `M + h D + h^2 K`: a steady step keeps it a good preconditioner). The steps
//! of a frame are evened out so the frame ends on its time. A step refused at
//! `min` fails the frame, which is retried with the largest step halved, then
//! the run stops with the reason: no step above a tolerance is ever accepted.
//!
//! The proposal is simulation state ([`StepControl`] in
//! [`super::SimState`]): a retried frame starts from the proposal its first
//! attempt started from, and a run is the same at any thread count.

use crate::math::Scalar;

/// Default `tolerance`, m.
pub const DEFAULT_STEP_TOLERANCE: Scalar = 5e-4;
/// Default `penetration`, m.
pub const DEFAULT_STEP_PENETRATION: Scalar = 1e-3;
/// Default `min`, s.
pub const DEFAULT_MIN_STEP: Scalar = 1e-5;
/// The first step's proposal, s (the implicit integrator's automatic step,
/// [`crate::physics::timestep::IMPLICIT_MAX_DT`]).
pub const FIRST_STEP: Scalar = crate::physics::timestep::IMPLICIT_MAX_DT;

/// Safety factor on the proposed growth.
const SAFETY: Scalar = 0.9;
/// Largest growth from one step to the next.
const GROW_MAX: Scalar = 2.0;
/// Largest shrink from one step to the next (also the shrink after a refused
/// penetration or solve).
const SHRINK_MAX: Scalar = 0.25;
/// Growth below this factor keeps the step as it is.
const HOLD: Scalar = 1.25;

/// The tolerances of `dt = "adaptive"` (`[simulation.adaptive_dt]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveStep {
    /// Largest estimated local position error of a step, m.
    pub tolerance: Scalar,
    /// Largest depth below an obstacle surface a step may end with, m.
    pub penetration: Scalar,
    /// Smallest step, s.
    pub min: Scalar,
    /// Largest step, s (`None`: one frame).
    pub max: Option<Scalar>,
}

impl AdaptiveStep {
    /// The largest step in a frame of `frame_interval` seconds.
    pub fn largest(&self, frame_interval: Scalar) -> Scalar {
        self.max.map_or(frame_interval, |m| m.min(frame_interval))
    }
}

/// The controller's state: the step it proposes next, s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepControl {
    /// The next step's proposed size, s (before the frame's evening out).
    pub next: Scalar,
}

impl Default for StepControl {
    fn default() -> StepControl {
        StepControl { next: FIRST_STEP }
    }
}

/// What a step measured, for the controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepMeasure {
    /// The estimated local position error, m.
    pub error: Scalar,
    /// The largest depth below an obstacle surface after the step, m.
    pub penetration: Scalar,
}

/// The controller's answer on one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Verdict {
    /// Keep the step; propose `next` seconds for the one after.
    Accept {
        /// The next proposal, s.
        next: Scalar,
    },
    /// Undo the step and try again with `retry` seconds.
    Refuse {
        /// Why.
        reason: Refusal,
        /// The step to try instead, s.
        retry: Scalar,
    },
}

/// Why a step was refused.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Refusal {
    /// The error estimate (m) exceeded the tolerance.
    Error(Scalar),
    /// The penetration (m) exceeded its tolerance.
    Penetration(Scalar),
    /// The step failed (solve, finiteness, energy).
    Failed,
}

/// The growth factor the error's order proposes for an estimate `error`.
fn factor(error: Scalar, tolerance: Scalar) -> Scalar {
    if error <= 0.0 {
        return GROW_MAX;
    }
    (SAFETY * (tolerance / error).sqrt()).clamp(SHRINK_MAX, GROW_MAX)
}

/// The verdict on a step of `h` seconds taken on the proposal `proposed`
/// (`h` is shorter when the frame's end evened it out), whose measure is `m`;
/// `largest`: the largest step allowed.
pub fn judge(
    settings: &AdaptiveStep,
    proposed: Scalar,
    h: Scalar,
    m: StepMeasure,
    largest: Scalar,
) -> Verdict {
    if m.error > settings.tolerance {
        let retry = h * factor(m.error, settings.tolerance);
        return Verdict::Refuse {
            reason: Refusal::Error(m.error),
            retry: retry.max(settings.min),
        };
    }
    if m.penetration > settings.penetration {
        return Verdict::Refuse {
            reason: Refusal::Penetration(m.penetration),
            retry: (h * SHRINK_MAX).max(settings.min),
        };
    }
    let f = factor(m.error, settings.tolerance);
    let next = if f < 1.0 {
        h * f
    } else if f < HOLD {
        proposed
    } else {
        proposed.max(h * f)
    };
    Verdict::Accept {
        next: next.clamp(settings.min, largest),
    }
}

/// The step to try after a failed one of `h` seconds (`None`: `h` was the
/// smallest step already).
pub fn after_failure(settings: &AdaptiveStep, h: Scalar) -> Option<Scalar> {
    if at_minimum(settings, h) {
        None
    } else {
        Some((h * SHRINK_MAX).max(settings.min))
    }
}

/// True when `h` is the smallest step allowed (to rounding).
pub fn at_minimum(settings: &AdaptiveStep, h: Scalar) -> bool {
    h <= settings.min * (1.0 + 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: AdaptiveStep = AdaptiveStep {
        tolerance: 1e-3,
        penetration: 1e-3,
        min: 1e-5,
        max: None,
    };

    fn measure(error: Scalar) -> StepMeasure {
        StepMeasure {
            error,
            penetration: 0.0,
        }
    }

    #[test]
    fn a_step_above_the_tolerance_is_refused_and_retried_by_the_errors_order() {
        // e = 4 tol: sqrt(1/4) * 0.9 = 0.45.
        match judge(&S, 0.01, 0.01, measure(4e-3), 0.033) {
            Verdict::Refuse {
                reason: Refusal::Error(e),
                retry,
            } => {
                assert_eq!(e, 4e-3);
                assert!((retry - 0.0045).abs() < 1e-15, "retry {retry}");
            }
            v => panic!("{v:?}"),
        }
    }

    #[test]
    fn a_resting_step_doubles_up_to_the_largest() {
        assert_eq!(
            judge(&S, 0.01, 0.01, measure(0.0), 0.033),
            Verdict::Accept { next: 0.02 }
        );
        assert_eq!(
            judge(&S, 0.02, 0.02, measure(0.0), 0.033),
            Verdict::Accept { next: 0.033 }
        );
    }

    #[test]
    fn a_small_growth_keeps_the_step() {
        // 0.9 sqrt(1 / 0.6) = 1.16 < 1.25.
        assert_eq!(
            judge(&S, 0.01, 0.01, measure(6e-4), 0.033),
            Verdict::Accept { next: 0.01 }
        );
        // Close to the tolerance: 0.9 sqrt(1 / 0.95) = 0.92 shrinks it.
        match judge(&S, 0.01, 0.01, measure(9.5e-4), 0.033) {
            Verdict::Accept { next } => assert!(next < 0.01 && next > 0.009, "{next}"),
            v => panic!("{v:?}"),
        }
    }

    #[test]
    fn a_step_shortened_by_the_frames_end_does_not_lower_the_proposal() {
        assert_eq!(
            judge(&S, 0.01, 0.001, measure(1e-6), 0.033),
            Verdict::Accept { next: 0.01 }
        );
    }

    #[test]
    fn a_penetrating_step_is_quartered_and_the_minimum_ends_the_shrinking() {
        let m = StepMeasure {
            error: 0.0,
            penetration: 2e-3,
        };
        match judge(&S, 0.01, 0.01, m, 0.033) {
            Verdict::Refuse {
                reason: Refusal::Penetration(_),
                retry,
            } => assert_eq!(retry, 0.0025),
            v => panic!("{v:?}"),
        }
        assert_eq!(after_failure(&S, 0.01), Some(0.0025));
        assert_eq!(after_failure(&S, 2e-5), Some(1e-5));
        assert_eq!(after_failure(&S, 1e-5), None);
    }
}
