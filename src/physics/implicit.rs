//! Implicit backward Euler with one Newton step (Baraff and Witkin 1998).
//!
//! Solve `A dv = b` with
//! `A = M + h (D + drag) + h^2 K` and `b = h f(x0, v0) - h^2 K v0`,
//! then `v1 = v0 + dv`, `x1 = x0 + h v1`. Here `K = -df/dx` and `D = -df/dv`.
//!
//! * Spring `e = (a, b)`, unit axis `n`, length `l`, rest `L`:
//!   `K_e = k (n n^T + max(0, 1 - L/l) (I - n n^T))`. The transverse term is
//!   clamped at zero under compression (Choi and Ko 2002) so `K` stays positive
//!   semi-definite; `D_e = c n n^T`. Both act on `p_a - p_b`.
//! * Dihedral hinge with gradient `g` of its angle: Gauss-Newton `K_h = k g g^T`
//!   (the curvature term of the exact Hessian is dropped; it is indefinite).
//! * Shape triangle (`shape.rs`), energy `theta^T M theta / 2` over its three edge
//!   angles with Jacobian `J` (rows: angle gradients): Gauss-Newton `K_t = J^T M J`
//!   (constant `M`; the curvature term is dropped as for the hinges).
//! * Wind is treated explicitly (only in `b`).
//!
//! `A` is never assembled: each CG iteration applies it matrix-free with the same
//! element pass + per-vertex gather as the forces, so results are deterministic.
//! Pinned vertices are handled by filtering (their `dv` is prescribed by the pin
//! script and their residual is zeroed). Preconditioner: the diagonal of `A`.
//!
//! Obstacle contact is filtered the same way, one direction instead of three
//! (Baraff and Witkin 1998, section 5): a vertex the collision pass left in contact
//! with an obstacle ([`Contact`]) whose right-hand side presses it into the surface
//! (`b . n < 0`) gets its normal velocity prescribed to the obstacle's
//! (`(v0 + dv) . n = u_n`) and its residual, search direction and operator rows
//! projected by `S = I - n n^T`, so the solve moves it only along the surface. Left
//! to the post-step response alone, a large step solves the cloth as if such a
//! vertex could sink in, then moves it back: the neighbours' velocities are those of
//! a cloth that sank, and each step of resting contact stretches the springs around
//! it (with 4 ms steps a tablecloth gained more energy than it started with). A
//! vertex pulled away from the surface (`b . n >= 0`) is left free, so cloth lifts off.

use rayon::prelude::*;

use super::bending::dihedral_angle_and_gradient;
use super::forces::{PAR_MIN, spring_force, wind_share};
use super::shape::{SHAPE_SLOTS, ShapeJacobian, rates, spread};
use super::{Contact, Stepper};
use crate::math::{Matrix3, Scalar, Vector, deterministic_sum, deterministic_sum2};
use crate::world::World;

/// Scratch memory of the implicit step, kept between steps.
#[derive(Debug, Default, Clone)]
pub struct ImplicitScratch {
    block: Vec<Matrix3>,
    spring_slot: Vec<Vector>,
    hinge_grad: Vec<Vector>,
    hinge_coef: Vec<Scalar>,
    hinge_slot: Vec<Vector>,
    shape_slot: Vec<Vector>,
    shape_grad: Vec<ShapeJacobian>,
    /// `h^2` of the step being solved (scales the shape triangles' `M`).
    h2: Scalar,
    tri_slot: Vec<Vector>,
    diag_mass: Vec<Scalar>,
    inv_diag: Vec<Vector>,
    b: Vec<Vector>,
    dv: Vec<Vector>,
    r: Vec<Vector>,
    z: Vec<Vector>,
    p: Vec<Vector>,
    ap: Vec<Vector>,
    /// Per vertex: the contact normal whose direction is filtered out of the
    /// solve, or zero (see the module docs).
    filter: Vec<Vector>,
    /// True when `dv` holds the previous step's solution on the same mesh, used
    /// as the first guess (the velocity change varies slowly between steps).
    pub(super) warm: bool,
}

