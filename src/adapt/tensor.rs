//! Tensor-product refinement (`method = "tensor"`): anisotropic refinement of
//! a rectangle's grid by whole grid lines, so that a sheet bent along one
//! axis only is halved along that axis only.
//!
//! Why. A strip bent along its length (the cantilever) needs short cells
//! along the bend and none across it: one cell across the strip gives the
//! square cells' rest error within 1 % at 1/25 of the wall time, but
//! red-green's 1-4 splits halve a cell both ways, so from a base one cell
//! across it carries 169 vertices at level 4 where 82 do. Anisotropic
//! bisection in a metric makes oblique thin triangles on which drape's
//! bending is wrong (`crate::physics::shape`); every structured mesh of stretched right
//! triangles bends exactly. This method keeps the mesh such a structured
//! mesh: the cloth is a tensor grid, its u-lines and v-lines each kept in a
//! one-dimensional binary hierarchy, and a pass inserts a line halving a
//! column (or row) or removes one that halved its parent. The mesh is
//! always conforming (a line crosses the whole sheet), every cell is a
//! rectangle split into two right triangles, and every new vertex is the
//! midpoint of an edge of the old mesh, so `transfer.rs` carries the state.
//!
//! What it costs. A line crosses the whole sheet: a fold that is not along
//! an axis, or a bend that is needed in one corner only, refines the whole
//! row or column through it. It suits strips and sheets bent about an axis,
//! not a falling tablecloth. Cells of different sizes meet only across grid
//! lines (there are no hanging nodes).
//!
//! The measure along u at a vertex is the bend of its grid line there: the
//! angle `phi` between the two segments of the row through it, counting only
//! the part of the turn about an axis in the surface (the surface normal at
//! the vertex is the cross product of the row's and the column's chords), so
//! that a line curving within the surface under shear or uneven stretch is
//! not a bend (along v the same with the column). With the angle criterion
//! a column splits where `phi` at one of its two bounding lines exceeds
//! `refine_angle` and a line goes where `phi` at it and at its two
//! neighbours is below `coarsen_angle` (and half `refine_angle`), as the
//! papers' criterion does with dihedral angles. With the sizing criterion
//! (`sizing.rs`) the curvature is `kappa = phi / hbar` (`hbar` the mean of
//! the two segments' material lengths), a column of width `h` splits where
//! `kappa h > refine_angle`, and a line goes where its parent column `H = 2
//! h` would carry `kappa H <= refine_angle / hysteresis`, `kappa` the
//! largest at the three lines. A row or column is judged by its largest
//! value over the whole sheet. Adjacent columns (rows) differ by at most one
//! halving: a split that would leave a neighbour two halvings coarser splits
//! that neighbour too (a forced split), and a removal that would leave one
//! two halvings finer is refused. So neighbouring cells differ by one halving
//! at most, in width by a factor of two at most on a uniform base grid. The
//! base lines need not be uniform: a rectangle's grid fitted to box pin
//! regions (`crate::mesh::fitted_lines`) has bands of slightly different
//! cells, and each base column is halved as a uniform one is. Levels follow paper A's count: a halving adds 2,
//! and `max_level` (even) allows `max_level / 2` halvings either way; a
//! triangle's level is that of its finer direction.
//!
//! A sheet with one cell across a direction has no interior line there to
//! measure, so it is never refined that way (the cantilever with
//! `cloth.short_side_segments = 1`: exactly what it needs).
//!
//! The lines' whole turn is not the measure: it counts a line curving within
//! the surface, so a flat sheet sheared in its plane would refine (test
//! `a_flat_sheet_distorted_in_its_plane_does_not_refine`).
//!
//! Where it pays: on the
//! cantilever from its own square cells, 1.03 times uniform 40's error at
//! rest in 0.18 of its wall time, 0.82 of the time of the uniform mesh of
//! its own finest cells; on `hanging_sheet_rest`, `drape_sphere`,
//! `tablecloth` and the flag, no better than red-green or the edge method
//! (lines through point pins and folds in every direction refine most of
//! the sheet). On stretched cells the implicit step's single Newton
//! iteration is much less accurate in fast motion (the 1-across strip's
//! swing: 0.74 % of the diagonal from the reference, 0.030 % with four
//! iterations); at rest it does not matter.

mod axis;

use crate::math::{Scalar, Vector, Vector2};
use crate::mesh::Mesh;

