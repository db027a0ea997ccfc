//! The scene file's data model: one struct per TOML section, deserialised by serde.
//!
//! Every key is documented in `docs/scenes.md`. Absent optional sections are not
//! modelled at all (no force, no cost). Ranges are checked in `validate.rs`, which
//! names the key and its line.

use serde::Deserialize;

// The engine's own types, deserialised straight from the file (see `crate::spec`).
use crate::physics::membrane::{Membrane, Orthotropic};
pub use crate::spec::{
    Adapt, AdaptCriterion, AdaptEvery, AdaptMethod, BendingMatrix, BendingModel, BodySurface,
    ClothShape, DEFAULT_THICKNESS, DiagonalPattern, Integrator, Keyframe, KeyframeAfter,
    KeyframeEasing, Measurement, MembraneModel, Obstacle, ObstacleShape, Part, Pin, PinMotion,
    Preconditioner, Refactor, SelfCollision, SequenceFiles, Solver, StiffnessRule,
};

/// A whole scene file.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Name of the scene; the default output file is `NAME.rrd`.
    pub name: String,
    /// Time span, integrator and global forces.
    pub simulation: Simulation,
    /// The cloth's rest shape and where it starts.
    pub cloth: Cloth,
    /// Physical parameters of the fabric.
    pub material: Material,
    /// Pinned regions (`[[pin]]`), none by default.
    #[serde(default)]
    pub pin: Vec<Pin>,
    /// Air drag; absent: no drag is computed.
    pub air: Option<Air>,
    /// Wind; absent: no wind force is computed.
    pub wind: Option<Wind>,
    /// Adaptive meshing; absent (or `method = "none"`): the mesh never changes.
    pub adapt: Option<Adapt>,
    /// Obstacles (`[[obstacle]]`), none by default: no collision pass runs.
    #[serde(default)]
    pub obstacle: Vec<Obstacle>,
    /// Self-collision; absent: the cloth may pass through itself (no cost).
    pub self_collision: Option<SelfCollision>,
    /// The textile measurements made on the end state (`measure`), none by
    /// default; each must apply to the scene (`validate_measure.rs`).
    #[serde(default)]
    pub measure: Vec<Measurement>,
    /// Garment panels (`[[panel]]`, with `shape = "panels"`).
    #[serde(default)]
    pub panel: Vec<PanelTable>,
    /// Garment seams (`[[seam]]`, with `shape = "panels"`).
    #[serde(default)]
    pub seam: Vec<SeamTable>,
    /// Garment attachments (`[[attachment]]`, with `shape = "panels"`): panel
    /// sides held on one side of a plane until a release time.
    #[serde(default)]
    pub attachment: Vec<crate::spec::AttachmentTable>,
    /// Where the recording's 3D views look from; absent: they follow the cloth.
    pub camera: Option<super::CameraTable>,
}

/// `[[panel]]`: one garment panel.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PanelTable {
    /// The panel's name (unique; seams name it).
    pub name: String,
    /// The outline's corners in pattern coordinates `[u, v]`, m (at least 3).
    pub outline: Vec<[f64; 2]>,
    /// Where the pattern's origin goes in the garment's frame, m (flat
    /// placement), or what is added to every wrapped point (with `wrap`).
    #[serde(default)]
    pub position: [f64; 3],
    /// Euler angles in degrees of the flat pattern (not with `wrap`).
    pub rotation: Option<[f64; 3]>,
    /// Wraps the pattern around the garment's vertical axis instead.
    pub wrap: Option<WrapTable>,
    /// The curved sides (the others are straight).
    #[serde(default)]
    pub curves: Vec<crate::spec::SideCurve>,
}

/// `wrap = { radius, angle }` of a panel: around a cylinder about z.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct WrapTable {
    /// Cylinder radius, m (> 0).
    pub radius: f64,
    /// Where the pattern's u = 0 lies, degrees about z from the -y direction.
    #[serde(default)]
    pub angle: f64,
}

/// `[[seam]]`: two panel sides sewn together.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SeamTable {
    /// The seam's name (unique).
    pub name: String,
    /// The first edge: `{ panel = "front", side = 2 }`, or several such
    /// sides joined end to end, `[{ ... }, { ... }]`.
    pub a: crate::spec::SeamEdge,
    /// The second edge, sewn end to start against the first.
    pub b: crate::spec::SeamEdge,
    /// Which way the second side runs against the first.
    #[serde(default)]
    pub direction: crate::spec::SeamDirection,
    /// The sides may differ in length: the longer one is gathered.
    #[serde(default)]
    pub gather: bool,
}

