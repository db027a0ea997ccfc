//! Speed against error (SPEC section 8): `drape bench` runs a ladder of uniform
//! and adaptive settings on a scene without recording, measures each run's
//! wall time, vertex counts and error against a cached fine reference, and
//! writes a CSV, a Markdown table and an SVG chart.
//!
//! ```text
//! ladder (rungs = --set lists) -> one common step (default) -> reference
//! (cached) -> each rung: sampled run, errors per frame (or at rest), median
//! wall time over reps -> Pareto front, convergence order -> CSV, MD, SVG
//! ```
//!
//! The spatial ladder runs every rung and the reference at one step, so that
//! the error is the mesh's; the time-step ladder (`--time-ladder`) keeps one
//! mesh and varies the step (SPEC section 8).

pub mod chart;
pub mod floor;
pub mod ladder;
pub mod map;
pub mod measure;
pub mod metric;
pub mod order;
pub mod pareto;
pub mod reference;
pub mod replot;
pub mod report;
pub mod sampling;
pub mod shadow;
pub mod steps;
pub mod window;

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use crate::math::Scalar;
use crate::run::{RunError, RunOptions};
use crate::scene::{DiagonalPattern, Scene, SceneError, load_scene_file};
pub use floor::{FLOOR_LIFT, Floor, FloorChange};
pub use ladder::{Compare, Ladder, Rung, StepPolicy};
pub use measure::{integrator_name, median};
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
    /// The chart could not be drawn.
    #[error("drawing the chart: {0}")]
    Chart(String),
    /// `--mesh-floor` does not apply.
    #[error("--mesh-floor: {0}")]
    MeshFloor(String),
    /// `--pattern-floor` does not apply.
    #[error("--pattern-floor: {0}")]
    PatternFloor(String),
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
    /// Run the time-step ladder ([`steps::time_ladder`]) instead of `ladder`.
    pub time_ladder: bool,
    /// Only these rungs of the ladder (empty: all).
    pub rungs: Vec<String>,
    /// What the error compares (`None`: the ladder's `compare`, else frame by frame).
    pub compare: Option<Compare>,
    /// Which step the runs take (`None`: the ladder's `step`, else common).
    pub step: Option<StepPolicy>,
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
    /// Reference resolution (`None`: 1.5 times the finest rung's, rounded up
    /// to even, or the resolution a ladder's own `reference` sets); with a
    /// ladder's `reference`, it sets that reference's `cloth.resolution`.
    pub reference_resolution: Option<u32>,
    /// Sample points per side of the material-space grid.
    pub grid: usize,
    /// Also run the reference with the cloth started [`FLOOR_LIFT`] higher
    /// (against gravity) and report how far it ends from the reference: the
    /// comparison's lift floor ([`floor`]).
    pub floor: bool,
    /// Also run the reference's settings with `cloth.resolution` this many
    /// segments and report how far it ends from the reference: the mesh
    /// floor ([`floor`]; rectangle cloths only, not with the time-step
    /// ladder).
    pub mesh_floor: Option<u32>,
    /// Also run the reference's settings with every grid square's diagonal
    /// turned (`cloth.diagonals = "alternating_flipped"`) and report how far
    /// it ends from the reference: the pattern floor ([`floor`]; rectangle
    /// cloths with alternating diagonals only, not with the time-step
    /// ladder).
    pub pattern_floor: bool,
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
    /// Every repetition's wall time in the order run: the sampled run's (without
    /// its sampling), then one per round (`measure::Sampled`); empty for a row
    /// read back from a CSV.
    pub walls: Vec<Scalar>,
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
    /// The rigid translation part of `final_error`: the length of the mean
    /// displacement of the samples at the last frame, relative to the diagonal
    /// ([`metric::relative_offset`]; `NaN` if failed, and in rows read back
    /// from a CSV, which does not hold it).
    pub final_offset: Scalar,
    /// What `error` is: the mean over the frames or the error at rest.
    pub compare: Compare,
    /// The error the report compares: `mean_error` for [`Compare::Frames`],
    /// `final_error` for [`Compare::Rest`].
    pub error: Scalar,
    /// `(time, error)` at every recorded frame.
    pub errors: Vec<(Scalar, Scalar)>,
    /// The shadow's relative difference from the reference's
    /// ([`shadow`]), compared like `error`: `NaN` where the samples are not
    /// a complete grid, the run failed, and in rows read back from a CSV.
    pub shadow_error: Scalar,
    /// Each sample point's error, in the order of the reference's points
    /// ([`sampling::sample_errors`], compared like `error`; empty in rows
    /// read back from a CSV).
    pub sample_errors: Vec<Scalar>,
    /// On the Pareto front of (wall time, error).
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
    /// Stem of the file names: the scene's name, with `-time` for the time-step ladder.
    pub stem: String,
    /// True for the time-step ladder.
    pub time_ladder: bool,
    /// What the errors compare.
    pub compare: Compare,
    /// Which step the runs took.
    pub step: StepPolicy,
    /// The common step and where it comes from (under [`StepPolicy::Common`]).
    pub common_dt: Option<(Scalar, String)>,
    /// How far the reference's samples moved over its last frame, relative to
    /// the diagonal (a check that a scene compared at rest has settled).
    pub reference_last_motion: Option<Scalar>,
    /// The lift floor (`None` unless asked for, or for the time-step ladder,
    /// or when its run failed).
    pub floor: Option<Floor>,
    /// Why the lift floor's run failed numerically, when it did.
    pub floor_failure: Option<String>,
    /// The mesh floor (`None` unless asked for, or when its run failed).
    pub mesh_floor: Option<Floor>,
    /// Why the mesh floor's run failed numerically, when it did.
    pub mesh_floor_failure: Option<String>,
    /// The pattern floor (`None` unless asked for, or when its run failed).
    pub pattern_floor: Option<Floor>,
    /// Why the pattern floor's run failed numerically, when it did.
    pub pattern_floor_failure: Option<String>,
}

