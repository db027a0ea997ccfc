//! The direct solver (`solver = "direct"`): `A` assembled into a fixed block pattern
//! ([`crate::physics::block`]), its projection factored by a sparse Cholesky
//! ([`crate::physics::cholesky`]), and conjugate gradients preconditioned by that
//! factor.
//!
//! Every step solves `A_s y = b_s` for the free part `y` of `dv = dv_c + y`, where
//! `dv_c` holds the prescribed parts (pinned vertices' velocity change, contacts'
//! normal velocity change), `A_s = S A S + (I - S) m` and `b_s = S (b - A dv_c)`
//! (`S`: identity for a free vertex, zero for a held one, `I - n n^T` for a contact).
//! `A_s` is symmetric positive definite on all of space and its solution has no
//! prescribed component, so any factor of a nearby `A_s` is a good preconditioner.
//!
//! The factor is reused from step to step. The first preconditioned iterate is the
//! solve with it; a fresh factor (this step's matrix) leaves only the dropped tip
//! blocks to correct, in a few iterations. With an older factor, conjugate
//! gradients correct the difference too; when the iterations it costs outweigh a
//! factorization ([`super::refactor`] module docs: the rule weighs the two in
//! iterations, at the start of a step and during it), the current matrix is factored
//! and the iteration restarts from where it is. So the cost per step adapts to how
//! fast the matrix changes: falling, folding cloth refactors often, cloth at rest
//! almost never.
//!
//! For example, on a falling, draping sheet
//! (`drape_sphere`, 2 s) the matrix changes enough in one step that the solver
//! factors at 206 of 247 steps, with 2.8 iterations a step; `hanging_sheet_rest` at
//! uniform 64 (coming to rest) needs 162 factorizations in 600 steps; the cantilever
//! strip 196 in 840.
//!
//! # Which factor
//! The reduced factor (block module docs, "The factored matrix") is cheap to make
//! and to apply but leaves the tip blocks to the iterations; the full one is
//! exact but larger. Counted in iterations with the reduced factor, a fresh reduced
//! factor costs `F + k` (`F` the scene's `refactor_iterations`, `k` the iterations
//! it needs) and a fresh full one about `F rho + rho` (one iteration), with `rho`
//! the ratio of the two factors' stored values, taking a factorization and a
//! solve to cost in proportion to the factor's size. The full factor pays once
//! `k > F (rho - 1) + rho`, the break-even. When a fresh reduced factor has
//! needed [`TIPS_CONSIDER`] iterations, the solver analyses the full pattern for
//! `rho` (once per topology: one more ordering in the summary) and, if `k` has
//! reached the break-even, factors every block from then on, for the rest of the
//! run. Sizes and counts, never clock time, so the choice is the same on every
//! machine and thread count.
//!
//! On `hanging_sheet_rest` at uniform 128, `rho = 3.97` puts the break-even at
//! 24.8 iterations, and timing each factor puts it at about 28.5: the stored
//! values are a fair proxy (`docs/model.md`, "The linear solver"). A fixed
//! iteration threshold would not do: fine fabrics need 9 to 14 iterations with a
//! fresh reduced factor and would switch to a full factor four times its size.
//! The factorization's flop count is no better a proxy than the stored values:
//! it overstates the full factor's cost (dense kernels run faster on its larger
//! supernodes), by as much as the stored values understate it.
//!
//! # Which preconditioner
//! The scene's `preconditioner` chooses what is factored: the block factor
//! above in double precision (the default) or single precision
//! ([`crate::physics::cholesky`], "Single precision"), or one scalar factor of
//! a weighted graph Laplacian ([`crate::physics::laplacian`]), which is never
//! switched to a full form. The conjugate gradients and the rule for when to
//! factor anew are the same for all three (`docs/model.md`, "Which
//! preconditioner, measured").

use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;

mod assembly;
mod factors;

pub(super) use assembly::{assemble, gather};
use factors::{precision, refactor, switch_to_full_factor};

