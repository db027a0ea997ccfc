//! The membrane triangles kind (`membrane.rs`): one force slot per corner; in
//! the implicit step the block `h^2 K_t + h D_t` over the deformation
//! gradient's columns.

use rayon::prelude::*;

use super::springs::matrix_diagonal;
use super::{ForceKind, kick_slots, lower_pairs, lower_stride, slot_pairs, stretch_blocks};
use crate::math::{Matrix3, Scalar, Vector, deterministic_sum};
use crate::mesh::Mesh;
use crate::physics::elements::{BuildContext, Elements, Incidence};
use crate::physics::forces::PAR_MIN;
use crate::physics::membrane::{ColumnBlocks, MEMBRANE_SLOTS, Membrane, MembraneTriangle};

/// The membrane triangles kind: the triangles of [`MembraneSet`].
#[derive(Debug, Clone, Copy, Default)]
pub struct MembraneTriangles;
/// The membrane triangles of one mesh and their incidence lists.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MembraneSet {
    /// Continuum membrane triangles, one per triangle (with
    /// [`Membrane::Triangles`]).
    pub triangles: Vec<MembraneTriangle>,
    /// Membrane-triangle slots `MEMBRANE_SLOTS * element + k` where the vertex
    /// is `v[k]`.
    pub slots: Incidence,
}

/// The membrane triangles' terms of the linearised step.
#[derive(Debug, Default, Clone)]
pub struct MembraneLinear {
    /// Per triangle: `h^2 K_t + h D_t` over its deformation gradient's columns.
    pub block: Vec<ColumnBlocks>,
    /// Per triangle and corner: its right-hand side slot, then its slot of a product.
    pub slot: Vec<Vector>,
    /// Per triangle, its lower blocks in [`lower_pairs`] order, each triangle
    /// a stretch of [`stride`] (the direct solver only).
    pub lower: Vec<Matrix3>,
}

/// The length of each triangle's stretch of [`MembraneLinear::lower`]: the
/// most lower blocks of a triangle (6).
fn stride(el: &Elements) -> usize {
    lower_stride(el.kinds.membrane.triangles.iter().map(|t| &t.v[..]))
}

impl ForceKind for MembraneTriangles {
    type Set = MembraneSet;
    type Deferred = ();
    type Forces = Vec<Vector>;
    type Linear = MembraneLinear;
    type Kick = Vec<[Vector; MEMBRANE_SLOTS]>;
    type InPlace = ();
    const ENERGY_RANK: usize = 1;

    /// One membrane triangle per triangle with the triangles membrane
    /// (`membrane.rs`), none with the springs, and their corners' incidence
    /// lists.
    fn build(cx: &BuildContext<'_>, set: &mut MembraneSet) {
        let (mesh, out) = (cx.mesh, &mut set.triangles);
        out.clear();
        if let Membrane::Triangles(moduli) = &cx.mat.membrane {
            out.extend(
                mesh.triangles
                    .iter()
                    .zip(cx.area)
                    .enumerate()
                    .map(|(t, (tri, &a))| {
                        MembraneTriangle::new(*tri, mesh.corners(t), a, moduli, cx.mat.damping)
                    }),
            );
        }
        set.slots.fill(
            mesh.vertex_count(),
            set.triangles.iter().enumerate().flat_map(|(t, m)| {
                (0..MEMBRANE_SLOTS).map(move |k| (m.v[k], (MEMBRANE_SLOTS * t + k) as u32))
            }),
        );
    }

    fn count(el: &Elements) -> usize {
        el.kinds.membrane.triangles.len()
    }

    fn element_vertices(el: &Elements, e: usize, out: &mut Vec<u32>) {
        out.clear();
        out.extend(el.kinds.membrane.triangles[e].v);
    }

    fn kick(
        el: &Elements,
        ids: &[u32],
        x: &[Vector],
        v: &[Vector],
        out: &mut Vec<Vector>,
        kick: &mut Vec<[Vector; MEMBRANE_SLOTS]>,
    ) {
        kick_slots(ids, 256, out, kick, |t| {
            let mut f = [Vector::ZERO; MEMBRANE_SLOTS];
            el.kinds.membrane.triangles[t].forces(x, v, &mut f);
            f
        });
    }

    fn size_forces(el: &Elements, out: &mut Vec<Vector>) {
        out.resize(
            MEMBRANE_SLOTS * el.kinds.membrane.triangles.len(),
            Vector::ZERO,
        );
    }

    fn forces(el: &Elements, x: &[Vector], v: &[Vector], out: &mut Vec<Vector>) {
        Self::size_forces(el, out);
        out.par_chunks_exact_mut(MEMBRANE_SLOTS)
            .with_min_len(PAR_MIN / MEMBRANE_SLOTS)
            .zip(el.kinds.membrane.triangles.par_iter())
            .for_each(|(f, t)| t.forces(x, v, f));
    }

    #[inline(always)]
    fn gather_force(el: &Elements, out: &Vec<Vector>, i: usize, f: &mut Vector) {
        for &s in el.kinds.membrane.slots.of(i) {
            *f += out[s as usize];
        }
    }

