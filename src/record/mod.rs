//! Recording of a run to a Rerun `.rrd` file (SPEC section 7), and OBJ frame export.
//!
//! This is the only module that imports `rerun`. The engine hands each frame over as plain
//! slices ([`FrameView`]); every conversion to rerun types lives in `convert.rs`.
//!
//! What a recording holds:
//! - timelines `frame` (sequence) and `sim_time` (duration, seconds), set before each frame
//!   (rerun's wall-clock `log_time` timeline is turned off);
//! - static data: view coordinates at `/` (right-handed, z up) and an annotation context at
//!   `cloth` that names and colours the refinement levels (`level 0`, `level 1`, ...);
//! - `cloth/mesh` every frame: a `Mesh3D` whose vertices are un-shared (three per triangle, in
//!   triangle order, no index buffer) so that each triangle carries its own colour from
//!   [`LEVEL_PALETTE`], with per-vertex normals and the level as class id (data + legend);
//! - `cloth/pins` every frame: the pinned vertices as points;
//! - `plots/<name>` every frame for each scalar of [`FrameView::scalars`];
//! - a default blueprint, sent with the first frame once the plot names are known: a 3D view
//!   of the whole scene beside one time-series view per top-level plot group (`plots/energy`,
//!   `plots/mesh`, ...).
//!
//! The recording is forced on: `RERUN=off` in the environment does not disable it (the builder
//! uses `enabled(true)`, which rerun documents as ignoring the `RERUN` variable). One
//! exception, a rerun 0.36.3 limitation: rerun builds the blueprint in a second, internal
//! stream that does honour `RERUN=off` (and then panics on the empty result), so under
//! `RERUN=off` the blueprint is left out and the viewer falls back to its automatic layout.
//! Rerun's private test variable `_RERUN_TEST_FORCE_SAVE` redirects every stream to its own
//! path; do not set it.

mod convert;
pub mod obj;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use rerun::blueprint::{
    Blueprint, BlueprintActivation, ContainerLike, Horizontal, Spatial3DView, TextLogView,
    TimeSeriesView, Vertical,
};
use rerun::{EntityPath, RecordingStream, RecordingStreamBuilder};

use crate::math::Vector;

/// Colour of each refinement level, as sRGB `[r, g, b]`.
///
/// | level | colour | hex |
/// |---|---|---|
/// | 0 | steel blue (calm, the coarse base mesh) | `#4682B4` |
/// | 1 | teal | `#26A69A` |
/// | 2 | green | `#66BB6A` |
/// | 3 | yellow | `#FDD835` |
/// | 4 | orange | `#FF9800` |
/// | 5 | deep orange | `#F4511E` |
/// | 6 | red | `#D32F2F` |
/// | 7 and deeper | crimson | `#880E4F` |
///
/// Deeper (finer) levels are warmer, so refined regions stand out against the blue base.
pub const LEVEL_PALETTE: [[u8; 3]; 8] = [
    [0x46, 0x82, 0xB4],
    [0x26, 0xA6, 0x9A],
    [0x66, 0xBB, 0x6A],
    [0xFD, 0xD8, 0x35],
    [0xFF, 0x98, 0x00],
    [0xF4, 0x51, 0x1E],
    [0xD3, 0x2F, 0x2F],
    [0x88, 0x0E, 0x4F],
];

/// Number of levels (0 up to this, exclusive) named in the annotation context; deeper levels
/// still get their colour, only without a label.
pub const ANNOTATED_LEVELS: usize = 16;

/// Rerun application id of every drape recording.
pub const APPLICATION_ID: &str = "drape";
/// Sequence timeline holding the frame index.
pub const TIMELINE_FRAME: &str = "frame";
/// Duration timeline holding the simulated time, in seconds.
pub const TIMELINE_SIM_TIME: &str = "sim_time";
/// Entity of the cloth mesh.
pub const ENTITY_MESH: &str = "cloth/mesh";
/// Entity of the pinned vertices.
pub const ENTITY_PINS: &str = "cloth/pins";
/// Parent entity of the scalar plots: scalar `name` is logged at `plots/<name>`.
pub const ENTITY_PLOTS: &str = "plots";
/// Parent entity of the obstacles: each is a mesh at `obstacles/<name>`.
pub const ENTITY_OBSTACLES: &str = "obstacles";
/// Colour of the obstacles (light grey).
const OBSTACLE_COLOR: [u8; 3] = [0xB0, 0xB0, 0xB0];

