//! Collecting a benchmark: every job's samples read back and checked, each
//! run's error against the reference, the median wall time, the Pareto front.

use std::path::Path;

use super::plan::{Plan, RunPlan};
use super::sampling::{self, FrameSamples, Samples};
use super::{BenchError, Compare};
use crate::math::{Scalar, Vector};

/// One run's result: its plan and measurements.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The run as planned (label, overrides, mesh, method).
    pub run: RunPlan,
    /// `ok`, or why the run failed.
    pub status: String,
    /// Every repetition's wall time without sampling, s, in repetition order.
    pub walls: Vec<Scalar>,
    /// The median of `walls`, s.
    pub wall_s: Scalar,
    /// Worker threads: `--threads`, or `default` (one per core) with the cores.
    pub threads: String,
    /// Steps taken.
    pub steps: u64,
    /// Mean vertices over the recorded frames.
    pub mean_vertices: Scalar,
    /// Peak vertices.
    pub peak_vertices: Scalar,
    /// Mean error over the frames, relative to the diagonal (`NaN` if failed).
    pub mean_error: Scalar,
    /// Error at the last frame (`NaN` if failed).
    pub final_error: Scalar,
    /// The compared error: `mean_error` frame by frame, `final_error` at rest.
    pub error: Scalar,
    /// `(time, error)` at every recorded frame.
    pub errors: Vec<(Scalar, Scalar)>,
    /// On the Pareto front of (wall time, error) among the candidates.
    pub pareto: bool,
}

/// A collected benchmark.
#[derive(Debug, Clone)]
pub struct BenchResult {
    /// The plan collected.
    pub plan: Plan,
    /// One row per run, in plan order (floors last).
    pub rows: Vec<Row>,
    /// The reference's samples.
    pub reference: Samples,
    /// How far the reference's samples moved over its last frame, relative to
    /// the diagonal (whether a scene compared at rest has settled).
    pub reference_last_motion: Option<Scalar>,
    /// Jobs whose run overlapped another job's in time (their wall times
    /// shared the machine).
    pub concurrent: usize,
}

/// Median of `v` (mean of the middle two for an even count; `NaN` if empty).
pub fn median(v: &[Scalar]) -> Scalar {
    let mut v = v.to_vec();
    v.sort_by(|a, b| a.total_cmp(b));
    match v.len() {
        0 => Scalar::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}

/// For each point `(cost, error)`, whether it is on the Pareto front: no other
/// point has a cost and an error both at most its own with one of them smaller.
/// Points with a non-finite coordinate (failed runs) are never on the front and
/// never dominate.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    let finite = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    points
        .iter()
        .map(|p| {
            finite(p)
                && !points
                    .iter()
                    .any(|q| finite(q) && q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1))
        })
        .collect()
}

/// Reads every job's output of the plan in `dir` and measures each run. A
/// job whose output is missing, unreadable or from another plan is an error
/// naming it (all such jobs at once).
pub fn collect(dir: &Path) -> Result<BenchResult, BenchError> {
    let plan = Plan::load(dir)?;
    let reference = read_job(dir, None, &plan.reference_output, &plan.reference.set);
    let mut problems = Vec::new();
    if let Err(why) = &reference {
        problems.push(format!("the reference ({}): {why}", plan.reference_output));
    }
    let mut outputs: Vec<Vec<Samples>> = vec![Vec::new(); plan.runs.len()];
    let mut intervals = Vec::new();
    for job in &plan.jobs {
        if job.run.is_none() {
            continue;
        }
        match read_job(dir, Some(plan.threads), &job.output, &plan.run_of(job).set) {
            Ok(s) => {
                intervals.push((s.started, s.finished));
                if let Some(i) = job.run {
                    outputs[i].push(s);
                }
            }
            Err(why) => problems.push(format!("{}: {why}", plan.job_name(job))),
        }
    }
    let reference = match reference {
        Ok(r) if problems.is_empty() => r,
        _ => return Err(BenchError::Jobs(problems)),
    };
    if plan.jobs.iter().any(|j| j.run.is_none()) {
        intervals.push((reference.started, reference.finished));
    }
    let mut rows: Vec<Row> = plan
        .runs
        .iter()
        .zip(&outputs)
        .map(|(run, reps)| row(run, reps, &reference, plan.compare))
        .collect();
    let candidates: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| match r.run.floor {
            true => (Scalar::NAN, Scalar::NAN),
            false => (r.wall_s, r.error),
        })
        .collect();
    for (row, on) in rows.iter_mut().zip(pareto_front(&candidates)) {
        row.pareto = on;
    }
    let reference_last_motion = sampling::last_frame_motion(&reference.frames, reference.diagonal);
    Ok(BenchResult {
        rows,
        reference,
        reference_last_motion,
        concurrent: overlapping(&intervals),
        plan,
    })
}

