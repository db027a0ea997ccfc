//! [`Recorder`]: one run written frame by frame to a `.rrd` file and/or a live viewer, with
//! the static data logged when it opens (the schema is in the module docs of [`super`]).

use std::collections::HashMap;
use std::path::Path;

use rerun::{AsComponents, EntityPath, RecordingStream, RecordingStreamBuilder};

use super::garment::{self, ColourBy, SINGLE_PANEL_NAME};
use super::{
    APPLICATION_ID, BoxError, Camera, ENTITY_EDGES, ENTITY_EVENT_LOG, ENTITY_EVENT_POINTS,
    ENTITY_LEGEND, ENTITY_MESH, ENTITY_PINS, ENTITY_PLOTS, ENTITY_SEAMS, EdgeDisplay, FrameView,
    RecordError, RecordTarget, TIMELINE_FRAME, TIMELINE_SIM_TIME, convert, edges, events, frame,
    layout, mesh, recording_id, sink,
};

/// Colour of the pin markers (white, visible on every level colour).
const PIN_COLOR: [u8; 3] = [0xFF, 0xFF, 0xFF];
/// Radius of the pin markers on screen, in UI points.
const PIN_RADIUS_UI: f32 = 4.0;

/// Writes one run to a `.rrd` file and/or a live viewer, frame by frame.
///
/// Dropping a `Recorder` without [`Recorder::finish`] (early return, `?`, panic unwinding)
/// still flushes and closes the file, footer included, so it stays a valid `.rrd`.
pub struct Recorder {
    /// The sole handle on the stream: dropping it joins rerun's threads and writes the footer.
    stream: RecordingStream,
    target: RecordTarget,
    /// `target.describe()`, for error messages.
    described: String,
    edges: EdgeDisplay,
    /// What the mesh's triangles are coloured by.
    colour_by: ColourBy,
    /// The class of each triangle of the frame being logged (scratch).
    classes: Vec<u16>,
    /// Whether the static data of `cloth/seams` has been logged.
    seams_static_sent: bool,
    mesh_path: EntityPath,
    edges_path: EntityPath,
    pins_path: EntityPath,
    /// The recorded topology of `cloth/mesh` (logged again only when it changes).
    cloth_mesh: mesh::ClothMesh,
    /// `plots/<name>` per scalar name, parsed once.
    scalar_paths: HashMap<String, EntityPath>,
    blueprint_sent: bool,
    /// The first recorded frame's mean edge length, m: the unrefined mesh's, which sizes the
    /// event points.
    base_edge: Option<f32>,
    /// Where the blueprint's 3D views look from.
    camera: Camera,
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder")
            .field("target", &self.target)
            .field("edges", &self.edges)
            .field("colour_by", &self.colour_by)
            .finish_non_exhaustive()
    }
}

impl Recorder {
    /// Opens `path` for writing, with every edge drawn; see [`Recorder::open`].
    pub fn create(path: &Path, scene_name: &str) -> Result<Recorder, RecordError> {
        Recorder::open(&RecordTarget::file(path), scene_name, EdgeDisplay::All)
    }

    /// Opens the recording's destinations with the triangles coloured by refinement level;
    /// see [`Recorder::open_coloured`].
    pub fn open(
        target: &RecordTarget,
        scene_name: &str,
        edges: EdgeDisplay,
    ) -> Result<Recorder, RecordError> {
        Recorder::open_coloured(target, scene_name, edges, ColourBy::Level)
    }

