//! `drape inspect`: decode a `.rrd` with rerun's decoder and gather what a reviewer wants
//! first (frames, time span, entities, mesh sizes, events); `report.rs` formats it.
//!
//! The decoder reads every message of the file; a message that does not decode is an error
//! ([`InspectError::Decode`]), so a successful [`inspect`] also proves the file decodes
//! completely. Whether rerun wrote its stream footer (the last thing written when a recording
//! is closed) is reported separately ([`Inspection::footer`]).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use rerun::external::arrow::array::{
    Array, ArrayRef, AsArray, ListArray, StringArray,
    types::{Float32Type, Float64Type, UInt8Type, UInt16Type},
};
use rerun::external::re_log_encoding::DecoderApp;
use rerun::log::{Chunk, LogMsg};

use super::garment::{SEAM_CLASS_OPEN, SEAM_CLASS_WELDED, SEAM_COMPONENT};
use super::{
    ENTITY_EDGES, ENTITY_EVENT_LOG, ENTITY_MESH, ENTITY_PLOTS, ENTITY_SEAMS, LEVEL_COMPONENT,
};
use super::{TIMELINE_FRAME, TIMELINE_SIM_TIME, edges::ANGLE_COMPONENT};

/// Why a file could not be inspected.
#[derive(Debug, thiserror::Error)]
pub enum InspectError {
    /// The file could not be opened or read.
    #[error("cannot read {}: {source}", .path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a Rerun recording (no `.rrd` header).
    #[error("{} is not a Rerun .rrd recording: {reason}", .path.display())]
    NotRrd {
        /// The file.
        path: PathBuf,
        /// What the decoder said.
        reason: String,
    },
    /// A message inside the recording does not decode (a damaged or truncated file).
    #[error("{} does not decode completely: message {index}: {reason}", .path.display())]
    Decode {
        /// The file.
        path: PathBuf,
        /// Index of the failing message (0-based).
        index: usize,
        /// What the decoder said.
        reason: String,
    },
    /// `--frame N` names a frame the recording does not hold.
    #[error("frame {frame} is not in the recording (it holds frames {first} to {last})")]
    NoFrame {
        /// The requested frame.
        frame: i64,
        /// First recorded frame.
        first: i64,
        /// Last recorded frame.
        last: i64,
    },
}

/// Rows of one entity.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EntityRows {
    /// Rows on the timelines.
    pub temporal: usize,
    /// Static rows (logged once, for all times).
    pub static_rows: usize,
}

/// One frame's row of `cloth/seams`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SeamRow {
    /// Segments of open seams (one per pair being sewn).
    pub open: usize,
    /// Edges of welded seams.
    pub welded: usize,
    /// The seam name of each segment, in logging order.
    pub names: Vec<String>,
    /// The class id of each segment (0 open, 1 welded), in logging order.
    pub classes: Vec<u16>,
}

/// What the recording holds at one value of the `frame` timeline.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FrameInfo {
    /// The `sim_time` of the frame, s.
    pub sim_time: Option<f64>,
    /// Rows of `cloth/mesh` at this frame (1 in a drape recording).
    pub mesh_rows: usize,
    /// Triangles of the mesh (its `triangle_indices`, the latest at or before the frame).
    pub triangles: Option<usize>,
    /// The `triangle_level` values of the mesh (one per triangle; the latest at or before the
    /// frame).
    pub levels: Vec<u8>,
    /// Whether this frame logged the mesh's topology (it changed since the previous one).
    pub topology: bool,
    /// Segments at `cloth/edges`.
    pub edges: Option<usize>,
    /// Largest `dihedral_angle_deg` at `cloth/edges`, degrees.
    pub max_edge_angle: Option<f64>,
    /// Smallest `dihedral_angle_deg` at `cloth/edges`, degrees.
    pub min_edge_angle: Option<f64>,
    /// The segments of `cloth/seams` (a garment's frames only).
    pub seams: Option<SeamRow>,
    /// `plots/<name>` values (name without the `plots/` prefix).
    pub scalars: BTreeMap<String, f64>,
    /// The lines of `events/log`, in logging order.
    pub events: Vec<String>,
}

impl FrameInfo {
    /// Vertices of the simulated mesh, from the `mesh/vertices` plot.
    pub fn vertices(&self) -> Option<f64> {
        self.scalars.get("mesh/vertices").copied()
    }
}

/// Everything [`inspect`] gathered from one recording.
#[derive(Debug, Clone, Default)]
pub struct Inspection {
    /// The file.
    pub path: PathBuf,
    /// Its size, bytes.
    pub bytes: u64,
    /// Whether the file ends with rerun's stream footer (written when the recording is closed).
    pub footer: bool,
    /// Messages decoded (recording and blueprint).
    pub messages: usize,
    /// Messages of the blueprint store.
    pub blueprint_messages: usize,
    /// Application ids of the recording store.
    pub application_ids: BTreeSet<String>,
    /// Recording ids of the recording store.
    pub recording_ids: BTreeSet<String>,
    /// Rows per entity path (as rerun writes it, with a leading `/`).
    pub entities: BTreeMap<String, EntityRows>,
    /// Per value of the `frame` timeline.
    pub frames: BTreeMap<i64, FrameInfo>,
}

