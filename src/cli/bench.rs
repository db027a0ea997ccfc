//! `drape bench`: speed against error, in-process or as a job list
//! (`drape bench plan`, the jobs anywhere, `drape bench collect`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result};
use clap::{Args, Subcommand};

use crate::emit;
use drape::bench::{BenchOptions, Compare, Ladder, StepPolicy, collect, report};

/// `drape bench [plan | collect]`.
#[derive(Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct BenchArgs {
    #[command(subcommand)]
    action: Option<BenchAction>,
    /// Scene file (TOML).
    scene: Option<PathBuf>,
    #[command(flatten)]
    ladder: LadderArgs,
}

#[derive(Subcommand)]
enum BenchAction {
    /// Write the ladder's runs as jobs into DIR (DIR/jobs.txt: one `drape run`
    /// command line per job, to run from DIR in any order, anywhere), without running them.
    Plan(PlanArgs),
    /// Read the jobs' outputs in DIR, check every one, and write DIR/SCENE.csv,
    /// DIR/SCENE-frames.csv, DIR/SCENE.md and DIR/SCENE.svg.
    Collect(CollectArgs),
}

#[derive(Args)]
struct CollectArgs {
    /// The bench directory (made by `drape bench plan`).
    dir: PathBuf,
}

#[derive(Args)]
struct PlanArgs {
    /// Scene file (TOML).
    scene: PathBuf,
    #[command(flatten)]
    ladder: LadderArgs,
}

#[derive(Args)]
struct LadderArgs {
    /// Override a scene value for every run and the reference, e.g. `--set simulation.frame_rate=15` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    overrides: Vec<String>,
    /// Ladder file: `[[rung]]` tables with `label`, `set = ["key=value", ...]` and optional
    /// `floor = true`, and optional `reference = [...]`, `compare` and `step` (default: a
    /// ladder built from the scene: uniform 16 to 64 and adaptive runs, see docs/bench.md).
    #[arg(long, value_name = "FILE.toml")]
    ladder: Option<PathBuf>,
    /// Run the time-step ladder instead: one uniform mesh at the scene's step, 1/2 and 1/4 of it, and for an implicit scene `dt = "adaptive"` at tolerances 2e-3, 5e-4 and 1.25e-4 m, against 1/32 of the step (files SCENE-time.*).
    #[arg(long, conflicts_with_all = ["ladder", "reference_resolution", "step"])]
    time_ladder: bool,
    /// What the error compares: `frames` (every recorded frame, mean; dynamic scenes) or `rest` (the last frame; quasi-static scenes). Default: the ladder's `compare`, else `frames`.
    #[arg(long, value_name = "HOW")]
    compare: Option<Compare>,
    /// Which step the runs take: `common` (one fixed step for every run and the reference: the error is the mesh's) or `own` (each run's scene setting). Default: the ladder's `step`, else `common`.
    #[arg(long, value_name = "POLICY")]
    step: Option<StepPolicy>,
    /// Run only these rungs of the ladder, by label (comma-separated).
    #[arg(long, value_name = "LABEL,...", value_delimiter = ',')]
    rungs: Vec<String>,
    /// Repetitions of each run; the median wall time is reported.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1000))]
    reps: u32,
    /// Simulated time of every run and the reference, s (default: the scene's duration).
    #[arg(long, value_name = "S", value_parser = positive_seconds)]
    duration: Option<f64>,
    /// Worker threads of every run (default: one per core). Give a count when jobs run side by side.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=256))]
    threads: Option<u32>,
    /// The bench directory (default: bench-out/SCENE, bench-out/SCENE-time for the time ladder).
    #[arg(long = "out", value_name = "DIR")]
    out_dir: Option<PathBuf>,
    /// Recompute the reference even if DIR/cache/ holds it (the new one is not cached).
    #[arg(long)]
    no_cache: bool,
    /// Leave out the lift floor (by default the reference runs once more with the cloth
    /// started 1 micrometre higher: errors closer than its error are not told apart).
    #[arg(long)]
    no_floor: bool,
    /// Segments of the reference's uniform mesh (default: 1.5 times the finest rung's, rounded up to even);
    /// with a ladder that names its own `reference`, that reference's `cloth.resolution`.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(2..))]
    reference_resolution: Option<u32>,
    /// Sample points per side of the material-space grid of the error metric.
    #[arg(long, value_name = "N", default_value_t = 24, value_parser = clap::value_parser!(u32).range(1..=1000))]
    samples: u32,
}

