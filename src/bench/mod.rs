//! Speed against error (SPEC section 8): `drape bench` runs a ladder of uniform
//! and adaptive settings on a scene without recording, measures each run's
//! wall time, vertex counts and error against a cached fine reference, and
//! writes a CSV, a Markdown table and an SVG chart.
//!
//! ```text
//! ladder (rungs = --set lists) -> reference (cached) -> each rung: sampled run,
//! errors per frame, median wall time over reps -> Pareto front -> CSV, MD, SVG
//! ```

pub mod chart;
pub mod ladder;
pub mod metric;
pub mod pareto;
pub mod reference;
pub mod replot;
pub mod report;
pub mod sampling;

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use crate::math::Scalar;
use crate::run::{RunError, RunOptions, run};
use crate::scene::{AdaptMethod, Integrator, Scene, SceneError, TimeStep, load_scene_file};
pub use ladder::{Ladder, Rung};
pub use reference::Reference;

/// Why a benchmark failed.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A scene (with a rung's or the reference's overrides) is invalid.
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
    /// A run could not start or failed for a reason other than numerics.
    #[error("{0}")]
    Run(#[from] RunError),
    /// The reference run failed numerically.
    #[error("the reference run failed ({0}); give it a smaller step with the ladder's `reference`")]
    Reference(String),
    /// The user interrupted the benchmark.
    #[error("interrupted")]
    Interrupted,
}

/// What to benchmark and how.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// The user's `--set` overrides, applied to every run and the reference.
    pub overrides: Vec<String>,
    /// The runs (`None`: [`ladder::default_ladder`]).
    pub ladder: Option<Ladder>,
    /// Only these rungs of the ladder (empty: all).
    pub rungs: Vec<String>,
    /// Repetitions of each rung; the median wall time is reported.
    pub reps: usize,
    /// Simulated time of every run (`None`: the scene's duration).
    pub duration: Option<Scalar>,
    /// Worker threads (`None`: one per core).
    pub threads: Option<usize>,
    /// Output directory (files `SCENE.csv`, `SCENE.md`, `SCENE.svg`, `cache/`).
    pub out_dir: PathBuf,
    /// Use (and write) the cached reference.
    pub cache: bool,
    /// Reference resolution (`None`: 1.5 times the finest rung's, rounded up to even).
    pub reference_resolution: Option<u32>,
    /// Sample points per side of the material-space grid.
    pub grid: usize,
}

/// One rung's result: its settings and measurements.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The rung's label.
    pub label: String,
    /// The rung's overrides.
    pub set: Vec<String>,
    /// True for an adaptive run.
    pub adaptive: bool,
    /// Remeshing method (`none` for uniform).
    pub method: String,
    /// Segments along the longer side (the adaptive base mesh).
    pub resolution: u32,
    /// The uniform resolution matching the finest reachable edges.
    pub finest_resolution: u32,
    /// Finest level (0 for uniform).
    pub max_level: u32,
    /// Refinement threshold, deg (`NaN` for uniform).
    pub refine_angle: Scalar,
    /// Coarsening threshold, deg (`NaN` for uniform).
    pub coarsen_angle: Scalar,
    /// Integrator name.
    pub integrator: String,
    /// Multirate stepping on.
    pub multirate: bool,
    /// The scene's step setting (`auto` or seconds).
    pub dt: String,
    /// `ok`, or why the run failed.
    pub status: String,
    /// Repetitions timed.
    pub reps: usize,
    /// Median wall time (without the error sampling), s.
    pub wall_s: Scalar,
    /// Steps taken.
    pub steps: u64,
    /// Mean vertices over the recorded frames.
    pub mean_vertices: Scalar,
    /// Peak vertices.
    pub peak_vertices: Scalar,
    /// Mean error over the recorded frames (relative to the diagonal; `NaN` if failed).
    pub mean_error: Scalar,
    /// Error at the last frame (`NaN` if failed).
    pub final_error: Scalar,
    /// `(time, error)` at every recorded frame.
    pub errors: Vec<(Scalar, Scalar)>,
    /// On the Pareto front of (wall time, mean error).
    pub pareto: bool,
}

