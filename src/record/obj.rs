//! Wavefront OBJ export of single frames, for tools that do not read `.rrd`.
//!
//! A plain cloth is written with one texture coordinate per vertex
//! ([`write_frame_obj`]); a garment with one per distinct corner coordinate,
//! its panels as groups and its open seams as `l` elements, each seam in a
//! group of its own ([`write_mesh_obj`]), so that drape reads the file back as the same panels
//! and seams.

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use super::RecordError;
use crate::math::{Vector, Vector2};
use crate::mesh::{Mesh, Panels};

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

    write_file(dir, frame, |out| {
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
        Ok(())
    })
}

/// Creates `DIR/frame_NNNNN.obj`, fills it with `write` and flushes it;
/// returns its path.
fn write_file(
    dir: &Path,
    frame: u64,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> Result<PathBuf, RecordError> {
    let path = dir.join(format!("frame_{frame:05}.obj"));
    let io_err = |source| RecordError::Obj {
        path: path.clone(),
        source,
    };
    let file = std::fs::File::create(&path).map_err(io_err)?;
    let mut out = std::io::BufWriter::new(file);
    write(&mut out).and_then(|()| out.flush()).map_err(io_err)?;
    Ok(path)
}

/// Writes `DIR/frame_NNNNN.obj` for one frame of `mesh` at `positions`: as
/// [`write_frame_obj`] for a plain cloth; for a garment, one `v` line per vertex,
/// one `vt` line per distinct (vertex, corner coordinate) (a vertex on a welded
/// seam has one per panel), a `g NAME` line wherever the panel changes, one
/// `f a/ta b/tb c/tc` line per triangle, and for each open seam a `# seam NAME`
/// comment and a `g NAME` line (the seam's name) and one `l a b` line per pair
/// (first side first).
///
/// [`crate::mesh::load_obj`] reads such a file back as the same panels (names,
/// triangles' panels, corner coordinates), home coordinates and open seams (their
/// pairs, each seam in its own group however its ends meet another's; their
/// names follow the new file's lines), as long as no two vertices share a
/// position that an open seam does not pair (equal positions are read as one
/// vertex, except the two vertices of a pair) and the vertices are numbered in
/// the order the triangles first use them (otherwise they come back renumbered
/// in that order). A welded seam comes back as its shared vertices.
///
/// Fails as [`write_frame_obj`] does, and with [`RecordError::InvalidFrame`] if
/// `positions` does not have one entry per vertex of `mesh`.
pub fn write_mesh_obj(
    dir: &Path,
    frame: u64,
    positions: &[Vector],
    mesh: &Mesh,
) -> Result<PathBuf, RecordError> {
    let Some(panels) = mesh.panels() else {
        return write_frame_obj(dir, frame, positions, &mesh.material, &mesh.triangles);
    };
    if positions.len() != mesh.vertex_count() {
        return Err(RecordError::InvalidFrame {
            frame,
            reason: format!(
                "{} positions for {} vertices",
                positions.len(),
                mesh.vertex_count()
            ),
        });
    }
    write_file(dir, frame, |out| {
        write_garment(out, frame, positions, mesh, panels)
    })
}

/// The garment's OBJ text (see [`write_mesh_obj`]).
fn write_garment(
    out: &mut impl std::io::Write,
    frame: u64,
    positions: &[Vector],
    mesh: &Mesh,
    panels: &Panels,
) -> std::io::Result<()> {
    writeln!(out, "# drape frame {frame}: {} panels", panels.names.len())?;
    for p in positions {
        writeln!(out, "v {} {} {}", p.x, p.y, p.z)?;
    }
    // One texture coordinate per distinct (vertex, corner), in first-use order.
    let mut index: HashMap<(u32, [u64; 2]), u64> = HashMap::new();
    let mut corner_vt = Vec::with_capacity(mesh.triangles.len());
    for (tri, corners) in mesh.triangles.iter().zip(&panels.corners) {
        let mut vt = [0u64; 3];
        for k in 0..3 {
            let c: Vector2 = corners[k];
            let key = (tri[k], [c.x.to_bits(), c.y.to_bits()]);
            let next = index.len() as u64 + 1;
            vt[k] = match index.entry(key) {
                Entry::Occupied(e) => *e.get(),
                Entry::Vacant(e) => {
                    writeln!(out, "vt {} {}", c.x, c.y)?;
                    *e.insert(next)
                }
            };
        }
        corner_vt.push(vt);
    }
    let mut panel = None;
    for ((tri, vt), &p) in mesh
        .triangles
        .iter()
        .zip(&corner_vt)
        .zip(&panels.of_triangle)
    {
        if panel != Some(p) {
            writeln!(out, "g {}", panels.names[p as usize])?;
            panel = Some(p);
        }
        let [a, b, c] = tri.map(|i| u64::from(i) + 1);
        let [ta, tb, tc] = *vt;
        writeln!(out, "f {a}/{ta} {b}/{tb} {c}/{tc}")?;
    }
    for seam in panels.seams.iter().filter(|s| s.is_open()) {
        writeln!(out, "# seam {}", seam.name)?;
        writeln!(out, "g {}", seam.name)?;
        for &[a, b] in &seam.pairs {
            writeln!(out, "l {} {}", u64::from(a) + 1, u64::from(b) + 1)?;
        }
    }
    Ok(())
}
