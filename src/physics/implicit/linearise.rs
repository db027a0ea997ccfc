//! Linearisation of the implicit step, shared by both solvers: per-element blocks
//! and slots (springs, hinges, shape triangles, membrane triangles, wind), then the per-vertex gather
//! of the right-hand side `b`, the mass diagonal and the Jacobi diagonal, in a
//! fixed order per vertex so the result is identical at any thread count; with
//! the direct solver, the block matrix too, while the fold splits are solved.

use rayon::prelude::*;

use super::super::bending::dihedral_angle_and_gradient;
use super::super::elements::Elements;
use super::super::forces::{PAR_MIN, edge_folds, fold_angles, spring_force, wind_share};
use super::super::membrane::{ColumnBlocks, MEMBRANE_SLOTS};
use super::super::sewing::{capped_spring_force, capped_spring_stiffness};
use super::super::shape::{SHAPE_SLOTS, rates, spread};
use super::super::{ExternalForces, Model, Stepper};
use super::ImplicitScratch;
use crate::math::{Matrix3, Scalar, Vector};
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
    // The direct solver's passes read each triangle's gradients from its
    // edges' folds; the CG solver's products read them by triangle.
    let direct = model.solver.solver == Solver::Direct;
    if direct {
        edge_folds(el, x, &mut s.edge_folds, &mut s.shape_folds);
    } else {
        fold_angles(
            el,
            x,
            &mut s.edge_folds,
            &mut s.shape_folds,
            &mut s.shape_grad,
        );
    }
    // The fold splits are a sequential sparse solve, which leaves the other
    // cores idle: the other elements' terms and the direct solver's block
    // matrix, which need no splits, are computed meanwhile. Each part's values
    // are the same whichever runs first.
    let folds = std::mem::take(&mut s.shape_folds);
    let mut splits = std::mem::take(&mut s.shape_splits);
    rayon::join(
        || {
            el.fold_splits
                .solve(&el.shape_triangles, &folds, &mut splits)
        },
        || {
            springs(s, el, x, v, h, k_term);
            hinges(s, el, x, v, h, k_term);
            membrane_triangles(s, el, x, v, h, k_term);
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
    (s.shape_folds, s.shape_splits) = (folds, splits);
    shape_triangles(s, el, v, h, k_term);
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

/// Per spring: the block `h^2 K_e + h D_e` and the slot `h f_e - h^2 K_e (v_a - v_b)`.
fn springs(
    s: &mut ImplicitScratch,
    el: &Elements,
    x: &[Vector],
    v: &[Vector],
    h: Scalar,
    k_term: Scalar,
) {
    s.spring_block.resize(el.springs.len(), Matrix3::ZERO);
    s.spring_slot.resize(el.springs.len(), Vector::ZERO);
    s.spring_block
        .par_iter_mut()
        .zip(s.spring_slot.par_iter_mut())
        .zip(el.springs.par_iter())
        .with_min_len(PAR_MIN)
        .for_each(|((block, slot), sp)| {
            let [a, b] = [sp.v[0] as usize, sp.v[1] as usize];
            let f = spring_force(x[a], x[b], v[a], v[b], sp.rest, sp.k, sp.c);
            let d = x[b] - x[a];
            let (len, nn) = axis(d);
            let transverse = if len > 0.0 {
                (1.0 - sp.rest / len).max(0.0)
            } else {
                0.0
            };
            let stiff = (nn + (Matrix3::IDENTITY - nn) * transverse) * sp.k;
            (*block, *slot) = spring_terms(f, stiff, nn, sp.c, v[a] - v[b], h, k_term);
        });
    capped_springs(s, el, x, v, h, k_term);
}

/// The length of a spring's separation `d` and the projector `n n^T` on its
/// axis (zero for coincident ends).
#[inline(always)]
fn axis(d: Vector) -> (Scalar, Matrix3) {
    let len = d.length();
    let dir = if len > 0.0 { d / len } else { Vector::ZERO };
    (len, outer(dir, dir))
}

/// The block `h^2 K + h c n n^T` and the slot `h f - h^2 K (v_a - v_b)` of a
/// spring with force `f` on its first end, stiffness `K`, axis projector
/// `nn = n n^T`, damping coefficient `c` and relative velocity `dv = v_a - v_b`.
#[inline(always)]
fn spring_terms(
    f: Vector,
    stiff: Matrix3,
    nn: Matrix3,
    c: Scalar,
    dv: Vector,
    h: Scalar,
    k_term: Scalar,
) -> (Matrix3, Vector) {
    let block = stiff * (h * h) + nn * (h * c);
    (block, f * h - stiff * dv * (h * h * k_term))
}

/// The capped sewing springs' blocks and slots over the plain ones the pass
/// above wrote (their force and stiffness of the Huber energy, `sewing.rs`).
fn capped_springs(
    s: &mut ImplicitScratch,
    el: &Elements,
    x: &[Vector],
    v: &[Vector],
    h: Scalar,
    k_term: Scalar,
) {
    for cap in &el.sewing_caps {
        let e = cap.spring as usize;
        let sp = &el.springs[e];
        let [a, b] = [sp.v[0] as usize, sp.v[1] as usize];
        let d = x[b] - x[a];
        let (_, nn) = axis(d);
        let f = capped_spring_force(x[a], x[b], v[a], v[b], sp.k, sp.c, cap.max_force);
        let stiff = capped_spring_stiffness(d, sp.k, cap.max_force);
        (s.spring_block[e], s.spring_slot[e]) =
            spring_terms(f, stiff, nn, sp.c, v[a] - v[b], h, k_term);
    }
}

/// Per hinge: the angle's gradient, `h^2 k` and the four slots.
fn hinges(
    s: &mut ImplicitScratch,
    el: &Elements,
    x: &[Vector],
    v: &[Vector],
    h: Scalar,
    k_term: Scalar,
) {
    let hinges = el.hinges.len();
    s.hinge_grad.resize(4 * hinges, Vector::ZERO);
    s.hinge_coef.resize(hinges, 0.0);
    s.hinge_slot.resize(4 * hinges, Vector::ZERO);
    s.hinge_grad
        .par_chunks_exact_mut(4)
        .zip(s.hinge_slot.par_chunks_exact_mut(4))
        .zip(s.hinge_coef.par_iter_mut())
        .zip(el.hinges.par_iter())
        .with_min_len(PAR_MIN / 4)
        .for_each(|(((grad, slot), coef), hg)| {
            let (theta, g) = dihedral_angle_and_gradient(hg.v.map(|i| x[i as usize]));
            let gv: Scalar = (0..4).map(|k| g[k].dot(v[hg.v[k] as usize])).sum();
            *coef = h * h * hg.k;
            for k in 0..4 {
                grad[k] = g[k];
                slot[k] = g[k] * (-h * hg.k * theta - *coef * gv * k_term);
            }
        });
}

/// Per shape triangle: slot = J^T (-h dE/dtheta - h^2 M J v), from the folds
/// and their Jacobian (read from the edges' folds) and the folds' splits
/// (`shape.rs`), solved before.
fn shape_triangles(
    s: &mut ImplicitScratch,
    el: &Elements,
    v: &[Vector],
    h: Scalar,
    k_term: Scalar,
) {
    let shapes = el.shape_triangles.len();
    s.shape_slot.resize(SHAPE_SLOTS * shapes, Vector::ZERO);
    let (edges, splits) = (&s.edge_folds, &s.shape_splits);
    s.shape_slot
        .par_chunks_exact_mut(SHAPE_SLOTS)
        .zip(el.shape_triangles.par_iter())
        .enumerate()
        .with_min_len(PAR_MIN / SHAPE_SLOTS)
        .for_each(|(i, (slot, t))| {
            let (theta, jac) = el.fold_edges.angles(i, edges);
            let jac = &jac;
            let jv = t.times_m(rates(t, jac, v));
            let moment = t.moments(theta, splits);
            let c = [0, 1, 2].map(|a| -h * moment[a] - h * h * jv[a] * k_term);
            spread(jac, c, slot);
        });
}

/// Per membrane triangle: the block `h^2 K_t + h D_t` over the columns and the
/// slots `h f_t - h^2 K_t v`.
fn membrane_triangles(
    s: &mut ImplicitScratch,
    el: &Elements,
    x: &[Vector],
    v: &[Vector],
    h: Scalar,
    k_term: Scalar,
) {
    let count = el.membrane_triangles.len();
    s.membrane_block.resize(count, ColumnBlocks::ZERO);
    s.membrane_slot.resize(MEMBRANE_SLOTS * count, Vector::ZERO);
    s.membrane_slot
        .par_chunks_exact_mut(MEMBRANE_SLOTS)
        .zip(s.membrane_block.par_iter_mut())
        .zip(el.membrane_triangles.par_iter())
        .with_min_len(PAR_MIN / MEMBRANE_SLOTS)
        .for_each(|((slot, block), t)| {
            let (gauss_newton, geometric) = t.stiffness(x);
            let stiff = gauss_newton.combine(1.0, &geometric, 1.0);
            *block = gauss_newton.combine(h * h + h * t.damping, &geometric, h * h);
            let mut kv = [Vector::ZERO; MEMBRANE_SLOTS];
            t.apply(&stiff, v, &mut kv);
            t.forces(x, v, slot);
            for (f, kv) in slot.iter_mut().zip(kv) {
                *f = *f * h - kv * (h * h * k_term);
            }
        });
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
    let (spring_slot, block, hinge_slot, hinge_grad, hinge_coef, tri_slot, v0, shape_slot) = (
        &s.spring_slot,
        &s.spring_block,
        &s.hinge_slot,
        &s.hinge_grad,
        &s.hinge_coef,
        &s.tri_slot,
        &s.v0,
        &s.shape_slot,
    );
    let shape_grad = &s.shape_grad;
    let (membrane_slot, membrane_block) = (&s.membrane_slot, &s.membrane_block);
    s.b.par_iter_mut()
        .zip(s.diag_mass.par_iter_mut().zip(s.inv_diag.par_iter_mut()))
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, (b, (dm, inv)))| {
            let mut rhs = Vector::ZERO;
            let mut diag = Vector::ZERO;
            for &e in el.spring_first.of(i) {
                rhs += spring_slot[e as usize];
                if jacobi {
                    diag += matrix_diagonal(&block[e as usize]);
                }
            }
            for &e in el.spring_second.of(i) {
                rhs -= spring_slot[e as usize];
                if jacobi {
                    diag += matrix_diagonal(&block[e as usize]);
                }
            }
            for &k in el.hinge_slots.of(i) {
                rhs += hinge_slot[k as usize];
                if jacobi {
                    let g = hinge_grad[k as usize];
                    diag += g * g * hinge_coef[k as usize / 4];
                }
            }
            for &k in el.shape_slots.of(i) {
                rhs += shape_slot[k as usize];
                let (t, slot) = (k as usize / SHAPE_SLOTS, k as usize % SHAPE_SLOTS);
                if !jacobi {
                    continue;
                }
                let (m, jac) = (&el.shape_triangles[t].m, &shape_grad[t]);
                for a in 0..3 {
                    for b in 0..3 {
                        diag += jac[a][slot] * jac[b][slot] * (h * h * m[a][b]);
                    }
                }
            }
            for &k in el.membrane_slots.of(i) {
                rhs += membrane_slot[k as usize];
                if jacobi {
                    let (t, slot) = (k as usize / MEMBRANE_SLOTS, k as usize % MEMBRANE_SLOTS);
                    let m = el.membrane_triangles[t].block(&membrane_block[t], slot, slot);
                    diag += matrix_diagonal(&m);
                }
            }
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

/// The outer product `a b^T`.
fn outer(a: Vector, b: Vector) -> Matrix3 {
    Matrix3::from_cols(a * b.x, a * b.y, a * b.z)
}

fn matrix_diagonal(m: &Matrix3) -> Vector {
    Vector::new(m.x_axis.x, m.y_axis.y, m.z_axis.z)
}
