//! The ladder of a benchmark: the runs (rungs) to compare, each a list of
//! `--set` overrides applied to the scene, and the reference run's overrides.
//!
//! A ladder file (`drape bench --ladder FILE.toml`) looks like
//!
//! ```toml
//! reference = ["cloth.resolution=128"]  # optional: the reference's own overrides
//! compare = "rest"                      # optional: "frames" (default) or "rest"
//! step = "common"                       # optional: "common" (default) or "own"
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
use crate::math::Scalar;
use crate::scene::{AdaptMethod, Integrator, Scene};

/// What the error compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Compare {
    /// Every recorded frame against the reference's at the same time; the
    /// error is the mean over the frames (dynamic scenes).
    Frames,
    /// The end state only, after the scene has settled; the error is the last
    /// frame's (quasi-static scenes: cantilever, hanging sheet at rest).
    Rest,
}

impl Compare {
    /// The name used in ladder files, on the command line and in the CSV.
    pub fn name(self) -> &'static str {
        match self {
            Compare::Frames => "frames",
            Compare::Rest => "rest",
        }
    }

    /// The compared error of per-frame `errors` (in frame order): their mean,
    /// or the last one at rest; `NaN` when there are none.
    pub fn of(self, errors: impl ExactSizeIterator<Item = Scalar>) -> Scalar {
        let n = errors.len();
        let (sum, last) = errors.fold((0.0, Scalar::NAN), |(s, _), e| (s + e, e));
        match self {
            _ if n == 0 => Scalar::NAN,
            Compare::Frames => sum / n as Scalar,
            Compare::Rest => last,
        }
    }
}

impl std::str::FromStr for Compare {
    type Err = String;
    fn from_str(s: &str) -> Result<Compare, String> {
        match s {
            "frames" => Ok(Compare::Frames),
            "rest" => Ok(Compare::Rest),
            _ => Err(format!("`{s}`: expected `frames` or `rest`")),
        }
    }
}

/// Which time step the runs take.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StepPolicy {
    /// Every rung and the reference take one fixed step (the scene's fixed step,
    /// the implicit automatic step, or the explicit automatic step of the
    /// reference's mesh, the finest of the benchmark): the error is the mesh's.
    Common,
    /// Every run takes its own scene setting (an automatic explicit step then
    /// follows each mesh): realistic costs, but the error mixes in the step's.
    Own,
}

impl StepPolicy {
    /// The name used in ladder files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            StepPolicy::Common => "common",
            StepPolicy::Own => "own",
        }
    }
}

impl std::str::FromStr for StepPolicy {
    type Err = String;
    fn from_str(s: &str) -> Result<StepPolicy, String> {
        match s {
            "common" => Ok(StepPolicy::Common),
            "own" => Ok(StepPolicy::Own),
            _ => Err(format!("`{s}`: expected `common` or `own`")),
        }
    }
}

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

/// The runs of a benchmark and, optionally, the reference's own overrides, the
/// comparison and the step policy.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ladder {
    /// Overrides of the reference run (`None`: [`reference_overrides`] decides).
    #[serde(default)]
    pub reference: Option<Vec<String>>,
    /// What the error compares (`None`: frame by frame, unless the command line says).
    #[serde(default)]
    pub compare: Option<Compare>,
    /// Which step the runs take (`None`: common, unless the command line says).
    #[serde(default)]
    pub step: Option<StepPolicy>,
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
        Ladder::parse(&text).map_err(|message| BenchError::Ladder {
            path: path.to_path_buf(),
            message,
        })
    }

    /// Parses a ladder file's text; the error says what is wrong.
    pub fn parse(text: &str) -> Result<Ladder, String> {
        let ladder: Ladder = toml::from_str(text).map_err(|e| e.to_string())?;
        if ladder.rung.is_empty() {
            return Err("no `[[rung]]`: the ladder needs at least one run".into());
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
/// remeshing method (red-green if it has none), the other method (edge for
/// red-green, red-green for the edge and tensor methods), tighter and looser
/// thresholds, and, for explicit integrators under [`StepPolicy::Own`] and
/// other methods than tensor, multirate stepping (under a common fixed step it would only subdivide
/// that step further: it is a choice of step, not of mesh).
pub fn default_ladder(scene: &Scene, step: StepPolicy) -> Ladder {
    let method = match scene.adapt.as_ref().map(|a| a.method) {
        Some(AdaptMethod::Edge) => "edge",
        Some(AdaptMethod::Tensor) => "tensor",
        _ => "red_green",
    };
    let other = if method == "red_green" {
        "edge"
    } else {
        "red_green"
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
        if m != "red_green" {
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
    // Multirate stepping is paper A's, on red-green's and the edge method's levels.
    if scene.simulation.integrator != Integrator::Implicit
        && step == StepPolicy::Own
        && method != "tensor"
    {
        rungs.push(rung(
            format!("{method} 16 L4 multirate"),
            &adaptive(method, 16, 4, &["adapt.multirate=true"]),
        ));
    }
    Ladder {
        reference: None,
        compare: None,
        step: None,
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

/// The reference run's overrides: uniform, without multirate, `resolution`
/// segments (the caller picks one finer than every rung). The step is not
/// touched here: under [`StepPolicy::Common`] the caller sets one step for
/// every run and the reference; under [`StepPolicy::Own`] the reference keeps
/// the scene's setting.
pub fn reference_overrides(resolution: u32) -> Vec<String> {
    vec![
        "adapt.method=none".to_owned(),
        "adapt.multirate=false".to_owned(),
        format!("cloth.resolution={resolution}"),
    ]
}
