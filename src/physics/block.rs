//! The implicit system matrix assembled into a fixed 3x3-block sparsity pattern.
//!
//! [`BlockPattern`] is built once per mesh topology: one block per vertex pair
//! that a force element couples (every kind's couplings,
//! [`super::kinds::ForceKind::couplings`]; both triangles stored, columns
//! sorted per row), and what the blocks of the lower triangle sum: per block
//! and per kind the kind's listed blocks, and each kind's own pattern of the
//! blocks it adds in place.
//!
//! # Assembly
//! Each step assembles the lower blocks of `A` ([`BlockPattern::gather`]) with
//! no atomics, locks or allocation once the scratch has grown to the mesh, and
//! with no dispatch on the element kind per block:
//! 1. Parallel over elements, each kind writes the values of its listed
//!    blocks into its own terms ([`super::kinds::ForceKind::write_blocks`]; a
//!    hinge's ten lower blocks, a membrane triangle's six, each element its own
//!    fixed-size stretch; a spring's one block is its linearised block).
//! 2. Parallel over bands of [`BAND_ROWS`] rows, each band owning its rows'
//!    blocks: every lower block sums, kind by kind in the list's order, the
//!    kind's values by its precomputed index list (element order; a spring's
//!    block added on the diagonal, subtracted off it), by plain 3x3 additions;
//!    then each kind adds its in-place blocks with their row in the band
//!    ([`super::kinds::ForceKind::add_in_place`]: the shape triangles, whose
//!    21 blocks each are formed and added in the band's cache rather than
//!    stored, `kinds/shapes/blocks.rs`), with the norms of those the
//!    factorization drops into the band's diagonal compensation; last the mass
//!    on the diagonal.
//!
//! Every block sums its terms in one fixed order (the listed blocks kind by
//! kind, then the in-place blocks kind by kind, each kind's in element order,
//! then the mass: with today's kinds springs, hinges, membrane triangles,
//! shape triangles), whatever the thread count; and it is the order and the
//! arithmetic of summing each block's terms one by one, each computed alone,
//! so the values are those to the last bit. The upper blocks are not stored:
//! [`BlockPattern::project`] and [`BlockPattern::multiply_lower`] read one as
//! its mirror's transpose.
//!
//! The pattern also carries the scalar compressed-column (CSC) structure of the
//! lower triangle that the sparse Cholesky factorization reads ([`super::cholesky`]),
//! with, for every scalar entry, the block and the component it comes from.
//!
//! # The factored matrix
//! The factorization reads only the diagonal and the blocks of the pairs the
//! kinds keep ([`super::kinds::ForceKind::factored_pairs`]: vertex pairs
//! joined by a spring or a membrane triangle's edge); each kind compensates on
//! the diagonal for the blocks it adds that are dropped
//! ([`super::kinds::ForceKind::dropped_terms`] and the in-place blocks'
//! rank-one lumps). The shape triangles' second-ring blocks (a tip with the
//! triangle's opposite vertex or another tip) are not in the pattern at all
//! with the first-ring bending matrix, which lumps them on the diagonal of
//! `A` itself (`kinds/shapes/blocks.rs`, "The first-ring matrix"); with the
//! exact one they are dropped from the factor like the hinges' below.
//! With dihedral hinges the only other blocks are the couplings between the two wing tips
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
#[cfg(test)]
mod tests;

pub use band::Band;

use super::elements::Elements;
use super::kinds::{
    KIND_COUNT, KindInPlace, KindLinear, coupling_count, couplings, dropped_terms, factored_pairs,
};
use crate::math::{Matrix3, Scalar, Vector};
pub(crate) use buckets::group_by_key;
use buckets::sorted_unique_rows;

/// Rows per band of the assembly (module docs, "Assembly"). Any size gives the
/// same sums (a block's terms come in the same order whichever band holds its
/// row); 512 rows share a 65 x 65 grid among 9 bands, enough to balance two to
/// four threads, while the triangles that straddle two bands (their slots span
/// about three grid rows) stay a third of them.
pub(crate) const BAND_ROWS: usize = 512;

/// The bit of a listed block's entry that marks it subtracted
/// ([`super::kinds::ForceKind::listed_blocks`]); the other bits index the
/// kind's values.
const NEGATE: u32 = 1 << 31;

