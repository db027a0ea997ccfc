//! The springs kind: stretch springs, hinge springs and sewing springs, one
//! force slot per spring (the force on its first end; the second end gets the
//! opposite). The capped sewing springs (`sewing.rs`) are computed as plain
//! springs and then overwritten with their capped force, energy and blocks.

use rayon::prelude::*;

use super::ForceKind;
use crate::math::{Matrix3, Scalar, Vector, deterministic_sum};
use crate::mesh::Mesh;
use crate::physics::block::outer;
use crate::physics::elements::Elements;
use crate::physics::forces::{PAR_MIN, spring_force};
use crate::physics::sewing::{
    cap_energy_change, cap_force, cap_forces, capped_spring_force, capped_spring_stiffness,
};

/// The springs of [`Elements::springs`] (with [`Elements::sewing_caps`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct Springs;

/// The springs' terms of the linearised step.
#[derive(Debug, Default, Clone)]
pub struct SpringLinear {
    /// Per spring: `h^2 K_e + h D_e`.
    pub block: Vec<Matrix3>,
    /// Per spring: its right-hand side slot, then its slot of a product.
    pub slot: Vec<Vector>,
}

impl ForceKind for Springs {
    type Forces = Vec<Vector>;
    type Linear = SpringLinear;
    type Kick = Vec<Vector>;
    type InPlace = ();
    const ENERGY_RANK: usize = 0;

    fn count(el: &Elements) -> usize {
        el.springs.len()
    }

    fn element_vertices(el: &Elements, e: usize, out: &mut Vec<u32>) {
        out.clear();
        out.extend(el.springs[e].v);
    }

    /// The capped sewing springs among `ids` get their capped force
    /// ([`Elements::sewing_caps`] is in spring order).
    fn kick(
        el: &Elements,
        ids: &[u32],
        x: &[Vector],
        v: &[Vector],
        out: &mut Vec<Vector>,
        kick: &mut Vec<Vector>,
    ) {
        let caps = &el.sewing_caps;
        ids.par_iter()
            .with_min_len(512)
            .map(|&s| match caps.binary_search_by_key(&s, |c| c.spring) {
                Ok(c) => cap_force(el, &caps[c], x, v),
                Err(_) => {
                    let sp = &el.springs[s as usize];
                    let [a, b] = [sp.v[0] as usize, sp.v[1] as usize];
                    spring_force(x[a], x[b], v[a], v[b], sp.rest, sp.k, sp.c)
                }
            })
            .collect_into_vec(kick);
        for (&s, &f) in ids.iter().zip(kick.iter()) {
            out[s as usize] = f;
        }
    }

    fn size_forces(el: &Elements, out: &mut Vec<Vector>) {
        out.resize(el.springs.len(), Vector::ZERO);
    }

    fn forces(el: &Elements, x: &[Vector], v: &[Vector], out: &mut Vec<Vector>) {
        Self::size_forces(el, out);
        out.par_iter_mut()
            .with_min_len(PAR_MIN)
            .zip(el.springs.par_iter())
            .for_each(|(f, s)| {
                let [a, b] = [s.v[0] as usize, s.v[1] as usize];
                *f = spring_force(x[a], x[b], v[a], v[b], s.rest, s.k, s.c);
            });
        cap_forces(el, x, v, out);
    }

    #[inline(always)]
    fn gather_force(el: &Elements, out: &Vec<Vector>, i: usize, f: &mut Vector) {
        for &s in el.spring_first.of(i) {
            *f += out[s as usize];
        }
        for &s in el.spring_second.of(i) {
            *f -= out[s as usize];
        }
    }

    fn energy(el: &Elements, x: &[Vector]) -> Scalar {
        let stretch = deterministic_sum(el.springs.len(), |s| {
            let sp = &el.springs[s];
            let stretch = x[sp.v[1] as usize].distance(x[sp.v[0] as usize]) - sp.rest;
            0.5 * sp.k * stretch * stretch
        });
        // The capped sewing springs' energy is Huber, not quadratic (`sewing.rs`).
        if el.sewing_caps.is_empty() {
            stretch
        } else {
            stretch + cap_energy_change(el, x)
        }
    }

