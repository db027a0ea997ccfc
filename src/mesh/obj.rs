//! Loading a cloth mesh from a Wavefront OBJ file.
//!
//! Texture coordinates (`vt`), when every face corner has one, become material
//! coordinates (times `uv_scale`). Without them the mesh must be flat, and its own
//! planar shape is the rest shape.

use std::collections::HashMap;
use std::path::Path;

use super::{Mesh, MeshError};
use crate::math::{Scalar, Vector, Vector2};

/// Why an OBJ file could not become a cloth.
#[derive(Debug, thiserror::Error)]
pub enum ObjError {
    /// The file could not be read or parsed.
    #[error("{path}: cannot read OBJ: {reason}")]
    Read {
        /// The file.
        path: String,
        /// tobj's description.
        reason: String,
    },
    /// A line of the file holds a value that cannot be part of a mesh.
    #[error("{path}:{line}: {reason}")]
    BadLine {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// Only some face corners have texture coordinates.
    #[error("{path}: some faces have texture coordinates and some do not; give all or none")]
    PartialTexcoords {
        /// The file.
        path: String,
    },
    /// One position is used with two different texture coordinates (a UV seam).
    #[error(
        "{path}: vertex {vertex} has two different texture coordinates (a UV seam); drape needs one material point per vertex"
    )]
    Seam {
        /// The file.
        path: String,
        /// The vertex (0-based position index).
        vertex: usize,
    },
    /// No texture coordinates and the mesh is not flat.
    #[error(
        "{path}: the mesh has no texture coordinates and is not flat (a point lies {distance:.3e} m off its plane), so it has no rest shape; add `vt` coordinates"
    )]
    NotPlanar {
        /// The file.
        path: String,
        /// Largest distance of a vertex from the best plane.
        distance: Scalar,
    },
    /// The mesh itself is not acceptable.
    #[error("{path}: {source}")]
    Mesh {
        /// The file.
        path: String,
        /// What is wrong with the mesh.
        source: MeshError,
    },
}

/// A cloth loaded from OBJ: its mesh and its initial (cloth-local) positions.
#[derive(Debug, Clone)]
pub struct ObjCloth {
    /// The validated mesh in material space.
    pub mesh: Mesh,
    /// Vertex positions from the file, in the cloth's local frame (m).
    pub positions: Vec<Vector>,
}

/// Loads `path`; `uv_scale` is metres per texture-coordinate unit.
pub fn load_obj(path: &Path, uv_scale: Scalar) -> Result<ObjCloth, ObjError> {
    let name = path.display().to_string();
    let options = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    scan_text(path, &name)?;
    let (models, _) = tobj::load_obj(path, &options).map_err(|e| ObjError::Read {
        path: name.clone(),
        reason: e.to_string(),
    })?;
    let MergedObj {
        positions,
        uvs,
        triangles,
        with_uv,
        without_uv,
    } = merge_models(&models, uv_scale, &name)?;
    if with_uv > 0 && without_uv > 0 {
        return Err(ObjError::PartialTexcoords { path: name });
    }
    let material = if with_uv > 0 {
        uvs.into_iter()
            .map(|uv| uv.unwrap_or(Vector2::ZERO))
            .collect()
    } else {
        planar_rest_shape(&positions, &triangles).map_err(|distance| ObjError::NotPlanar {
            path: name.clone(),
            distance,
        })?
    };
    let mesh =
        Mesh::new(material, triangles).map_err(|source| ObjError::Mesh { path: name, source })?;
    Ok(ObjCloth { mesh, positions })
}

/// The triangles of every object of an OBJ file over one vertex set.
struct MergedObj {
    /// Vertex positions, one per distinct position in the file.
    positions: Vec<Vector>,
    /// Per vertex: its texture coordinate times `uv_scale`, when a triangle gave one.
    uvs: Vec<Option<Vector2>>,
    /// Triangles as indices into `positions`.
    triangles: Vec<[u32; 3]>,
    /// Triangles of objects with texture coordinates.
    with_uv: usize,
    /// Triangles of objects without them.
    without_uv: usize,
}

