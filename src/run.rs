//! Running a scene: build the world, step it frame by frame, record every frame,
//! and summarise. The step is a short list of named phases:
//! forces + integrate (the stepper), health check, record.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

mod pipeline;
mod recording;
mod tally;

use pipeline::{EnergyBound, Pipeline};
use tally::{Tally, TallyEnd};

use crate::adapt::{AdaptConfig, Adapter};
use crate::collide::{CollideError, Collider, CollisionStats};
use crate::math::{Scalar, Vector};
use crate::physics::{Model, Stepper};
use crate::record::{
    EdgeDisplay, LiveViewer, RecordError, RecordTarget, Recorder, obj::write_frame_obj,
};
use crate::scene::{Scene, TimeStep};
use crate::summary::Summary;
use crate::world::{BuildError, World};

/// How often a failing frame is retried with half the step before giving up.
pub const MAX_STEP_HALVINGS: u32 = 4;

/// A frame whose energy minus external work rose by more than this share of the
/// run's energy scale ([`EnergyBound`]) is retried with halved steps: large steps
/// through an impact (one vertex stopped, its neighbours still moving) stretch the
/// springs and create energy that smaller steps do not (a tablecloth at 4 ms steps
/// gained 1.48 J, at 1 ms none).
pub const ENERGY_GAIN_TOLERANCE: Scalar = 0.01;

/// The most halvings spent on an energy gain (the frame is then accepted).
pub const MAX_ENERGY_HALVINGS: u32 = 3;

/// A step "explodes" when the cloth's kinetic plus gravitational energy exceeds the
/// physical bound (initial energy plus the work of wind, pins and moving obstacles)
/// by this many times the run's energy scale ([`EnergyBound`]): far beyond any
/// discretisation error, only an instability gets there.
pub const EXPLOSION_FACTOR: Scalar = 1.0;

/// Why a step was rejected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepFailure {
    /// A position became NaN or infinite.
    NonFinite,
    /// The implicit step's equations could not be solved.
    Solver(crate::physics::SolveFailure),
    /// The energy exceeded its bound by [`EXPLOSION_FACTOR`] energy scales.
    Explosion {
        /// Kinetic plus gravitational energy after the step, J.
        energy: Scalar,
        /// The bound it exceeded, J.
        bound: Scalar,
    },
}

impl std::fmt::Display for StepFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StepFailure::NonFinite => write!(f, "positions became NaN or infinite"),
            StepFailure::Solver(why) => write!(f, "{why}"),
            StepFailure::Explosion { energy, bound } => write!(
                f,
                "the energy exploded (kinetic + gravitational {energy:.4e} J, above the explosion limit {bound:.4e} J)"
            ),
        }
    }
}

/// What to produce besides the simulation itself.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Write the recording here (`None`: no recording).
    pub record: Option<PathBuf>,
    /// Write each recorded frame as an OBJ into this directory.
    pub obj_dir: Option<PathBuf>,
    /// Worker threads (`None`: rayon's default, one per core).
    pub threads: Option<usize>,
    /// Also stream the recording to a live viewer (with or without a file).
    pub live: Option<LiveViewer>,
    /// Record (and export OBJ for) every K-th frame only; 0 and 1 both mean every frame.
    /// Frame 0 and the last frame are always recorded, and so is the last good frame of a run
    /// stopped early; events of the frames left out go with the next recorded frame.
    pub record_every: u64,
    /// Which edges `cloth/edges` shows; [`EdgeDisplay::Review`] (the default) is resolved
    /// against the scene's refine threshold.
    pub edges: EdgeDisplay,
}

