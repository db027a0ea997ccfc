//! Recording of a run to a Rerun `.rrd` file or a live viewer (`docs/recording.md`), the `drape
//! inspect` decoder, and OBJ frame export.
//!
//! This is the only module that imports `rerun`. The engine hands each frame over as plain
//! slices ([`FrameView`]) to a [`Recorder`] (`recorder.rs`); every conversion to rerun types
//! lives in this module's files.
//! `docs/recording.md` documents the schema (every entity, type and unit) for users.
//!
//! What a recording holds:
//! - timelines `frame` (sequence) and `sim_time` (duration, seconds), set before each frame
//!   (rerun's wall-clock `log_time` timeline is turned off);
//! - static data: view coordinates at `/` (right-handed, z up) and, with the first frame, an
//!   annotation context at `cloth` that names and colours the triangles' classes: the
//!   refinement levels (`level 0`, `level 1`, ...), or with [`ColourBy::Panel`] the garment's
//!   panels (class id = panel index, label = panel name; `cloth` for a cloth without panels);
//! - `cloth/mesh`: a `Mesh3D` with shared vertices, copied only where triangles of different
//!   classes meet so that each triangle shows its class's colour ([`LEVEL_PALETTE`] or
//!   [`garment::PANEL_PALETTE`]); the positions and normals every frame, the triangle
//!   indices, vertex colours, class ids (legend) and the data `triangle_level` (`u8` per
//!   triangle) and `duplicate_of` only on frames where the topology changed (`mesh.rs`;
//!   [`decode::cloth_mesh_at`] reads a frame back);
//! - `cloth/seams` every frame of a garment (`garment.rs`): each open seam's pairs as segments
//!   (class `open seam`, orange) and each welded seam's edges (class `welded seam`, green),
//!   with the seam name and vertex pair of each segment as data; its annotation context and
//!   line width are static;
//! - `cloth/edges` every frame unless turned off: the edges as line segments coloured by their
//!   dihedral angle (a class id per whole degree, [`edges::angle_class`], coloured and named by
//!   a static annotation context at `cloth/edges`), with the angle (`dihedral_angle_deg`, `f32`)
//!   and the vertex pair (`edge_vertices`) of each segment as data; by default the edges near
//!   the scene's refine threshold, or all, or those above a given angle ([`EdgeDisplay`]);
//! - `cloth/pins` every frame: the pinned vertices as points;
//! - `events/points` and `events/log`: the remeshing events and seam welds since the previous
//!   recorded frame;
//! - `legend` (static, with the first frame): a markdown text document naming the colours;
//! - `plots/<name>` every frame for each scalar of [`FrameView::scalars`];
//! - `obstacles/<name>`: obstacle meshes, static or per frame;
//! - a default blueprint, sent with the first frame once the plot names are known (`layout.rs`),
//!   its 3D eyes placed by the scene's [`Camera`] (`camera.rs`).
//!
//! The recording is forced on: `RERUN=off` in the environment does not disable it (the builder
//! uses `enabled(true)`, which rerun documents as ignoring the `RERUN` variable), and so is
//! the blueprint's own in-memory stream (`blueprint.rs`).
//! Rerun's private test variable `_RERUN_TEST_FORCE_SAVE` redirects every stream to its own
//! path; do not set it.

mod blueprint;
mod camera;
mod convert;
pub mod decode;
pub mod edges;
mod error;
mod events;
mod frame;
pub mod garment;
pub mod inspect;
mod layout;
pub mod mesh;
pub mod obj;
mod obstacles;
mod recorder;
mod report;
mod sink;

