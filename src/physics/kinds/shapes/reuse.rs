//! Incremental rebuild: which shape triangles keep their matrix after a remesh.
//!
//! A shape triangle's matrix `M` (`shape.rs`) is the one element constant that
//! costs more than a few flops (a transition triangle's takes a 3 x 3
//! pseudo-inverse), and it depends on the triangle's stencil only: the material
//! points of its corners and of the tips across its interior edges, which edges
//! are interior, the levels of the triangle and its neighbours, and which
//! vertices a clamp holds. A remesh changes the mesh in a few places, so most
//! stencils come through it unchanged; [`Reuse`] finds them and their triangles
//! keep `M`, bit for bit (`tests/integration/elements.rs` compares every
//! rebuild with a fresh build over random remeshes).
//!
//! * Vertices are matched by material point (exact bits): a remesh keeps each
//!   surviving vertex's point and gives new vertices new points. A point that two
//!   vertices of the previous mesh share (a seam) matches neither.
//! * A triangle matches a previous one with the same corners in the same order
//!   (so that its area, computed from the first corner, has the same bits) and
//!   the same level, found among the previous triangles at its first corner.
//! * A shape triangle is kept when its triangle and every neighbour across an
//!   interior edge match, its tips are the previous element's, and each vertex of
//!   its stencil is held by the same clamp (or none) as before.
//!
//! Everything else is recomputed, into the buffers of the previous build:
//! springs, hinges, masses and gather lists cost a few flops per element, less
//! than finding each one's predecessor would.

use crate::math::Vector2;
use crate::mesh::Mesh;
use crate::mesh::PairMap;
use crate::physics::elements::{Incidence, MaterialParams};
use crate::physics::shape::{SHAPE_SLOTS, ShapeMatrix, ShapeTriangle};

/// No match.
const NONE: u32 = u32::MAX;

/// How the last rebuild of the shape triangles ([`super::ShapeSet`]) made
/// them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RebuildCounts {
    /// Shape triangles whose matrix was kept from the previous mesh.
    pub kept: usize,
    /// Shape triangles whose matrix was computed.
    pub computed: usize,
}

/// What a set of elements was built from.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Previous {
    material: Vec<Vector2>,
    triangles: Vec<[u32; 3]>,
    levels: Vec<u8>,
    /// Per vertex: the clamping pin, or `NONE`.
    clamped: Vec<u32>,
    /// Per triangle: its shape triangle, or `NONE` (held, or no shape model).
    shape_of: Vec<u32>,
    /// The material (`None`: nothing built yet).
    params: Option<MaterialParams>,
}

impl Previous {
    /// Records what elements with shape triangles `shapes` were just built from.
    pub(crate) fn record(
        &mut self,
        mesh: &Mesh,
        mat: &MaterialParams,
        clamped: &[u32],
        shapes: &[ShapeTriangle],
    ) {
        self.material.clone_from(&mesh.material);
        self.triangles.clone_from(&mesh.triangles);
        self.levels.clone_from(&mesh.levels);
        self.clamped.clear();
        self.clamped
            .extend((0..mesh.vertex_count()).map(|v| clamp_of(clamped, v as u32)));
        // Shape triangles come in triangle order, one per triangle not held.
        self.shape_of.clear();
        let mut next = shapes.iter().enumerate().peekable();
        for tri in &mesh.triangles {
            let own = next.next_if(|(_, st)| st.v[..3] == tri[..]);
            self.shape_of.push(own.map_or(NONE, |(p, _)| p as u32));
        }
        debug_assert!(
            next.next().is_none(),
            "a shape triangle without its triangle"
        );
        self.params = Some(*mat);
    }
}

/// The clamping pin of vertex `v` (`clamped` empty: none).
fn clamp_of(clamped: &[u32], v: u32) -> u32 {
    clamped.get(v as usize).copied().unwrap_or(NONE)
}

/// The matching of a new mesh against the previous one.
#[derive(Debug, Clone, Default)]
pub(crate) struct Reuse {
    by_point: PairMap<[u64; 2], u32>,
    /// Per new vertex: the previous vertex at its material point, or `NONE`.
    old_vertex: Vec<u32>,
    /// Per new triangle: the matching previous triangle, or `NONE` (empty: no
    /// previous mesh to match).
    old_triangle: Vec<u32>,
}

impl Reuse {
    /// Forgets the last matching: nothing is kept.
    fn nothing_to_keep(&mut self) {
        self.old_vertex.clear();
        self.old_triangle.clear();
    }

    /// Matches `mesh`'s vertices and triangles against `previous` (whose
    /// triangles at each vertex are `old_at`), for rigidity and model `mat`.
    pub(crate) fn match_previous(
        &mut self,
        previous: &Previous,
        old_at: &Incidence,
        mesh: &Mesh,
        mat: &MaterialParams,
    ) {
        self.nothing_to_keep();
        // A garment's panels may overlap in pattern space: a material point does
        // not name one vertex there, so nothing is matched.
        if previous.params != Some(*mat) || mesh.panels().is_some() {
            return;
        }
        self.by_point.clear();
        for (i, p) in previous.material.iter().enumerate() {
            self.by_point
                .entry(point_key(*p))
                .and_modify(|v| *v = NONE)
                .or_insert(i as u32);
        }
        let by_point = &self.by_point;
        self.old_vertex.extend(
            mesh.material
                .iter()
                .map(|p| by_point.get(&point_key(*p)).copied().unwrap_or(NONE)),
        );
        let old_vertex = &self.old_vertex;
        self.old_triangle
            .extend(mesh.triangles.iter().zip(&mesh.levels).map(|(tri, level)| {
                let old = tri.map(|v| old_vertex[v as usize]);
                if old.contains(&NONE) {
                    return NONE;
                }
                old_at
                    .of(old[0] as usize)
                    .iter()
                    .copied()
                    .find(|&t| {
                        previous.triangles[t as usize] == old
                            && previous.levels[t as usize] == *level
                    })
                    .unwrap_or(NONE)
            }));
    }

    /// The matrix new triangle `t` keeps from `old_shapes` (the previous shape
    /// triangles), given its stencil and neighbours, or `None` (module docs:
    /// when a shape triangle is kept).
    pub(crate) fn kept(
        &self,
        previous: &Previous,
        old_shapes: &[ShapeTriangle],
        t: usize,
        stencil: &ShapeTriangle,
        across: &[usize; 3],
        clamped: &[u32],
    ) -> Option<ShapeMatrix> {
        let old_t = *self.old_triangle.get(t)?;
        let p = *previous.shape_of.get(old_t as usize)?;
        let old = old_shapes.get(p as usize)?;
        if old.interior != stencil.interior {
            return None;
        }
        let same_vertex = |k: usize| {
            let v = stencil.v[k];
            self.old_vertex[v as usize] == old.v[k]
                && clamp_of(clamped, v) == previous.clamped[old.v[k] as usize]
        };
        let same_neighbour = |a: usize| self.old_triangle[across[a]] != NONE;
        // Corners always; a tip only across an interior edge (else unused).
        let used = |k: usize| k < 3 || stencil.interior[k - 3];
        let stencil_kept = (0..SHAPE_SLOTS).all(|k| !used(k) || same_vertex(k))
            && (0..3).all(|a| !stencil.interior[a] || same_neighbour(a));
        stencil_kept.then_some(old.m)
    }
}

/// A material point's exact bits.
fn point_key(p: Vector2) -> [u64; 2] {
    [p.x.to_bits(), p.y.to_bits()]
}
