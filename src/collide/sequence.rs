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

/// A sequence's triangles and its frames' vertex positions.
type Frames = (Vec<[u32; 3]>, Vec<Vec<Vector>>);

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
) -> Result<Frames, CollideError> {
    let err = |path: &str, reason: String| CollideError::Obj {
        index,
        path: path.to_string(),
        reason,
    };
    let Some(first_path) = files.first() else {
        return Err(CollideError::Spec {
            index,
            why: crate::spec::ObstacleSpecError::Missing {
                shape: "mesh sequence",
                key: "files",
            },
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

/// Reads one OBJ frame: its `v` and `f` lines (every object of the file;
/// polygons cut into fans of triangles; texture and normal indices ignored),
/// scaled by `scale`. Vertices keep the file's numbering, so that a frame
/// whose faces use other vertices is told apart.
fn read_frame(index: usize, path: &str, scale: Scalar) -> Result<Frame, CollideError> {
    let err = |reason: String| CollideError::Obj {
        index,
        path: path.to_string(),
        reason,
    };
    let text = std::fs::read_to_string(Path::new(path))
        .map_err(|e| err(format!("cannot read the file: {e}")))?;
    let mut x = Vec::new();
    let mut tris = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let at = |what: String| err(format!("line {}: {what}", n + 1));
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<f64> = words
                    .take(3)
                    .map(str::parse)
                    .collect::<Result<_, _>>()
                    .map_err(|e| at(format!("a vertex coordinate is not a number ({e})")))?;
                let v = match c[..] {
                    [a, b, c] => Vector::new(a, b, c) * scale,
                    _ => return Err(at("a vertex needs three coordinates".into())),
                };
                if !v.is_finite() {
                    return Err(at(format!(
                        "the vertex {c:?} has a coordinate that is not a finite number (after scaling by {scale})"
                    )));
                }
                x.push(v);
            }
            Some("f") => {
                let count = x.len() as i64;
                let corners = words
                    .map(|w| {
                        let i: i64 = w
                            .split('/')
                            .next()
                            .unwrap_or("")
                            .parse()
                            .map_err(|_| at(format!("`{w}` is not a vertex reference")))?;
                        let k = if i < 0 { count + i } else { i - 1 };
                        if (0..count).contains(&k) {
                            Ok(k as u32)
                        } else {
                            Err(at(format!(
                                "the face refers to vertex {i}, and {count} are defined before it"
                            )))
                        }
                    })
                    .collect::<Result<Vec<u32>, _>>()?;
                if corners.len() < 3 {
                    return Err(at("a face needs at least three vertices".into()));
                }
                tris.extend(
                    (1..corners.len() - 1).map(|j| [corners[0], corners[j], corners[j + 1]]),
                );
            }
            _ => {}
        }
    }
    if tris.is_empty() {
        return Err(err("the file has no triangles".into()));
    }
    Ok((x, tris))
}
