//! The benchmark's files: `SCENE.csv` (one row per run), `SCENE-frames.csv`
//! (the error at every recorded frame of every run), `SCENE-samples.csv`
//! (each run's error at every sample point: where the error is, drawn in
//! `SCENE-map.svg`), `SCENE.md` (a Markdown
//! table with the comparison, the step, the reference's settings, the uniform
//! runs' observed order of convergence and the target check) and `SCENE.svg`.
//! The time-step ladder writes the same files as `SCENE-time.*`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::ladder::StepPolicy;
use super::order::{self, Convergence, Variable};
use super::steps::TIME_REFERENCE_DIVISOR;
use super::{BenchError, BenchResult, Floor, Row};
use crate::math::Scalar;

/// The CSV header: the settings, then the measurements. `error` is the one
/// compared (`compare`: `frames`, the mean over the frames; `rest`, the last frame's).
pub const CSV_HEADER: &str = "label,kind,method,resolution,finest_resolution,max_level,refine_angle,coarsen_angle,integrator,multirate,dt,status,reps,wall_s,steps,mean_vertices,peak_vertices,mean_error,final_error,compare,error,pareto,overrides";

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
            r.compare.name().into(),
            num(r.error),
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

/// The per-frame errors: `label,time,error`, then the floors' (labelled by
/// [`super::FloorChange::label`]) when they were measured.
pub fn frames_csv<'a>(rows: &[Row], floors: impl IntoIterator<Item = &'a Floor>) -> String {
    let mut out = String::from("label,time,error\n");
    for r in rows {
        for (t, e) in &r.errors {
            let _ = writeln!(out, "{},{t},{e}", field(&r.label));
        }
    }
    for f in floors {
        let label = f.change.label();
        for (t, e) in &f.errors {
            let _ = writeln!(out, "{},{t},{e}", field(&label));
        }
    }
    out
}

/// Where each run's error is: `u,v` (the sample point in material
/// coordinates, m), then one column per row and per floor (headed by its
/// label) with that point's error relative to the diagonal
/// ([`super::sampling::sample_errors`]: at the last frame at rest, else the
/// RMS over the frames; empty where the point was not found or the run
/// failed).
pub fn samples_csv<'a>(
    points: &[[Scalar; 2]],
    rows: &[Row],
    floors: impl IntoIterator<Item = &'a Floor>,
) -> String {
    let floors: Vec<&Floor> = floors.into_iter().collect();
    let mut out = String::from("u,v");
    let labels = rows
        .iter()
        .map(|r| r.label.clone())
        .chain(floors.iter().map(|f| f.change.label()));
    for label in labels {
        let _ = write!(out, ",{}", field(&label));
    }
    out.push('\n');
    let columns: Vec<&[Scalar]> = rows
        .iter()
        .map(|r| &r.sample_errors[..])
        .chain(floors.iter().map(|f| &f.sample_errors[..]))
        .collect();
    for (i, p) in points.iter().enumerate() {
        let _ = write!(out, "{},{}", p[0], p[1]);
        for c in &columns {
            let _ = write!(out, ",{}", c.get(i).map_or(String::new(), |&e| num(e)));
        }
        out.push('\n');
    }
    out
}

