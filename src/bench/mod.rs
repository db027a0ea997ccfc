//! Speed against error (`docs/bench.md`): `drape bench` runs a ladder of
//! uniform and adaptive settings on a scene without recording, measures each
//! run's wall time and vertex counts and its error against a cached fine
//! reference, and writes a CSV, a short Markdown report and an SVG chart.
//!
//! ```text
//! plan:    scene + ladder -> runs (reference, rungs, floors) -> jobs -> DIR
//! run:     each job is `drape run ... --sample-at points.json --samples-out out/J.json`
//! collect: DIR/out/*.json -> errors against the reference, median wall times,
//!          Pareto front -> STEM.csv, STEM-frames.csv, STEM.md, STEM.svg
//! ```
//!
//! Every run is a job that needs nothing but the bench directory and a
//! `drape` binary, so a ladder can run in-process ([`bench`]: plan, every job
//! in turn, collect), from `DIR/jobs.txt` with GNU parallel or `xargs -P`, or
//! as a Slurm array on a cluster, and be collected the same way. The jobs of
//! one run are its repetitions; the first repetition's samples are compared,
//! every repetition's wall time counts (the median is reported).
//!
//! The error metric ([`metric`]) samples fixed material points through the
//! material coordinates, so a uniform and an adapted mesh are compared at the
//! same cloth points. The spatial ladder runs every rung and the reference at
//! one step (the error is the mesh's); the time-step ladder keeps one mesh
//! and varies the step. A floor is an ordinary run marked as such (the
//! reference lifted 1 um, or a ladder rung with `floor = true`): its error is
//! the comparison's resolution, not a candidate.

pub mod chart;
pub mod collect;
mod garment;
pub mod ladder;
pub mod metric;
pub mod plan;
pub mod report;
pub mod sampling;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use crate::run::{RunError, RunOptions};
use crate::scene::{SceneError, load_scene_file};
pub use collect::{BenchResult, Row, collect, median};
pub use ladder::{Compare, Ladder, Rung, StepPolicy};
pub use plan::{Job, Plan, make_plan, write_plan};
pub use sampling::{SamplePoints, Samples};

/// Why a benchmark failed.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A scene (with a run's overrides) is invalid.
    #[error("{context}: {source}")]
    Scene {
        /// Which run.
        context: String,
        /// The scene error.
        source: Box<SceneError>,
    },
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// A plan or samples file is malformed.
    #[error("{}: {message}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The ladder file is malformed.
    #[error("ladder {}: {message}", path.display())]
    Ladder {
        /// The ladder file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// `--rungs` named a rung the ladder does not have.
    #[error("no rung labelled `{label}` in the ladder (rungs: {known})")]
    UnknownRung {
        /// The label asked for.
        label: String,
        /// The ladder's labels.
        known: String,
    },
    /// The plan cannot be made as asked.
    #[error("{0}")]
    Plan(String),
    /// A run could not start or failed for a reason other than numerics.
    #[error("{0}")]
    Run(#[from] RunError),
    /// The reference run failed numerically.
    #[error("the reference run failed ({0}); give it a smaller step with the ladder's `reference`")]
    Reference(String),
    /// Jobs without a usable output, each named.
    #[error("{} job(s) without a usable output:\n  {}", .0.len(), .0.join("\n  "))]
    Jobs(Vec<String>),
    /// The user interrupted the benchmark.
    #[error("interrupted")]
    Interrupted,
    /// The chart could not be drawn.
    #[error("drawing the chart: {0}")]
    Chart(String),
}

impl BenchError {
    /// An I/O error at `path`.
    pub fn io(path: &Path, source: std::io::Error) -> BenchError {
        BenchError::Io {
            path: path.to_path_buf(),
            source,
        }
    }
}

/// What to benchmark and how.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// The user's `--set` overrides, applied to every run and the reference.
    pub overrides: Vec<String>,
    /// The runs (`None`: [`ladder::default_ladder`], or the time-step ladder).
    pub ladder: Option<Ladder>,
    /// Run the time-step ladder ([`ladder::time_ladder`]) instead of `ladder`.
    pub time_ladder: bool,
    /// Only these rungs of the ladder (empty: all).
    pub rungs: Vec<String>,
    /// What the error compares (`None`: the ladder's `compare`, else frame by frame).
    pub compare: Option<Compare>,
    /// Which step the runs take (`None`: the ladder's `step`, else common).
    pub step: Option<StepPolicy>,
    /// Repetitions of each run; the median wall time is reported.
    pub reps: usize,
    /// Simulated time of every run (`None`: the scene's duration).
    pub duration: Option<f64>,
    /// Worker threads of every job (`None`: one per core).
    pub threads: Option<usize>,
    /// Use (and write) the cached reference in `DIR/cache/`.
    pub cache: bool,
    /// Reference resolution (`None`: 1.5 times the finest rung's, rounded up
    /// to even, or the ladder's own `reference`; with one, its `cloth.resolution`).
    pub reference_resolution: Option<u32>,
    /// Sample points per side of the material-space grid.
    pub grid: usize,
    /// Add the lift floor: the reference started 1 um higher.
    pub floor: bool,
}

