//! The ladder of a benchmark: the runs (rungs) to compare, each a list of
//! `--set` overrides applied to the scene, the reference's overrides, and the
//! time steps the runs take.
//!
//! A ladder file (`drape bench SCENE --ladder FILE.toml`) looks like
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
//!
//! [[rung]]                              # a sensitivity floor: another fine mesh
//! label = "uniform 96"
//! set = ["adapt.method=none", "cloth.resolution=96"]
//! floor = true
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::BenchError;
use crate::math::Scalar;
use crate::physics::timestep::fit_to_frame;
use crate::physics::{Model, Stepper};
use crate::run::RunError;
use crate::scene::{AdaptMethod, Integrator, Scene, TimeStep};
use crate::world::World;

/// What the error compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
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
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StepPolicy {
    /// Every rung and the reference take one fixed step (the scene's fixed
    /// step, the implicit automatic step, or the explicit automatic step of the
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
    /// A sensitivity floor rather than a candidate: a run as fine as the
    /// reference that differs from it in a way no setting resolves (another
    /// fine mesh, turned diagonals, the cloth lifted 1 um). Its error is how
    /// close two errors may be and still be told apart.
    #[serde(default)]
    pub floor: bool,
}

impl Rung {
    /// A candidate rung.
    pub fn new(label: impl Into<String>, set: Vec<String>) -> Rung {
        Rung {
            label: label.into(),
            set,
            floor: false,
        }
    }
}

/// The runs of a benchmark and, optionally, the reference's own overrides, the
/// comparison and the step policy.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ladder {
    /// Overrides of the reference run (`None`: [`reference_overrides`]).
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
        let text = std::fs::read_to_string(path).map_err(|e| BenchError::io(path, e))?;
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
        let mut labels: Vec<&str> = ladder.rung.iter().map(|r| r.label.as_str()).collect();
        labels.sort_unstable();
        if let Some(w) = labels.windows(2).find(|w| w[0] == w[1]) {
            return Err(format!("two rungs are labelled `{}`", w[0]));
        }
        Ok(ladder)
    }

    /// Keeps only the rungs whose labels are in `labels` (in the ladder's order).
    pub fn select(&mut self, labels: &[String]) -> Result<(), BenchError> {
        if let Some(missing) = labels
            .iter()
            .find(|l| !self.rung.iter().any(|r| &r.label == *l))
        {
            let known: Vec<&str> = self.rung.iter().map(|r| r.label.as_str()).collect();
            return Err(BenchError::UnknownRung {
                label: missing.clone(),
                known: known.join(", "),
            });
        }
        self.rung.retain(|r| labels.contains(&r.label));
        Ok(())
    }
}

