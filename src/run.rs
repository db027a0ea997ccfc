//! Running a scene: build the simulation ([`crate::sim::build`]), then frame by
//! frame ([`FrameLoop`]) advance it ([`crate::sim::Pipeline::advance_frame`]: the
//! step's phases are listed in [`crate::sim`]), observe and record it, and
//! summarise at the end.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

mod frame_loop;
mod measure;
mod outputs;
mod phases;
mod recording;
mod tally;

pub use frame_loop::FrameLoop;

pub use crate::sim::{
    ENERGY_GAIN_TOLERANCE, EXPLOSION_FACTOR, MAX_ENERGY_HALVINGS, MAX_STEP_HALVINGS, StepFailure,
};

use crate::math::{Scalar, Vector};
use crate::record::{ColourBy, DecisionData, EdgeDisplay, LiveViewer, RecordError};
use crate::scene::Scene;
use crate::sim::{SimBuildError, SimParts};
use crate::summary::Summary;
use crate::world::BuildError;

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
    /// What the triangles of `cloth/mesh` are coloured by: refinement level (the default)
    /// or garment panel, or the refinement decisions' ratio or state.
    pub colour_by: ColourBy,
    /// Whether the recording holds each triangle's refinement decision (recorded by
    /// default; `--no-decisions`).
    pub decisions: DecisionData,
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
    /// The scene could not become a simulation: its cloth, pins, obstacles or
    /// adaptive method.
    #[error(transparent)]
    Build(#[from] SimBuildError),
    /// A measurement the scene asks for (`measure`) cannot be made on its cloth.
    #[error("key `measure`: the {measurement} measurement {why}")]
    Measurement {
        /// The measurement.
        measurement: crate::scene::Measurement,
        /// What it needs that the cloth lacks.
        why: &'static str,
    },
    /// Recording failed.
    #[error("recording: {0}")]
    Record(#[from] RecordError),
    /// Remeshing produced an invalid mesh (a bug: please report it).
    #[error("adaptive remeshing: {0}")]
    Remesh(#[from] crate::mesh::MeshError),
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
        "numerical failure at step {step} in frame {frame} (t = {time:.4} s): {failure}{}; the run stopped and the recording holds every frame up to the last good one. Likely cause: {cause}",
        tried(*halvings, *dt)
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
        /// Halvings tried (0 with `dt = "adaptive"`, whose steps shrink
        /// by error control instead).
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
    /// Where the triangles' corners lie in material space (a garment's panels).
    pub pattern: &'a crate::mesh::Pattern,
}

impl From<BuildError> for RunError {
    /// The cloth or its pins could not be built (for callers that build a world
    /// from the scene themselves).
    fn from(e: BuildError) -> RunError {
        RunError::Build(SimBuildError::Build(e))
    }
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
    let sim = crate::sim::build(&scene.resolve()?)?;
    run_built(scene, sim, opts, interrupt, progress, observe)
}

/// [`run_observed`] from a simulation already built from `scene` (by
/// [`crate::sim::build`], which is where a scene's cloth and obstacles are
/// validated: `drape run` builds it before opening any output).
pub fn run_built(
    scene: &Scene,
    sim: SimParts,
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
    pool.install(|| {
        let mut frames = FrameLoop::new(scene, sim, opts)?;
        loop {
            frames.record(observe)?;
            progress(frames.progress());
            if frames.at_end() {
                break;
            }
            if interrupt.load(Ordering::Relaxed) {
                frames.interrupt();
                break;
            }
            if !frames.advance()? {
                break;
            }
        }
        frames.finish()
    })
}

/// What a failed frame tried, in words: " even with the step halved N times
/// to DT s", or nothing when it was not halved (an adaptive step).
fn tried(halvings: u32, dt: Scalar) -> String {
    if halvings == 0 {
        String::new()
    } else {
        format!(" even with the step halved {halvings} times to {dt:.3e} s")
    }
}
