//! The implicit system matrix assembled into a fixed 3x3-block sparsity pattern.
//!
//! [`BlockPattern`] is built once per mesh topology: one block per vertex pair
//! coupled by a spring, a membrane triangle, a hinge or a shape triangle (both
//! triangles stored, columns sorted per row), and what the blocks of the lower
//! triangle sum: per block its springs and its hinge and membrane terms, per
//! band of rows its shape triangles (below), each in element order.
//!
//! # Assembly
//! Each step assembles the lower blocks of `A` ([`BlockPattern::gather`]) with
//! no atomics, locks or allocation once the scratch has grown to the mesh:
//! 1. Parallel over elements, every hinge and membrane triangle writes the
//!    blocks it adds to the lower triangle (pairs of its vertices `(i, j)` with
//!    `j <= i`) into its own fixed-size stretch of a flat array
//!    ([`ElementTerms`]), hinges first, each kind in element order.
//! 2. Parallel over bands of [`BAND_ROWS`] rows, each band owning its rows'
//!    blocks: every lower block sums its springs' blocks (read where the
//!    linearisation left them: added on the diagonal, subtracted off it) and
//!    its hinge and membrane terms, by precomputed index lists of plain 3x3
//!    additions (no dispatch on the element kind); then each shape triangle
//!    with a slot in the band, in triangle order, forms its products
//!    `sum_b M_ab J_bl` once and adds its blocks `h^2 sum_a J_ak (M J)_al^T`
//!    with their row in the band straight into them, by its precomputed slots,
//!    and the Frobenius norm of each dropped block into the diagonal
//!    compensation of both its vertices that lie in the band (the lower block
//!    serves its transpose too); last the mass on the diagonal. A triangle's
//!    Jacobian is read from its edges' folds ([`ElementBlocks::shape_jacobian`]).
//!
//! The shape triangles are the bulk (21 blocks each, against 3 per spring).
//! Summed per block from the Jacobians, a triangle's products would be formed
//! again for every block it adds to, and once more for the compensation
//! (`perf` put two thirds of a shape-operator sheet's assembly there). Formed
//! once per triangle but written to a flat array like the hinges' terms, its
//! blocks would cost 12 MB of memory traffic a step at 4,096 vertices, and
//! gathering them took as long as computing them (measured). Added in place,
//! they go straight into the band's blocks, which stay in the cache; a
//! triangle with slots in two bands forms its products in both (a third of the
//! triangles, with bands of 512 rows on a 65 x 65 grid).
//!
//! Every block sums its terms in one fixed order (springs, hinges, membrane
//! triangles, shape triangles, each in element order, then the mass), whatever
//! the thread count; and it is the order and the arithmetic of summing each
//! block's terms one by one, each computed alone, so the values are those to
//! the last bit. The upper blocks are not stored: [`BlockPattern::project`]
//! and [`BlockPattern::multiply_lower`] read one as its mirror's transpose.
//!
//! The pattern also carries the scalar compressed-column (CSC) structure of the
//! lower triangle that the sparse Cholesky factorization reads ([`super::cholesky`]),
//! with, for every scalar entry, the block and the component it comes from.
//!
//! # The factored matrix
//! The factorization reads only the blocks of vertex pairs joined by a spring or
//! a membrane triangle's edge (and the diagonal). The only other blocks are the couplings between the two wing tips
//! `p`, `q` of a hinge, and keeping them more than doubles the factor: on a 65 x 65
//! grid its stored values go from 0.80 to 1.99 million and a numerical factorization
//! from 11 to 45 ms (measured on this machine with a probe that factored a test matrix on the pattern). So the
//! factored matrix is `A` without the `p`-`q` blocks, made positive semi-definite
//! again by adding `c g_p g_p^T` to block `(p, p)` and `c g_q g_q^T` to `(q, q)` for
//! each hinge: with `alpha = g_a.x_a + g_b.x_b`, `beta = g_p.x_p`, `gamma = g_q.x_q`,
//! the hinge's quadratic form becomes `c ((alpha + beta + gamma)^2 - 2 beta gamma +
//! beta^2 + gamma^2) = c ((alpha + beta + gamma)^2 + (beta - gamma)^2) >= 0`. The
//! difference is a bending term, small against mass and stretch on fabrics; the
//! conjugate gradients that use the factor as their preconditioner apply the exact
//! `A` and remove it in a few iterations. Where bending dominates (a stiff strip at
//! fine resolution) it is not small: a cantilever strip of 969 vertices needed 100
//! iterations a step with the fresh factor. So the solver switches to factoring
//! every block (`factor_tips`) once a fresh factor needs more iterations than the
//! full factor's extra size is worth (the direct solver's module docs, "Which
//! factor", in the implicit module).
//!
mod assemble;
mod band;
mod buckets;
mod csc;
mod sources;
mod terms;
#[cfg(test)]
mod tests;

