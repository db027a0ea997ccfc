//! The direct solver's factors: which one (the reduced or the full block
//! factor, in double or single precision, or the scalar Laplacian) and
//! factoring it (direct solver module docs, "Which factor").

use std::sync::Arc;
use std::time::Instant;

use super::{DirectScratch, SolveFailure};
use crate::math::{Matrix3, Scalar};
use crate::physics::Preconditioner;
use crate::physics::StepStats;
use crate::physics::block::BlockPattern;
use crate::physics::cholesky::{FactorError, Factorization, Precision};
use crate::physics::elements::Elements;

/// The precision of the block factor for `preconditioner`.
pub(super) fn precision(preconditioner: Preconditioner) -> Precision {
    match preconditioner {
        Preconditioner::FactorSingle => Precision::Single,
        Preconditioner::Factor | Preconditioner::Laplacian => Precision::Double,
    }
}

/// Asked once a fresh reduced factor has needed `since_factor` (at least
/// [`TIPS_CONSIDER`]) iterations: is it so poor a preconditioner here that the
/// full one is cheaper (module docs, "Which factor")? If so, switches to factoring
/// every block for the rest of the run, factors `A_s` that way and returns true.
pub(super) fn switch_to_full_factor(
    a: &mut DirectScratch,
    pattern: &BlockPattern,
    elements: &Elements,
    factorization_cost: Scalar,
    since_factor: u32,
    stats: &mut StepStats,
) -> Result<bool, SolveFailure> {
    let mut full = None;
    let break_even = match a.tips_break_even {
        Some(k) => k,
        None => {
            let (k, pattern, analysed) =
                tips_break_even(a, pattern, elements, factorization_cost, stats)?;
            a.tips_break_even = Some(k);
            full = Some((pattern, analysed));
            k
        }
    };
    if Scalar::from(since_factor) >= break_even {
        // Factor every block from now on (same blocks, so `pattern` still serves
        // the products).
        let (full, analysed) = match full {
            Some(f) => f,
            None => (
                Arc::new(BlockPattern::build(pattern.vertices(), elements, true)),
                Factorization::with_precision(a.factorization.precision()),
            ),
        };
        a.factor_tips = true;
        a.pattern = Some(full.clone());
        a.compensation.iter_mut().for_each(|m| *m = Matrix3::ZERO);
        a.factorization = analysed;
        refactor(a, &full, &elements.mass, stats)?;
        a.policy.factored(false);
        return Ok(true);
    }
    Ok(false)
}

/// The break-even of module docs, "Which factor": `F (rho - 1) + rho` for the
/// current pattern, with the full pattern and its analysis (kept in case the
/// solver switches at once). Counts as one symbolic analysis, timed with the
/// factorizations.
fn tips_break_even(
    a: &DirectScratch,
    pattern: &BlockPattern,
    elements: &Elements,
    factorization_cost: Scalar,
    stats: &mut StepStats,
) -> Result<(Scalar, Arc<BlockPattern>, Factorization), SolveFailure> {
    let started = Instant::now();
    let full = Arc::new(BlockPattern::build(pattern.vertices(), elements, true));
    let mut analysed = Factorization::with_precision(a.factorization.precision());
    analysed.analyse(&full).map_err(|_| SolveFailure::Setup)?;
    stats.symbolic_analyses += 1;
    stats.factorization_s += started.elapsed().as_secs_f64();
    let rho = match (analysed.stored_values(), a.factorization.stored_values()) {
        (Some(f), Some(r)) if r > 0 => f as Scalar / r as Scalar,
        _ => return Err(SolveFailure::Setup),
    };
    Ok((factorization_cost * (rho - 1.0) + rho, full, analysed))
}

/// Factors `A_s` (or its scalar Laplacian, with the vertices' `mass`),
/// analysing the pattern first when needed.
pub(super) fn refactor(
    a: &mut DirectScratch,
    pattern: &BlockPattern,
    mass: &[Scalar],
    stats: &mut StepStats,
) -> Result<(), SolveFailure> {
    let started = Instant::now();
    let map = |e: FactorError| match e {
        FactorError::NotPositiveDefinite => SolveFailure::NotPositiveDefinite,
        FactorError::Setup => SolveFailure::Setup,
    };
    let result = if a.preconditioner == Preconditioner::Laplacian {
        if !a.laplacian.is_analysed() {
            a.laplacian.analyse(pattern).map_err(map)?;
            stats.symbolic_analyses += 1;
        }
        a.laplacian.factor(pattern, &a.system, mass).map_err(map)
    } else {
        if !a.factorization.is_analysed() {
            a.factorization.analyse(pattern).map_err(map)?;
            stats.symbolic_analyses += 1;
        } else if std::mem::take(&mut a.analysis_uncounted) {
            stats.symbolic_analyses += 1;
        }
        a.factorization
            .factor(pattern, &a.system, &a.compensation)
            .map_err(map)
    };
    stats.factorizations += 1;
    if a.factor_tips {
        stats.full_factorizations += 1;
    }
    // A new mesh's ordering and first factor are part of rebuilding after the
    // change of mesh.
    let elapsed = started.elapsed().as_secs_f64();
    if std::mem::take(&mut a.new_mesh) {
        stats.rebuild_s += elapsed;
    } else {
        stats.factorization_s += elapsed;
    }
    result
}
