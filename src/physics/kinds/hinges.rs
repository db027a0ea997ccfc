//! The dihedral hinges kind (`bending.rs`): four force slots per hinge, one
//! per vertex; in the implicit step the Gauss-Newton block `k g g^T` of the
//! angle's gradient `g`.

use rayon::prelude::*;

use super::{ForceKind, kick_slots};
use crate::math::{Scalar, Vector, deterministic_sum};
use crate::mesh::Mesh;
use crate::physics::bending::dihedral_angle_and_gradient;
use crate::physics::elements::Elements;
use crate::physics::forces::PAR_MIN;

/// The hinges of [`Elements::hinges`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Hinges;

/// The hinges' terms of the linearised step.
#[derive(Debug, Default, Clone)]
pub struct HingeLinear {
    /// Per hinge and vertex: the angle's gradient.
    pub grad: Vec<Vector>,
    /// Per hinge: `h^2 k`.
    pub coef: Vec<Scalar>,
    /// Per hinge and vertex: its right-hand side slot, then its slot of a product.
    pub slot: Vec<Vector>,
}

impl ForceKind for Hinges {
    type Forces = Vec<Vector>;
    type Linear = HingeLinear;
    type Kick = Vec<[Vector; 4]>;
    const ENERGY_RANK: usize = 2;

    fn count(el: &Elements) -> usize {
        el.hinges.len()
    }

    fn element_vertices(el: &Elements, e: usize, out: &mut Vec<u32>) {
        out.clear();
        out.extend(el.hinges[e].v);
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
            let hg = &el.hinges[h];
            let (theta, grad) = dihedral_angle_and_gradient(hg.v.map(|i| x[i as usize]));
            grad.map(|gk| gk * (-hg.k * theta))
        });
    }

    fn size_forces(el: &Elements, out: &mut Vec<Vector>) {
        out.resize(4 * el.hinges.len(), Vector::ZERO);
    }

    fn forces(el: &Elements, x: &[Vector], _v: &[Vector], out: &mut Vec<Vector>) {
        Self::size_forces(el, out);
        out.par_chunks_exact_mut(4)
            .with_min_len(PAR_MIN / 4)
            .zip(el.hinges.par_iter())
            .for_each(|(f, h)| {
                let (theta, g) = dihedral_angle_and_gradient(h.v.map(|i| x[i as usize]));
                for k in 0..4 {
                    f[k] = g[k] * (-h.k * theta);
                }
            });
    }

    #[inline(always)]
    fn gather_force(el: &Elements, out: &Vec<Vector>, i: usize, f: &mut Vector) {
        for &s in el.hinge_slots.of(i) {
            *f += out[s as usize];
        }
    }

    fn energy(el: &Elements, x: &[Vector]) -> Scalar {
        deterministic_sum(el.hinges.len(), |h| {
            let hg = &el.hinges[h];
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
        let hinges = el.hinges.len();
        lin.grad.resize(4 * hinges, Vector::ZERO);
        lin.coef.resize(hinges, 0.0);
        lin.slot.resize(4 * hinges, Vector::ZERO);
        lin.grad
            .par_chunks_exact_mut(4)
            .zip(lin.slot.par_chunks_exact_mut(4))
            .zip(lin.coef.par_iter_mut())
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
        for &k in el.hinge_slots.of(i) {
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
            .zip(el.hinges.par_iter())
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
        for &k in el.hinge_slots.of(i) {
            *acc += lin.slot[k as usize];
        }
    }

    fn coupling_count(el: &Elements) -> usize {
        12 * el.hinges.len()
    }

    fn couplings(el: &Elements, pairs: &mut Vec<(u32, u32)>) {
        for hg in &el.hinges {
            for k in 0..4 {
                for l in 0..4 {
                    if k != l {
                        pairs.push((hg.v[k], hg.v[l]));
                    }
                }
            }
        }
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
        for hg in &el.hinges {
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
