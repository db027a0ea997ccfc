//! [`FrameLoop`]: a run frame by frame — advance the simulation, observe and record
//! the frame, and summarise at the end.

use std::path::PathBuf;
use std::time::Instant;

use super::recording::{self, FrameTiming, Snapshot};
use super::tally::{Tally, TallyEnd};
use super::{FrameState, Progress, RunError, RunOptions};
use crate::adapt::Adapter;
use crate::math::{Scalar, Vector};
use crate::physics::Energy;
use crate::record::{RecordError, RecordTarget, Recorder, obj::write_mesh_obj};
use crate::scene::Scene;
use crate::sim::{
    FrameFailed, FrameFailure, MAX_STEP_HALVINGS, Pipeline, Setup, SimParts, SimState, StepFailure,
    StepSize,
};
use crate::summary::Summary;

/// A run in progress: the simulation, its outputs and its running statistics.
/// [`FrameLoop::new`] opens the outputs; then, per frame, [`FrameLoop::record`]
/// and [`FrameLoop::advance`]; [`FrameLoop::finish`] closes the recording and makes
/// the summary.
pub struct FrameLoop<'a> {
    scene: &'a Scene,
    setup: Setup,
    state: SimState,
    pipeline: Pipeline,
    /// The energy of the state as it is, once measured (or handed over by the
    /// pipeline) for the frame's statistics; cleared when the state advances.
    energy_now: Option<Energy>,
    recorder: Option<Recorder>,
    record_path: Option<PathBuf>,
    obj_dir: Option<PathBuf>,
    record_every: u64,
    /// Frames after the initial one.
    frames: u64,
    frame_interval: Scalar,
    /// The frame the state is at.
    frame: u64,
    tally: Tally,
    started: Instant,
    sim_seconds: Scalar,
    record_seconds: Scalar,
    /// Wall time of the last frame's stepping and of the last recorded frame's recording.
    timing: FrameTiming,
    recorded_frames: u64,
    last_recorded: Option<u64>,
    normals: Vec<Vector>,
    interrupted: bool,
    /// The frame whose steps all failed, and how.
    failure: Option<(u64, FrameFailure)>,
}

