//! [`FrameLoop`]: a run frame by frame — advance the simulation, observe and record
//! the frame, and summarise at the end.

use std::time::Instant;

use super::outputs::{Outputs, WrittenRecording};
use super::phases::Phases;
use super::recording::FrameTiming;
use super::tally::{Tally, TallyEnd};
use super::{FrameState, Progress, RunError, RunOptions};
use crate::adapt::Adapter;
use crate::math::Scalar;
use crate::physics::Energy;
use crate::scene::Scene;
use crate::sim::{FrameFailed, FrameFailure, MAX_STEP_HALVINGS, SimParts, StepFailure, StepSize};
use crate::summary::Summary;

/// A run in progress: the simulation, its outputs and its running statistics.
/// [`FrameLoop::new`] opens the outputs; then, per frame, [`FrameLoop::record`]
/// and [`FrameLoop::advance`]; [`FrameLoop::finish`] closes the recording and makes
/// the summary.
pub struct FrameLoop<'a> {
    scene: &'a Scene,
    /// The setup, the state and the pipeline that advances it.
    sim: SimParts,
    /// The energy of the state as it is, once measured (or handed over by the
    /// pipeline) for the frame's statistics; cleared when the state advances.
    energy_now: Option<Energy>,
    /// The recording and the OBJ export.
    outputs: Outputs,
    /// Which frame the state is at, of how many.
    clock: FrameClock,
    /// Wall time spent stepping and recording.
    wall: WallClock,
    /// Running statistics for the summary.
    tally: Tally,
    /// Sewing weightless, draping, and the rest criterion.
    phases: Phases,
    /// Why the run stopped before its last frame, if it did.
    stop: Option<Stop>,
}

/// The frames of a run: the one the state is at, and how many.
struct FrameClock {
    /// The frame the state is at (0: the initial state).
    frame: u64,
    /// Frames after the initial one (fewer once the cloth is at rest).
    frames: u64,
    /// Simulated seconds between frames.
    interval: Scalar,
}

/// Wall time spent stepping and recording, s.
struct WallClock {
    /// When the run started.
    started: Instant,
    /// Stepping, over the run.
    sim_seconds: Scalar,
    /// Recording and exporting, over the run.
    record_seconds: Scalar,
    /// The last frame's stepping and the last recorded frame's recording.
    timing: FrameTiming,
}

