//! The scene file's data model: one struct per TOML section, deserialised by serde.
//!
//! Every key is documented in `docs/scenes.md`. Absent optional sections are not
//! modelled at all (no force, no cost). Ranges are checked in `validate.rs`, which
//! names the key and its line.

use serde::Deserialize;

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
    /// Time step: `"auto"` or a step in seconds (> 0).
    #[serde(default)]
    pub dt: TimeStep,
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
    /// Direct solver: preconditioned iterations allowed with a factorization from an
    /// earlier step before the matrix is factored anew.
    #[serde(default = "default_refactor_iterations")]
    pub refactor_iterations: u32,
    /// Newton iterations per implicit step (1: the linearised step of Baraff and Witkin).
    #[serde(default = "default_newton_iterations")]
    pub newton_iterations: u32,
    /// Relative residual of the implicit equations at which Newton iterations stop
    /// (used when `newton_iterations` > 1).
    #[serde(default = "default_newton_tolerance")]
    pub newton_tolerance: f64,
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

/// The linear solver of the implicit integrator.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum Solver {
    /// Sparse Cholesky factorization (faer), reused over steps as the preconditioner
    /// of conjugate gradients and refactored when they need more than
    /// `refactor_iterations`.
    #[default]
    Direct,
    /// Matrix-free conjugate gradients with a Jacobi (diagonal) preconditioner.
    Cg,
}

/// The time integrator.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Symplectic (semi-implicit) Euler, paper A.
    SymplecticEuler,
    /// Classic fourth-order Runge-Kutta, paper B.
    Rk4,
    /// Backward Euler with one Newton step solved by conjugate gradients (Baraff-Witkin).
    #[default]
    Implicit,
}

/// A fixed step in seconds, or `"auto"` (a stability estimate).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum TimeStep {
    /// Chosen from the stiffest spring and the lightest mass (see `physics::timestep`).
    #[default]
    Auto,
    /// This step in seconds (rounded down so that a whole number of steps fills a frame).
    Fixed(f64),
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
}

/// How the cloth's mesh is made.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ClothShape {
    /// A `width` x `height` grid of right triangles.
    Rectangle,
    /// A disk of concentric rings of nearly equilateral triangles.
    Disk,
    /// A triangle mesh read from an OBJ file.
    Obj,
}

/// Which diagonal splits each grid square of a rectangle.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum DiagonalPattern {
    /// Every square split along the same diagonal.
    Regular,
    /// Diagonals alternate in a checkerboard, which is more isotropic.
    #[default]
    Alternating,
}

/// `[material]`: physical fabric parameters, per area, independent of the mesh.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Area density in kg/m^2 (> 0).
    pub density: f64,
    /// Stretch stiffness in N/m (> 0).
    pub stretch: f64,
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

/// The bending force model.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum BendingModel {
    /// Per triangle, the curvature tensor from its three edge angles and the
    /// plate energy `(B/2) A |S|^2`: a loaded strip follows the textile
    /// cantilever's rigidity (the heavy elastica) at every resolution.
    #[default]
    ShapeOperator,
    /// Discrete dihedral-angle hinges scaled so that an imposed cylinder has the
    /// right energy (loaded strips are about 20% too soft).
    Dihedral,
    /// Paper A: a spring between the two vertices opposite each interior edge.
    HingeSpring,
}

/// How stretch spring constants are derived.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum StiffnessRule {
    /// From the rest triangles (Van Gelder 1998): resolution independent.
    #[default]
    Consistent,
    /// Paper A: the same constant on every level-0 spring, times 2^(n/2) at level n.
    PaperA,
}

/// `[[pin]]`: a pinned region of the cloth, selected in material space.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Pin {
    /// `corner:top_left|top_right|bottom_left|bottom_right`, `edge:top|bottom|left|right`,
    /// `box` (with `box_min`/`box_max`) or `all`.
    pub region: String,
    /// Lower corner of a `box` region in material coordinates (m).
    pub box_min: Option<[f64; 2]>,
    /// Upper corner of a `box` region in material coordinates (m).
    pub box_max: Option<[f64; 2]>,
    /// How the pinned vertices move.
    #[serde(default)]
    pub motion: PinMotion,
    /// Velocity in m/s for `linear` motion.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Acceleration in m/s^2 for `linear` motion.
    #[serde(default)]
    pub acceleration: [f64; 3],
    /// A point on the rotation axis (world, m) for `circular` motion.
    #[serde(default)]
    pub center: [f64; 3],
    /// Rotation axis for `circular` motion (normalised; must not be zero).
    #[serde(default = "default_axis")]
    pub axis: [f64; 3],
    /// Angular velocity in rad/s for `circular` motion (right-handed about `axis`).
    #[serde(default)]
    pub angular_velocity: f64,
    /// Time in s at which the pin lets go (absent: never).
    pub release_time: Option<f64>,
}

/// How a pin moves.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum PinMotion {
    /// Held in place.
    #[default]
    Fixed,
    /// `x(t) = x0 + velocity t + acceleration t^2 / 2`.
    Linear,
    /// Rotation about `axis` through `center` at `angular_velocity`.
    Circular,
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

