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
    /// Remeshing events and seam welds since the previous frame, shown at
    /// `events/points` and written one line each to `events/log`.
    pub events: &'a [EventMark],
    /// The garment's panels and seams (`None`: a cloth without panels, which has
    /// no `cloth/seams` and colours as one panel named `cloth`).
    pub garment: Option<GarmentView<'a>>,
    /// The refinement decision at every triangle (`None`: a cloth that does not adapt, or
    /// decisions not recorded).
    pub decisions: Option<DecisionView<'a>>,
}

/// The refinement decision at every triangle of a frame, as plain data for `cloth/mesh`.
#[derive(Debug, Clone, Copy)]
pub struct DecisionView<'a> {
    /// The criterion's value against its threshold (refines above 1), per triangle.
    pub ratio: &'a [f32],
    /// The term that gave the ratio, per triangle (a code of [`super::decisions::TERM_NAMES`]).
    pub term: &'a [u8],
    /// What holds the triangle, per triangle (a code of [`super::decisions::STATE_NAMES`]).
    pub state: &'a [u8],
}

/// A garment's panels and seams at one frame, as plain data for the recording.
#[derive(Debug, Clone, Copy)]
pub struct GarmentView<'a> {
    /// Panel names, in panel index order (the legend of `--colour-by panel`).
    pub panel_names: &'a [String],
    /// The panel index of each triangle (same length as [`FrameView::triangles`]).
    pub triangle_panels: &'a [u16],
    /// The seams as line segments at `cloth/seams`.
    pub seams: &'a [SeamSegment<'a>],
}

/// One segment of a seam: the two vertices of an open seam's pair, or an edge along a
/// welded seam.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SeamSegment<'a> {
    /// The seam's name.
    pub seam: &'a str,
    /// The segment's two vertices.
    pub vertices: [u32; 2],
    /// Whether the seam is welded (an edge of the welded surface) or open (a pair being
    /// sewn).
    pub welded: bool,
}

/// What a `weld` event adds to its mark.
#[derive(Debug, Clone, PartialEq)]
pub struct WeldMark {
    /// The welded seam's name.
    pub seam: String,
    /// The largest distance between a pair just before the weld, m.
    pub gap: f64,
}

/// One remeshing event or seam weld, as plain data for the recording.
#[derive(Debug, Clone, PartialEq)]
pub struct EventMark {
    /// What happened: `split`, `closure_split`, `bounce`, `merge`, `merge_refused`, `flip`,
    /// `collapse`, `rollback` or `weld`.
    pub kind: &'static str,
    /// Where, in world coordinates (m).
    pub position: Vector,
    /// Level of the triangles it made.
    pub level: u8,
    /// The angle that triggered it, degrees, if any.
    pub angle: Option<f64>,
    /// The step after which it happened.
    pub step: u64,
    /// For a `weld`: the seam and its gap (`None` for remeshing events).
    pub weld: Option<WeldMark>,
    /// Why it happened, in words (empty for a weld).
    pub reason: String,
    /// The corners of the triangle it split, merged into or refused, in world coordinates
    /// (m), where the event is one triangle's.
    pub corners: Option<[Vector; 3]>,
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
    if let Some(g) = &frame.garment {
        validate_garment(g, n, frame.triangles.len()).map_err(invalid)?;
    }
    if let Some(d) = &frame.decisions {
        validate_decisions(d, frame.triangles.len()).map_err(invalid)?;
    }
    Ok(index)
}

/// Checks a garment's panels and seams against the frame's `n` vertices and
/// `triangles`; the reason when they do not fit.
fn validate_garment(g: &GarmentView, n: usize, triangles: usize) -> Result<(), String> {
    if g.triangle_panels.len() != triangles {
        return Err(format!(
            "{} triangle panels for {triangles} triangles",
            g.triangle_panels.len()
        ));
    }
    let panels = g.panel_names.len();
    if let Some(p) = g.triangle_panels.iter().find(|&&p| p as usize >= panels) {
        return Err(format!("panel {p} is past the {panels} panel names"));
    }
    if let Some(s) = g
        .seams
        .iter()
        .find(|s| s.vertices.iter().any(|&i| i as usize >= n))
    {
        return Err(format!(
            "seam {} segment {:?} refers to a vertex past the {n} vertices",
            s.seam, s.vertices
        ));
    }
    Ok(())
}

/// Checks the decisions against the frame's `triangles`: one of each per triangle, codes in
/// range; the reason when they do not fit.
fn validate_decisions(d: &DecisionView, triangles: usize) -> Result<(), String> {
    use super::decisions::{STATE_NAMES, TERM_NAMES};
    for (what, len) in [
        ("ratios", d.ratio.len()),
        ("terms", d.term.len()),
        ("states", d.state.len()),
    ] {
        if len != triangles {
            return Err(format!("{len} decision {what} for {triangles} triangles"));
        }
    }
    if let Some(t) = d.term.iter().find(|&&t| usize::from(t) >= TERM_NAMES.len()) {
        return Err(format!(
            "decision term {t} is past the {} terms",
            TERM_NAMES.len()
        ));
    }
    if let Some(s) = d
        .state
        .iter()
        .find(|&&s| usize::from(s) >= STATE_NAMES.len())
    {
        return Err(format!(
            "decision state {s} is past the {} states",
            STATE_NAMES.len()
        ));
    }
    Ok(())
}