/// A finished benchmark.
#[derive(Debug, Clone)]
pub struct BenchResult {
    /// The scene's name.
    pub scene: String,
    /// One row per rung, in ladder order.
    pub rows: Vec<Row>,
    /// The reference.
    pub reference: Reference,
    /// True when the reference came from the cache.
    pub cache_hit: bool,
    /// Simulated time of the runs, s.
    pub duration: Scalar,
    /// The files written.
    pub files: Vec<PathBuf>,
}

fn load(path: &Path, overrides: &[String], context: &str) -> Result<Scene, BenchError> {
    load_scene_file(path, overrides).map_err(|source| BenchError::Scene {
        context: context.to_owned(),
        source: Box::new(source),
    })
}

/// Runs the benchmark, reporting progress lines through `log`.
pub fn bench(
    opts: &BenchOptions,
    interrupt: &AtomicBool,
    log: &mut dyn FnMut(&str),
) -> Result<BenchResult, BenchError> {
    let mut base_set = opts.overrides.clone();
    if let Some(d) = opts.duration {
        base_set.push(format!("simulation.duration={d:e}"));
    }
    let base = load(&opts.scene, &base_set, "scene")?;
    let mut ladder = opts
        .ladder
        .clone()
        .unwrap_or_else(|| ladder::default_ladder(&base));
    if !opts.rungs.is_empty() {
        ladder.select(&opts.rungs)?;
    }
    // Resolve every rung first: a bad override fails before any run.
    let mut scenes = Vec::new();
    for r in &ladder.rung {
        let set: Vec<String> = base_set.iter().chain(&r.set).cloned().collect();
        scenes.push(load(&opts.scene, &set, &format!("rung `{}`", r.label))?);
    }
    let finest = scenes
        .iter()
        .map(ladder::finest_resolution)
        .max()
        .unwrap_or(0);
    let ref_res = opts
        .reference_resolution
        .unwrap_or_else(|| (finest * 3).div_ceil(2).next_multiple_of(2));
    let ref_own = ladder
        .reference
        .clone()
        .unwrap_or_else(|| ladder::reference_overrides(&base, ref_res));
    let ref_set: Vec<String> = base_set.iter().chain(&ref_own).cloned().collect();
    let ref_scene = load(&opts.scene, &ref_set, "reference")?;
    let scene_text = std::fs::read_to_string(&opts.scene).map_err(|source| BenchError::Io {
        path: opts.scene.clone(),
        source,
    })?;
    let key = reference::cache_key(&scene_text, &ref_set, opts.grid);
    let cache_file = reference::cache_path(&opts.out_dir, &base.name, &key);
    let run_opts = RunOptions {
        threads: opts.threads,
        ..RunOptions::default()
    };
    let cached = if opts.cache {
        reference::load_cached(&cache_file, &key)
    } else {
        None
    };
    let cache_hit = cached.is_some();
    let reference = match cached {
        Some(r) => {
            log(&format!("reference: cached {}", cache_file.display()));
            r
        }
        None => {
            log(&format!("reference: computing ({})", ref_own.join(" ")));
            let r = reference::compute(&ref_scene, ref_set, key, opts.grid, &run_opts, interrupt)?;
            log(&format!(
                "reference: {} vertices, {} steps, {:.1} s",
                r.vertices, r.steps, r.wall_s
            ));
            if opts.cache {
                reference::store(&cache_file, &r)?;
            }
            r
        }
    };
    let points = reference.sample_points();
    let mut rows = Vec::new();
    for (i, (r, scene)) in ladder.rung.iter().zip(&scenes).enumerate() {
        log(&format!("[{}/{}] {}", i + 1, scenes.len(), r.label));
        let row = measure(r, scene, &reference, &points, opts, &run_opts, interrupt)?;
        log(&format!(
            "[{}/{}] {}: {} wall {:.2} s, {:.0} vertices (peak {:.0}), mean error {:.3e}",
            i + 1,
            scenes.len(),
            r.label,
            row.status,
            row.wall_s,
            row.mean_vertices,
            row.peak_vertices,
            row.mean_error
        ));
        rows.push(row);
    }
    let front = pareto::pareto_front(
        &rows
            .iter()
            .map(|r| (r.wall_s, r.mean_error))
            .collect::<Vec<_>>(),
    );
    for (row, on) in rows.iter_mut().zip(front) {
        row.pareto = on;
    }
    let mut result = BenchResult {
        scene: base.name.clone(),
        rows,
        reference,
        cache_hit,
        duration: base.simulation.duration,
        files: Vec::new(),
    };
    result.files = report::write_all(&opts.out_dir, &result, &opts.scene)?;
    Ok(result)
}