/// A fraction in percent: three decimals, or three significant digits below
/// 0.01 % (so that small errors do not print as 0.000).
pub fn pct(x: Scalar) -> String {
    if x.is_finite() && (100.0 * x).abs() < 0.01 && x != 0.0 {
        format!("{:.2e}", 100.0 * x)
    } else if x.is_finite() {
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
    /// Adaptive error divided by the uniform's (the compared errors).
    pub error_ratio: Scalar,
    /// Adaptive wall time divided by the uniform's.
    pub time_ratio: Scalar,
    /// The smallest and largest ratio of the two runs' wall times taken
    /// repetition by repetition (the sampled runs, then each round's), when
    /// both ran at least twice: how far the machine's drift moves the ratio
    /// within one ladder (`docs/speed-vs-error.md`, "Fifteenth session").
    pub time_ratio_range: Option<(Scalar, Scalar)>,
    /// The error is within 10 % of the uniform run's (or below it).
    pub within_10: bool,
    /// Within 10 % of the uniform's error at a quarter of its wall time or less.
    pub met: bool,
    /// Within 10 % of the uniform's error at a tenth of its wall time or less.
    pub met_tenth: bool,
}

/// The target for every adaptive run that has a uniform counterpart
/// (a uniform run whose resolution equals its finest resolution and that
/// takes the same step setting).
pub fn target_checks(rows: &[Row]) -> Vec<TargetCheck> {
    rows.iter()
        .filter(|r| r.status == "ok" && r.adaptive)
        .filter_map(|a| {
            let u = uniform_counterpart(rows, a)?;
            let error_ratio = a.error / u.error;
            let time_ratio = a.wall_s / u.wall_s;
            let within_10 = error_ratio <= 1.1;
            Some(TargetCheck {
                adaptive: a.label.clone(),
                uniform: u.label.clone(),
                error_ratio,
                time_ratio,
                time_ratio_range: ratio_range(&a.walls, &u.walls),
                within_10,
                met: within_10 && time_ratio <= 0.25,
                met_tenth: within_10 && time_ratio <= 0.1,
            })
        })
        .collect()
}

/// The smallest and largest of `a[k] / u[k]` over the repetitions both have,
/// when they have two or more ([`TargetCheck::time_ratio_range`]).
fn ratio_range(a: &[Scalar], u: &[Scalar]) -> Option<(Scalar, Scalar)> {
    let ratios: Vec<Scalar> = a.iter().zip(u).map(|(a, u)| a / u).collect();
    if ratios.len() < 2 {
        return None;
    }
    let lo = ratios.iter().copied().fold(Scalar::INFINITY, Scalar::min);
    let hi = ratios
        .iter()
        .copied()
        .fold(Scalar::NEG_INFINITY, Scalar::max);
    Some((lo, hi))
}

/// The uniform run (that finished) with the finest edges and the step of the
/// adaptive run `a`, which the target check compares it with.
fn uniform_counterpart<'a>(rows: &'a [Row], a: &Row) -> Option<&'a Row> {
    rows.iter().find(|u| {
        u.status == "ok" && !u.adaptive && u.resolution == a.finest_resolution && u.dt == a.dt
    })
}

