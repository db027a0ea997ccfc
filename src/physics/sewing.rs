//! Sewing springs: a zero-length spring between the two vertices of each pair
//! of every open seam, and the cap on their force (`[cloth.sewing] max_force`).
//!
//! A sewing spring of stiffness `k` pulls with `k d` at a gap `d`. With a cap
//! `F` it pulls with `min(k d, F)`: the force is the gradient of the Huber
//! energy
//!
//! ```text
//! E(d) = k d^2 / 2            for d <= d0 = F / k
//! E(d) = F (d - d0 / 2)       beyond,
//! ```
//!
//! continuous with its first derivative at `d0`. Its Hessian with respect to
//! the second end is `k I` up to `d0` and `(F / d) (I - n n^T)` beyond (`n`
//! the unit vector from the first end to the second): positive semidefinite
//! and never stiffer than `k`, so the implicit step's matrix stays positive
//! definite and the explicit step bound of a spring of stiffness `k`
//! (`timestep.rs`) still holds. Because the capped force is conservative, the
//! energy the run checks each frame (`sim::pipeline`) is the energy the forces
//! do work against.
//!
//! The capped springs stay in the springs kind's springs
//! ([`super::kinds::SpringSet`]), so every per-vertex list, the block pattern
//! and the solvers treat them as springs; its `caps` lists them with their
//! caps. The springs kind (`kinds/springs.rs`) computes
//! every spring as usual and then overwrites the few capped ones (forces,
//! energy, the implicit blocks), so the loops over the ordinary springs are
//! unchanged; a multirate kick looks each of its springs up among the caps.
//! Within `d0` a capped spring's force, energy and blocks are the uncapped
//! spring's to the last bit, so a cap that is never reached changes nothing.

use super::block::outer;
use super::elements::{Elements, MaterialParams};
use super::forces::spring_force;
use super::kinds::Spring;
use crate::math::{Matrix3, Scalar, Vector, deterministic_sum};
use crate::mesh::Mesh;

/// A sewing spring with a maximum force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpringCap {
    /// The spring's index in [`super::kinds::SpringSet::springs`] (a zero-length spring).
    pub spring: u32,
    /// The largest force it pulls with, N.
    pub max_force: Scalar,
}

/// A zero-length spring between the two vertices of each pair of every open
/// seam, appended to `springs`: stiffness the seam's (per metre) times the
/// pair's share of the seam's length, so the pull per metre of seam does not
/// depend on how finely it is sampled; damped like the stretch springs. A seam
/// with a `max_force` caps each pair's force at it times the same share, each
/// such spring listed in `caps` (cleared first).
pub(crate) fn sewing_springs(
    mesh: &Mesh,
    mat: &MaterialParams,
    springs: &mut Vec<Spring>,
    caps: &mut Vec<SpringCap>,
) {
    caps.clear();
    for seam in mesh.seams().iter().filter(|s| s.is_open()) {
        for (pair, share) in seam.pairs.iter().zip(seam.pair_lengths(mesh)) {
            let k = mat.sewing.stiffness * share;
            if let Some(max_force) = mat.sewing.max_force {
                caps.push(SpringCap {
                    spring: springs.len() as u32,
                    max_force: max_force * share,
                });
            }
            springs.push(Spring {
                v: *pair,
                rest: 0.0,
                k,
                c: mat.damping * k,
            });
        }
    }
}

/// The force of a zero-length spring of stiffness `k`, damping `c` and cap
/// `max_force` on its first end `a` (the second end gets the opposite):
/// `(min(k l, F) + c (v_b - v_a) . d) d` with `l` the distance and `d` the unit
/// vector from a to b. Up to the cap it is [`spring_force`]'s bit for bit.
#[inline]
pub fn capped_spring_force(
    xa: Vector,
    xb: Vector,
    va: Vector,
    vb: Vector,
    k: Scalar,
    c: Scalar,
    max_force: Scalar,
) -> Vector {
    let d = xb - xa;
    let len = d.length();
    if k * len <= max_force {
        return spring_force(xa, xb, va, vb, 0.0, k, c);
    }
    let dir = d / len;
    dir * (max_force + c * (vb - va).dot(dir))
}

/// The Huber energy of a zero-length spring of stiffness `k` and cap
/// `max_force` stretched to length `len` (module docs), J.
pub fn capped_spring_energy(len: Scalar, k: Scalar, max_force: Scalar) -> Scalar {
    if k * len <= max_force {
        0.5 * k * len * len
    } else {
        max_force * (len - 0.5 * max_force / k)
    }
}

/// The Hessian of [`capped_spring_energy`] with respect to the second end at
/// separation `d = x_b - x_a`: `k I` up to the cap (in the uncapped spring's
/// own form, `k (n n^T + (I - n n^T))`), `(F / l) (I - n n^T)` beyond.
pub fn capped_spring_stiffness(d: Vector, k: Scalar, max_force: Scalar) -> Matrix3 {
    let len = d.length();
    let dir = if len > 0.0 { d / len } else { Vector::ZERO };
    let nn = outer(dir, dir);
    if k * len <= max_force {
        let transverse = if len > 0.0 { 1.0 } else { 0.0 };
        (nn + (Matrix3::IDENTITY - nn) * transverse) * k
    } else {
        (Matrix3::IDENTITY - nn) * (max_force / len)
    }
}

/// Writes the capped springs' forces at `(x, v)` over their slots in `slots`
/// (one per spring, the force on its first end).
pub fn cap_forces(el: &Elements, x: &[Vector], v: &[Vector], slots: &mut [Vector]) {
    for cap in &el.kinds.springs.caps {
        slots[cap.spring as usize] = cap_force(el, cap, x, v);
    }
}

/// The force of one capped spring on its first end.
#[inline]
pub(super) fn cap_force(el: &Elements, cap: &SpringCap, x: &[Vector], v: &[Vector]) -> Vector {
    let sp = &el.kinds.springs.springs[cap.spring as usize];
    let [a, b] = [sp.v[0] as usize, sp.v[1] as usize];
    capped_spring_force(x[a], x[b], v[a], v[b], sp.k, sp.c, cap.max_force)
}

/// What the caps change in the springs' energy at `x`: the sum over capped
/// springs of their Huber energy minus the quadratic energy the plain sum
/// counted, `-k (l - d0)^2 / 2` beyond the cap and exactly zero within it, J.
pub fn cap_energy_change(el: &Elements, x: &[Vector]) -> Scalar {
    deterministic_sum(el.kinds.springs.caps.len(), |c| {
        let cap = &el.kinds.springs.caps[c];
        let sp = &el.kinds.springs.springs[cap.spring as usize];
        let len = x[sp.v[1] as usize].distance(x[sp.v[0] as usize]);
        let beyond = len - cap.max_force / sp.k;
        if sp.k * len <= cap.max_force {
            0.0
        } else {
            -0.5 * sp.k * beyond * beyond
        }
    })
}
