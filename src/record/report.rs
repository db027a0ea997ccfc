//! The text `drape inspect` prints: an overview of a recording, or one frame in detail.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::inspect::{InspectError, Inspection};

/// How many of the busiest frames the overview names.
const BUSIEST_FRAMES: usize = 5;

/// `min to max` of some values, or `-` when there are none.
fn range<T: PartialOrd + Copy + std::fmt::Display>(values: impl Iterator<Item = T>) -> String {
    let mut lo_hi: Option<(T, T)> = None;
    for v in values {
        lo_hi = Some(match lo_hi {
            None => (v, v),
            Some((lo, hi)) => (if v < lo { v } else { lo }, if v > hi { v } else { hi }),
        });
    }
    match lo_hi {
        Some((lo, hi)) => format!("{lo} to {hi}"),
        None => "-".to_owned(),
    }
}

/// `kind n, kind n, ...`, or `none`.
fn counts_line(counts: &BTreeMap<String, usize>) -> String {
    if counts.is_empty() {
        return "none".to_owned();
    }
    counts
        .iter()
        .map(|(k, n)| format!("{k} {n}"))
        .collect::<Vec<_>>()
        .join(", ")
}

impl Inspection {
    /// The overview: file, ids, frames and time span, mesh size range, a garment's seam
    /// segments, event counts by kind, the frames with the most events, and every entity path
    /// with its row counts.
    pub fn report(&self) -> String {
        let mut s = String::new();
        self.write_file_lines(&mut s);
        self.write_frame_lines(&mut s);
        self.write_seam_line(&mut s);
        self.write_event_lines(&mut s);
        let _ = writeln!(s, "entities (rows on the timelines, static rows):");
        let width = self.entities.keys().map(String::len).max().unwrap_or(0);
        for (path, rows) in &self.entities {
            let _ = writeln!(
                s,
                "  {path:<width$}  {:>7}  {:>3}",
                rows.temporal, rows.static_rows
            );
        }
        s
    }

    /// The overview's file line (size, messages, footer) and ids line.
    fn write_file_lines(&self, s: &mut String) {
        let footer = if self.footer {
            "complete (stream footer present)"
        } else {
            "NO stream footer (the recording was not closed)"
        };
        let _ = writeln!(
            s,
            "{}: {} bytes, {} messages decoded, {footer}",
            self.path.display(),
            self.bytes,
            self.messages
        );
        let ids = |set: &std::collections::BTreeSet<String>| {
            set.iter().cloned().collect::<Vec<_>>().join(", ")
        };
        let _ = writeln!(
            s,
            "application {}, recording id {}, blueprint messages {}",
            ids(&self.application_ids),
            ids(&self.recording_ids),
            self.blueprint_messages
        );
    }

    /// The overview's frame span, mesh size ranges, topology rows and edge angles.
    fn write_frame_lines(&self, s: &mut String) {
        let first = self.frames.keys().next();
        let last = self.frames.keys().next_back();
        let times: Vec<f64> = self.frames.values().filter_map(|f| f.sim_time).collect();
        match (first, last) {
            (Some(a), Some(b)) => {
                let _ = writeln!(
                    s,
                    "frames: {} recorded, {a} to {b}; sim_time {}",
                    self.frames.len(),
                    match (times.first(), times.last()) {
                        (Some(t0), Some(t1)) => format!("{t0:.4} s to {t1:.4} s"),
                        _ => "-".to_owned(),
                    }
                );
            }
            _ => {
                let _ = writeln!(s, "frames: none");
            }
        }
        let frames = self.frames.values();
        let _ = writeln!(
            s,
            "vertices: {}; triangles: {}; levels: {}",
            range(frames.clone().filter_map(|f| f.vertices())),
            range(frames.clone().filter_map(|f| f.triangles)),
            range(frames.clone().flat_map(|f| f.levels.iter().copied())),
        );
        let _ = writeln!(
            s,
            "mesh topology logged on {} of {} frames",
            frames.clone().filter(|f| f.topology).count(),
            self.frames.len()
        );
        if self.frames.values().any(|f| f.edges.is_some()) {
            let _ = writeln!(
                s,
                "edges per frame: {}; largest angle {} deg",
                range(frames.clone().filter_map(|f| f.edges)),
                frames
                    .clone()
                    .filter_map(|f| f.max_edge_angle)
                    .reduce(f64::max)
                    .map_or("-".to_owned(), |a| format!("{a:.2}")),
            );
        }
    }

    /// The overview's seam line (garments only): open segments and welded edges per frame.
    fn write_seam_line(&self, s: &mut String) {
        let rows: Vec<_> = self
            .frames
            .values()
            .filter_map(|f| f.seams.as_ref())
            .collect();
        if rows.is_empty() {
            return;
        }
        let _ = writeln!(
            s,
            "seams per frame: open segments {}; welded edges {}",
            range(rows.iter().map(|r| r.open)),
            range(rows.iter().map(|r| r.welded)),
        );
    }