/// Merges all objects into one vertex set, keyed by exact position. A vertex given two
/// different texture coordinates (a UV seam) is an error.
fn merge_models(
    models: &[tobj::Model],
    uv_scale: Scalar,
    name: &str,
) -> Result<MergedObj, ObjError> {
    let mut index_of: HashMap<[u64; 3], u32> = HashMap::new();
    let mut positions: Vec<Vector> = Vec::new();
    let mut uvs: Vec<Option<Vector2>> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let (mut with_uv, mut without_uv) = (0usize, 0usize);
    for model in models {
        let m = &model.mesh;
        let has_uv = !m.texcoord_indices.is_empty();
        for (f, corners) in m.indices.chunks_exact(3).enumerate() {
            let mut tri = [0u32; 3];
            for (k, &p) in corners.iter().enumerate() {
                let p = p as usize;
                let pos = Vector::new(
                    m.positions[3 * p],
                    m.positions[3 * p + 1],
                    m.positions[3 * p + 2],
                );
                let key = pos.to_array().map(f64::to_bits);
                let next = positions.len() as u32;
                let v = *index_of.entry(key).or_insert_with(|| {
                    positions.push(pos);
                    uvs.push(None);
                    next
                });
                if has_uv {
                    let t = m.texcoord_indices[3 * f + k] as usize;
                    let uv = Vector2::new(m.texcoords[2 * t], m.texcoords[2 * t + 1]) * uv_scale;
                    match uvs[v as usize] {
                        Some(old) if old != uv => {
                            return Err(ObjError::Seam {
                                path: name.to_owned(),
                                vertex: v as usize,
                            });
                        }
                        _ => uvs[v as usize] = Some(uv),
                    }
                }
                tri[k] = v;
            }
            if has_uv {
                with_uv += 1
            } else {
                without_uv += 1
            }
            triangles.push(tri);
        }
    }
    Ok(MergedObj {
        positions,
        uvs,
        triangles,
        with_uv,
        without_uv,
    })
}

/// Checks what tobj lets through, from the file's text: coordinates that are NaN or
/// infinite, face indices of 0 (OBJ counts from 1; tobj accepts a texture index
/// 0, which OBJ does not define), and `vt` on some faces only (tobj fills a corner without `vt`
/// with another corner's coordinates, so that is recognised from the text).
fn scan_text(path: &Path, name: &str) -> Result<(), ObjError> {
    let read = |reason: String| ObjError::Read {
        path: name.to_string(),
        reason,
    };
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::InvalidData => {
            return Err(read("not a text file (it is not valid UTF-8)".into()));
        }
        Err(e) => return Err(read(e.to_string())),
    };
    let bad = |line: usize, reason: String| ObjError::BadLine {
        path: name.to_string(),
        line: line + 1,
        reason,
    };
    let (mut with, mut without) = (0usize, 0usize);
    for (n, line) in text.lines().enumerate() {
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some(kind @ ("v" | "vt")) => {
                let value = tokens
                    .filter_map(|t| t.parse::<f64>().ok())
                    .find(|x| !x.is_finite());
                if let Some(x) = value {
                    return Err(bad(
                        n,
                        format!("`{kind}` has a coordinate that is not a finite number: {x}"),
                    ));
                }
            }
            Some("f") => {
                for corner in tokens {
                    if corner.split('/').any(|i| i.parse::<i64>() == Ok(0)) {
                        return Err(bad(
                            n,
                            format!("face corner `{corner}` has index 0; OBJ indices start at 1"),
                        ));
                    }
                    match corner.split('/').nth(1) {
                        Some(vt) if !vt.is_empty() => with += 1,
                        _ => without += 1,
                    }
                }
            }
            _ => {}
        }
    }
    if with > 0 && without > 0 {
        return Err(ObjError::PartialTexcoords {
            path: name.to_string(),
        });
    }
    Ok(())
}

/// Coordinates of the points in the plane of the mesh; `Err(distance)` if not flat.
fn planar_rest_shape(positions: &[Vector], triangles: &[[u32; 3]]) -> Result<Vec<Vector2>, Scalar> {
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
