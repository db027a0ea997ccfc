//! The shape triangles of one mesh ([`ShapeSet`]): built by the shapes kind,
//! incrementally after a remesh (module [`super::reuse`]), with their interior
//! edges, their fold splits' system and their incidence lists.

use super::reuse::{Previous, RebuildCounts, Reuse};
use crate::physics::elements::{BuildContext, Incidence};
use crate::physics::shape::{
    FoldEdges, FoldSplits, SHAPE_SLOTS, ShapeScratch, ShapeTriangle, build_shape_triangles_into,
};
use crate::spec::BendingModel;

/// The shape triangles of one mesh, their interior edges, their fold splits'
/// system and their incidence lists.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ShapeSet {
    /// Shape-operator bending elements, one per triangle not held by a clamp
    /// (only with that model and non-zero rigidity).
    pub triangles: Vec<ShapeTriangle>,
    /// The factored system of the fold splits.
    pub fold_splits: FoldSplits,
    /// The interior edges, each once (their folds are computed per edge).
    pub fold_edges: FoldEdges,
    /// Shape-triangle slots `SHAPE_SLOTS * element + k` where the vertex is
    /// `v[k]` (used slots only).
    pub slots: Incidence,
    /// The direct solver's matrix holds only the first-ring blocks, each
    /// second-ring block lumped on the diagonal (module `blocks`); set by the
    /// stepper from [`crate::spec::BendingMatrix`], false (every block) for
    /// elements built alone. A rebuild keeps it.
    pub lump_second_ring: bool,
    /// The number of split unknowns of `triangles` (the size of the system
    /// [`ShapeSet::renewed_fold_splits`] makes).
    splits: usize,
    /// What these triangles were built from, for the next rebuild.
    previous: Previous,
    /// Scratch memory of a rebuild (never part of a comparison).
    scratch: Scratch,
}

/// Scratch memory of a rebuild, kept between rebuilds.
#[derive(Debug, Clone, Default)]
struct Scratch {
    shapes: Vec<ShapeTriangle>,
    shape: ShapeScratch,
    pairs: Vec<(u32, u32)>,
    reuse: Reuse,
    counts: RebuildCounts,
}

/// Scratch memory holds nothing the elements mean.
impl PartialEq for Scratch {
    fn eq(&self, _: &Scratch) -> bool {
        true
    }
}

impl ShapeSet {
    /// Makes these the shape triangles of `cx`'s mesh, each keeping its
    /// matrix where its whole stencil was already in the mesh they were built
    /// for (module [`super::reuse`]); the fold splits' system is left that of
    /// the mesh before ([`ShapeSet::renewed_fold_splits`] makes the new one).
    pub(super) fn rebuild(&mut self, cx: &BuildContext<'_>) {
        let (mesh, mat) = (cx.mesh, cx.mat);
        let n = mesh.vertex_count();
        let scratch = &mut self.scratch;
        scratch.shapes.clear();
        let mut kept = 0;
        let mut splits = 0;
        if mat.bending > 0.0 && mat.bending_model == BendingModel::ShapeOperator {
            let (old, previous) = (&self.triangles, &self.previous);
            let reuse = &mut scratch.reuse;
            reuse.match_previous(previous, cx.previous_vertex_triangles, mesh, mat);
            let reuse = &*reuse;
            splits = build_shape_triangles_into(
                mesh,
                cx.area,
                mat.bending,
                cx.clamped,
                &mut scratch.shape,
                |t, stencil, across| {
                    let m = reuse.kept(previous, old, t, stencil, across, cx.clamped);
                    kept += usize::from(m.is_some());
                    m
                },
                &mut scratch.shapes,
            );
        }
        scratch.counts = RebuildCounts {
            kept,
            computed: scratch.shapes.len() - kept,
        };
        std::mem::swap(&mut self.triangles, &mut scratch.shapes);
        self.splits = splits;
        self.fold_edges = FoldEdges::build(&self.triangles, n);
        let pairs = &mut scratch.pairs;
        pairs.clear();
        pairs.extend(self.triangles.iter().enumerate().flat_map(|(p, st)| {
            st.slots()
                .map(move |(k, v)| (v, (SHAPE_SLOTS * p + k) as u32))
        }));
        self.slots.fill(n, pairs.iter().copied());
        self.previous.record(mesh, mat, cx.clamped, &self.triangles);
    }

    /// The fold splits' system of the current shape triangles (reusing what
    /// it shares with the present one: [`FoldSplits::renew`]).
    pub fn renewed_fold_splits(&self) -> FoldSplits {
        self.fold_splits
            .renew(&self.triangles, self.splits)
            .expect("the plate matrices of a valid mesh are positive definite")
    }

    /// How the last rebuild made its shape triangles.
    pub fn last_rebuild(&self) -> RebuildCounts {
        self.scratch.counts
    }
}
