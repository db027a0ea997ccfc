//! A mesh sequence: OBJ files of one topology, one per frame at a stated
//! frame rate (as exported from Blender), interpolated linearly between
//! frames.
//!
//! With frames `p_0 .. p_(n-1)` at `frame_rate` f, the time `t` falls at
//! frame position `s = t f`, between frames `k = floor(s)` and `k + 1`, at
//! `u = s - k`: each vertex is at `p_k + u (p_(k+1) - p_k)` and moves at
//! `(p_(k+1) - p_k) f` (constant within a frame interval). Before the first
//! frame the mesh holds it; after the last it holds the last (`hold`), or the
//! sequence repeats with period `n / f`, the last frame followed by the first
//! (`loop`, for a cyclic animation exported without a repeated first frame).

use std::path::Path;

use super::CollideError;
use crate::math::{Scalar, Vector};
use crate::spec::KeyframeAfter;

/// The frames of a mesh sequence, placed in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct Sequence {
    frames: Vec<Vec<Vector>>,
    frame_rate: Scalar,
    after: KeyframeAfter,
}

impl Sequence {
    /// Frames of equal vertex count (at least one), `frame_rate` > 0.
    pub fn new(frames: Vec<Vec<Vector>>, frame_rate: Scalar, after: KeyframeAfter) -> Sequence {
        Sequence {
            frames,
            frame_rate,
            after,
        }
    }

    /// The vertex positions and velocities at time `t` (module docs).
    pub fn sample(&self, t: Scalar, x: &mut Vec<Vector>, v: &mut Vec<Vector>) {
        let n = self.frames.len();
        let s = t * self.frame_rate;
        let (k, next, u) = match self.after {
            _ if n == 1 => (0, 0, 0.0),
            KeyframeAfter::Loop => {
                let s = s.rem_euclid(n as Scalar);
                let k = (s.floor() as usize).min(n - 1);
                (k, (k + 1) % n, s - k as Scalar)
            }
            KeyframeAfter::Hold if s <= 0.0 => (0, 0, 0.0),
            KeyframeAfter::Hold if s >= (n - 1) as Scalar => (n - 1, n - 1, 0.0),
            KeyframeAfter::Hold => {
                let k = (s.floor() as usize).min(n - 2);
                (k, k + 1, s - k as Scalar)
            }
        };
        let (a, b) = (&self.frames[k], &self.frames[next]);
        x.clear();
        v.clear();
        x.extend(a.iter().zip(b).map(|(&p, &q)| p + (q - p) * u));
        v.extend(a.iter().zip(b).map(|(&p, &q)| (q - p) * self.frame_rate));
    }

    /// For `drape check`.
    pub fn describe(&self) -> String {
        format!(
            "{} OBJ frames at {} frames/s, then {}",
            self.frames.len(),
            self.frame_rate,
            match self.after {
                KeyframeAfter::Hold => "hold",
                KeyframeAfter::Loop => "loop",
            }
        )
    }
}

/// One OBJ frame: vertex positions (scaled) and triangles.
type Frame = (Vec<Vector>, Vec<[u32; 3]>);

/// Loads the frames of obstacle `index` from `files` (in order, at least
/// one), each scaled by `scale` and placed by `place`, and checks that they
/// share one topology: the same vertex count and the same triangles (the
/// same vertex indices in the same order). Returns the triangles and the
/// frames' vertex positions.
pub fn load_frames(
    index: usize,
    files: &[String],
    scale: Scalar,
    place: &dyn Fn(Vector) -> Vector,
) -> Result<(Vec<[u32; 3]>, Vec<Vec<Vector>>), CollideError> {
    let err = |path: &str, reason: String| CollideError::Obj {
        index,
        path: path.to_string(),
        reason,
    };
    let Some(first_path) = files.first() else {
        return Err(CollideError::Missing {
            index,
            key: "files",
        });
    };
    let (first, triangles) = read_frame(index, first_path, scale)?;
    let mut frames = vec![first];
    for path in &files[1..] {
        let (x, tris) = read_frame(index, path, scale)?;
        let one_based = |t: [u32; 3]| t.map(|i| i + 1);
        let changed = if x.len() != frames[0].len() {
            Some(format!("it has {} vertices", x.len()))
        } else if tris.len() != triangles.len() {
            Some(format!("it has {} triangles", tris.len()))
        } else {
            tris.iter()
                .zip(&triangles)
                .position(|(a, b)| a != b)
                .map(|f| {
                    format!(
                        "its triangle {} has the vertices {:?}, in the first frame {:?}",
                        f + 1,
                        one_based(tris[f]),
                        one_based(triangles[f])
                    )
                })
        };
        if let Some(what) = changed {
            let (nv, nt) = (frames[0].len(), triangles.len());
            return Err(err(
                path,
                format!(
                    "the topology changed: {what}; the first frame `{first_path}` has {nv} vertices and {nt} triangles, and every frame of a mesh sequence must have the same vertices and triangles"
                ),
            ));
        }
        frames.push(x);
    }
    for f in &mut frames {
        for p in f.iter_mut() {
            *p = place(*p);
        }
    }
    Ok((triangles, frames))
}

/// Reads one OBJ frame: every object of the file, triangulated, vertices
/// indexed as the file numbers them (texture coordinates and normals do not
/// split them), scaled by `scale`.
fn read_frame(index: usize, path: &str, scale: Scalar) -> Result<Frame, CollideError> {
    let err = |reason: String| CollideError::Obj {
        index,
        path: path.to_string(),
        reason,
    };
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj(Path::new(path), &opts)
        .map_err(|e| err(format!("{e} (not a readable Wavefront OBJ file)")))?;
    let mut x = Vec::new();
    let mut tris = Vec::new();
    for m in &models {
        let base = x.len() as u32;
        let count = (m.mesh.positions.len() / 3) as u32;
        for (n, c) in m.mesh.positions.chunks_exact(3).enumerate() {
            let v = Vector::new(c[0], c[1], c[2]) * scale;
            if !v.is_finite() {
                return Err(err(format!(
                    "vertex {} has a coordinate that is not a finite number: {c:?}",
                    base as usize + n + 1
                )));
            }
            x.push(v);
        }
        for f in m.mesh.indices.chunks_exact(3) {
            if f.iter().any(|&i| i >= count) {
                return Err(err("a face references a vertex that does not exist".into()));
            }
            tris.push([base + f[0], base + f[1], base + f[2]]);
        }
    }
    if tris.is_empty() {
        return Err(err("the file has no triangles".into()));
    }
    Ok((x, tris))
}
