//! The objects tobj reads, merged over one vertex set; the planar rest shape of
//! a flat mesh without texture coordinates.

use std::collections::HashMap;

use crate::math::{Scalar, Vector, Vector2};

/// The triangles of every object of an OBJ file over one vertex set.
pub(super) struct MergedObj {
    /// Vertex positions, one per distinct position in the file, in the order
    /// the faces first use them.
    pub positions: Vec<Vector>,
    /// The vertex of each position (keyed by its coordinates' bits).
    pub index_of: HashMap<[u64; 3], u32>,
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

/// The key under which [`MergedObj::index_of`] finds a position.
pub(super) fn position_key(p: Vector) -> [u64; 3] {
    p.to_array().map(f64::to_bits)
}

/// Merges all objects into one vertex set, keyed by exact position: equal
/// positions are one vertex, whichever objects or `v` lines they come from.
pub(super) fn merge_models(models: &[tobj::Model], uv_scale: Scalar) -> MergedObj {
    let mut merged = MergedObj {
        positions: Vec::new(),
        index_of: HashMap::new(),
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
                let p = p as usize;
                let pos = Vector::new(
                    m.positions[3 * p],
                    m.positions[3 * p + 1],
                    m.positions[3 * p + 2],
                );
                let next = merged.positions.len() as u32;
                let positions = &mut merged.positions;
                tri[k] = *merged.index_of.entry(position_key(pos)).or_insert_with(|| {
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
    merged
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
