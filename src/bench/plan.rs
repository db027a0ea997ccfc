//! Planning a benchmark: the ladder resolved into runs (the reference, the
//! rungs and the floors), each repetition of a run one job, written into a
//! directory that holds everything the jobs need.
//!
//! ```text
//! DIR/plan.json     the runs and jobs (read by `drape bench collect DIR`)
//! DIR/jobs.txt      one `drape run ...` command line per job, run from DIR
//! DIR/points.json   the material points every job samples
//! DIR/scene/...     the scene file and the OBJ files it names
//! DIR/out/          each job's samples (written by the jobs)
//! DIR/cache/        the reference's samples, kept between plans
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::garment::{check_garment_ladder, default_garment_ladder, is_garment};
use super::ladder::{self, Compare, Ladder, StepPolicy};
use super::metric::{diagonal, panel_grid_samples};
use super::sampling::{SamplePoints, read_json};
use super::{BenchError, BenchOptions};
use crate::math::{Scalar, Vector};
use crate::run::RunError;
use crate::scene::{AdaptMethod, Integrator, Scene, TimeStep, load_scene_file};
use crate::world::World;

mod write;

pub use write::{fnv1a, shell_words, write_plan};

/// The plan file's name in a bench directory.
pub const PLAN_FILE: &str = "plan.json";
/// The job list's name in a bench directory.
pub const JOBS_FILE: &str = "jobs.txt";
/// The sample points' file name in a bench directory.
pub const POINTS_FILE: &str = "points.json";
/// The format tag of a plan file.
pub const PLAN_FORMAT: &str = "drape-bench-plan-1";
/// The label of the lift floor's run.
pub const LIFT_LABEL: &str = "reference lifted 1 um";
/// How far the lift floor's run starts from the reference's, m: the cloth
/// lifted 1 micrometre against gravity, a change no mesh or step resolves. A
/// smooth problem answers with about nothing; a chaotic one (a sheet folding
/// onto an obstacle) amplifies it.
pub const FLOOR_LIFT: Scalar = 1e-6;

/// One run of a plan: the reference, a rung or a floor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunPlan {
    /// Name in the table and the chart.
    pub label: String,
    /// Every `--set` override of the run, the user's first.
    pub set: Vec<String>,
    /// A sensitivity floor, not a candidate.
    pub floor: bool,
    /// Subtracted from the run's samples before comparing, m (the lift).
    pub shift: [Scalar; 3],
    /// Remeshing method (`none` for uniform).
    pub method: String,
    /// Segments along the longer side (the adaptive base mesh).
    pub resolution: u32,
    /// The uniform resolution matching the finest reachable edges.
    pub finest_resolution: u32,
    /// Finest level (0 for uniform).
    pub max_level: u32,
    /// Integrator name.
    pub integrator: String,
    /// The step setting (`auto` or seconds).
    pub dt: String,
}

impl RunPlan {
    /// True for an adaptive run.
    pub fn adaptive(&self) -> bool {
        self.method != "none"
    }
}

/// One job: one repetition of one run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Job {
    /// The run: `None` for the reference, else the index into `Plan::runs`.
    pub run: Option<usize>,
    /// Repetition, from 1.
    pub rep: usize,
    /// The samples file it writes, relative to the bench directory.
    pub output: String,
}

/// A planned benchmark (`plan.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// [`PLAN_FORMAT`].
    pub format: String,
    /// drape's version.
    pub version: String,
    /// The scene's name.
    pub scene: String,
    /// Stem of the result files: the scene's name, `-time` for the time ladder.
    pub stem: String,
    /// The scene file, relative to the bench directory.
    pub scene_file: String,
    /// What the errors compare.
    pub compare: Compare,
    /// Which step the runs take.
    pub step: StepPolicy,
    /// The common step and where it comes from (under [`StepPolicy::Common`]).
    pub common_dt: Option<(Scalar, String)>,
    /// Simulated time of the runs, s.
    pub duration: Scalar,
    /// `--threads` given to every job (`None`: one per core).
    pub threads: Option<usize>,
    /// Repetitions of each rung.
    pub reps: usize,
    /// The reference run.
    pub reference: RunPlan,
    /// Where the reference's samples are, relative to the bench directory.
    pub reference_output: String,
    /// The rungs and floors, in ladder order (floors last).
    pub runs: Vec<RunPlan>,
    /// Every job still to run, in order: the reference (unless cached), then
    /// the runs round by round, so that a slow spell of a shared machine falls
    /// on one repetition of several runs and the median drops it.
    pub jobs: Vec<Job>,
}

impl Plan {
    /// The `drape run` arguments of `job` (after `drape`), run from the bench
    /// directory.
    pub fn argv(&self, job: &Job) -> Vec<String> {
        let mut argv = vec!["run".to_owned(), self.scene_file.clone()];
        argv.extend(["--no-record", "--quiet"].map(String::from));
        if let Some(n) = self.threads {
            argv.extend(["--threads".to_owned(), n.to_string()]);
        }
        for s in &self.run_of(job).set {
            argv.extend(["--set".to_owned(), s.clone()]);
        }
        argv.extend(["--sample-at".to_owned(), POINTS_FILE.to_owned()]);
        argv.extend(["--samples-out".to_owned(), job.output.clone()]);
        argv
    }

