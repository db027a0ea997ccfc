//! `[adapt]`: the adaptive remeshing table, deserialised straight from the
//! scene file, with its defaults.

use serde::Deserialize;

/// `[adapt]`: adaptive refinement and coarsening driven by dihedral angles.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Adapt {
    /// Which remeshing method runs.
    pub method: AdaptMethod,
    /// Upper threshold, degrees: refine where the angle between the normals of the
    /// two triangles at an interior edge exceeds it.
    #[serde(default = "default_refine_angle")]
    pub refine_angle: f64,
    /// Lower threshold, degrees: coarsen where every relevant angle is below it.
    #[serde(default = "default_coarsen_angle")]
    pub coarsen_angle: f64,
    /// Finest level (paper A's levels: a 1-4 split adds 2, a 1-2 split adds 1).
    #[serde(default = "default_max_level")]
    pub max_level: u32,
    /// Shortest edge refinement may create, in material space (m); 0: no limit.
    #[serde(default)]
    pub min_edge_length: f64,
    /// When to adapt: every this many steps (default 4, see `default_every`), or
    /// once per frame.
    #[serde(default = "default_every")]
    pub every: AdaptEvery,
    /// Paper A's rollback: redo a step after refining where it bent too far.
    #[serde(default)]
    pub rollback: bool,
    /// Rollbacks allowed per step before the step is accepted as it is.
    #[serde(default = "default_max_rollbacks")]
    pub max_rollbacks: u32,
    /// Paper A's multirate stepping: each level with its own time step.
    #[serde(default)]
    pub multirate: bool,
    /// What decides where to refine and coarsen: the papers' angle thresholds,
    /// or a target size from the curvature (`src/adapt/sizing.rs`).
    #[serde(default = "default_criterion")]
    pub criterion: AdaptCriterion,
    /// Sizing criterion only: four children merge when their parent would
    /// carry at most `refine_angle / hysteresis` at the measured curvature
    /// (> 1; absent: [`DEFAULT_HYSTERESIS`]; doubled for a parent once per
    /// bounce, `src/adapt/sizing.rs`).
    #[serde(default)]
    pub hysteresis: Option<f64>,
    /// Sizing criterion with red-green only: also split a leaf where the
    /// membrane (Green) strain jumps across one of its edges by more than this
    /// (dimensionless); absent or 0: curvature alone. See `src/adapt/sizing.rs`,
    /// "Strain jumps".
    #[serde(default)]
    pub refine_strain: Option<f64>,
    /// Sizing criterion with red-green only: also split a leaf where one of its
    /// edges leans towards the nearest obstacle by more than this fraction of
    /// its height above it (dimensionless); absent or 0: no obstacle term. See
    /// `src/adapt/proximity.rs`.
    #[serde(default)]
    pub refine_obstacle: Option<f64>,
    /// Red-green only: how the children of red splits are triangulated
    /// (absent: [`RedDiagonals::Alternating`]). See `src/adapt/red_green/mesh.rs`,
    /// "Alternating diagonals".
    #[serde(default)]
    pub diagonals: Option<RedDiagonals>,
    /// Red-green only: apply an adaptation pass only when its operations would
    /// replace at least this fraction of the mesh's triangles, or when one of
    /// its splits is urgent (`urgent_ratio`); a deferred pass changes nothing.
    /// 0 (the default): every pass is applied. See `src/adapt/gate.rs`.
    #[serde(default)]
    pub min_change: f64,
    /// With `min_change`: a pass with a split whose criterion reads at least
    /// this ratio (1: at the threshold) is applied whatever its size
    /// ([`DEFAULT_URGENT_RATIO`] unless set).
    #[serde(default = "default_urgent_ratio")]
    pub urgent_ratio: f64,
}

/// The urgent ratio of the remesh gate when a scene does not set
/// `adapt.urgent_ratio`: a triangle twice as coarse as its target is refined
/// at the next pass.
pub const DEFAULT_URGENT_RATIO: f64 = 2.0;

fn default_urgent_ratio() -> f64 {
    DEFAULT_URGENT_RATIO
}

/// How the simulation mesh triangulates the children of a red (1-4) split.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum RedDiagonals {
    /// The diagonal of the square at a right (or obtuse) corner of a split
    /// triangle is flipped, so that a refined grid alternates its diagonals
    /// like the uniform grid of the same edge length (and is that grid where
    /// refined everywhere).
    #[default]
    Alternating,
    /// The four children exactly as the split made them (paper A): inside a
    /// split grid square every diagonal runs the same way.
    AsSplit,
}

