//! The attachments kind: each vertex a garment's attachment holds
//! ([`crate::mesh::Hold`]) is kept on the side of the attachment's plane its
//! normal points to by a one-sided spring, until the attachment's release
//! time, as GarmentCode holds a pattern's labelled edges at the body.
//!
//! A held vertex at `x` with `d = n . (x - p) < 0` (behind the plane through
//! `p` with unit normal `n`) is pulled back along `n` with the force
//! `-(k d + c n . v) n`, energy `k d^2 / 2`; in front of the plane it feels
//! nothing. `k` is the attachment's stiffness per metre times the vertex's
//! share of the held sides' rest length ([`crate::mesh::Hold::shares`]), so
//! the pull per metre of side does not depend on the mesh; `c` is the
//! material's stiffness-proportional damping times `k`, as for a spring.
//! One slot per held vertex; the blocks are on the diagonal only.
//!
//! The elements exist while the attachment holds: they are built for the
//! attachments that hold at the world's time (`Stepper::rebuild`), and the
//! pipeline rebuilds them once a release time has passed.

use rayon::prelude::*;

use super::{ForceKind, kick_slots};
use crate::math::{Matrix3, Scalar, Vector, deterministic_sum};
use crate::mesh::Mesh;
use crate::physics::block::outer;
use crate::physics::elements::{BuildContext, Elements, Incidence};
use crate::physics::forces::PAR_MIN;

use super::springs::matrix_diagonal;

/// The attachments kind: the held vertices of [`AttachmentSet`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Attachments;

/// One held vertex: its plane and its one-sided spring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeldVertex {
    /// The vertex.
    pub v: u32,
    /// A point of the plane, m.
    pub point: Vector,
    /// The plane's unit normal (the side the vertex is kept on).
    pub normal: Vector,
    /// Stiffness, N/m.
    pub k: Scalar,
    /// Damping coefficient along the normal, N s/m.
    pub c: Scalar,
}

impl HeldVertex {
    /// How far `x` lies behind the plane, as a negative distance (`None` in
    /// front of it or on it: no force).
    #[inline(always)]
    fn depth(&self, x: Vector) -> Option<Scalar> {
        let d = self.normal.dot(x - self.point);
        (d < 0.0).then_some(d)
    }

    /// The force at position `x` and velocity `v`, N.
    #[inline(always)]
    fn force(&self, x: Vector, v: Vector) -> Vector {
        match self.depth(x) {
            Some(d) => self.normal * -(self.k * d + self.c * self.normal.dot(v)),
            None => Vector::ZERO,
        }
    }
}

/// The held vertices of one mesh and their incidence lists.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct AttachmentSet {
    /// Per attachment that holds, per held vertex, in hold and chain order.
    pub held: Vec<HeldVertex>,
    /// The held entries of each vertex.
    pub at: Incidence,
}

/// The attachments' terms of the linearised step.
#[derive(Debug, Default, Clone)]
pub struct AttachmentLinear {
    /// Per held vertex: `h^2 K + h D` (zero in front of the plane).
    pub block: Vec<Matrix3>,
    /// Per held vertex: its right-hand side slot, then its slot of a product.
    pub slot: Vec<Vector>,
}

impl ForceKind for Attachments {
    type Set = AttachmentSet;
    type Deferred = ();
    type Forces = Vec<Vector>;
    type Linear = AttachmentLinear;
    type Kick = Vec<[Vector; 1]>;
    type InPlace = ();
    const ENERGY_RANK: usize = 4;

    /// One element per vertex of each hold whose attachment holds at the
    /// context's time.
    fn build(cx: &BuildContext<'_>, set: &mut AttachmentSet) {
        set.held.clear();
        let holds = cx.mesh.holds();
        for (hold, a) in holds.iter().zip(cx.holding.attachments) {
            if !a.holds_at(cx.holding.time) {
                continue;
            }
            for (v, share) in hold.shares(cx.mesh) {
                let k = a.stiffness * share;
                set.held.push(HeldVertex {
                    v,
                    point: a.point,
                    normal: a.normal,
                    k,
                    c: cx.mat.damping * k,
                });
            }
        }
        let pairs = set.held.iter().enumerate().map(|(e, h)| (h.v, e as u32));
        set.at.fill(cx.mesh.vertex_count(), pairs);
    }

    fn count(el: &Elements) -> usize {
        el.kinds.attachments.held.len()
    }

    fn element_vertices(el: &Elements, e: usize, out: &mut Vec<u32>) {
        out.clear();
        out.push(el.kinds.attachments.held[e].v);
    }