    /// Per spring: the block `h^2 K_e + h D_e` and the slot `h f_e - h^2 K_e (v_a - v_b)`.
    fn linearise(
        el: &Elements,
        x: &[Vector],
        v: &[Vector],
        h: Scalar,
        k_term: Scalar,
        lin: &mut SpringLinear,
    ) {
        lin.block.resize(el.springs.len(), Matrix3::ZERO);
        lin.slot.resize(el.springs.len(), Vector::ZERO);
        lin.block
            .par_iter_mut()
            .zip(lin.slot.par_iter_mut())
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
        capped_springs(lin, el, x, v, h, k_term);
    }

    #[inline(always)]
    fn gather_linear(
        el: &Elements,
        lin: &SpringLinear,
        i: usize,
        _h: Scalar,
        jacobi: bool,
        rhs: &mut Vector,
        diag: &mut Vector,
    ) {
        for &e in el.spring_first.of(i) {
            *rhs += lin.slot[e as usize];
            if jacobi {
                *diag += matrix_diagonal(&lin.block[e as usize]);
            }
        }
        for &e in el.spring_second.of(i) {
            *rhs -= lin.slot[e as usize];
            if jacobi {
                *diag += matrix_diagonal(&lin.block[e as usize]);
            }
        }
    }

    fn product(el: &Elements, lin: &mut SpringLinear, p: &[Vector], _h2: Scalar) {
        lin.slot
            .par_iter_mut()
            .zip(lin.block.par_iter())
            .zip(el.springs.par_iter())
            .with_min_len(PAR_MIN)
            .for_each(|((q, block), sp)| {
                *q = *block * (p[sp.v[0] as usize] - p[sp.v[1] as usize]);
            });
    }

    #[inline(always)]
    fn gather_product(el: &Elements, lin: &SpringLinear, i: usize, acc: &mut Vector) {
        for &e in el.spring_first.of(i) {
            *acc += lin.slot[e as usize];
        }
        for &e in el.spring_second.of(i) {
            *acc -= lin.slot[e as usize];
        }
    }

    fn coupling_count(el: &Elements) -> usize {
        2 * el.springs.len()
    }

    fn couplings(el: &Elements, pairs: &mut Vec<(u32, u32)>) {
        for sp in &el.springs {
            let [a, b] = sp.v;
            pairs.extend([(a, b), (b, a)]);
        }
    }

    /// One value per spring, its block: added on both ends' diagonal blocks
    /// and subtracted off it.
    fn listed_blocks(el: &Elements, mut f: impl FnMut(u32, u32, u32, bool)) {
        for (e, sp) in el.springs.iter().enumerate() {
            let ([a, b], e) = (sp.v, e as u32);
            f(a, a, e, false);
            f(b, b, e, false);
            f(a, b, e, a != b);
        }
    }

    fn block_values(lin: &SpringLinear) -> &[Matrix3] {
        &lin.block
    }

    /// A spring's ends: the factorization keeps its coupling.
    fn factored_pairs(el: &Elements, mut f: impl FnMut(u32, u32)) {
        for sp in &el.springs {
            let [a, b] = sp.v;
            f(a, b);
            f(b, a);
        }
    }

    fn gershgorin(
        el: &Elements,
        _mesh: &Mesh,
        _flat: &mut [Vector],
        stiff: &mut [Scalar],
        damp: &mut [Scalar],
    ) {
        for s in &el.springs {
            for &v in &s.v {
                stiff[v as usize] += 2.0 * s.k;
                damp[v as usize] += 2.0 * s.c;
            }
        }
    }
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
    lin: &mut SpringLinear,
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
        (lin.block[e], lin.slot[e]) = spring_terms(f, stiff, nn, sp.c, v[a] - v[b], h, k_term);
    }
}

/// The diagonal of a 3 x 3 matrix.
#[inline(always)]
pub(crate) fn matrix_diagonal(m: &Matrix3) -> Vector {
    Vector::new(m.x_axis.x, m.y_axis.y, m.z_axis.z)
}