/// One backward Euler step; returns the number of CG iterations used.
pub fn backward_euler(st: &mut Stepper, w: &mut World, h: Scalar) -> u32 {
    let t = w.time;
    let n = w.x.len();
    w.pins.held_at(t, &mut st.held);
    assemble(st, w, h);
    let s = &mut st.implicit;
    if !s.warm || s.dv.len() != n {
        s.dv.clear();
    }
    for buf in [&mut s.dv, &mut s.r, &mut s.z, &mut s.p, &mut s.ap] {
        buf.resize(n, Vector::ZERO);
    }
    s.warm = true;
    // Prescribed velocity change of pinned vertices; the free ones start from
    // the previous step's solution.
    for a in &w.pins.anchors {
        if st.held[a.vertex as usize] {
            let (_, vel) = w.pins.target(a, t + h);
            s.dv[a.vertex as usize] = vel - w.v[a.vertex as usize];
        }
    }
    contact_filters(s, &st.contacts, &st.held, &w.v);
    // Taken out for the solve so that `apply_operator` can borrow the stepper.
    let held_owned = std::mem::take(&mut st.held);
    let held = &held_owned;
    // r = b - A dv, filtered.
    apply_operator(st, Which::Solution, held);
    let s = &mut st.implicit;
    s.r.par_iter_mut()
        .zip(s.b.par_iter().zip(s.ap.par_iter()))
        .enumerate()
        .for_each(|(i, (r, (b, ap)))| {
            *r = if held[i] { Vector::ZERO } else { *b - *ap };
        });
    filter_rows(&s.filter, &mut s.r);
    let b_norm = deterministic_sum(n, |i| {
        if held[i] {
            0.0
        } else {
            without(s.filter[i], s.b[i]).length_squared()
        }
    })
    .sqrt();
    precondition(s);
    s.p.copy_from_slice(&s.z);
    let (mut rz, mut rr) = dot2(&s.r, &s.z);
    let tol = st.model.cg_tolerance * b_norm;
    let mut iterations = 0;
    while iterations < st.model.cg_max_iterations {
        if rr.sqrt() <= tol {
            break;
        }
        apply_operator(st, Which::Direction, held);
        let s = &mut st.implicit;
        let pap = dot(&s.p, &s.ap);
        if pap <= 0.0 || !pap.is_finite() {
            break;
        }
        let alpha = rz / pap;
        // One pass: step the solution and the residual, precondition.
        s.dv.par_iter_mut()
            .zip(s.r.par_iter_mut().zip(s.z.par_iter_mut()))
            .zip(
                s.p.par_iter()
                    .zip(s.ap.par_iter().zip(s.inv_diag.par_iter())),
            )
            .zip(s.filter.par_iter())
            .with_min_len(PAR_MIN)
            .for_each(|(((d, (r, z)), (p, (ap, inv))), n)| {
                *d += *p * alpha;
                *r -= *ap * alpha;
                *z = without(*n, *r * *inv);
            });
        let rz_new;
        (rz_new, rr) = dot2(&s.r, &s.z);
        let beta = rz_new / rz;
        rz = rz_new;
        s.p.par_iter_mut()
            .zip(s.z.par_iter())
            .with_min_len(PAR_MIN)
            .for_each(|(p, z)| *p = *z + *p * beta);
        iterations += 1;
    }
    contact_pressure(st, held);
    let s = &st.implicit;
    w.x.par_iter_mut()
        .zip(w.v.par_iter_mut())
        .zip(s.dv.par_iter())
        .for_each(|((x, v), dv)| {
            *v += *dv;
            *x += *v * h;
        });
    w.pins.apply(t + h, &mut w.x, &mut w.v);
    st.held = held_owned;
    iterations
}

