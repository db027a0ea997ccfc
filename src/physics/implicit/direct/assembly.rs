//! The direct solver's assembly: the lower blocks of `A` gathered into the
//! block pattern while the linearisation solves the fold splits ([`gather`]),
//! then the prescribed parts split off and the projected system `A_s`, `b_s`
//! and the factor's diagonal compensation ([`assemble`]).

use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;

use super::super::ImplicitScratch;
use crate::math::Vector;
use crate::physics::Stepper;
use crate::physics::block::{BlockPattern, ElementBlocks};
use crate::physics::elements::Elements;
use crate::physics::forces::PAR_MIN;

/// What the assembly reads of `s` ([`ElementBlocks`]), by field, so that
/// `s.direct` stays free to borrow.
macro_rules! element_blocks {
    ($s:expr, $el:expr) => {
        ElementBlocks {
            elements: $el,
            kinds: &$s.kinds,
            h2: $s.h2,
            diagonal_mass: &$s.diag_mass,
        }
    };
}

/// Writes every kind's block values ([`crate::physics::kinds::KindLinear::write_blocks`])
/// and gathers the lower blocks of `A` into the block pattern, built first for
/// a new mesh; the linearisation calls it while the fold splits are solved
/// (the kinds' terms that need them are not read). Returns the pattern.
pub(in crate::physics::implicit) fn gather(
    s: &mut ImplicitScratch,
    el: &Elements,
) -> Arc<BlockPattern> {
    let n = s.diag_mass.len();
    let a = &mut s.direct;
    if a.pattern.is_none() {
        a.factorization.reset();
        a.tips_break_even = None;
    }
    let started = Instant::now();
    let built = a.pattern.is_none();
    let pattern = a
        .pattern
        .get_or_insert_with(|| Arc::new(BlockPattern::build(n, el, a.factor_tips)))
        .clone();
    if built && a.new_mesh {
        a.pattern_s += started.elapsed().as_secs_f64();
    }
    s.kinds.write_blocks(el);
    let terms = element_blocks!(s, el);
    pattern.gather(&terms, &mut s.direct.lumps, &mut s.direct.lower);
    pattern
}

/// Completes the assembly that the linearisation began ([`gather`]): `A_s` and
/// `b_s` (module docs) from the first guess `dv` and `held`, and the diagonal
/// compensation of the factored matrix; timed as assembly. Returns the pattern.
pub(in crate::physics::implicit) fn assemble(st: &mut Stepper, held: &[bool]) -> Arc<BlockPattern> {
    let started = Instant::now();
    let n = st.implicit.dv.len();
    let s = &mut st.implicit;
    let pattern = match &s.direct.pattern {
        Some(pattern) => pattern.clone(),
        // Not gathered yet (the linearisation always gathers first).
        None => gather(s, &st.elements),
    };
    split_prescribed(s, held);
    let terms = element_blocks!(s, &st.elements);
    let a = &mut s.direct;
    pattern.touched_rows(&a.projection, &mut a.touched);
    pattern.compensation(&terms, &a.lumps, &a.projection, &mut a.compensation);
    // b_s = S (b - A dv_c).
    a.ap.resize(n, Vector::ZERO);
    pattern.multiply_lower(&a.lower, &a.prescribed, Some(&a.touched), &mut a.ap);
    a.rhs.resize(n, Vector::ZERO);
    a.rhs
        .par_iter_mut()
        .zip(s.b.par_iter().zip(a.ap.par_iter()))
        .zip(a.projection.par_iter())
        .with_min_len(PAR_MIN)
        .for_each(|((r, (b, ap)), proj)| *r = project(*proj, *b - *ap));
    pattern.project(
        &a.lower,
        &a.projection,
        &a.touched,
        &st.elements.mass,
        &mut a.system,
    );
    st.stats.assembly_s += started.elapsed().as_secs_f64();
    pattern
}

/// Splits the first guess `dv` into its prescribed part and the free first guess
/// `y`, and sets the projections.
fn split_prescribed(s: &mut ImplicitScratch, held: &[bool]) {
    let n = s.dv.len();
    let a = &mut s.direct;
    a.projection.resize(n, None);
    a.prescribed.resize(n, Vector::ZERO);
    a.y.resize(n, Vector::ZERO);
    a.projection
        .par_iter_mut()
        .zip(a.prescribed.par_iter_mut().zip(a.y.par_iter_mut()))
        .zip(s.dv.par_iter().zip(s.filter.par_iter()))
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, ((proj, (c, y)), (dv, f)))| {
            if held[i] {
                (*proj, *c, *y) = (Some(Vector::ZERO), *dv, Vector::ZERO);
            } else if *f != Vector::ZERO {
                let normal = *f * f.dot(*dv);
                (*proj, *c, *y) = (Some(*f), normal, *dv - normal);
            } else {
                (*proj, *c, *y) = (None, Vector::ZERO, *dv);
            }
        });
}

/// `S v` for one vertex's projection.
#[inline(always)]
fn project(proj: Option<Vector>, v: Vector) -> Vector {
    match proj {
        None => v,
        Some(n) if n == Vector::ZERO => Vector::ZERO,
        Some(n) => v - n * n.dot(v),
    }
}
