//! The benchmark's files: `SCENE.csv` (one row per run), `SCENE-frames.csv`
//! (the error at every recorded frame of every run), `SCENE.md` (a Markdown
//! table with the reference's settings and the target check) and `SCENE.svg`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::{BenchError, BenchResult, Row};
use crate::math::Scalar;

/// The CSV header: the settings, then the measurements.
pub const CSV_HEADER: &str = "label,kind,method,resolution,finest_resolution,max_level,refine_angle,coarsen_angle,integrator,multirate,dt,status,reps,wall_s,steps,mean_vertices,peak_vertices,mean_error,final_error,pareto,overrides";

/// A number for the CSV: empty when not a number.
fn num(x: Scalar) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        String::new()
    }
}

/// Quotes a CSV field when it holds a comma or a quote.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

/// The CSV text: the header and one line per row.
pub fn csv(rows: &[Row]) -> String {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for r in rows {
        let cells = [
            field(&r.label),
            kind(r).into(),
            r.method.clone(),
            r.resolution.to_string(),
            r.finest_resolution.to_string(),
            r.max_level.to_string(),
            num(r.refine_angle),
            num(r.coarsen_angle),
            r.integrator.clone(),
            r.multirate.to_string(),
            r.dt.clone(),
            field(&r.status),
            r.reps.to_string(),
            num(r.wall_s),
            r.steps.to_string(),
            num(r.mean_vertices),
            num(r.peak_vertices),
            num(r.mean_error),
            num(r.final_error),
            r.pareto.to_string(),
            field(&r.set.join(" ")),
        ];
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    out
}

/// `uniform` or `adaptive`.
pub fn kind(r: &Row) -> &'static str {
    if r.adaptive { "adaptive" } else { "uniform" }
}

/// The per-frame errors: `label,time,error`.
pub fn frames_csv(rows: &[Row]) -> String {
    let mut out = String::from("label,time,error\n");
    for r in rows {
        for (t, e) in &r.errors {
            let _ = writeln!(out, "{},{t},{e}", field(&r.label));
        }
    }
    out
}

fn pct(x: Scalar) -> String {
    if x.is_finite() {
        format!("{:.3}", 100.0 * x)
    } else {
        "-".into()
    }
}

/// One adaptive run against the uniform run with the same finest edges.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetCheck {
    /// The adaptive run.
    pub adaptive: String,
    /// The uniform run it is compared with.
    pub uniform: String,
    /// Adaptive mean error divided by the uniform's.
    pub error_ratio: Scalar,
    /// Adaptive wall time divided by the uniform's.
    pub time_ratio: Scalar,
    /// Error at most the uniform's at a quarter of its wall time or less.
    pub met: bool,
}

/// The target for every adaptive run that has a uniform counterpart
/// (a uniform run whose resolution equals its finest resolution).
pub fn target_checks(rows: &[Row]) -> Vec<TargetCheck> {
    let ok = |r: &&Row| r.status == "ok";
    rows.iter()
        .filter(ok)
        .filter(|r| r.adaptive)
        .filter_map(|a| {
            let u = rows
                .iter()
                .filter(ok)
                .find(|u| !u.adaptive && u.resolution == a.finest_resolution)?;
            let error_ratio = a.mean_error / u.mean_error;
            let time_ratio = a.wall_s / u.wall_s;
            Some(TargetCheck {
                adaptive: a.label.clone(),
                uniform: u.label.clone(),
                error_ratio,
                time_ratio,
                met: error_ratio <= 1.0 && time_ratio <= 0.25,
            })
        })
        .collect()
}

/// The Markdown report of one benchmark.
pub fn markdown(res: &BenchResult, scene_path: &Path) -> String {
    let r = &res.reference;
    let mut out = String::new();
    let _ = writeln!(out, "## {} ({:.2} s simulated)\n", res.scene, res.duration);
    let _ = writeln!(
        out,
        "Reference: `{}` with `{}`: {} vertices, {} steps (smallest step {:.3e} s, {}), {:.1} s wall{}; {} sample points, error relative to the diagonal {:.4} m.\n",
        scene_path.display(),
        r.overrides.join(" "),
        r.vertices,
        r.steps,
        r.dt,
        r.integrator,
        r.wall_s,
        if res.cache_hit { " (cached)" } else { "" },
        r.points.len(),
        r.diagonal,
    );
    out.push_str("| run | kind | base res | finest res | integrator | wall s (median) | reps | steps | mean verts | peak verts | mean error % | final error % | Pareto |\n");
    out.push_str("|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|:-:|\n");
    for row in &res.rows {
        let status = if row.status == "ok" {
            String::new()
        } else {
            format!(" ({})", row.status)
        };
        let _ = writeln!(
            out,
            "| {}{} | {} | {} | {} | {}{} | {:.3} | {} | {} | {:.0} | {:.0} | {} | {} | {} |",
            row.label,
            status,
            kind(row),
            row.resolution,
            row.finest_resolution,
            row.integrator,
            if row.multirate { " multirate" } else { "" },
            row.wall_s,
            row.reps,
            row.steps,
            row.mean_vertices,
            row.peak_vertices,
            pct(row.mean_error),
            pct(row.final_error),
            if row.pareto { "**yes**" } else { "" },
        );
    }
    let checks = target_checks(&res.rows);
    if !checks.is_empty() {
        out.push_str("\nTarget (adaptive error <= the uniform run's with the same finest edges, at <= 1/4 of its wall time):\n\n");
        for c in checks {
            let _ = writeln!(
                out,
                "- {} vs {}: error x{:.2}, wall time x{:.3}: {}",
                c.adaptive,
                c.uniform,
                c.error_ratio,
                c.time_ratio,
                if c.met { "met" } else { "not met" }
            );
        }
    }
    out
}

/// Writes the CSV, per-frame CSV, Markdown and SVG into `dir`; returns their paths.
pub fn write_all(
    dir: &Path,
    res: &BenchResult,
    scene_path: &Path,
) -> Result<Vec<PathBuf>, BenchError> {
    std::fs::create_dir_all(dir).map_err(|source| BenchError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let files = [
        (format!("{}.csv", res.scene), csv(&res.rows)),
        (format!("{}-frames.csv", res.scene), frames_csv(&res.rows)),
        (format!("{}.md", res.scene), markdown(res, scene_path)),
        (
            format!("{}.svg", res.scene),
            super::chart::svg(&res.scene, &res.rows),
        ),
    ];
    let mut paths = Vec::new();
    for (name, text) in files {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|source| BenchError::Io {
            path: path.clone(),
            source,
        })?;
        paths.push(path);
    }
    Ok(paths)
}
