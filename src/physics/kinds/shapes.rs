//! The shape triangles kind (`shape.rs`): `SHAPE_SLOTS` force slots per
//! triangle (used slots only in the incidence lists); the folds are computed
//! per interior edge and their splits solved over the whole mesh first
//! ([`ShapeSet::fold_edges`], [`ShapeSet::fold_splits`]); in the implicit step
//! the Gauss-Newton block `J^T M J` of the folds' Jacobian `J`.

mod blocks;
mod reuse;
mod set;

#[cfg(test)]
pub(crate) use blocks::{ShapeOp, frobenius, moved_angles};

use rayon::prelude::*;

use super::{ForceKind, kick_slots, slot_pairs};
use crate::math::{Scalar, Vector, deterministic_sum};
use crate::mesh::Mesh;
use crate::physics::block::{Band, BlockPattern};
use crate::physics::elements::{BuildContext, Elements};
use crate::physics::forces::PAR_MIN;
use crate::physics::shape::FoldSplits;
use crate::physics::shape::{EdgeFold, SHAPE_SLOTS, ShapeJacobian, rates, spread};
pub use blocks::ShapeBlocks;
pub use reuse::RebuildCounts;
pub use set::ShapeSet;

/// The shape triangles kind: the triangles of [`ShapeSet`].
#[derive(Debug, Clone, Copy, Default)]
pub struct ShapeTriangles;

/// The shape triangles' scratch of the element pass.
#[derive(Debug, Default, Clone)]
pub struct ShapeForces {
    /// Force on each shape triangle's slots, `SHAPE_SLOTS` per element.
    pub slots: Vec<Vector>,
    /// Each interior edge's fold ([`crate::physics::shape::FoldEdges`]).
    pub edge_folds: Vec<EdgeFold>,
    /// Each shape triangle's three folds.
    pub folds: Vec<[Scalar; 3]>,
    /// Each shape triangle's fold gradients by slot.
    pub fold_gradients: Vec<ShapeJacobian>,
    /// The fold splits at the current folds.
    pub splits: Vec<Scalar>,
}

/// The shape triangles' terms of the linearised step.
#[derive(Debug, Default, Clone)]
pub struct ShapeLinear {
    /// Per triangle and slot: its right-hand side slot, then its slot of a product.
    pub slot: Vec<Vector>,
    /// Per triangle: the folds' gradients by slot (CG solver only).
    pub grad: Vec<ShapeJacobian>,
    /// Per interior edge: its fold.
    pub edge_folds: Vec<EdgeFold>,
    /// Per shape triangle: its folds.
    pub folds: Vec<[Scalar; 3]>,
    /// The fold splits at the step's start.
    pub splits: Vec<Scalar>,
}

/// The fold splits that minimise the bending energy at `x` (see
/// [`solve_splits`]); empty without shape triangles.
pub fn splits_at(el: &Elements, x: &[Vector]) -> Vec<Scalar> {
    let (mut folds, mut splits) = (Vec::new(), Vec::new());
    if !el.kinds.shapes.triangles.is_empty() {
        solve_splits(el, x, &mut folds, &mut splits);
    }
    splits
}

/// Into `folds`, `gradients` and `splits`: each shape triangle's folds at
/// `x` and their gradients by slot, then the splits that minimise the
/// bending energy for them (`shape.rs`, "Splitting the folds"); `edges` is
/// scratch ([`fold_angles`]).
pub fn fold_angles_and_splits(
    el: &Elements,
    x: &[Vector],
    edges: &mut Vec<EdgeFold>,
    folds: &mut Vec<[Scalar; 3]>,
    gradients: &mut Vec<ShapeJacobian>,
    splits: &mut Vec<Scalar>,
) {
    fold_angles(el, x, edges, folds, gradients);
    el.kinds
        .shapes
        .fold_splits
        .solve(&el.kinds.shapes.triangles, folds, splits);
}