impl BenchResult {
    /// The floors measured: the lift's, the mesh's, then the pattern's.
    pub fn floors(&self) -> impl Iterator<Item = &Floor> {
        self.floor
            .iter()
            .chain(&self.mesh_floor)
            .chain(&self.pattern_floor)
    }

    /// The floor that decides the target check: the larger of those measured,
    /// or `None` when none was, or when one that was asked for is missing (its
    /// run failed) or could not be compared: a check is then not called
    /// decided on the other floor alone.
    pub fn deciding_floor(&self) -> Option<Scalar> {
        if self.floor_failure.is_some()
            || self.mesh_floor_failure.is_some()
            || self.pattern_floor_failure.is_some()
        {
            return None;
        }
        floor::largest(self.floors())
    }
}

fn load(path: &Path, overrides: &[String], context: &str) -> Result<Scene, BenchError> {
    load_scene_file(path, overrides).map_err(|source| BenchError::Scene {
        context: context.to_owned(),
        source: Box::new(source),
    })
}

/// Everything resolved before any run: the ladder, every rung's scene, the
/// reference's scene and overrides, the comparison and the step.
struct Plan {
    base: Scene,
    ladder: Ladder,
    scenes: Vec<Scene>,
    ref_own: Vec<String>,
    ref_set: Vec<String>,
    ref_scene: Scene,
    /// The reference's overrides and scene with the cloth lifted by
    /// [`FLOOR_LIFT`].
    floor_set: Vec<String>,
    floor_scene: Scene,
    floor_lift: crate::math::Vector,
    /// The reference's overrides and scene on the mesh floor's mesh, with its
    /// resolution (`None` unless asked for).
    mesh: Option<(Vec<String>, Scene, u32)>,
    /// The reference's overrides and scene with every diagonal turned, and
    /// that pattern (`None` unless asked for).
    pattern: Option<(Vec<String>, Scene, DiagonalPattern)>,
    compare: Compare,
    step: StepPolicy,
    common_dt: Option<(Scalar, String)>,
}

/// `a` then `b` then `c`, as one override list.
fn chain(a: &[String], b: &[String], c: &[String]) -> Vec<String> {
    a.iter().chain(b).chain(c).cloned().collect()
}