/// Builds the per-element blocks, the right-hand side `b` and the preconditioner.
fn assemble(st: &mut Stepper, w: &World, h: Scalar) {
    let (el, ext) = (&st.elements, &st.model.external);
    let (x, v) = (&w.x, &w.v);
    let s = &mut st.implicit;
    let n = x.len();
    s.block.resize(el.springs.len(), Matrix3::ZERO);
    s.spring_slot.resize(el.springs.len(), Vector::ZERO);
    s.block
        .par_iter_mut()
        .zip(s.spring_slot.par_iter_mut())
        .zip(el.springs.par_iter())
        .with_min_len(PAR_MIN)
        .for_each(|((block, slot), sp)| {
            let [a, b] = [sp.v[0] as usize, sp.v[1] as usize];
            let f = spring_force(x[a], x[b], v[a], v[b], sp.rest, sp.k, sp.c);
            let d = x[b] - x[a];
            let len = d.length();
            let dir = if len > 0.0 { d / len } else { Vector::ZERO };
            let nn = outer(dir, dir);
            let transverse = if len > 0.0 {
                (1.0 - sp.rest / len).max(0.0)
            } else {
                0.0
            };
            let stiff = (nn + (Matrix3::IDENTITY - nn) * transverse) * sp.k;
            *block = stiff * (h * h) + nn * (h * sp.c);
            *slot = f * h - stiff * (v[a] - v[b]) * (h * h);
        });
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
                slot[k] = g[k] * (-h * hg.k * theta - *coef * gv);
            }
        });
    // Shape triangles: slot = J^T (-h M theta - h^2 M J v).
    s.h2 = h * h;
    let shapes = el.shape_triangles.len();
    s.shape_slot.resize(SHAPE_SLOTS * shapes, Vector::ZERO);
    s.shape_grad
        .resize(shapes, [[Vector::ZERO; SHAPE_SLOTS]; 3]);
    s.shape_slot
        .par_chunks_exact_mut(SHAPE_SLOTS)
        .zip(s.shape_grad.par_iter_mut())
        .zip(el.shape_triangles.par_iter())
        .with_min_len(PAR_MIN / SHAPE_SLOTS)
        .for_each(|((slot, grad), t)| {
            let (theta, jac) = t.angles(x);
            let jv = rates(t, &jac, v);
            let c = t.times_m([0, 1, 2].map(|a| -h * theta[a] - h * h * jv[a]));
            spread(&jac, c, slot);
            *grad = jac;
        });
    if let Some(wind) = &ext.wind {
        s.tri_slot.resize(w.mesh.triangles.len(), Vector::ZERO);
        s.tri_slot
            .par_iter_mut()
            .zip(w.mesh.triangles.par_iter())
            .with_min_len(PAR_MIN)
            .for_each(|(f, t)| {
                *f = wind_share(t.map(|i| x[i as usize]), t.map(|i| v[i as usize]), wind) * h
            });
    }
    s.b.resize(n, Vector::ZERO);
    s.diag_mass.resize(n, 0.0);
    s.inv_diag.resize(n, Vector::ZERO);
    let (spring_slot, block, hinge_slot, hinge_grad, hinge_coef, tri_slot, shape_slot) = (
        &s.spring_slot,
        &s.block,
        &s.hinge_slot,
        &s.hinge_grad,
        &s.hinge_coef,
        &s.tri_slot,
        &s.shape_slot,
    );
    let shape_grad = &s.shape_grad;
    s.b.par_iter_mut()
        .zip(s.diag_mass.par_iter_mut().zip(s.inv_diag.par_iter_mut()))
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, (b, (dm, inv)))| {
            let mut rhs = Vector::ZERO;
            let mut diag = Vector::ZERO;
            for &e in el.spring_first.of(i) {
                rhs += spring_slot[e as usize];
                diag += matrix_diagonal(&block[e as usize]);
            }
            for &e in el.spring_second.of(i) {
                rhs -= spring_slot[e as usize];
                diag += matrix_diagonal(&block[e as usize]);
            }
            for &k in el.hinge_slots.of(i) {
                rhs += hinge_slot[k as usize];
                let g = hinge_grad[k as usize];
                diag += g * g * hinge_coef[k as usize / 4];
            }
            for &k in el.shape_slots.of(i) {
                rhs += shape_slot[k as usize];
                let (t, slot) = (k as usize / SHAPE_SLOTS, k as usize % SHAPE_SLOTS);
                let (m, jac) = (&el.shape_triangles[t].m, &shape_grad[t]);
                for a in 0..3 {
                    for b in 0..3 {
                        diag += jac[a][slot] * jac[b][slot] * (h * h * m[a][b]);
                    }
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
            let mut m = el.mass[i];
            if let Some(drag) = ext.drag {
                rhs -= (v[i] - ext.air_velocity) * (drag * el.vertex_area[i] * h);
                m += h * drag * el.vertex_area[i];
            }
            *b = rhs;
            *dm = m;
            *inv = Vector::ONE / (diag + Vector::splat(m));
        });
}