/// Into `folds` and `gradients`: each shape triangle's folds at `x` and their
/// gradients by slot (the first half of [`fold_angles_and_splits`]), read
/// from each interior edge's fold, computed once into `edges`.
pub fn fold_angles(
    el: &Elements,
    x: &[Vector],
    edges: &mut Vec<EdgeFold>,
    folds: &mut Vec<[Scalar; 3]>,
    gradients: &mut Vec<ShapeJacobian>,
) {
    let shapes = el.kinds.shapes.triangles.len();
    el.kinds.shapes.fold_edges.compute(x, edges);
    let edges = &*edges;
    folds.resize(shapes, [0.0; 3]);
    gradients.resize(shapes, [[Vector::ZERO; SHAPE_SLOTS]; 3]);
    folds
        .par_iter_mut()
        .zip(gradients.par_iter_mut())
        .enumerate()
        .with_min_len(PAR_MIN / SHAPE_SLOTS)
        .for_each(|(t, (folds, jac))| (*folds, *jac) = el.kinds.shapes.fold_edges.angles(t, edges));
}

/// Into `edges` and `folds`: each interior edge's fold at `x` and each shape
/// triangle's folds read from them ([`fold_angles`] without the gradients by
/// slot, which a pass that needs them reads from `edges` with
/// [`crate::physics::shape::FoldEdges::angles`]).
pub fn edge_folds(
    el: &Elements,
    x: &[Vector],
    edges: &mut Vec<EdgeFold>,
    folds: &mut Vec<[Scalar; 3]>,
) {
    el.kinds.shapes.fold_edges.compute(x, edges);
    let edges = &*edges;
    folds.resize(el.kinds.shapes.triangles.len(), [0.0; 3]);
    folds
        .par_iter_mut()
        .enumerate()
        .with_min_len(PAR_MIN)
        .for_each(|(t, folds)| *folds = el.kinds.shapes.fold_edges.folds(t, edges));
}

/// Into `folds` and `splits`: each shape triangle's folds at `x` and the
/// splits that minimise the bending energy for them (`shape.rs`, "Splitting
/// the folds").
pub fn solve_splits(
    el: &Elements,
    x: &[Vector],
    folds: &mut Vec<[Scalar; 3]>,
    splits: &mut Vec<Scalar>,
) {
    folds.resize(el.kinds.shapes.triangles.len(), [0.0; 3]);
    folds
        .par_iter_mut()
        .with_min_len(PAR_MIN)
        .zip(el.kinds.shapes.triangles.par_iter())
        .for_each(|(f, t)| *f = t.folds(x));
    el.kinds
        .shapes
        .fold_splits
        .solve(&el.kinds.shapes.triangles, folds, splits);
}

impl ShapeTriangles {
    /// The folds at `x` into `lin` before the splits are solved: from each
    /// edge's fold for the direct solver, whose passes read each triangle's
    /// gradients from its edges' folds, and with each triangle's gradients
    /// for the CG solver's products, which read them by triangle.
    pub fn fold(el: &Elements, x: &[Vector], direct: bool, lin: &mut ShapeLinear) {
        if direct {
            edge_folds(el, x, &mut lin.edge_folds, &mut lin.folds);
        } else {
            fold_angles(el, x, &mut lin.edge_folds, &mut lin.folds, &mut lin.grad);
        }
    }
}

impl ForceKind for ShapeTriangles {
    type Set = ShapeSet;
    type Deferred = FoldSplits;
    type Forces = ShapeForces;
    type Linear = ShapeLinear;
    type Kick = Vec<[Vector; SHAPE_SLOTS]>;
    type InPlace = ShapeBlocks;
    const ENERGY_RANK: usize = 3;

    /// One shape triangle per triangle not held by a clamp (shape-operator
    /// model), incrementally ([`ShapeSet`]); the fold splits' system is
    /// deferred.
    fn build(cx: &BuildContext<'_>, set: &mut ShapeSet) {
        set.rebuild(cx);
    }

    /// The fold splits' system of the rebuilt triangles.
    fn deferred(set: &ShapeSet) -> FoldSplits {
        set.renewed_fold_splits()
    }

    fn install(set: &mut ShapeSet, fold_splits: FoldSplits) {
        set.fold_splits = fold_splits;
    }

    fn count(el: &Elements) -> usize {
        el.kinds.shapes.triangles.len()
    }

    fn element_vertices(el: &Elements, e: usize, out: &mut Vec<u32>) {
        out.clear();
        out.extend(el.kinds.shapes.triangles[e].slots().map(|(_, v)| v));
    }

