//! When the direct solver factors its matrix anew: a rule that weighs what a
//! factorization costs against the iterations an older factor costs.
//!
//! # The costs
//! `F`, the cost of one factorization counted in conjugate-gradient iterations, is the
//! scene's `refactor_iterations`. Measured on a 2-core machine (`drape run ...
//! --summary`, factorization time per factorization against solve time per
//! factor solve): 14.7 ms against 2.16 ms on `hanging_sheet_rest` at
//! uniform 64 (6.8 iterations), 2.7 ms against 0.37 ms on its red-green run of
//! about 1,200 vertices (7.2); the default is 7.
//!
//! A factor made in solve 0 of a cycle needs `k_0` iterations there (the reduced
//! factor is not exact, block module docs) and `k_a` in the solve `a` steps later;
//! `k_a` grows as the matrix drifts away from the factored one. A cycle of `m`
//! solves costs `(F + k_0 + ... + k_{m-1}) / m` per solve. With `k_a` growing, that
//! average is smallest where the next solve's cost would pass it, so:
//!
//! 1. **At the start of a solve** the factor is renewed when this solve's
//!    iterations with it, estimated from the last two by a straight line
//!    (`k_a ~ 2 k_{a-1} - k_{a-2}`, never below `k_{a-1}`; one solve old: `k_0`),
//!    would raise the cycle's average cost, factorization included:
//!    `k_a * a >= F + k_0 + ... + k_{a-1}`. A factor whose iterations do not grow
//!    (cloth at rest) is kept for good.
//! 2. **During a solve with an older factor** the solve gives up on it and factors
//!    when the iterations it still needs, extrapolated from the residual's fall so
//!    far, exceed a factorization plus what a fresh factor needed (`F + k_0`), or
//!    when it has already spent that many (a bound like a ski rental's: never more
//!    than twice the better choice).
//! 3. **A factor that fails one solve after it was made** (the matrix changes a lot
//!    every step: a falling, folding sheet) is not tried again at that age for the
//!    next 1, 2, 4, ... up to [`MAX_WAIT`] solves: each of them factors at its start,
//!    and a successful try resets the wait to 1.
//!
//! Everything here counts iterations and compares residual norms, never clock
//! time, so a run gives the same results on every machine and thread count.
//!
//! # Why not a fixed iteration count
//! Refactoring after a fixed number of iterations with an older factor cannot suit
//! every scene: even a fresh factor needs about 5 iterations on
//! `hanging_sheet_rest` at uniform 64, so a count of 4 refactors at almost every
//! step while the sheet hangs at rest, yet on `drape_sphere` a count of 1 is faster
//! than 4 or 8. Weighing the costs as above suits both.

use crate::math::Scalar;

/// The longest run of solves that factor at their start after failed tries of a
/// one-solve-old factor (rule 3). It bounds both ways what the wait can cost: a
/// failed try (at most `F + k_0` wasted iterations, about 10) once in 33 solves adds
/// about 3 % to a solve that factors anyway (about 10 iterations' worth), and cloth
/// that has stopped moving keeps factoring at every solve for at most 32 more.
const MAX_WAIT: u32 = 32;

/// Iterations with an older factor before the residual's fall is extrapolated
/// (rule 2): one iteration's ratio is too noisy (conjugate-gradient residuals do not
/// fall monotonically).
const EXTRAPOLATE_AFTER: u32 = 2;

/// What the rule remembers between solves; scratch, reset with the solver.
#[derive(Debug, Default, Clone, PartialEq)]
pub(super) struct RefactorPolicy {
    /// Solves since the current factor was made (0: made in the last solve).
    age: u32,
    /// Iterations the factor needed in the solve that made it (`k_0`).
    fresh_iterations: u32,
    /// Iterations of every solve since the factor was made.
    cycle_iterations: u64,
    /// Iterations of the last solve.
    last_iterations: u32,
    /// Iterations of the solve before it, when it used the same factor.
    previous_iterations: Option<u32>,
    /// Solves left that factor at their start before a one-solve-old factor is tried
    /// again (rule 3).
    wait: u32,
    /// The next wait after a failed try.
    next_wait: u32,
}

impl RefactorPolicy {
    /// Rule 1 and rule 3, at the start of a solve with a valid factor: `true` when
    /// the factor should be renewed before iterating. Advances the factor's age.
    pub(super) fn renew_at_start(&mut self, factorization_cost: Scalar) -> bool {
        self.age += 1;
        if self.wait > 0 && self.age == 1 {
            self.wait -= 1;
            return true;
        }
        let last = Scalar::from(self.last_iterations);
        let estimate = match self.previous_iterations {
            Some(before) => last + (last - Scalar::from(before)).max(0.0),
            None => last,
        };
        estimate * Scalar::from(self.age) >= factorization_cost + self.cycle_iterations as Scalar
    }