use super::transfer::{Origin, Remeshed};
use axis::{Axis, Line, Source};
pub(super) use axis::{AxisOps, Thresholds};

/// The mesh given to [`TensorGrid::from_mesh`] is not a rectangle's grid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "adapt.method = \"tensor\" needs the grid of a generated rectangle (shape = \"rectangle\"): {0}"
)]
pub struct NotAGrid(pub String);

/// A rectangle's grid as two axes of lines; vertex `j * nu + i` of the world's
/// mesh sits at u-line `i` and v-line `j`.
#[derive(Debug, Clone, PartialEq)]
pub struct TensorGrid {
    u: Axis,
    v: Axis,
    alternating: bool,
}

impl TensorGrid {
    /// The grid of a mesh made by `mesh::rectangle_cells` (vertices row by row
    /// along u, each cell split by one diagonal, all the same way or
    /// alternating); anything else is refused. The pattern is read from the
    /// triangles; a single cell matches both and is taken as alternating.
    pub fn from_mesh(mesh: &Mesh) -> Result<TensorGrid, NotAGrid> {
        let coords = |f: fn(&Vector2) -> Scalar| {
            let mut c: Vec<Scalar> = mesh.material.iter().map(f).collect();
            c.sort_by(Scalar::total_cmp);
            c.dedup();
            c
        };
        let (us, vs) = (coords(|p| p.x), coords(|p| p.y));
        let base = |c: Vec<Scalar>| Axis {
            lines: c.into_iter().map(|at| Line { at, level: 0 }).collect(),
        };
        let (u, v) = (base(us), base(vs));
        if u.n() < 2 || v.n() < 2 || u.n() * v.n() != mesh.vertex_count() {
            return Err(NotAGrid(format!(
                "{} vertices on {} distinct u and {} distinct v coordinates",
                mesh.vertex_count(),
                u.n(),
                v.n()
            )));
        }
        for (k, p) in mesh.material.iter().enumerate() {
            let (i, j) = (k % u.n(), k / u.n());
            if p.x != u.lines[i].at || p.y != v.lines[j].at {
                return Err(NotAGrid(format!(
                    "vertex {k} is not the grid's node ({i}, {j}) in row order"
                )));
            }
        }
        for alternating in [true, false] {
            let grid = TensorGrid {
                u: u.clone(),
                v: v.clone(),
                alternating,
            };
            let (tris, _) = grid.triangles();
            if tris == mesh.triangles {
                return Ok(grid);
            }
        }
        Err(NotAGrid(
            "its triangles are not the grid's cells split by regular or alternating diagonals"
                .to_owned(),
        ))
    }

    /// Checks that `mesh` is this grid (its vertices the grid's nodes in row
    /// order, its triangles the grid's cells with their diagonals), that every
    /// line that is not a base line sits at the middle of its parent column
    /// (between the nearest coarser lines) one level finer than it, and that
    /// neighbouring columns differ by one halving at most.
    pub fn check(&self, mesh: &Mesh) -> Result<(), String> {
        let nu = self.u.n();
        if mesh.vertex_count() != nu * self.v.n() {
            return Err(format!(
                "tensor grid of {} x {} nodes, mesh of {} vertices",
                nu,
                self.v.n(),
                mesh.vertex_count()
            ));
        }
        for (k, p) in mesh.material.iter().enumerate() {
            let (u, v) = (self.u.lines[k % nu].at, self.v.lines[k / nu].at);
            if p.x != u || p.y != v {
                return Err(format!("vertex {k} at {p:?}, its grid node at ({u}, {v})"));
            }
        }
        if self.triangles().0 != mesh.triangles {
            return Err("the mesh's triangles are not the grid's cells".to_owned());
        }
        for (name, axis) in [("u", &self.u), ("v", &self.v)] {
            for c in 0..axis.n() - 1 {
                if axis.width(c) <= 0.0 {
                    return Err(format!("{name}-lines {c} and {} out of order", c + 1));
                }
            }
            // A line of level L halves the column between the nearest lines
            // of lower level on either side, whose level is L - 1.
            for (m, line) in axis.lines.iter().enumerate().filter(|(_, l)| l.level > 0) {
                let coarser = |k: &usize| axis.lines[*k].level < line.level;
                let (l, r) = ((0..m).rev().find(coarser), (m + 1..axis.n()).find(coarser));
                let (Some(l), Some(r)) = (l, r) else {
                    return Err(format!(
                        "{name}-line {m} (level {}) has no parent column",
                        line.level
                    ));
                };
                let (a, b) = (axis.lines[l], axis.lines[r]);
                if line.at != 0.5 * (a.at + b.at) || line.level != a.level.max(b.level) + 1 {
                    return Err(format!(
                        "{name}-line {m} at {} (level {}) does not halve lines {l} and {r} at {} and {} (levels {}, {})",
                        line.at, line.level, a.at, b.at, a.level, b.level
                    ));
                }
            }
            for c in 1..axis.n().saturating_sub(1) {
                let (a, b) = (axis.column_level(c - 1), axis.column_level(c));
                if a.abs_diff(b) > 1 {
                    return Err(format!(
                        "{name}-columns {} and {c} differ by {} halvings",
                        c - 1,
                        a.abs_diff(b)
                    ));
                }
            }
        }
        Ok(())
    }

