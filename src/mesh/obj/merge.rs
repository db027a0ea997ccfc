//! The objects tobj reads, merged over one vertex set; the planar rest shape of
//! a flat mesh without texture coordinates.

use std::collections::{HashMap, HashSet};

use super::text::ObjText;
use crate::math::{Scalar, Vector, Vector2};

/// The triangles of every object of an OBJ file over one vertex set.
pub(super) struct MergedObj {
    /// Vertex positions, one per distinct [`VertexKey`] the faces use, in the
    /// order the faces first use them.
    pub positions: Vec<Vector>,
    /// The vertex of each key.
    index_of: HashMap<VertexKey, u32>,
    /// The positions (keyed by their coordinates' bits) at which an `l`
    /// element pairs two different `v` lines: there each `v` line is a vertex
    /// of its own.
    split: HashSet<[u64; 3]>,
    /// Triangles as indices into `positions`, in file order.
    pub triangles: Vec<[u32; 3]>,
    /// Each triangle's corners' texture coordinates times `uv_scale` (zero for
    /// a triangle without them).
    pub uvs: Vec<[Vector2; 3]>,
    /// The object (tobj model) of each triangle.
    pub model_of: Vec<u32>,
    /// Triangles of objects with texture coordinates.
    pub with_uv: usize,
    /// Triangles of objects without them.
    pub without_uv: usize,
}

/// What makes two `v` lines one vertex.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum VertexKey {
    /// Every `v` line at this position (its coordinates' bits) is one vertex.
    Position([u64; 3]),
    /// This `v` line (0-based), at a split position, is a vertex of its own.
    Line(usize),
}

impl MergedObj {
    /// The key of `v` line `line` at `position`.
    fn key(&self, line: usize, position: Vector) -> VertexKey {
        let bits = position_key(position);
        if self.split.contains(&bits) {
            VertexKey::Line(line)
        } else {
            VertexKey::Position(bits)
        }
    }

    /// The vertex of `v` line `line` (0-based) of `text`, `None` when no face
    /// uses it (nor, where positions merge, another `v` line at its position).
    pub fn vertex_of_line(&self, text: &ObjText, line: usize) -> Option<u32> {
        let position = text.positions.get(line).copied().flatten()?;
        self.index_of.get(&self.key(line, position)).copied()
    }
}

/// The key under which positions merge: the coordinates' bits.
fn position_key(p: Vector) -> [u64; 3] {
    p.to_array().map(f64::to_bits)
}

/// The positions at which an `l` element pairs two different `v` lines.
fn split_positions(text: &ObjText) -> HashSet<[u64; 3]> {
    let mut split = HashSet::new();
    for element in &text.lines {
        for w in element.vertices.windows(2) {
            let (Some(Some(a)), Some(Some(b))) =
                (text.positions.get(w[0]), text.positions.get(w[1]))
            else {
                continue;
            };
            if w[0] != w[1] && position_key(*a) == position_key(*b) {
                split.insert(position_key(*a));
            }
        }
    }
    split
}

/// The `v` line (0-based) of corner `p` of a tobj mesh read from
/// [`ObjText::faces_text`], whose x is the line's index, and its position.
fn corner_line(text: &ObjText, mesh: &tobj::Mesh, p: usize) -> Option<(usize, Vector)> {
    let x = mesh.positions[3 * p];
    let line = (x >= 0.0 && x.fract() == 0.0).then_some(x as usize)?;
    Some((line, text.positions.get(line).copied().flatten()?))
}

/// Merges all objects into one vertex set: the `v` lines at one position are
/// one vertex, whichever objects use them, except at a position where an `l`
/// element pairs two different `v` lines (the two sides of a seam that lie on
/// each other), where each `v` line is a vertex of its own. `None` if a corner
/// does not name a `v` line of `text` (tobj's models were not read from
/// [`ObjText::faces_text`]).
pub(super) fn merge_models(
    models: &[tobj::Model],
    text: &ObjText,
    uv_scale: Scalar,
) -> Option<MergedObj> {
    let mut merged = MergedObj {
        positions: Vec::new(),
        index_of: HashMap::new(),
        split: split_positions(text),
        triangles: Vec::new(),
        uvs: Vec::new(),
        model_of: Vec::new(),
        with_uv: 0,
        without_uv: 0,
    };
    for (model_index, model) in models.iter().enumerate() {
        let m = &model.mesh;
        let has_uv = !m.texcoord_indices.is_empty();
        for (f, corners) in m.indices.chunks_exact(3).enumerate() {
            let mut tri = [0u32; 3];
            let mut uv = [Vector2::ZERO; 3];
            for (k, &p) in corners.iter().enumerate() {
                let (line, pos) = corner_line(text, m, p as usize)?;
                let next = merged.positions.len() as u32;
                let key = merged.key(line, pos);
                let positions = &mut merged.positions;
                tri[k] = *merged.index_of.entry(key).or_insert_with(|| {
                    positions.push(pos);
                    next
                });
                if has_uv {
                    let t = m.texcoord_indices[3 * f + k] as usize;
                    uv[k] = Vector2::new(m.texcoords[2 * t], m.texcoords[2 * t + 1]) * uv_scale;
                }
            }
            if has_uv {
                merged.with_uv += 1;
            } else {
                merged.without_uv += 1;
            }
            merged.triangles.push(tri);
            merged.uvs.push(uv);
            merged.model_of.push(model_index as u32);
        }
    }
    Some(merged)
}

/// Coordinates of the points in the plane of the mesh; `Err(distance)` if not flat.
pub(super) fn planar_rest_shape(
    positions: &[Vector],
    triangles: &[[u32; 3]],
) -> Result<Vec<Vector2>, Scalar> {
    if positions.is_empty() {
        return Ok(Vec::new());
    }
    let centroid = positions.iter().copied().sum::<Vector>() / positions.len() as Scalar;
    // Face normals, each turned to agree with the first (winding is unreliable).
    let face = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| positions[v as usize]);
        (b - a).cross(c - a)
    };
    let first = triangles.first().map(face).unwrap_or(Vector::ZERO);
    let normal = triangles
        .iter()
        .map(|t| {
            let n = face(t);
            if n.dot(first) < 0.0 { -n } else { n }
        })
        .sum::<Vector>()
        .normalize_or_zero();
    let size = positions
        .iter()
        .map(|p| p.distance(centroid))
        .fold(0.0, Scalar::max);
    let off_plane = positions
        .iter()
        .map(|p| (*p - centroid).dot(normal).abs())
        .fold(0.0, Scalar::max);
    if normal == Vector::ZERO || off_plane > 1e-6 * size.max(Scalar::MIN_POSITIVE) {
        return Err(off_plane);
    }
    let e1 = normal.any_orthonormal_vector();
    let e2 = normal.cross(e1);
    Ok(positions
        .iter()
        .map(|p| Vector2::new((*p - centroid).dot(e1), (*p - centroid).dot(e2)))
        .collect())
}
