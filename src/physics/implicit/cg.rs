//! Matrix-free conjugate gradients with a Jacobi preconditioner (`solver = "cg"`).
//!
//! `A` is never assembled: each iteration applies it with the same element pass +
//! per-vertex gather as the forces, so results are deterministic. The
//! preconditioner is the diagonal of `A`. Its iteration count grows with
//! `stretch * h^2 / (mass * edge^2)` (and with `edge^-4` for bending), which is why
//! the direct solver is the default.

use rayon::prelude::*;

use super::{ImplicitScratch, SolveFailure, without};
use crate::math::{Scalar, Vector, deterministic_sum, deterministic_sum2};
use crate::physics::forces::PAR_MIN;
use crate::physics::{Model, Stepper};

/// Vectors of the iteration, kept between steps.
#[derive(Debug, Default, Clone)]
pub(super) struct CgScratch {
    r: Vec<Vector>,
    z: Vec<Vector>,
    p: Vec<Vector>,
    ap: Vec<Vector>,
}

/// Solves `A dv = b` in place of the first guess `dv` (module docs); `reference`:
/// the norm the tolerance is relative to.
pub(super) fn solve(
    st: &mut Stepper,
    model: &Model,
    held: &[bool],
    reference: Scalar,
    contact_push: bool,
) -> Result<(), SolveFailure> {
    let started = std::time::Instant::now();
    let (mut rz, mut rr) = start(st, held);
    let tolerance = model.cg_tolerance;
    let goal = tolerance * reference;
    let mut iterations = 0;
    let outcome = loop {
        if rr.sqrt() <= goal {
            break Ok(());
        }
        if iterations >= model.cg_max_iterations {
            break Err(SolveFailure::not_converged(
                iterations,
                rr.sqrt(),
                reference,
                tolerance,
            ));
        }
        apply_operator(st, Which::Direction, held, true);
        let s = &mut st.implicit;
        let pap = dot(&s.cg.p, &s.cg.ap);
        if pap <= 0.0 || !pap.is_finite() {
            break Err(SolveFailure::NotPositiveDefinite);
        }
        let rz_new;
        (rz_new, rr) = step(s, rz / pap);
        let beta = rz_new / rz;
        rz = rz_new;
        let c = &mut s.cg;
        c.p.par_iter_mut()
            .zip(c.z.par_iter())
            .with_min_len(PAR_MIN)
            .for_each(|(p, z)| *p = *z + *p * beta);
        iterations += 1;
    };
    st.stats.cg_iterations += iterations as u64;
    if outcome.is_ok() && contact_push {
        contact_pressure(st, held);
    }
    st.stats.solve_s += started.elapsed().as_secs_f64();
    outcome
}

/// Starts the iteration from the first guess `dv`: `r = b - A dv` (filtered,
/// zero on held vertices), `z` the preconditioned `r`, `p = z`. Returns `r.z`
/// and `r.r`.
fn start(st: &mut Stepper, held: &[bool]) -> (Scalar, Scalar) {
    let n = st.implicit.dv.len();
    {
        let c = &mut st.implicit.cg;
        for buf in [&mut c.r, &mut c.z, &mut c.p, &mut c.ap] {
            buf.resize(n, Vector::ZERO);
        }
    }
    apply_operator(st, Which::Solution, held, true);
    let s = &mut st.implicit;
    let c = &mut s.cg;
    c.r.par_iter_mut()
        .zip(s.b.par_iter().zip(c.ap.par_iter()))
        .zip(s.filter.par_iter())
        .enumerate()
        .for_each(|(i, ((r, (b, ap)), f))| {
            *r = if held[i] {
                Vector::ZERO
            } else {
                without(*f, *b - *ap)
            };
        });
    precondition(&mut c.z, &c.r, &s.inv_diag, &s.filter);
    c.p.copy_from_slice(&c.z);
    dot2(&c.r, &c.z)
}

/// One pass with step `alpha`: `dv += alpha p`, `r -= alpha A p`, `z` the
/// preconditioned `r`. Returns the new `r.z` and `r.r`.
fn step(s: &mut ImplicitScratch, alpha: Scalar) -> (Scalar, Scalar) {
    let c = &mut s.cg;
    s.dv.par_iter_mut()
        .zip(c.r.par_iter_mut().zip(c.z.par_iter_mut()))
        .zip(
            c.p.par_iter()
                .zip(c.ap.par_iter().zip(s.inv_diag.par_iter())),
        )
        .zip(s.filter.par_iter())
        .with_min_len(PAR_MIN)
        .for_each(|(((d, (r, z)), (p, (ap, inv))), n)| {
            *d += *p * alpha;
            *r -= *ap * alpha;
            *z = without(*n, *r * *inv);
        });
    dot2(&c.r, &c.z)
}

/// Which vector the operator is applied to.
#[derive(Clone, Copy, PartialEq)]
enum Which {
    /// The current solution `dv`.
    Solution,
    /// The search direction `p`.
    Direction,
}

/// `ap = A * (dv or p)`, matrix-free: element pass into slots, then gather;
/// `filtered`: with the contact filters applied to the rows.
fn apply_operator(st: &mut Stepper, which: Which, held: &[bool], filtered: bool) {
    let el = &st.elements;
    let s = &mut st.implicit;
    let input: &Vec<Vector> = if which == Which::Solution {
        &s.dv
    } else {
        &s.cg.p
    };
    s.kinds.product(el, input, s.h2);
    let (kinds, diag_mass, filter) = (&s.kinds, &s.diag_mass, &s.filter);
    s.cg.ap
        .par_iter_mut()
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, out)| {
            // Pinned rows are filtered out of the system.
            if held[i] {
                *out = Vector::ZERO;
                return;
            }
            let mut acc = input[i] * diag_mass[i];
            kinds.gather_product(el, i, &mut acc);
            *out = if filtered {
                without(filter[i], acc)
            } else {
                acc
            };
        });
}

/// `z = S P^-1 r` with the diagonal preconditioner and the contact filters.
fn precondition(z: &mut [Vector], r: &[Vector], inv_diag: &[Vector], filter: &[Vector]) {
    z.par_iter_mut()
        .zip(r.par_iter().zip(inv_diag.par_iter()))
        .zip(filter.par_iter())
        .with_min_len(PAR_MIN)
        .for_each(|((z, (r, inv)), n)| *z = without(*n, *r * *inv));
}

/// The contacts' normal impulses from the linear residual `A dv - b` (see
/// [`super::contact_push_from`]).
fn contact_pressure(st: &mut Stepper, held: &[bool]) {
    if st.implicit.filter.iter().any(|f| *f != Vector::ZERO) {
        apply_operator(st, Which::Solution, held, false);
    }
    let s = &st.implicit;
    super::contact_push_from(
        &s.filter,
        Some(&s.cg.ap),
        &s.b,
        &st.elements.mass,
        &mut st.contact_push,
    );
}

/// `r . z` and `r . r` in one pass, each bit-identical to its own [`dot`].
fn dot2(r: &[Vector], z: &[Vector]) -> (Scalar, Scalar) {
    deterministic_sum2(r.len(), |i| (r[i].dot(z[i]), r[i].dot(r[i])))
}

/// Dot product of two vector fields, deterministic at any thread count.
pub(super) fn dot(a: &[Vector], b: &[Vector]) -> Scalar {
    deterministic_sum(a.len(), |i| a[i].dot(b[i]))
}
