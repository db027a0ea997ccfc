//! The implicit system matrix assembled into a fixed 3x3-block sparsity pattern.
//!
//! [`BlockPattern`] is built once per mesh topology: one block per vertex pair
//! coupled by a spring, a membrane triangle, a hinge or a shape triangle (both triangles stored, columns sorted per row),
//! and for every block of the lower triangle the list of element terms that sum
//! into it, in element order. Assembly ([`BlockPattern::gather`]) then needs no
//! triplets, no sorting and no atomics: each lower block sums its own sources in a
//! fixed order (parallel over rows), and each upper block copies the transpose of its
//! mirror, so the values are identical at any thread count.
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
mod buckets;
mod csc;
mod terms;
#[cfg(test)]
mod tests;

pub use terms::ElementBlocks;

use rayon::prelude::*;

use super::elements::Elements;
use super::forces::{PAR_MIN, PAR_MIN_ROWS};
use super::shape::SHAPE_SLOTS;
use crate::math::{Matrix3, Scalar, Vector};
use buckets::{group_by_key, sorted_unique_rows};

/// One element term summed into a lower block.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Source {
    /// `+K_e` of spring `e` (a diagonal block of one of its ends).
    SpringDiagonal(u32),
    /// `-K_e` of spring `e` (the block coupling its ends).
    SpringCoupling(u32),
    /// `c_h g_k g_l^T` of hinge `h`, `k` and `l` its local vertices.
    Hinge { hinge: u32, k: u8, l: u8 },
    /// `h^2 sum_ab M_ab J_ak J_bl^T` of shape triangle `tri`, slots `k` and `l`.
    Shape { tri: u32, k: u8, l: u8 },
    /// Corner block `(k, l)` of membrane triangle `tri`.
    Membrane { tri: u32, k: u8, l: u8 },
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
    /// Per vertex, CSC-like: the shape-triangle blocks `(tri, k, l)` of row `i` that
    /// the factorization drops; each is compensated by its Frobenius norm on the
    /// diagonal (`[[s I, -B], [-B^T, s I]]` is positive semi-definite for
    /// `s >= |B|`), so the factored matrix stays positive definite. The tighter
    /// rank-one compensation `B B^T / |B|` (each such `B = u v^T` involves a
    /// tip) saves about 1 % of the iterations, not worth its code.
    shape_dropped_start: Vec<u32>,
    shape_dropped: Vec<(u32, u8, u8)>,
    /// Per block (lower blocks only; empty range for upper ones): its sources.
    source_start: Vec<u32>,
    sources: Vec<Source>,
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
        let mut pairs: Vec<(u32, u32)> = (0..n as u32).map(|i| (i, i)).collect();
        for sp in &elements.springs {
            let [a, b] = sp.v;
            pairs.extend([(a, b), (b, a)]);
        }
        for hg in &elements.hinges {
            for k in 0..4 {
                for l in 0..4 {
                    if k != l {
                        pairs.push((hg.v[k], hg.v[l]));
                    }
                }
            }
        }
        for t in &elements.membrane_triangles {
            for i in t.v {
                for j in t.v {
                    if i != j {
                        pairs.push((i, j));
                    }
                }
            }
        }
        for t in &elements.shape_triangles {
            for (k, i) in t.slots() {
                for (l, j) in t.slots() {
                    if k != l && i != j {
                        pairs.push((i, j));
                    }
                }
            }
        }
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
        p.build_sources(elements);
        p.build_csc();
        p
    }

    /// Number of vertices (block rows).
    pub fn vertices(&self) -> usize {
        self.row_start.len().saturating_sub(1)
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

    /// The element terms of every lower block, in element order, and the shape
    /// triangles' blocks that the factorization drops (`shape_dropped`).
    fn build_sources(&mut self, elements: &Elements) {
        let mut tagged: Vec<(u32, Source)> = Vec::new();
        let lower = |s: &Self, i: u32, j: u32| if j <= i { s.slot(i, j) } else { s.slot(j, i) };
        for (e, sp) in elements.springs.iter().enumerate() {
            let [a, b] = sp.v;
            let e = e as u32;
            tagged.push((self.diagonal[a as usize], Source::SpringDiagonal(e)));
            tagged.push((self.diagonal[b as usize], Source::SpringDiagonal(e)));
            tagged.push((lower(self, a, b), Source::SpringCoupling(e)));
        }
        for (h, hg) in elements.hinges.iter().enumerate() {
            for k in 0..4u8 {
                for l in 0..4u8 {
                    let (i, j) = (hg.v[k as usize], hg.v[l as usize]);
                    if j <= i {
                        let hinge = h as u32;
                        tagged.push((self.slot(i, j), Source::Hinge { hinge, k, l }));
                    }
                }
            }
        }
        for (ti, t) in elements.membrane_triangles.iter().enumerate() {
            for k in 0..3u8 {
                for l in 0..3u8 {
                    let (i, j) = (t.v[k as usize], t.v[l as usize]);
                    if j <= i {
                        let tri = ti as u32;
                        tagged.push((self.slot(i, j), Source::Membrane { tri, k, l }));
                    }
                }
            }
        }
        // The shape triangles' sources, and the blocks the factorization drops
        // (compensated on the diagonal: `shape_dropped`), from one lookup per
        // pair of slots: `factored` is symmetric, so the lower block tells.
        let mut dropped: Vec<(u32, (u32, u8, u8))> = Vec::new();
        for (ti, t) in elements.shape_triangles.iter().enumerate() {
            let mut active = [(0usize, 0u32); SHAPE_SLOTS];
            let mut count = 0;
            for (k, i) in t.slots() {
                active[count] = (k, i);
                count += 1;
            }
            let active = &active[..count];
            let mut lower_slot = [[0u32; SHAPE_SLOTS]; SHAPE_SLOTS];
            for (x, &(_, i)) in active.iter().enumerate() {
                for (y, &(_, j)) in active.iter().enumerate().take(x + 1) {
                    let b = if i == j {
                        self.diagonal[i as usize]
                    } else {
                        lower(self, i, j)
                    };
                    (lower_slot[x][y], lower_slot[y][x]) = (b, b);
                }
            }
            let tri = ti as u32;
            for (x, &(k, i)) in active.iter().enumerate() {
                for (y, &(l, j)) in active.iter().enumerate() {
                    let (b, k, l) = (lower_slot[x][y], k as u8, l as u8);
                    if i != j && !self.factored[b as usize] {
                        dropped.push((i, (tri, k, l)));
                    }
                    if j <= i {
                        tagged.push((b, Source::Shape { tri, k, l }));
                    }
                }
            }
        }
        (self.shape_dropped_start, self.shape_dropped) = group_by_key(self.vertices(), &dropped);
        // Grouped stably: the sources of a block stay in element order.
        (self.source_start, self.sources) = group_by_key(self.blocks(), &tagged);
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

    /// Per vertex: the diagonal compensation of the dropped tip-tip blocks (module
    /// docs), projected like the system (`S c g g^T S`).
    pub fn compensation(
        &self,
        terms: &ElementBlocks<'_>,
        projection: &[Option<Vector>],
        extra: &mut Vec<Matrix3>,
    ) {
        extra.resize(self.vertices(), Matrix3::ZERO);
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
                for &(tri, k, l) in &self.shape_dropped[range] {
                    let b = terms.shape_block(tri as usize, k as usize, l as usize);
                    sigma += (b.x_axis.length_squared()
                        + b.y_axis.length_squared()
                        + b.z_axis.length_squared())
                    .sqrt();
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

    /// Sums the element terms into `blocks` (module docs): `M + h D + h^2 K`.
    /// `lower`: scratch that receives the lower blocks first.
    pub fn gather(
        &self,
        terms: &ElementBlocks<'_>,
        lower: &mut Vec<Matrix3>,
        blocks: &mut Vec<Matrix3>,
    ) {
        lower.resize(self.blocks(), Matrix3::ZERO);
        blocks.resize(self.blocks(), Matrix3::ZERO);
        // Each lower block (and the diagonal) from its own sources, in element order.
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
                let range = self.source_start[slot] as usize..self.source_start[slot + 1] as usize;
                for src in &self.sources[range] {
                    m += match *src {
                        Source::SpringDiagonal(e) => terms.springs[e as usize],
                        Source::SpringCoupling(e) => -terms.springs[e as usize],
                        Source::Hinge { hinge, k, l } => {
                            let g = &terms.hinge_gradients[4 * hinge as usize..];
                            outer(g[k as usize], g[l as usize])
                                * terms.hinge_coefficients[hinge as usize]
                        }
                        Source::Shape { tri, k, l } => {
                            terms.shape_block(tri as usize, k as usize, l as usize)
                        }
                        Source::Membrane { tri, k, l } => {
                            let tri = tri as usize;
                            terms.membrane_triangles[tri].block(
                                &terms.membrane_blocks[tri],
                                k as usize,
                                l as usize,
                            )
                        }
                    };
                }
                if j == i {
                    m += Matrix3::from_diagonal(Vector::splat(terms.diagonal_mass[i]));
                }
                *out = m;
            });
        // Then every block: a lower one as computed, an upper one as its mirror's
        // transpose (summed once, not twice).
        let lower = &*lower;
        blocks
            .par_iter_mut()
            .enumerate()
            .with_min_len(PAR_MIN)
            .for_each(|(slot, out)| {
                *out = if self.columns[slot] <= self.rows[slot] {
                    lower[slot]
                } else {
                    lower[self.mirror[slot] as usize].transpose()
                };
            });
    }

    /// The projected system `S A S + (I - S) m` of the module docs of
    /// [`super::implicit`]: `filter[i]` is `None` for a free vertex, `Some(0)` for a
    /// held one (all three directions prescribed) and `Some(n)` for a contact whose
    /// normal `n` is prescribed. `scale[i]` is the diagonal put back on the
    /// prescribed directions (the vertex's mass, so the matrix keeps its scale).
    pub fn project(
        &self,
        raw: &[Matrix3],
        projection: &[Option<Vector>],
        scale: &[Scalar],
        out: &mut Vec<Matrix3>,
    ) {
        out.resize(raw.len(), Matrix3::ZERO);
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
                let si = s(i);
                let mut m = raw[slot];
                if let Some(si) = si {
                    m = si * m;
                }
                if let Some(sj) = s(j) {
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
}

/// `a b^T`.
pub(super) fn outer(a: Vector, b: Vector) -> Matrix3 {
    Matrix3::from_cols(a * b.x, a * b.y, a * b.z)
}
