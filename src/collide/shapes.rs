//! The rigid shapes of obstacles: the primitives of parts, the OBJ mesh
//! loader and the shapes' names.

use std::path::Path;

use parry3d_f64::shape::{Ball, Capsule, Cuboid, Shape, TriMesh, TriMeshFlags};

use super::CollideError;
use crate::math::{Scalar, Vector};
use crate::spec::Primitive;

/// The parry shape of a sphere, box or capsule (capsules along local z).
pub(super) fn primitive(p: &Primitive) -> Box<dyn Shape> {
    match *p {
        Primitive::Sphere { radius } => Box::new(Ball::new(radius)),
        Primitive::Box { half_extents } => Box::new(Cuboid::new(Vector::from_array(half_extents))),
        Primitive::Capsule {
            radius,
            half_height,
        } => Box::new(Capsule::new_z(half_height, radius)),
    }
}

/// Loads an obstacle mesh from OBJ (every object of the file, triangulated), scaled.
pub(super) fn load_mesh(index: usize, path: &Path, scale: Scalar) -> Result<TriMesh, CollideError> {
    let err = |reason: String| CollideError::Obj {
        index,
        path: path.display().to_string(),
        reason,
    };
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj(path, &opts)
        .map_err(|e| err(format!("{e} (not a readable Wavefront OBJ file)")))?;
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    for m in &models {
        let base = vertices.len() as u32;
        let p = &m.mesh.positions;
        for c in p.chunks_exact(3) {
            let v = Vector::new(c[0], c[1], c[2]) * scale;
            if !v.is_finite() {
                return Err(err("a vertex coordinate is not a finite number".into()));
            }
            vertices.push(v);
        }
        let count = (p.len() / 3) as u32;
        for f in m.mesh.indices.chunks_exact(3) {
            if f.iter().any(|&i| i >= count) {
                return Err(err("a face references a vertex that does not exist".into()));
            }
            indices.push([base + f[0], base + f[1], base + f[2]]);
        }
    }
    if indices.is_empty() {
        return Err(err("the file has no triangles".into()));
    }
    TriMesh::with_flags(
        vertices,
        indices,
        TriMeshFlags::ORIENTED | TriMeshFlags::MERGE_DUPLICATE_VERTICES,
    )
    .map_err(|e| err(format!("{e:?}")))
}