/// Resolves the ladder and every scene; a bad override fails before any run.
fn plan(opts: &BenchOptions) -> Result<Plan, BenchError> {
    let mut base_set = opts.overrides.clone();
    if let Some(d) = opts.duration {
        base_set.push(format!("simulation.duration={d:e}"));
    }
    let base = load(&opts.scene, &base_set, "scene")?;
    let mut ladder = if opts.time_ladder {
        let uniform = [
            "adapt.method=none".to_owned(),
            "adapt.multirate=false".to_owned(),
        ];
        let scene = load(&opts.scene, &chain(&base_set, &uniform, &[]), "scene")?;
        steps::time_ladder(steps::scene_step(&scene)?)
    } else {
        let step = opts
            .step
            .or(opts.ladder.as_ref().and_then(|l| l.step))
            .unwrap_or(StepPolicy::Common);
        opts.ladder
            .clone()
            .unwrap_or_else(|| ladder::default_ladder(&base, step))
    };
    let step = if opts.time_ladder {
        StepPolicy::Own
    } else {
        opts.step.or(ladder.step).unwrap_or(StepPolicy::Common)
    };
    let compare = opts.compare.or(ladder.compare).unwrap_or(Compare::Frames);
    if !opts.rungs.is_empty() {
        ladder.select(&opts.rungs)?;
    }
    let resolve = |step_set: &[String]| -> Result<Vec<Scene>, BenchError> {
        ladder
            .rung
            .iter()
            .map(|r| {
                let set = chain(&base_set, step_set, &r.set);
                load(&opts.scene, &set, &format!("rung `{}`", r.label))
            })
            .collect()
    };
    let mut scenes = resolve(&[])?;
    let finest = scenes
        .iter()
        .map(ladder::finest_resolution)
        .max()
        .unwrap_or(0);
    let ref_res = opts
        .reference_resolution
        .unwrap_or_else(|| (finest * 3).div_ceil(2).next_multiple_of(2));
    let mut ref_own = ladder
        .reference
        .clone()
        .unwrap_or_else(|| ladder::reference_overrides(ref_res));
    // A ladder's own reference takes `--reference-resolution` as its mesh
    // (it was silently ignored there before).
    if let (Some(_), Some(n)) = (&ladder.reference, opts.reference_resolution) {
        ref_own.push(format!("cloth.resolution={n}"));
    }
    let mut ref_scene = load(&opts.scene, &chain(&base_set, &ref_own, &[]), "reference")?;
    let mut step_set = Vec::new();
    let mut common_dt = None;
    if step == StepPolicy::Common {
        let dt = steps::scene_step(&ref_scene)?;
        common_dt = Some((dt, steps::step_origin(&ref_scene).to_owned()));
        step_set.push(steps::dt_override(dt));
        scenes = resolve(&step_set)?;
        ref_scene = load(
            &opts.scene,
            &chain(&base_set, &step_set, &ref_own),
            "reference",
        )?;
    }
    let ref_set = chain(&base_set, &step_set, &ref_own);
    let floor_lift = floor::lift(&ref_scene);
    let floor_set = chain(
        &ref_set,
        &[floor::lifted_position(&ref_scene, floor_lift)],
        &[],
    );
    let floor_scene = load(&opts.scene, &floor_set, "reference, lifted")?;
    let mesh = match opts.mesh_floor {
        Some(n) => {
            let set = floor::mesh_override(&ref_scene, n, opts.time_ladder)
                .map_err(BenchError::MeshFloor)?;
            let set = chain(&ref_set, &[set], &[]);
            let scene = load(&opts.scene, &set, "reference, mesh floor")?;
            Some((set, scene, n))
        }
        None => None,
    };
    let pattern = match opts.pattern_floor {
        true => {
            let (set, p) = floor::pattern_override(&ref_scene, opts.time_ladder)
                .map_err(BenchError::PatternFloor)?;
            let set = chain(&ref_set, &[set], &[]);
            let scene = load(&opts.scene, &set, "reference, pattern floor")?;
            Some((set, scene, p))
        }
        false => None,
    };
    Ok(Plan {
        mesh,
        pattern,
        base,
        ref_set,
        floor_set,
        floor_scene,
        floor_lift,
        ladder,
        scenes,
        ref_own,
        ref_scene,
        compare,
        step,
        common_dt,
    })
}