/// Which vector the operator is applied to.
#[derive(Clone, Copy, PartialEq)]
enum Which {
    /// The current solution `dv`.
    Solution,
    /// The search direction `p`.
    Direction,
}

/// `ap = A * (dv or p)`, matrix-free: element pass into slots, then gather.
fn apply_operator(st: &mut Stepper, which: Which, held: &[bool]) {
    apply_operator_rows(st, which, held, true);
}

/// `ap = A * (dv or p)`; `filtered`: with the contact filters applied to the rows.
fn apply_operator_rows(st: &mut Stepper, which: Which, held: &[bool], filtered: bool) {
    let el = &st.elements;
    let s = &mut st.implicit;
    let input: &Vec<Vector> = if which == Which::Solution {
        &s.dv
    } else {
        &s.p
    };
    s.spring_slot
        .par_iter_mut()
        .zip(s.block.par_iter())
        .zip(el.springs.par_iter())
        .with_min_len(PAR_MIN)
        .for_each(|((q, block), sp)| {
            *q = *block * (input[sp.v[0] as usize] - input[sp.v[1] as usize]);
        });
    s.hinge_slot
        .par_chunks_exact_mut(4)
        .zip(s.hinge_grad.par_chunks_exact(4))
        .zip(s.hinge_coef.par_iter())
        .zip(el.hinges.par_iter())
        .with_min_len(PAR_MIN / 4)
        .for_each(|(((slot, g), coef), hg)| {
            let gp: Scalar = (0..4).map(|k| g[k].dot(input[hg.v[k] as usize])).sum();
            for k in 0..4 {
                slot[k] = g[k] * (coef * gp);
            }
        });
    let h2 = s.h2;
    s.shape_slot
        .par_chunks_exact_mut(SHAPE_SLOTS)
        .zip(s.shape_grad.par_iter())
        .zip(el.shape_triangles.par_iter())
        .with_min_len(PAR_MIN / SHAPE_SLOTS)
        .for_each(|((slot, jac), t)| {
            let c = t.times_m(rates(t, jac, input));
            spread(jac, c.map(|c| c * h2), slot);
        });
    let (spring_slot, hinge_slot, shape_slot, diag_mass, filter) = (
        &s.spring_slot,
        &s.hinge_slot,
        &s.shape_slot,
        &s.diag_mass,
        &s.filter,
    );
    s.ap.par_iter_mut()
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, out)| {
            // Pinned rows are filtered out of the system.
            if held[i] {
                *out = Vector::ZERO;
                return;
            }
            let mut acc = input[i] * diag_mass[i];
            for &e in el.spring_first.of(i) {
                acc += spring_slot[e as usize];
            }
            for &e in el.spring_second.of(i) {
                acc -= spring_slot[e as usize];
            }
            for &k in el.hinge_slots.of(i) {
                acc += hinge_slot[k as usize];
            }
            for &k in el.shape_slots.of(i) {
                acc += shape_slot[k as usize];
            }
            *out = if filtered {
                without(filter[i], acc)
            } else {
                acc
            };
        });
}

