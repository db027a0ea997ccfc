//! The benchmark's files: `STEM.csv` (one row per run), `STEM-frames.csv`
//! (each run's error at every frame), `STEM.md` (a short report) and
//! `STEM.svg` (the chart).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::collect::{BenchResult, Row};
use super::{BenchError, chart};
use crate::math::Scalar;

/// The columns of `STEM.csv`.
pub const CSV_HEADER: &str = "label,kind,set,method,resolution,finest_resolution,max_level,integrator,dt,threads,status,reps,wall_s,wall_min_s,wall_max_s,steps,mean_vertices,peak_vertices,mean_error,final_error,error,pareto";

/// A CSV field, quoted when it holds a comma, a quote or a newline.
fn field(s: &str) -> String {
    match s.contains([',', '"', '\n']) {
        true => format!("\"{}\"", s.replace('"', "\"\"")),
        false => s.to_owned(),
    }
}

/// A number for the CSV: full precision, empty for `NaN`.
fn num(x: Scalar) -> String {
    match x.is_nan() {
        true => String::new(),
        false => format!("{x:e}"),
    }
}

/// The kind of a row: `floor` or `candidate`.
fn kind(r: &Row) -> &'static str {
    match r.run.floor {
        true => "floor",
        false => "candidate",
    }
}

/// `STEM.csv`: the header and one line per run.
pub fn csv(result: &BenchResult) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    for r in &result.rows {
        let min = r.walls.iter().copied().fold(Scalar::INFINITY, Scalar::min);
        let max = r
            .walls
            .iter()
            .copied()
            .fold(Scalar::NEG_INFINITY, Scalar::max);
        let cells = [
            field(&r.run.label),
            kind(r).to_owned(),
            field(&r.run.set.join(" ")),
            r.run.method.clone(),
            r.run.resolution.to_string(),
            r.run.finest_resolution.to_string(),
            r.run.max_level.to_string(),
            r.run.integrator.clone(),
            r.run.dt.clone(),
            field(&r.threads),
            field(&r.status),
            r.walls.len().to_string(),
            num(r.wall_s),
            num(min),
            num(max),
            r.steps.to_string(),
            num(r.mean_vertices),
            num(r.peak_vertices),
            num(r.mean_error),
            num(r.final_error),
            num(r.error),
            r.pareto.to_string(),
        ];
        let _ = writeln!(out, "{}", cells.join(","));
    }
    out
}

/// `STEM-frames.csv`: `label,time,error`, one line per run and frame.
pub fn frames_csv(result: &BenchResult) -> String {
    let mut out = "label,time,error\n".to_owned();
    for r in &result.rows {
        for (t, e) in &r.errors {
            let _ = writeln!(out, "{},{},{}", field(&r.run.label), num(*t), num(*e));
        }
    }
    out
}

/// A relative error in percent with three significant digits (`-` for `NaN`).
pub fn percent(e: Scalar) -> String {
    let p = e * 100.0;
    match p.abs() {
        x if !x.is_finite() => "-".to_owned(),
        0.0 => "0 %".to_owned(),
        x if (1e-3..1e3).contains(&x) => {
            let decimals = (2 - x.log10().floor() as i32).max(0) as usize;
            format!("{p:.decimals$} %")
        }
        _ => format!("{p:.2e} %"),
    }
}

/// `STEM.md`: what was compared and how, and the table of runs.
pub fn markdown(result: &BenchResult) -> String {
    let p = &result.plan;
    let mut s = format!("# Speed against error: {}\n\n", p.scene);
    let _ = writeln!(
        s,
        "Error: RMS distance of {} material points from the reference's, relative to the cloth's diagonal, {}. Simulated time {} s.",
        result
            .reference
            .frames
            .first()
            .map_or(0, |f| f.positions.len()),
        match p.compare {
            super::Compare::Frames => "averaged over the recorded frames",
            super::Compare::Rest => "at the last frame (at rest)",
        },
        p.duration
    );
    let _ = writeln!(
        s,
        "\nReference: `{}` ({:.0} vertices, {} steps, {:.2} s).",
        p.reference.set.join(" "),
        result.reference.mean_vertices,
        result.reference.steps,
        result.reference.wall_s
    );
    if let Some((dt, origin)) = &p.common_dt {
        let _ = writeln!(s, "\nEvery run takes one step, {dt:.4e} s ({origin}).");
    }
    if let Some(m) = result
        .reference_last_motion
        .filter(|_| p.compare == super::Compare::Rest)
    {
        let _ = writeln!(
            s,
            "\nThe reference moved {} over its last frame.",
            percent(m)
        );
    }
    s.push_str(&timing_note(result));
    s.push_str(
        "\n| run | vertices (mean) | steps | wall s (median) | error | final error | status |\n",
    );
    s.push_str("|---|---:|---:|---:|---:|---:|---|\n");
    for r in &result.rows {
        let mark = match (r.run.floor, r.pareto) {
            (true, _) => " (floor)",
            (false, true) => " *",
            _ => "",
        };
        let _ = writeln!(
            s,
            "| {}{mark} | {:.0} | {} | {:.3} ({}) | {} | {} | {} |",
            r.run.label,
            r.mean_vertices,
            r.steps,
            r.wall_s,
            r.walls.len(),
            percent(r.error),
            percent(r.final_error),
            r.status
        );
    }
    s.push_str("\n`*`: on the Pareto front of wall time and error. A floor's error is how close two errors can be and still be told apart.\n");
    let _ = writeln!(s, "\n![chart]({}.svg)", p.stem);
    s
}

/// How the wall times were taken, and a warning when jobs overlapped.
fn timing_note(result: &BenchResult) -> String {
    let p = &result.plan;
    let threads = p
        .threads
        .map_or("the default thread count (one per core)".into(), |n| {
            format!("{n} thread(s)")
        });
    let mut s = format!(
        "\nWall times: median of {} repetition(s), stepping only, with {threads}.",
        p.reps
    );
    if result.concurrent > 0 {
        let _ = write!(
            s,
            " **{} jobs ran at the same time as another**: their wall times shared the machine{}.",
            result.concurrent,
            match p.threads {
                Some(_) => "",
                None => " and its cores, so they are not comparable with each other",
            }
        );
    }
    s.push('\n');
    s
}

/// Writes the CSVs, the report and the chart into `dir`; returns their paths.
pub fn write_all(dir: &Path, result: &BenchResult) -> Result<Vec<PathBuf>, BenchError> {
    let stem = &result.plan.stem;
    let title = format!(
        "{}: error ({}) against wall time",
        result.plan.scene,
        result.plan.compare.name()
    );
    let files = [
        (format!("{stem}.csv"), csv(result)),
        (format!("{stem}-frames.csv"), frames_csv(result)),
        (format!("{stem}.md"), markdown(result)),
        (
            format!("{stem}.svg"),
            chart::svg(&title, &result.rows, result.plan.compare)?,
        ),
    ];
    let mut written = Vec::new();
    for (name, text) in files {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| BenchError::io(&path, e))?;
        written.push(path);
    }
    Ok(written)
}
