//! The per-step passes over a [`BlockPattern`] (block module docs,
//! "Assembly"): the lower blocks gathered from the kinds' terms, the diagonal
//! compensation of the dropped blocks, the projected system, and products.

use rayon::prelude::*;

use super::super::forces::PAR_MIN_ROWS;
use super::band::Band;
use super::{BlockPattern, ElementBlocks, outer};
use crate::math::{Matrix3, Scalar, Vector};

impl BlockPattern {
    /// Sums the lower blocks of `M + h D + h^2 K` into `lower` (one entry per
    /// block; the upper ones are left as they are, zero when first grown), and
    /// the compensation of the dropped in-place blocks per vertex into `lumps` (module
    /// docs, "Assembly"): band by band, each lower block's listed blocks kind
    /// by kind, the kinds' in-place blocks, and the mass on the diagonal.
    pub fn gather(
        &self,
        terms: &ElementBlocks<'_>,
        lumps: &mut Vec<Matrix3>,
        lower: &mut Vec<Matrix3>,
    ) {
        lower.resize(self.blocks(), Matrix3::ZERO);
        lumps.resize(self.vertices(), Matrix3::ZERO);
        let values = terms.kinds.block_values();
        let band = |b: usize, lower: &mut [Matrix3], lumps: &mut [Matrix3]| {
            let rows = self.band_rows(b);
            let mut band = Band {
                first_row: rows.start,
                base: self.row_start[rows.start] as usize,
                lower,
                lumps,
            };
            self.gather_band(terms, &values, &mut band);
        };
        self.for_each_band(0..self.bands(), lower, lumps, &band);
    }

    /// Runs `f(band, lower, lumps)` for the bands in `bands`, in parallel, each
    /// with the slices of its own rows (`lower` and `lumps` start at the first
    /// band's first row), by halving the range: no allocation, and each band's
    /// work the same at any thread count.
    fn for_each_band<F>(
        &self,
        bands: std::ops::Range<usize>,
        lower: &mut [Matrix3],
        lumps: &mut [Matrix3],
        f: &F,
    ) where
        F: Fn(usize, &mut [Matrix3], &mut [Matrix3]) + Sync,
    {
        match bands.len() {
            0 => {}
            1 => f(bands.start, lower, lumps),
            len => {
                let mid = bands.start + len / 2;
                let (first, split) = (self.band_rows(bands.start).start, self.band_rows(mid).start);
                let blocks = (self.row_start[split] - self.row_start[first]) as usize;
                let (lower_a, lower_b) = lower.split_at_mut(blocks);
                let (lumps_a, lumps_b) = lumps.split_at_mut(split - first);
                rayon::join(
                    || self.for_each_band(bands.start..mid, lower_a, lumps_a, f),
                    || self.for_each_band(mid..bands.end, lower_b, lumps_b, f),
                );
            }
        }
    }

