//! The body file a pattern drapes on, checked before the scene is built: it
//! exists, has triangles, and its size in metres (with the given scale) is
//! that of a body.

use std::path::Path;

use crate::math::Scalar;

/// The smallest and largest extent a body may have, m: a scale that makes it
/// smaller or larger is a units mistake (centimetres read as metres, say).
pub const BODY_EXTENT_RANGE: (Scalar, Scalar) = (0.1, 10.0);

/// Why a body file is refused, naming the file.
#[derive(Debug, thiserror::Error)]
pub enum BodyError {
    /// The file cannot be read as OBJ.
    #[error("body {file}: cannot read it as an OBJ file: {why}")]
    Unreadable {
        /// The file.
        file: String,
        /// Why.
        why: String,
    },
    /// The file has no faces.
    #[error("body {file}: the file has no faces")]
    NoFaces {
        /// The file.
        file: String,
    },
    /// Its size is not that of a body.
    #[error(
        "body {file}: with scale {scale} its largest extent is {extent:.3} m, outside {} to {} m; \
         give --body-scale 0.01 for a file in centimetres, 1 for metres",
        BODY_EXTENT_RANGE.0,
        BODY_EXTENT_RANGE.1
    )]
    Size {
        /// The file.
        file: String,
        /// The scale given.
        scale: Scalar,
        /// The largest extent along an axis, m.
        extent: Scalar,
    },
}

/// A body file's size, m (the file's coordinates times its scale).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodySize {
    /// Its largest extent along an axis, m.
    pub extent: Scalar,
    /// Its smallest coordinate along each axis of the file, m.
    pub lowest: [Scalar; 3],
}

/// Checks the body file at `path` read with `scale`; returns its size.
pub fn check_body(path: &Path, scale: Scalar) -> Result<BodySize, BodyError> {
    let file = path.display().to_string();
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj(path, &options).map_err(|e| BodyError::Unreadable {
        file: file.clone(),
        why: e.to_string(),
    })?;
    let faces: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    if faces == 0 {
        return Err(BodyError::NoFaces { file });
    }
    let mut lo = [Scalar::INFINITY; 3];
    let mut hi = [Scalar::NEG_INFINITY; 3];
    for m in &models {
        for p in m.mesh.positions.chunks_exact(3) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, Scalar::max) * scale;
    if !(BODY_EXTENT_RANGE.0..=BODY_EXTENT_RANGE.1).contains(&extent) {
        return Err(BodyError::Size {
            file,
            scale,
            extent,
        });
    }
    Ok(BodySize {
        extent,
        lowest: lo.map(|c| c * scale),
    })
}