use super::SolveFailure;
use super::cg::dot;
use super::refactor::RefactorPolicy;
use crate::math::{Matrix3, Scalar, Vector};
use crate::physics::block::BlockPattern;
use crate::physics::cholesky::Factorization;
use crate::physics::elements::Elements;
use crate::physics::forces::PAR_MIN;
use crate::physics::laplacian::LaplacianFactor;
use crate::physics::{Model, Preconditioner, Refactor, StepStats, Stepper};

/// Iterations with a fresh factor of the reduced matrix (block module docs) at
/// which the solver first asks whether factoring the tip-tip blocks too would be
/// cheaper (module docs, "Which factor"). Below it the reduced factor is kept
/// without asking: a fresh one needs about 3 iterations on fabrics at
/// `drape_sphere`'s resolution, 9 to 14 on `hanging_sheet_rest` at uniform
/// 128's edges, and 27 to 200 on a bending-dominated strip (resolutions 14 to
/// 112).
const TIPS_CONSIDER: u32 = 10;

/// The direct solver's scratch: pattern, matrices, factor and iteration vectors.
#[derive(Debug, Default, Clone)]
pub(super) struct DirectScratch {
    /// Block pattern of the current mesh (`None`: not built yet).
    pattern: Option<Arc<BlockPattern>>,
    /// True from a change of mesh until the new mesh's first factorization:
    /// its pattern, ordering and first factor are counted as rebuilding
    /// ([`StepStats::rebuild_s`]).
    new_mesh: bool,
    /// True when the block factor's ordering was made ahead of the new mesh's
    /// first factorization ([`DirectScratch::prepare`]), which counts it.
    analysis_uncounted: bool,
    /// Wall time of building the pattern after a change of mesh, s, not yet
    /// moved from the linearisation's assembly time to the rebuild's
    /// ([`DirectScratch::take_pattern_time`]).
    pattern_s: f64,
    /// Factor the hinge tip-tip blocks too (block module docs): set for the rest of
    /// the run once a fresh factor without them needed more iterations than
    /// `tips_break_even` (module docs, "Which factor").
    factor_tips: bool,
    /// For the current pattern: the iterations with a fresh reduced factor past
    /// which the full factor is the cheaper one (module docs, "Which factor");
    /// `None` until a solve has asked.
    tips_break_even: Option<Scalar>,
    /// The lower blocks of `A` (the upper ones are their mirrors' transposes).
    lower: Vec<Matrix3>,
    /// Per vertex: the compensation of the dropped in-place blocks on its
    /// diagonal block ([`BlockPattern::gather`]).
    lumps: Vec<Matrix3>,
    /// `A_s`, the projected matrix.
    system: Vec<Matrix3>,
    /// Per vertex: the diagonal compensation added to the factored matrix.
    compensation: Vec<Matrix3>,
    /// Per vertex: `None` free, `Some(0)` held, `Some(n)` contact normal.
    projection: Vec<Option<Vector>>,
    /// Per row: whether it holds a block of a projected vertex
    /// ([`BlockPattern::touched_rows`]).
    touched: Vec<bool>,
    factorization: Factorization,
    /// What is factored: the block factor `factorization` (in its precision) or
    /// the scalar `laplacian`.
    preconditioner: Preconditioner,
    laplacian: LaplacianFactor,
    /// When to factor anew (its module docs).
    policy: RefactorPolicy,
    prescribed: Vec<Vector>,
    /// `b_s`.
    rhs: Vec<Vector>,
    y: Vec<Vector>,
    r: Vec<Vector>,
    z: Vec<Vector>,
    p: Vec<Vector>,
    ap: Vec<Vector>,
}

impl DirectScratch {
    /// Forgets the pattern and the factorization (the mesh changed).
    pub(super) fn mesh_changed(&mut self) {
        self.pattern = None;
        self.new_mesh = true;
        self.analysis_uncounted = false;
        self.tips_break_even = None;
        self.factorization.reset();
        self.laplacian.reset();
    }