/// Runs every job of the plan in `dir` in this process, one after another,
/// reporting progress through `log`.
pub fn run_jobs(
    dir: &Path,
    plan: &Plan,
    interrupt: &AtomicBool,
    log: &mut dyn FnMut(&str),
) -> Result<(), BenchError> {
    let points = SamplePoints::load(&dir.join(plan::POINTS_FILE))?;
    let opts = RunOptions {
        threads: plan.threads,
        ..RunOptions::default()
    };
    let n = plan.jobs.len();
    for (i, job) in plan.jobs.iter().enumerate() {
        if interrupt.load(Ordering::Relaxed) {
            return Err(BenchError::Interrupted);
        }
        let run = plan.run_of(job);
        let scene = load_scene_file(&dir.join(&plan.scene_file), &run.set).map_err(|e| {
            BenchError::Scene {
                context: run.label.clone(),
                source: Box::new(e),
            }
        })?;
        let s = sampling::sampled_run(&scene, &run.set, &opts, &points, interrupt)?;
        if interrupt.load(Ordering::Relaxed) {
            return Err(BenchError::Interrupted);
        }
        if let (None, Some(f)) = (job.run, &s.failure) {
            return Err(BenchError::Reference(f.clone()));
        }
        s.store(&dir.join(&job.output))?;
        let status = s.failure.as_deref().unwrap_or("ok");
        log(&format!(
            "[{}/{n}] {}, repetition {}: {status}, {:.2} s, {:.0} vertices",
            i + 1,
            run.label,
            job.rep,
            s.wall_s,
            s.mean_vertices
        ));
    }
    Ok(())
}

/// Plans `opts` into `dir`, runs every job in this process and collects:
/// `drape bench SCENE`. Writes the result files into `dir`.
pub fn bench(
    opts: &BenchOptions,
    dir: &Path,
    interrupt: &AtomicBool,
    log: &mut dyn FnMut(&str),
) -> Result<(BenchResult, Vec<PathBuf>), BenchError> {
    let (plan, points) = make_plan(opts)?;
    bench_planned(opts, (plan, &points), dir, interrupt, log)
}

/// [`bench`] of a plan already made from `opts` by [`make_plan`] (with its
/// sample points): writes it into `dir`, runs every job and collects.
pub fn bench_planned(
    opts: &BenchOptions,
    (plan, points): (Plan, &SamplePoints),
    dir: &Path,
    interrupt: &AtomicBool,
    log: &mut dyn FnMut(&str),
) -> Result<(BenchResult, Vec<PathBuf>), BenchError> {
    let plan = write_plan(plan, points, &opts.scene, dir, opts.cache)?;
    if let Some((dt, origin)) = &plan.common_dt {
        log(&format!("time step: {dt:.4e} s ({origin}) for every run"));
    }
    if plan.jobs.first().is_some_and(|j| j.run.is_some()) {
        log(&format!("reference: cached {}", plan.reference_output));
    }
    run_jobs(dir, &plan, interrupt, log)?;
    let result = collect(dir)?;
    let files = report::write_all(dir, &result)?;
    Ok((result, files))
}
