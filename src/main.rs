//! The `drape` command line.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};

use cli::bench::{BenchArgs, cmd_bench};
use cli::body_frames::{BodyFramesArgs, cmd_body_frames};
use cli::garment::{GarmentArgs, cmd_garment};
use cli::garment_batch::{
    GarmentCollectArgs, GarmentPlanArgs, cmd_garment_collect, cmd_garment_plan,
};
use cli::run::cmd_run;
use drape::record::history::history_at;
use drape::record::inspect::inspect;
use drape::scene::{Scene, default_scene, load_scene_file};

/// The subcommands that have a file of their own.
mod cli {
    pub mod bench;
    pub mod body_frames;
    pub mod garment;
    pub mod garment_batch;
    pub mod run;
}

/// Adaptive mass-spring cloth simulation, recorded to Rerun .rrd files.
#[derive(Parser)]
#[command(name = "drape", version, about, long_about = None)]
pub(crate) struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a scene and record every frame to a .rrd file.
    Run(RunArgs),
    /// Drape a GarmentCode sewing pattern (`*_specification.json`) on a body
    /// (`--body BODY.obj`): the pattern and the body become a scene
    /// (`--write-scene` saves it), run as `drape run` runs one.
    Garment(GarmentArgs),
    /// Write a folder of GarmentCode patterns as a job list (DIR/jobs.txt, one
    /// `drape garment` per pattern, for GNU parallel or a Slurm array).
    GarmentPlan(GarmentPlanArgs),
    /// Gather the summaries of the jobs `garment-plan` wrote into DIR/garments.csv.
    GarmentCollect(GarmentCollectArgs),
    /// Validate a scene and print the resolved model without simulating.
    Check(SceneArgs),
    /// Decode a .rrd recording and print what it holds.
    Inspect(InspectArgs),
    /// Speed against error: run a ladder of uniform and adaptive settings on a
    /// scene (no recording), compare each with a fine cached reference, and
    /// write DIR/SCENE.csv, DIR/SCENE-frames.csv, DIR/SCENE.md and DIR/SCENE.svg;
    /// `bench plan` writes the runs as a job list, `bench collect` reads them back.
    Bench(BenchArgs),
    /// Run the hard-case stability suite (built in; `--suite DIR` for another
    /// folder of scenes) and print a pass/fail table.
    Stability(StabilityArgs),
    /// Write a scene's deforming mesh obstacle (an articulated body with
    /// surface = "skinned_mesh") as one OBJ file per recorded frame,
    /// DIR/frame_0000.obj, ..., for a `mesh_sequence` obstacle to read back.
    BodyFrames(BodyFramesArgs),
}

#[derive(Args)]
struct StabilityArgs {
    /// Shortened durations and coarser meshes, so that the whole suite runs in a few minutes.
    #[arg(long)]
    quick: bool,
    /// Run only this case (repeatable), e.g. `--case impact`; default: every case.
    #[arg(long = "case", value_name = "NAME")]
    cases: Vec<String>,
    /// Worker threads per run, 1 to 256 (default: one per core). Results are identical at any count.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=256))]
    threads: Option<u32>,
    /// Also write the table (Markdown) to this file.
    #[arg(long, value_name = "FILE.md")]
    markdown: Option<PathBuf>,
    /// Run the scenes (`*.toml`) of this folder instead of the built-in hard cases;
    /// a scene named after a hard case runs with that case's settings.
    #[arg(long, value_name = "DIR")]
    suite: Option<PathBuf>,
}

#[derive(Args)]
struct InspectArgs {
    /// The recording to read.
    file: PathBuf,
    /// Print this frame's mesh statistics, plots and events instead of the overview (with
    /// --at: the frame the point is taken at; default the last).
    #[arg(long, value_name = "N", conflicts_with = "frames")]
    frame: Option<i64>,
    /// Print the history of the triangle under the point X,Y,Z (m) instead: its level,
    /// refinement ratio, term and state where they change, and every remeshing event on it
    /// with its reason.
    #[arg(long, value_name = "X,Y,Z", value_parser = point, conflicts_with = "frames")]
    at: Option<[f64; 3]>,
    /// Print one line per frame instead of the overview: time, vertices, triangles,
    /// triangles at the finest level, splits, merges, rollbacks, contacts and the
    /// frame's stepping time, summed at the end.
    #[arg(long)]
    frames: bool,
}