/// `[cloth.sewing]`: how seams are sewn and welded.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SewingTable {
    /// Sewing stiffness per metre of seam, N/m per m (> 0).
    #[serde(default = "default_sewing_stiffness")]
    pub stiffness: f64,
    /// A seam is welded once every sewn pair is closer than this, m (> 0).
    #[serde(default = "default_weld_gap")]
    pub weld_gap: f64,
    /// The largest pull of the sewing springs per metre of seam, N/m (> 0);
    /// absent: no cap.
    #[serde(default)]
    pub max_force: Option<f64>,
    /// Gravity is off while a seam is open, for at most this long from the
    /// start, s (> 0); absent: gravity acts from the start.
    #[serde(default)]
    pub weightless: Option<f64>,
}

impl Default for SewingTable {
    fn default() -> SewingTable {
        SewingTable {
            stiffness: default_sewing_stiffness(),
            weld_gap: default_weld_gap(),
            max_force: None,
            weightless: None,
        }
    }
}

fn default_sewing_stiffness() -> f64 {
    crate::spec::DEFAULT_SEWING_STIFFNESS
}

fn default_weld_gap() -> f64 {
    crate::spec::DEFAULT_WELD_GAP
}

/// `[simulation]`: time span, integrator and global forces.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Simulation {
    /// Simulated duration in seconds (> 0).
    pub duration: f64,
    /// Recorded frames per second (> 0).
    #[serde(default = "default_frame_rate")]
    pub frame_rate: f64,
    /// Time integrator.
    #[serde(default)]
    pub integrator: Integrator,
    /// Time step: `"auto"`, `"adaptive"` or a step in seconds (> 0).
    #[serde(default)]
    pub dt: TimeStep,
    /// The error control of `dt = "adaptive"` (defaults when absent).
    #[serde(default)]
    pub adaptive_dt: Option<AdaptiveDt>,
    /// Gravity in m/s^2; z is up. `[0, 0, 0]` turns gravity off.
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
    /// Relative residual at which the implicit integrator's conjugate gradients stop.
    #[serde(default = "default_cg_tolerance")]
    pub cg_tolerance: f64,
    /// Iteration cap of the implicit integrator's conjugate gradients: a solve that
    /// reaches it without meeting `cg_tolerance` is a failed step (retried with halved
    /// steps, then the run stops).
    #[serde(default = "default_cg_max_iterations")]
    pub cg_max_iterations: u32,
    /// Linear solver of the implicit integrator.
    #[serde(default)]
    pub solver: Solver,
    /// Direct solver: what one factorization costs, counted in preconditioned
    /// iterations; the solver weighs it against the iterations an older factor costs
    /// (`physics::implicit::refactor`).
    #[serde(default = "default_refactor_iterations")]
    pub refactor_iterations: u32,
    /// Direct solver: when it factors its matrix anew.
    #[serde(default)]
    pub refactor: Refactor,
    /// Direct solver: what it factors as the preconditioner of its conjugate
    /// gradients.
    #[serde(default)]
    pub preconditioner: Preconditioner,
    /// Direct solver: which of the shape triangles' bending blocks its matrix
    /// holds.
    #[serde(default)]
    pub bending_matrix: BendingMatrix,
    /// Newton iterations per implicit step (1: the linearised step of Baraff and Witkin).
    #[serde(default = "default_newton_iterations")]
    pub newton_iterations: u32,
    /// Relative residual of the implicit equations at which Newton iterations stop
    /// (used when `newton_iterations` > 1).
    #[serde(default = "default_newton_tolerance")]
    pub newton_tolerance: f64,
    /// Iterations after which an unconverged quasi-Newton step fails (used by
    /// `solver = "quasi_newton"`).
    #[serde(default = "default_quasi_newton_iterations")]
    pub quasi_newton_iterations: u32,
    /// When the run ends at rest (absent: it runs for `duration`).
    #[serde(default)]
    pub rest: Option<crate::spec::Rest>,
}

impl Simulation {
    /// Frames after the initial one: `duration * frame_rate`, rounded, at least 1.
    pub fn frame_count(&self) -> u64 {
        (self.duration * self.frame_rate).round().max(1.0) as u64
    }

    /// Simulated time between two frames, s.
    pub fn frame_interval(&self) -> f64 {
        1.0 / self.frame_rate
    }
}