    /// Rule 2, during a solve with an older factor, after `spent` iterations that
    /// took the residual from `first` to `now` (norms) towards `goal`: `true` when
    /// the factor should be given up.
    pub(super) fn give_up(
        &self,
        factorization_cost: Scalar,
        spent: u32,
        first: Scalar,
        now: Scalar,
        goal: Scalar,
    ) -> bool {
        let budget = factorization_cost + Scalar::from(self.fresh_iterations);
        if Scalar::from(spent) >= budget {
            return true;
        }
        if spent < EXTRAPOLATE_AFTER || now <= goal {
            return false;
        }
        // Residual falls by `rate` per iteration on average so far.
        let rate = (now / first).powf(1.0 / Scalar::from(spent));
        // Not falling, or not a number (a zero first residual cannot reach here).
        if rate >= 1.0 || rate.is_nan() {
            return true;
        }
        (goal / now).ln() / rate.ln() > budget
    }

    /// A factor was just made: its cycle starts. `gave_up` tells whether an older
    /// factor was given up in this solve (rule 2), for rule 3.
    pub(super) fn factored(&mut self, gave_up: bool) {
        if gave_up && self.age == 1 {
            self.wait = self.next_wait.max(1);
            self.next_wait = (self.wait * 2).min(MAX_WAIT);
        }
        self.age = 0;
        self.cycle_iterations = 0;
        self.previous_iterations = None;
    }

    /// The solve ended after `iterations` with the current factor (counted since it
    /// was made, when that was in this solve).
    pub(super) fn solved(&mut self, iterations: u32) {
        if self.age == 0 {
            self.fresh_iterations = iterations;
        } else if self.age == 1 {
            // A one-solve-old factor served: try it again at once next time.
            self.next_wait = 1;
        }
        if self.age > 0 {
            self.previous_iterations = Some(self.last_iterations);
        }
        self.cycle_iterations += u64::from(iterations);
        self.last_iterations = iterations;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs the policy over solves whose older-factor iteration counts are given by
    /// `stale(age)`, a fresh factor needing `fresh`; returns the factorizations and
    /// the iterations spent (given-up iterations included).
    fn simulate(cost: Scalar, fresh: u32, stale: impl Fn(u32) -> u32, solves: u32) -> (u32, u32) {
        let mut p = RefactorPolicy::default();
        let (mut factorizations, mut iterations) = (1, fresh);
        p.factored(false);
        p.solved(fresh);
        for _ in 1..solves {
            if p.renew_at_start(cost) {
                factorizations += 1;
                p.factored(false);
                p.solved(fresh);
                iterations += fresh;
                continue;
            }
            let need = stale(p.age);
            if Scalar::from(need) >= cost + Scalar::from(p.fresh_iterations) {
                // The budget runs out first.
                let spent = (cost + Scalar::from(p.fresh_iterations)) as u32;
                factorizations += 1;
                iterations += spent + fresh;
                p.factored(true);
                p.solved(fresh);
            } else {
                iterations += need;
                p.solved(need);
            }
        }
        (factorizations, iterations)
    }

    #[test]
    fn a_factor_whose_iterations_do_not_grow_is_kept() {
        // Cloth at rest: a fresh factor needs 5, an older one 6 at every age.
        let (f, i) = simulate(7.0, 5, |_| 6, 600);
        println!("{f} factorizations, {i} iterations");
        assert_eq!(f, 1);
    }

    #[test]
    fn a_drifting_factor_is_renewed_where_the_average_cost_is_least() {
        // k_a = 3 + 2a: the cycle average (7 + sum) / m is least at m = 3
        // ((7+3)/1 = 10, (7+3+5)/2 = 7.5, (7+3+5+7)/3 = 7.33, (7+3+5+7+9)/4 = 7.75):
        // a factorization every third solve.
        let (f, i) = simulate(7.0, 3, |a| 3 + 2 * a, 600);
        println!("{f} factorizations, {i} iterations");
        assert_eq!(f, 200);
        // Renewing every solve would cost 600 x 10 = 6000 in all.
        assert!(Scalar::from(i) + 7.0 * Scalar::from(f) < 0.8 * 6000.0);
    }

    #[test]
    fn a_factor_that_fails_at_once_waits_longer_and_longer() {
        // A falling sheet: an older factor would need 40 at every age.
        let (f, i) = simulate(7.0, 3, |_| 40, 600);
        let per_solve = (Scalar::from(i) + 7.0 * Scalar::from(f)) / 600.0;
        println!("{f} factorizations, {i} iterations, {per_solve:.2} a solve");
        // Factoring at every solve costs 10 a solve; each failed try wastes 10 more,
        // and the tries thin out to one in 33.
        assert!(per_solve < 10.0 * 1.1, "{per_solve}");
    }

    #[test]
    fn extrapolation_gives_up_on_a_slow_fall_and_keeps_a_fast_one() {
        let p = RefactorPolicy {
            fresh_iterations: 3,
            ..RefactorPolicy::default()
        };
        // 1e-6 goal: halving per iteration needs ~20 iterations, more than 7 + 3.
        assert!(p.give_up(7.0, 2, 1.0, 0.25, 1e-6));
        // A fall by 100 per iteration needs one more.
        assert!(!p.give_up(7.0, 2, 1.0, 1e-4, 1e-6));
        // No fall at all.
        assert!(p.give_up(7.0, 2, 1.0, 1.0, 1e-6));
        // Too early to tell, and the budget spent.
        assert!(!p.give_up(7.0, 1, 1.0, 0.9, 1e-6));
        assert!(p.give_up(7.0, 10, 1.0, 1e-5, 1e-6));
    }
}