pub use camera::{Camera, CameraSide};
pub use edges::EdgeDisplay;
pub use error::{BoxError, RecordError};
pub use frame::{EventMark, FrameView, GarmentView, SeamSegment, WeldMark};
pub use garment::ColourBy;
pub use mesh::{DUPLICATE_COMPONENT, LEVEL_COMPONENT};
pub use recorder::Recorder;
pub use sink::{LiveViewer, RecordTarget};
/// Colour of each refinement level, as sRGB `[r, g, b]`.
///
/// | level | colour | hex |
/// |---|---|---|
/// | 0 | steel blue (calm, the coarse base mesh) | `#4682B4` |
/// | 1 | teal | `#26A69A` |
/// | 2 | green | `#66BB6A` |
/// | 3 | yellow | `#FDD835` |
/// | 4 | orange | `#FF9800` |
/// | 5 | deep orange | `#F4511E` |
/// | 6 | red | `#D32F2F` |
/// | 7 and deeper | crimson | `#880E4F` |
///
/// Deeper (finer) levels are warmer, so refined regions stand out against the blue base.
pub const LEVEL_PALETTE: [[u8; 3]; 8] = [
    [0x46, 0x82, 0xB4],
    [0x26, 0xA6, 0x9A],
    [0x66, 0xBB, 0x6A],
    [0xFD, 0xD8, 0x35],
    [0xFF, 0x98, 0x00],
    [0xF4, 0x51, 0x1E],
    [0xD3, 0x2F, 0x2F],
    [0x88, 0x0E, 0x4F],
];

/// Number of levels (0 up to this, exclusive) named in the annotation context; deeper levels
/// still get their colour, only without a label.
pub const ANNOTATED_LEVELS: usize = 16;

/// Rerun application id of every drape recording.
pub const APPLICATION_ID: &str = "drape";
/// Sequence timeline holding the frame index.
pub const TIMELINE_FRAME: &str = "frame";
/// Duration timeline holding the simulated time, in seconds.
pub const TIMELINE_SIM_TIME: &str = "sim_time";
/// Entity of the cloth mesh.
pub const ENTITY_MESH: &str = "cloth/mesh";
/// Entity of the edges coloured by dihedral angle.
pub const ENTITY_EDGES: &str = "cloth/edges";
/// Entity of the static legend (a markdown text document: level or panel colours, angle scale,
/// seam colours, event colours).
pub const ENTITY_LEGEND: &str = "legend";
/// Entity of the seams of a garment (open pairs and welded edges, coloured by state).
pub const ENTITY_SEAMS: &str = "cloth/seams";
/// Entity of the pinned vertices.
pub const ENTITY_PINS: &str = "cloth/pins";
/// Parent entity of the scalar plots: scalar `name` is logged at `plots/<name>`.
pub const ENTITY_PLOTS: &str = "plots";
/// Parent entity of the obstacles: each is a mesh at `obstacles/<name>`.
pub const ENTITY_OBSTACLES: &str = "obstacles";
/// Entity of the event points (one point per event of the frame, labelled).
pub const ENTITY_EVENT_POINTS: &str = "events/points";
/// Entity of the event log (one text line per event).
pub const ENTITY_EVENT_LOG: &str = "events/log";

/// The recording id for a scene: the same scene name always gives the same id, so re-running a
/// scene replaces its recording in the viewer instead of adding a new one.
///
/// It is a 128-bit FNV-1a hash of `drape/<scene_name>`, formatted as a version-8 UUID.
pub fn recording_id(scene_name: &str) -> String {
    const OFFSET: u128 = 0x6c62_272e_07bb_0142_62b8_2175_6295_c58d;
    const PRIME: u128 = 0x0000_0000_0100_0000_0000_0000_0000_013b;
    let mut h = OFFSET;
    for &b in b"drape/".iter().chain(scene_name.as_bytes()) {
        h ^= u128::from(b);
        h = h.wrapping_mul(PRIME);
    }
    h = (h & !(0xf << 76)) | (0x8 << 76); // version 8 (custom)
    h = (h & !(0x3 << 62)) | (0x2 << 62); // RFC 4122 variant
    format!(
        "{:08x}-{:04x}-{:04x}-{:04x}-{:012x}",
        h >> 96,
        (h >> 80) & 0xffff,
        (h >> 64) & 0xffff,
        (h >> 48) & 0xffff,
        h & 0xffff_ffff_ffff
    )
}
