//! `drape run`: simulate a scene, record it, print and write its summary.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};

use crate::{ColourChoice, EdgeChoice, RunArgs, load};
use drape::bench::sampling::{SamplePoints, Sampler};
use drape::record::{ColourBy, DecisionData, EdgeDisplay, LiveViewer};
use drape::run::{FrameState, Progress, RunError, RunOptions, run_built};
use drape::scene::Scene;
use drape::summary::Summary;

/// Runs `drape run`. Exit codes: 0 done, 1 an error before or during the run, 2 the run
/// stopped on a numerical failure (its summary is still printed and written), 130
/// interrupted by Ctrl-C.
pub fn cmd_run(args: RunArgs) -> Result<ExitCode> {
    if args.no_decisions && matches!(args.colour_by, ColourChoice::Ratio | ColourChoice::State) {
        anyhow::bail!(
            "--colour-by {} colours the triangles by their refinement decisions, which \
             --no-decisions leaves out of the recording; drop one of the two",
            match args.colour_by {
                ColourChoice::Ratio => "ratio",
                _ => "state",
            }
        );
    }
    let scene = load(&args.scene)?;
    let adapts = scene
        .adapt
        .as_ref()
        .is_some_and(|a| a.method != drape::scene::AdaptMethod::None);
    if !adapts && matches!(args.colour_by, ColourChoice::Ratio | ColourChoice::State) {
        anyhow::bail!(
            "--colour-by ratio and --colour-by state colour the triangles by their refinement \
             decisions, and scene `{}` does not adapt its mesh (no [adapt], or method = \"none\")",
            scene.name
        );
    }
    run_scene(scene, &args)
}

/// Runs a loaded scene with `drape run`'s options (its scene arguments
/// already applied), with `drape run`'s exit codes.
pub fn run_scene(scene: Scene, args: &RunArgs) -> Result<ExitCode> {
    let opts = run_options(args, &scene);
    // Build the cloth and the obstacles once before any output is opened: a bad
    // OBJ or a pin that selects nothing fails here and leaves no empty recording
    // behind (nor truncates an existing one).
    let sim = drape::sim::build(&scene.resolve()?)?;
    // Create the OBJ directory before the recording is opened, so that an unusable
    // one fails with its own message and leaves no recording behind.
    if let Some(dir) = &args.output.obj_dir {
        create_obj_dir(dir)?;
    }
    // Open the summary now so that an unwritable path fails before a long run.
    let summary_file = match &args.output.summary {
        Some(path) => Some(
            std::fs::File::create(path)
                .with_context(|| format!("cannot write summary {}", path.display()))?,
        ),
        None => None,
    };
    let points = match &args.sample_at {
        Some(path) => Some(SamplePoints::load(path)?),
        None => None,
    };
    let interrupt = interrupt_on_ctrl_c()?;
    let bar = progress_bar(args.output.quiet);
    let mut on_progress = |p: Progress| {
        bar.set_length(p.frames);
        bar.set_position(p.frame);
        bar.set_message(format!("t = {:.2} s", p.sim_time));
    };
    let mut sampler = points.as_ref().map(Sampler::new);
    let mut observe = |f: &FrameState| {
        if let Some(s) = &mut sampler {
            s.observe(f);
        }
    };
    let outcome = run_built(
        &scene,
        sim,
        &opts,
        &interrupt,
        &mut on_progress,
        &mut observe,
    );
    bar.finish_and_clear();
    let samples = sampler.and_then(|s| s.finish(&outcome, &args.scene.overrides, opts.threads));
    if let (Some(samples), Some(path)) = (samples, &args.samples_out) {
        samples.store(path)?;
    }
    report_outcome(outcome, args.output.summary.as_deref(), summary_file)
}

/// Prints the run's summary and writes it to `summary_file` (opened before the run, at
/// `summary_path`), also after a numerical failure, which the exit code 2 reports. Any
/// other error leaves no summary: the file opened for it is removed.
fn report_outcome(
    outcome: Result<Summary, RunError>,
    summary_path: Option<&Path>,
    summary_file: Option<std::fs::File>,
) -> Result<ExitCode> {
    let (summary, failure) = match outcome {
        Ok(s) => (s, None),
        Err(e) => match &e {
            // The run stopped on a numerical failure: still report what it did.
            RunError::Numerical { summary, .. } => (summary.as_ref().clone(), Some(e.to_string())),
            _ => {
                // No summary to write: remove the file opened for it.
                if let Some(path) = summary_path {
                    let _ = std::fs::remove_file(path);
                }
                return Err(e.into());
            }
        },
    };
    crate::emit(&format!("{}\n", summary.paragraph()))?;
    if let Some(file) = summary_file {
        write_json(file, &summary)?;
    }
    if let Some(message) = failure {
        eprintln!("error: {message}");
        return Ok(ExitCode::from(2));
    }
    Ok(if summary.interrupted {
        ExitCode::from(130)
    } else {
        ExitCode::SUCCESS
    })
}

/// The run's options from the command line: where to record (by default `<scene name>.rrd`),
/// OBJ export, threads, live viewer, frame stride, which edges to record and what colours the
/// triangles.
fn run_options(args: &RunArgs, scene: &Scene) -> RunOptions {
    let record = (!args.output.no_record).then(|| {
        args.output
            .out
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("{}.rrd", scene.name)))
    });
    RunOptions {
        record,
        obj_dir: args.output.obj_dir.clone(),
        threads: args.output.threads.map(|n| n as usize),
        live: if args.spawn {
            Some(LiveViewer::Spawn)
        } else {
            args.connect.clone().map(LiveViewer::Connect)
        },
        record_every: args.record_every,
        edges: match (args.no_edges, args.edge_threshold, args.edges) {
            (true, _, _) => EdgeDisplay::Off,
            (false, Some(deg), _) => EdgeDisplay::Above(deg),
            (false, None, EdgeChoice::Review) => EdgeDisplay::Review,
            (false, None, EdgeChoice::All) => EdgeDisplay::All,
        },
        colour_by: match args.colour_by {
            ColourChoice::Level => ColourBy::Level,
            ColourChoice::Panel => ColourBy::Panel,
            ColourChoice::Ratio => ColourBy::Ratio,
            ColourChoice::State => ColourBy::State,
        },
        decisions: match args.no_decisions {
            true => DecisionData::Off,
            false => DecisionData::Recorded,
        },
    }
}

/// Creates the `--obj-dir` directory (and its parents); a file of that name is an error.
fn create_obj_dir(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        anyhow::bail!(
            "cannot create the OBJ directory {}: a file of that name exists",
            dir.display()
        );
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the OBJ directory {}", dir.display()))
}

/// A flag that Ctrl-C sets: the run stops after its current frame and reports.
fn interrupt_on_ctrl_c() -> Result<Arc<AtomicBool>> {
    let interrupt = Arc::new(AtomicBool::new(false));
    let flag = interrupt.clone();
    ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
        .context("installing the Ctrl-C handler")?;
    Ok(interrupt)
}

/// The frame progress bar on stderr, hidden with `--quiet`.
fn progress_bar(quiet: bool) -> ProgressBar {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(0)
    };
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:40} frame {pos}/{len} {msg} (eta {eta})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// Writes `summary` as pretty-printed JSON plus a final newline.
fn write_json(mut f: std::fs::File, summary: &Summary) -> Result<()> {
    serde_json::to_writer_pretty(&mut f, summary)?;
    writeln!(f)?;
    Ok(())
}