/// A fixed step in seconds, `"auto"` (a stability estimate) or `"adaptive"`
/// (error control, implicit integrator only).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum TimeStep {
    /// Chosen from the stiffest spring and the lightest mass (see `physics::timestep`).
    #[default]
    Auto,
    /// This step in seconds (rounded down so that a whole number of steps fills a frame).
    Fixed(f64),
    /// Chosen step by step by error control (`[simulation.adaptive_dt]`,
    /// `sim::step_control`).
    Adaptive,
}

/// `[simulation.adaptive_dt]`: the tolerances of `dt = "adaptive"`, in
/// physical units.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AdaptiveDt {
    /// Largest estimated local position error of a step, m: half the distance
    /// between the step's free vertices and where their start velocity alone
    /// would have carried them (backward Euler's local error estimate).
    #[serde(default = "default_adaptive_tolerance")]
    pub tolerance: f64,
    /// Largest depth below an obstacle surface a step may end with, m.
    #[serde(default = "default_adaptive_penetration")]
    pub penetration: f64,
    /// Smallest step, s: a step that still fails its tolerances at this size
    /// fails the frame (retried, then the run stops with the reason).
    #[serde(default = "default_adaptive_min")]
    pub min: f64,
    /// Largest step, s (absent: one frame, 1 / frame_rate).
    #[serde(default)]
    pub max: Option<f64>,
}

impl Default for AdaptiveDt {
    fn default() -> AdaptiveDt {
        AdaptiveDt {
            tolerance: default_adaptive_tolerance(),
            penetration: default_adaptive_penetration(),
            min: default_adaptive_min(),
            max: None,
        }
    }
}

fn default_adaptive_tolerance() -> f64 {
    crate::sim::DEFAULT_STEP_TOLERANCE
}
fn default_adaptive_penetration() -> f64 {
    crate::sim::DEFAULT_STEP_PENETRATION
}
fn default_adaptive_min() -> f64 {
    crate::sim::DEFAULT_MIN_STEP
}

/// `[cloth]`: the rest shape (material space) and the initial placement in the world.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Cloth {
    /// Which generator or loader makes the mesh.
    pub shape: ClothShape,
    /// Rectangle width in m (along material u / local x).
    pub width: Option<f64>,
    /// Rectangle height in m (along material v / local y).
    pub height: Option<f64>,
    /// Disk radius in m.
    pub radius: Option<f64>,
    /// Segments along the longer side (rectangle) or the diameter (disk).
    pub resolution: Option<u32>,
    /// Rectangle only: segments along the shorter side (default: square cells).
    pub short_side_segments: Option<u32>,
    /// Diagonal pattern of the rectangle's grid.
    #[serde(default)]
    pub diagonals: DiagonalPattern,
    /// OBJ file for `shape = "obj"`, relative to the scene file.
    pub path: Option<String>,
    /// Metres per texture-coordinate unit when an OBJ's `vt` become material coordinates.
    #[serde(default = "default_one")]
    pub uv_scale: f64,
    /// World position of the cloth's local origin (the centre of generated shapes), m.
    #[serde(default)]
    pub position: [f64; 3],
    /// Euler angles in degrees (about x, then y, then z); the generated sheet lies in xy.
    #[serde(default)]
    pub rotation: [f64; 3],
    /// Panels: the target edge length of their triangles, m.
    pub max_edge: Option<f64>,
    /// How seams (from `[[seam]]` or an OBJ's `l` elements) are sewn and welded.
    #[serde(default)]
    pub sewing: SewingTable,
}

/// `[material]`: physical fabric parameters, per area, independent of the mesh.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// The measured fabric whose values fill the keys this table does not
    /// write ([`super::presets::FABRICS`]; `None`: no preset).
    pub preset: Option<String>,
    /// Area density in kg/m^2 (> 0).
    pub density: f64,
    /// Stretch stiffness in N/m (> 0): the springs' constant, and the
    /// triangles' isotropic shorthand (`warp = weft = stretch`, `shear =
    /// stretch / 2`).
    pub stretch: f64,
    /// The in-plane force model: `"springs"` or `"triangles"`.
    #[serde(default)]
    pub membrane: MembraneModel,
    /// Tensile stiffness along material u in N/m (> 0; triangles only;
    /// default `stretch`).
    pub warp: Option<f64>,
    /// Tensile stiffness along material v in N/m (> 0; triangles only;
    /// default `stretch`).
    pub weft: Option<f64>,
    /// In-plane shear stiffness in N/m (> 0; triangles only; default
    /// `stretch / 2`).
    pub shear: Option<f64>,
    /// Bending rigidity in N m (>= 0; 0 turns bending off).
    #[serde(default)]
    pub bending: f64,
    /// Bending length in m (> 0), the cantilever test's `c`: an alternative to
    /// `bending` (not both), converted as `B = density * |gravity| * c^3`.
    pub bending_length: Option<f64>,
    /// Stiffness-proportional spring damping in s (>= 0; 0 turns damping off).
    #[serde(default)]
    pub damping: f64,
    /// Bending force model.
    #[serde(default)]
    pub bending_model: BendingModel,
    /// How spring constants follow from the material.
    #[serde(default)]
    pub stiffness_rule: StiffnessRule,
}