#[derive(Args)]
pub(crate) struct SceneArgs {
    /// Scene file (TOML). Without one, the embedded default scene is used.
    scene: Option<PathBuf>,
    /// Override a scene value by its dotted path, e.g. `--set cloth.resolution=64` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    overrides: Vec<String>,
}

/// Where a run's results go and how it runs: the options `drape run` and
/// `drape garment` share.
#[derive(Args)]
pub(crate) struct OutputArgs {
    /// Output recording (default: the scene's name + `.rrd` in the current directory).
    #[arg(long, short, value_name = "FILE.rrd", conflicts_with = "no_record")]
    out: Option<PathBuf>,
    /// Do not write a recording file (with `drape run --spawn` or `--connect`: stream to the
    /// viewer only).
    #[arg(long)]
    no_record: bool,
    /// Write a machine-readable summary (JSON) here.
    #[arg(long, value_name = "FILE.json")]
    summary: Option<PathBuf>,
    /// Write every recorded frame as an OBJ file into this directory.
    #[arg(long, value_name = "DIR")]
    obj_dir: Option<PathBuf>,
    /// Worker threads, 1 to 256 (default: one per core). Results are identical at any count.
    // The cap: with --threads 10000 a 0.05 s run had not finished after 60 s on a
    // 2-core machine (thousands of threads scheduled every step): it looked like a hang.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=256))]
    threads: Option<u32>,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Args)]
pub(crate) struct RunArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    output: OutputArgs,
    /// Record (and export OBJ for) every K-th frame only; frame 0 and the last are always recorded.
    #[arg(long, value_name = "K", default_value_t = 1,
          value_parser = clap::value_parser!(u64).range(1..))]
    record_every: u64,
    /// Which edges `cloth/edges` holds: `review` (default) the edges near the scene's refine
    /// threshold (within a factor 1.2 either way: 12.5 to 18 deg for 15 deg; 15 deg without
    /// adaptivity), `all` every edge.
    #[arg(long, value_enum, value_name = "WHICH", default_value_t = EdgeChoice::Review)]
    edges: EdgeChoice,
    /// Leave out `cloth/edges` (the per-edge dihedral angles).
    #[arg(long, conflicts_with_all = ["edge_threshold", "edges"])]
    no_edges: bool,
    /// Record only the edges whose dihedral angle is above DEG degrees (instead of --edges).
    #[arg(long, value_name = "DEG", value_parser = non_negative_degrees,
          conflicts_with = "edges")]
    edge_threshold: Option<f64>,
    /// What colours the cloth's triangles: `level` (default) the refinement level, `panel`
    /// the garment panel (each panel in its own colour, named in the legend; a cloth without
    /// panels is one panel, `cloth`), `ratio` the refinement criterion's value against its
    /// threshold, `state` what holds the triangle (both of an adaptive run's decisions;
    /// hovering a triangle then shows its ratio, term and state).
    #[arg(long = "colour-by", alias = "color-by", value_enum, value_name = "WHAT",
          default_value_t = ColourChoice::Level)]
    colour_by: ColourChoice,
    /// Leave out each triangle's refinement decision (`decision_ratio`, `decision_term`,
    /// `decision_state` on `cloth/mesh`), recorded every frame of an adaptive run by default.
    #[arg(long)]
    no_decisions: bool,
    /// Also start a Rerun viewer (`rerun` 0.36.3 on PATH) and stream the run to it live.
    #[arg(long, conflicts_with = "connect")]
    spawn: bool,
    /// Also stream the run live to a running viewer, e.g. rerun+http://127.0.0.1:9876/proxy.
    #[arg(long, value_name = "URL")]
    connect: Option<String>,
    /// Sample the cloth at the material points in this file (a bench plan's
    /// `points.json`) at every recorded frame; with --samples-out.
    #[arg(long, value_name = "POINTS.json", requires = "samples_out")]
    sample_at: Option<PathBuf>,
    /// Write the samples and the run's cost here as JSON (what `drape bench
    /// collect` reads; written also when the run stops on a numerical failure).
    #[arg(long, value_name = "FILE.json", requires = "sample_at")]
    samples_out: Option<PathBuf>,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run(args) => cmd_run(args),
        Command::Garment(args) => cmd_garment(args),
        Command::GarmentPlan(args) => cmd_garment_plan(args),
        Command::GarmentCollect(args) => cmd_garment_collect(args),
        Command::Check(args) => cmd_check(args),
        Command::Inspect(args) => cmd_inspect(args),
        Command::Bench(args) => cmd_bench(args),
        Command::Stability(args) => cmd_stability(args),
        Command::BodyFrames(args) => cmd_body_frames(args),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", one_line(&e));
            ExitCode::from(1)
        }
    }
}

