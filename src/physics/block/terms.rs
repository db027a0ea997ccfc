//! The per-element matrix terms that [`super::BlockPattern::gather`] sums into
//! its blocks: what the implicit step computed per element ([`ElementBlocks`]);
//! the lower blocks of the hinges and membrane triangles, written once per step
//! into a flat array in element order ([`ElementTerms`]); and the shape
//! triangles' blocks, added band by band ([`super::band::Band`]; the block module docs,
//! "Assembly").

use rayon::prelude::*;

use super::super::forces::PAR_MIN;
use super::{BlockPattern, outer};
use crate::math::{Matrix3, Scalar, Vector};
use crate::physics::elements::Hinge;
use crate::physics::membrane::{ColumnBlocks, MembraneTriangle};
use crate::physics::shape::{EdgeFold, FoldEdges, ShapeJacobian, ShapeTriangle};

/// The per-element matrix terms of one implicit step, computed by the caller.
#[derive(Debug, Clone, Copy)]
pub struct ElementBlocks<'a> {
    /// Per spring: `h^2 K_e + h D_e`, acting on `x_a - x_b`.
    pub springs: &'a [Matrix3],
    /// The hinges (their vertices).
    pub hinges: &'a [Hinge],
    /// Per hinge, four gradients of its angle (one per vertex).
    pub hinge_gradients: &'a [Vector],
    /// Per hinge: `h^2 k` (its Gauss-Newton block is `coef g g^T`).
    pub hinge_coefficients: &'a [Scalar],
    /// Per vertex: mass plus `h` times its drag coefficient, kg.
    pub diagonal_mass: &'a [Scalar],
    /// The shape triangles (constant `M`) and, per triangle, the angle gradients.
    pub shape_triangles: &'a [ShapeTriangle],
    /// The shape triangles' interior edges, where each triangle reads the
    /// gradients of its three angles ([`ElementBlocks::shape_jacobian`]).
    pub fold_edges: &'a FoldEdges,
    /// Per interior edge: its fold and the fold's gradient.
    pub edge_folds: &'a [EdgeFold],
    /// `h^2`, the scale of the shape triangles' blocks.
    pub h2: Scalar,
    /// The membrane triangles.
    pub membrane_triangles: &'a [MembraneTriangle],
    /// Per membrane triangle: `h^2 K_t + h D_t` over its columns.
    pub membrane_blocks: &'a [ColumnBlocks],
}

impl ElementBlocks<'_> {
    /// Shape triangle `t`'s angle gradients by slot, read from its edges'
    /// folds.
    #[inline(always)]
    pub fn shape_jacobian(&self, t: usize) -> ShapeJacobian {
        self.fold_edges.angles(t, self.edge_folds).1
    }
}

/// The lower blocks that the hinges and membrane triangles add to `A` in one
/// step, laid out by the pattern (block module docs, "Assembly"): each element
/// owns a stretch of fixed length (the most that an element of its kind has),
/// in element order, so that the elements fill it in parallel; entries past an
/// element's own stay unread. And per vertex, the sum of the norms of its
/// dropped shape blocks. Kept between steps (no allocation once grown).
#[derive(Debug, Clone, Default)]
pub struct ElementTerms {
    /// Per element, its lower blocks in [`lower_pairs`] order.
    pub(super) blocks: Vec<Matrix3>,
    /// Per vertex, the Frobenius norms of the dropped shape blocks in its row
    /// or column, summed (by triangle, then by lower slot pair).
    pub(super) sigma: Vec<Scalar>,
}

impl BlockPattern {
    /// Writes every hinge's and membrane triangle's lower blocks into `out`,
    /// parallel over the elements of each kind (module docs).
    pub(super) fn element_terms(&self, terms: &ElementBlocks<'_>, out: &mut ElementTerms) {
        let l = &self.layout;
        out.blocks.resize(l.len, Matrix3::ZERO);
        let (hinges, membrane) = out.blocks.split_at_mut(l.membrane_start);
        if !terms.hinge_coefficients.is_empty() {
            hinges
                .par_chunks_mut(l.hinge)
                .zip(terms.hinge_gradients.par_chunks_exact(4))
                .zip(terms.hinge_coefficients.par_iter())
                .zip(terms.hinges.par_iter())
                .with_min_len(PAR_MIN / 4)
                .for_each(|(((out, g), &c), hinge)| {
                    let mut w = 0;
                    lower_pairs(&hinge.v, 0b1111, |k, l| {
                        out[w] = outer(g[k], g[l]) * c;
                        w += 1;
                    });
                });
        }
        if !terms.membrane_triangles.is_empty() {
            membrane
                .par_chunks_mut(l.membrane)
                .zip(terms.membrane_triangles.par_iter())
                .zip(terms.membrane_blocks.par_iter())
                .with_min_len(PAR_MIN / 4)
                .for_each(|((out, t), m)| {
                    let mut w = 0;
                    lower_pairs(&t.v, 0b111, |k, l| {
                        out[w] = t.block(m, k, l);
                        w += 1;
                    });
                });
        }
    }
}

/// Calls `f(k, l)` for every block that an element with vertices `v` adds to
/// the lower triangle: local vertices `k` and `l`, both set in `active` (bit
/// `k`), with `v[l] <= v[k]`; `k` outer and `l` inner, each ascending. The
/// pattern (where each term goes) and [`BlockPattern::element_terms`] (what
/// it is) both enumerate through here, so they agree.
#[inline(always)]
pub(super) fn lower_pairs(v: &[u32], active: u32, mut f: impl FnMut(usize, usize)) {
    for k in (0..v.len()).filter(|&k| active >> k & 1 != 0) {
        for l in (0..v.len()).filter(|&l| active >> l & 1 != 0) {
            if v[l] <= v[k] {
                f(k, l);
            }
        }
    }
}

/// The used slots of a shape triangle as a bit set: its own three vertices and
/// the tips across its interior edges.
#[inline(always)]
pub(super) fn shape_active(t: &ShapeTriangle) -> u32 {
    (0..3).fold(0b111, |bits, a| bits | u32::from(t.interior[a]) << (3 + a))
}

/// The Frobenius norm of `b`.
#[inline(always)]
pub(super) fn frobenius(b: &Matrix3) -> Scalar {
    (b.x_axis.length_squared() + b.y_axis.length_squared() + b.z_axis.length_squared()).sqrt()
}

#[cfg(test)]
impl ElementBlocks<'_> {
    /// Block `(k, l)` of shape triangle `tri` computed alone, from the
    /// Jacobians: `h^2 sum_ab M_ab J_ak J_bl^T`, summed as the per-triangle pass
    /// does (the tests' reference).
    pub(super) fn shape_block(&self, tri: usize, k: usize, l: usize) -> Matrix3 {
        let (m, jac) = (&self.shape_triangles[tri].m, &self.shape_jacobian(tri));
        let mut out = Matrix3::ZERO;
        for a in super::band::moved_angles(k) {
            let row = &m[a];
            let right = match l {
                0..3 => jac[0][l] * row[0] + jac[1][l] * row[1] + jac[2][l] * row[2],
                _ => jac[l - 3][l] * row[l - 3],
            };
            out += outer(jac[a][k], right);
        }
        out * self.h2
    }
}
