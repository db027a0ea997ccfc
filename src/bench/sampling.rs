//! Running a scene while sampling the cloth at fixed material points every
//! recorded frame (the input of the error metric).

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::metric::{locate, relative_offset, relative_rms, sample_positions};
use crate::math::{Scalar, Vector, Vector2};
use crate::mesh::Mesh;
use crate::run::{FrameState, Progress, RunError, RunOptions, run_observed};
use crate::scene::Scene;
use crate::summary::Summary;

/// The world positions of the sample points at one recorded frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrameSamples {
    /// Frame index (0: the initial state).
    pub frame: u64,
    /// Simulated time, s.
    pub time: Scalar,
    /// World position of each sample point, m (`None`: not found in the mesh).
    pub positions: Vec<Option<[Scalar; 3]>>,
}

/// A run's outcome with its samples.
#[derive(Debug, Clone)]
pub struct SampledRun {
    /// The run's summary (also for a run that failed numerically).
    pub summary: Summary,
    /// Samples of every frame done.
    pub frames: Vec<FrameSamples>,
    /// Wall time spent sampling (to subtract from the run's wall time), s.
    pub sampling_s: Scalar,
    /// The numerical failure that stopped the run early, if any.
    pub failure: Option<String>,
}

/// Runs `scene` without recording, sampling `points` (material coordinates)
/// at every recorded frame.
pub fn sampled_run(
    scene: &Scene,
    opts: &RunOptions,
    points: &[Vector2],
    interrupt: &AtomicBool,
) -> Result<SampledRun, RunError> {
    let mut frames = Vec::new();
    let mut sampling_s = 0.0;
    let mut observe = |f: &FrameState| {
        let t0 = Instant::now();
        frames.push(sample_frame(f, points));
        sampling_s += t0.elapsed().as_secs_f64();
    };
    let outcome = run_observed(scene, opts, interrupt, &mut |_: Progress| {}, &mut observe);
    let (summary, failure) = match outcome {
        Ok(s) => (s, None),
        Err(RunError::Numerical {
            frame,
            time,
            summary,
            ..
        }) => (
            *summary,
            Some(format!(
                "numerical failure in frame {frame} (t = {time:.3} s)"
            )),
        ),
        Err(e) => return Err(e),
    };
    Ok(SampledRun {
        summary,
        frames,
        sampling_s,
        failure,
    })
}

/// Samples one frame: locates the points in the frame's mesh by material
/// coordinates and interpolates the world positions.
pub fn sample_frame(f: &FrameState, points: &[Vector2]) -> FrameSamples {
    let mesh = Mesh {
        material: f.material.to_vec(),
        triangles: f.triangles.to_vec(),
        levels: Vec::new(),
        edges: Vec::new(),
    };
    let located = locate(&mesh, points);
    let positions = located
        .iter()
        .map(|l| {
            l.map(|l| {
                let p = sample_positions(&mesh, f.positions, &[l])[0];
                p.to_array()
            })
        })
        .collect();
    FrameSamples {
        frame: f.frame,
        time: f.sim_time,
        positions,
    }
}

/// The samples found in both frames, as `(run, reference)` positions, or
/// `None` when the frames' times differ or no sample is found in both.
pub fn matched(run: &FrameSamples, reference: &FrameSamples) -> Option<(Vec<Vector>, Vec<Vector>)> {
    let dt = (run.time - reference.time).abs();
    if dt > 1e-9 * reference.time.abs().max(1.0) {
        return None;
    }
    let (a, b): (Vec<Vector>, Vec<Vector>) = run
        .positions
        .iter()
        .zip(&reference.positions)
        .filter_map(|(p, q)| Some((Vector::from_array((*p)?), Vector::from_array((*q)?))))
        .unzip();
    (!a.is_empty()).then_some((a, b))
}

/// The error of one frame against the reference's frame: the relative RMS
/// distance over the samples found in both, or `None` when the frames' times
/// differ or no sample is found in both.
pub fn frame_error(
    run: &FrameSamples,
    reference: &FrameSamples,
    diagonal: Scalar,
) -> Option<Scalar> {
    matched(run, reference).map(|(a, b)| relative_rms(&a, &b, diagonal))
}

/// The offset of one frame against the reference's frame
/// ([`super::metric::relative_offset`] over the samples found in both), with the
/// same conditions as [`frame_error`].
pub fn frame_offset(
    run: &FrameSamples,
    reference: &FrameSamples,
    diagonal: Scalar,
) -> Option<Scalar> {
    matched(run, reference).map(|(a, b)| relative_offset(&a, &b, diagonal))
}

/// Per-frame errors of a run against the reference (matched by frame index;
/// frames without a counterpart are left out), as `(time, error)`.
pub fn run_errors(
    run: &[FrameSamples],
    reference: &[FrameSamples],
    diagonal: Scalar,
) -> Vec<(Scalar, Scalar)> {
    run.iter()
        .filter_map(|f| {
            let r = reference.iter().find(|r| r.frame == f.frame)?;
            Some((f.time, frame_error(f, r, diagonal)?))
        })
        .collect()
}

/// How far the samples moved between the last two frames, as the relative RMS
/// distance (`None` with fewer than two frames or no sample found in both).
pub fn last_frame_motion(frames: &[FrameSamples], diagonal: Scalar) -> Option<Scalar> {
    let [.., a, b] = frames else {
        return None;
    };
    let (p, q): (Vec<Vector>, Vec<Vector>) = a
        .positions
        .iter()
        .zip(&b.positions)
        .filter_map(|(p, q)| Some((Vector::from_array((*p)?), Vector::from_array((*q)?))))
        .unzip();
    (!p.is_empty()).then(|| relative_rms(&p, &q, diagonal))
}

/// Each sample point's error against the reference, relative to the diagonal:
/// its distance from the reference's sample at the last frame (`at_rest`), or
/// the RMS of that distance over the frames matched by number and time
/// (otherwise); `NaN` for a point that no pair of frames holds in both. Where
/// the error of [`run_errors`] is, for `drape bench`'s `SCENE-samples.csv`.
pub fn sample_errors(
    run: &[FrameSamples],
    reference: &[FrameSamples],
    diagonal: Scalar,
    at_rest: bool,
) -> Vec<Scalar> {
    let n = reference.first().map_or(0, |r| r.positions.len());
    let same_time = |a: &FrameSamples, b: &FrameSamples| {
        a.frame == b.frame && (a.time - b.time).abs() <= 1e-9 * b.time.abs().max(1.0)
    };
    let pairs: Vec<(&FrameSamples, &FrameSamples)> = if at_rest {
        run.last().zip(reference.last()).into_iter().collect()
    } else {
        run.iter()
            .filter_map(|f| Some((f, reference.iter().find(|r| r.frame == f.frame)?)))
            .collect()
    };
    let pairs: Vec<_> = pairs.into_iter().filter(|(a, b)| same_time(a, b)).collect();
    (0..n)
        .map(|i| {
            let (mut sum, mut count) = (0.0, 0usize);
            for (a, b) in &pairs {
                let p = a.positions.get(i).copied().flatten();
                let q = b.positions.get(i).copied().flatten();
                if let (Some(p), Some(q)) = (p, q) {
                    sum += Vector::from_array(p).distance_squared(Vector::from_array(q));
                    count += 1;
                }
            }
            if count == 0 {
                Scalar::NAN
            } else {
                (sum / count as Scalar).sqrt() / diagonal
            }
        })
        .collect()
}
