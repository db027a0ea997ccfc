//! The dihedral hinges kind (`bending.rs`): four force slots per hinge, one
//! per vertex; in the implicit step the Gauss-Newton block `k g g^T` of the
//! angle's gradient `g`.

use rayon::prelude::*;

use super::{ForceKind, kick_slots, lower_pairs, lower_stride, stretch_blocks};
use crate::math::{Matrix3, Scalar, Vector, deterministic_sum};
use crate::mesh::Mesh;
use crate::physics::bending::dihedral_angle_and_gradient;
use crate::physics::block::outer;
use crate::physics::elements::{BuildContext, Elements, Incidence, MaterialParams};
use crate::physics::forces::PAR_MIN;
use crate::spec::BendingModel;

/// The dihedral hinges kind: the hinges of [`HingeSet`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Hinges;
/// A dihedral bending hinge: `v[0], v[1]` span the edge, `v[2], v[3]` are the wing tips.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hinge {
    /// Vertices: edge start, edge end, tip of the first wing, tip of the second.
    pub v: [u32; 4],
    /// Angular stiffness, N m (energy `k theta^2 / 2`).
    pub k: Scalar,
}

/// The hinges of one mesh and their incidence lists.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HingeSet {
    /// Dihedral hinges (only with the dihedral model and non-zero rigidity).
    pub hinges: Vec<Hinge>,
    /// Hinge slots `4 * hinge + k` where the vertex is `v[k]`.
    pub slots: Incidence,
}

/// One hinge per interior edge with the dihedral model and non-zero rigidity
/// (`elements.rs`, "Stiffness derivations"), into `hinges` (cleared first).
fn dihedral_hinges(mesh: &Mesh, mat: &MaterialParams, area: &[Scalar], hinges: &mut Vec<Hinge>) {
    hinges.clear();
    if mat.bending <= 0.0 || mat.bending_model != BendingModel::Dihedral {
        return;
    }
    for (e, edge) in mesh
        .edges
        .iter()
        .enumerate()
        .filter(|(_, e)| e.is_interior())
    {
        let [t0, t1] = edge.triangles;
        // Orient the edge as it runs in t0 (counter-clockwise) so that the
        // signed angle has a consistent meaning.
        let [a, b] = oriented_in(&mesh.triangles[t0 as usize], edge.vertices);
        let (p, q) = (
            mesh.opposite_vertex(t0, edge),
            mesh.opposite_vertex(t1, edge),
        );
        let len = mesh.rest_length(e);
        let k = mat.bending * len * len / (area[t0 as usize] + area[t1 as usize]);
        hinges.push(Hinge { v: [a, b, p, q], k });
    }
}

/// The edge `[a, b]` in the order it runs inside triangle `tri`.
fn oriented_in(tri: &[u32; 3], [a, b]: [u32; 2]) -> [u32; 2] {
    for k in 0..3 {
        if tri[k] == a && tri[(k + 1) % 3] == b {
            return [a, b];
        }
    }
    [b, a]
}

/// The hinges' terms of the linearised step.
#[derive(Debug, Default, Clone)]
pub struct HingeLinear {
    /// Per hinge and vertex: the angle's gradient.
    pub grad: Vec<Vector>,
    /// Per hinge: `h^2 k`.
    pub coef: Vec<Scalar>,
    /// Per hinge and vertex: its right-hand side slot, then its slot of a product.
    pub slot: Vec<Vector>,
    /// Per hinge, its lower blocks `h^2 k g_k g_l^T` in [`lower_pairs`]
    /// order, each hinge a stretch of [`stride`] (the direct solver only).
    pub lower: Vec<Matrix3>,
}

/// The length of each hinge's stretch of [`HingeLinear::lower`]: the most
/// lower blocks of a hinge (10 for four distinct vertices).
fn stride(el: &Elements) -> usize {
    lower_stride(el.kinds.hinges.hinges.iter().map(|h| &h.v[..]))
}

impl ForceKind for Hinges {
    type Set = HingeSet;
    type Deferred = ();
    type Forces = Vec<Vector>;
    type Linear = HingeLinear;
    type Kick = Vec<[Vector; 4]>;
    type InPlace = ();
    const ENERGY_RANK: usize = 2;

