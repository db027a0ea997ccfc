//! The cloth mesh at `cloth/mesh`: shared vertices, duplicated only where triangles of
//! different classes meet, and the topology logged only when it changed.
//!
//! A triangle's class is what colours it: its refinement level (the default), or its
//! garment panel (`--colour-by panel`, [`super::ColourBy`]). `Mesh3D` has no per-face
//! colour, so a vertex where triangles of several classes meet is drawn once per class: the
//! first `V` vertices of the recorded mesh are the simulated mesh's vertices in their order
//! (each in the colour of the class of most of its triangles, the highest on a tie), and
//! after them come the copies, one per vertex and further class it is used at, listed by
//! `duplicate_of` (the simulated vertex each copy repeats). Every frame logs the positions
//! and normals of all of them; a frame whose triangles, levels, classes or vertex count
//! differ from the last logged topology also logs the triangle indices (into the recorded
//! vertices), the vertex colours and class ids (legend and hover label), `triangle_level`
//! (one `u8` per triangle, in the simulated mesh's triangle order) and `duplicate_of`.
//! Rerun keeps the latest value of each component, so every frame shows (and decodes to)
//! the topology last logged at or before it.

use std::collections::HashMap;
use std::sync::Arc;

use rerun::external::arrow::array::{UInt8Array, UInt32Array};

use super::convert;
use crate::math::Vector;

/// Component name of the per-triangle level data on `cloth/mesh` (`u8`, one per triangle).
pub const LEVEL_COMPONENT: &str = "triangle_level";
/// Component name of the copied vertices on `cloth/mesh` (`u32`, one per recorded vertex past
/// the simulated mesh's: recorded vertex `V + i` is a copy of simulated vertex
/// `duplicate_of[i]`).
pub const DUPLICATE_COMPONENT: &str = "duplicate_of";

/// The recorded topology of the cloth mesh, and the inputs it was built from.
#[derive(Debug, Default)]
pub(super) struct ClothMesh {
    /// Simulated vertices of the topology last built.
    vertices: usize,
    /// Triangles of the topology last built (simulated vertex indices).
    triangles: Vec<[u32; 3]>,
    /// Levels of the topology last built.
    levels: Vec<u8>,
    /// Classes (colours) of the triangles of the topology last built.
    classes: Vec<u16>,
    /// Class (colour) of each recorded vertex.
    vertex_classes: Vec<u16>,
    /// Simulated vertex of each recorded vertex past the first `vertices`.
    duplicate_of: Vec<u32>,
    /// Triangles as indices into the recorded vertices.
    indices: Vec<[u32; 3]>,
    /// Whether a topology has been built (and must be logged) yet.
    built: bool,
}

impl ClothMesh {
    /// Rebuilds the recorded topology when `triangles`, `levels`, `classes` or the vertex
    /// count differ from the last one; returns whether they did (the topology must then be
    /// logged). The slices must have been validated (indices in range, one level and one
    /// class per triangle).
    pub(super) fn update(
        &mut self,
        vertices: usize,
        triangles: &[[u32; 3]],
        levels: &[u8],
        classes: &[u16],
    ) -> bool {
        if self.built
            && self.vertices == vertices
            && self.triangles == triangles
            && self.levels == levels
            && self.classes == classes
        {
            return false;
        }
        self.built = true;
        self.vertices = vertices;
        self.triangles.clear();
        self.triangles.extend_from_slice(triangles);
        self.levels.clear();
        self.levels.extend_from_slice(levels);
        self.classes.clear();
        self.classes.extend_from_slice(classes);

        // Each vertex keeps the class of most of its triangles (the highest on a tie), so
        // that as few corners as possible need a copy; other classes get one.
        let mut corners: Vec<(u32, u16)> = triangles
            .iter()
            .zip(classes)
            .flat_map(|(t, &c)| t.map(|i| (i, c)))
            .collect();
        corners.sort_unstable();
        self.vertex_classes.clear();
        self.vertex_classes.resize(vertices, 0);
        let mut best = vec![0usize; vertices];
        for run in corners.chunk_by(|a, b| a == b) {
            let (i, c) = run[0];
            let i = i as usize;
            // Runs come in ascending class per vertex: `>=` keeps the highest on a tie.
            if run.len() >= best[i] {
                best[i] = run.len();
                self.vertex_classes[i] = c;
            }
        }
        self.duplicate_of.clear();
        self.indices.clear();
        let mut copies: HashMap<(u32, u16), u32> = HashMap::new();
        for (t, &c) in triangles.iter().zip(classes) {
            let mut corner = |i: u32, this: &mut Self| -> u32 {
                if this.vertex_classes[i as usize] == c {
                    return i;
                }
                *copies.entry((i, c)).or_insert_with(|| {
                    this.duplicate_of.push(i);
                    this.vertex_classes.push(c);
                    (this.vertex_classes.len() - 1) as u32
                })
            };
            let tri = [corner(t[0], self), corner(t[1], self), corner(t[2], self)];
            self.indices.push(tri);
        }
        true
    }

