//! A sampled run: the cloth's world positions at fixed material points at
//! every recorded frame (the input of the error metric), with the run's
//! cost. This is what one bench job writes (`drape run --sample-at POINTS.json
//! --samples-out FILE.json`) and what the collector reads.

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};

use super::BenchError;
use super::metric::{locate_in_panels, relative_rms, sample_positions};
use crate::math::{Scalar, Vector, Vector2};
use crate::mesh::Mesh;
use crate::run::{FrameState, RunError, RunOptions, run_observed};
use crate::scene::Scene;
use crate::summary::Summary;

/// The format tag of a samples file; the collector refuses any other.
pub const SAMPLES_FORMAT: &str = "drape-samples-1";

/// The material points a job samples (`points.json` of a plan).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SamplePoints {
    /// Material coordinates of each point, m (in its panel's pattern).
    pub points: Vec<[Scalar; 2]>,
    /// The garment panel of each point (empty for a cloth in one piece: every
    /// point in panel 0).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub panels: Vec<u16>,
    /// The cloth's diagonal in material space, m (the error's scale).
    pub diagonal: Scalar,
}

impl SamplePoints {
    /// Reads a points file.
    pub fn load(path: &Path) -> Result<SamplePoints, BenchError> {
        read_json(path)
    }

    /// The points as vectors.
    pub fn vectors(&self) -> Vec<Vector2> {
        self.points
            .iter()
            .map(|p| Vector2::from_array(*p))
            .collect()
    }

    /// The panel of each point (all 0 for a cloth in one piece).
    pub fn point_panels(&self) -> Vec<u16> {
        match self.panels.is_empty() {
            true => vec![0; self.points.len()],
            false => self.panels.clone(),
        }
    }
}

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

/// One sampled run: what a bench job writes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Samples {
    /// [`SAMPLES_FORMAT`].
    pub format: String,
    /// drape's version.
    pub version: String,
    /// The scene's `--set` overrides, in order (the collector checks them
    /// against the job's).
    pub overrides: Vec<String>,
    /// `--threads` (`None`: one per core).
    pub threads: Option<usize>,
    /// The cloth's diagonal in material space, m (from the points file).
    pub diagonal: Scalar,
    /// The machine's cores as the run saw them.
    pub cores: usize,
    /// When the run started and finished, seconds since the Unix epoch (the
    /// collector finds jobs that ran at the same time).
    pub started: Scalar,
    /// See `started`.
    pub finished: Scalar,
    /// Wall time of the run without its sampling, s.
    pub wall_s: Scalar,
    /// Steps taken.
    pub steps: u64,
    /// The smallest step, s.
    pub dt: Scalar,
    /// Mean vertices over the recorded frames.
    pub mean_vertices: Scalar,
    /// Peak vertices.
    pub peak_vertices: Scalar,
    /// The numerical failure that stopped the run early, if any.
    pub failure: Option<String>,
    /// When the run came to rest and ended there (`simulation.rest`), s;
    /// `None` when it ran for its whole duration.
    #[serde(default)]
    pub rest_time: Option<Scalar>,
    /// Samples of every frame done.
    pub frames: Vec<FrameSamples>,
}

impl Samples {
    /// Reads a samples file, refusing another format.
    pub fn load(path: &Path) -> Result<Samples, BenchError> {
        let s: Samples = read_json(path)?;
        if s.format != SAMPLES_FORMAT {
            return Err(BenchError::Invalid {
                path: path.to_path_buf(),
                message: format!("format `{}`, expected `{SAMPLES_FORMAT}`", s.format),
            });
        }
        Ok(s)
    }

    /// Writes the file (creating its directory).
    pub fn store(&self, path: &Path) -> Result<(), BenchError> {
        write_json(path, self)
    }
}

/// Samples a run at every recorded frame ([`Sampler::observe`] is the run's
/// frame observer) and makes its samples file ([`Sampler::finish`]).
#[derive(Debug)]
pub struct Sampler<'a> {
    points: &'a SamplePoints,
    at: Vec<Vector2>,
    panels: Vec<u16>,
    frames: Vec<FrameSamples>,
    sampling_s: Scalar,
    started: Scalar,
}