/// `[[obstacle]]`: a rigid obstacle the cloth collides with (a parry3d shape).
///
/// The shape is defined in its local frame (round shapes' axes along local z), placed by
/// `position` and `rotation`, and optionally moved: translated at `velocity` and rotated at
/// `angular_velocity` about `axis` through its (moving) `position`.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Obstacle {
    /// Which shape.
    pub shape: ObstacleShape,
    /// Radius in m (sphere, capsule, cylinder).
    pub radius: Option<f64>,
    /// Half the length of the axis in m (capsule: of the segment between the caps; cylinder).
    pub half_height: Option<f64>,
    /// Half the size along local x, y, z in m (box).
    pub half_extents: Option<[f64; 3]>,
    /// Outward normal of a plane in its local frame (plane); the solid is below it.
    #[serde(default = "default_axis")]
    pub normal: [f64; 3],
    /// OBJ file of a `mesh` obstacle, relative to the scene file.
    pub path: Option<String>,
    /// Scale applied to a mesh's coordinates (mesh).
    #[serde(default = "default_one")]
    pub scale: f64,
    /// World position of the local origin (a point on a plane), m.
    #[serde(default)]
    pub position: [f64; 3],
    /// Euler angles in degrees (about x, then y, then z), as for the cloth.
    #[serde(default)]
    pub rotation: [f64; 3],
    /// Static friction coefficient (Coulomb, paper A), >= 0.
    #[serde(default = "default_friction")]
    pub friction_static: f64,
    /// Kinetic friction coefficient, 0 <= kinetic <= static; absent: equal to `friction_static`.
    pub friction_kinetic: Option<f64>,
    /// Cloth thickness against this obstacle, m: vertices are kept this far outside.
    #[serde(default = "default_thickness")]
    pub thickness: f64,
    /// Linear velocity, m/s.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Angular velocity about `axis` through `position`, rad/s (right-handed).
    #[serde(default)]
    pub angular_velocity: f64,
    /// Rotation axis in world coordinates (normalised; not zero when `angular_velocity` is set).
    #[serde(default = "default_axis")]
    pub axis: [f64; 3],
}

/// The shape of an obstacle.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ObstacleShape {
    /// A ball of `radius`.
    Sphere,
    /// A cuboid of `half_extents`.
    Box,
    /// A half-space below the plane through `position` with outward `normal`.
    Plane,
    /// A capsule along local z: `half_height` and `radius`.
    Capsule,
    /// A cylinder along local z: `half_height` and `radius` (a disk on a stand).
    Cylinder,
    /// A triangle mesh from an OBJ file (`path`, `scale`).
    Mesh,
}

/// `[self_collision]`: contacts of the cloth with itself.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SelfCollision {
    /// Distance kept between non-adjacent parts of the cloth, m (> 0).
    #[serde(default = "default_thickness")]
    pub thickness: f64,
    /// Repulsion passes per step (>= 1).
    #[serde(default = "default_self_iterations")]
    pub iterations: u32,
    /// Volino's curvature-based culling of patches that cannot self-intersect.
    #[serde(default = "default_true")]
    pub culling: bool,
    /// Size of the culling patches in material space, m (> 0); absent: about 12 triangles across.
    pub patch_size: Option<f64>,
}

fn default_friction() -> f64 {
    0.5
}
/// Default cloth thickness for obstacle and self contact, m.
pub const DEFAULT_THICKNESS: f64 = 0.003;
fn default_thickness() -> f64 {
    DEFAULT_THICKNESS
}
fn default_self_iterations() -> u32 {
    4
}
fn default_true() -> bool {
    true
}
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
    /// Adapt every this many steps.
    #[serde(default = "default_every")]
    pub every: u32,
    /// Paper A's rollback: redo a step after refining where it bent too far.
    #[serde(default)]
    pub rollback: bool,
    /// Rollbacks allowed per step before the step is accepted as it is.
    #[serde(default = "default_max_rollbacks")]
    pub max_rollbacks: u32,
    /// Paper A's multirate stepping: each level with its own time step.
    #[serde(default)]
    pub multirate: bool,
}

/// The adaptive remeshing method.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum AdaptMethod {
    /// Paper A: hierarchical 1-4 (red) splits closed by 1-2 (green) splits, merging.
    RedGreen,
    /// Paper B: edge splits with local re-triangulation, coarsening by edge collapse.
    Edge,
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
fn default_every() -> u32 {
    1
}
fn default_max_rollbacks() -> u32 {
    3
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
    4
}
fn default_newton_iterations() -> u32 {
    1
}
fn default_newton_tolerance() -> f64 {
    1e-3
}
fn default_one() -> f64 {
    1.0
}
fn default_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
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
                f.write_str("\"auto\" or a time step in seconds")
            }
            fn visit_str<E: serde::de::Error>(self, s: &str) -> Result<TimeStep, E> {
                if s == "auto" {
                    Ok(TimeStep::Auto)
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
