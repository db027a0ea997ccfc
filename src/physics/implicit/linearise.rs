//! Linearisation of the implicit step, shared by both solvers: per-element blocks
//! and slots (every force element kind's, `kinds.rs`, and wind), then the per-vertex gather
//! of the right-hand side `b`, the mass diagonal and the Jacobi diagonal, in a
//! fixed order per vertex so the result is identical at any thread count; with
//! the direct solver, the block matrix too, while the fold splits are solved.

use rayon::prelude::*;

use super::super::elements::Elements;
use super::super::forces::{PAR_MIN, wind_share};
use super::super::kinds::ShapeTriangles;
use super::super::{ExternalForces, Model, Stepper};
use super::ImplicitScratch;
use crate::math::{Scalar, Vector};
use crate::spec::Solver;
use crate::world::World;

/// Builds the per-element blocks, the right-hand side `b` and the diagonal. With
/// `newton`, `b` is the residual `h f(x, v) - M (v - v0)` at the current iterate
/// instead of Baraff and Witkin's `h f(x0, v0) - h^2 K v0`. With the direct
/// solver, also gathers the block matrix ([`super::direct::gather`]).
pub(super) fn linearise(st: &mut Stepper, model: &Model, w: &World, h: Scalar, newton: bool) {
    let started = std::time::Instant::now();
    let (el, ext) = (&st.elements, &model.external);
    let (x, v) = (&w.x, &w.v);
    let s = &mut st.implicit;
    // The `-h^2 K v` term of the linearised step (none in a Newton residual).
    let k_term = if newton { 0.0 } else { 1.0 };
    s.h2 = h * h;
    // The block matrix: the direct solver's, or the quasi-Newton solver's to factor.
    let direct = model.solver.solver == Solver::Direct || s.gather_blocks;
    ShapeTriangles::fold(el, x, direct, &mut s.kinds.shapes);
    // The fold splits are a sequential sparse solve, which leaves the other
    // cores idle: the other kinds' terms and the direct solver's block
    // matrix, which need no splits, are computed meanwhile. Each part's values
    // are the same whichever runs first.
    let shapes = &mut s.kinds.shapes;
    let folds = std::mem::take(&mut shapes.folds);
    let mut splits = std::mem::take(&mut shapes.splits);
    rayon::join(
        || {
            el.kinds
                .shapes
                .fold_splits
                .solve(&el.kinds.shapes.triangles, &folds, &mut splits)
        },
        || {
            s.kinds.linearise(el, x, v, h, k_term);
            if direct {
                s.diag_mass.resize(x.len(), 0.0);
                s.diag_mass
                    .par_iter_mut()
                    .enumerate()
                    .with_min_len(PAR_MIN)
                    .for_each(|(i, m)| *m = diagonal_mass(el, ext, h, i));
                super::direct::gather(s, el);
            }
        },
    );
    (s.kinds.shapes.folds, s.kinds.shapes.splits) = (folds, splits);
    s.kinds.linearise_solved(el, v, h, k_term);
    // Wind is explicit: its force at the start of the step serves every Newton
    // iteration (re-evaluated at each iterate, without its derivative in `A`, the
    // iterations diverged on a flag at 10 ms steps).
    if let Some(wind) = ext.wind.as_ref().filter(|_| !newton) {
        s.tri_slot.resize(w.mesh.triangles.len(), Vector::ZERO);
        s.tri_slot
            .par_iter_mut()
            .zip(w.mesh.triangles.par_iter())
            .with_min_len(PAR_MIN)
            .for_each(|(f, t)| {
                *f = wind_share(t.map(|i| x[i as usize]), t.map(|i| v[i as usize]), wind) * h
            });
    }
    // The diagonal of `A` is the Jacobi preconditioner of `solver = "cg"` only.
    gather(s, el, ext, v, h, newton, !direct);
    // A new mesh's pattern is part of rebuilding after the change of mesh.
    let pattern_s = s.direct.take_pattern_time();
    st.stats.assembly_s += started.elapsed().as_secs_f64() - pattern_s;
    st.stats.rebuild_s += pattern_s;
}

/// Mass plus `h` times the drag coefficient of vertex `i`, kg: the diagonal of
/// `M + h D` that no element adds to.
#[inline(always)]
fn diagonal_mass(el: &Elements, ext: &ExternalForces, h: Scalar, i: usize) -> Scalar {
    match ext.drag {
        Some(drag) => el.mass[i] + h * drag * el.vertex_area[i],
        None => el.mass[i],
    }
}

/// Per vertex, in a fixed order: `b` (the slots of its elements, gravity, drag,
/// the Newton residual's inertia), the mass plus drag diagonal, and with
/// `jacobi` the inverse Jacobi diagonal (the CG solver's preconditioner; the
/// direct solver reads none of it, and it is left as it was).
fn gather(
    s: &mut ImplicitScratch,
    el: &Elements,
    ext: &ExternalForces,
    v: &[Vector],
    h: Scalar,
    newton: bool,
    jacobi: bool,
) {
    let n = v.len();
    s.b.resize(n, Vector::ZERO);
    s.diag_mass.resize(n, 0.0);
    s.inv_diag.resize(n, Vector::ZERO);
    let (kinds, tri_slot, v0) = (&s.kinds, &s.tri_slot, &s.v0);
    s.b.par_iter_mut()
        .zip(s.diag_mass.par_iter_mut().zip(s.inv_diag.par_iter_mut()))
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, (b, (dm, inv)))| {
            let mut rhs = Vector::ZERO;
            let mut diag = Vector::ZERO;
            kinds.gather(el, i, h, jacobi, &mut rhs, &mut diag);
            if ext.wind.is_some() {
                for &t in el.vertex_triangles.of(i) {
                    rhs += tri_slot[t as usize];
                }
            }
            if let Some(g) = ext.gravity {
                rhs += g * (el.mass[i] * h);
            }
            if let Some(drag) = ext.drag {
                rhs -= (v[i] - ext.air_velocity) * (drag * el.vertex_area[i] * h);
            }
            let m = diagonal_mass(el, ext, h, i);
            if newton {
                rhs -= (v[i] - v0[i]) * el.mass[i];
            }
            *b = rhs;
            *dm = m;
            if jacobi {
                *inv = Vector::ONE / (diag + Vector::splat(m));
            }
        });
}
