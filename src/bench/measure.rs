//! One rung of the ladder: a sampled run (its errors against the reference),
//! further timed repetitions, and the row of the report.

use std::sync::atomic::AtomicBool;

use super::ladder::{self, Compare, Rung};
use super::{BenchError, Reference, Row};
use super::{sampling, shadow};
use crate::math::{Scalar, Vector2};
use crate::run::{RunOptions, run};
use crate::scene::{AdaptMethod, Integrator, Scene, TimeStep};

/// A rung measured by its sampled run, waiting for its timed repetitions.
///
/// The bench runs every rung's sampled run first and then the timed
/// repetitions round by round, one of each rung per round
/// ([`super::bench`]), so that a slow spell of the machine (these machines
/// are shared) falls on one repetition of several rungs rather than on every
/// repetition of one: the median then drops it. Before the fifteenth session
/// each rung's repetitions ran back to back (`docs/speed-vs-error.md`,
/// "Fifteenth session", measured why this matters).
#[derive(Debug)]
pub struct Sampled {
    /// The rung's row; `wall_s` and `reps` are set by [`Sampled::finish`].
    pub row: Row,
    /// Wall times so far: the sampled run's stepping time, then each timed run's.
    walls: Vec<Scalar>,
    /// False when the sampled run failed: a failed rung is not timed again.
    timeable: bool,
}

impl Sampled {
    /// True when the rung is timed again (its sampled run did not fail).
    pub fn timeable(&self) -> bool {
        self.timeable
    }

    /// The sampled run's stepping time, s (its sampling excluded).
    pub fn first_wall(&self) -> Scalar {
        self.walls.first().copied().unwrap_or(Scalar::NAN)
    }

    /// Records one more timed run's wall time, s.
    pub fn add_wall(&mut self, wall_s: Scalar) {
        self.walls.push(wall_s);
    }

    /// The row, with the median of the wall times and their number.
    pub fn finish(mut self) -> Row {
        self.row.reps = self.walls.len();
        self.row.walls = self.walls.clone();
        self.row.wall_s = median(&mut self.walls);
        self.row
    }
}

/// Runs `scene` once more, timed only (one repetition of a rung); its wall time, s.
pub fn time_once(
    scene: &Scene,
    run_opts: &RunOptions,
    interrupt: &AtomicBool,
) -> Result<Scalar, BenchError> {
    let s = run(scene, run_opts, interrupt, &mut |_| {})?;
    if s.interrupted {
        return Err(BenchError::Interrupted);
    }
    Ok(s.wall_time_s)
}

/// Runs `rung` (`scene` holds its overrides) once, sampled, and measures its
/// error against `reference` as `compare` says; its timed repetitions follow
/// ([`Sampled`]).
pub fn measure(
    rung: &Rung,
    scene: &Scene,
    reference: &Reference,
    points: &[Vector2],
    compare: Compare,
    run_opts: &RunOptions,
    interrupt: &AtomicBool,
) -> Result<Sampled, BenchError> {
    let first = sampling::sampled_run(scene, run_opts, points, interrupt)?;
    if first.summary.interrupted {
        return Err(BenchError::Interrupted);
    }
    let walls = vec![first.summary.wall_time_s - first.sampling_s];
    let timeable = first.failure.is_none();
    let errors = sampling::run_errors(&first.frames, &reference.frames, reference.diagonal);
    let complete = first.failure.is_none()
        && errors.len() == first.frames.len()
        && errors.len() == reference.frames.len();
    let (mean_error, final_error) = if complete && !errors.is_empty() {
        let mean = errors.iter().map(|e| e.1).sum::<Scalar>() / errors.len() as Scalar;
        (mean, errors.last().map_or(Scalar::NAN, |e| e.1))
    } else {
        (Scalar::NAN, Scalar::NAN)
    };
    let cell = reference.diagonal / shadow::CELLS_PER_DIAGONAL;
    let shadows = shadow::shadow_errors(&first.frames, &reference.frames, cell);
    let shadow_error = if complete && shadows.len() == errors.len() {
        compare.of(shadows.iter().map(|e| e.1))
    } else {
        Scalar::NAN
    };
    let final_offset = match (complete, first.frames.last(), reference.frames.last()) {
        (true, Some(run), Some(r)) if run.frame == r.frame => {
            sampling::frame_offset(run, r, reference.diagonal).unwrap_or(Scalar::NAN)
        }
        _ => Scalar::NAN,
    };
    let status = match (&first.failure, complete) {
        (Some(f), _) => format!("failed: {f}"),
        (None, false) => "failed: frames do not match the reference's".to_owned(),
        (None, true) => "ok".to_owned(),
    };
    let adapt = scene
        .adapt
        .as_ref()
        .filter(|a| a.method != AdaptMethod::None);
    let row = Row {
        label: rung.label.clone(),
        set: rung.set.clone(),
        adaptive: adapt.is_some(),
        method: adapt
            .map_or("none", |a| match a.method {
                AdaptMethod::RedGreen => "red_green",
                AdaptMethod::Edge => "edge",
                AdaptMethod::Tensor => "tensor",
                AdaptMethod::None => "none",
            })
            .to_owned(),
        resolution: scene.cloth.resolution.unwrap_or(0),
        finest_resolution: ladder::finest_resolution(scene),
        max_level: adapt.map_or(0, |a| a.max_level),
        refine_angle: adapt.map_or(Scalar::NAN, |a| a.refine_angle),
        coarsen_angle: adapt.map_or(Scalar::NAN, |a| a.coarsen_angle),
        integrator: integrator_name(scene.simulation.integrator).to_owned(),
        multirate: adapt.is_some_and(|a| a.multirate),
        dt: match scene.simulation.dt {
            TimeStep::Auto => "auto".into(),
            TimeStep::Fixed(dt) => format!("{dt}"),
        },
        status,
        reps: 0,
        wall_s: Scalar::NAN,
        walls: Vec::new(),
        steps: first.summary.steps,
        mean_vertices: first.summary.vertices.mean,
        peak_vertices: first.summary.vertices.max,
        mean_error,
        final_error,
        final_offset,
        compare,
        error: match compare {
            Compare::Frames => mean_error,
            Compare::Rest => final_error,
        },
        errors,
        shadow_error,
        sample_errors: if complete {
            let at_rest = compare == Compare::Rest;
            sampling::sample_errors(
                &first.frames,
                &reference.frames,
                reference.diagonal,
                at_rest,
            )
        } else {
            Vec::new()
        },
        pareto: false,
    };
    Ok(Sampled {
        row,
        walls,
        timeable,
    })
}

/// The integrator's name as scene files spell it.
pub fn integrator_name(i: Integrator) -> &'static str {
    match i {
        Integrator::SymplecticEuler => "symplectic_euler",
        Integrator::Rk4 => "rk4",
        Integrator::Implicit => "implicit",
    }
}

/// Median of `v` (mean of the middle two for an even count; `NaN` if empty).
pub fn median(v: &mut [Scalar]) -> Scalar {
    if v.is_empty() {
        return Scalar::NAN;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}
