//! Remeshing events and seam welds as rerun data: labelled points at `events/points`, one text
//! line per event at `events/log`.

use super::{EventMark, convert};

/// Colour of an event's point by kind, sRGB.
///
/// | kind | colour |
/// |---|---|
/// | `split` | orange `#FF8F00` |
/// | `closure_split` | yellow `#FFD54F` |
/// | `bounce` | purple `#AB47BC` |
/// | `merge`, `collapse` | blue `#42A5F5` |
/// | `merge_refused` | light blue `#90CAF9` |
/// | `flip` | grey `#BDBDBD` |
/// | `rollback` | red `#E53935` |
/// | `weld` | green `#00C853` (the welded seams' colour) |
pub fn event_rgb(kind: &str) -> [u8; 3] {
    match kind {
        "weld" => super::garment::SEAM_WELDED_RGB,
        "split" => [0xFF, 0x8F, 0x00],
        "closure_split" => [0xFF, 0xD5, 0x4F],
        "bounce" => [0xAB, 0x47, 0xBC],
        "merge" | "collapse" => [0x42, 0xA5, 0xF5],
        "merge_refused" => [0x90, 0xCA, 0xF9],
        "flip" => [0xBD, 0xBD, 0xBD],
        _ => [0xE5, 0x39, 0x35],
    }
}

/// Radius of the event points on screen when the mesh's edge length is unknown, UI points.
const EVENT_RADIUS_UI: f32 = 6.0;

/// Radius of an event point as a fraction of the edge length at its level: small enough that
/// a burst of splits leaves the triangles they made visible between the markers.
const EVENT_RADIUS_PER_EDGE: f32 = 0.12;

/// The mean edge length of a mesh (each triangle's three edges), m; `None` without triangles.
pub(super) fn mean_edge_length(
    positions: &[crate::math::Vector],
    triangles: &[[u32; 3]],
) -> Option<f32> {
    let sum: f64 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            a.distance(b) + b.distance(c) + c.distance(a)
        })
        .sum();
    let mean = sum / (3 * triangles.len()) as f64;
    (mean.is_finite() && mean > 0.0).then_some(mean as f32)
}

/// The frame's events but refused merges as labelled points (empty when there are none, so the
/// 3D view shows only the current frame's events), each sized to the edges at its level: `base_edge` is the
/// unrefined mesh's mean edge length, halved every two levels (a red 1-4 split, or two edge
/// bisections). Without it the points have a fixed size on screen.
pub(super) fn event_points(events: &[EventMark], base_edge: Option<f32>) -> rerun::Points3D {
    // Refused merges change nothing on the cloth: they are in the log only, so that the
    // points mark where the mesh changed.
    let events: Vec<&EventMark> = events
        .iter()
        .filter(|e| e.kind != "merge_refused")
        .collect();
    let points = rerun::Points3D::new(events.iter().map(|e| convert::position(e.position)))
        .with_colors(events.iter().map(|e| {
            let [r, g, b] = event_rgb(e.kind);
            rerun::Rgba32::from_rgb(r, g, b)
        }))
        .with_labels(events.iter().map(|e| point_label(e)));
    match base_edge {
        Some(h) => points.with_radii(events.iter().map(|e| {
            let edge = h * 0.5f32.powf(f32::from(e.level) / 2.0);
            rerun::Radius::new_scene_units(EVENT_RADIUS_PER_EDGE * edge)
        })),
        None => points.with_radii([rerun::Radius::new_ui_points(EVENT_RADIUS_UI)]),
    }
}

/// An event point's label: the kind, and for a weld the seam (`weld left`).
fn point_label(e: &EventMark) -> String {
    match &e.weld {
        Some(w) => format!("{} {}", e.kind, w.seam),
        None => e.kind.to_owned(),
    }
}

/// Component name of the corners of an event's triangle on its `events/log` row (nine `f32`,
/// three corners' x, y, z in metres; absent where the event is not one triangle's).
pub const EVENT_CORNERS_COMPONENT: &str = "event_corners";

/// One event's log row: the line `KIND after step S: level L[, angle A deg], at (x, y, z) m;
/// REASON`, or for a weld `weld after step S: seam NAME, gap G mm, at (x, y, z) m`, at level
/// `WARN` for rollbacks and `INFO` otherwise, and the corners of the event's triangle
/// ([`EVENT_CORNERS_COMPONENT`]) where it has one. `drape inspect` reads the kind back from the
/// first word.
pub(super) fn event_row(e: &EventMark) -> (rerun::TextLog, rerun::AnyValues) {
    let corners: Vec<f32> = e
        .corners
        .iter()
        .flat_map(|c| c.iter().flat_map(|&p| convert::f32x3(p)))
        .collect();
    let data = match e.corners {
        Some(_) => rerun::AnyValues::default().with_component_from_data(
            EVENT_CORNERS_COMPONENT,
            std::sync::Arc::new(rerun::external::arrow::array::Float32Array::from(corners)),
        ),
        None => rerun::AnyValues::default(),
    };
    (event_line(e), data)
}

/// One event's log line (see [`event_row`]).
fn event_line(e: &EventMark) -> rerun::TextLog {
    let what = match &e.weld {
        Some(w) => format!("seam {}, gap {:.2} mm", w.seam, 1e3 * w.gap),
        None => {
            let angle = e
                .angle
                .map(|a| format!(", angle {a:.2} deg"))
                .unwrap_or_default();
            format!("level {}{angle}", e.level)
        }
    };
    let reason = match e.reason.is_empty() {
        true => String::new(),
        false => format!("; {}", e.reason),
    };
    let line = format!(
        "{} after step {}: {what}, at ({:.3}, {:.3}, {:.3}) m{reason}",
        e.kind, e.step, e.position.x, e.position.y, e.position.z
    );
    let level = if e.kind == "rollback" { "WARN" } else { "INFO" };
    rerun::TextLog::new(line).with_level(level)
}
