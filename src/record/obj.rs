//! Wavefront OBJ export of single frames, for tools that do not read `.rrd`.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use super::RecordError;
use crate::math::{Vector, Vector2};

/// Writes `DIR/frame_NNNNN.obj` (frame number zero-padded to 5 digits) for one frame.
///
/// The file holds one `v x y z` line per vertex (world position, m), one `vt u v` line per
/// vertex (material coordinates, m) and one `f a/a b/b c/c` line per triangle, with 1-based
/// indices; position and texture-coordinate indices are equal because both are per vertex.
/// Numbers are written with Rust's shortest round-trip formatting, so they read back exactly.
///
/// Returns the path written. Fails with [`RecordError::Obj`] if the file cannot be written
/// (e.g. `dir` does not exist) and with [`RecordError::InvalidFrame`] if `material` does not
/// have one entry per position or a triangle refers to a missing vertex; nothing is written
/// in that case.
pub fn write_frame_obj(
    dir: &Path,
    frame: u64,
    positions: &[Vector],
    material: &[Vector2],
    triangles: &[[u32; 3]],
) -> Result<PathBuf, RecordError> {
    let invalid = |reason: String| RecordError::InvalidFrame { frame, reason };
    if material.len() != positions.len() {
        return Err(invalid(format!(
            "{} material coordinates for {} vertices",
            material.len(),
            positions.len()
        )));
    }
    if let Some((t, tri)) = triangles
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&i| i as usize >= positions.len()))
    {
        return Err(invalid(format!(
            "triangle {t} {tri:?} refers to a vertex past the {} vertices",
            positions.len()
        )));
    }

    let path = dir.join(format!("frame_{frame:05}.obj"));
    let io_err = |source| RecordError::Obj {
        path: path.clone(),
        source,
    };
    let file = std::fs::File::create(&path).map_err(io_err)?;
    let mut out = std::io::BufWriter::new(file);
    let write = |out: &mut std::io::BufWriter<std::fs::File>| -> std::io::Result<()> {
        writeln!(out, "# drape frame {frame}")?;
        for p in positions {
            writeln!(out, "v {} {} {}", p.x, p.y, p.z)?;
        }
        for m in material {
            writeln!(out, "vt {} {}", m.x, m.y)?;
        }
        for tri in triangles {
            let [a, b, c] = tri.map(|i| u64::from(i) + 1);
            writeln!(out, "f {a}/{a} {b}/{b} {c}/{c}")?;
        }
        out.flush()
    };
    write(&mut out).map_err(io_err)?;
    Ok(path)
}