    /// After a change of mesh ([`DirectScratch::mesh_changed`]): builds the new
    /// mesh's block pattern from its `elements` and, for a block factor, its
    /// ordering, ahead of the first solve (so that the rebuild can run them
    /// beside the fold splits' factorization). The first factorization counts
    /// the ordering as a symbolic analysis, as if it had made it.
    pub(super) fn prepare(&mut self, elements: &Elements, preconditioner: Preconditioner) {
        self.choose(preconditioner);
        let n = elements.mass.len();
        let pattern = Arc::new(BlockPattern::build(n, elements, self.factor_tips));
        // A failed analysis is left to the first factorization, which reports it.
        self.analysis_uncounted = preconditioner != Preconditioner::Laplacian
            && self.factorization.analyse(&pattern).is_ok();
        self.pattern = Some(pattern);
    }

    /// The wall time spent building a new mesh's pattern since the last call, s.
    pub(super) fn take_pattern_time(&mut self) -> f64 {
        std::mem::take(&mut self.pattern_s)
    }

    /// The projected matrix `A_s` of the last assembly ([`assemble`]), in the
    /// pattern's lower blocks.
    pub(super) fn system(&self) -> &[Matrix3] {
        &self.system
    }

    /// Makes `preconditioner` the one factored from now on (a change forgets
    /// the factor).
    fn choose(&mut self, preconditioner: Preconditioner) {
        if preconditioner == self.preconditioner
            && self.factorization.precision() == precision(preconditioner)
        {
            return;
        }
        self.preconditioner = preconditioner;
        self.factorization = Factorization::with_precision(precision(preconditioner));
        self.laplacian.reset();
    }

    /// True when the chosen preconditioner holds a factor.
    fn factor_valid(&self) -> bool {
        match self.preconditioner {
            Preconditioner::Laplacian => self.laplacian.is_valid(),
            _ => self.factorization.is_valid(),
        }
    }

    /// `z = P^-1 r` with the chosen preconditioner's factor.
    fn precondition(&mut self) {
        self.z.resize(self.r.len(), Vector::ZERO);
        match self.preconditioner {
            Preconditioner::Laplacian => self.laplacian.solve(&self.r, &mut self.z),
            _ => self.factorization.solve(&self.r, &mut self.z),
        }
    }
}

/// Solves `A dv = b` (module docs) in place of the first guess `dv`, whose
/// prescribed parts are kept; `reference`: the norm the tolerance is relative to.
pub(super) fn solve(
    st: &mut Stepper,
    model: &Model,
    held: &[bool],
    reference: Scalar,
    contact_push: bool,
) -> Result<(), SolveFailure> {
    let pattern = assemble(st, held);
    let outcome = iterate(st, model, &pattern, reference);
    let s = &mut st.implicit;
    let a = &mut s.direct;
    // dv = dv_c + y.
    s.dv.par_iter_mut()
        .zip(a.prescribed.par_iter().zip(a.y.par_iter()))
        .with_min_len(PAR_MIN)
        .for_each(|(d, (c, y))| *d = *c + *y);
    if outcome.is_ok() && contact_push {
        contact_pressure(st, &pattern);
    }
    outcome
}