/// What one step's assembly reads: the elements, every kind's terms of the
/// linearised step (with the values of their listed blocks written,
/// [`KindLinear::write_blocks`]), `h^2`, and per vertex its mass plus `h`
/// times its drag coefficient, kg.
#[derive(Debug, Clone, Copy)]
pub struct ElementBlocks<'a> {
    /// The force elements.
    pub elements: &'a Elements,
    /// Every kind's terms of the linearised step.
    pub kinds: &'a KindLinear,
    /// `h^2`, the scale of the blocks added in place.
    pub h2: Scalar,
    /// Per vertex: mass plus `h` times its drag coefficient, kg.
    pub diagonal_mass: &'a [Scalar],
}

/// Lists grouped by key (block or vertex), CSR-like: `entries[start[k]..start[k
/// + 1]]` belong to key `k`; no entries at all for a kind that has none.
#[derive(Debug, Clone, Default)]
struct Lists {
    start: Vec<u32>,
    entries: Vec<u32>,
}

impl Lists {
    /// Groups `(key, entry)` pairs by key (keys below `keys`), each key's
    /// entries in their order in `pairs`.
    fn grouped(keys: usize, pairs: &[(u32, u32)]) -> Lists {
        if pairs.is_empty() {
            return Lists::default();
        }
        let (start, entries) = group_by_key(keys, pairs);
        Lists { start, entries }
    }

    /// The entries of key `k`.
    #[inline(always)]
    fn of(&self, k: usize) -> &[u32] {
        if self.entries.is_empty() {
            return &[];
        }
        &self.entries[self.start[k] as usize..self.start[k + 1] as usize]
    }
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
    /// Per block: true when the factorization reads it (the diagonal and the
    /// pairs of [`super::kinds::ForceKind::factored_pairs`]).
    factored: Vec<bool>,
    /// Per kind (list order), per vertex: the terms that compensate on its
    /// diagonal the blocks the factorization drops
    /// ([`super::kinds::ForceKind::dropped_terms`]).
    dropped: [Lists; KIND_COUNT],
    /// Per kind (list order), per block (lower blocks only; none for upper
    /// ones): the indices of the kind's values it sums, in element order, each
    /// with [`NEGATE`] where subtracted.
    listed: [Lists; KIND_COUNT],
    /// Every kind's pattern of the blocks it adds in place.
    in_place: KindInPlace,
    /// Scalar CSC structure of the lower triangle: column pointers.
    csc_column_start: Vec<u32>,
    /// Scalar CSC row indices.
    csc_rows: Vec<u32>,
    /// Per CSC entry: `block * 9 + column * 3 + row` of the block it reads.
    csc_source: Vec<u32>,
}

impl BlockPattern {
    /// The pattern of `elements` on `vertices` vertices; `factor_tips`: the
    /// factorization reads every block (module docs, "The factored matrix"),
    /// otherwise only the diagonal and the kinds' factored pairs, the others
    /// compensated on the diagonal.
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
        p.in_place = KindInPlace::build(elements, &p);
        p.build_csc();
        p
    }

    /// Which blocks the factorization reads ([`BlockPattern::factored`]) and
    /// the terms that compensate on the diagonal for those it drops.
    fn mark_factored(&mut self, elements: &Elements, factor_tips: bool) {
        let n = self.vertices();
        let p = self;
        p.factored = (0..p.blocks())
            .map(|b| p.rows[b] == p.columns[b] || factor_tips)
            .collect();
        factored_pairs(elements, |i, j| {
            let s = p.slot(i, j) as usize;
            p.factored[s] = true;
        });
        let mut terms: [Vec<(u32, u32)>; KIND_COUNT] = Default::default();
        dropped_terms(
            elements,
            |i, j| p.factored[p.slot(i, j) as usize],
            |kind, vertex, term| terms[kind].push((vertex, term)),
        );
        p.dropped = terms.map(|t| Lists::grouped(n, &t));
    }

    /// Number of vertices (block rows).
    pub fn vertices(&self) -> usize {
        self.row_start.len().saturating_sub(1)
    }

    /// Number of bands of [`BAND_ROWS`] rows.
    pub(crate) fn bands(&self) -> usize {
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
    pub(crate) fn slot(&self, i: u32, j: u32) -> u32 {
        let (s, e) = (
            self.row_start[i as usize] as usize,
            self.row_start[i as usize + 1] as usize,
        );
        let found = self.columns[s..e].binary_search(&j);
        debug_assert!(found.is_ok(), "block ({i}, {j}) missing from the pattern");
        (s + found.unwrap_or(0)) as u32
    }

    /// Whether the factorization reads block `slot`.
    pub(crate) fn is_factored(&self, slot: u32) -> bool {
        self.factored[slot as usize]
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
pub(crate) fn outer(a: Vector, b: Vector) -> Matrix3 {
    Matrix3::from_cols(a * b.x, a * b.y, a * b.z)
}