    /// Vertices along u and v.
    pub fn counts(&self) -> (usize, usize) {
        (self.u.n(), self.v.n())
    }

    /// The lines' material coordinates along u and v (for tests and
    /// inspection).
    pub fn lines(&self) -> (Vec<Scalar>, Vec<Scalar>) {
        let at = |a: &Axis| a.lines.iter().map(|l| l.at).collect();
        (at(&self.u), at(&self.v))
    }

    /// The level (halvings) of every column along u and every row along v.
    pub(super) fn column_levels(&self) -> (Vec<u8>, Vec<u8>) {
        let levels = |a: &Axis| (0..a.n() - 1).map(|c| a.column_level(c)).collect();
        (levels(&self.u), levels(&self.v))
    }

    /// Whether the cell at columns `i`, rows `j` is split along its diagonal
    /// from (i, j) to (i + 1, j + 1), given each axis's column indices
    /// ([`Axis::cell_indices`]). Alternating grids alternate among cells of
    /// the same size: the parity is that of the cell's index among cells of
    /// its width and height, so a cell keeps its diagonal when lines are
    /// inserted elsewhere.
    fn along_ac(&self, index: &(Vec<i64>, Vec<i64>), i: usize, j: usize) -> bool {
        !self.alternating || (index.0[i] + index.1[j]) % 2 == 0
    }

    /// The column indices of both axes, for [`TensorGrid::along_ac`].
    fn cell_indices(&self) -> (Vec<i64>, Vec<i64>) {
        (self.u.cell_indices(), self.v.cell_indices())
    }

    /// The grid's triangles (row order of vertices) and their levels.
    pub fn triangles(&self) -> (Vec<[u32; 3]>, Vec<u8>) {
        let nu = self.u.n();
        let id = |i: usize, j: usize| (j * nu + i) as u32;
        let mut tris = Vec::with_capacity(2 * (nu - 1) * (self.v.n() - 1));
        let mut levels = Vec::with_capacity(tris.capacity());
        let index = self.cell_indices();
        for j in 0..self.v.n() - 1 {
            for i in 0..nu - 1 {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                if self.along_ac(&index, i, j) {
                    tris.extend([[a, b, c], [a, c, d]]);
                } else {
                    tris.extend([[a, b, d], [b, c, d]]);
                }
                let level = self.u.column_level(i).max(self.v.column_level(j));
                let level = level.saturating_mul(2);
                levels.extend([level, level]);
            }
        }
        (tris, levels)
    }