/// Preconditioned conjugate gradients on `A_s y = b_s`,
/// refactoring when the factor is stale (module docs).
fn iterate(
    st: &mut Stepper,
    model: &Model,
    pattern: &BlockPattern,
    reference: Scalar,
) -> Result<(), SolveFailure> {
    let tolerance = model.cg_tolerance;
    let goal = tolerance * reference;
    let factorization_cost = Scalar::from(model.solver.refactor_iterations);
    let cap = model.cg_max_iterations;
    let rule = model.solver.refactor;
    let a = &mut st.implicit.direct;
    a.choose(model.solver.preconditioner);
    let mass = &st.elements.mass;
    let mut fresh = !a.factor_valid() || renew_at_start(a, rule, factorization_cost);
    if fresh {
        refactor(a, pattern, mass, &mut st.stats)?;
        a.policy.factored(false);
    }
    let mut started = Instant::now();
    residual(a, pattern);
    let mut total = 0u32;
    let mut since_factor = 0u32;
    let outcome = 'restart: loop {
        let (mut rz, mut rr) = pcg_start(a, &mut st.stats);
        let restart_norm = rr.sqrt();
        loop {
            let norm = rr.sqrt();
            if norm <= goal {
                break 'restart Ok(());
            }
            // A `per_mesh` factor that reaches the cap is renewed instead (`give_up`).
            if since_factor >= cap && (fresh || rule != Refactor::PerMesh) {
                let failure = SolveFailure::not_converged(total, norm, reference, tolerance);
                break 'restart Err(failure);
            }
            if fresh && since_factor >= TIPS_CONSIDER {
                let (el, stats) = (&st.elements, &mut st.stats);
                let cost = (factorization_cost, since_factor);
                if tips_switched(a, pattern, el, cost, stats, &mut started)? {
                    since_factor = 0;
                    continue 'restart;
                }
            }
            if !fresh
                && give_up(
                    a,
                    rule,
                    factorization_cost,
                    since_factor,
                    cap,
                    (restart_norm, norm, goal),
                )
            {
                renew(a, pattern, mass, &mut st.stats, &mut started)?;
                fresh = true;
                since_factor = 0;
                continue 'restart;
            }
            let Some(next) = pcg_step(a, pattern, rz) else {
                break 'restart Err(SolveFailure::NotPositiveDefinite);
            };
            (rz, rr) = next;
            st.stats.factor_solves += 1;
            total += 1;
            since_factor += 1;
        }
    };
    st.stats.cg_iterations += total as u64;
    if outcome.is_ok() {
        st.implicit.direct.policy.solved(since_factor);
    }
    st.stats.solve_s += started.elapsed().as_secs_f64();
    outcome
}

/// With a fresh factor that leaves out the tips, after `cost.1` iterations
/// (the factorization costing `cost.0` of them): whether it switched to the
/// full factor ([`switch_to_full_factor`]), after which the solve restarts.
/// `started` times the solve, paused while it decides.
fn tips_switched(
    a: &mut DirectScratch,
    pattern: &BlockPattern,
    elements: &Elements,
    (factorization_cost, since_factor): (Scalar, u32),
    stats: &mut StepStats,
    started: &mut Instant,
) -> Result<bool, SolveFailure> {
    if a.factor_tips || a.preconditioner == Preconditioner::Laplacian {
        return Ok(false);
    }
    stats.solve_s += started.elapsed().as_secs_f64();
    let switched = switch_to_full_factor(
        a,
        pattern,
        elements,
        factorization_cost,
        since_factor,
        stats,
    )?;
    *started = Instant::now();
    Ok(switched)
}

/// Factors anew in the middle of a solve ([`give_up`]) and restarts from the
/// residual; `started` times the solve, paused while it factors.
fn renew(
    a: &mut DirectScratch,
    pattern: &BlockPattern,
    mass: &[Scalar],
    stats: &mut StepStats,
    started: &mut Instant,
) -> Result<(), SolveFailure> {
    stats.solve_s += started.elapsed().as_secs_f64();
    refactor(a, pattern, mass, stats)?;
    a.policy.factored(true);
    *started = Instant::now();
    residual(a, pattern);
    Ok(())
}

/// Whether to factor anew at the start of a solve with a valid factor, by the
/// scene's `refactor` rule (module docs).
fn renew_at_start(a: &mut DirectScratch, rule: Refactor, factorization_cost: Scalar) -> bool {
    match rule {
        Refactor::Cost => a.policy.renew_at_start(factorization_cost),
        Refactor::EverySolve => true,
        Refactor::PerMesh => false,
    }
}