    /// One hinge per interior edge (dihedral model) and their slots'
    /// incidence lists.
    fn build(cx: &BuildContext<'_>, set: &mut HingeSet) {
        dihedral_hinges(cx.mesh, cx.mat, cx.area, &mut set.hinges);
        set.slots.fill(
            cx.mesh.vertex_count(),
            set.hinges
                .iter()
                .enumerate()
                .flat_map(|(h, hg)| (0..4).map(move |k| (hg.v[k], (4 * h + k) as u32))),
        );
    }

    fn count(el: &Elements) -> usize {
        el.kinds.hinges.hinges.len()
    }

    fn element_vertices(el: &Elements, e: usize, out: &mut Vec<u32>) {
        out.clear();
        out.extend(el.kinds.hinges.hinges[e].v);
    }

    fn kick(
        el: &Elements,
        ids: &[u32],
        x: &[Vector],
        _v: &[Vector],
        out: &mut Vec<Vector>,
        kick: &mut Vec<[Vector; 4]>,
    ) {
        kick_slots(ids, 256, out, kick, |h| {
            let hg = &el.kinds.hinges.hinges[h];
            let (theta, grad) = dihedral_angle_and_gradient(hg.v.map(|i| x[i as usize]));
            grad.map(|gk| gk * (-hg.k * theta))
        });
    }

    fn size_forces(el: &Elements, out: &mut Vec<Vector>) {
        out.resize(4 * el.kinds.hinges.hinges.len(), Vector::ZERO);
    }

    fn forces(el: &Elements, x: &[Vector], _v: &[Vector], out: &mut Vec<Vector>) {
        Self::size_forces(el, out);
        out.par_chunks_exact_mut(4)
            .with_min_len(PAR_MIN / 4)
            .zip(el.kinds.hinges.hinges.par_iter())
            .for_each(|(f, h)| {
                let (theta, g) = dihedral_angle_and_gradient(h.v.map(|i| x[i as usize]));
                for k in 0..4 {
                    f[k] = g[k] * (-h.k * theta);
                }
            });
    }

    #[inline(always)]
    fn gather_force(el: &Elements, out: &Vec<Vector>, i: usize, f: &mut Vector) {
        for &s in el.kinds.hinges.slots.of(i) {
            *f += out[s as usize];
        }
    }

    fn energy(el: &Elements, x: &[Vector]) -> Scalar {
        deterministic_sum(el.kinds.hinges.hinges.len(), |h| {
            let hg = &el.kinds.hinges.hinges[h];
            let (theta, _) = dihedral_angle_and_gradient(hg.v.map(|i| x[i as usize]));
            0.5 * hg.k * theta * theta
        })
    }

