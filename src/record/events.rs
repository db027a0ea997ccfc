//! Remeshing events as rerun data: labelled points at `events/points`, one text line per event
//! at `events/log`.

use super::{EventMark, convert};

/// Colour of an event's point by kind, sRGB.
///
/// | kind | colour |
/// |---|---|
/// | `split` | orange `#FF8F00` |
/// | `closure_split` | yellow `#FFD54F` |
/// | `bounce` | purple `#AB47BC` |
/// | `merge`, `collapse` | blue `#42A5F5` |
/// | `flip` | grey `#BDBDBD` |
/// | `rollback` | red `#E53935` |
pub fn event_rgb(kind: &str) -> [u8; 3] {
    match kind {
        "split" => [0xFF, 0x8F, 0x00],
        "closure_split" => [0xFF, 0xD5, 0x4F],
        "bounce" => [0xAB, 0x47, 0xBC],
        "merge" | "collapse" => [0x42, 0xA5, 0xF5],
        "flip" => [0xBD, 0xBD, 0xBD],
        _ => [0xE5, 0x39, 0x35],
    }
}

/// Radius of the event points on screen, UI points.
const EVENT_RADIUS_UI: f32 = 6.0;

/// The frame's events as labelled points (empty when there are none, so the 3D view shows only
/// the current frame's events).
pub(super) fn event_points(events: &[EventMark]) -> rerun::Points3D {
    rerun::Points3D::new(events.iter().map(|e| convert::position(e.position)))
        .with_colors(events.iter().map(|e| {
            let [r, g, b] = event_rgb(e.kind);
            rerun::Rgba32::from_rgb(r, g, b)
        }))
        .with_labels(events.iter().map(|e| e.kind))
        .with_radii([rerun::Radius::new_ui_points(EVENT_RADIUS_UI)])
}

/// One event's log line: `KIND after step S: level L[, angle A deg], at (x, y, z) m`, at level
/// `WARN` for rollbacks and `INFO` otherwise. `drape inspect` reads the kind back from the
/// first word.
pub(super) fn event_line(e: &EventMark) -> rerun::TextLog {
    let angle = e
        .angle
        .map(|a| format!(", angle {a:.2} deg"))
        .unwrap_or_default();
    let line = format!(
        "{} after step {}: level {}{angle}, at ({:.3}, {:.3}, {:.3}) m",
        e.kind, e.step, e.level, e.position.x, e.position.y, e.position.z
    );
    let level = if e.kind == "rollback" { "WARN" } else { "INFO" };
    rerun::TextLog::new(line).with_level(level)
}