/// The lines saying what is compared, at which step, against which reference.
fn preamble(res: &BenchResult, scene_path: &Path) -> String {
    let r = &res.reference;
    let mut out = String::new();
    let title = if res.time_ladder {
        "time-step ladder, "
    } else {
        ""
    };
    let _ = writeln!(
        out,
        "## {} ({title}{:.2} s simulated)\n",
        res.scene, res.duration
    );
    let frames = r.frames.len();
    match res.compare {
        super::Compare::Frames => {
            let _ = writeln!(
                out,
                "Compared frame by frame: the error is the mean over the {frames} recorded frames.\n"
            );
        }
        super::Compare::Rest => {
            let t = r.frames.last().map_or(Scalar::NAN, |f| f.time);
            let _ = writeln!(
                out,
                "Compared at rest: the error is the last frame's (t = {t:.3} s); over its last frame the reference's samples moved {} % of the diagonal.\n",
                res.reference_last_motion
                    .map_or("-".into(), |m| format!("{:.2e}", 100.0 * m))
            );
        }
    }
    if res.time_ladder {
        let _ = writeln!(
            out,
            "One uniform mesh at the scene's step and its halves, against the same mesh at 1/{TIME_REFERENCE_DIVISOR} of the scene's step: the error is the step's.\n"
        );
    } else if let Some((dt, origin)) = &res.common_dt {
        let _ = writeln!(
            out,
            "Time step: {dt:.4e} s ({origin}) for every run and the reference: the error is the mesh's.\n"
        );
    } else if res.step == StepPolicy::Own {
        out.push_str("Time step: each run's own setting (an automatic explicit step follows each mesh): the error includes the step's.\n\n");
    }
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
    let how = compared(res.compare);
    if let Some(f) = &res.floor {
        out.push_str(&floor_text(f, how));
    }
    if let Some(why) = &res.floor_failure {
        let _ = writeln!(
            out,
            "Sensitivity floor: not measured: the reference run started 1 micrometre higher failed ({why}).\n"
        );
    }
    if let Some(f) = &res.mesh_floor {
        out.push_str(&floor_text(f, how));
    }
    if let Some(why) = &res.mesh_floor_failure {
        let _ = writeln!(out, "Mesh floor: not measured ({why}).\n");
    }
    if let Some(f) = &res.pattern_floor {
        out.push_str(&floor_text(f, how));
    }
    if let Some(why) = &res.pattern_floor_failure {
        let _ = writeln!(out, "Pattern floor: not measured ({why}).\n");
    }
    let measured = res.floors().count();
    match res.deciding_floor() {
        Some(f) => {
            let which = if measured > 1 {
                "the larger floor"
            } else {
                "the floor"
            };
            let _ = writeln!(
                out,
                "Differences between runs' errors smaller than {which} ({} %) are not resolved by this comparison: the target table marks a check as decided only where the adaptive run's error and 1.1 times the uniform run's are more than 2.1 times it apart (each may move by the floor).\n",
                pct(f)
            );
        }
        None if measured > 0 => {
            out.push_str("A floor that was asked for is missing: the target table decides no check on the other alone.\n\n");
        }
        None => {}
    }
    out.push_str("Final offset: the length of the mean displacement of the samples from the reference's at the last frame (the rigid translation part of the final error; what is left once it is taken out is `sqrt(final^2 - offset^2)`).\n\n");
    out
}

/// The runs' table.
fn table(rows: &[Row]) -> String {
    let mut out = String::new();
    out.push_str("| run | kind | base res | finest res | integrator | dt s | wall s (median) | reps | steps | mean verts | peak verts | mean error % | final error % | final offset % | Pareto |\n");
    out.push_str("|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|:-:|\n");
    for row in rows {
        let status = if row.status == "ok" {
            String::new()
        } else {
            format!(" ({})", row.status)
        };
        let _ = writeln!(
            out,
            "| {}{} | {} | {} | {} | {}{} | {} | {:.3} | {} | {} | {:.0} | {:.0} | {} | {} | {} | {} |",
            row.label,
            status,
            kind(row),
            row.resolution,
            row.finest_resolution,
            row.integrator,
            if row.multirate { " multirate" } else { "" },
            row.dt
                .parse::<Scalar>()
                .map_or(row.dt.clone(), |dt| format!("{dt:.4e}")),
            row.wall_s,
            row.reps,
            row.steps,
            row.mean_vertices,
            row.peak_vertices,
            pct(row.mean_error),
            pct(row.final_error),
            pct(row.final_offset),
            if row.pareto { "**yes**" } else { "" },
        );
    }
    out
}