    /// The simulated vertex of each recorded vertex, in recorded order.
    fn sources(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.vertices).chain(self.duplicate_of.iter().map(|&i| i as usize))
    }

    /// The per-frame part of the row: positions and normals of every recorded vertex.
    pub(super) fn geometry(&self, positions: &[Vector], normals: &[Vector]) -> rerun::Mesh3D {
        rerun::Mesh3D::update_fields()
            .with_vertex_positions(self.sources().map(|i| convert::position(positions[i])))
            .with_vertex_normals(self.sources().map(|i| convert::vector(normals[i])))
    }

    /// The topology part of the row: triangle indices, vertex colours (`colour` of each
    /// vertex's class) and class ids (legend and hover label), and the data components
    /// `triangle_level` and `duplicate_of`. The colours cannot be left to the class ids: the
    /// 0.36 viewer draws a `Mesh3D` without vertex colours in its default grey, annotation
    /// context or not.
    pub(super) fn topology(
        &self,
        colour: impl Fn(u16) -> [u8; 3],
    ) -> (rerun::Mesh3D, rerun::AnyValues) {
        let mesh = rerun::Mesh3D::update_fields()
            .with_triangle_indices(self.indices.iter().copied())
            // Needed: the 0.36 viewer does not colour a mesh from its class ids.
            .with_vertex_colors(self.vertex_classes.iter().map(|&c| {
                let [r, g, b] = colour(c);
                rerun::Rgba32::from_rgb(r, g, b)
            }))
            .with_class_ids(
                self.vertex_classes
                    .iter()
                    .map(|&c| rerun::components::ClassId::from(c)),
            );
        let data = rerun::AnyValues::default()
            .with_component_from_data(
                LEVEL_COMPONENT,
                Arc::new(UInt8Array::from(self.levels.clone())),
            )
            .with_component_from_data(
                DUPLICATE_COMPONENT,
                Arc::new(UInt32Array::from(self.duplicate_of.clone())),
            );
        (mesh, data)
    }
}

/// The simulated mesh's triangles rebuilt from a decoded `cloth/mesh` topology: recorded
/// triangle `indices` mapped back through `duplicate_of` onto the first `vertices` (the
/// simulated vertices). `None` when an index points past the recorded vertices.
pub fn simulated_triangles(
    vertices: usize,
    indices: &[[u32; 3]],
    duplicate_of: &[u32],
) -> Option<Vec<[u32; 3]>> {
    let source = |i: u32| -> Option<u32> {
        let i = i as usize;
        if i < vertices {
            u32::try_from(i).ok()
        } else {
            duplicate_of.get(i - vertices).copied()
        }
    };
    indices
        .iter()
        .map(|t| Some([source(t[0])?, source(t[1])?, source(t[2])?]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copies_only_where_levels_meet_and_rebuild_only_on_change() {
        // Two triangles sharing the edge 0-2, at levels 0 and 1: vertex 2 and 0 are shared.
        let tris = [[0, 1, 2], [0, 2, 3]];
        let mut m = ClothMesh::default();
        assert!(m.update(4, &tris, &[0, 1], &[0, 1]));
        // 0 and 2 have one triangle at each level: the tie goes to level 1, so triangle 0
        // needs copies of both.
        assert_eq!(m.duplicate_of, vec![0, 2]);
        assert_eq!(m.indices, vec![[4, 1, 5], [0, 2, 3]]);
        assert_eq!(m.vertex_classes, vec![1, 0, 1, 1, 0, 0]);
        assert_eq!(
            simulated_triangles(4, &m.indices, &m.duplicate_of),
            Some(tris.to_vec())
        );
        assert!(!m.update(4, &tris, &[0, 1], &[0, 1]), "same topology");
        assert!(m.update(4, &tris, &[1, 1], &[1, 1]), "levels changed");
        assert!(m.duplicate_of.is_empty());
        assert_eq!(m.vertex_classes.len(), 4);
        assert!(m.update(4, &tris, &[1, 1], &[0, 0]), "classes changed");
        assert!(m.update(5, &tris, &[1, 1], &[1, 1]), "vertex count changed");
        // Vertex 0 has two triangles at level 0 and one at level 1: it keeps level 0.
        let fan = [[0, 1, 2], [0, 2, 3], [0, 3, 4]];
        assert!(m.update(5, &fan, &[0, 0, 1], &[0, 0, 1]));
        assert_eq!(m.vertex_classes[..5], [0, 0, 0, 1, 1]);
        assert_eq!(m.duplicate_of, vec![3, 0]);
        assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 5], [6, 3, 4]]);
        assert_eq!(
            simulated_triangles(5, &m.indices, &m.duplicate_of),
            Some(fan.to_vec())
        );
        assert_eq!(simulated_triangles(4, &[[0, 1, 9]], &[]), None);
    }
}