/// Progress report after each frame.
#[derive(Debug, Clone, Copy)]
pub struct Progress {
    /// Frames done (including the initial frame).
    pub frame: u64,
    /// Frames in the whole run.
    pub frames: u64,
    /// Simulated time, s.
    pub sim_time: Scalar,
}

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The scene could not become a world.
    #[error("{0}")]
    Build(#[from] BuildError),
    /// Recording failed.
    #[error("recording: {0}")]
    Record(#[from] RecordError),
    /// The scene's obstacles could not be built.
    #[error("{0}")]
    Collide(#[from] CollideError),
    /// Remeshing produced an invalid mesh (a bug: please report it).
    #[error("adaptive remeshing: {0}")]
    Remesh(#[from] crate::mesh::MeshError),
    /// Internal: every step size tried in a frame failed (becomes `Numerical`).
    #[error("all step sizes failed, down to {last_dt:.3e} s: {failure}")]
    StepFailed {
        /// The last step tried.
        last_dt: Scalar,
        /// What went wrong with it.
        failure: StepFailure,
        /// The step (counted from the start of the run) that failed.
        step: u64,
    },
    /// The thread pool could not be created.
    #[error("cannot start {threads} worker threads: {reason}")]
    Threads {
        /// Requested threads.
        threads: usize,
        /// Why.
        reason: String,
    },
    /// The state became non-finite even with the smallest step tried.
    #[error(
        "numerical failure at step {step} in frame {frame} (t = {time:.4} s): {failure} even with the step halved {halvings} times to {dt:.3e} s; the run stopped and the recording holds every frame up to the last good one. Likely cause: the time step is too large for the stiffness ({cause})"
    )]
    Numerical {
        /// The step (counted from the start of the run) that failed.
        step: u64,
        /// What went wrong.
        failure: StepFailure,
        /// Frame whose steps failed.
        frame: u64,
        /// Simulated time at the start of that frame.
        time: Scalar,
        /// Halvings tried.
        halvings: u32,
        /// The last step size tried.
        dt: Scalar,
        /// A hint naming the likely cause.
        cause: String,
        /// What the run produced up to the failure.
        summary: Box<Summary>,
    },
}

/// The cloth's state at a frame, handed to the observer of [`run_observed`]
/// (the benchmark samples its error metric from it).
#[derive(Debug, Clone, Copy)]
pub struct FrameState<'a> {
    /// Frame index (0 is the initial state).
    pub frame: u64,
    /// Simulated time, s.
    pub sim_time: Scalar,
    /// World positions, m.
    pub positions: &'a [Vector],
    /// Material (rest) coordinates of the same vertices, m.
    pub material: &'a [crate::math::Vector2],
    /// Triangles (vertex indices).
    pub triangles: &'a [[u32; 3]],
}

/// Runs `scene` to the end (or until `interrupt` is set), calling `progress`
/// after every frame.
pub fn run(
    scene: &Scene,
    opts: &RunOptions,
    interrupt: &AtomicBool,
    progress: &mut (dyn FnMut(Progress) + Send),
) -> Result<Summary, RunError> {
    run_observed(scene, opts, interrupt, progress, &mut |_| {})
}

/// [`run`], also handing every frame's state (after the step, before it is
/// recorded) to `observe`.
pub fn run_observed(
    scene: &Scene,
    opts: &RunOptions,
    interrupt: &AtomicBool,
    progress: &mut (dyn FnMut(Progress) + Send),
    observe: &mut (dyn FnMut(&FrameState) + Send),
) -> Result<Summary, RunError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .build()
        .map_err(|e| RunError::Threads {
            threads: opts.threads.unwrap_or(0),
            reason: e.to_string(),
        })?;
    pool.install(|| run_in_pool(scene, opts, interrupt, progress, observe))
}