/// The convergence paragraph of one series.
pub fn convergence_text(c: &Convergence) -> String {
    let what = match c.variable {
        Variable::EdgeLength => "edge length (1 / resolution)",
        Variable::Step => "time step",
    };
    let mut out = format!(
        "Uniform runs, error against {what} at {}: **observed order {:.2}** (error ~ h^{:.2}, least squares over {} runs; local orders from coarse to fine: {}).\n\n",
        c.fixed,
        c.order,
        c.order,
        c.points.len(),
        c.local
            .iter()
            .map(|p| format!("{p:.2}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    out.push_str("| run | h | error % |\n|---|---:|---:|\n");
    for (label, h, e) in &c.points {
        let _ = writeln!(out, "| {label} | {h:.4e} | {} |", pct(*e));
    }
    out
}

/// Whether a floor decides a target check: each compared error may move by
/// up to the floor against another reference as far from the truth (the
/// triangle inequality), so whether `adaptive` is within 10 % of `uniform`
/// holds for every such reference where the two sides stay apart:
/// `|adaptive - 1.1 uniform| > 2.1 floor`. Before the twelfth sitting the
/// bench called a check decided where the floor was below a tenth of the
/// uniform run's error, whatever the adaptive run's: that left clear misses
/// (five times the error against a floor of 0.6 of it, `drape_sphere`'s
/// contact) undecided, and could call a run on the 10 % line decided.
pub fn floor_decides(adaptive: Scalar, uniform: Scalar, floor: Scalar) -> bool {
    (adaptive - 1.1 * uniform).abs() > 2.1 * floor
}

/// The target paragraph: every adaptive run against its uniform counterpart,
/// and, with the floors measured, whether the larger one, `floor`, decides
/// the 10 % ([`floor_decides`]).
fn targets(rows: &[Row], floor: Option<Scalar>) -> String {
    let checks = target_checks(rows);
    if checks.is_empty() {
        return String::new();
    }
    let mut out = String::from(
        "\nTarget (an adaptive run within 10 % of the error of the uniform run with its finest edges, at <= 1/4 of that run's wall time on every scene, <= 1/10 on two):\n\n| adaptive | uniform | error ratio | within 10 % | wall time ratio | per repetition | <= 1/4 | <= 1/10 | floor / uniform error | decided |\n|---|---|---:|:-:|---:|---:|:-:|:-:|---:|:-:|\n",
    );
    let yes = |b: bool| if b { "**yes**" } else { "no" };
    let error_of = |label: &str| {
        rows.iter()
            .find(|r| r.label == label)
            .map_or(Scalar::NAN, |r| r.error)
    };
    for c in checks {
        let (uniform_error, adaptive_error) = (error_of(&c.uniform), error_of(&c.adaptive));
        let (ratio, decided) = match floor {
            Some(f) => (
                format!("{:.2}", f / uniform_error),
                yes(floor_decides(adaptive_error, uniform_error, f)),
            ),
            None => ("-".into(), "-"),
        };
        let _ = writeln!(
            out,
            "| {} | {} | {:.2} | {} | {:.3} | {} | {} | {} | {ratio} | {decided} |",
            c.adaptive,
            c.uniform,
            c.error_ratio,
            yes(c.within_10),
            c.time_ratio,
            c.time_ratio_range
                .map_or("-".to_owned(), |(lo, hi)| format!("{lo:.3} to {hi:.3}")),
            yes(c.met),
            yes(c.met_tenth)
        );
    }
    out
}

/// The Markdown report of one benchmark: what is compared, the runs, the
/// uniform runs' convergence (before any adaptive comparison) and the target.
pub fn markdown(res: &BenchResult, scene_path: &Path) -> String {
    let mut out = preamble(res, scene_path);
    out.push_str(&table(&res.rows));
    out.push('\n');
    let series: Vec<Convergence> = [order::spatial(&res.rows), order::temporal(&res.rows)]
        .into_iter()
        .flatten()
        .collect();
    if series.is_empty() {
        out.push_str("Convergence: fewer than two uniform runs differing only in resolution or step: no order.\n");
    }
    for c in &series {
        out.push_str(&convergence_text(c));
    }
    out.push_str(&targets(&res.rows, res.deciding_floor()));
    out.push_str(&before_parting(res));
    out.push_str(&shadows(res));
    out
}

/// The frames the mesh decides ([`super::window`]), for a frame-by-frame
/// comparison with the lift floor or the pattern floor: until when the
/// lifted reference and the one with every diagonal turned stay within a
/// tenth of the nearest uniform run, and every run's and floor's mean error
/// over those frames against the uniform run with its finest edges. When
/// one of the two was asked for and its run failed, no window is given on
/// the other alone (as [`BenchResult::deciding_floor`] decides nothing
/// then). Empty otherwise.
fn before_parting(res: &BenchResult) -> String {
    if res.compare != super::Compare::Frames || res.time_ladder {
        return String::new();
    }
    if res.floor_failure.is_some() || res.pattern_floor_failure.is_some() {
        return "\nBefore the runs part: not given: a floor that ends the window was asked for and its run failed, so no window is drawn from the other alone.\n".into();
    }
    let seeds: Vec<&Floor> = res.floor.iter().chain(&res.pattern_floor).collect();
    match seeds.is_empty() {
        false => parting_text(&res.rows, &seeds, res.floors()),
        true => String::new(),
    }
}

/// Who a floor's run is, in the window's sentence.
fn seed_name(f: &Floor) -> String {
    match f.change {
        super::FloorChange::Lift(_) => "the lifted reference".into(),
        super::FloorChange::Resolution(n) => format!("the reference at {n} segments"),
        super::FloorChange::Pattern(_) => format!("the {}", f.change.label()),
    }
}

/// The paragraph and table of [`before_parting`] from the rows, the floors
/// whose per-frame errors end the window (`seeds`: the lift's and the
/// pattern's, the larger at each frame of the first) and every floor
/// measured (`floors`, the seeds included); empty where
/// [`super::window::parting`] gives no answer.
pub fn parting_text<'a>(
    rows: &[Row],
    seeds: &[&Floor],
    floors: impl IntoIterator<Item = &'a Floor>,
) -> String {
    let Some(first) = seeds.first() else {
        return String::new();
    };
    let others: Vec<&[(Scalar, Scalar)]> = seeds[1..].iter().map(|s| s.errors.as_slice()).collect();
    let deciding = super::window::larger_at_each_frame(&first.errors, &others);
    let who = match seeds {
        [one] => seed_name(one),
        _ => format!(
            "{} (the larger at each frame)",
            seeds
                .iter()
                .map(|s| seed_name(s))
                .collect::<Vec<_>>()
                .join(" and ")
        ),
    };
    let stays = if seeds.len() > 1 { "stay" } else { "stays" };
    let is = if seeds.len() > 1 { "are" } else { "is" };
    let ok = |r: &&Row| r.status == "ok";
    let uniform: Vec<&[(Scalar, Scalar)]> = rows
        .iter()
        .filter(ok)
        .filter(|r| !r.adaptive)
        .map(|r| r.errors.as_slice())
        .collect();
    let Some(p) = super::window::parting(&deciding, &uniform) else {
        return String::new();
    };
    let mut out = String::from("\nBefore the runs part: ");
    let Some((t, l, m)) = p.parted else {
        let _ = writeln!(
            out,
            "{who} {stays} below a tenth of the nearest uniform run's error at every frame, so the floors that seed the parting decide nothing by themselves here (`src/bench/window.rs`)."
        );
        return out;
    };
    if p.decided == 0 {
        let _ = writeln!(
            out,
            "{who} {is} {} % from the reference at {t:.3} s, the first frame with anything to decide, against {} % for the nearest uniform run: no frame is decided by the mesh (`src/bench/window.rs`).",
            pct(l),
            pct(m)
        );
        return out;
    }
    let until = p.until;
    let _ = writeln!(
        out,
        "{who} {stays} below a tenth of the nearest uniform run's error until {until:.3} s ({} of {} frames) and {is} {} % from the reference at {t:.3} s, against {} % for the nearest uniform run (`src/bench/window.rs`). The mean error over the frames to {until:.3} s, which the mesh decides (the wall times above are the whole run's: run again with `--duration {until}` for the cost of these frames alone):\n",
        p.frames,
        deciding.len(),
        pct(l),
        pct(m),
    );
    out.push_str(
        "| run | mean error % to then | / uniform with its finest edges |\n|---|---:|---:|\n",
    );
    let mean = |r: &Row| super::window::mean_until(&r.errors, until);
    for r in rows.iter().filter(ok) {
        let ratio = uniform_counterpart(rows, r)
            .filter(|_| r.adaptive)
            .map_or("".into(), |u| format!("{:.2}", mean(r) / mean(u)));
        let _ = writeln!(out, "| {} | {} | {ratio} |", r.label, pct(mean(r)));
    }
    for f in floors {
        let _ = writeln!(
            out,
            "| floor: {} | {} | |",
            f.change.label(),
            pct(super::window::mean_until(&f.errors, until))
        );
    }
    out
}

/// The report's paragraph on one floor, compared `how`.
fn floor_text(f: &Floor, how: &str) -> String {
    let cached = if f.cache_hit { " (cached)" } else { "" };
    let (error, last) = (
        pct(f.error),
        pct(f.errors.last().map_or(Scalar::NAN, |e| e.1)),
    );
    match f.change {
        super::FloorChange::Lift(lift) => format!(
            "Sensitivity floor: the reference run again with the cloth started {lift:.0e} m higher{cached}, moved back down by that lift, is {error} % of the diagonal from the reference ({how}; {last} % at the last frame; as it started, {} %, the lift itself).\n\n",
            pct(f.start),
        ),
        super::FloorChange::Resolution(n) => format!(
            "Mesh floor: the reference's settings on a uniform mesh of {n} segments instead of its own{cached}, is {error} % of the diagonal from the reference ({how}; {last} % at the last frame). Where the mesh decides where folds form, this is as large as the distance between any two fine meshes.\n\n"
        ),
        super::FloorChange::Pattern(p) => format!(
            "Pattern floor: the reference's settings with {} diagonals (every grid square's diagonal turned){cached}, at its own resolution, is {error} % of the diagonal from the reference ({how}; {last} % at the last frame). Where the triangulation seeds where folds form, an adaptive mesh's transitions may move them as far; a uniform rung shares the reference's triangulation.\n\n",
            super::floor::pattern_name(p),
        ),
    }
}

/// How an error is compared, in words.
fn compared(c: super::Compare) -> &'static str {
    match c {
        super::Compare::Frames => "mean over the frames",
        super::Compare::Rest => "at rest",
    }
}

/// The shadow paragraph (module [`super::shadow`]): every run's shadow
/// against the reference's, with the floors' in the same measure; empty where
/// no run has one.
fn shadows(res: &BenchResult) -> String {
    if !res.rows.iter().any(|r| r.shadow_error.is_finite()) {
        return String::new();
    }
    let how = compared(res.compare);
    let mut out = format!(
        "\nShadow (the area of the cloth's projection on the ground plane, from the sample grid, as in the textile drape test; `src/bench/shadow.rs`): its difference from the reference's, relative to the reference's, {how}. It does not compare where each fold lies, only how far the cloth spreads.\n\n| run | wall s | mean verts | shadow error % |\n|---|---:|---:|---:|\n"
    );
    for r in &res.rows {
        let _ = writeln!(
            out,
            "| {} | {:.3} | {:.0} | {} |",
            r.label,
            r.wall_s,
            r.mean_vertices,
            pct(r.shadow_error)
        );
    }
    for f in res.floors() {
        let _ = writeln!(
            out,
            "| floor: {} | | | {} |",
            f.change.label(),
            pct(f.shadow_error)
        );
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
    let stem = &res.stem;
    let files = [
        (format!("{stem}.csv"), csv(&res.rows)),
        (
            format!("{stem}-frames.csv"),
            frames_csv(&res.rows, res.floors()),
        ),
        (
            format!("{stem}-samples.csv"),
            samples_csv(&res.reference.points, &res.rows, res.floors()),
        ),
        (format!("{stem}.md"), markdown(res, scene_path)),
        (
            format!("{stem}.svg"),
            super::chart::svg(stem, &res.rows, res.deciding_floor())?,
        ),
    ];
    let map = super::map::svg(stem, &res.reference.points, &res.rows, res.floors())?;
    let map = map.map(|text| (format!("{stem}-map.svg"), text));
    let mut paths = Vec::new();
    for (name, text) in files.into_iter().chain(map) {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|source| BenchError::Io {
            path: path.clone(),
            source,
        })?;
        paths.push(path);
    }
    Ok(paths)
}