/// Colour of the pin markers (white, visible on every level colour).
const PIN_COLOR: [u8; 3] = [0xFF, 0xFF, 0xFF];
/// Radius of the pin markers on screen, in UI points.
const PIN_RADIUS_UI: f32 = 4.0;

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
    /// What happened: `split`, `closure_split`, `merge`, `flip`, `collapse` or `rollback`.
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

/// Entity of the event points (one point per event of the frame, labelled).
pub const ENTITY_EVENT_POINTS: &str = "events/points";
/// Entity of the event log (one text line per event).
pub const ENTITY_EVENT_LOG: &str = "events/log";

/// Colour of an event's point by kind, sRGB.
fn event_color(kind: &str) -> [u8; 3] {
    match kind {
        "split" => [0xFF, 0x8F, 0x00],
        "closure_split" => [0xFF, 0xD5, 0x4F],
        "merge" | "collapse" => [0x42, 0xA5, 0xF5],
        "flip" => [0xBD, 0xBD, 0xBD],
        _ => [0xE5, 0x39, 0x35],
    }
}

/// Boxed error from rerun, kept opaque so rerun's types stay inside this module.
type BoxError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// Everything that can go wrong while recording.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The `.rrd` file could not be created (missing directory, no permission, ...).
    #[error("cannot create recording file {}: {source}", .path.display())]
    Create {
        /// The requested `.rrd` path.
        path: PathBuf,
        /// What rerun or the file system reported.
        #[source]
        source: BoxError,
    },
    /// Rerun refused to log an entity.
    #[error("cannot log {entity} to recording {}: {source}", .path.display())]
    Log {
        /// The `.rrd` path.
        path: PathBuf,
        /// The entity being logged.
        entity: String,
        /// What rerun reported.
        #[source]
        source: BoxError,
    },
    /// The frame data is inconsistent (length mismatch, index out of range, non-finite time).
    #[error("invalid frame {frame}: {reason}")]
    InvalidFrame {
        /// The frame index.
        frame: u64,
        /// What is wrong with it.
        reason: String,
    },
    /// Flushing or closing the `.rrd` file failed; the file may be incomplete.
    #[error("cannot finish recording file {}: {message}", .path.display())]
    Finish {
        /// The `.rrd` path.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// An OBJ frame file could not be written.
    #[error("cannot write OBJ file {}: {source}", .path.display())]
    Obj {
        /// The OBJ path.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// The recording id for a scene: the same scene name always gives the same id, so re-running a
/// scene replaces its recording in the viewer instead of adding a new one.
///
/// It is a 128-bit FNV-1a hash of `drape/<scene_name>`, formatted as a version-8 UUID.
pub fn recording_id(scene_name: &str) -> String {
    const OFFSET: u128 = 0x6c62_272e_07bb_0142_62b8_2175_6295_c58d;
    const PRIME: u128 = 0x0000_0000_0100_0000_0000_0000_0000_013b;
    let mut h = OFFSET;
    for &b in b"drape/".iter().chain(scene_name.as_bytes()) {
        h ^= u128::from(b);
        h = h.wrapping_mul(PRIME);
    }
    h = (h & !(0xf << 76)) | (0x8 << 76); // version 8 (custom)
    h = (h & !(0x3 << 62)) | (0x2 << 62); // RFC 4122 variant
    format!(
        "{:08x}-{:04x}-{:04x}-{:04x}-{:012x}",
        h >> 96,
        (h >> 80) & 0xffff,
        (h >> 64) & 0xffff,
        (h >> 48) & 0xffff,
        h & 0xffff_ffff_ffff
    )
}

/// Writes one run to a `.rrd` file, frame by frame.
///
/// Dropping a `Recorder` without [`Recorder::finish`] (early return, `?`, panic unwinding)
/// still flushes and closes the file, footer included, so it stays a valid `.rrd`.
pub struct Recorder {
    /// The sole handle on the stream: dropping it joins rerun's threads and writes the footer.
    stream: RecordingStream,
    path: PathBuf,
    mesh_path: EntityPath,
    pins_path: EntityPath,
    /// `plots/<name>` per scalar name, parsed once.
    scalar_paths: HashMap<String, EntityPath>,
    blueprint_sent: bool,
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder")
            .field("path", &self.path)
            .finish_non_exhaustive()
    }
}

impl Recorder {
    /// Opens `path` for writing and logs the static data.
    ///
    /// The file is created (truncated) immediately, so an unwritable path (missing directory,
    /// no permission) fails here with [`RecordError::Create`]. The recording id derives from
    /// `scene_name` ([`recording_id`]), which is also the recording's name. Logs once: view
    /// coordinates (right-handed, z up) and the annotation context of the level colours. The
    /// default blueprint follows with the first frame (see the module docs).
    pub fn create(path: &Path, scene_name: &str) -> Result<Recorder, RecordError> {
        let create_err = |source: BoxError| RecordError::Create {
            path: path.to_path_buf(),
            source,
        };
        let stream = RecordingStreamBuilder::new(APPLICATION_ID)
            .recording_id(recording_id(scene_name))
            // `recording_id` turns the properties chunk off; keep the name in the file.
            .send_properties(true)
            .recording_name(scene_name)
            // Ignore `RERUN=off`: a requested file is always written.
            .enabled(true)
            .save(path)
            .map_err(|e| create_err(Box::new(e)))?;
        if !stream.is_enabled() {
            return Err(create_err("rerun disabled the recording stream".into()));
        }
        // Only `frame` and `sim_time`: no wall-clock `log_time` column (wall time per frame is
        // a plot instead), which also keeps the data part of the file reproducible.
        stream.set_log_time_enabled(false);
        let recorder = Recorder {
            stream,
            path: path.to_path_buf(),
            mesh_path: EntityPath::from(ENTITY_MESH),
            pins_path: EntityPath::from(ENTITY_PINS),
            scalar_paths: HashMap::new(),
            blueprint_sent: false,
        };
        recorder
            .stream
            .log_static("/", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())
            .map_err(|e| recorder.log_err("/", e))?;
        recorder
            .stream
            .log_static("cloth", &convert::level_annotations())
            .map_err(|e| recorder.log_err("cloth", e))?;
        Ok(recorder)
    }

    /// The `.rrd` path being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Logs one frame: sets the `frame` and `sim_time` timelines, then logs the mesh at
    /// `cloth/mesh` (un-shared vertices coloured by level, normals, level as class id), the
    /// pinned vertices at `cloth/pins` and each scalar at `plots/<name>`.
    ///
    /// The data is validated first ([`RecordError::InvalidFrame`] on a length mismatch, an
    /// index out of range or a non-finite `sim_time`); nothing is logged for an invalid frame
    /// and the recorder stays usable. Vertices are converted straight from the slices into
    /// rerun's arrow buffers: no per-frame buffers of our own are needed.
    pub fn record_frame(&mut self, frame: &FrameView) -> Result<(), RecordError> {
        let frame_index = validate(frame)?;
        if !self.blueprint_sent {
            self.send_blueprint(frame.scalars)?;
            self.blueprint_sent = true;
        }

        self.stream.set_time_sequence(TIMELINE_FRAME, frame_index);
        self.stream
            .set_duration_secs(TIMELINE_SIM_TIME, frame.sim_time);

        let (positions, normals) = (frame.positions, frame.vertex_normals);
        let corners = |tri: &[u32; 3]| tri.map(|i| i as usize);
        let mesh = rerun::Mesh3D::new(
            frame
                .triangles
                .iter()
                .flat_map(|t| corners(t).map(|i| convert::position(positions[i]))),
        )
        .with_vertex_normals(
            frame
                .triangles
                .iter()
                .flat_map(|t| corners(t).map(|i| convert::vector(normals[i]))),
        )
        .with_vertex_colors(
            frame
                .triangle_levels
                .iter()
                .flat_map(|&l| [convert::level_color(l); 3]),
        )
        .with_class_ids(
            frame
                .triangle_levels
                .iter()
                .flat_map(|&l| [convert::level_class_id(l); 3]),
        );
        self.stream
            .log(self.mesh_path.clone(), &mesh)
            .map_err(|e| self.log_err(ENTITY_MESH, e))?;

        let [r, g, b] = PIN_COLOR;
        let pins = rerun::Points3D::new(
            frame
                .pinned
                .iter()
                .map(|&i| convert::position(positions[i as usize])),
        )
        .with_radii([rerun::Radius::new_ui_points(PIN_RADIUS_UI)])
        .with_colors([rerun::Rgba32::from_rgb(r, g, b)]);
        self.stream
            .log(self.pins_path.clone(), &pins)
            .map_err(|e| self.log_err(ENTITY_PINS, e))?;

        self.record_events(frame.events)?;

        for &(name, value) in frame.scalars {
            let path = match self.scalar_paths.get(name) {
                Some(path) => path.clone(),
                None => {
                    let path = EntityPath::from(format!("{ENTITY_PLOTS}/{name}"));
                    self.scalar_paths.insert(name.to_owned(), path.clone());
                    path
                }
            };
            self.stream
                .log(path, &rerun::Scalars::single(value))
                .map_err(|e| self.log_err(&format!("{ENTITY_PLOTS}/{name}"), e))?;
        }
        Ok(())
    }

    /// Logs an obstacle's triangulation at `obstacles/<name>` (non-alphanumeric characters of
    /// `name` become `_`) in a neutral grey: as static data when `fixed` (log it once), else
    /// at the current frame (call it after [`Recorder::record_frame`] every frame).
    pub fn record_obstacle(
        &mut self,
        name: &str,
        positions: &[Vector],
        triangles: &[[u32; 3]],
        fixed: bool,
    ) -> Result<(), RecordError> {
        let n = positions.len();
        if let Some(t) = triangles
            .iter()
            .find(|t| t.iter().any(|&i| i as usize >= n))
        {
            return Err(RecordError::InvalidFrame {
                frame: 0,
                reason: format!("obstacle {name}: triangle {t:?} indexes past {n} vertices"),
            });
        }
        let clean: String = name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        let entity = format!("{ENTITY_OBSTACLES}/{clean}");
        let [r, g, b] = OBSTACLE_COLOR;
        let mesh = rerun::Mesh3D::new(positions.iter().map(|&p| convert::position(p)))
            .with_triangle_indices(triangles.iter().copied())
            .with_albedo_factor(rerun::Rgba32::from_rgb(r, g, b));
        let logged = if fixed {
            self.stream.log_static(entity.as_str(), &mesh)
        } else {
            self.stream.log(entity.as_str(), &mesh)
        };
        logged.map_err(|e| self.log_err(&entity, e))
    }

    /// Flushes and closes the file, footer included, and returns its size in bytes.
    ///
    /// The stream is closed even when flushing fails; the error then says the file may be
    /// incomplete.
    pub fn finish(mut self) -> Result<u64, RecordError> {
        let stream = std::mem::replace(&mut self.stream, RecordingStream::disabled());
        let flushed = stream.flush_blocking();
        // Last handle: this joins rerun's batcher and writer threads, which write the footer.
        drop(stream);
        let finish_err = |message: String| RecordError::Finish {
            path: self.path.clone(),
            message,
        };
        flushed.map_err(|e| finish_err(e.to_string()))?;
        let len = std::fs::metadata(&self.path)
            .map_err(|e| finish_err(format!("cannot read the file size: {e}")))?
            .len();
        Ok(len)
    }

    /// Logs the frame's events: labelled points (an empty set when there are none, so the
    /// 3D view shows only the current frame's events) and one text line per event.
    fn record_events(&mut self, events: &[EventMark]) -> Result<(), RecordError> {
        let points = rerun::Points3D::new(events.iter().map(|e| convert::position(e.position)))
            .with_colors(events.iter().map(|e| {
                let [r, g, b] = event_color(e.kind);
                rerun::Rgba32::from_rgb(r, g, b)
            }))
            .with_labels(events.iter().map(|e| e.kind))
            .with_radii([rerun::Radius::new_ui_points(6.0)]);
        self.stream
            .log(ENTITY_EVENT_POINTS, &points)
            .map_err(|e| self.log_err(ENTITY_EVENT_POINTS, e))?;
        for e in events {
            let angle = e
                .angle
                .map(|a| format!(", angle {a:.2} deg"))
                .unwrap_or_default();
            let line = format!(
                "{} after step {}: level {}{angle}, at ({:.3}, {:.3}, {:.3}) m",
                e.kind, e.step, e.level, e.position.x, e.position.y, e.position.z
            );
            let level = if e.kind == "rollback" { "WARN" } else { "INFO" };
            self.stream
                .log(
                    ENTITY_EVENT_LOG,
                    &rerun::TextLog::new(line).with_level(level),
                )
                .map_err(|err| self.log_err(ENTITY_EVENT_LOG, err))?;
        }
        Ok(())
    }

    /// Sends the default blueprint: the 3D scene beside one time-series view per top-level
    /// plot group (first segment of the scalar names) and the event log.
    fn send_blueprint(&self, scalars: &[(&str, f64)]) -> Result<(), RecordError> {
        // rerun 0.36.3's `Blueprint::send` builds an internal stream that honours `RERUN=off`
        // and then panics on its empty output: skip the blueprint in that case.
        if !rerun::decide_logging_enabled(true) {
            return Ok(());
        }
        let mut groups: Vec<&str> = scalars
            .iter()
            .filter_map(|(name, _)| name.split('/').find(|s| !s.is_empty()))
            .collect();
        groups.sort_unstable();
        groups.dedup();
        let scene: ContainerLike = Spatial3DView::new("cloth").with_origin("/").into();
        let root: ContainerLike = if groups.is_empty() {
            scene
        } else {
            let plots = groups.iter().map(|g| {
                TimeSeriesView::new(*g)
                    .with_origin(format!("{ENTITY_PLOTS}/{g}"))
                    .into()
            });
            let log: ContainerLike = TextLogView::new("events")
                .with_origin(ENTITY_EVENT_LOG)
                .into();
            Horizontal::new([scene, Vertical::new(plots.chain([log])).into()])
                .with_column_shares([2.0_f32, 1.0])
                .into()
        };
        Blueprint::new(root)
            .with_auto_views(false)
            .send(
                &self.stream,
                BlueprintActivation {
                    make_active: true,
                    make_default: true,
                },
            )
            .map_err(|e| self.log_err("blueprint", e))
    }

    fn log_err(
        &self,
        entity: &str,
        source: impl std::error::Error + Send + Sync + 'static,
    ) -> RecordError {
        RecordError::Log {
            path: self.path.clone(),
            entity: entity.to_owned(),
            source: Box::new(source),
        }
    }
}

impl Drop for Recorder {
    /// Flushes and closes the stream if [`Recorder::finish`] was not called, so that an early
    /// return or a panic still leaves a complete `.rrd` (errors go to stderr: none can be
    /// returned from here).
    fn drop(&mut self) {
        let stream = std::mem::replace(&mut self.stream, RecordingStream::disabled());
        if stream.is_enabled()
            && let Err(e) = stream.flush_blocking()
        {
            eprintln!(
                "drape: warning: recording {} may be incomplete: {e}",
                self.path.display()
            );
        }
        drop(stream);
    }
}

/// Checks the frame's slices against each other; returns the frame index for the timeline.
fn validate(frame: &FrameView) -> Result<i64, RecordError> {
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
    if let Some(&i) = frame.pinned.iter().find(|&&i| i as usize >= n) {
        return Err(invalid(format!(
            "pinned vertex {i} is past the {n} vertices"
        )));
    }
    Ok(index)
}