/// The reference or a floor's run (`what`, for the log; `set` and `scene`
/// from the plan): from the cache when allowed and present, else computed.
fn obtain_reference(
    plan: &Plan,
    opts: &BenchOptions,
    (what, set, scene): (&str, &[String], &Scene),
    (run_opts, interrupt): (&RunOptions, &AtomicBool),
    log: &mut dyn FnMut(&str),
) -> Result<(Reference, bool), BenchError> {
    let scene_text = std::fs::read_to_string(&opts.scene).map_err(|source| BenchError::Io {
        path: opts.scene.clone(),
        source,
    })?;
    let key = reference::cache_key(&scene_text, set, opts.grid);
    let cache_file = reference::cache_path(&opts.out_dir, &plan.base.name, &key);
    if opts.cache
        && let Some(r) = reference::load_cached(&cache_file, &key)
    {
        log(&format!("{what}: cached {}", cache_file.display()));
        return Ok((r, true));
    }
    // A floor's run is the reference's overrides and one more.
    let change = match set.len() > plan.ref_set.len() {
        true => format!(", then {}", set.last().map_or("", String::as_str)),
        false => String::new(),
    };
    log(&format!(
        "{what}: computing ({}{change})",
        plan.ref_own.join(" ")
    ));
    let r = reference::compute(scene, set.to_vec(), key, opts.grid, run_opts, interrupt)?;
    log(&format!(
        "{what}: {} vertices, {} steps, {:.1} s",
        r.vertices, r.steps, r.wall_s
    ));
    if opts.cache {
        reference::store(&cache_file, &r)?;
    }
    Ok((r, false))
}

/// True when `run` samples the material points of `reference` (to rounding:
/// the two meshes' bounds, from which the grid is laid, can differ in the last
/// bits).
fn same_points(run: &Reference, reference: &Reference) -> bool {
    let tol = 1e-9 * reference.diagonal;
    run.points.len() == reference.points.len()
        && run
            .points
            .iter()
            .zip(&reference.points)
            .all(|(a, b)| (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol)
}

/// Which floor [`measure_floor`] measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FloorKind {
    /// The cloth started [`FLOOR_LIFT`] higher.
    Lift,
    /// The reference's settings at `--mesh-floor`'s resolution.
    Mesh,
    /// The reference's settings with every diagonal turned.
    Pattern,
}

/// A floor's run and its comparison with `reference` (module [`floor`]):
/// `Ok(None)` when the floor was not asked for, `Err(why)` when its run
/// failed numerically (the rungs are still measured).
fn measure_floor(
    plan: &Plan,
    opts: &BenchOptions,
    kind: FloorKind,
    reference: &Reference,
    run: (&RunOptions, &AtomicBool),
    log: &mut dyn FnMut(&str),
) -> Result<Result<Option<Floor>, String>, BenchError> {
    let label;
    let zero = crate::math::Vector::ZERO;
    let (name, change, lift, set, scene) = match (kind, &plan.mesh, &plan.pattern) {
        (FloorKind::Mesh, None, _) | (FloorKind::Pattern, _, None) => return Ok(Ok(None)),
        (FloorKind::Mesh, Some((set, scene, n)), _) => {
            label = floor::mesh_label(*n);
            ("mesh floor", FloorChange::Resolution(*n), zero, set, scene)
        }
        (FloorKind::Pattern, _, Some((set, scene, p))) => {
            label = floor::pattern_label(*p);
            ("pattern floor", FloorChange::Pattern(*p), zero, set, scene)
        }
        (FloorKind::Lift, ..) if !opts.floor || opts.time_ladder => return Ok(Ok(None)),
        (FloorKind::Lift, ..) => {
            label = floor::FLOOR_LABEL.to_owned();
            let change = FloorChange::Lift(plan.floor_lift.length());
            let (set, scene) = (&plan.floor_set, &plan.floor_scene);
            ("sensitivity floor", change, plan.floor_lift, set, scene)
        }
    };
    match obtain_reference(plan, opts, (&label, set, scene), run, log) {
        // The floor compares the same material points as the rungs; a cloth
        // whose outline changes with the mesh cannot be compared this way (a
        // turned pattern keeps the outline, so there this is a broken
        // invariant, reported all the same).
        Ok((r, _)) if !same_points(&r, reference) => {
            let why = "its sample points differ from the reference's (the cloth's outline changes with the mesh)".into();
            Err(match kind {
                FloorKind::Pattern => BenchError::PatternFloor(why),
                _ => BenchError::MeshFloor(why),
            })
        }
        Ok((r, hit)) => {
            let f = Floor {
                cache_hit: hit,
                ..floor::floor_of(&r, reference, change, lift, plan.compare)
            };
            log(&format!(
                "{name} ({}): {:.3e} of the diagonal",
                plan.compare.name(),
                f.error
            ));
            Ok(Ok(Some(f)))
        }
        // The floor's run failed numerically where the reference did not: the
        // floor is reported as missing, and the rungs are still measured.
        Err(BenchError::Reference(why)) => {
            log(&format!("{name}: its run failed ({why})"));
            Ok(Err(why))
        }
        Err(e) => Err(e),
    }
}