/// The hysteresis of the sizing criterion when `[adapt]` does not set it.
pub const DEFAULT_HYSTERESIS: f64 = 2.0;

/// What decides where an adaptive mesh refines and coarsens.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum AdaptCriterion {
    /// The papers' criterion, exactly: refine where the angle between the
    /// normals at an edge exceeds `refine_angle`, coarsen where every angle
    /// around is below `coarsen_angle` (and half of `refine_angle`).
    Angle,
    /// Curvature sizing: the curvature (dihedral angle per unit length) gives
    /// each triangle a target size that carries `refine_angle`; refine what is
    /// coarser than its target, merge what would still be finer than it by the
    /// factor `hysteresis`.
    Sizing,
}

/// A textile measurement a scene asks for (`measure`), made on its end state.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Measurement {
    /// The cantilever bending test (Peirce 1930, ASTM D1388): a rectangle held
    /// over one end by fixed pins, under gravity alone ([`crate::cantilever`]).
    Cantilever,
    /// The Cusick drape test: a disk specimen on a vertical support cylinder
    /// centred under it (`crate::collide::cusick`).
    Cusick,
}

impl std::fmt::Display for Measurement {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Measurement::Cantilever => "cantilever",
            Measurement::Cusick => "cusick",
        })
    }
}

/// The adaptive remeshing method.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum AdaptMethod {
    /// Paper A: hierarchical 1-4 (red) splits closed by 1-2 (green) splits, merging.
    RedGreen,
    /// Paper B: edge splits with local re-triangulation, coarsening by edge collapse.
    Edge,
    /// Whole grid lines of a rectangle inserted and removed (anisotropic,
    /// axis-aligned: `src/adapt/tensor.rs`), for sheets bent about an axis.
    Tensor,
    /// No adaptation (the same as leaving `[adapt]` out).
    None,
}

fn default_refine_angle() -> f64 {
    15.0
}
fn default_coarsen_angle() -> f64 {
    1.5
}
fn default_max_level() -> u32 {
    4
}
/// Every 4 steps: on
/// `tablecloth` adapting every step took 3.3 times the steps (retried frames)
/// and 3.2 times the wall time of every 4; on `hanging_sheet` and
/// `drape_sphere` every 4 had the same or a lower error than every step.
fn default_every() -> AdaptEvery {
    AdaptEvery::Steps(4)
}

/// When the adaptation pass runs (`adapt.every`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AdaptEvery {
    /// After every this many accepted steps (`every = 4`).
    Steps(u32),
    /// Once per frame, after the frame's last step (`every = "frame"`), as
    /// ARCSim does.
    Frame,
}

impl AdaptEvery {
    /// True when the pass runs after accepted step number `steps_done`.
    pub fn after_step(self, steps_done: u64) -> bool {
        match self {
            AdaptEvery::Steps(n) => {
                debug_assert!(n > 0, "adapt.every = 0 passed validation");
                steps_done.is_multiple_of(n.max(1) as u64)
            }
            AdaptEvery::Frame => false,
        }
    }
}

impl std::fmt::Display for AdaptEvery {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AdaptEvery::Steps(1) => f.write_str("every step"),
            AdaptEvery::Steps(n) => write!(f, "every {n} steps"),
            AdaptEvery::Frame => f.write_str("once per frame"),
        }
    }
}

impl<'de> Deserialize<'de> for AdaptEvery {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = AdaptEvery;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an integer >= 1 (steps) or \"frame\"")
            }
            fn visit_str<E: serde::de::Error>(self, s: &str) -> Result<AdaptEvery, E> {
                if s == "frame" {
                    Ok(AdaptEvery::Frame)
                } else {
                    Err(E::invalid_value(serde::de::Unexpected::Str(s), &self))
                }
            }
            fn visit_i64<E: serde::de::Error>(self, x: i64) -> Result<AdaptEvery, E> {
                u32::try_from(x)
                    .map(AdaptEvery::Steps)
                    .map_err(|_| E::invalid_value(serde::de::Unexpected::Signed(x), &self))
            }
            fn visit_u64<E: serde::de::Error>(self, x: u64) -> Result<AdaptEvery, E> {
                u32::try_from(x)
                    .map(AdaptEvery::Steps)
                    .map_err(|_| E::invalid_value(serde::de::Unexpected::Unsigned(x), &self))
            }
        }
        d.deserialize_any(V)
    }
}

fn default_max_rollbacks() -> u32 {
    3
}

/// Sizing: fewer vertices
/// than the angle criterion on every measured scene.
fn default_criterion() -> AdaptCriterion {
    AdaptCriterion::Sizing
}