    /// Opens the recording's destinations and logs the static data.
    ///
    /// The file, if any, is created (truncated) immediately, so an unwritable path (missing
    /// directory, no permission) fails here with [`RecordError::Create`], before a viewer is
    /// started and before any simulation. A viewer that cannot be spawned (no `rerun` on
    /// `PATH`) or a URL that is not a viewer's proxy URL fails here too; a viewer that does not
    /// answer does not (rerun keeps retrying in the background).
    ///
    /// The recording id derives from `scene_name` ([`recording_id`]), which is also the
    /// recording's name. Logs once: view coordinates (right-handed, z up) and the annotation
    /// context of the angle classes at `cloth/edges` (unless edges are off). The annotation
    /// context of the triangles' classes (levels, or panels with [`ColourBy::Panel`]), the
    /// legend, the static parts of `cloth/seams` (garments only) and the default blueprint
    /// follow with the first frame, which names the panels and tells whether the cloth is a
    /// garment.
    ///
    /// Without a live viewer the rows of an entity are batched into chunks of up to 2 MiB
    /// whatever the time between frames ([`sink::file_only_batching`]): a slow run otherwise
    /// gets one chunk, with its own schema, per entity and frame. With a viewer rerun's
    /// default (a chunk at least every 200 ms) keeps the viewer up to date.
    pub fn open_coloured(
        target: &RecordTarget,
        scene_name: &str,
        edges: EdgeDisplay,
        colour_by: ColourBy,
    ) -> Result<Recorder, RecordError> {
        let described = target.describe();
        let create_err = |source: BoxError| RecordError::Create {
            target: described.clone(),
            source,
        };
        let sinks = sink::open_sinks(target)?;
        let mut builder = RecordingStreamBuilder::new(APPLICATION_ID);
        if target.live.is_none() {
            builder = builder.batcher_config(sink::file_only_batching());
        }
        let stream = builder
            .recording_id(recording_id(scene_name))
            // `recording_id` turns the properties chunk off; keep the name in the file.
            .send_properties(true)
            .recording_name(scene_name)
            // Ignore `RERUN=off`: a requested recording is always written.
            .enabled(true)
            .set_sinks(sinks)
            .map_err(|e| create_err(Box::new(e)))?;
        if !stream.is_enabled() {
            return Err(create_err("rerun disabled the recording stream".into()));
        }
        // Only `frame` and `sim_time`: no wall-clock `log_time` column (wall time per frame is
        // a plot instead), which also keeps the data part of the file reproducible.
        stream.set_log_time_enabled(false);
        let recorder = Recorder {
            stream,
            target: target.clone(),
            described,
            edges,
            colour_by,
            classes: Vec::new(),
            seams_static_sent: false,
            mesh_path: EntityPath::from(ENTITY_MESH),
            edges_path: EntityPath::from(ENTITY_EDGES),
            pins_path: EntityPath::from(ENTITY_PINS),
            cloth_mesh: mesh::ClothMesh::default(),
            scalar_paths: HashMap::new(),
            blueprint_sent: false,
            base_edge: None,
            camera: Camera::Follow,
        };
        recorder.log_static_data()?;
        Ok(recorder)
    }

    /// Logs what every frame shares, once: view coordinates and the angle annotations
    /// (unless edges are off).
    fn log_static_data(&self) -> Result<(), RecordError> {
        self.stream
            .log_static("/", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())
            .map_err(|e| self.log_err("/", e))?;
        if self.edges != EdgeDisplay::Off {
            self.stream
                .log_static(ENTITY_EDGES, &edges::angle_annotations())
                .map_err(|e| self.log_err(ENTITY_EDGES, e))?;
        }
        Ok(())
    }

    /// Logs, with the first frame, the static data that depends on the cloth: the annotation
    /// context at `cloth` (levels, or the panels' names), the legend, and the blueprint.
    fn log_first_frame_data(&self, frame: &FrameView) -> Result<(), RecordError> {
        let single = [SINGLE_PANEL_NAME.to_owned()];
        let panels = frame
            .garment
            .as_ref()
            .map_or(&single[..], |g| g.panel_names);
        let context = match self.colour_by {
            ColourBy::Level => convert::level_annotations(),
            ColourBy::Panel => garment::panel_annotations(panels),
        };
        self.stream
            .log_static("cloth", &context)
            .map_err(|e| self.log_err("cloth", e))?;
        let legend_panels = (self.colour_by == ColourBy::Panel).then_some(panels);
        let legend = layout::legend_markdown(legend_panels, frame.garment.is_some());
        self.stream
            .log_static(ENTITY_LEGEND, &rerun::TextDocument::from_markdown(legend))
            .map_err(|e| self.log_err(ENTITY_LEGEND, e))?;
        let names: Vec<&str> = frame.scalars.iter().map(|(n, _)| *n).collect();
        layout::send_blueprint(&self.stream, &names, self.camera, frame.positions)
            .map_err(|e| self.log_err("blueprint", e))
    }