    fn energy(el: &Elements, x: &[Vector]) -> Scalar {
        deterministic_sum(el.kinds.membrane.triangles.len(), |t| {
            el.kinds.membrane.triangles[t].energy(x)
        })
    }

    /// Per membrane triangle: the block `h^2 K_t + h D_t` over the columns and the
    /// slots `h f_t - h^2 K_t v`.
    fn linearise(
        el: &Elements,
        x: &[Vector],
        v: &[Vector],
        h: Scalar,
        k_term: Scalar,
        lin: &mut MembraneLinear,
    ) {
        let count = el.kinds.membrane.triangles.len();
        lin.block.resize(count, ColumnBlocks::ZERO);
        lin.slot.resize(MEMBRANE_SLOTS * count, Vector::ZERO);
        lin.slot
            .par_chunks_exact_mut(MEMBRANE_SLOTS)
            .zip(lin.block.par_iter_mut())
            .zip(el.kinds.membrane.triangles.par_iter())
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

    #[inline(always)]
    fn gather_linear(
        el: &Elements,
        lin: &MembraneLinear,
        i: usize,
        _h: Scalar,
        jacobi: bool,
        rhs: &mut Vector,
        diag: &mut Vector,
    ) {
        for &k in el.kinds.membrane.slots.of(i) {
            *rhs += lin.slot[k as usize];
            if jacobi {
                let (t, slot) = (k as usize / MEMBRANE_SLOTS, k as usize % MEMBRANE_SLOTS);
                let m = el.kinds.membrane.triangles[t].block(&lin.block[t], slot, slot);
                *diag += matrix_diagonal(&m);
            }
        }
    }

    fn product(el: &Elements, lin: &mut MembraneLinear, p: &[Vector], _h2: Scalar) {
        lin.slot
            .par_chunks_exact_mut(MEMBRANE_SLOTS)
            .zip(lin.block.par_iter())
            .zip(el.kinds.membrane.triangles.par_iter())
            .with_min_len(PAR_MIN / MEMBRANE_SLOTS)
            .for_each(|((slot, block), t)| t.apply(block, p, slot));
    }

    #[inline(always)]
    fn gather_product(el: &Elements, lin: &MembraneLinear, i: usize, acc: &mut Vector) {
        for &k in el.kinds.membrane.slots.of(i) {
            *acc += lin.slot[k as usize];
        }
    }

    fn coupling_count(el: &Elements) -> usize {
        6 * el.kinds.membrane.triangles.len()
    }

    fn couplings(el: &Elements, pairs: &mut Vec<(u32, u32)>) {
        for t in &el.kinds.membrane.triangles {
            slot_pairs(t.v.into_iter().enumerate(), pairs);
        }
    }

    /// Its lower blocks over the columns, a stretch per triangle.
    fn listed_blocks(el: &Elements, f: impl FnMut(u32, u32, u32, bool)) {
        let triangles = el.kinds.membrane.triangles.iter().map(|t| &t.v[..]);
        stretch_blocks(triangles, 0b111, stride(el), f);
    }

    fn write_blocks(el: &Elements, lin: &mut MembraneLinear) {
        if el.kinds.membrane.triangles.is_empty() {
            return;
        }
        let stride = stride(el);
        lin.lower
            .resize(stride * el.kinds.membrane.triangles.len(), Matrix3::ZERO);
        lin.lower
            .par_chunks_mut(stride)
            .zip(el.kinds.membrane.triangles.par_iter())
            .zip(lin.block.par_iter())
            .with_min_len(PAR_MIN / 4)
            .for_each(|((out, t), m)| {
                let mut w = 0;
                lower_pairs(&t.v, 0b111, |k, l| {
                    out[w] = t.block(m, k, l);
                    w += 1;
                });
            });
    }

    fn block_values(lin: &MembraneLinear) -> &[Matrix3] {
        &lin.lower
    }

    /// A membrane triangle couples the ends of its edges, as the springs do:
    /// the factorization keeps them.
    fn factored_pairs(el: &Elements, mut f: impl FnMut(u32, u32)) {
        for t in &el.kinds.membrane.triangles {
            for i in t.v {
                for j in t.v {
                    f(i, j);
                }
            }
        }
    }

    fn gershgorin(
        el: &Elements,
        mesh: &Mesh,
        flat: &mut [Vector],
        stiff: &mut [Scalar],
        damp: &mut [Scalar],
    ) {
        let garment = mesh.panels().is_some();
        for t in &el.kinds.membrane.triangles {
            // Gershgorin bound of the rest stiffness (Gauss-Newton; no stress at rest).
            if garment {
                mesh.lay_flat(&t.v, flat);
            }
            let (gauss_newton, _) = t.stiffness(flat);
            for i in 0..3 {
                let mut rows = Vector::ZERO;
                for j in 0..3 {
                    let b = t.block(&gauss_newton, i, j);
                    rows += b.x_axis.abs() + b.y_axis.abs() + b.z_axis.abs();
                }
                let bound = rows.max_element();
                stiff[t.v[i] as usize] += bound;
                damp[t.v[i] as usize] += t.damping * bound;
            }
        }
    }
}
