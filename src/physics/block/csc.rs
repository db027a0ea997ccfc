//! The scalar compressed-column (CSC) form of the factored lower triangle of a
//! [`BlockPattern`], which the sparse Cholesky factorization reads.

use rayon::prelude::*;

use super::super::forces::PAR_MIN;
use super::BlockPattern;
use crate::math::{Matrix3, Scalar};

impl BlockPattern {
    /// The scalar CSC structure of the lower triangle. Scalar entry (row 3i+p,
    /// column 3j+q), i >= j, is component (p, q) of block (i, j), i.e. component
    /// (q, p) of block (j, i), which is stored in block row j: so column 3j+q is read
    /// from block row j's blocks with column i >= j, in ascending order.
    pub(super) fn build_csc(&mut self) {
        let n = self.vertices();
        let mut start = Vec::with_capacity(3 * n + 1);
        let (mut rows, mut source) = (Vec::new(), Vec::new());
        start.push(0u32);
        for j in 0..n {
            let (s, e) = (self.row_start[j] as usize, self.row_start[j + 1] as usize);
            for q in 0..3u32 {
                for slot in s..e {
                    let i = self.columns[slot];
                    if (i as usize) < j || !self.factored[slot] {
                        continue;
                    }
                    let first = if i as usize == j { q } else { 0 };
                    for p in first..3 {
                        rows.push(3 * i + p);
                        // Component (row q, column p) of block (j, i).
                        source.push(slot as u32 * 9 + p * 3 + q);
                    }
                }
                start.push(rows.len() as u32);
            }
        }
        self.csc_column_start = start;
        self.csc_rows = rows;
        self.csc_source = source;
    }

    /// The block-level (one row and column per vertex) CSC structure of the factored
    /// lower triangle, diagonal included, rows ascending within each column: the
    /// graph that the fill-reducing ordering reads ([`super::super::cholesky`],
    /// "Ordering by vertex"), as column starts and row indices.
    pub fn vertex_structure(&self) -> (Vec<u32>, Vec<u32>) {
        let n = self.vertices();
        let (mut column_start, mut rows) = (Vec::with_capacity(n + 1), Vec::new());
        column_start.push(0);
        for j in 0..n {
            let (s, e) = (self.row_start[j] as usize, self.row_start[j + 1] as usize);
            for slot in s..e {
                let i = self.columns[slot];
                if i as usize >= j && self.factored[slot] {
                    rows.push(i);
                }
            }
            column_start.push(rows.len() as u32);
        }
        (column_start, rows)
    }

    /// Column pointers and row indices of the lower triangle's scalar CSC form.
    pub fn csc_structure(&self) -> (&[u32], &[u32]) {
        (&self.csc_column_start, &self.csc_rows)
    }

    /// Fills `values` (one per CSC entry) from the blocks, adding `extra[i]` to
    /// each diagonal block `(i, i)` (the compensation of [`Self::compensation`]).
    pub fn csc_values(&self, blocks: &[Matrix3], extra: &[Matrix3], values: &mut Vec<Scalar>) {
        values.resize(self.csc_source.len(), 0.0);
        values
            .par_iter_mut()
            .zip(self.csc_source.par_iter())
            .with_min_len(8 * PAR_MIN)
            .for_each(|(v, &src)| {
                let (b, c, r) = (
                    (src / 9) as usize,
                    (src % 9) as usize / 3,
                    (src % 9) as usize % 3,
                );
                let (i, j) = (self.rows[b] as usize, self.columns[b] as usize);
                *v = blocks[b].col(c)[r];
                if i == j {
                    *v += extra[i].col(c)[r];
                }
            });
    }
}

impl BlockPattern {
    /// Per entry of [`BlockPattern::vertex_structure`], in its order: the lower
    /// block it reads.
    pub fn vertex_structure_blocks(&self) -> Vec<u32> {
        let n = self.vertices();
        let mut blocks = Vec::new();
        for j in 0..n {
            let (s, e) = (self.row_start[j] as usize, self.row_start[j + 1] as usize);
            for slot in s..e {
                let i = self.columns[slot];
                if i as usize >= j && self.factored[slot] {
                    blocks.push(slot as u32);
                }
            }
        }
        blocks
    }
}