impl<'a> Sampler<'a> {
    /// A sampler of `points`; the run starts now.
    pub fn new(points: &'a SamplePoints) -> Sampler<'a> {
        Sampler {
            points,
            at: points.vectors(),
            panels: points.point_panels(),
            frames: Vec::new(),
            sampling_s: 0.0,
            started: unix_now(),
        }
    }

    /// Samples one recorded frame (its time is taken out of the run's).
    pub fn observe(&mut self, f: &FrameState) {
        let t0 = Instant::now();
        self.frames.push(sample_frame(f, &self.at, &self.panels));
        self.sampling_s += t0.elapsed().as_secs_f64();
    }

    /// The samples file of a run with `overrides` and `threads` that ended
    /// (`Ok`) or stopped on a numerical failure (a result, in `failure`);
    /// `None` for any other error, which leaves no summary.
    pub fn finish(
        self,
        outcome: &Result<Summary, RunError>,
        overrides: &[String],
        threads: Option<usize>,
    ) -> Option<Samples> {
        let (summary, failure) = match outcome {
            Ok(s) => (s, None),
            Err(RunError::Numerical {
                frame,
                time,
                summary,
                ..
            }) => (
                summary.as_ref(),
                Some(format!(
                    "numerical failure in frame {frame} (t = {time:.3} s)"
                )),
            ),
            Err(_) => return None,
        };
        Some(Samples {
            format: SAMPLES_FORMAT.to_owned(),
            version: env!("CARGO_PKG_VERSION").to_owned(),
            overrides: overrides.to_vec(),
            threads,
            diagonal: self.points.diagonal,
            cores: std::thread::available_parallelism().map_or(1, usize::from),
            started: self.started,
            finished: unix_now(),
            wall_s: summary.wall.wall_time_s - self.sampling_s,
            steps: summary.extent.steps,
            dt: summary.stepping.dt,
            mean_vertices: summary.mesh.vertices.mean,
            peak_vertices: summary.mesh.vertices.max,
            failure,
            rest_time: summary
                .checks
                .rest
                .as_ref()
                .filter(|r| r.at_rest)
                .and_then(|r| r.time),
            frames: self.frames,
        })
    }
}

/// Runs `scene` (loaded with `overrides`) as `opts` say, sampling `points`
/// at every recorded frame. A numerical failure is a result, not an error.
pub fn sampled_run(
    scene: &Scene,
    overrides: &[String],
    opts: &RunOptions,
    points: &SamplePoints,
    interrupt: &AtomicBool,
) -> Result<Samples, RunError> {
    let mut sampler = Sampler::new(points);
    let outcome = run_observed(scene, opts, interrupt, &mut |_| {}, &mut |f| {
        sampler.observe(f)
    });
    match (sampler.finish(&outcome, overrides, opts.threads), outcome) {
        (Some(samples), _) => Ok(samples),
        (None, Err(e)) => Err(e),
        (None, Ok(_)) => unreachable!("a run that ended has a summary"),
    }
}

/// Seconds since the Unix epoch.
fn unix_now() -> Scalar {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

/// Samples one frame: locates the points (each in its panel, `panels`) in the
/// frame's mesh by material coordinates and interpolates the world positions.
pub fn sample_frame(f: &FrameState, points: &[Vector2], panels: &[u16]) -> FrameSamples {
    let mesh = Mesh {
        material: f.material.to_vec(),
        triangles: f.triangles.to_vec(),
        levels: Vec::new(),
        edges: Vec::new(),
        pattern: f.pattern.clone(),
    };
    let positions = locate_in_panels(&mesh, points, panels)
        .iter()
        .map(|l| l.map(|l| sample_positions(&mesh, f.positions, &[l])[0].to_array()))
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

/// The error of a run's last frame against the reference's last frame,
/// whatever their times (two runs that ended at rest, each when it came to
/// rest), as `(the run's last time, error)`; `None` without frames or with no
/// sample found in both.
pub fn rest_error(
    run: &[FrameSamples],
    reference: &[FrameSamples],
    diagonal: Scalar,
) -> Option<(Scalar, Scalar)> {
    let (last, reference) = (run.last()?, reference.last()?);
    let aligned = FrameSamples {
        frame: reference.frame,
        time: reference.time,
        ..last.clone()
    };
    Some((last.time, frame_error(&aligned, reference, diagonal)?))
}

/// How far the samples moved between the last two frames, as the relative RMS
/// distance (`None` with fewer than two frames or no sample found in both).
pub fn last_frame_motion(frames: &[FrameSamples], diagonal: Scalar) -> Option<Scalar> {
    let [.., a, b] = frames else {
        return None;
    };
    let b = FrameSamples {
        time: a.time,
        ..b.clone()
    };
    frame_error(&b, a, diagonal)
}

/// Reads a JSON file into `T`.
pub(super) fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, BenchError> {
    let text = std::fs::read_to_string(path).map_err(|e| BenchError::io(path, e))?;
    serde_json::from_str(&text).map_err(|e| BenchError::Invalid {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// Writes `value` as JSON to `path`, creating its directory.
pub(super) fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<(), BenchError> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| BenchError::io(dir, e))?;
    }
    let text = serde_json::to_string(value).map_err(|e| BenchError::io(path, e.into()))?;
    std::fs::write(path, text).map_err(|e| BenchError::io(path, e))
}