    /// The run a job repeats.
    pub fn run_of(&self, job: &Job) -> &RunPlan {
        job.run.map_or(&self.reference, |i| &self.runs[i])
    }

    /// A job's name in messages: `uniform 32, repetition 2 (out/...)`.
    pub fn job_name(&self, job: &Job) -> String {
        let label = &self.run_of(job).label;
        format!("`{label}`, repetition {} ({})", job.rep, job.output)
    }

    /// Reads `DIR/plan.json`.
    pub fn load(dir: &Path) -> Result<Plan, BenchError> {
        let path = dir.join(PLAN_FILE);
        if !path.is_file() {
            return Err(BenchError::Plan(format!(
                "{} is not a bench directory (it has no {PLAN_FILE}; `drape bench plan` makes one)",
                dir.display()
            )));
        }
        let plan: Plan = read_json(&path)?;
        if plan.format != PLAN_FORMAT {
            let message = format!("format `{}`, expected `{PLAN_FORMAT}`", plan.format);
            return Err(BenchError::Invalid { path, message });
        }
        Ok(plan)
    }
}

fn load(path: &Path, set: &[String], context: &str) -> Result<Scene, BenchError> {
    load_scene_file(path, set).map_err(|source| BenchError::Scene {
        context: context.to_owned(),
        source: Box::new(source),
    })
}

fn chain(a: &[String], b: &[String]) -> Vec<String> {
    a.iter().chain(b).cloned().collect()
}

/// What a run's scene is, for the table.
fn run_plan(label: &str, set: Vec<String>, scene: &Scene) -> RunPlan {
    let adapt = scene
        .adapt
        .as_ref()
        .filter(|a| a.method != AdaptMethod::None);
    RunPlan {
        label: label.to_owned(),
        set,
        floor: false,
        shift: [0.0; 3],
        method: adapt.map_or("none", |a| method_name(a.method)).to_owned(),
        resolution: scene.cloth.resolution.unwrap_or(0),
        finest_resolution: ladder::finest_resolution(scene),
        max_level: adapt.map_or(0, |a| a.max_level),
        integrator: integrator_name(scene.simulation.integrator).to_owned(),
        dt: match scene.simulation.dt {
            TimeStep::Auto => "auto".into(),
            TimeStep::Adaptive => "adaptive".into(),
            TimeStep::Fixed(dt) => format!("{dt}"),
        },
    }
}

/// The remeshing method's name as scene files spell it.
fn method_name(m: AdaptMethod) -> &'static str {
    match m {
        AdaptMethod::RedGreen => "red_green",
        AdaptMethod::Edge => "edge",
        AdaptMethod::Tensor => "tensor",
        AdaptMethod::None => "none",
    }
}

/// The integrator's name as scene files spell it.
fn integrator_name(i: Integrator) -> &'static str {
    match i {
        Integrator::SymplecticEuler => "symplectic_euler",
        Integrator::Rk4 => "rk4",
        Integrator::Implicit => "implicit",
    }
}

/// The ladder of `opts` (given, default or the time-step ladder), after `--rungs`.
fn resolve_ladder(opts: &BenchOptions, base_set: &[String]) -> Result<Ladder, BenchError> {
    let mut ladder = if opts.time_ladder {
        let uniform = ["adapt.method=none", "adapt.multirate=false"].map(String::from);
        let scene = load(&opts.scene, &chain(base_set, &uniform), "scene")?;
        let implicit = scene.simulation.integrator == Integrator::Implicit;
        ladder::time_ladder(ladder::scene_step(&scene)?, implicit)
    } else {
        match &opts.ladder {
            Some(l) => l.clone(),
            None => {
                let scene = load(&opts.scene, base_set, "scene")?;
                match is_garment(&scene) {
                    true => default_garment_ladder(&scene)?,
                    false => ladder::default_ladder(&scene),
                }
            }
        }
    };
    if !opts.rungs.is_empty() {
        ladder.select(&opts.rungs)?;
    }
    Ok(ladder)
}

/// The reference's own overrides: the ladder's (with `--reference-resolution`
/// as its mesh), or a uniform mesh 1.5 times the finest rung's, rounded up to even.
fn reference_set(opts: &BenchOptions, ladder: &Ladder, finest: u32) -> Vec<String> {
    match &ladder.reference {
        Some(own) => {
            let mut own = own.clone();
            if let Some(n) = opts.reference_resolution.filter(|_| !opts.time_ladder) {
                own.push(format!("cloth.resolution={n}"));
            }
            own
        }
        None => {
            let n = opts.reference_resolution;
            ladder::reference_overrides(n.unwrap_or((finest * 3).div_ceil(2).next_multiple_of(2)))
        }
    }
}

