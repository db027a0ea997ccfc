//! One band's share of the assembly (block module docs, "Assembly"): its
//! rows' lower blocks summed from their springs and element terms, the shape
//! triangles' blocks added in place, and the mass on the diagonal.

use super::terms::frobenius;
use super::{BAND_ROWS, BlockPattern, ElementBlocks, ShapeOp};
use crate::math::{Matrix3, Scalar, Vector};
use crate::physics::shape::{SHAPE_SLOTS, ShapeJacobian, ShapeTriangle};

/// One band's share of the assembly: its rows' lower blocks (the band's first
/// block at `base`) and its vertices' dropped-block norms.
pub(super) struct Band<'a> {
    /// The band's first row.
    pub first_row: usize,
    /// The slot of the band's first block.
    pub base: usize,
    /// The band's blocks (lower ones filled, upper ones unused).
    pub lower: &'a mut [Matrix3],
    /// Per row of the band, the dropped shape blocks' norms.
    pub sigma: &'a mut [Scalar],
}

impl BlockPattern {
    /// Sums band `band`'s lower blocks (block module docs, "Assembly"), from
    /// the element terms `terms` and the hinges' and membrane triangles'
    /// blocks `flat`: each lower block's springs and hinge and membrane
    /// terms, then the shape triangles' blocks, then the mass.
    pub(super) fn gather_band(
        &self,
        terms: &ElementBlocks<'_>,
        flat: &[Matrix3],
        band: &mut Band<'_>,
    ) {
        let rows = band.first_row..band.first_row + band.sigma.len();
        for i in rows.clone() {
            // The lower blocks lead each row (columns ascend to the diagonal).
            for slot in self.row_start[i] as usize..=self.diagonal[i] as usize {
                let mut m = Matrix3::ZERO;
                let springs =
                    self.spring_start[slot] as usize..self.spring_start[slot + 1] as usize;
                let springs = &self.springs[springs];
                if self.columns[slot] as usize == i {
                    for &e in springs {
                        m += terms.springs[e as usize];
                    }
                } else {
                    for &e in springs {
                        m -= terms.springs[e as usize];
                    }
                }
                let range = self.term_start[slot] as usize..self.term_start[slot + 1] as usize;
                for &t in &self.terms[range] {
                    m += flat[t as usize];
                }
                band.lower[slot - band.base] = m;
            }
        }
        band.sigma.fill(0.0);
        let b = rows.start / BAND_ROWS;
        let shapes = self.band_shape_start[b] as usize..self.band_shape_start[b + 1] as usize;
        for &tri in &self.band_shapes[shapes] {
            let tri = tri as usize;
            let ops = self.shape_op_start[tri] as usize..self.shape_op_start[tri + 1] as usize;
            band.add_shape(
                &terms.shape_triangles[tri],
                &terms.shape_jacobian(tri),
                terms.h2,
                &self.shape_ops[ops],
            );
        }
        for i in rows {
            band.lower[self.diagonal[i] as usize - band.base] +=
                Matrix3::from_diagonal(Vector::splat(terms.diagonal_mass[i]));
        }
    }
}

impl Band<'_> {
    /// Computes shape triangle `t`'s blocks `ops` with a vertex in the band
    /// (with the triangle's Jacobian `jac`): adds each to its block when its
    /// row is in the band, and a dropped one's norm to the compensation of
    /// each of its two vertices in the band. The products `M J` are formed
    /// once for all its blocks.
    #[inline(always)]
    fn add_shape(&mut self, t: &ShapeTriangle, jac: &ShapeJacobian, h2: Scalar, ops: &[ShapeOp]) {
        let mut mj = [[Vector::ZERO; SHAPE_SLOTS]; 3];
        times_m(&t.m, jac, &mut mj);
        let rows = self.first_row..self.first_row + self.sigma.len();
        for op in ops {
            let (row, column) = (t.v[op.k as usize] as usize, t.v[op.l as usize] as usize);
            let (in_row, in_column) = (rows.contains(&row), rows.contains(&column));
            if !(in_row || op.dropped && in_column) {
                continue;
            }
            let (k, l) = (op.k as usize, op.l as usize);
            let mut block = Matrix3::ZERO;
            for a in moved_angles(k) {
                block += super::outer(jac[a][k], mj[a][l]);
            }
            block *= h2;
            if in_row {
                self.lower[op.slot as usize - self.base] += block;
            }
            if op.dropped {
                let norm = frobenius(&block);
                if in_row {
                    self.sigma[row - self.first_row] += norm;
                }
                if in_column {
                    self.sigma[column - self.first_row] += norm;
                }
            }
        }
    }
}

/// `(M J)_al = sum_b M_ab J_bl` for every angle `a` and slot `l`. A tip slot
/// `3 + b` moves angle `b` only (`shape.rs`, `HINGE_SLOTS`), so its column has
/// one term; skipping the exact zeros leaves every value the same to the last
/// bit.
#[inline(always)]
fn times_m(m: &[[Scalar; 3]; 3], jac: &ShapeJacobian, mj: &mut [[Vector; SHAPE_SLOTS]; 3]) {
    for (row, out) in m.iter().zip(mj) {
        for (l, o) in out.iter_mut().enumerate() {
            *o = match l {
                0..3 => jac[0][l] * row[0] + jac[1][l] * row[1] + jac[2][l] * row[2],
                _ => jac[l - 3][l] * row[l - 3],
            };
        }
    }
}

/// The angles of a shape triangle that slot `k` moves: all three for one of
/// its own vertices, angle `a` alone for the tip across edge `a` (slot `3 + a`).
#[inline(always)]
pub(super) fn moved_angles(k: usize) -> std::ops::Range<usize> {
    if k < 3 { 0..3 } else { k - 3..k - 2 }
}