    /// The overview's event counts by kind and the busiest frames.
    fn write_event_lines(&self, s: &mut String) {
        let counts = self.event_counts();
        let total: usize = counts.values().sum();
        let _ = writeln!(s, "events: {total} ({})", counts_line(&counts));
        let mut busy: Vec<(i64, usize)> = self
            .frames
            .iter()
            .filter(|(_, f)| !f.events.is_empty())
            .map(|(&n, f)| (n, f.events.len()))
            .collect();
        busy.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        if !busy.is_empty() {
            let top: Vec<String> = busy
                .iter()
                .take(BUSIEST_FRAMES)
                .map(|(n, c)| format!("{n} ({c})"))
                .collect();
            let _ = writeln!(s, "frames with the most events: {}", top.join(", "));
        }
    }

    /// One line per frame (`drape inspect --frames`): its time, the mesh's vertices
    /// and triangles, how many triangles are at the recording's finest level, the
    /// adaptive operations and contacts since the previous frame, and the frame's
    /// stepping time (`timing/sim_ms`), with the stepping time summed at the end;
    /// `-` where the recording has no value. Where an adaptive run spends its time
    /// (which frames, at what mesh size) reads off it without one `--frame` per
    /// frame.
    pub fn frames_table(&self) -> String {
        let finest = self
            .frames
            .values()
            .flat_map(|f| f.levels.iter().copied())
            .max();
        let cell = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v}"));
        let mut s = String::new();
        let finest_head = finest.map_or("finest -".to_owned(), |l| format!("at level {l}"));
        let _ = writeln!(
            s,
            "{:>6} {:>9} {:>9} {:>9} {:>11} {:>7} {:>7} {:>9} {:>8} {:>10}",
            "frame",
            "time s",
            "vertices",
            "triangles",
            finest_head,
            "splits",
            "merges",
            "rollbacks",
            "contacts",
            "sim ms"
        );
        let mut total_ms = 0.0;
        for (n, f) in &self.frames {
            let scalar = |name: &str| f.scalars.get(name).copied();
            let at_finest = finest.map(|l| f.levels.iter().filter(|&&x| x == l).count());
            let sim_ms = scalar("timing/sim_ms");
            total_ms += sim_ms.unwrap_or(0.0);
            let _ = writeln!(
                s,
                "{n:>6} {:>9} {:>9} {:>9} {:>11} {:>7} {:>7} {:>9} {:>8} {:>10}",
                f.sim_time.map_or("-".to_owned(), |t| format!("{t:.4}")),
                cell(f.vertices()),
                f.triangles.map_or("-".to_owned(), |t| t.to_string()),
                match (at_finest, f.levels.is_empty()) {
                    (Some(c), false) => c.to_string(),
                    _ => "-".to_owned(),
                },
                cell(scalar("adapt/splits")),
                cell(scalar("adapt/merges")),
                cell(scalar("adapt/rollbacks")),
                cell(scalar("collision/contacts")),
                sim_ms.map_or("-".to_owned(), |v| format!("{v:.1}")),
            );
        }
        let _ = writeln!(s, "stepping time over the frames: {total_ms:.1} ms");
        s
    }

    /// One frame in detail: its time, mesh statistics (triangles, vertices, triangles per
    /// level), edges, a garment's seams, every plot value, and its events.
    pub fn frame_report(&self, n: i64) -> Result<String, InspectError> {
        let f = self.frame(n)?;
        let mut s = String::new();
        let time = f.sim_time.map_or("-".to_owned(), |t| format!("{t:.4} s"));
        let _ = writeln!(s, "frame {n}, sim_time {time}");
        let tris = f.triangles.map_or("-".to_owned(), |t| t.to_string());
        let verts = f.vertices().map_or("-".to_owned(), |v| format!("{v}"));
        let logged = if f.topology {
            "logged at this frame"
        } else {
            "as last logged"
        };
        let _ = writeln!(
            s,
            "mesh: {tris} triangles, {verts} vertices (topology {logged})"
        );
        let mut per_level: BTreeMap<u8, usize> = BTreeMap::new();
        for &l in &f.levels {
            *per_level.entry(l).or_insert(0) += 1;
        }
        let levels: Vec<String> = per_level
            .iter()
            .map(|(l, c)| format!("level {l}: {c}"))
            .collect();
        let _ = writeln!(
            s,
            "triangles per level ({} values): {}",
            f.levels.len(),
            if levels.is_empty() {
                "-".to_owned()
            } else {
                levels.join(", ")
            }
        );
        if let Some(e) = f.edges {
            let _ = writeln!(
                s,
                "edges: {e} recorded, largest angle {}",
                f.max_edge_angle
                    .map_or("-".to_owned(), |a| format!("{a:.2} deg"))
            );
        }
        if let Some(r) = &f.seams {
            let _ = writeln!(
                s,
                "seams: {} open segments, {} welded edges",
                r.open, r.welded
            );
        }
        let _ = writeln!(s, "plots:");
        for (name, v) in &f.scalars {
            let _ = writeln!(s, "  {name} = {v}");
        }
        let _ = writeln!(s, "events: {}", f.events.len());
        for line in &f.events {
            let _ = writeln!(s, "  {line}");
        }
        Ok(s)
    }
}