    /// Sets where the blueprint's 3D views look from ([`Camera::Follow`] unless set). The
    /// blueprint goes out with the first frame, so a camera set after it has no effect.
    pub fn set_camera(&mut self, camera: Camera) {
        self.camera = camera;
    }

    /// Where the recording goes.
    pub fn target(&self) -> &RecordTarget {
        &self.target
    }

    /// Logs one frame: sets the `frame` and `sim_time` timelines, then logs the mesh at
    /// `cloth/mesh` (positions and normals; the topology, colours, class ids and
    /// `triangle_level` data too when the triangles, levels or classes changed), the edges at
    /// `cloth/edges` (unless [`EdgeDisplay::Off`]), a garment's seams at `cloth/seams`, the
    /// pinned vertices at `cloth/pins`, the events at `events/points` and `events/log`, and
    /// each scalar at `plots/<name>`.
    ///
    /// The data is validated first ([`RecordError::InvalidFrame`] on a length mismatch, an
    /// index out of range or a non-finite `sim_time`); nothing is logged for an invalid frame
    /// and the recorder stays usable. Vertices are converted straight from the slices into
    /// rerun's arrow buffers; the recorder keeps one copy of the last logged topology to tell
    /// whether it changed.
    pub fn record_frame(&mut self, frame: &FrameView) -> Result<(), RecordError> {
        let frame_index = frame::validate(frame)?;
        if !self.blueprint_sent {
            self.log_first_frame_data(frame)?;
            self.blueprint_sent = true;
            self.base_edge = events::mean_edge_length(frame.positions, frame.triangles);
        }

        self.stream.set_time_sequence(TIMELINE_FRAME, frame_index);
        self.stream
            .set_duration_secs(TIMELINE_SIM_TIME, frame.sim_time);

        self.log_mesh(frame)?;
        self.log_edges(frame)?;
        self.log_seams(frame)?;
        self.log_pins(frame)?;
        self.log_events(frame)?;
        self.log_scalars(frame)
    }

    /// `cloth/mesh`: positions and normals, with the topology when it changed.
    fn log_mesh(&mut self, frame: &FrameView) -> Result<(), RecordError> {
        let (positions, normals) = (frame.positions, frame.vertex_normals);
        self.classes.clear();
        match (self.colour_by, &frame.garment) {
            (ColourBy::Level, _) => self
                .classes
                .extend(frame.triangle_levels.iter().map(|&l| u16::from(l))),
            (ColourBy::Panel, Some(g)) => self.classes.extend_from_slice(g.triangle_panels),
            (ColourBy::Panel, None) => self.classes.resize(frame.triangles.len(), 0),
        }
        let changed = self.cloth_mesh.update(
            positions.len(),
            frame.triangles,
            frame.triangle_levels,
            &self.classes,
        );
        let geometry = self.cloth_mesh.geometry(positions, normals);
        let logged = if changed {
            let (topology, data) = match self.colour_by {
                ColourBy::Level => self
                    .cloth_mesh
                    .topology(|c| convert::level_rgb(u8::try_from(c).unwrap_or(u8::MAX))),
                ColourBy::Panel => self.cloth_mesh.topology(garment::panel_rgb),
            };
            self.stream.log(
                self.mesh_path.clone(),
                &[&geometry as &dyn AsComponents, &topology, &data],
            )
        } else {
            self.stream.log(self.mesh_path.clone(), &geometry)
        };
        logged.map_err(|e| self.log_err(ENTITY_MESH, e))
    }

