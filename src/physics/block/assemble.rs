//! The per-step passes over a [`BlockPattern`] (block module docs,
//! "Assembly"): the lower blocks gathered from the element terms, the diagonal
//! compensation of the dropped blocks, the projected system, and products.

use rayon::prelude::*;

use super::super::forces::{PAR_MIN, PAR_MIN_ROWS};
use super::{BlockPattern, ElementBlocks, ElementTerms, outer};
use crate::math::{Matrix3, Scalar, Vector};

impl BlockPattern {
    /// Sums the lower blocks of `M + h D + h^2 K` into `lower` (one entry per
    /// block; the upper ones are left as they are, zero when first grown): per
    /// block its springs' blocks, then its terms in `element` (written by
    /// [`Self::element_terms`] for `terms`), then the mass on the diagonal.
    pub fn gather(
        &self,
        terms: &ElementBlocks<'_>,
        element: &ElementTerms,
        lower: &mut Vec<Matrix3>,
    ) {
        lower.resize(self.blocks(), Matrix3::ZERO);
        let blocks = element.blocks();
        lower
            .par_iter_mut()
            .enumerate()
            .with_min_len(PAR_MIN)
            .for_each(|(slot, out)| {
                let (i, j) = (self.rows[slot] as usize, self.columns[slot] as usize);
                if j > i {
                    return;
                }
                let mut m = Matrix3::ZERO;
                let springs =
                    self.spring_start[slot] as usize..self.spring_start[slot + 1] as usize;
                let springs = &self.springs[springs];
                if i == j {
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
                    m += blocks[t as usize];
                }
                if i == j {
                    m += Matrix3::from_diagonal(Vector::splat(terms.diagonal_mass[i]));
                }
                *out = m;
            });
    }

    /// Per vertex: the diagonal compensation of the dropped tip-tip blocks (module
    /// docs) and of the dropped shape blocks (their norms in `element`),
    /// projected like the system (`S c g g^T S`).
    pub fn compensation(
        &self,
        terms: &ElementBlocks<'_>,
        element: &ElementTerms,
        projection: &[Option<Vector>],
        extra: &mut Vec<Matrix3>,
    ) {
        extra.resize(self.vertices(), Matrix3::ZERO);
        let norms = element.norms();
        extra
            .par_iter_mut()
            .enumerate()
            .with_min_len(PAR_MIN_ROWS)
            .for_each(|(i, out)| {
                let range =
                    self.compensation_start[i] as usize..self.compensation_start[i + 1] as usize;
                let mut m = Matrix3::ZERO;
                for &k in &self.compensation[range] {
                    let g = terms.hinge_gradients[k as usize];
                    m += outer(g, g) * terms.hinge_coefficients[k as usize / 4];
                }
                let range =
                    self.shape_dropped_start[i] as usize..self.shape_dropped_start[i + 1] as usize;
                let mut sigma = 0.0;
                for &n in &self.shape_dropped[range] {
                    sigma += norms[n as usize];
                }
                m += Matrix3::from_diagonal(Vector::splat(sigma));
                *out = match projection[i] {
                    None => m,
                    Some(n) if n == Vector::ZERO => Matrix3::ZERO,
                    Some(n) => {
                        let s = Matrix3::IDENTITY - outer(n, n);
                        s * m * s
                    }
                };
            });
    }

    /// Block `slot` of the symmetric matrix whose lower blocks are `lower`: the
    /// block itself, or the transpose of its mirror for an upper one.
    #[inline(always)]
    pub(super) fn full_block(&self, lower: &[Matrix3], slot: usize) -> Matrix3 {
        if self.columns[slot] <= self.rows[slot] {
            lower[slot]
        } else {
            lower[self.mirror[slot] as usize].transpose()
        }
    }

    /// The projected system `S A S + (I - S) m` of the module docs of
    /// [`super::super::implicit`], every block, from the lower blocks of `A`
    /// ([`Self::gather`]): `filter[i]` is `None` for a free vertex, `Some(0)` for
    /// a held one (all three directions prescribed) and `Some(n)` for a contact
    /// whose normal `n` is prescribed. `scale[i]` is the diagonal put back on the
    /// prescribed directions (the vertex's mass, so the matrix keeps its scale).
    pub fn project(
        &self,
        lower: &[Matrix3],
        projection: &[Option<Vector>],
        scale: &[Scalar],
        out: &mut Vec<Matrix3>,
    ) {
        out.resize(lower.len(), Matrix3::ZERO);
        let s = |i: usize| match projection[i] {
            None => None,
            Some(n) if n == Vector::ZERO => Some(Matrix3::ZERO),
            Some(n) => Some(Matrix3::IDENTITY - outer(n, n)),
        };
        out.par_iter_mut()
            .enumerate()
            .with_min_len(PAR_MIN)
            .for_each(|(slot, out)| {
                let (i, j) = (self.rows[slot] as usize, self.columns[slot] as usize);
                let mut m = self.full_block(lower, slot);
                let (si, sj) = match (projection[i], projection[j]) {
                    (None, None) => {
                        *out = m;
                        return;
                    }
                    _ => (s(i), s(j)),
                };
                if let Some(si) = si {
                    m = si * m;
                }
                if let Some(sj) = sj {
                    m *= sj;
                }
                if i == j
                    && let Some(si) = si
                {
                    m += (Matrix3::IDENTITY - si) * scale[i];
                }
                *out = m;
            });
    }

    /// `y = A x` with the blocks `a` of this pattern, by rows (deterministic).
    pub fn multiply(&self, a: &[Matrix3], x: &[Vector], y: &mut [Vector]) {
        self.multiply_by(|slot| a[slot], x, y);
    }

    /// `y = A x` with `A` given by its lower blocks ([`Self::gather`]), by rows;
    /// the same values as [`Self::multiply`] with every block stored.
    pub fn multiply_lower(&self, lower: &[Matrix3], x: &[Vector], y: &mut [Vector]) {
        self.multiply_by(|slot| self.full_block(lower, slot), x, y);
    }

    /// `y = A x` with block `slot` of `A` given by `block`.
    #[inline(always)]
    fn multiply_by(&self, block: impl Fn(usize) -> Matrix3 + Sync, x: &[Vector], y: &mut [Vector]) {
        y.par_iter_mut()
            .enumerate()
            .with_min_len(PAR_MIN_ROWS)
            .for_each(|(i, out)| {
                let range = self.row_start[i] as usize..self.row_start[i + 1] as usize;
                let mut acc = Vector::ZERO;
                for s in range {
                    acc += block(s) * x[self.columns[s] as usize];
                }
                *out = acc;
            });
    }
}
