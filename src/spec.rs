//! Engine specifications: what the engine (`mesh`, `physics`, `collide`, `adapt`,
//! `world`) is built from.
//!
//! The engine owns these types; [`crate::scene`] re-exports them and resolves a scene
//! file into them (`scene::resolve`), so the dependency runs one way: `scene` uses the
//! engine, no engine module imports `crate::scene`. The enums and the pin, obstacle,
//! self-collision and adaptivity tables are deserialised straight from the scene file
//! (their serde derives and defaults are here, so a key's spelling and default are
//! defined once); ranges are checked by the scene's validation before the engine sees
//! them. [`ClothSpec`] is the cloth table resolved: the keys its shape needs, present.

use serde::Deserialize;

mod adapt;
mod attachment;
mod curve;
mod garment;
mod obstacle_spec;
mod part;
mod pin;
mod rest;
mod sequence;
pub use adapt::{
    Adapt, AdaptCriterion, AdaptEvery, AdaptMethod, DEFAULT_HYSTERESIS, DEFAULT_URGENT_RATIO,
    Measurement, RedDiagonals,
};
pub use attachment::{Attachment, AttachmentTable, DEFAULT_ATTACHMENT_STIFFNESS, HoldSpec};
pub use curve::{Curve, SideCurve};
pub use garment::{
    DEFAULT_SEWING_STIFFNESS, DEFAULT_WELD_GAP, Garment, Gather, PanelSpec, Placement,
    SeamDirection, SeamEdge, SeamSide, SeamSpec, Sewing,
};
pub use obstacle_spec::{
    Geometry, ObstacleMotion, ObstacleSpec, ObstacleSpecError, PartSpec, Primitive,
};
pub use part::Part;
pub use pin::{Pin, PinMotion};
pub use rest::Rest;
pub use sequence::{BodySurface, SequenceFiles};

/// The cloth's rest mesh and its placement in the world, resolved from `[cloth]`.
#[derive(Debug, Clone, PartialEq)]
pub struct ClothSpec {
    /// How the rest mesh is made.
    pub mesh: ClothMesh,
    /// World position of the cloth's local origin (the centre of generated shapes), m.
    pub position: [f64; 3],
    /// Euler angles in degrees (about x, then y, then z); the generated sheet lies in xy.
    pub rotation: [f64; 3],
}

/// How the cloth's rest mesh is made, with the sizes its shape needs.
#[derive(Debug, Clone, PartialEq)]
pub enum ClothMesh {
    /// A `width` x `height` grid of right triangles.
    Rectangle {
        /// m.
        width: f64,
        /// m.
        height: f64,
        /// Segments along the longer side.
        resolution: u32,
        /// Segments along the shorter side (`None`: square cells).
        short_side_segments: Option<u32>,
        /// Which diagonal splits each grid square.
        diagonals: DiagonalPattern,
    },
    /// A disk of concentric rings of nearly equilateral triangles.
    Disk {
        /// m.
        radius: f64,
        /// Segments along the diameter.
        resolution: u32,
    },
    /// An OBJ file (path already resolved) with its texture coordinates scaled.
    Obj {
        /// The file.
        path: String,
        /// Metres per texture-coordinate unit (the `vt` become material coordinates).
        uv_scale: f64,
    },
    /// A garment: panels cut from outlines and sewn at seams.
    Panels(Garment),
}

/// The linear solver of the implicit integrator.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum Solver {
    /// Sparse Cholesky factorization (faer), reused over steps as the preconditioner
    /// of conjugate gradients and refactored when the iterations an older factor
    /// costs outweigh a factorization (worth `refactor_iterations` of them).
    #[default]
    Direct,
    /// Matrix-free conjugate gradients with a Jacobi (diagonal) preconditioner.
    Cg,
    /// L-BFGS on the backward Euler equations, the scalar Laplacian factor as
    /// its initial Hessian, with a line search (Liu, Bouaziz and Kavan 2017).
    QuasiNewton,
}

/// When the direct solver factors its matrix anew (`docs/model.md`, "The linear
/// solver").
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum Refactor {
    /// Weigh a factorization (worth `refactor_iterations` iterations) against the
    /// iterations an older factor costs, at the start of a solve and during it.
    #[default]
    Cost,
    /// Factor this solve's matrix at the start of every solve.
    EverySolve,
    /// Factor the first matrix of each mesh and keep it as the preconditioner
    /// until the mesh changes (or a solve with it reaches the iteration cap).
    PerMesh,
}

/// What the direct solver factors as the preconditioner of its conjugate
/// gradients (`docs/model.md`, "The linear solver").
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum Preconditioner {
    /// The 3x3-block Cholesky factor of the system matrix, in double precision.
    #[default]
    Factor,
    /// The same factor with its values in single precision.
    FactorSingle,
    /// One scalar factor of a weighted graph Laplacian plus the mass, applied
    /// to x, y and z alike.
    Laplacian,
}