    /// Per vertex: the diagonal compensation of the dropped blocks (module
    /// docs, "The factored matrix"): the kinds' compensation terms, kind by
    /// kind, then the compensation `lumps` of the dropped in-place blocks (from
    /// [`Self::gather`]), projected like the system (`S c g g^T S`).
    pub fn compensation(
        &self,
        terms: &ElementBlocks<'_>,
        lumps: &[Matrix3],
        projection: &[Option<Vector>],
        extra: &mut Vec<Matrix3>,
    ) {
        extra.resize(self.vertices(), Matrix3::ZERO);
        extra
            .par_iter_mut()
            .enumerate()
            .with_min_len(PAR_MIN_ROWS)
            .for_each(|(i, out)| {
                let mut m = Matrix3::ZERO;
                let dropped = std::array::from_fn(|kind| self.dropped[kind].of(i));
                terms.kinds.add_dropped(dropped, &mut m);
                m += lumps[i];
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
    /// By rows: a row's lower blocks are copied and its upper ones are their
    /// mirrors' transposes, projected where either vertex is: in the rows
    /// that `touched` marks ([`Self::touched_rows`]).
    pub fn project(
        &self,
        lower: &[Matrix3],
        projection: &[Option<Vector>],
        touched: &[bool],
        scale: &[Scalar],
        out: &mut Vec<Matrix3>,
    ) {
        out.resize(lower.len(), Matrix3::ZERO);
        let rows = |rows: std::ops::Range<usize>, out: &mut [Matrix3]| {
            let base = self.row_start[rows.start] as usize;
            for i in rows {
                let (start, diagonal, end) = (
                    self.row_start[i] as usize,
                    self.diagonal[i] as usize,
                    self.row_start[i + 1] as usize,
                );
                let out = &mut out[start - base..end - base];
                let (own, upper) = out.split_at_mut(diagonal + 1 - start);
                own.copy_from_slice(&lower[start..=diagonal]);
                for (o, &m) in upper.iter_mut().zip(&self.mirror[diagonal + 1..end]) {
                    *o = lower[m as usize].transpose();
                }
                if touched[i] {
                    for (o, slot) in out.iter_mut().zip(start..) {
                        self.project_block(projection, scale, slot, o);
                    }
                }
            }
        };
        self.for_each_row_chunk(0..self.vertices(), out, &rows);
    }

    /// Per row, into `touched`: whether the row holds a block of a projected
    /// vertex (`projection` not `None`: the row's own or a column's), found
    /// from the projected vertices' rows (the pattern is symmetric), so that
    /// a step with few prescribed vertices visits few rows.
    pub fn touched_rows(&self, projection: &[Option<Vector>], touched: &mut Vec<bool>) {
        touched.clear();
        touched.resize(self.vertices(), false);
        for (i, _) in projection.iter().enumerate().filter(|(_, p)| p.is_some()) {
            let row = self.row_start[i] as usize..self.row_start[i + 1] as usize;
            for &j in &self.columns[row] {
                touched[j as usize] = true;
            }
        }
    }

    /// Block `slot` of the projected system in place, `out` holding the block
    /// of `A` ([`Self::project`]).
    #[inline(always)]
    fn project_block(
        &self,
        projection: &[Option<Vector>],
        scale: &[Scalar],
        slot: usize,
        out: &mut Matrix3,
    ) {
        let s = |i: usize| match projection[i] {
            None => None,
            Some(n) if n == Vector::ZERO => Some(Matrix3::ZERO),
            Some(n) => Some(Matrix3::IDENTITY - outer(n, n)),
        };
        let (i, j) = (self.rows[slot] as usize, self.columns[slot] as usize);
        if projection[i].is_none() && projection[j].is_none() {
            return;
        }
        let (si, sj) = (s(i), s(j));
        let mut m = *out;
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
    }

    /// Runs `f(rows, out)` over chunks of at most [`PAR_MIN_ROWS`] rows in
    /// parallel, `out` holding the chunk's blocks, by halving the range: no
    /// allocation, and each block's work the same at any thread count.
    fn for_each_row_chunk<F>(&self, rows: std::ops::Range<usize>, out: &mut [Matrix3], f: &F)
    where
        F: Fn(std::ops::Range<usize>, &mut [Matrix3]) + Sync,
    {
        if rows.len() <= PAR_MIN_ROWS {
            f(rows, out);
            return;
        }
        let mid = rows.start + rows.len() / 2;
        let blocks = (self.row_start[mid] - self.row_start[rows.start]) as usize;
        let (a, b) = out.split_at_mut(blocks);
        rayon::join(
            || self.for_each_row_chunk(rows.start..mid, a, f),
            || self.for_each_row_chunk(mid..rows.end, b, f),
        );
    }

    /// `y = A x` with the blocks `a` of this pattern, by rows (deterministic).
    pub fn multiply(&self, a: &[Matrix3], x: &[Vector], y: &mut [Vector]) {
        y.par_iter_mut()
            .enumerate()
            .with_min_len(PAR_MIN_ROWS)
            .for_each(|(i, out)| {
                let range = self.row_start[i] as usize..self.row_start[i + 1] as usize;
                let mut acc = Vector::ZERO;
                for s in range {
                    acc += a[s] * x[self.columns[s] as usize];
                }
                *out = acc;
            });
    }

    /// `y = A x` with `A` given by its lower blocks ([`Self::gather`]), by rows:
    /// the same values as [`Self::multiply`] with every block stored. Blocks
    /// that meet a zero `x_j` are skipped (the solver's prescribed velocity
    /// change is zero but at pins and contacts): with finite blocks their
    /// products are zeros, which leave the sums as they are.
    /// With `rows`, only the rows it marks are summed and the others set to
    /// zero: the same values when `x` is zero in every column of an unmarked
    /// row (as [`Self::touched_rows`] marks them for an `x` that is zero but
    /// at projected vertices).
    pub fn multiply_lower(
        &self,
        lower: &[Matrix3],
        x: &[Vector],
        rows: Option<&[bool]>,
        y: &mut [Vector],
    ) {
        y.par_iter_mut()
            .enumerate()
            .with_min_len(PAR_MIN_ROWS)
            .for_each(|(i, out)| {
                if rows.is_some_and(|rows| !rows[i]) {
                    *out = Vector::ZERO;
                    return;
                }
                let range = self.row_start[i] as usize..self.row_start[i + 1] as usize;
                let mut acc = Vector::ZERO;
                for s in range {
                    let xj = x[self.columns[s] as usize];
                    if xj != Vector::ZERO {
                        acc += self.full_block(lower, s) * xj;
                    }
                }
                *out = acc;
            });
    }
}
