//! The per-frame recording block of a run: gathers the world's state, the pending remeshing
//! events and seam welds, a garment's panels and seams, and the plots into a [`FrameView`]
//! for the recorder.

use std::collections::HashSet;

use crate::adapt::{AdaptEvent, Adapter, EventKind, edge_angles};
use crate::collide::Drawn;
use crate::math::{Scalar, Vector};
use crate::mesh::Mesh;
use crate::physics::Energy;
use crate::record::{
    DecisionData, DecisionView, EventMark, FrameView, GarmentView, Recorder, SeamSegment, WeldMark,
};
use crate::sim::{Pipeline, Setup, SimState, WeldEvent};
use crate::world::World;

use super::RunError;

/// Wall time of the latest frame's stepping and of the latest recorded frame's recording, s.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct FrameTiming {
    /// Stepping the frame (forces, integration, collisions, remeshing).
    pub sim_s: Scalar,
    /// Recording the previous recorded frame (and its OBJ export): a frame cannot time its own
    /// recording before logging it.
    pub record_s: Scalar,
}

/// What the run loop knows about the frame being recorded.
#[derive(Debug, Clone, Copy)]
pub(super) struct Snapshot {
    /// Frame index.
    pub frame: u64,
    /// The cloth's energies at the frame.
    pub energy: Energy,
    /// Wall times to plot.
    pub timing: FrameTiming,
    /// Simulated seconds between frames.
    pub frame_interval: Scalar,
    /// Whether to record the refinement decisions.
    pub decisions: DecisionData,
}

/// Records the world's current state as frame `snap.frame`, with the events and welds since
/// the previous recorded frame (taken from the state), a garment's seams, the plots, and the
/// obstacles ([`record_obstacles`]).
pub(super) fn record_state(
    rec: &mut Recorder,
    setup: &Setup,
    state: &mut SimState,
    pipe: &mut Pipeline,
    snap: &Snapshot,
    normals: &mut Vec<crate::math::Vector>,
) -> Result<(), RunError> {
    let events = state
        .adapter
        .as_mut()
        .map(Adapter::take_events)
        .unwrap_or_default();
    let welds = std::mem::take(&mut state.welds);
    let world = &state.world;
    let mut marks: Vec<EventMark> = events.iter().map(event_mark).collect();
    marks.extend(welds.iter().map(weld_mark));
    let seams = seam_segments(&world.mesh);
    let garment = world.mesh.panels().map(|p| GarmentView {
        panel_names: &p.names,
        triangle_panels: &p.of_triangle,
        seams: &seams,
    });
    let angles = edge_angles(world);
    let edges: Vec<[u32; 2]> = world.mesh.edges.iter().map(|e| e.vertices).collect();
    world.vertex_normals(normals);
    let pinned: Vec<u32> = world.pins.anchors.iter().map(|a| a.vertex).collect();
    let dt_now = pipe.step_taken(setup, world, snap.frame_interval);
    let mut scalars = frame_plots(world, snap, dt_now, &angles);
    if state.adapter.is_some() {
        scalars.extend(adapt_plots(&events));
    }
    if pipe.collider().is_some() {
        let c = &state.ledger.collision;
        scalars.push(("collision/contacts", c.last_contacts as f64));
        scalars.push(("penetration/max_mm", c.last_penetration * 1e3));
    }
    let decided = decisions(setup, state, snap.decisions);
    let world = &state.world;
    rec.record_frame(&FrameView {
        frame: snap.frame,
        sim_time: world.time,
        positions: &world.x,
        vertex_normals: normals,
        triangles: &world.mesh.triangles,
        triangle_levels: &world.mesh.levels,
        edges: &edges,
        edge_angles: &angles,
        pinned: &pinned,
        scalars: &scalars,
        events: &marks,
        garment,
        decisions: decided.as_ref().map(|d| DecisionView {
            ratio: &d.0,
            term: &d.1,
            state: &d.2,
        }),
    })?;
    record_obstacles(rec, setup, world, snap.frame)
}

/// The plots of every frame: mesh size, energies, the step, the wall times
/// and the largest dihedral angle of `angles`.
fn frame_plots(
    world: &World,
    snap: &Snapshot,
    dt_now: Scalar,
    angles: &[Scalar],
) -> Vec<(&'static str, f64)> {
    let e = snap.energy;
    vec![
        ("mesh/vertices", world.x.len() as f64),
        ("mesh/triangles", world.mesh.triangles.len() as f64),
        ("energy/kinetic", e.kinetic),
        ("energy/gravitational", e.gravitational),
        ("energy/elastic", e.elastic),
        ("energy/total", e.total()),
        ("time/dt_ms", 1e3 * dt_now),
        ("timing/sim_ms", 1e3 * snap.timing.sim_s),
        ("timing/record_ms", 1e3 * snap.timing.record_s),
        (
            "angle/max_deg",
            angles.iter().copied().fold(0.0, Scalar::max),
        ),
    ]
}