/// Writes `text` to standard output. A closed pipe (`drape inspect F | head`,
/// `drape bench plan ... | head`) ends the output quietly instead of panicking in
/// `print!` (regression test `inspect_into_a_closed_pipe_ends_quietly`); any other
/// write error is an error.
pub(crate) fn emit(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(e).context("cannot write to standard output")
        }
        _ => Ok(()),
    }
}

/// The error and its causes on one line. Most of drape's errors already include their
/// source in their own message, so a cause whose text is already there is not repeated
/// (`{e:#}` would print each one again).
fn one_line(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let cause = cause.to_string();
        if !text.contains(&cause) {
            text = format!("{text}: {cause}");
        }
    }
    text
}

fn load(args: &SceneArgs) -> Result<Scene> {
    Ok(match &args.scene {
        Some(path) => load_scene_file(path, &args.overrides)?,
        None => default_scene(&args.overrides)?,
    })
}

/// The values of `--edges`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum EdgeChoice {
    /// The edges near the scene's refine threshold.
    Review,
    /// Every edge.
    All,
}

/// The values of `--colour-by`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ColourChoice {
    /// The refinement level.
    Level,
    /// The garment panel.
    Panel,
    /// The refinement criterion's ratio.
    Ratio,
    /// The refinement decision's state.
    State,
}

fn cmd_check(args: SceneArgs) -> Result<ExitCode> {
    let scene = load(&args)?;
    emit(&drape::check::describe(&scene)?)?;
    Ok(ExitCode::SUCCESS)
}

/// A point `X,Y,Z` of three finite numbers (for `--at`).
fn point(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y, z] = parts[..] else {
        return Err(format!(
            "{s} is not a point X,Y,Z (three numbers separated by commas)"
        ));
    };
    let number = |v: &str| match v.parse::<f64>() {
        Ok(n) if n.is_finite() => Ok(n),
        _ => Err(format!("{v} in {s} is not a finite number")),
    };
    Ok([number(x)?, number(y)?, number(z)?])
}

/// A finite angle in degrees, at least 0 (for `--edge-threshold`).
fn non_negative_degrees(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        Ok(v) => Err(format!("{v} is not an angle of 0 degrees or more")),
        Err(e) => Err(format!("{s:?} is not a number of degrees: {e}")),
    }
}

fn cmd_stability(args: StabilityArgs) -> Result<ExitCode> {
    use drape::stability::{Suite, all_passed, integrator_name, run_variant, table};
    let suite = match &args.suite {
        Some(dir) => Suite::from_dir(dir, &args.cases)?,
        None => Suite::embedded(&args.cases)?,
    };
    let variants = suite.variants(args.quick);
    // Open the Markdown file first so that an unwritable path fails before the runs.
    let markdown = match &args.markdown {
        Some(path) => Some(
            std::fs::File::create(path)
                .with_context(|| format!("cannot write {}", path.display()))?,
        ),
        None => None,
    };
    let mut rows = Vec::with_capacity(variants.len());
    for (i, variant) in variants.iter().enumerate() {
        eprint!(
            "[{}/{}] {} {} adaptive {} ... ",
            i + 1,
            variants.len(),
            variant.case.name,
            integrator_name(variant.integrator),
            if variant.adaptive { "on" } else { "off" }
        );
        let scene = variant.scene(args.quick);
        let row = run_variant(&scene, variant, args.threads.map(|n| n as usize))?;
        eprintln!(
            "{} in {:.1} s",
            if row.passed() { "pass" } else { "FAIL" },
            row.wall_s
        );
        rows.push(row);
    }
    let text = table(&rows);
    emit(&text)?;
    if let (Some(mut file), Some(path)) = (markdown, &args.markdown) {
        file.write_all(text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(if all_passed(&rows) {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn cmd_inspect(args: InspectArgs) -> Result<ExitCode> {
    if let Some(at) = args.at {
        emit(&history_at(&args.file, at, args.frame)?.report())?;
        return Ok(ExitCode::SUCCESS);
    }
    let inspection = inspect(&args.file)?;
    match args.frame {
        Some(n) => emit(&inspection.frame_report(n)?)?,
        None if args.frames => emit(&inspection.frames_table())?,
        None => emit(&inspection.report())?,
    }
    Ok(ExitCode::SUCCESS)
}