/// Why a run stopped before its last frame.
enum Stop {
    /// Ctrl-C, before the next frame.
    Interrupted,
    /// Every step size tried for frame `frame` failed.
    Failed {
        /// The frame whose steps failed.
        frame: u64,
        /// How its last try failed.
        failure: FrameFailure,
    },
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
        let outputs = Outputs::open(scene, opts)?;
        let (model, world) = (&sim.setup.model, &sim.state.world);
        let tally = Tally::new(model, world, sim.pipeline.stepper(), &scene.pin);
        let phases = Phases::new(scene, model, world);
        Ok(FrameLoop {
            scene,
            sim,
            energy_now: None,
            outputs,
            clock: FrameClock {
                frame: 0,
                frames: scene.simulation.frame_count(),
                interval: scene.simulation.frame_interval(),
            },
            wall: WallClock {
                started: Instant::now(),
                sim_seconds: 0.0,
                record_seconds: 0.0,
                timing: FrameTiming::default(),
            },
            tally,
            phases,
            stop: None,
        })
    }

    /// True when the state is at the last frame.
    pub fn at_end(&self) -> bool {
        self.clock.frame >= self.clock.frames
    }

    /// Progress after the frame the state is at.
    pub fn progress(&self) -> Progress {
        Progress {
            frame: self.clock.frame + 1,
            frames: self.clock.frames + 1,
            sim_time: self.sim.state.world.time,
        }
    }

    /// Notes that the run was interrupted (Ctrl-C) before the next frame: the
    /// run ends there.
    pub fn interrupt(&mut self) {
        self.stop = Some(Stop::Interrupted);
    }

    /// Advances the simulation by one frame. False when every step size tried
    /// failed: the state is back at the frame's start, and [`FrameLoop::finish`]
    /// reports the failure.
    pub fn advance(&mut self) -> Result<bool, RunError> {
        let t0 = Instant::now();
        let mut start_energy = self.energy_now.take();
        let sim = &mut self.sim;
        if self
            .phases
            .before_frame(&mut sim.setup.model, &sim.state.world)
        {
            // The energy measured under the other gravity is not this frame's.
            start_energy = None;
        }
        match sim.pipeline.advance_frame_from(
            &sim.setup,
            &mut sim.state,
            self.clock.interval,
            start_energy,
        ) {
            Ok(_) => {}
            Err(FrameFailed::Steps(failure)) => {
                let frame = self.clock.frame + 1;
                self.stop = Some(Stop::Failed { frame, failure });
                return Ok(false);
            }
            Err(FrameFailed::Remesh(e)) => return Err(RunError::Remesh(e)),
        }
        self.clock.frame += 1;
        if self.phases.after_frame(&self.sim.state.world) {
            // At rest: this frame is the last, recorded and exported.
            self.clock.frames = self.clock.frame;
        }
        self.wall.timing.sim_s = t0.elapsed().as_secs_f64();
        self.wall.sim_seconds += self.wall.timing.sim_s;
        Ok(true)
    }

    /// Observes the frame the state is at (statistics, `observe`) and records it
    /// when it is due (every `record_every`-th frame and the last).
    pub fn record(
        &mut self,
        observe: &mut (dyn FnMut(&FrameState) + Send),
    ) -> Result<(), RunError> {
        let energy = self.energy();
        let world = &self.sim.state.world;
        self.tally.observe(world, energy);
        observe(&FrameState {
            frame: self.clock.frame,
            sim_time: world.time,
            positions: &world.x,
            material: &world.mesh.material,
            triangles: &world.mesh.triangles,
            pattern: &world.mesh.pattern,
        });
        if self.outputs.due(self.clock.frame, self.clock.frames) {
            self.record_now()?;
        }
        if !self.outputs.recording() {
            // Nobody takes the events: drop them rather than let them pile up.
            let state = &mut self.sim.state;
            state.adapter.as_mut().map(Adapter::take_events);
            state.welds.clear();
        }
        Ok(())
    }

    /// The energy of the state as it is: measured once per state, or the one
    /// the pipeline's last frame measured on it.
    fn energy(&mut self) -> Energy {
        if let Some(e) = self.energy_now {
            return e;
        }
        let sim = &mut self.sim;
        let e = match sim.pipeline.take_frame_end_energy() {
            Some(e) => e,
            None => sim
                .pipeline
                .stepper()
                .energy(&sim.setup.model, &sim.state.world),
        };
        self.energy_now = Some(e);
        e
    }

    /// Records the current frame and exports its OBJ.
    fn record_now(&mut self) -> Result<(), RunError> {
        let t1 = Instant::now();
        self.log_frame()?;
        self.outputs
            .export_obj(self.clock.frame, &self.sim.state.world)?;
        self.wall.timing.record_s = t1.elapsed().as_secs_f64();
        self.wall.record_seconds += self.wall.timing.record_s;
        Ok(())
    }

    /// Logs the current frame to the recording (when there is one).
    fn log_frame(&mut self) -> Result<(), RunError> {
        // `record` has measured this state already (after a failed frame,
        // `finish` comes here with the restored state and measures it once).
        let energy = self.energy();
        let (frame, timing) = (self.clock.frame, self.wall.timing);
        self.outputs
            .log(&mut self.sim, frame, energy, timing, self.clock.interval)
    }

    /// Ends the run: records the last good frame if `record_every` left it out
    /// (a run stopped early), closes the recording and returns the summary, or
    /// [`RunError::Numerical`] (with the summary) when a frame failed.
    pub fn finish(mut self) -> Result<Summary, RunError> {
        if self.outputs.lacks(self.clock.frame) {
            let t1 = Instant::now();
            self.log_frame()?;
            self.wall.record_seconds += t1.elapsed().as_secs_f64();
        }
        let recording = self.outputs.finish()?;
        let summary = self.summary(recording);
        match self.stop.take() {
            None | Some(Stop::Interrupted) => Ok(summary),
            Some(Stop::Failed { frame, failure }) => {
                Err(self.numerical_error(frame, failure, summary))
            }
        }
    }

    /// The error for frame `frame`, whose steps all failed with `f`, with the
    /// summary of the run up to it and a hint at the likely cause.
    fn numerical_error(&mut self, frame: u64, f: FrameFailure, summary: Summary) -> RunError {
        let sim = &mut self.sim;
        let adaptive = matches!(sim.setup.settings.step, StepSize::Adaptive(_));
        let cause = if adaptive {
            format!(
                "the tolerances are tighter than any step down to `simulation.adaptive_dt.min` = {:.3e} s meets (try a smaller `min`, or a larger `simulation.adaptive_dt.tolerance` or `penetration`{})",
                f.last_dt,
                solver_hint(&f.failure)
            )
        } else {
            format!(
                "the time step is too large for the stiffness (step {:.3e} s with the {:?} integrator; try a smaller `simulation.dt`, `dt = \"auto\"`, or `integrator = \"implicit\"`{})",
                sim.pipeline.step_size(&sim.setup, &sim.state.world),
                sim.setup.model.integrator,
                solver_hint(&f.failure)
            )
        };
        RunError::Numerical {
            step: f.step,
            failure: f.failure,
            frame,
            time: sim.state.world.time,
            halvings: if adaptive { 0 } else { MAX_STEP_HALVINGS },
            dt: f.last_dt,
            cause,
            summary: Box::new(summary),
        }
    }

    /// The summary of the run so far, with the recording written.
    fn summary(&mut self, recording: Option<WrittenRecording>) -> Summary {
        let (state, pipe) = (&self.sim.state, &mut self.sim.pipeline);
        let setup = &self.sim.setup;
        let dt = if state.effort.min_dt.is_finite() {
            state.effort.min_dt
        } else {
            pipe.step_size(setup, &state.world)
        };
        let stepper = pipe.stepper();
        let (cusick, cantilever) = super::measure::at_end(self.scene, setup, &state.world);
        self.tally.finish(TallyEnd {
            scene: self.scene.name.clone(),
            frames: self.clock.frame + 1,
            sim_time: state.world.time,
            wall_time_s: self.wall.started.elapsed().as_secs_f64(),
            sim_wall_s: self.wall.sim_seconds,
            record_wall_s: self.wall.record_seconds,
            dt,
            dt_max: state.effort.max_dt.max(dt),
            adaptive_dt: matches!(setup.settings.step, StepSize::Adaptive(_)),
            interrupted: matches!(self.stop, Some(Stop::Interrupted)),
            recording,
            state,
            mass_final: stepper.elements.total_mass(),
            cusick,
            cantilever,
            rest: self.phases.summary(),
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
        StepFailure::Solver(SolveFailure::QuasiNewtonNotConverged { .. }) => {
            "; or a larger `simulation.newton_tolerance`"
        }
        StepFailure::Solver(SolveFailure::NewtonNotConverged { .. }) => {
            "; or allow more `simulation.newton_iterations` or a larger `simulation.newton_tolerance`"
        }
        _ => "",
    }
}
