//! Loading a cloth mesh from a Wavefront OBJ file.
//!
//! Texture coordinates (`vt`), when every face corner has one, become material
//! coordinates (times `uv_scale`). Without them the mesh must be flat, and its own
//! planar shape is the rest shape. Faces of all objects share one vertex set:
//! equal positions are one vertex, whichever `v` lines give them, except where
//! an `l` element pairs two different `v` lines at one position (the two sides
//! of a seam lying on each other): there each `v` line is a vertex of its own.
//!
//! # Garments
//!
//! A file is a garment (its mesh has
//! [`Pattern::Panels`](crate::mesh::Pattern::Panels)) when it has several
//! pieces, a position used with several texture coordinates, or `l` elements;
//! any other file (one connected piece, one `vt` per position, no `l`) is a
//! plain cloth with one material point per vertex
//! ([`Pattern::PerVertex`](crate::mesh::Pattern::PerVertex)).
//!
//! - **Panels** are the texture islands: two triangles are in one panel when
//!   they share an edge whose two corners have the same vertex and the same
//!   texture coordinate in both. Without `vt` they are the connected pieces.
//!   Panels are numbered in the order of their first triangles in the file. A
//!   panel is named after the object or group (`o`, `g`) its triangles lie in
//!   when they all lie in objects of that one name and no other panel's do;
//!   otherwise it is `pieceN`, N its number (1 for the first).
//! - **Welded panels**: a position used with several texture coordinates is
//!   one vertex welded across the panels (a garment sewn in a modeller), with
//!   one coordinate per corner. Its home coordinate ([`Mesh::material`]) and
//!   home panel are those of the first triangle in the file that uses it.
//! - **Seams** come from `l` elements (Blender exports sewing edges as loose
//!   edges from one side of a seam to the other): each pairs its consecutive
//!   vertices, which must be boundary vertices of the mesh not joined by an
//!   edge. The pairs are grouped into open seams along the boundary, the pairs
//!   of one object or group (`o`, `g`) only, each seam named `lN` after the
//!   line of its first element ([`seams`] gives the rule); how they are sewn
//!   is the physics model's (`[cloth.sewing]`). Two vertices an `l` pairs may
//!   lie at one position (in `v` lines of their own).
//!
//! tobj reads the faces; the loader reads the text itself too ([`text`]),
//! for what tobj lets through and for the `l` elements, which it hides from
//! tobj (tobj reads an `l` of three or more vertices as a face).

mod merge;
mod pieces;
mod seams;
mod text;

use std::path::Path;

use super::{Mesh, MeshError, topology};
use crate::math::{Scalar, Vector, Vector2};
use merge::{MergedObj, merge_models, planar_rest_shape};
use pieces::{Pieces, find_pieces};
use seams::{SeamMesh, read_seams};
use text::{ObjText, scan_text};

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
    /// The file has more pieces than a garment can have panels.
    #[error(
        "{path}: the mesh falls into {count} pieces (texture islands); a cloth has at most 65536"
    )]
    TooManyPieces {
        /// The file.
        path: String,
        /// The number of pieces.
        count: usize,
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

/// Loads `path`; `uv_scale` is metres per texture-coordinate unit (see the
/// module docs for how a file becomes a plain cloth or a garment).
pub fn load_obj(path: &Path, uv_scale: Scalar) -> Result<ObjCloth, ObjError> {
    let name = path.display().to_string();
    let text = scan_text(path, &name)?;
    let models = read_models(&text, &name)?;
    let merged = merge_models(&models, &text, uv_scale).ok_or_else(|| ObjError::Read {
        path: name.clone(),
        reason: "a face corner names no `v` line".into(),
    })?;
    if merged.with_uv > 0 && merged.without_uv > 0 {
        return Err(ObjError::PartialTexcoords { path: name });
    }
    let planar = if merged.with_uv > 0 {
        None
    } else {
        let shape =
            planar_rest_shape(&merged.positions, &merged.triangles).map_err(|distance| {
                ObjError::NotPlanar {
                    path: name.clone(),
                    distance,
                }
            })?;
        Some(shape)
    };
    let corners: Vec<[Vector2; 3]> = match &planar {
        Some(shape) => merged
            .triangles
            .iter()
            .map(|t| t.map(|v| shape[v as usize]))
            .collect(),
        None => merged.uvs.clone(),
    };
    let pieces = find_pieces(&merged.triangles, &corners);
    if pieces.count <= 1 && !pieces.welded && text.lines.is_empty() {
        let material = match planar {
            Some(shape) => shape,
            None => vertex_coordinates(&merged, &corners),
        };
        let mesh = Mesh::new(material, merged.triangles)
            .map_err(|source| ObjError::Mesh { path: name, source })?;
        return Ok(ObjCloth {
            mesh,
            positions: merged.positions,
        });
    }
    garment(&text, &models, merged, corners, &pieces, name)
}

/// Runs tobj over the file's text (without its `l` lines, and without
/// materials, which the cloth does not use).
fn read_models(text: &ObjText, name: &str) -> Result<Vec<tobj::Model>, ObjError> {
    let options = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let mut reader = text.faces_text.as_bytes();
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| ObjError::Read {
        path: name.to_string(),
        reason: e.to_string(),
    })?;
    Ok(models)
}

/// One material point per vertex, for a file whose vertices each have one
/// coordinate: the coordinate of its corners.
fn vertex_coordinates(merged: &MergedObj, corners: &[[Vector2; 3]]) -> Vec<Vector2> {
    let mut material = vec![Vector2::ZERO; merged.positions.len()];
    for (tri, c) in merged.triangles.iter().zip(corners) {
        for k in 0..3 {
            material[tri[k] as usize] = c[k];
        }
    }
    material
}

/// Builds the garment: its panels from the pieces, its seams from the `l`
/// elements.
fn garment(
    text: &ObjText,
    models: &[tobj::Model],
    merged: MergedObj,
    corners: Vec<[Vector2; 3]>,
    pieces: &Pieces,
    name: String,
) -> Result<ObjCloth, ObjError> {
    if pieces.count > usize::from(u16::MAX) + 1 {
        return Err(ObjError::TooManyPieces {
            path: name,
            count: pieces.count,
        });
    }
    let mesh_error = |source| ObjError::Mesh {
        path: name.clone(),
        source,
    };
    let model_names: Vec<&str> = models.iter().map(|m| m.name.as_str()).collect();
    let (material, mut panels) = pieces::panels(
        merged.positions.len(),
        &merged.triangles,
        corners,
        pieces,
        &merged.model_of,
        &model_names,
    );
    if !text.lines.is_empty() {
        let edges =
            topology::build_edges(&merged.triangles, merged.positions.len()).map_err(mesh_error)?;
        let seam_mesh = SeamMesh {
            edges: &edges,
            of_vertex: &panels.of_vertex,
        };
        panels.seams = read_seams(text, &merged, &seam_mesh, &name)?;
    }
    let mesh = Mesh::from_panels(material, merged.triangles, panels).map_err(mesh_error)?;
    Ok(ObjCloth {
        mesh,
        positions: merged.positions,
    })
}