/// What the direct solver's matrix holds of the shape triangles' bending
/// blocks (`docs/model.md`, "The shape triangles' matrix").
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum BendingMatrix {
    /// The blocks between vertices joined by a mesh edge (the first ring);
    /// each second-ring block is lumped onto its two vertices' diagonal
    /// blocks as a positive semi-definite rank-one pair, so that the matrix
    /// stays positive definite and at least as stiff as the exact one.
    FirstRing,
    /// Every block of the Gauss-Newton Hessian `J^T M J`, the second ring too.
    #[default]
    Exact,
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
    /// Garment panels from `[[panel]]` outlines, sewn at `[[seam]]`s.
    Panels,
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
    /// The same checkerboard with every square's diagonal turned (the other
    /// parity): an equally isotropic triangulation of the same grid, whose
    /// diagonals meet where the alternating one's do not (`drape bench
    /// --pattern-floor` compares the two).
    AlternatingFlipped,
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

/// The in-plane (stretch and shear) force model (`material.membrane`).
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum MembraneModel {
    /// One spring per edge from `stretch` (the papers' model): its response
    /// depends on the triangulation.
    #[default]
    Springs,
    /// Constant-strain triangles in material coordinates with orthotropic
    /// moduli (warp, weft, shear): the continuum on every triangulation.
    Triangles,
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

/// `[[obstacle]]`: a rigid obstacle the cloth collides with (a parry3d shape).
///
/// The shape is defined in its local frame (round shapes' axes along local z), placed by
/// `position` and `rotation`, and optionally moved: translated at `velocity` and rotated at
/// `angular_velocity` about `axis` through its (moving) `position`.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Obstacle {
    /// The name pins attach to (`[[pin]] attach`), unique among the scene's
    /// obstacles; absent: no pin can attach to it.
    pub name: Option<String>,
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
    /// Keyframed motion instead of `velocity` and `angular_velocity`: poses
    /// relative to the placement at rest, at increasing times (at least two;
    /// none: no keyframes). See `src/kinematics/motion.rs`.
    #[serde(default)]
    pub keyframes: Vec<Keyframe>,
    /// How poses between keyframes are interpolated.
    #[serde(default)]
    pub easing: KeyframeEasing,
    /// What the obstacle does after its last keyframe.
    #[serde(default)]
    pub after_last: KeyframeAfter,
    /// The parts of an `articulated` obstacle (`[[obstacle.part]]`), whose
    /// root frame is the obstacle's own (placed and keyframed as any obstacle).
    #[serde(default)]
    pub part: Vec<Part>,
    /// How an `articulated` obstacle meets the cloth: rigid parts, or one
    /// mesh skinned to them.
    #[serde(default)]
    pub surface: BodySurface,
    /// The OBJ frames of a `mesh_sequence`, relative to the scene file (the
    /// scene loader replaces them by the list of resolved paths).
    pub files: Option<SequenceFiles>,
    /// Frames per second of a `mesh_sequence`.
    pub frame_rate: Option<f64>,
    /// The number a `files` pattern starts from (default 0).
    pub first_frame: Option<u64>,
}

/// `[[obstacle.keyframes]]`: the obstacle's pose at one time, relative to its
/// placement at rest (`position`, `rotation`).
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    /// Simulated time of the key, s.
    pub time: f64,
    /// Displacement of the obstacle's origin, m.
    #[serde(default)]
    pub translation: [f64; 3],
    /// Rotation about the obstacle's origin: Euler angles in degrees (about x,
    /// then y, then z, as `rotation`).
    #[serde(default)]
    pub rotation: [f64; 3],
}

/// How an obstacle moves between two keyframes.
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum KeyframeEasing {
    /// At a constant velocity and spin between keys (jumps at the keys).
    #[default]
    Linear,
    /// Easing in and out of every key: the velocity is zero at the keys and
    /// continuous (C1).
    Smooth,
}

/// What a keyframed obstacle does after its last key.
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum KeyframeAfter {
    /// It stays at the last key.
    #[default]
    Hold,
    /// The keys repeat with the period from the first key to the last (the
    /// last key's pose must equal the first's).
    Loop,
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
    /// Primitives in a joint hierarchy (`part`), moved by forward kinematics.
    Articulated,
    /// A triangle mesh deformed by a sequence of OBJ files of one topology
    /// (`files`, `frame_rate`, `scale`), interpolated between frames.
    MeshSequence,
}

impl ObstacleShape {
    /// The scene's word for the shape, for names and messages.
    pub fn name(self) -> &'static str {
        match self {
            ObstacleShape::Sphere => "sphere",
            ObstacleShape::Box => "box",
            ObstacleShape::Plane => "plane",
            ObstacleShape::Capsule => "capsule",
            ObstacleShape::Cylinder => "cylinder",
            ObstacleShape::Mesh => "mesh",
            ObstacleShape::Articulated => "articulated",
            ObstacleShape::MeshSequence => "mesh sequence",
        }
    }
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

fn default_one() -> f64 {
    1.0
}
pub(crate) fn default_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}