/// Whether a solve with an older factor gives it up after `spent` iterations, by the
/// scene's `refactor` rule; `residuals`: the norms at the restart, now and the goal.
/// With `per_mesh` only the iteration cap gives the factor up.
fn give_up(
    a: &DirectScratch,
    rule: Refactor,
    factorization_cost: Scalar,
    spent: u32,
    cap: u32,
    (first, now, goal): (Scalar, Scalar, Scalar),
) -> bool {
    match rule {
        Refactor::Cost => a
            .policy
            .give_up(factorization_cost, spent, first, now, goal),
        Refactor::EverySolve => false,
        Refactor::PerMesh => spent >= cap,
    }
}

/// Starts (or restarts) the preconditioned iteration from the residual `r`:
/// `z = M^-1 r` (one solve with the factor), `p = z`. Returns `r.z` and `r.r`.
fn pcg_start(a: &mut DirectScratch, stats: &mut StepStats) -> (Scalar, Scalar) {
    a.precondition();
    stats.factor_solves += 1;
    a.p.clone_from(&a.z);
    let rz = dot(&a.r, &a.z);
    let rr = dot(&a.r, &a.r);
    (rz, rr)
}

/// One conjugate-gradient step from `p` and `rz = r.z`: `A_s p`, then the update
/// with `alpha = rz / p.A_s p`. Returns the new `r.z` and `r.r`; `None` when
/// `p.A_s p` is not positive (the matrix is not positive definite).
fn pcg_step(a: &mut DirectScratch, pattern: &BlockPattern, rz: Scalar) -> Option<(Scalar, Scalar)> {
    pattern.multiply(&a.system, &a.p, &mut a.ap);
    let pap = dot(&a.p, &a.ap);
    if pap <= 0.0 || !pap.is_finite() {
        return None;
    }
    let rz_new = pcg_update(a, rz / pap, rz);
    Some((rz_new, dot(&a.r, &a.r)))
}

/// One conjugate-gradient update with step `alpha`: `y += alpha p`,
/// `r -= alpha A p`, `z = M^-1 r` (one solve with the factor), `p = z + beta p`
/// with `beta = r.z / rz`. Returns the new `r.z`.
fn pcg_update(a: &mut DirectScratch, alpha: Scalar, rz: Scalar) -> Scalar {
    a.y.par_iter_mut()
        .zip(a.r.par_iter_mut())
        .zip(a.p.par_iter().zip(a.ap.par_iter()))
        .with_min_len(PAR_MIN)
        .for_each(|((y, r), (p, ap))| {
            *y += *p * alpha;
            *r -= *ap * alpha;
        });
    a.precondition();
    let rz_new = dot(&a.r, &a.z);
    let beta = rz_new / rz;
    a.p.par_iter_mut()
        .zip(a.z.par_iter())
        .with_min_len(PAR_MIN)
        .for_each(|(p, z)| *p = *z + *p * beta);
    rz_new
}

/// `r = b_s - A_s y`.
fn residual(a: &mut DirectScratch, pattern: &BlockPattern) {
    let n = a.rhs.len();
    a.ap.resize(n, Vector::ZERO);
    a.r.resize(n, Vector::ZERO);
    pattern.multiply(&a.system, &a.y, &mut a.ap);
    a.r.par_iter_mut()
        .zip(a.rhs.par_iter().zip(a.ap.par_iter()))
        .with_min_len(PAR_MIN)
        .for_each(|(r, (b, ap))| *r = *b - *ap);
}

/// The contacts' normal impulses from the linear residual `A dv - b`, with the
/// unprojected `A` (see [`super::contact_push_from`]).
fn contact_pressure(st: &mut Stepper, pattern: &BlockPattern) {
    let s = &mut st.implicit;
    if s.filter.iter().any(|f| *f != Vector::ZERO) {
        pattern.multiply_lower(&s.direct.lower, &s.dv, None, &mut s.direct.ap);
    }
    super::contact_push_from(
        &s.filter,
        Some(&s.direct.ap),
        &s.b,
        &st.elements.mass,
        &mut st.contact_push,
    );
}