    /// The splits couple every fold: they are solved over the whole mesh.
    fn kick(
        el: &Elements,
        ids: &[u32],
        x: &[Vector],
        _v: &[Vector],
        out: &mut ShapeForces,
        kick: &mut Vec<[Vector; SHAPE_SLOTS]>,
    ) {
        if !ids.is_empty() {
            solve_splits(el, x, &mut out.folds, &mut out.splits);
        }
        let splits = &out.splits;
        kick_slots(ids, 128, &mut out.slots, kick, |p| {
            let mut f = [Vector::ZERO; SHAPE_SLOTS];
            el.kinds.shapes.triangles[p].forces(x, splits, &mut f);
            f
        });
    }

    fn size_forces(el: &Elements, out: &mut ShapeForces) {
        out.slots
            .resize(SHAPE_SLOTS * el.kinds.shapes.triangles.len(), Vector::ZERO);
    }

    fn forces(el: &Elements, x: &[Vector], _v: &[Vector], out: &mut ShapeForces) {
        Self::size_forces(el, out);
        fold_angles_and_splits(
            el,
            x,
            &mut out.edge_folds,
            &mut out.folds,
            &mut out.fold_gradients,
            &mut out.splits,
        );
        let (folds, jacs, splits) = (&out.folds, &out.fold_gradients, &out.splits);
        out.slots
            .par_chunks_exact_mut(SHAPE_SLOTS)
            .with_min_len(PAR_MIN / SHAPE_SLOTS)
            .zip(
                el.kinds
                    .shapes
                    .triangles
                    .par_iter()
                    .zip(folds.par_iter().zip(jacs.par_iter())),
            )
            .for_each(|(f, (t, (theta, jac)))| {
                spread(jac, t.moments(*theta, splits).map(|c| -c), f)
            });
    }

    #[inline(always)]
    fn gather_force(el: &Elements, out: &ShapeForces, i: usize, f: &mut Vector) {
        for &s in el.kinds.shapes.slots.of(i) {
            *f += out.slots[s as usize];
        }
    }

    fn energy(el: &Elements, x: &[Vector]) -> Scalar {
        let splits = splits_at(el, x);
        deterministic_sum(el.kinds.shapes.triangles.len(), |t| {
            el.kinds.shapes.triangles[t].energy(x, &splits)
        })
    }

    /// Nothing before the splits are solved but the folds
    /// ([`ShapeTriangles::fold`]).
    fn linearise(
        _el: &Elements,
        _x: &[Vector],
        _v: &[Vector],
        _h: Scalar,
        _k_term: Scalar,
        _lin: &mut ShapeLinear,
    ) {
    }

    /// Per shape triangle: slot = J^T (-h dE/dtheta - h^2 M J v), from the folds
    /// and their Jacobian (read from the edges' folds) and the folds' splits
    /// (`shape.rs`), solved before.
    fn linearise_solved(
        el: &Elements,
        v: &[Vector],
        h: Scalar,
        k_term: Scalar,
        lin: &mut ShapeLinear,
    ) {
        let shapes = el.kinds.shapes.triangles.len();
        lin.slot.resize(SHAPE_SLOTS * shapes, Vector::ZERO);
        let (edges, splits) = (&lin.edge_folds, &lin.splits);
        lin.slot
            .par_chunks_exact_mut(SHAPE_SLOTS)
            .zip(el.kinds.shapes.triangles.par_iter())
            .enumerate()
            .with_min_len(PAR_MIN / SHAPE_SLOTS)
            .for_each(|(i, (slot, t))| {
                let (theta, jac) = el.kinds.shapes.fold_edges.angles(i, edges);
                let jac = &jac;
                let jv = t.times_m(rates(t, jac, v));
                let moment = t.moments(theta, splits);
                let c = [0, 1, 2].map(|a| -h * moment[a] - h * h * jv[a] * k_term);
                spread(jac, c, slot);
            });
    }