    /// Per hinge: the angle's gradient, `h^2 k` and the four slots.
    fn linearise(
        el: &Elements,
        x: &[Vector],
        v: &[Vector],
        h: Scalar,
        k_term: Scalar,
        lin: &mut HingeLinear,
    ) {
        let hinges = el.kinds.hinges.hinges.len();
        lin.grad.resize(4 * hinges, Vector::ZERO);
        lin.coef.resize(hinges, 0.0);
        lin.slot.resize(4 * hinges, Vector::ZERO);
        lin.grad
            .par_chunks_exact_mut(4)
            .zip(lin.slot.par_chunks_exact_mut(4))
            .zip(lin.coef.par_iter_mut())
            .zip(el.kinds.hinges.hinges.par_iter())
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

    #[inline(always)]
    fn gather_linear(
        el: &Elements,
        lin: &HingeLinear,
        i: usize,
        _h: Scalar,
        jacobi: bool,
        rhs: &mut Vector,
        diag: &mut Vector,
    ) {
        for &k in el.kinds.hinges.slots.of(i) {
            *rhs += lin.slot[k as usize];
            if jacobi {
                let g = lin.grad[k as usize];
                *diag += g * g * lin.coef[k as usize / 4];
            }
        }
    }

    fn product(el: &Elements, lin: &mut HingeLinear, p: &[Vector], _h2: Scalar) {
        lin.slot
            .par_chunks_exact_mut(4)
            .zip(lin.grad.par_chunks_exact(4))
            .zip(lin.coef.par_iter())
            .zip(el.kinds.hinges.hinges.par_iter())
            .with_min_len(PAR_MIN / 4)
            .for_each(|(((slot, g), coef), hg)| {
                let gp: Scalar = (0..4).map(|k| g[k].dot(p[hg.v[k] as usize])).sum();
                for k in 0..4 {
                    slot[k] = g[k] * (coef * gp);
                }
            });
    }

    #[inline(always)]
    fn gather_product(el: &Elements, lin: &HingeLinear, i: usize, acc: &mut Vector) {
        for &k in el.kinds.hinges.slots.of(i) {
            *acc += lin.slot[k as usize];
        }
    }

    fn coupling_count(el: &Elements) -> usize {
        12 * el.kinds.hinges.hinges.len()
    }

    fn couplings(el: &Elements, pairs: &mut Vec<(u32, u32)>) {
        for hg in &el.kinds.hinges.hinges {
            for k in 0..4 {
                for l in 0..4 {
                    if k != l {
                        pairs.push((hg.v[k], hg.v[l]));
                    }
                }
            }
        }
    }

    /// Its lower blocks `h^2 k g_k g_l^T`, a stretch per hinge.
    fn listed_blocks(el: &Elements, f: impl FnMut(u32, u32, u32, bool)) {
        let hinges = el.kinds.hinges.hinges.iter().map(|h| &h.v[..]);
        stretch_blocks(hinges, 0b1111, stride(el), f);
    }

    fn write_blocks(el: &Elements, lin: &mut HingeLinear) {
        if el.kinds.hinges.hinges.is_empty() {
            return;
        }
        let stride = stride(el);
        lin.lower
            .resize(stride * el.kinds.hinges.hinges.len(), Matrix3::ZERO);
        lin.lower
            .par_chunks_mut(stride)
            .zip(lin.grad.par_chunks_exact(4))
            .zip(lin.coef.par_iter())
            .zip(el.kinds.hinges.hinges.par_iter())
            .with_min_len(PAR_MIN / 4)
            .for_each(|(((out, g), &c), hinge)| {
                let mut w = 0;
                lower_pairs(&hinge.v, 0b1111, |k, l| {
                    out[w] = outer(g[k], g[l]) * c;
                    w += 1;
                });
            });
    }

    fn block_values(lin: &HingeLinear) -> &[Matrix3] {
        &lin.lower
    }

    /// The factorization drops a hinge's tip-tip block unless another kind
    /// couples the tips (`block.rs`, "The factored matrix"): `c g_p g_p^T` on
    /// tip `p`'s diagonal and `c g_q g_q^T` on `q`'s (terms: slots `4 h + k`).
    fn dropped_terms(
        el: &Elements,
        factored: impl Fn(u32, u32) -> bool,
        mut f: impl FnMut(u32, u32),
    ) {
        for (h, hg) in el.kinds.hinges.hinges.iter().enumerate() {
            let (tip_p, tip_q) = (hg.v[2], hg.v[3]);
            if !factored(tip_p, tip_q) {
                f(tip_p, 4 * h as u32 + 2);
                f(tip_q, 4 * h as u32 + 3);
            }
        }
    }

    #[inline(always)]
    fn dropped_block(lin: &HingeLinear, k: u32) -> Matrix3 {
        let g = lin.grad[k as usize];
        outer(g, g) * lin.coef[k as usize / 4]
    }

    fn gershgorin(
        el: &Elements,
        mesh: &Mesh,
        flat: &mut [Vector],
        stiff: &mut [Scalar],
        _damp: &mut [Scalar],
    ) {
        // A garment's stencils are laid flat one by one (`Mesh::lay_flat`).
        let garment = mesh.panels().is_some();
        for hg in &el.kinds.hinges.hinges {
            if garment {
                mesh.lay_flat(&hg.v, flat);
            }
            let (_, g) = dihedral_angle_and_gradient(hg.v.map(|i| flat[i as usize]));
            let sum: Scalar = g.iter().map(|gi| gi.length()).sum();
            for k in 0..4 {
                stiff[hg.v[k] as usize] += hg.k * g[k].length() * sum;
            }
        }
    }
}