impl<'a> FrameLoop<'a> {
    /// A run of `scene` from the built simulation ([`crate::sim::build`]); opens
    /// the recording and the OBJ directory.
    pub fn new(
        scene: &'a Scene,
        sim: SimParts,
        opts: &RunOptions,
    ) -> Result<FrameLoop<'a>, RunError> {
        super::measure::check(scene, &sim.setup, &sim.state.world)?;
        let recorder = match (&opts.record, &opts.live) {
            (None, None) => None,
            (file, live) => {
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
                Some(recorder)
            }
        };
        if let Some(dir) = &opts.obj_dir {
            std::fs::create_dir_all(dir).map_err(|source| RecordError::Obj {
                path: dir.clone(),
                source,
            })?;
        }
        let frames = scene.simulation.frame_count();
        let SimParts {
            setup,
            state,
            pipeline,
        } = sim;
        let tally = Tally::new(&setup.model, &state.world, pipeline.stepper(), &scene.pin);
        Ok(FrameLoop {
            scene,
            setup,
            state,
            pipeline,
            recorder,
            record_path: opts.record.clone(),
            obj_dir: opts.obj_dir.clone(),
            record_every: opts.record_every.max(1),
            frames,
            frame_interval: scene.simulation.frame_interval(),
            frame: 0,
            tally,
            started: Instant::now(),
            sim_seconds: 0.0,
            record_seconds: 0.0,
            timing: FrameTiming::default(),
            recorded_frames: 0,
            last_recorded: None,
            normals: Vec::new(),
            energy_now: None,
            interrupted: false,
            failure: None,
        })
    }

    /// True when the state is at the last frame.
    pub fn at_end(&self) -> bool {
        self.frame >= self.frames
    }

    /// Progress after the frame the state is at.
    pub fn progress(&self) -> Progress {
        Progress {
            frame: self.frame + 1,
            frames: self.frames + 1,
            sim_time: self.state.world.time,
        }
    }

    /// Notes that the run was interrupted (Ctrl-C) before the next frame.
    pub fn interrupt(&mut self) {
        self.interrupted = true;
    }

    /// Advances the simulation by one frame. False when every step size tried
    /// failed: the state is back at the frame's start, and [`FrameLoop::finish`]
    /// reports the failure.
    pub fn advance(&mut self) -> Result<bool, RunError> {
        let t0 = Instant::now();
        let start_energy = self.energy_now.take();
        match self.pipeline.advance_frame_from(
            &self.setup,
            &mut self.state,
            self.frame_interval,
            start_energy,
        ) {
            Ok(_) => {}
            Err(FrameFailed::Steps(f)) => {
                self.failure = Some((self.frame + 1, f));
                return Ok(false);
            }
            Err(FrameFailed::Remesh(e)) => return Err(RunError::Remesh(e)),
        }
        self.frame += 1;
        self.timing.sim_s = t0.elapsed().as_secs_f64();
        self.sim_seconds += self.timing.sim_s;
        Ok(true)
    }

    /// Observes the frame the state is at (statistics, `observe`) and records it
    /// when it is due (every `record_every`-th frame and the last).
    pub fn record(
        &mut self,
        observe: &mut (dyn FnMut(&FrameState) + Send),
    ) -> Result<(), RunError> {
        let energy = self.energy();
        let world = &self.state.world;
        self.tally.observe(world, energy);
        observe(&FrameState {
            frame: self.frame,
            sim_time: world.time,
            positions: &world.x,
            material: &world.mesh.material,
            triangles: &world.mesh.triangles,
            pattern: &world.mesh.pattern,
        });
        if self.frame.is_multiple_of(self.record_every) || self.frame == self.frames {
            self.record_now()?;
        }
        if self.recorder.is_none() {
            // Nobody takes the events: drop them rather than let them pile up.
            self.state.adapter.as_mut().map(Adapter::take_events);
            self.state.welds.clear();
        }
        Ok(())
    }

    /// The energy of the state as it is: measured once per state, or the one
    /// the pipeline's last frame measured on it.
    fn energy(&mut self) -> Energy {
        if let Some(e) = self.energy_now {
            return e;
        }
        let e = match self.pipeline.take_frame_end_energy() {
            Some(e) => e,
            None => self
                .pipeline
                .stepper()
                .energy(&self.setup.model, &self.state.world),
        };
        self.energy_now = Some(e);
        e
    }

    /// Records the current frame and exports its OBJ.
    fn record_now(&mut self) -> Result<(), RunError> {
        let t1 = Instant::now();
        self.log_frame()?;
        if let Some(dir) = &self.obj_dir {
            let w = &self.state.world;
            write_mesh_obj(dir, self.frame, &w.x, &w.mesh)?;
        }
        self.timing.record_s = t1.elapsed().as_secs_f64();
        self.record_seconds += self.timing.record_s;
        Ok(())
    }

    /// Logs the current frame to the recording (when there is one).
    fn log_frame(&mut self) -> Result<(), RunError> {
        // `record` has measured this state already (after a failed frame,
        // `finish` comes here with the restored state and measures it once).
        let energy = self.energy();
        let Some(rec) = self.recorder.as_mut() else {
            return Ok(());
        };
        let snap = Snapshot {
            frame: self.frame,
            energy,
            timing: self.timing,
            frame_interval: self.frame_interval,
        };
        let (state, pipeline) = (&mut self.state, &mut self.pipeline);
        recording::record_state(rec, &self.setup, state, pipeline, &snap, &mut self.normals)?;
        self.recorded_frames += 1;
        self.last_recorded = Some(self.frame);
        Ok(())
    }

    /// Ends the run: records the last good frame if `record_every` left it out
    /// (a run stopped early), closes the recording and returns the summary, or
    /// [`RunError::Numerical`] (with the summary) when a frame failed.
    pub fn finish(mut self) -> Result<Summary, RunError> {
        if self.recorder.is_some() && self.last_recorded != Some(self.frame) {
            let t1 = Instant::now();
            self.log_frame()?;
            self.record_seconds += t1.elapsed().as_secs_f64();
        }
        let recording = match self.recorder.take() {
            Some(rec) => {
                let bytes = rec.finish()?;
                let frames = self.recorded_frames;
                self.record_path.take().map(|path| (path, bytes, frames))
            }
            None => None,
        };
        let summary = self.summary(recording);
        match self.failure {
            None => Ok(summary),
            Some((frame, f)) => Err(RunError::Numerical {
                step: f.step,
                failure: f.failure,
                frame,
                time: self.state.world.time,
                halvings: match self.setup.settings.step {
                    StepSize::Adaptive(_) => 0,
                    _ => MAX_STEP_HALVINGS,
                },
                dt: f.last_dt,
                cause: match self.setup.settings.step {
                    StepSize::Adaptive(_) => format!(
                        "the tolerances are tighter than any step down to `simulation.adaptive_dt.min` = {:.3e} s meets (try a smaller `min`, or a larger `simulation.adaptive_dt.tolerance` or `penetration`{})",
                        f.last_dt,
                        solver_hint(&f.failure)
                    ),
                    _ => format!(
                        "the time step is too large for the stiffness (step {:.3e} s with the {:?} integrator; try a smaller `simulation.dt`, `dt = \"auto\"`, or `integrator = \"implicit\"`{})",
                        self.pipeline.step_size(&self.setup, &self.state.world),
                        self.setup.model.integrator,
                        solver_hint(&f.failure)
                    ),
                },
                summary: Box::new(summary),
            }),
        }
    }

    fn summary(&mut self, recording: Option<(PathBuf, u64, u64)>) -> Summary {
        let (state, pipe) = (&self.state, &mut self.pipeline);
        let dt = if state.effort.min_dt.is_finite() {
            state.effort.min_dt
        } else {
            pipe.step_size(&self.setup, &state.world)
        };
        let stepper = pipe.stepper();
        let (cusick, cantilever) = super::measure::at_end(self.scene, &self.setup, &state.world);
        self.tally.finish(TallyEnd {
            scene: self.scene.name.clone(),
            frames: self.frame + 1,
            sim_time: state.world.time,
            wall_time_s: self.started.elapsed().as_secs_f64(),
            sim_wall_s: self.sim_seconds,
            record_wall_s: self.record_seconds,
            dt,
            dt_max: state.effort.max_dt.max(dt),
            adaptive_dt: matches!(self.setup.settings.step, StepSize::Adaptive(_)),
            interrupted: self.interrupted,
            recording,
            state,
            mass_final: stepper.elements.total_mass(),
            cusick,
            cantilever,
        })
    }
}

/// What else to try when the implicit solver failed.
fn solver_hint(failure: &StepFailure) -> &'static str {
    use crate::physics::SolveFailure;
    match failure {
        StepFailure::Solver(SolveFailure::NotConverged { .. }) => {
            "; or let the linear solve converge: `simulation.solver = \"direct\"`, a larger `simulation.cg_max_iterations` or `simulation.cg_tolerance`"
        }
        StepFailure::Solver(SolveFailure::NewtonNotConverged { .. }) => {
            "; or allow more `simulation.newton_iterations` or a larger `simulation.newton_tolerance`"
        }
        _ => "",
    }
}