    #[inline(always)]
    fn gather_linear(
        el: &Elements,
        lin: &ShapeLinear,
        i: usize,
        h: Scalar,
        jacobi: bool,
        rhs: &mut Vector,
        diag: &mut Vector,
    ) {
        for &k in el.kinds.shapes.slots.of(i) {
            *rhs += lin.slot[k as usize];
            let (t, slot) = (k as usize / SHAPE_SLOTS, k as usize % SHAPE_SLOTS);
            if !jacobi {
                continue;
            }
            let (m, jac) = (&el.kinds.shapes.triangles[t].m, &lin.grad[t]);
            for a in 0..3 {
                for b in 0..3 {
                    *diag += jac[a][slot] * jac[b][slot] * (h * h * m[a][b]);
                }
            }
        }
    }

    fn product(el: &Elements, lin: &mut ShapeLinear, p: &[Vector], h2: Scalar) {
        lin.slot
            .par_chunks_exact_mut(SHAPE_SLOTS)
            .zip(lin.grad.par_iter())
            .zip(el.kinds.shapes.triangles.par_iter())
            .with_min_len(PAR_MIN / SHAPE_SLOTS)
            .for_each(|((slot, jac), t)| {
                let c = t.times_m(rates(t, jac, p));
                spread(jac, c.map(|c| c * h2), slot);
            });
    }

    #[inline(always)]
    fn gather_product(el: &Elements, lin: &ShapeLinear, i: usize, acc: &mut Vector) {
        for &k in el.kinds.shapes.slots.of(i) {
            *acc += lin.slot[k as usize];
        }
    }

    fn coupling_count(el: &Elements) -> usize {
        SHAPE_SLOTS * (SHAPE_SLOTS - 1) * el.kinds.shapes.triangles.len()
    }

    /// Every pair of used slots, or with the first-ring matrix
    /// (`lump_second_ring`, module [`blocks`]) the first-ring pairs alone.
    fn couplings(el: &Elements, pairs: &mut Vec<(u32, u32)>) {
        if el.kinds.shapes.lump_second_ring {
            Self::factored_pairs(el, |i, j| pairs.push((i, j)));
            return;
        }
        for t in &el.kinds.shapes.triangles {
            slot_pairs(t.slots(), pairs);
        }
    }

    /// With the first-ring matrix, its pairs (the ends of mesh edges, which
    /// the springs or membrane triangles factor too): none of its blocks is
    /// dropped. Otherwise none of its own.
    fn factored_pairs(el: &Elements, mut f: impl FnMut(u32, u32)) {
        if !el.kinds.shapes.lump_second_ring {
            return;
        }
        for t in &el.kinds.shapes.triangles {
            for (k, i) in t.slots() {
                for (l, j) in t.slots() {
                    if k != l && i != j && !blocks::second_ring(k, l) {
                        f(i, j);
                    }
                }
            }
        }
    }

    fn in_place_pattern(el: &Elements, p: &BlockPattern) -> ShapeBlocks {
        ShapeBlocks::build(el, p)
    }

    /// Every block, in place (module [`blocks`]): the bulk of the assembly.
    #[inline(always)]
    fn add_in_place(
        el: &Elements,
        lin: &ShapeLinear,
        data: &ShapeBlocks,
        h2: Scalar,
        band: &mut Band<'_>,
    ) {
        data.add(el, &lin.edge_folds, h2, band);
    }

    fn gershgorin(
        el: &Elements,
        mesh: &Mesh,
        flat: &mut [Vector],
        stiff: &mut [Scalar],
        _damp: &mut [Scalar],
    ) {
        let garment = mesh.panels().is_some();
        for t in &el.kinds.shapes.triangles {
            // Gershgorin bound of J^T M J at the flat rest state.
            if garment {
                let ids: Vec<u32> = t.slots().map(|(_, v)| v).collect();
                mesh.lay_flat(&ids, flat);
            }
            let (_, jac) = t.angles(flat);
            let row: [Scalar; 3] = [0, 1, 2].map(|a| jac[a].iter().map(|g| g.length()).sum());
            for (k, v) in t.slots() {
                for (ma, ja) in t.m.iter().zip(&jac) {
                    for (mab, rb) in ma.iter().zip(&row) {
                        stiff[v as usize] += (mab * ja[k].length() * rb).abs();
                    }
                }
            }
        }
    }
}