fn measure(
    rung: &Rung,
    scene: &Scene,
    reference: &Reference,
    points: &[crate::math::Vector2],
    opts: &BenchOptions,
    run_opts: &RunOptions,
    interrupt: &AtomicBool,
) -> Result<Row, BenchError> {
    let first = sampling::sampled_run(scene, run_opts, points, interrupt)?;
    if first.summary.interrupted {
        return Err(BenchError::Interrupted);
    }
    let mut walls = vec![first.summary.wall_time_s - first.sampling_s];
    if first.failure.is_none() {
        for _ in 1..opts.reps.max(1) {
            let s = run(scene, run_opts, interrupt, &mut |_| {})?;
            if s.interrupted {
                return Err(BenchError::Interrupted);
            }
            walls.push(s.wall_time_s);
        }
    }
    let errors = sampling::run_errors(&first.frames, &reference.frames, reference.diagonal);
    let complete = first.failure.is_none() && errors.len() == first.frames.len();
    let (mean_error, final_error) = if complete && !errors.is_empty() {
        let mean = errors.iter().map(|e| e.1).sum::<Scalar>() / errors.len() as Scalar;
        (mean, errors.last().map_or(Scalar::NAN, |e| e.1))
    } else {
        (Scalar::NAN, Scalar::NAN)
    };
    let status = match (&first.failure, complete) {
        (Some(f), _) => format!("failed: {f}"),
        (None, false) => "failed: frames do not match the reference's".to_owned(),
        (None, true) => "ok".to_owned(),
    };
    let adapt = scene
        .adapt
        .as_ref()
        .filter(|a| a.method != AdaptMethod::None);
    Ok(Row {
        label: rung.label.clone(),
        set: rung.set.clone(),
        adaptive: adapt.is_some(),
        method: adapt
            .map_or("none", |a| match a.method {
                AdaptMethod::RedGreen => "red_green",
                AdaptMethod::Edge => "edge",
                AdaptMethod::None => "none",
            })
            .to_owned(),
        resolution: scene.cloth.resolution.unwrap_or(0),
        finest_resolution: ladder::finest_resolution(scene),
        max_level: adapt.map_or(0, |a| a.max_level),
        refine_angle: adapt.map_or(Scalar::NAN, |a| a.refine_angle),
        coarsen_angle: adapt.map_or(Scalar::NAN, |a| a.coarsen_angle),
        integrator: integrator_name(scene.simulation.integrator).to_owned(),
        multirate: adapt.is_some_and(|a| a.multirate),
        dt: match scene.simulation.dt {
            TimeStep::Auto => "auto".into(),
            TimeStep::Fixed(dt) => format!("{dt}"),
        },
        status,
        reps: walls.len(),
        wall_s: median(&mut walls),
        steps: first.summary.steps,
        mean_vertices: first.summary.vertices.mean,
        peak_vertices: first.summary.vertices.max,
        mean_error,
        final_error,
        errors,
        pareto: false,
    })
}

/// The integrator's name as scene files spell it.
pub fn integrator_name(i: Integrator) -> &'static str {
    match i {
        Integrator::SymplecticEuler => "symplectic_euler",
        Integrator::Rk4 => "rk4",
        Integrator::Implicit => "implicit",
    }
}

/// Median of `v` (mean of the middle two for an even count; `NaN` if empty).
pub fn median(v: &mut [Scalar]) -> Scalar {
    if v.is_empty() {
        return Scalar::NAN;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}