/// The default ladder for `scene`: uniform meshes of 16 to 64 segments, and
/// adaptive runs whose finest edges match 32 or 64 segments with the scene's
/// remeshing method (red-green if it has none) and the other of red-green and
/// edge.
pub fn default_ladder(scene: &Scene) -> Ladder {
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
    let mut rung: Vec<Rung> = [16, 32, 48, 64]
        .iter()
        .map(|res| {
            let set = vec![
                "adapt.method=none".into(),
                format!("cloth.resolution={res}"),
            ];
            Rung::new(format!("uniform {res}"), set)
        })
        .collect();
    let adaptive = |m: &str, res: u32, level: u32| {
        let mut set = vec![
            format!("adapt.method={m}"),
            format!("cloth.resolution={res}"),
            format!("adapt.max_level={level}"),
        ];
        if m != "red_green" {
            // Rollback is paper A's, on red-green's hierarchy only, and the
            // strain and obstacle terms are red-green's sizing rule's: off.
            set.push("adapt.rollback=false".into());
            set.push("adapt.refine_strain=0".into());
            set.push("adapt.refine_obstacle=0".into());
        }
        Rung::new(format!("{m} {res} L{level}"), set)
    };
    rung.push(adaptive(method, 16, 2));
    rung.push(adaptive(method, 16, 4));
    rung.push(adaptive(method, 32, 2));
    rung.push(adaptive(other, 16, 4));
    Ladder {
        reference: None,
        compare: None,
        step: None,
        rung,
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
/// segments (finer than every rung). The step is set by the caller.
pub fn reference_overrides(resolution: u32) -> Vec<String> {
    vec![
        "adapt.method=none".to_owned(),
        "adapt.multirate=false".to_owned(),
        format!("cloth.resolution={resolution}"),
    ]
}

/// The steps of the time-step ladder's rungs, as divisors of the scene's step.
pub const TIME_LADDER_DIVISORS: [u32; 3] = [1, 2, 4];

/// The time-step ladder's reference step, as a divisor of the scene's step: 8
/// times below the smallest rung's, so that for a first-order integrator the
/// reference's own error is about 1/8 of that rung's.
pub const TIME_REFERENCE_DIVISOR: u32 = 32;

/// The tolerances of the time-step ladder's adaptive rungs (`dt = "adaptive"`,
/// implicit scenes), m: around the default, each a quarter of the last, so
/// that the step halves from one to the next.
pub const TIME_LADDER_TOLERANCES: [Scalar; 3] = [2e-3, 5e-4, 1.25e-4];

/// The time-step ladder on one uniform mesh (the scene's resolution): rungs at
/// `dt / k` for `k` in [`TIME_LADDER_DIVISORS`], with `implicit` the adaptive
/// step at each of [`TIME_LADDER_TOLERANCES`], and the reference at
/// `dt / TIME_REFERENCE_DIVISOR` on the same mesh. `dt` is the scene's step
/// ([`scene_step`] of the uniform scene).
pub fn time_ladder(dt: Scalar, implicit: bool) -> Ladder {
    let uniform = ["adapt.method=none", "adapt.multirate=false"].map(String::from);
    let mut rung = TIME_LADDER_DIVISORS
        .iter()
        .map(|&k| {
            let h = dt / Scalar::from(k);
            let mut set = uniform.to_vec();
            set.push(dt_override(h));
            let label = match k {
                1 => format!("dt {h:.3e}"),
                _ => format!("dt/{k} {h:.3e}"),
            };
            Rung::new(label, set)
        })
        .collect::<Vec<_>>();
    if implicit {
        rung.extend(TIME_LADDER_TOLERANCES.iter().map(|&tolerance| {
            let mut set = uniform.to_vec();
            set.push("simulation.dt=\"adaptive\"".to_owned());
            set.push(format!("simulation.adaptive_dt.tolerance={tolerance:e}"));
            Rung::new(format!("adaptive {tolerance:e} m"), set)
        }));
    }
    let mut reference = uniform.to_vec();
    reference.push(dt_override(dt / Scalar::from(TIME_REFERENCE_DIVISOR)));
    Ladder {
        reference: Some(reference),
        compare: None,
        step: Some(StepPolicy::Own),
        rung,
    }
}

/// The step `scene` takes, fitted to fill its frames exactly: its fixed step,
/// or its automatic one on its initial mesh (the implicit integrator's cap, or
/// the explicit integrators' stability estimate; without multirate); for an
/// adaptive step, its first proposal (the implicit integrator's cap).
pub fn scene_step(scene: &Scene) -> Result<Scalar, BenchError> {
    let target = match scene.simulation.dt {
        TimeStep::Fixed(dt) => dt,
        TimeStep::Adaptive => crate::sim::step_control::FIRST_STEP,
        TimeStep::Auto => {
            let world = World::from_scene(scene).map_err(RunError::from)?;
            let model = Model::from_scene(scene);
            let mut stepper = Stepper::new(&model, &world);
            stepper.multirate = false;
            stepper.auto_dt(&model, &world)
        }
    };
    Ok(fit_to_frame(target, scene.simulation.frame_interval()).1)
}

/// How `scene` sets its step, in words (for the report).
pub fn step_origin(scene: &Scene) -> &'static str {
    match (scene.simulation.dt, scene.simulation.integrator) {
        (TimeStep::Fixed(_), _) => "the scene's fixed step",
        (TimeStep::Adaptive, _) => "the adaptive step's first proposal (the implicit cap)",
        (TimeStep::Auto, Integrator::Implicit) => "the implicit integrator's automatic step",
        (TimeStep::Auto, _) => "the explicit stability estimate on the reference's mesh",
    }
}

/// The override that sets a step, in a form that reads back to the same number.
pub fn dt_override(dt: Scalar) -> String {
    format!("simulation.dt={dt:e}")
}