impl Inspection {
    /// Event counts by kind (the first word of each `events/log` line), over all frames.
    pub fn event_counts(&self) -> BTreeMap<String, usize> {
        let mut counts = BTreeMap::new();
        for line in self.frames.values().flat_map(|f| &f.events) {
            let kind = line.split_whitespace().next().unwrap_or("").to_owned();
            *counts.entry(kind).or_insert(0) += 1;
        }
        counts
    }

    /// The frame `n`, or [`InspectError::NoFrame`].
    pub fn frame(&self, n: i64) -> Result<&FrameInfo, InspectError> {
        self.frames.get(&n).ok_or_else(|| InspectError::NoFrame {
            frame: n,
            first: self.frames.keys().next().copied().unwrap_or(0),
            last: self.frames.keys().next_back().copied().unwrap_or(0),
        })
    }
}

/// One decoded message of a recording, as [`read_messages`] hands it over.
pub(super) enum Message {
    /// A message of the blueprint store.
    Blueprint,
    /// A message of the recording store, with its ids, and its chunk when it carries data.
    Recording {
        /// The store's application id.
        application_id: String,
        /// The store's recording id.
        recording_id: String,
        /// The data, for an arrow message (boxed: a chunk is large beside the other variant).
        chunk: Option<Box<Chunk>>,
    },
}

/// The raw bytes of a recording file and whether they end with rerun's stream footer.
pub(super) struct RecordingFile {
    /// The file.
    pub path: PathBuf,
    /// Its contents.
    pub bytes: Vec<u8>,
}