/// One job's samples, checked against its overrides and, where given, the
/// plan's `--threads` (a cached reference may come from any thread count:
/// results are the same at every count); why not, in words.
fn read_job(
    dir: &Path,
    threads: Option<Option<usize>>,
    output: &str,
    set: &[String],
) -> Result<Samples, String> {
    let path = dir.join(output);
    if !path.is_file() {
        return Err("its output is missing (the job did not run or did not finish)".into());
    }
    let s = Samples::load(&path).map_err(|e| e.to_string())?;
    if s.overrides != set {
        return Err("its output was written by another plan (its overrides differ)".into());
    }
    if let Some(t) = threads.filter(|t| *t != s.threads) {
        return Err(format!(
            "it ran with --threads {:?}, the plan says {t:?}",
            s.threads
        ));
    }
    Ok(s)
}

/// How many of the `[start, end]` intervals overlap another.
fn overlapping(intervals: &[(Scalar, Scalar)]) -> usize {
    let overlaps = |a: &(Scalar, Scalar), b: &(Scalar, Scalar)| a.0 < b.1 && b.0 < a.1;
    intervals
        .iter()
        .enumerate()
        .filter(|(i, a)| {
            intervals
                .iter()
                .enumerate()
                .any(|(j, b)| *i != j && overlaps(a, b))
        })
        .count()
}

/// A run's row from its repetitions' samples (the first repetition's are
/// compared; every repetition's wall time counts).
fn row(run: &RunPlan, reps: &[Samples], reference: &Samples, compare: Compare) -> Row {
    let diagonal = reference.diagonal;
    let first = &reps[0];
    let shift = Vector::from_array(run.shift);
    let frames: Vec<FrameSamples> = first.frames.iter().map(|f| shifted(f, shift)).collect();
    let errors = sampling::run_errors(&frames, &reference.frames, diagonal);
    let failure = reps.iter().find_map(|s| s.failure.clone());
    let every_frame = errors.len() == frames.len() && errors.len() == reference.frames.len();
    // Runs that end at rest end at frames of their own: at rest, their last
    // frames are compared.
    let both_at_rest =
        compare == Compare::Rest && first.rest_time.is_some() && reference.rest_time.is_some();
    let rest = match both_at_rest {
        true => sampling::rest_error(&frames, &reference.frames, diagonal),
        false => None,
    };
    let complete = failure.is_none() && (every_frame || rest.is_some());
    let mean_error = match complete && every_frame {
        true => Compare::Frames.of(errors.iter().map(|e| e.1)),
        false => Scalar::NAN,
    };
    let final_error = match (complete, rest) {
        (false, _) => Scalar::NAN,
        (true, Some((_, error))) => error,
        (true, None) => Compare::Rest.of(errors.iter().map(|e| e.1)),
    };
    let walls: Vec<Scalar> = reps.iter().map(|s| s.wall_s).collect();
    Row {
        run: run.clone(),
        status: match (failure, complete) {
            (Some(f), _) => format!("failed: {f}"),
            (None, false) => "failed: frames do not match the reference's".to_owned(),
            (None, true) => "ok".to_owned(),
        },
        wall_s: median(&walls),
        walls,
        threads: first
            .threads
            .map_or(format!("default ({} cores)", first.cores), |n| {
                n.to_string()
            }),
        steps: first.steps,
        mean_vertices: first.mean_vertices,
        peak_vertices: first.peak_vertices,
        mean_error,
        final_error,
        error: match compare {
            Compare::Frames => mean_error,
            Compare::Rest => final_error,
        },
        errors,
        pareto: false,
    }
}

/// `f` with `shift` subtracted from every position.
fn shifted(f: &FrameSamples, shift: Vector) -> FrameSamples {
    FrameSamples {
        positions: f
            .positions
            .iter()
            .map(|p| p.map(|q| (Vector::from_array(q) - shift).to_array()))
            .collect(),
        ..f.clone()
    }
}
