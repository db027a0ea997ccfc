//! The ladder of a benchmark: the runs (rungs) to compare, each a list of
//! `--set` overrides applied to the scene, and the reference run's overrides.
//!
//! A ladder file (`drape bench --ladder FILE.toml`) looks like
//!
//! ```toml
//! reference = ["cloth.resolution=128", "simulation.dt=0.002"]  # optional
//!
//! [[rung]]
//! label = "uniform 32"
//! set = ["adapt.method=none", "cloth.resolution=32"]
//!
//! [[rung]]
//! label = "red_green 16 L4"
//! set = ["adapt.method=red_green", "cloth.resolution=16", "adapt.max_level=4"]
//! ```

use std::path::Path;

use serde::Deserialize;

use super::BenchError;
use crate::physics::timestep::IMPLICIT_MAX_DT;
use crate::scene::{AdaptMethod, Integrator, Scene, TimeStep};

/// One run of the ladder.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rung {
    /// Name shown in the table and the chart.
    pub label: String,
    /// `--set` overrides applied to the scene (after the user's own).
    #[serde(default)]
    pub set: Vec<String>,
}

/// The runs of a benchmark and, optionally, the reference's own overrides.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ladder {
    /// Overrides of the reference run (`None`: [`reference_overrides`] decides).
    #[serde(default)]
    pub reference: Option<Vec<String>>,
    /// The runs, in order.
    #[serde(default)]
    pub rung: Vec<Rung>,
}

impl Ladder {
    /// Reads a ladder file.
    pub fn load(path: &Path) -> Result<Ladder, BenchError> {
        let text = std::fs::read_to_string(path).map_err(|source| BenchError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let ladder: Ladder = toml::from_str(&text).map_err(|e| BenchError::Ladder {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        if ladder.rung.is_empty() {
            return Err(BenchError::Ladder {
                path: path.to_path_buf(),
                message: "no `[[rung]]`: the ladder needs at least one run".into(),
            });
        }
        Ok(ladder)
    }

    /// Keeps only the rungs whose labels are in `labels` (in the ladder's order).
    pub fn select(&mut self, labels: &[String]) -> Result<(), BenchError> {
        if let Some(missing) = labels
            .iter()
            .find(|l| !self.rung.iter().any(|r| &r.label == *l))
        {
            return Err(BenchError::UnknownRung {
                label: missing.clone(),
                known: self
                    .rung
                    .iter()
                    .map(|r| r.label.clone())
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
        self.rung.retain(|r| labels.contains(&r.label));
        Ok(())
    }
}

fn rung(label: String, set: &[String]) -> Rung {
    Rung {
        label,
        set: set.to_vec(),
    }
}

/// The default ladder for `scene`: uniform meshes of 16 to 64 segments, and
/// adaptive runs whose finest edges match 32 or 64 segments, with the scene's
/// remeshing method (red-green if it has none), the other method, tighter and
/// looser thresholds, and, for explicit integrators, multirate stepping.
pub fn default_ladder(scene: &Scene) -> Ladder {
    let method = match scene.adapt.as_ref().map(|a| a.method) {
        Some(AdaptMethod::Edge) => "edge",
        _ => "red_green",
    };
    let other = if method == "edge" {
        "red_green"
    } else {
        "edge"
    };
    let mut rungs = Vec::new();
    for res in [16, 32, 48, 64] {
        rungs.push(rung(
            format!("uniform {res}"),
            &[
                "adapt.method=none".into(),
                format!("cloth.resolution={res}"),
            ],
        ));
    }
    let adaptive = |m: &str, res: u32, level: u32, extra: &[&str]| -> Vec<String> {
        let mut set = vec![
            format!("adapt.method={m}"),
            format!("cloth.resolution={res}"),
            format!("adapt.max_level={level}"),
        ];
        if m == "edge" {
            // Rollback is paper A's (red-green only).
            set.push("adapt.rollback=false".into());
        }
        set.extend(extra.iter().map(|s| (*s).to_owned()));
        set
    };
    let tight = ["adapt.refine_angle=8.0", "adapt.coarsen_angle=0.8"];
    let loose = ["adapt.refine_angle=25.0", "adapt.coarsen_angle=3.0"];
    rungs.push(rung(
        format!("{method} 16 L2"),
        &adaptive(method, 16, 2, &[]),
    ));
    rungs.push(rung(
        format!("{method} 16 L4"),
        &adaptive(method, 16, 4, &[]),
    ));
    rungs.push(rung(
        format!("{method} 32 L2"),
        &adaptive(method, 32, 2, &[]),
    ));
    rungs.push(rung(
        format!("{method} 16 L4 tight"),
        &adaptive(method, 16, 4, &tight),
    ));
    rungs.push(rung(
        format!("{method} 16 L4 loose"),
        &adaptive(method, 16, 4, &loose),
    ));
    rungs.push(rung(format!("{other} 16 L4"), &adaptive(other, 16, 4, &[])));
    if scene.simulation.integrator != Integrator::Implicit {
        rungs.push(rung(
            format!("{method} 16 L4 multirate"),
            &adaptive(method, 16, 4, &["adapt.multirate=true"]),
        ));
    }
    Ladder {
        reference: None,
        rung: rungs,
    }
}

/// Segments along the cloth's longer side of the uniform mesh whose edges are
/// as short as the finest edges `scene` can reach: the resolution, doubled
/// for every two levels (a red 1-4 split adds two levels and halves the
/// edges; two edge bisections halve a triangle's edges).
pub fn finest_resolution(scene: &Scene) -> u32 {
    let res = scene.cloth.resolution.unwrap_or(0);
    match &scene.adapt {
        Some(a) if a.method != AdaptMethod::None => res << (a.max_level / 2).min(16),
        _ => res,
    }
}

/// The reference run's overrides: uniform, `resolution` segments (the caller
/// picks one finer than every rung), and a smaller step: half the scene's fixed
/// step, half the implicit integrator's automatic step, or, for the explicit
/// integrators' automatic step, the stability estimate of the finer mesh
/// (already smaller than any rung's).
pub fn reference_overrides(scene: &Scene, resolution: u32) -> Vec<String> {
    let mut set = vec![
        "adapt.method=none".to_owned(),
        "adapt.multirate=false".to_owned(),
        format!("cloth.resolution={resolution}"),
    ];
    match (scene.simulation.dt, scene.simulation.integrator) {
        (TimeStep::Fixed(dt), _) => set.push(format!("simulation.dt={:e}", dt / 2.0)),
        (TimeStep::Auto, Integrator::Implicit) => {
            set.push(format!("simulation.dt={:e}", IMPLICIT_MAX_DT / 2.0));
        }
        (TimeStep::Auto, _) => {}
    }
    set
}