/// The remeshing plots of an adaptive run: `events` counted by kind.
fn adapt_plots(events: &[AdaptEvent]) -> [(&'static str, f64); 4] {
    let count = |k: EventKind| events.iter().filter(|e| e.kind == k).count() as f64;
    [
        (
            "adapt/splits",
            count(EventKind::Split) + count(EventKind::ClosureSplit) + count(EventKind::Bounce),
        ),
        (
            "adapt/merges",
            count(EventKind::Merge) + count(EventKind::Collapse),
        ),
        ("adapt/flips", count(EventKind::Flip)),
        ("adapt/rollbacks", count(EventKind::Rollback)),
    ]
}

/// Each triangle's refinement decision (ratio, term code, state code), when the run adapts
/// and `data` asks for them: read on the state as it is, as the next pass would (with the
/// obstacles' nearest planes when the sizing criterion has an obstacle term).
fn decisions(
    setup: &Setup,
    state: &SimState,
    data: DecisionData,
) -> Option<(Vec<f32>, Vec<u8>, Vec<u8>)> {
    let (Some(ad), Some(config), DecisionData::Recorded) =
        (&state.adapter, &setup.settings.adapt, data)
    else {
        return None;
    };
    let world = &state.world;
    let mut planes = Vec::new();
    if config.refine_obstacle.is_some() {
        setup
            .obstacles
            .nearest_planes(&world.x, world.time, &mut planes);
    }
    let all = ad.decisions(config, world, &planes);
    Some((
        all.iter().map(|d| d.reading.ratio as f32).collect(),
        all.iter().map(|d| d.reading.term.code()).collect(),
        all.iter().map(|d| d.state.code()).collect(),
    ))
}

/// Records the obstacles at `frame`: their meshes with frame 0, and every recorded frame the
/// poses of moving ones and the mesh of a moving plane or the vertices of a deforming mesh.
fn record_obstacles(
    rec: &mut Recorder,
    setup: &Setup,
    world: &World,
    frame: u64,
) -> Result<(), RunError> {
    if setup.obstacles.is_empty() {
        return Ok(());
    }
    // Every mesh but a moving plane's is logged once, at the first frame;
    // moving rigid shapes are placed by a transform every frame, deforming
    // meshes get their vertex positions every frame.
    let first = frame == 0;
    for m in setup
        .obstacles
        .meshes(world.time, plane_display(world), first)
    {
        if m.drawn == Drawn::Deforming {
            rec.record_deforming_obstacle(&m.name, &m.positions, &m.triangles)?;
            continue;
        }
        let fixed = m.drawn != Drawn::Redrawn;
        rec.record_obstacle(&m.name, &m.positions, &m.triangles, fixed)?;
    }
    for p in setup.obstacles.poses(world.time) {
        rec.record_obstacle_pose(&p.name, p.translation, p.rotation)?;
    }
    Ok(())
}

/// Where a plane obstacle is drawn: around the cloth's centre, out to 0.6 of
/// its material diagonal (a square cloth's side is 0.71 of it), so that the
/// cloth and the floor under it fill the 3D views.
fn plane_display(world: &World) -> (Vector, Scalar) {
    let n = world.x.len().max(1) as Scalar;
    let centre = world.x.iter().copied().sum::<Vector>() / n;
    let (lo, hi) = world.mesh.material_bounds();
    (centre, 0.6 * lo.distance(hi))
}

/// The recording's plain view of an adaptivity event.
fn event_mark(e: &AdaptEvent) -> EventMark {
    let kind = match e.kind {
        EventKind::Split => "split",
        EventKind::ClosureSplit => "closure_split",
        EventKind::Bounce => "bounce",
        EventKind::Merge => "merge",
        EventKind::MergeRefused => "merge_refused",
        EventKind::Rollback => "rollback",
        EventKind::Flip => "flip",
        EventKind::Collapse => "collapse",
    };
    EventMark {
        kind,
        position: e.position,
        level: e.level,
        angle: e.angle,
        step: e.step,
        weld: None,
        reason: e.reason.to_string(),
        corners: e.corners,
    }
}

/// The recording's plain view of a seam weld: kind `weld`, with the seam and its gap.
fn weld_mark(w: &WeldEvent) -> EventMark {
    EventMark {
        kind: "weld",
        position: w.position,
        level: 0,
        angle: None,
        step: w.step,
        weld: Some(WeldMark {
            seam: w.seam.clone(),
            gap: w.gap,
        }),
        reason: String::new(),
        corners: None,
    }
}

/// A garment's seams as segments for `cloth/seams` (none for a cloth without panels): each
/// open seam's pairs, and each welded seam's edges, the interior edges between two of its
/// vertices whose two triangles lie in different panels or meet there with different
/// pattern coordinates (the edges the weld joined; a chord inside one panel between two
/// seam vertices is left out).
fn seam_segments(mesh: &Mesh) -> Vec<SeamSegment<'_>> {
    let Some(panels) = mesh.panels() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for seam in &panels.seams {
        let segment = |vertices: [u32; 2], welded: bool| SeamSegment {
            seam: &seam.name,
            vertices,
            welded,
        };
        if seam.is_open() {
            out.extend(seam.pairs.iter().map(|&p| segment(p, false)));
            continue;
        }
        let on_seam: HashSet<u32> = seam.pairs.iter().flatten().copied().collect();
        for e in mesh.edges.iter().filter(|e| e.is_interior()) {
            let [a, b] = e.vertices;
            if !(on_seam.contains(&a) && on_seam.contains(&b)) {
                continue;
            }
            let [t0, t1] = e.triangles.map(|t| t as usize);
            let across = mesh.panel_of(t0) != mesh.panel_of(t1)
                || [a, b]
                    .iter()
                    .any(|&v| mesh.corner_at(t0, v) != mesh.corner_at(t1, v));
            if across {
                out.push(segment(e.vertices, true));
            }
        }
    }
    out
}