/// Resolves `opts` into a plan and the sample points; every run's scene is
/// loaded, so a bad override fails here, before any job runs.
pub fn make_plan(opts: &BenchOptions) -> Result<(Plan, SamplePoints), BenchError> {
    if let Some(s) = opts.overrides.iter().find(|s| is_path_key(s)) {
        return Err(BenchError::Plan(format!(
            "`--set {s}`: files given on the command line are not carried into the bench directory; name them in the scene file"
        )));
    }
    let mut base_set = opts.overrides.clone();
    if let Some(d) = opts.duration {
        base_set.push(format!("simulation.duration={d:e}"));
    }
    let base = load(&opts.scene, &base_set, "scene")?;
    let ladder = resolve_ladder(opts, &base_set)?;
    if is_garment(&base) {
        check_garment_ladder(opts, &ladder)?;
    }
    let step = match opts.time_ladder {
        true => StepPolicy::Own,
        false => opts.step.or(ladder.step).unwrap_or(StepPolicy::Common),
    };
    let compare = opts.compare.or(ladder.compare).unwrap_or(Compare::Frames);
    let mut finest = 0;
    // The reference is finer than every candidate; a floor may be as fine.
    for r in ladder.rung.iter().filter(|r| !r.floor) {
        let scene = load(&opts.scene, &chain(&base_set, &r.set), &r.label)?;
        finest = finest.max(ladder::finest_resolution(&scene));
    }
    let ref_own = reference_set(opts, &ladder, finest);
    let ref_scene = load(&opts.scene, &chain(&base_set, &ref_own), "reference")?;
    let mut common_dt = None;
    if step == StepPolicy::Common {
        let dt = ladder::scene_step(&ref_scene)?;
        common_dt = Some((dt, ladder::step_origin(&ref_scene).to_owned()));
        base_set.push(ladder::dt_override(dt));
    }
    let ref_set = chain(&base_set, &ref_own);
    let ref_scene = load(&opts.scene, &ref_set, "reference")?;
    let mut runs = Vec::new();
    for r in &ladder.rung {
        let set = chain(&base_set, &r.set);
        let scene = load(&opts.scene, &set, &format!("rung `{}`", r.label))?;
        runs.push(RunPlan {
            floor: r.floor,
            ..run_plan(&r.label, set, &scene)
        });
    }
    if opts.floor && !opts.time_ladder {
        runs.push(lift_floor(&opts.scene, &ref_set, &ref_scene)?);
    }
    let world = World::from_scene(&ref_scene).map_err(RunError::from)?;
    let samples = panel_grid_samples(&world.mesh, opts.grid);
    let points = SamplePoints {
        points: samples.iter().map(|(p, _)| p.to_array()).collect(),
        panels: match world.mesh.panels() {
            Some(_) => samples.iter().map(|&(_, panel)| panel).collect(),
            None => Vec::new(),
        },
        diagonal: diagonal(&world.mesh),
    };
    let plan = Plan {
        format: PLAN_FORMAT.to_owned(),
        version: env!("CARGO_PKG_VERSION").to_owned(),
        scene: base.name.clone(),
        stem: match opts.time_ladder {
            true => format!("{}-time", base.name),
            false => base.name.clone(),
        },
        scene_file: String::new(),
        compare,
        step,
        common_dt,
        duration: base.simulation.duration,
        threads: opts.threads,
        reps: opts.reps.max(1),
        reference: run_plan("reference", ref_set, &ref_scene),
        reference_output: String::new(),
        runs,
        jobs: Vec::new(),
    };
    Ok((plan, points))
}

/// The lift floor: the reference with the cloth started [`FLOOR_LIFT`] higher
/// (against gravity), moved back down before comparing. A garment's panels are
/// each lifted.
fn lift_floor(path: &Path, ref_set: &[String], ref_scene: &Scene) -> Result<RunPlan, BenchError> {
    let g = Vector::from(ref_scene.simulation.gravity);
    let lift = (-g).try_normalize().unwrap_or(Vector::Z) * FLOOR_LIFT;
    let at = |p: [f64; 3]| {
        let p = Vector::from(p) + lift;
        format!("[{:e}, {:e}, {:e}]", p.x, p.y, p.z)
    };
    let moved: Vec<String> = match is_garment(ref_scene) {
        false => vec![format!("cloth.position={}", at(ref_scene.cloth.position))],
        true => (ref_scene.panel.iter().enumerate())
            .map(|(k, p)| format!("panel.{k}.position={}", at(p.position)))
            .collect(),
    };
    let set = chain(ref_set, &moved);
    let scene = load(path, &set, LIFT_LABEL)?;
    Ok(RunPlan {
        floor: true,
        shift: lift.to_array(),
        ..run_plan(LIFT_LABEL, set, &scene)
    })
}

/// True for an override of a file path (`cloth.path`, `obstacle.N.path`).
fn is_path_key(set: &str) -> bool {
    set.split_once('=')
        .is_some_and(|(k, _)| k.trim() == "path" || k.trim().ends_with(".path"))
}
