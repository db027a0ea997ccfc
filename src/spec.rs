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

use crate::math::Scalar;

mod curve;
mod obstacle_spec;
mod part;
mod pin;
mod rest;
mod sequence;
pub use curve::{Curve, SideCurve};
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

/// A garment made from sewing-pattern panels.
#[derive(Debug, Clone, PartialEq)]
pub struct Garment {
    /// The panels, in scene order.
    pub panels: Vec<PanelSpec>,
    /// The seams, in scene order.
    pub seams: Vec<SeamSpec>,
    /// The target edge length of the panels' triangles, m.
    pub max_edge: f64,
}

/// One panel: its outline in pattern coordinates and where it starts.
#[derive(Debug, Clone, PartialEq)]
pub struct PanelSpec {
    /// The panel's name (what seams name).
    pub name: String,
    /// The outline's corners in pattern coordinates, m; side k runs from corner
    /// k to corner k + 1 (1-based), the last side back to the first corner.
    pub outline: Vec<[f64; 2]>,
    /// The sides that are curved (every other side is straight), at most one
    /// entry per side.
    pub curves: Vec<SideCurve>,
    /// How the flat pattern is placed in the garment's frame.
    pub placement: Placement,
}

/// How a panel's pattern (u, v) is placed in the garment's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Placement {
    /// Flat: the pattern's plane rotated (Euler angles in degrees, about x,
    /// then y, then z) and moved to `position`, m.
    Flat {
        /// Where the pattern's origin goes, m.
        position: [f64; 3],
        /// Euler angles, degrees.
        rotation: [f64; 3],
    },
    /// Wrapped around the garment's vertical (z) axis: u becomes arc length on
    /// a cylinder of `radius` (u = 0 at `angle` degrees from -y, counter-clockwise
    /// seen from above), v becomes height; the pattern's front faces outwards.
    Cylinder {
        /// Cylinder radius, m.
        radius: f64,
        /// Where u = 0 lies, degrees about z from the -y direction.
        angle: f64,
        /// Added to every point, m.
        position: [f64; 3],
    },
}

/// A seam: two panel sides sewn together, by default the first side's start
/// to the second side's end (two counter-clockwise outlines run a shared seam
/// in opposite directions). Both sides are divided into the same number of
/// segments, each side's points equally spaced along its own length, so a
/// longer side gathers into a shorter one.
#[derive(Debug, Clone, PartialEq)]
pub struct SeamSpec {
    /// The seam's name.
    pub name: String,
    /// The first side.
    pub a: SeamSide,
    /// The second side.
    pub b: SeamSide,
    /// Which way the second side runs against the first.
    pub direction: SeamDirection,
    /// How much longer one side may be than the other.
    pub gather: Gather,
}

/// Which way a seam's second side runs against its first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SeamDirection {
    /// The first side's start meets the second side's end.
    #[default]
    Opposite,
    /// The first side's start meets the second side's start.
    Same,
}

/// How much the lengths of a seam's two sides may differ.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Gather {
    /// Within [`crate::garment::SEAM_LENGTH_TOLERANCE`] of each other: the
    /// sides are sewn point to point.
    #[default]
    None,
    /// Any lengths: the longer side is gathered into the shorter one.
    Any,
}

/// One side of a seam: a panel and one of its outline's sides.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeamSide {
    /// The panel's name.
    pub panel: String,
    /// The side, 1-based: side k runs from outline corner k to corner k + 1.
    pub side: usize,
}

/// The sewing stiffness a seam gets unless told otherwise, N/m per m of seam:
/// a 1 m seam's springs together pull with 50 N per metre of gap.
pub const DEFAULT_SEWING_STIFFNESS: Scalar = 50.0;

/// The weld gap a seam gets unless told otherwise, m: it is welded once every
/// pair is closer than 5 mm.
pub const DEFAULT_WELD_GAP: Scalar = 0.005;

/// How the seams are sewn: the pull of their springs, its cap, and the gap at
/// which a seam is welded. Part of the physics model
/// (`physics::MaterialParams`), not of the mesh: the mesh only says which
/// vertices each seam pairs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sewing {
    /// Sewing stiffness per metre of seam, N/m per m: each pair's zero-length
    /// spring gets this times its share of the seam's length.
    pub stiffness: Scalar,
    /// The seam is welded once every pair is closer than this, m.
    pub weld_gap: Scalar,
    /// The largest pull per metre of seam, N/m (`None`: no cap): each pair's
    /// spring pulls with at most this times its share of the seam's length,
    /// and beyond the gap where it reaches that force its energy grows
    /// linearly (`physics::sewing`).
    pub max_force: Option<Scalar>,
}

impl Default for Sewing {
    /// The scene's defaults: [`DEFAULT_SEWING_STIFFNESS`], [`DEFAULT_WELD_GAP`],
    /// no cap.
    fn default() -> Sewing {
        Sewing {
            stiffness: DEFAULT_SEWING_STIFFNESS,
            weld_gap: DEFAULT_WELD_GAP,
            max_force: None,
        }
    }
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

fn default_one() -> f64 {
    1.0
}
pub(crate) fn default_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}