    fn kick(
        el: &Elements,
        ids: &[u32],
        x: &[Vector],
        v: &[Vector],
        out: &mut Vec<Vector>,
        kick: &mut Vec<[Vector; 1]>,
    ) {
        kick_slots(ids, 512, out, kick, |e| {
            let h = &el.kinds.attachments.held[e];
            [h.force(x[h.v as usize], v[h.v as usize])]
        });
    }

    fn size_forces(el: &Elements, out: &mut Vec<Vector>) {
        out.resize(el.kinds.attachments.held.len(), Vector::ZERO);
    }

    fn forces(el: &Elements, x: &[Vector], v: &[Vector], out: &mut Vec<Vector>) {
        Self::size_forces(el, out);
        out.par_iter_mut()
            .with_min_len(PAR_MIN)
            .zip(el.kinds.attachments.held.par_iter())
            .for_each(|(f, h)| *f = h.force(x[h.v as usize], v[h.v as usize]));
    }

    #[inline(always)]
    fn gather_force(el: &Elements, out: &Vec<Vector>, i: usize, f: &mut Vector) {
        for &e in el.kinds.attachments.at.of(i) {
            *f += out[e as usize];
        }
    }

    fn energy(el: &Elements, x: &[Vector]) -> Scalar {
        let held = &el.kinds.attachments.held;
        deterministic_sum(held.len(), |e| {
            let h = &held[e];
            h.depth(x[h.v as usize]).map_or(0.0, |d| 0.5 * h.k * d * d)
        })
    }

    /// Per held vertex behind its plane: the block `h^2 k n n^T + h c n n^T`
    /// and the slot `h f - h^2 k n n^T v`; zero in front of it.
    fn linearise(
        el: &Elements,
        x: &[Vector],
        v: &[Vector],
        h: Scalar,
        k_term: Scalar,
        lin: &mut AttachmentLinear,
    ) {
        let held = &el.kinds.attachments.held;
        lin.block.resize(held.len(), Matrix3::ZERO);
        lin.slot.resize(held.len(), Vector::ZERO);
        lin.block
            .par_iter_mut()
            .zip(lin.slot.par_iter_mut())
            .zip(held.par_iter())
            .with_min_len(PAR_MIN)
            .for_each(|((block, slot), hv)| {
                let (xi, vi) = (x[hv.v as usize], v[hv.v as usize]);
                if hv.depth(xi).is_none() {
                    (*block, *slot) = (Matrix3::ZERO, Vector::ZERO);
                    return;
                }
                let nn = outer(hv.normal, hv.normal);
                let stiff = nn * hv.k;
                *block = stiff * (h * h) + nn * (h * hv.c);
                *slot = hv.force(xi, vi) * h - stiff * vi * (h * h * k_term);
            });
    }

    #[inline(always)]
    fn gather_linear(
        el: &Elements,
        lin: &AttachmentLinear,
        i: usize,
        _h: Scalar,
        jacobi: bool,
        rhs: &mut Vector,
        diag: &mut Vector,
    ) {
        for &e in el.kinds.attachments.at.of(i) {
            *rhs += lin.slot[e as usize];
            if jacobi {
                *diag += matrix_diagonal(&lin.block[e as usize]);
            }
        }
    }

    fn product(el: &Elements, lin: &mut AttachmentLinear, p: &[Vector], _h2: Scalar) {
        lin.slot
            .par_iter_mut()
            .zip(lin.block.par_iter())
            .zip(el.kinds.attachments.held.par_iter())
            .with_min_len(PAR_MIN)
            .for_each(|((q, block), hv)| *q = *block * p[hv.v as usize]);
    }

    #[inline(always)]
    fn gather_product(el: &Elements, lin: &AttachmentLinear, i: usize, acc: &mut Vector) {
        for &e in el.kinds.attachments.at.of(i) {
            *acc += lin.slot[e as usize];
        }
    }

    fn coupling_count(_el: &Elements) -> usize {
        0
    }

    /// None: each block is on its vertex's diagonal.
    fn couplings(_el: &Elements, _pairs: &mut Vec<(u32, u32)>) {}

    /// One value per held vertex, its block, on its diagonal.
    fn listed_blocks(el: &Elements, mut f: impl FnMut(u32, u32, u32, bool)) {
        for (e, hv) in el.kinds.attachments.held.iter().enumerate() {
            f(hv.v, hv.v, e as u32, false);
        }
    }

    fn block_values(lin: &AttachmentLinear) -> &[Matrix3] {
        &lin.block
    }

    fn gershgorin(
        el: &Elements,
        _mesh: &Mesh,
        _flat: &mut [Vector],
        stiff: &mut [Scalar],
        damp: &mut [Scalar],
    ) {
        for hv in &el.kinds.attachments.held {
            stiff[hv.v as usize] += hv.k;
            damp[hv.v as usize] += hv.c;
        }
    }
}
