//! `drape garment-plan` and `drape garment-collect`: a folder of GarmentCode patterns
//! draped as a job list, one `drape garment` per pattern (for GNU parallel or a Slurm
//! array, as `drape bench plan` writes its runs), and the jobs' summaries gathered into
//! one CSV.
//!
//! ```text
//! OUT/jobs.txt       one `drape garment ...` command line per pattern, run from OUT
//! OUT/patterns.tsv   each job's name and pattern file, what `garment-collect` reads
//! OUT/NAME.json      each job's summary, written by the job
//! OUT/garments.csv   written by `garment-collect`
//! ```

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Args;
use serde_json::Value;

use crate::cli::garment::{BodyArgs, Up};
use drape::bench::plan::shell_words;

/// The job list, one command line per pattern.
const JOBS_FILE: &str = "jobs.txt";
/// The jobs' names and patterns, tab-separated.
const PATTERNS_FILE: &str = "patterns.tsv";
/// The collected table.
const CSV_FILE: &str = "garments.csv";
/// How a GarmentCode specification's file name ends.
const SPEC_SUFFIX: &str = "_specification.json";

#[derive(Args)]
pub struct GarmentPlanArgs {
    /// The folder of GarmentCode patterns: every `*_specification.json` in it.
    patterns: PathBuf,
    #[command(flatten)]
    body: BodyArgs,
    /// Override a value of every pattern's scene (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    overrides: Vec<String>,
    /// Worker threads of each job, 1 to 256 (default: one per core).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=256))]
    threads: Option<u32>,
    /// Also export every recorded frame of each job as OBJ files into OUT/NAME-obj (for
    /// `garment-check.py` and other checks of the draped shape).
    #[arg(long)]
    obj: bool,
    /// The directory to write the job list into (created if needed).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

#[derive(Args)]
pub struct GarmentCollectArgs {
    /// The directory `drape garment-plan` wrote.
    dir: PathBuf,
}

/// The job name of a pattern file: its name without `_specification.json`.
fn job_name(spec: &Path) -> String {
    let file = spec.file_name().map(|f| f.to_string_lossy().into_owned());
    let file = file.unwrap_or_default();
    file.strip_suffix(SPEC_SUFFIX).unwrap_or(&file).to_owned()
}

/// Writes the job list of `drape garment-plan`.
pub fn cmd_garment_plan(args: GarmentPlanArgs) -> Result<ExitCode> {
    let cwd = std::env::current_dir().context("cannot read the current directory")?;
    let folder = cwd.join(&args.patterns);
    let mut specs: Vec<PathBuf> = std::fs::read_dir(&folder)
        .with_context(|| format!("cannot read the pattern folder {}", folder.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.to_string_lossy().ends_with(SPEC_SUFFIX))
        .collect();
    specs.sort();
    if specs.is_empty() {
        anyhow::bail!(
            "{}: no GarmentCode pattern (`*{SPEC_SUFFIX}`) in the folder",
            folder.display()
        );
    }
    // A bad body fails here, once, rather than in every job.
    args.body.check()?;
    let body = cwd.join(&args.body.body);
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let (mut jobs, mut names) = (String::new(), String::new());
    for spec in &specs {
        let name = job_name(spec);
        let mut argv: Vec<String> = vec!["garment".into(), spec.display().to_string()];
        argv.extend(["--body".into(), body.display().to_string()]);
        let up = match args.body.body_up {
            Up::Y => "y",
            Up::Z => "z",
        };
        argv.extend(["--body-up".into(), up.into()]);
        argv.extend(["--body-scale".into(), args.body.body_scale.to_string()]);
        if let Some(file) = &args.body.body_measurements {
            argv.extend([
                "--body-measurements".into(),
                cwd.join(file).display().to_string(),
            ]);
        }
        if args.body.no_hold {
            argv.push("--no-hold".into());
        }
        argv.extend(["--no-record".into(), "--quiet".into()]);
        argv.extend(["--summary".into(), format!("{name}.json")]);
        if args.obj {
            argv.extend(["--obj-dir".into(), format!("{name}-obj")]);
        }
        if let Some(n) = args.threads {
            argv.extend(["--threads".into(), n.to_string()]);
        }
        for s in &args.overrides {
            argv.extend(["--set".into(), s.clone()]);
        }
        let _ = writeln!(jobs, "drape {}", shell_words(&argv));
        let _ = writeln!(names, "{name}\t{}", spec.display());
    }
    for (file, text) in [(JOBS_FILE, &jobs), (PATTERNS_FILE, &names)] {
        let path = args.out.join(file);
        std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
    }
    println!(
        "{} jobs in {}: run them from that directory (`parallel < {JOBS_FILE}`, or line \
         $SLURM_ARRAY_TASK_ID of it in a Slurm array), then `drape garment-collect {}`",
        specs.len(),
        args.out.join(JOBS_FILE).display(),
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// What a job has left in its summary file.
enum Summary {
    /// No file: the job has not started, or failed before its run.
    Missing,
    /// An empty file: the job is running, or was killed (e.g. by a time limit)
    /// before it wrote its summary at the end.
    Empty,
    /// The summary.
    Written(Value),
}

impl Summary {
    /// Reads `path`; a file that is not JSON is an error.
    fn read(path: &Path) -> Result<Summary> {
        let Ok(text) = std::fs::read_to_string(path) else {
            return Ok(Summary::Missing);
        };
        if text.trim().is_empty() {
            return Ok(Summary::Empty);
        }
        let value = serde_json::from_str::<Value>(&text)
            .with_context(|| format!("{}: not a drape summary", path.display()))?;
        Ok(Summary::Written(value))
    }
}

/// One CSV row from a job's summary.
fn row(name: &str, summary: &Summary) -> String {
    let s = match summary {
        Summary::Missing => return format!("{name},,,,,,,,,missing"),
        Summary::Empty => return format!("{name},,,,,,,,,empty"),
        Summary::Written(s) => s,
    };
    let num = |v: Option<&Value>| v.and_then(Value::as_f64);
    let seams = s.get("seams").and_then(Value::as_array);
    let seams = seams.map_or(&[][..], Vec::as_slice);
    let welded = seams
        .iter()
        .filter(|x| x.get("welded_at").is_some_and(|w| !w.is_null()))
        .count();
    let widest_gap = seams
        .iter()
        .filter_map(|x| num(x.get("gap")))
        .fold(0.0, f64::max);
    let rest = s.get("rest");
    let at_rest = rest.and_then(|r| r.get("at_rest")).and_then(Value::as_bool);
    let cell = |v: Option<f64>, scale: f64| v.map_or(String::new(), |x| format!("{}", x * scale));
    format!(
        "{name},{},{},{},{},{},{},{},{},ok",
        cell(num(s.pointer("/vertices/max")), 1.0),
        cell(num(s.get("wall_time_s")), 1.0),
        at_rest.map_or(String::new(), |b| b.to_string()),
        cell(num(rest.and_then(|r| r.get("time"))), 1.0),
        welded,
        seams.len(),
        1e3 * widest_gap,
        cell(num(s.get("max_penetration")), 1e3),
    )
}

/// Gathers the jobs' summaries of `drape garment-collect` into DIR/garments.csv.
pub fn cmd_garment_collect(args: GarmentCollectArgs) -> Result<ExitCode> {
    let list = args.dir.join(PATTERNS_FILE);
    let names = std::fs::read_to_string(&list).with_context(|| {
        format!(
            "cannot read {}: is {} a directory `drape garment-plan` wrote?",
            list.display(),
            args.dir.display()
        )
    })?;
    let mut csv = String::from(
        "pattern,vertices,wall_s,at_rest,rest_time_s,seams_welded,seams,widest_gap_mm,\
         max_penetration_mm,status\n",
    );
    let mut missing = 0;
    for name in names.lines().filter_map(|l| l.split('\t').next()) {
        let summary = Summary::read(&args.dir.join(format!("{name}.json")))?;
        missing += usize::from(!matches!(summary, Summary::Written(_)));
        csv.push_str(&row(name, &summary));
        csv.push('\n');
    }
    let out = args.dir.join(CSV_FILE);
    std::fs::write(&out, &csv).with_context(|| format!("cannot write {}", out.display()))?;
    print!("{csv}");
    println!("written to {}", out.display());
    if missing > 0 {
        eprintln!(
            "{missing} jobs have no summary (status `missing`: no file; `empty`: still \
             running, or killed before the end)"
        );
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}