impl Material {
    /// The in-plane model with its moduli: the springs, or the triangles with
    /// `warp`, `weft` and `shear` where given and the isotropic shorthand of
    /// `stretch` otherwise.
    pub fn membrane(&self) -> Membrane {
        match self.membrane {
            MembraneModel::Springs => Membrane::Springs,
            MembraneModel::Triangles => {
                let iso = Orthotropic::isotropic(self.stretch);
                Membrane::Triangles(Orthotropic {
                    warp: self.warp.unwrap_or(iso.warp),
                    weft: self.weft.unwrap_or(iso.weft),
                    shear: self.shear.unwrap_or(iso.shear),
                })
            }
        }
    }

    /// The bending rigidity in N m: `bending`, or `density * |gravity| * c^3` when
    /// the bending length `c` is given instead.
    pub fn rigidity(&self, gravity: [f64; 3]) -> f64 {
        match self.bending_length {
            Some(c) => {
                let g = gravity.iter().map(|x| x * x).sum::<f64>().sqrt();
                self.density * g * c * c * c
            }
            None => self.bending,
        }
    }
}

/// `[air]`: drag on the velocity relative to the air (the wind velocity, or still air).
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Air {
    /// Linear drag per area in kg/(m^2 s) (>= 0): `F_i = -drag * A_i * (v_i - v_air)`.
    pub drag: f64,
    /// Air density in kg/m^3 used by the wind force.
    #[serde(default = "default_air_density")]
    pub density: f64,
}

/// `[wind]`: aerodynamic pressure on each triangle from the relative air velocity.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Wind {
    /// Wind velocity in m/s.
    pub velocity: [f64; 3],
    /// Pressure (normal force) coefficient, dimensionless (>= 0).
    #[serde(default = "default_one")]
    pub coefficient: f64,
}

fn default_frame_rate() -> f64 {
    30.0
}
fn default_gravity() -> [f64; 3] {
    [0.0, 0.0, -9.81]
}
fn default_cg_tolerance() -> f64 {
    1e-6
}
fn default_cg_max_iterations() -> u32 {
    500
}
fn default_refactor_iterations() -> u32 {
    7
}
fn default_newton_iterations() -> u32 {
    1
}
fn default_newton_tolerance() -> f64 {
    1e-3
}
fn default_quasi_newton_iterations() -> u32 {
    200
}
fn default_one() -> f64 {
    1.0
}
/// Air density at sea level, kg/m^3.
pub const DEFAULT_AIR_DENSITY: f64 = 1.2;
fn default_air_density() -> f64 {
    DEFAULT_AIR_DENSITY
}

impl<'de> Deserialize<'de> for TimeStep {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = TimeStep;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("\"auto\", \"adaptive\" or a time step in seconds")
            }
            fn visit_str<E: serde::de::Error>(self, s: &str) -> Result<TimeStep, E> {
                if s == "auto" {
                    Ok(TimeStep::Auto)
                } else if s == "adaptive" {
                    Ok(TimeStep::Adaptive)
                } else {
                    Err(E::invalid_value(serde::de::Unexpected::Str(s), &self))
                }
            }
            fn visit_f64<E: serde::de::Error>(self, x: f64) -> Result<TimeStep, E> {
                Ok(TimeStep::Fixed(x))
            }
            fn visit_i64<E: serde::de::Error>(self, x: i64) -> Result<TimeStep, E> {
                Ok(TimeStep::Fixed(x as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, x: u64) -> Result<TimeStep, E> {
                Ok(TimeStep::Fixed(x as f64))
            }
        }
        d.deserialize_any(V)
    }
}