/// `z = S P^-1 r` with the diagonal preconditioner and the contact filters.
fn precondition(s: &mut ImplicitScratch) {
    s.z.par_iter_mut()
        .zip(s.r.par_iter().zip(s.inv_diag.par_iter()))
        .zip(s.filter.par_iter())
        .for_each(|((z, (r, inv)), n)| *z = without(*n, *r * *inv));
}

/// `v` without its component along the unit vector `n` (`v` itself when `n` is zero).
#[inline(always)]
fn without(n: Vector, v: Vector) -> Vector {
    v - n * n.dot(v)
}

/// Projects every row by its contact filter.
fn filter_rows(filter: &[Vector], rows: &mut [Vector]) {
    rows.par_iter_mut()
        .zip(filter.par_iter())
        .with_min_len(PAR_MIN)
        .for_each(|(r, n)| *r = without(*n, *r));
}

/// The normal velocity change each filtered contact imposed in the solve,
/// `n . (A dv - b) / m` (positive: the obstacle pushed), into
/// [`Stepper::contact_push`]; the collision pass turns it into friction.
fn contact_pressure(st: &mut Stepper, held: &[bool]) {
    let n = st.implicit.filter.len();
    st.contact_push.clear();
    st.contact_push.resize(n, 0.0);
    if st.implicit.filter.iter().all(|f| *f == Vector::ZERO) {
        return;
    }
    apply_operator_rows(st, Which::Solution, held, false);
    let s = &st.implicit;
    let mass = &st.elements.mass;
    st.contact_push
        .par_iter_mut()
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(i, push)| {
            let f = s.filter[i];
            if f != Vector::ZERO {
                *push = (f.dot(s.ap[i] - s.b[i]) / mass[i]).max(0.0);
            }
        });
}

/// Chooses the contact filters (module docs) and prescribes the filtered vertices'
/// normal velocity change. `contacts` not matching the mesh (empty, or stale after a
/// remesh) filters nothing.
fn contact_filters(s: &mut ImplicitScratch, contacts: &[Contact], held: &[bool], v: &[Vector]) {
    let n = v.len();
    s.filter.clear();
    s.filter.resize(n, Vector::ZERO);
    if contacts.len() != n {
        return;
    }
    for i in 0..n {
        let c = contacts[i];
        if held[i] || c.normal == Vector::ZERO || s.b[i].dot(c.normal) >= 0.0 {
            continue;
        }
        s.filter[i] = c.normal;
        // (v0 + dv) . n = u_n, the tangential part of the warm start kept.
        s.dv[i] = without(c.normal, s.dv[i]) + c.normal * (c.normal_speed - v[i].dot(c.normal));
    }
}

/// `r . z` and `r . r` in one pass, each bit-identical to its own [`dot`].
fn dot2(r: &[Vector], z: &[Vector]) -> (Scalar, Scalar) {
    deterministic_sum2(r.len(), |i| (r[i].dot(z[i]), r[i].dot(r[i])))
}

/// Dot product of two vector fields, deterministic at any thread count.
fn dot(a: &[Vector], b: &[Vector]) -> Scalar {
    deterministic_sum(a.len(), |i| a[i].dot(b[i]))
}

fn outer(a: Vector, b: Vector) -> Matrix3 {
    Matrix3::from_cols(a * b.x, a * b.y, a * b.z)
}

fn matrix_diagonal(m: &Matrix3) -> Vector {
    Vector::new(m.x_axis.x, m.y_axis.y, m.z_axis.z)
}