/// Runs the benchmark, reporting progress lines through `log`.
pub fn bench(
    opts: &BenchOptions,
    interrupt: &AtomicBool,
    log: &mut dyn FnMut(&str),
) -> Result<BenchResult, BenchError> {
    let plan = plan(opts)?;
    if let Some((dt, origin)) = &plan.common_dt {
        log(&format!(
            "time step: {dt:.4e} s ({origin}) for every run and the reference"
        ));
    }
    let run_opts = RunOptions {
        threads: opts.threads,
        ..RunOptions::default()
    };
    let run = (&run_opts, interrupt);
    let ref_run = ("reference", &plan.ref_set[..], &plan.ref_scene);
    let (reference, cache_hit) = obtain_reference(&plan, opts, ref_run, run, log)?;
    let (floor, floor_failure) =
        match measure_floor(&plan, opts, FloorKind::Lift, &reference, run, log)? {
            Ok(f) => (f, None),
            Err(why) => (None, Some(why)),
        };
    let (mesh_floor, mesh_floor_failure) =
        match measure_floor(&plan, opts, FloorKind::Mesh, &reference, run, log)? {
            Ok(f) => (f, None),
            Err(why) => (None, Some(why)),
        };
    let (pattern_floor, pattern_floor_failure) =
        match measure_floor(&plan, opts, FloorKind::Pattern, &reference, run, log)? {
            Ok(f) => (f, None),
            Err(why) => (None, Some(why)),
        };
    let points = reference.sample_points();
    let mut sampled = Vec::new();
    let n = plan.scenes.len();
    for (i, (r, scene)) in plan.ladder.rung.iter().zip(&plan.scenes).enumerate() {
        log(&format!("[{}/{n}] {}", i + 1, r.label));
        let m = measure::measure(
            r,
            scene,
            &reference,
            &points,
            plan.compare,
            &run_opts,
            interrupt,
        )?;
        let row = &m.row;
        log(&format!(
            "[{}/{n}] {}: {} wall {:.2} s, {:.0} vertices (peak {:.0}), error ({}) {:.3e}",
            i + 1,
            r.label,
            row.status,
            m.first_wall(),
            row.mean_vertices,
            row.peak_vertices,
            plan.compare.name(),
            row.error
        ));
        sampled.push(m);
    }
    // The timed repetitions, one of each rung per round (`measure::Sampled`).
    let reps = opts.reps.max(1);
    for round in 2..=reps {
        for (i, (m, scene)) in sampled.iter_mut().zip(&plan.scenes).enumerate() {
            if !m.timeable() {
                continue;
            }
            let wall = measure::time_once(scene, &run_opts, interrupt)?;
            m.add_wall(wall);
            log(&format!(
                "repetition {round}/{reps} [{}/{n}] {}: wall {wall:.2} s",
                i + 1,
                m.row.label
            ));
        }
    }
    let mut rows: Vec<_> = sampled.into_iter().map(measure::Sampled::finish).collect();
    let front = pareto::pareto_front(&rows.iter().map(|r| (r.wall_s, r.error)).collect::<Vec<_>>());
    for (row, on) in rows.iter_mut().zip(front) {
        row.pareto = on;
    }
    let reference_last_motion = sampling::last_frame_motion(&reference.frames, reference.diagonal);
    let stem = if opts.time_ladder {
        format!("{}-time", plan.base.name)
    } else {
        plan.base.name.clone()
    };
    let mut result = BenchResult {
        scene: plan.base.name.clone(),
        rows,
        reference,
        cache_hit,
        duration: plan.base.simulation.duration,
        files: Vec::new(),
        stem,
        time_ladder: opts.time_ladder,
        compare: plan.compare,
        step: plan.step,
        common_dt: plan.common_dt,
        reference_last_motion,
        floor,
        floor_failure,
        mesh_floor,
        mesh_floor_failure,
        pattern_floor,
        pattern_floor_failure,
    };
    result.files = report::write_all(&opts.out_dir, &result, &opts.scene)?;
    Ok(result)
}

/// The ladder `bench` would run with `opts` (after `--rungs`), without running
/// anything (`drape bench --list`).
pub fn resolved_ladder(opts: &BenchOptions) -> Result<Ladder, BenchError> {
    Ok(plan(opts)?.ladder)
}