/// A finite duration above zero, in seconds (for `--duration`).
fn positive_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(v) => Err(format!("{v} is not a duration above 0 s")),
        Err(e) => Err(format!("{s:?} is not a number of seconds: {e}")),
    }
}

impl LadderArgs {
    fn options(&self, scene: &Path) -> Result<BenchOptions> {
        Ok(BenchOptions {
            scene: scene.to_path_buf(),
            overrides: self.overrides.clone(),
            ladder: match &self.ladder {
                Some(path) => Some(Ladder::load(path)?),
                None => None,
            },
            time_ladder: self.time_ladder,
            rungs: self.rungs.clone(),
            compare: self.compare,
            step: self.step,
            reps: self.reps as usize,
            duration: self.duration,
            threads: self.threads.map(|n| n as usize),
            cache: !self.no_cache,
            reference_resolution: self.reference_resolution,
            grid: self.samples as usize,
            floor: !self.no_floor,
        })
    }

    /// `--out`, or `bench-out/` and the plan's stem.
    fn dir(&self, stem: &str) -> PathBuf {
        self.out_dir
            .clone()
            .unwrap_or_else(|| Path::new("bench-out").join(stem))
    }
}

/// Runs `drape bench`.
pub fn cmd_bench(args: BenchArgs) -> Result<ExitCode> {
    match (args.action, &args.scene) {
        (Some(BenchAction::Plan(p)), _) => cmd_plan(&p.scene, &p.ladder),
        (Some(BenchAction::Collect(c)), _) => cmd_collect(&c.dir),
        (None, Some(scene)) => cmd_local(scene, &args.ladder),
        (None, None) => {
            use clap::CommandFactory;
            crate::Cli::command()
                .error(
                    clap::error::ErrorKind::MissingRequiredArgument,
                    "`drape bench` needs a scene file: `drape bench SCENE`, `drape bench plan SCENE` or `drape bench collect DIR`",
                )
                .exit()
        }
    }
}

fn cmd_plan(scene: &Path, args: &LadderArgs) -> Result<ExitCode> {
    let opts = args.options(scene)?;
    let (plan, points) = drape::bench::make_plan(&opts)?;
    let dir = args.dir(&plan.stem);
    let plan = drape::bench::write_plan(plan, &points, &opts.scene, &dir, opts.cache)?;
    let mut text = String::new();
    for run in &plan.runs {
        let floor = if run.floor { " (floor)" } else { "" };
        text.push_str(&format!("{}{floor}: {}\n", run.label, run.set.join(" ")));
    }
    let cached = match plan.jobs.first().is_some_and(|j| j.run.is_some()) {
        true => format!(" (the reference is cached: {})", plan.reference_output),
        false => String::new(),
    };
    text.push_str(&format!(
        "wrote {} jobs to {}{cached}; run them from {}, then `drape bench collect {}`\n",
        plan.jobs.len(),
        dir.join(drape::bench::plan::JOBS_FILE).display(),
        dir.display(),
        dir.display()
    ));
    emit(&text)?;
    Ok(ExitCode::SUCCESS)
}

fn cmd_collect(dir: &Path) -> Result<ExitCode> {
    let result = collect(dir)?;
    let files = report::write_all(dir, &result)?;
    finish(&result, &files)
}

fn cmd_local(scene: &Path, args: &LadderArgs) -> Result<ExitCode> {
    let opts = args.options(scene)?;
    let interrupt = Arc::new(AtomicBool::new(false));
    let flag = interrupt.clone();
    ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
        .context("installing the Ctrl-C handler")?;
    let (plan, points) = drape::bench::make_plan(&opts)?;
    let dir = args.dir(&plan.stem);
    let mut log = |line: &str| eprintln!("{line}");
    let planned = (plan, &points);
    let (result, files) = drape::bench::bench_planned(&opts, planned, &dir, &interrupt, &mut log)?;
    finish(&result, &files)
}

fn finish(result: &drape::bench::BenchResult, files: &[PathBuf]) -> Result<ExitCode> {
    let mut text = report::markdown(result);
    for f in files {
        text.push_str(&format!("wrote {}\n", f.display()));
    }
    emit(&text)?;
    Ok(ExitCode::SUCCESS)
}