    /// The largest measure at each line of both axes, from the world's
    /// positions `x` (row order): the angle by which the grid lines through
    /// it bend out of the surface there, or with `sizing` that angle over the
    /// mean length of the two segments (a curvature). The surface normal at a
    /// vertex is the cross product of the two lines' chords through it (one
    /// sided at the boundary), and only the part of the turn about an axis in
    /// the surface counts: a line curving within the surface (shear, uneven
    /// stretch) is not a bend.
    pub(super) fn measures(&self, x: &[Vector], sizing: bool) -> (Vec<Scalar>, Vec<Scalar>) {
        let (nu, nv) = (self.u.n(), self.v.n());
        let normal = |i: usize, j: usize| {
            let at = |i: usize, j: usize| x[j * nu + i];
            let du = at((i + 1).min(nu - 1), j) - at(i.saturating_sub(1), j);
            let dv = at(i, (j + 1).min(nv - 1)) - at(i, j.saturating_sub(1));
            du.cross(dv).normalize_or_zero()
        };
        let bend = |p: Vector, q: Vector, r: Vector, n: Vector| {
            let (a, b) = (q - p, r - q);
            let c = a.cross(b);
            (c - n * c.dot(n)).length().atan2(a.dot(b))
        };
        let mut at_u = vec![0.0; nu];
        let mut at_v = vec![0.0; nv];
        for (i, slot) in at_u.iter_mut().enumerate().take(nu - 1).skip(1) {
            let hbar = 0.5 * (self.u.lines[i + 1].at - self.u.lines[i - 1].at);
            for j in 0..nv {
                let k = j * nu + i;
                let m = bend(x[k - 1], x[k], x[k + 1], normal(i, j));
                *slot = Scalar::max(*slot, if sizing { m / hbar } else { m });
            }
        }
        for (j, slot) in at_v.iter_mut().enumerate().take(nv - 1).skip(1) {
            let hbar = 0.5 * (self.v.lines[j + 1].at - self.v.lines[j - 1].at);
            for i in 0..nu {
                let k = j * nu + i;
                let m = bend(x[k - nu], x[k], x[k + nu], normal(i, j));
                *slot = Scalar::max(*slot, if sizing { m / hbar } else { m });
            }
        }
        (at_u, at_v)
    }

    /// The operations of a pass on both axes.
    pub(super) fn marks(
        &self,
        measures: &(Vec<Scalar>, Vec<Scalar>),
        th: &Thresholds,
    ) -> (AxisOps, AxisOps) {
        (self.u.marks(&measures.0, th), self.v.marks(&measures.1, th))
    }

    /// Applies the operations and returns the new topology (vertices in row
    /// order; every new vertex the midpoint of an edge of the old mesh).
    pub(super) fn apply(&mut self, ops: &(AxisOps, AxisOps)) -> Remeshed {
        let old = self.clone();
        let su = self.u.apply(&ops.0);
        let sv = self.v.apply(&ops.1);
        let (nu, nv) = (self.u.n(), self.v.n());
        let old_nu = old.u.n();
        // New index of each surviving old line.
        let new_of = |s: &[Source], n_old: usize| {
            let mut m = vec![usize::MAX; n_old];
            for (k, src) in s.iter().enumerate() {
                if let Source::Old(i) = src {
                    m[*i] = k;
                }
            }
            m
        };
        let (nu_of, nv_of) = (new_of(&su, old_nu), new_of(&sv, old.v.n()));
        let old_index = old.cell_indices();
        let id = |i: usize, j: usize| (j * nu + i) as u32;
        let mut material = Vec::with_capacity(nu * nv);
        let mut origin = Vec::with_capacity(nu * nv);
        for (j, sj) in sv.iter().enumerate() {
            for (i, si) in su.iter().enumerate() {
                material.push(Vector2::new(self.u.lines[i].at, self.v.lines[j].at));
                origin.push(match (*si, *sj) {
                    (Source::Old(a), Source::Old(b)) => Origin::Old((b * old_nu + a) as u32),
                    (Source::Between(a), Source::Old(_)) => {
                        Origin::Midpoint(id(nu_of[a], j), id(nu_of[a + 1], j))
                    }
                    (Source::Old(_), Source::Between(b)) => {
                        Origin::Midpoint(id(i, nv_of[b]), id(i, nv_of[b + 1]))
                    }
                    (Source::Between(a), Source::Between(b)) => {
                        // The centre of old cell (a, b): the midpoint of its diagonal.
                        let (l, r, lo, hi) = (nu_of[a], nu_of[a + 1], nv_of[b], nv_of[b + 1]);
                        if old.along_ac(&old_index, a, b) {
                            Origin::Midpoint(id(l, lo), id(r, hi))
                        } else {
                            Origin::Midpoint(id(r, lo), id(l, hi))
                        }
                    }
                });
            }
        }
        let mut parents_first: Vec<u32> = (0..origin.len() as u32).collect();
        parents_first.sort_by_key(|&k| matches!(origin[k as usize], Origin::Midpoint(..)));
        let (triangles, levels) = self.triangles();
        Remeshed {
            material,
            triangles,
            levels,
            origin,
            parents_first,
            corners: None,
        }
    }
}
