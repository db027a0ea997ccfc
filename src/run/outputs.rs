//! [`Outputs`]: where a run's frames go — the recording (a file, a live viewer
//! or both) and the OBJ directory — which frames are due, and what has been
//! recorded.

use std::path::PathBuf;

use super::recording::{self, FrameTiming, Snapshot};
use super::{RunError, RunOptions};
use crate::math::{Scalar, Vector};
use crate::physics::Energy;
use crate::record::{DecisionData, RecordError, RecordTarget, Recorder, obj::write_mesh_obj};
use crate::scene::Scene;
use crate::sim::SimParts;
use crate::world::World;

/// A run's outputs and what they have received.
pub(super) struct Outputs {
    /// The open recording (`None`: no recording).
    recorder: Option<Recorder>,
    /// The recording's file, for the summary.
    record_path: Option<PathBuf>,
    /// Where each recorded frame goes as an OBJ.
    obj_dir: Option<PathBuf>,
    /// Every `record_every`-th frame is recorded (and the last).
    record_every: u64,
    /// Whether the recording holds the refinement decisions.
    decisions: DecisionData,
    /// Frames in the recording so far.
    recorded_frames: u64,
    /// The last frame in the recording.
    last_recorded: Option<u64>,
    /// Scratch for the vertex normals of a recorded frame.
    normals: Vec<Vector>,
}

/// The file a finished recording was written to: its path, its size in bytes
/// and its frames.
pub(super) type WrittenRecording = (PathBuf, u64, u64);

impl Outputs {
    /// Opens the recording and creates the OBJ directory that `opts` ask for.
    pub(super) fn open(scene: &Scene, opts: &RunOptions) -> Result<Outputs, RunError> {
        let recorder = match (&opts.record, &opts.live) {
            (None, None) => None,
            (file, live) => Some(open_recorder(scene, opts, file, live)?),
        };
        if let Some(dir) = &opts.obj_dir {
            std::fs::create_dir_all(dir).map_err(|source| RecordError::Obj {
                path: dir.clone(),
                source,
            })?;
        }
        Ok(Outputs {
            recorder,
            record_path: opts.record.clone(),
            obj_dir: opts.obj_dir.clone(),
            record_every: opts.record_every.max(1),
            decisions: opts.decisions,
            recorded_frames: 0,
            last_recorded: None,
            normals: Vec::new(),
        })
    }

    /// True when frame `frame` is to be recorded: every `record_every`-th
    /// frame and the last one, `last`.
    pub(super) fn due(&self, frame: u64, last: u64) -> bool {
        frame.is_multiple_of(self.record_every) || frame == last
    }

    /// True when there is a recording.
    pub(super) fn recording(&self) -> bool {
        self.recorder.is_some()
    }

    /// True when there is a recording and `frame` is not its last frame.
    pub(super) fn lacks(&self, frame: u64) -> bool {
        self.recorder.is_some() && self.last_recorded != Some(frame)
    }

    /// Logs the simulation's state as frame `frame` to the recording (when there
    /// is one), with its energy, the wall times to plot and the frame interval.
    pub(super) fn log(
        &mut self,
        sim: &mut SimParts,
        frame: u64,
        energy: Energy,
        timing: FrameTiming,
        frame_interval: Scalar,
    ) -> Result<(), RunError> {
        let Some(rec) = self.recorder.as_mut() else {
            return Ok(());
        };
        let snap = Snapshot {
            frame,
            energy,
            timing,
            frame_interval,
            decisions: self.decisions,
        };
        let SimParts {
            setup,
            state,
            pipeline,
        } = sim;
        recording::record_state(rec, setup, state, pipeline, &snap, &mut self.normals)?;
        self.recorded_frames += 1;
        self.last_recorded = Some(frame);
        Ok(())
    }

    /// Writes the world as frame `frame`'s OBJ (when there is an OBJ directory).
    pub(super) fn export_obj(&self, frame: u64, world: &World) -> Result<(), RunError> {
        if let Some(dir) = &self.obj_dir {
            write_mesh_obj(dir, frame, &world.x, &world.mesh)?;
        }
        Ok(())
    }

    /// Closes the recording; the file written, when there is one.
    pub(super) fn finish(&mut self) -> Result<Option<WrittenRecording>, RunError> {
        let Some(rec) = self.recorder.take() else {
            return Ok(None);
        };
        let bytes = rec.finish()?;
        let frames = self.recorded_frames;
        Ok(self.record_path.take().map(|path| (path, bytes, frames)))
    }
}

/// Opens the recording of `scene` into `file`, `live` or both, with the edges,
/// colours and camera `opts` and the scene ask for.
fn open_recorder(
    scene: &Scene,
    opts: &RunOptions,
    file: &Option<PathBuf>,
    live: &Option<crate::record::LiveViewer>,
) -> Result<Recorder, RunError> {
    let target = RecordTarget {
        file: file.clone(),
        live: live.clone(),
    };
    let refine = scene.adapt.as_ref().map(|a| a.refine_angle);
    let mut recorder = Recorder::open_coloured(
        &target,
        &scene.name,
        opts.edges.resolve(refine),
        opts.colour_by,
    )?;
    if let Some(camera) = &scene.camera {
        recorder.set_camera(camera.camera());
    }
    Ok(recorder)
}
