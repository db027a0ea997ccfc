//! One recorded frame as plain data, and its validation.

use super::RecordError;
use crate::math::Vector;

/// One recorded frame, as plain slices (no engine types).
#[derive(Debug, Clone, Copy)]
pub struct FrameView<'a> {
    /// Frame index, on timeline `frame` (sequence).
    pub frame: u64,
    /// Simulated time in seconds, on timeline `sim_time` (duration). Must be finite.
    pub sim_time: f64,
    /// World positions, m.
    pub positions: &'a [Vector],
    /// Unit normal per vertex (same length as `positions`).
    pub vertex_normals: &'a [Vector],
    /// Triangles as vertex indices into `positions`.
    pub triangles: &'a [[u32; 3]],
    /// Refinement level per triangle (same length as `triangles`); 0 is the base mesh.
    pub triangle_levels: &'a [u8],
    /// Edges as vertex pairs (for `cloth/edges`); may be empty.
    pub edges: &'a [[u32; 2]],
    /// Dihedral angle per edge, degrees (same length as `edges`; 0 at boundary edges).
    pub edge_angles: &'a [f64],
    /// Indices of pinned vertices.
    pub pinned: &'a [u32],
    /// Plot path -> value, e.g. `("energy/kinetic", 0.1)`, logged at `plots/<path>`.
    pub scalars: &'a [(&'a str, f64)],
    /// Remeshing events since the previous frame, shown at `events/points` and
    /// written one line each to `events/log`.
    pub events: &'a [EventMark],
}

/// One remeshing event, as plain data for the recording.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EventMark {
    /// What happened: `split`, `closure_split`, `bounce`, `merge`, `flip`, `collapse` or `rollback`.
    pub kind: &'static str,
    /// Where, in world coordinates (m).
    pub position: Vector,
    /// Level of the triangles it made.
    pub level: u8,
    /// The angle that triggered it, degrees, if any.
    pub angle: Option<f64>,
    /// The step after which it happened.
    pub step: u64,
}

/// Checks the frame's slices against each other; returns the frame index for the timeline.
pub(super) fn validate(frame: &FrameView) -> Result<i64, RecordError> {
    let invalid = |reason: String| RecordError::InvalidFrame {
        frame: frame.frame,
        reason,
    };
    let n = frame.positions.len();
    let index = i64::try_from(frame.frame)
        .map_err(|_| invalid("frame index does not fit the `frame` timeline (i64)".into()))?;
    if !frame.sim_time.is_finite() {
        return Err(invalid(format!("sim_time is {}", frame.sim_time)));
    }
    if frame.vertex_normals.len() != n {
        return Err(invalid(format!(
            "{} vertex normals for {n} vertices",
            frame.vertex_normals.len()
        )));
    }
    if frame.triangle_levels.len() != frame.triangles.len() {
        return Err(invalid(format!(
            "{} triangle levels for {} triangles",
            frame.triangle_levels.len(),
            frame.triangles.len()
        )));
    }
    if let Some((t, tri)) = frame
        .triangles
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&i| i as usize >= n))
    {
        return Err(invalid(format!(
            "triangle {t} {tri:?} refers to a vertex past the {n} vertices"
        )));
    }
    if frame.edge_angles.len() != frame.edges.len() {
        return Err(invalid(format!(
            "{} edge angles for {} edges",
            frame.edge_angles.len(),
            frame.edges.len()
        )));
    }
    if let Some(e) = frame
        .edges
        .iter()
        .find(|e| e.iter().any(|&i| i as usize >= n))
    {
        return Err(invalid(format!(
            "edge {e:?} refers to a vertex past the {n} vertices"
        )));
    }
    if let Some(&i) = frame.pinned.iter().find(|&&i| i as usize >= n) {
        return Err(invalid(format!(
            "pinned vertex {i} is past the {n} vertices"
        )));
    }
    Ok(index)
}
