//! The reference run: a uniform mesh finer than every rung (at the rungs' step
//! by default; at a much smaller step on the same mesh for the time-step ladder),
//! computed once and cached under `OUT/cache/` by a hash of the scene text, the
//! overrides, the sampling and drape's version.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use serde::{Deserialize, Serialize};

use super::BenchError;
use super::metric::{diagonal, grid_samples};
use super::sampling::{FrameSamples, sampled_run};
use crate::math::{Scalar, Vector2};
use crate::run::RunOptions;
use crate::scene::Scene;
use crate::world::World;

/// The reference's samples and the settings that produced them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Reference {
    /// Cache key (hex).
    pub key: String,
    /// drape version that computed it.
    pub version: String,
    /// All overrides applied to the scene (the user's, then the reference's).
    pub overrides: Vec<String>,
    /// Vertices of the reference mesh.
    pub vertices: usize,
    /// Steps taken and the smallest step, s.
    pub steps: u64,
    /// Smallest time step, s.
    pub dt: Scalar,
    /// Integrator name.
    pub integrator: String,
    /// Wall time of the reference run, s.
    pub wall_s: Scalar,
    /// Sample points in material coordinates, m.
    pub points: Vec<[Scalar; 2]>,
    /// The cloth's diagonal in material space, m (the error's scale).
    pub diagonal: Scalar,
    /// Samples at every recorded frame.
    pub frames: Vec<FrameSamples>,
}

/// FNV-1a, 64 bits: a hash that is the same on every platform and version.
pub fn fnv1a(parts: &[&str]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for b in part.bytes().chain([0u8]) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// The cache key of a reference: the scene's text, every override, the sample
/// grid and drape's version.
pub fn cache_key(scene_text: &str, overrides: &[String], grid: usize) -> String {
    let grid = grid.to_string();
    let mut parts: Vec<&str> = vec![scene_text, env!("CARGO_PKG_VERSION"), &grid];
    parts.extend(overrides.iter().map(String::as_str));
    format!("{:016x}", fnv1a(&parts))
}

/// Where the reference with `key` for scene `name` is cached under `out_dir`.
pub fn cache_path(out_dir: &Path, name: &str, key: &str) -> PathBuf {
    out_dir.join("cache").join(format!("{name}-{key}.json"))
}

/// Reads a cached reference, if there is a readable one with this key.
pub fn load_cached(path: &Path, key: &str) -> Option<Reference> {
    let text = std::fs::read_to_string(path).ok()?;
    let r: Reference = serde_json::from_str(&text).ok()?;
    (r.key == key).then_some(r)
}

/// Computes the reference for `scene` (already overridden to the reference
/// settings) with a `grid` x `grid` sample grid.
pub fn compute(
    scene: &Scene,
    overrides: Vec<String>,
    key: String,
    grid: usize,
    opts: &RunOptions,
    interrupt: &AtomicBool,
) -> Result<Reference, BenchError> {
    let world = World::from_scene(scene).map_err(crate::run::RunError::from)?;
    let points = grid_samples(&world.mesh, grid);
    let scale = diagonal(&world.mesh);
    let run = sampled_run(scene, opts, &points, interrupt)?;
    if let Some(failure) = run.failure {
        return Err(BenchError::Reference(failure));
    }
    if run.summary.interrupted {
        return Err(BenchError::Interrupted);
    }
    Ok(Reference {
        key,
        version: env!("CARGO_PKG_VERSION").to_owned(),
        overrides,
        vertices: world.x.len(),
        steps: run.summary.steps,
        dt: run.summary.dt,
        integrator: super::integrator_name(scene.simulation.integrator).to_owned(),
        wall_s: run.summary.wall_time_s - run.sampling_s,
        points: points.iter().map(|p| p.to_array()).collect(),
        diagonal: scale,
        frames: run.frames,
    })
}

/// Writes `r` to the cache file `path` (creating its directory).
pub fn store(path: &Path, r: &Reference) -> Result<(), BenchError> {
    let io = |source| BenchError::Io {
        path: path.to_path_buf(),
        source,
    };
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    let text = serde_json::to_string(r).map_err(|e| BenchError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e),
    })?;
    std::fs::write(path, text).map_err(io)
}

impl Reference {
    /// The sample points as vectors.
    pub fn sample_points(&self) -> Vec<Vector2> {
        self.points
            .iter()
            .map(|p| Vector2::from_array(*p))
            .collect()
    }
}