pub use terms::{ElementBlocks, ElementTerms};

use super::elements::Elements;
use super::kinds::{coupling_count, couplings};
use crate::math::{Matrix3, Vector};
pub(crate) use buckets::group_by_key;
use buckets::sorted_unique_rows;
use sources::TermLayout;

/// Rows per band of the assembly (module docs, "Assembly"). Any size gives the
/// same sums (a block's terms come in the same order whichever band holds its
/// row); 512 rows share a 65 x 65 grid among 9 bands, enough to balance two to
/// four threads, while the triangles that straddle two bands (their slots span
/// about three grid rows) stay a third of them.
const BAND_ROWS: usize = 512;

/// One lower block `(k, l)` (slots) of a shape triangle, which the assembly
/// computes and adds to block `slot`. When the factorization drops it, its
/// Frobenius norm also compensates the diagonals of both its vertices, `v[k]`
/// and `v[l]` (its transpose, the upper block, has the same norm):
/// `[[s I, -B], [-B^T, s I]]` is positive semi-definite for `s >= |B|`, so the
/// factored matrix stays positive definite (the tighter rank-one compensation
/// `B B^T / |B|`, each such `B = u v^T` involving a tip, saves about 1 % of the
/// iterations, not worth its code).
#[derive(Debug, Clone, Copy, PartialEq)]
struct ShapeOp {
    /// The lower block it adds to.
    slot: u32,
    /// Its row slot.
    k: u8,
    /// Its column slot.
    l: u8,
    /// Whether the factorization drops it (pair of used slots on distinct
    /// vertices whose block is not factored).
    dropped: bool,
}

/// A fixed 3x3-block sparsity pattern for one mesh topology (module docs).
#[derive(Debug, Clone, Default)]
pub struct BlockPattern {
    /// Start of each block row in `columns`; length `vertices + 1`.
    row_start: Vec<u32>,
    /// Block row of each block.
    rows: Vec<u32>,
    /// Block column of each block, sorted within a row.
    columns: Vec<u32>,
    /// Per vertex: the index of its diagonal block.
    diagonal: Vec<u32>,
    /// Per block: the block holding its transpose.
    mirror: Vec<u32>,
    /// Per block: true when the factorization reads it (diagonal, spring pair or
    /// membrane triangle edge).
    factored: Vec<bool>,
    /// Per vertex, CSC-like: the hinge slots `4 h + k` (k a wing tip) whose
    /// dropped tip-tip coupling is compensated on this vertex's diagonal.
    compensation_start: Vec<u32>,
    compensation: Vec<u32>,
    /// Per shape triangle, CSC-like: the blocks the assembly computes
    /// ([`ShapeOp`]), in the order of its slot pairs `(k, l)`.
    shape_op_start: Vec<u32>,
    shape_ops: Vec<ShapeOp>,
    /// Per band of [`BAND_ROWS`] rows, CSC-like: the shape triangles with a
    /// used slot in the band, ascending.
    band_shape_start: Vec<u32>,
    band_shapes: Vec<u32>,
    /// Per block (lower blocks only; empty range for upper ones): the springs
    /// whose block it adds (diagonal) or subtracts (coupling), in spring order.
    spring_start: Vec<u32>,
    springs: Vec<u32>,
    /// Per block (lower blocks only): the indices of its hinge and membrane
    /// terms in [`ElementTerms`], ascending (hinges, then membrane triangles,
    /// each in element order).
    term_start: Vec<u32>,
    terms: Vec<u32>,
    /// Where each element's terms lie in [`ElementTerms`].
    layout: TermLayout,
    /// Scalar CSC structure of the lower triangle: column pointers.
    csc_column_start: Vec<u32>,
    /// Scalar CSC row indices.
    csc_rows: Vec<u32>,
    /// Per CSC entry: `block * 9 + column * 3 + row` of the block it reads.
    csc_source: Vec<u32>,
}