fn run_in_pool(
    scene: &Scene,
    opts: &RunOptions,
    interrupt: &AtomicBool,
    progress: &mut (dyn FnMut(Progress) + Send),
    observe: &mut (dyn FnMut(&FrameState) + Send),
) -> Result<Summary, RunError> {
    // Open the output first: an unwritable path fails before any simulation.
    let mut recorder = match (&opts.record, &opts.live) {
        (None, None) => None,
        (file, live) => {
            let target = RecordTarget {
                file: file.clone(),
                live: live.clone(),
            };
            let refine = scene.adapt.as_ref().map(|a| a.refine_angle);
            Some(Recorder::open(
                &target,
                &scene.name,
                opts.edges.resolve(refine),
            )?)
        }
    };
    let every = opts.record_every.max(1);
    if let Some(dir) = &opts.obj_dir {
        std::fs::create_dir_all(dir).map_err(|source| RecordError::Obj {
            path: dir.clone(),
            source,
        })?;
    }
    let mut world = World::from_scene(scene)?;
    let model = Model::from_scene(scene);
    let mut stepper = Stepper::new(model, &world);
    stepper.multirate = scene.adapt.as_ref().is_some_and(|a| a.multirate);
    let adapter = AdaptConfig::from_scene(scene.adapt.as_ref())
        .map(|c| Adapter::new(c, &world, scene.material.density));
    let collider = Collider::from_scene(scene)?;
    let mut pipe = Pipeline {
        stepper,
        adapter,
        steps_done: 0,
        collider,
        collision: CollisionStats::default(),
        fixed_dt: match scene.simulation.dt {
            TimeStep::Fixed(dt) => Some(dt),
            TimeStep::Auto => None,
        },
        auto_dt: None,
        min_dt: Scalar::INFINITY,
        external_work: 0.0,
        air_power: None,
        bound: EnergyBound {
            initial: 0.0,
            scale: 0.0,
        },
        failure: StepFailure::NonFinite,
        excess_max: 0.0,
        energy_retries: 0,
    };
    pipe.bound = EnergyBound::new(&world, &pipe.stepper);
    let frame_interval = 1.0 / scene.simulation.frame_rate;
    let frames = (scene.simulation.duration * scene.simulation.frame_rate)
        .round()
        .max(1.0) as u64;

    let mut tally = Tally::new(&world, &pipe.stepper);
    let started = Instant::now();
    let mut sim_seconds = 0.0;
    let mut record_seconds = 0.0;
    let mut nan_recoveries = 0u64;
    let mut frames_done = 0u64;
    let mut interrupted = false;
    let mut normals = Vec::new();
    let mut failure = None;
    // Wall time of the last frame's stepping and of the last recorded frame's recording.
    let mut timing = recording::FrameTiming::default();
    let mut recorded_frames = 0u64;
    let mut last_recorded = None;
    for frame in 0..=frames {
        if frame > 0 {
            if interrupt.load(Ordering::Relaxed) {
                interrupted = true;
                break;
            }
            let t0 = Instant::now();
            match pipe.advance_frame(&mut world, frame_interval) {
                Ok(recoveries) => nan_recoveries += recoveries,
                Err(RunError::StepFailed {
                    last_dt,
                    failure: what,
                    step,
                }) => {
                    failure = Some((frame, last_dt, what, step));
                    break;
                }
                Err(e) => return Err(e),
            }
            timing.sim_s = t0.elapsed().as_secs_f64();
            sim_seconds += timing.sim_s;
        }
        let energy = pipe.stepper.energy(&world);
        tally.observe(&world, energy);
        observe(&FrameState {
            frame,
            sim_time: world.time,
            positions: &world.x,
            material: &world.mesh.material,
            triangles: &world.mesh.triangles,
        });
        let t1 = Instant::now();
        let record_now = frame % every == 0 || frame == frames;
        if record_now {
            if let Some(rec) = recorder.as_mut() {
                let view = recording::Snapshot {
                    frame,
                    energy,
                    timing,
                };
                recording::record_state(rec, &world, &mut pipe, &view, &mut normals)?;
                recorded_frames += 1;
                last_recorded = Some(frame);
            }
            if let Some(dir) = &opts.obj_dir {
                write_frame_obj(
                    dir,
                    frame,
                    &world.x,
                    &world.mesh.material,
                    &world.mesh.triangles,
                )?;
            }
            timing.record_s = t1.elapsed().as_secs_f64();
            record_seconds += timing.record_s;
        }
        if recorder.is_none() {
            // Nobody takes the events: drop them rather than let them pile up.
            pipe.adapter.as_mut().map(Adapter::take_events);
        }
        frames_done = frame + 1;
        progress(Progress {
            frame: frames_done,
            frames: frames + 1,
            sim_time: world.time,
        });
    }
    // A run stopped early (Ctrl-C, numerical failure) after frames left out by
    // `record_every`: record the last good state too, with the pending events.
    if let Some(rec) = recorder.as_mut()
        && let Some(last) = frames_done.checked_sub(1)
        && last_recorded != Some(last)
    {
        let t1 = Instant::now();
        let energy = pipe.stepper.energy(&world);
        let view = recording::Snapshot {
            frame: last,
            energy,
            timing,
        };
        recording::record_state(rec, &world, &mut pipe, &view, &mut normals)?;
        recorded_frames += 1;
        record_seconds += t1.elapsed().as_secs_f64();
    }
    let recording = match recorder {
        Some(rec) => {
            let bytes = rec.finish()?;
            opts.record
                .clone()
                .map(|path| (path, bytes, recorded_frames))
        }
        None => None,
    };
    let summary = tally.finish(TallyEnd {
        scene: scene.name.clone(),
        frames: frames_done,
        steps: pipe.stepper.stats.steps,
        sim_time: world.time,
        wall_time_s: started.elapsed().as_secs_f64(),
        sim_wall_s: sim_seconds,
        record_wall_s: record_seconds,
        dt: if pipe.min_dt.is_finite() {
            pipe.min_dt
        } else {
            pipe.step_size(&world)
        },
        nan_recoveries,
        interrupted,
        recording,
        stepper: &pipe.stepper,
        adapt: pipe.adapter.as_ref().map(|a| a.stats),
        collision: pipe.collision,
        cusick: pipe.collider.as_ref().and_then(|c| c.cusick(scene, &world)),
        cantilever: crate::cantilever::for_run(scene, &world, &pipe.stepper.model.material),
        external_work: pipe.work(),
        excess_max: pipe.excess_max,
        energy_retries: pipe.energy_retries,
    });
    match failure {
        None => Ok(summary),
        Some((frame, last_dt, what, step)) => Err(RunError::Numerical {
            step,
            failure: what,
            frame,
            time: world.time,
            halvings: MAX_STEP_HALVINGS,
            dt: last_dt,
            cause: format!(
                "step {:.3e} s with the {:?} integrator; try a smaller `simulation.dt`, `dt = \"auto\"`, or `integrator = \"implicit\"`{}",
                pipe.step_size(&world),
                pipe.stepper.model.integrator,
                solver_hint(&what)
            ),
            summary: Box::new(summary),
        }),
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
