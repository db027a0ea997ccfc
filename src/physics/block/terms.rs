//! The per-element matrix terms that [`super::BlockPattern::gather`] sums into
//! its blocks: what the implicit step computed per element, and the blocks of
//! the elements that store theirs in a factored form.

use super::outer;
use crate::math::{Matrix3, Scalar, Vector};
use crate::physics::membrane::{ColumnBlocks, MembraneTriangle};
use crate::physics::shape::{ShapeJacobian, ShapeTriangle};

/// The per-element matrix terms of one implicit step, computed by the caller.
#[derive(Debug, Clone, Copy)]
pub struct ElementBlocks<'a> {
    /// Per spring: `h^2 K_e + h D_e`, acting on `x_a - x_b`.
    pub springs: &'a [Matrix3],
    /// Per hinge, four gradients of its angle (one per vertex).
    pub hinge_gradients: &'a [Vector],
    /// Per hinge: `h^2 k` (its Gauss-Newton block is `coef g g^T`).
    pub hinge_coefficients: &'a [Scalar],
    /// Per vertex: mass plus `h` times its drag coefficient, kg.
    pub diagonal_mass: &'a [Scalar],
    /// The shape triangles (constant `M`) and, per triangle, the angle gradients.
    pub shape_triangles: &'a [ShapeTriangle],
    /// Per shape triangle: the gradients of its three angles.
    pub shape_jacobians: &'a [ShapeJacobian],
    /// `h^2`, the scale of the shape triangles' blocks.
    pub h2: Scalar,
    /// The membrane triangles.
    pub membrane_triangles: &'a [MembraneTriangle],
    /// Per membrane triangle: `h^2 K_t + h D_t` over its columns.
    pub membrane_blocks: &'a [ColumnBlocks],
}

impl ElementBlocks<'_> {
    /// Block `(k, l)` of shape triangle `tri`: `h^2 sum_ab M_ab J_ak J_bl^T`.
    ///
    /// `M J` is not precomputed per triangle and step: the gather reads blocks
    /// in pattern order, not triangle order, and a second 432-byte row per
    /// triangle measured slower than the arithmetic it saves.
    ///
    /// A tip slot `3 + a` moves angle `a` only (`shape.rs`, `HINGE_SLOTS`), so
    /// its gradients by the other two angles are zero and their terms are
    /// skipped: a block with one tip sums one outer product or one term of
    /// `M J` instead of three, a tip-tip block one of each. Skipping exact
    /// zeros leaves every block the same to the last bit.
    pub(super) fn shape_block(&self, tri: usize, k: usize, l: usize) -> Matrix3 {
        let (m, jac) = (&self.shape_triangles[tri].m, &self.shape_jacobians[tri]);
        let mut out = Matrix3::ZERO;
        for a in moved_angles(k) {
            // sum_b M_ab J_bl
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

/// The angles of a shape triangle that slot `k` moves: all three for one of
/// its own vertices, angle `a` alone for the tip across edge `a` (slot `3 + a`).
#[inline(always)]
fn moved_angles(k: usize) -> std::ops::Range<usize> {
    if k < 3 { 0..3 } else { k - 3..k - 2 }
}