impl BlockPattern {
    /// The pattern of `elements`' springs and hinges on `vertices` vertices;
    /// `factor_tips`: the factorization reads the hinge tip-tip blocks too (module
    /// docs), otherwise they are compensated on the diagonal.
    pub fn build(vertices: usize, elements: &Elements, factor_tips: bool) -> BlockPattern {
        let n = vertices;
        // Every coupled pair, both ways, and the diagonal.
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(n + coupling_count(elements));
        pairs.extend((0..n as u32).map(|i| (i, i)));
        couplings(elements, &mut pairs);
        let (row_start, columns) = sorted_unique_rows(n, &pairs);
        let rows = (0..n as u32)
            .flat_map(|i| {
                std::iter::repeat_n(
                    i,
                    (row_start[i as usize + 1] - row_start[i as usize]) as usize,
                )
            })
            .collect();
        let mut p = BlockPattern {
            row_start,
            rows,
            columns,
            ..Default::default()
        };
        p.diagonal = (0..n as u32).map(|i| p.slot(i, i)).collect();
        p.mirror = p.mirrors();
        p.mark_factored(elements, factor_tips);
        p.build_sources(elements);
        p.build_csc();
        p
    }

    /// Which blocks the factorization reads ([`BlockPattern::factored`]) and
    /// the hinge tips whose blocks it leaves out, compensated on the diagonal.
    fn mark_factored(&mut self, elements: &Elements, factor_tips: bool) {
        let n = self.vertices();
        let p = self;
        p.factored = (0..p.blocks())
            .map(|b| p.rows[b] == p.columns[b] || factor_tips)
            .collect();
        for sp in &elements.springs {
            let [a, b] = sp.v;
            for (i, j) in [(a, b), (b, a)] {
                let s = p.slot(i, j) as usize;
                p.factored[s] = true;
            }
        }
        // A membrane triangle couples the ends of its edges, as the springs do.
        for t in &elements.membrane_triangles {
            for i in t.v {
                for j in t.v {
                    let s = p.slot(i, j) as usize;
                    p.factored[s] = true;
                }
            }
        }
        let mut tips: Vec<(u32, u32)> = Vec::new();
        for (h, hg) in elements.hinges.iter().enumerate() {
            let (tip_p, tip_q) = (hg.v[2], hg.v[3]);
            if !p.factored[p.slot(tip_p, tip_q) as usize] {
                tips.push((tip_p, 4 * h as u32 + 2));
                tips.push((tip_q, 4 * h as u32 + 3));
            }
        }
        (p.compensation_start, p.compensation) = group_by_key(n, &tips);
    }

    /// Number of vertices (block rows).
    pub fn vertices(&self) -> usize {
        self.row_start.len().saturating_sub(1)
    }

    /// Number of bands of [`BAND_ROWS`] rows.
    fn bands(&self) -> usize {
        self.vertices().div_ceil(BAND_ROWS)
    }

    /// The rows of band `b`.
    fn band_rows(&self, b: usize) -> std::ops::Range<usize> {
        b * BAND_ROWS..((b + 1) * BAND_ROWS).min(self.vertices())
    }

    /// Number of stored blocks (both triangles).
    pub fn blocks(&self) -> usize {
        self.columns.len()
    }

    /// The block index of `(i, j)`; the pair must be in the pattern.
    fn slot(&self, i: u32, j: u32) -> u32 {
        let (s, e) = (
            self.row_start[i as usize] as usize,
            self.row_start[i as usize + 1] as usize,
        );
        let found = self.columns[s..e].binary_search(&j);
        debug_assert!(found.is_ok(), "block ({i}, {j}) missing from the pattern");
        (s + found.unwrap_or(0)) as u32
    }

    /// The block of the lower triangle joining `i` and `j` (either order).
    fn lower_slot(&self, i: u32, j: u32) -> u32 {
        if i == j {
            self.diagonal[i as usize]
        } else if j < i {
            self.slot(i, j)
        } else {
            self.slot(j, i)
        }
    }

    /// Per block: the block holding its transpose. Row `j` lists its columns in
    /// ascending order, and the rows are visited in ascending order, so the
    /// blocks `(i, j)` of column `j` are met in the order of row `j`'s list: a
    /// cursor per row finds every mirror without a search.
    fn mirrors(&self) -> Vec<u32> {
        let mut cursor: Vec<u32> = self.row_start[..self.vertices()].to_vec();
        let mut mirror = vec![0u32; self.blocks()];
        for (b, &j) in self.columns.iter().enumerate() {
            let m = cursor[j as usize];
            debug_assert_eq!(
                self.columns[m as usize], self.rows[b],
                "the pattern is not symmetric"
            );
            mirror[b] = m;
            cursor[j as usize] += 1;
        }
        mirror
    }
}

/// `a b^T`.
pub(super) fn outer(a: Vector, b: Vector) -> Matrix3 {
    Matrix3::from_cols(a * b.x, a * b.y, a * b.z)
}