impl RecordingFile {
    /// Reads the file at `path` ([`InspectError::Read`] when it cannot be read).
    pub fn read(path: &Path) -> Result<RecordingFile, InspectError> {
        let bytes = std::fs::read(path).map_err(|source| InspectError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(RecordingFile {
            path: path.to_path_buf(),
            bytes,
        })
    }

    /// Whether the file ends with rerun's stream footer (written when a recording is closed).
    pub fn footer(&self) -> bool {
        let n = self.bytes.len();
        n >= 12 && &self.bytes[n - 12..n - 4] == b"RRF2FOOT"
    }

    /// Decodes every message in file order and hands each to `visit` with its index; the
    /// shared loop of [`inspect`] and [`super::decode::cloth_mesh_at`].
    ///
    /// Fails with [`InspectError::NotRrd`] when the file has no `.rrd` header, with
    /// [`InspectError::Decode`] at the first message (or chunk) that does not decode, and
    /// with whatever `visit` returns.
    pub fn read_messages(
        &self,
        mut visit: impl FnMut(usize, Message) -> Result<(), InspectError>,
    ) -> Result<(), InspectError> {
        let decoder =
            DecoderApp::decode_eager(self.bytes.as_slice()).map_err(|e| InspectError::NotRrd {
                path: self.path.clone(),
                reason: e.to_string(),
            })?;
        for (index, msg) in decoder.enumerate() {
            let decode_err = |reason: String| InspectError::Decode {
                path: self.path.clone(),
                index,
                reason,
            };
            let msg = msg.map_err(|e| decode_err(e.to_string()))?;
            let store = msg.store_id();
            if store.kind() != rerun::StoreKind::Recording {
                visit(index, Message::Blueprint)?;
                continue;
            }
            let chunk = match &msg {
                LogMsg::ArrowMsg(_, arrow) => Some(Box::new(
                    Chunk::from_arrow_msg(arrow).map_err(|e| decode_err(e.to_string()))?,
                )),
                _ => None,
            };
            visit(
                index,
                Message::Recording {
                    application_id: store.application_id().to_string(),
                    recording_id: store.recording_id().to_string(),
                    chunk,
                },
            )?;
        }
        Ok(())
    }
}

/// Decodes the recording at `path` completely and gathers its contents.
pub fn inspect(path: &Path) -> Result<Inspection, InspectError> {
    let file = RecordingFile::read(path)?;
    let mut out = Inspection {
        path: path.to_path_buf(),
        bytes: file.bytes.len() as u64,
        footer: file.footer(),
        ..Inspection::default()
    };
    file.read_messages(|_, msg| {
        out.messages += 1;
        match msg {
            Message::Blueprint => out.blueprint_messages += 1,
            Message::Recording {
                application_id,
                recording_id,
                chunk,
            } => {
                out.application_ids.insert(application_id);
                out.recording_ids.insert(recording_id);
                if let Some(chunk) = chunk {
                    gather(&mut out, &chunk);
                }
            }
        }
        Ok(())
    })?;
    carry_topology(&mut out);
    Ok(out)
}

/// Adds one chunk's rows to the inspection.
fn gather(out: &mut Inspection, chunk: &Chunk) {
    let entity = chunk.entity_path().to_string();
    let rows = out.entities.entry(entity.clone()).or_default();
    if chunk.is_static() {
        rows.static_rows += chunk.num_rows();
        return;
    }
    rows.temporal += chunk.num_rows();
    let timeline = |name: &str| super::decode::timeline_times(chunk, name);
    let Some(frames) = timeline(TIMELINE_FRAME) else {
        return;
    };
    let sim_times = timeline(TIMELINE_SIM_TIME);
    let entity = entity.trim_start_matches('/');
    let columns: Vec<(String, &ListArray)> = chunk
        .component_descriptors()
        .filter_map(|d| {
            let array = chunk.components().get_array(d.component)?;
            Some((d.component.as_str().to_owned(), array))
        })
        .collect();
    let column = |suffix: &str| {
        columns
            .iter()
            .find(|(name, _)| name == suffix || name.ends_with(&format!(":{suffix}")))
            .map(|(_, a)| *a)
    };
    for (row, &frame) in frames.iter().enumerate() {
        let info = out.frames.entry(frame).or_default();
        if let Some(t) = sim_times.as_ref().and_then(|t| t.get(row)) {
            info.sim_time = Some(*t as f64 * 1e-9);
        }
        let cell = |suffix: &str| {
            column(suffix)
                .filter(|a| a.is_valid(row))
                .map(|a| a.value(row))
        };
        gather_row(info, entity, cell);
    }
}

/// Adds one row of `entity` to its frame's `info`; `cell` gives the row's value of a
/// component, named by its name or its descriptor's suffix.
fn gather_row(info: &mut FrameInfo, entity: &str, cell: impl Fn(&str) -> Option<ArrayRef>) {
    if entity == ENTITY_MESH {
        info.mesh_rows += 1;
        if let Some(t) = cell("triangle_indices") {
            info.triangles = Some(t.len());
            info.topology = true;
        }
        if let Some(l) = cell(LEVEL_COMPONENT)
            && let Some(l) = l.as_primitive_opt::<UInt8Type>()
        {
            info.levels = l.values().to_vec();
        }
    } else if entity == ENTITY_EDGES {
        if let Some(a) = cell(ANGLE_COMPONENT).and_then(|a| edge_angles(&a)) {
            info.edges = Some(a.len());
            info.max_edge_angle = a.iter().copied().reduce(f64::max);
            info.min_edge_angle = a.iter().copied().reduce(f64::min);
        }
    } else if entity == ENTITY_SEAMS {
        info.seams = Some(seam_row(&cell));
    } else if entity == ENTITY_EVENT_LOG {
        if let Some(t) = cell("text")
            && let Some(t) = t.as_any().downcast_ref::<StringArray>()
        {
            info.events.extend(t.iter().flatten().map(str::to_owned));
        }
    } else if let Some(name) = entity
        .strip_prefix(ENTITY_PLOTS)
        .and_then(|n| n.strip_prefix('/'))
        && let Some(v) = cell("scalars")
        && let Some(v) = v.as_primitive_opt::<Float64Type>()
        && let Some(&v) = v.values().first()
    {
        info.scalars.insert(name.to_owned(), v);
    }
}

/// One `cloth/seams` row: the segments' classes and seam names, counted by state.
fn seam_row(cell: &impl Fn(&str) -> Option<ArrayRef>) -> SeamRow {
    let classes: Vec<u16> = cell("class_ids")
        .and_then(|c| {
            c.as_primitive_opt::<UInt16Type>()
                .map(|c| c.values().to_vec())
        })
        .unwrap_or_default();
    let names: Vec<String> = cell(SEAM_COMPONENT)
        .and_then(|n| {
            n.as_any()
                .downcast_ref::<StringArray>()
                .map(|n| n.iter().flatten().map(str::to_owned).collect())
        })
        .unwrap_or_default();
    SeamRow {
        open: classes.iter().filter(|&&c| c == SEAM_CLASS_OPEN).count(),
        welded: classes.iter().filter(|&&c| c == SEAM_CLASS_WELDED).count(),
        names,
        classes,
    }
}

/// The dihedral angles of one `cloth/edges` row, in degrees: `f32`, or `f64` in
/// older recordings.
fn edge_angles(cell: &ArrayRef) -> Option<Vec<f64>> {
    cell.as_primitive_opt::<Float32Type>()
        .map(|a| a.values().iter().map(|&v| f64::from(v)).collect())
        .or_else(|| {
            cell.as_primitive_opt::<Float64Type>()
                .map(|a| a.values().to_vec())
        })
}

/// Rerun shows the latest value of each component: a frame that did not log the mesh's
/// topology has the triangles and levels of the last frame before it that did.
fn carry_topology(out: &mut Inspection) {
    let mut last: Option<(usize, Vec<u8>)> = None;
    for info in out.frames.values_mut() {
        match (&info.triangles, &last) {
            (Some(t), _) => last = Some((*t, info.levels.clone())),
            (None, Some((t, levels))) if info.mesh_rows > 0 => {
                info.triangles = Some(*t);
                info.levels.clone_from(levels);
            }
            _ => {}
        }
    }
}