    /// `cloth/edges`, unless [`EdgeDisplay::Off`] (or no edge is selected).
    fn log_edges(&self, frame: &FrameView) -> Result<(), RecordError> {
        if let Some((strips, data)) =
            edges::edge_row(self.edges, frame.positions, frame.edges, frame.edge_angles)
        {
            self.stream
                .log(
                    self.edges_path.clone(),
                    &[&strips as &dyn AsComponents, &data],
                )
                .map_err(|e| self.log_err(ENTITY_EDGES, e))?;
        }
        Ok(())
    }

    /// `cloth/seams` for a garment: every seam's segments, this frame's positions; with the
    /// first garment frame its static annotation context and line width.
    fn log_seams(&mut self, frame: &FrameView) -> Result<(), RecordError> {
        let Some(g) = &frame.garment else {
            return Ok(());
        };
        if !self.seams_static_sent {
            let (context, width) = garment::seam_static();
            self.stream
                .log_static(ENTITY_SEAMS, &[&context as &dyn AsComponents, &width])
                .map_err(|e| self.log_err(ENTITY_SEAMS, e))?;
            self.seams_static_sent = true;
        }
        let (strips, data) = garment::seam_row(frame.positions, g.seams);
        self.stream
            .log(ENTITY_SEAMS, &[&strips as &dyn AsComponents, &data])
            .map_err(|e| self.log_err(ENTITY_SEAMS, e))
    }

    /// `cloth/pins`: the pinned vertices as white points.
    fn log_pins(&self, frame: &FrameView) -> Result<(), RecordError> {
        let [r, g, b] = PIN_COLOR;
        let pins = rerun::Points3D::new(
            frame
                .pinned
                .iter()
                .map(|&i| convert::position(frame.positions[i as usize])),
        )
        .with_radii([rerun::Radius::new_ui_points(PIN_RADIUS_UI)])
        .with_colors([rerun::Rgba32::from_rgb(r, g, b)]);
        self.stream
            .log(self.pins_path.clone(), &pins)
            .map_err(|e| self.log_err(ENTITY_PINS, e))
    }

    /// `events/points` (one row, possibly empty) and one `events/log` line per event.
    fn log_events(&self, frame: &FrameView) -> Result<(), RecordError> {
        self.stream
            .log(
                ENTITY_EVENT_POINTS,
                &events::event_points(frame.events, self.base_edge),
            )
            .map_err(|e| self.log_err(ENTITY_EVENT_POINTS, e))?;
        for e in frame.events {
            self.stream
                .log(ENTITY_EVENT_LOG, &events::event_line(e))
                .map_err(|err| self.log_err(ENTITY_EVENT_LOG, err))?;
        }
        Ok(())
    }

    /// `plots/<name>` for each scalar, the entity paths parsed once per name.
    fn log_scalars(&mut self, frame: &FrameView) -> Result<(), RecordError> {
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

    /// Flushes and closes the stream (the file's footer included) and returns the size of the
    /// `.rrd` file in bytes (0 when only streaming to a viewer).
    ///
    /// The stream is closed even when flushing fails; the error then says the file may be
    /// incomplete.
    pub fn finish(mut self) -> Result<u64, RecordError> {
        let stream = std::mem::replace(&mut self.stream, RecordingStream::disabled());
        let flushed = stream.flush_blocking();
        // Last handle: this joins rerun's batcher and writer threads, which write the footer.
        drop(stream);
        let finish_err = |message: String| RecordError::Finish {
            target: self.described.clone(),
            message,
        };
        flushed.map_err(|e| finish_err(e.to_string()))?;
        match &self.target.file {
            Some(path) => Ok(std::fs::metadata(path)
                .map_err(|e| finish_err(format!("cannot read the file size: {e}")))?
                .len()),
            None => Ok(0),
        }
    }

    /// The recording stream (for the obstacle logging in `obstacles.rs`).
    pub(super) fn stream(&self) -> &RecordingStream {
        &self.stream
    }

    /// A [`RecordError::Log`] for `entity`.
    pub(super) fn log_err(
        &self,
        entity: &str,
        source: impl std::error::Error + Send + Sync + 'static,
    ) -> RecordError {
        RecordError::Log {
            target: self.described.clone(),
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
                self.described
            );
        }
        drop(stream);
    }
}
