//! A garment's specification: its panels, their placement, its seams and how
//! they are sewn.

use serde::Deserialize;

use super::SideCurve;
use crate::math::Scalar;

/// A garment made from sewing-pattern panels.
#[derive(Debug, Clone, PartialEq)]
pub struct Garment {
    /// The panels, in scene order.
    pub panels: Vec<PanelSpec>,
    /// The seams, in scene order.
    pub seams: Vec<SeamSpec>,
    /// The held sides of each attachment, in scene order.
    pub holds: Vec<super::HoldSpec>,
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

/// A seam: two edges sewn together, by default the first edge's start to the
/// second edge's end (two counter-clockwise outlines run a shared seam in
/// opposite directions). Each edge is one panel side or several joined end to
/// end (a waistband's long side sewn to the tops of a skirt's front and
/// back). Both edges are divided into the same number of segments, each
/// panel side's points equally spaced along its own length and each side's
/// share of its edge's segments in proportion to its length, so a longer
/// edge gathers into a shorter one.
#[derive(Debug, Clone, PartialEq)]
pub struct SeamSpec {
    /// The seam's name.
    pub name: String,
    /// The first edge: one or more panel sides, joined end to end in order.
    pub a: Vec<SeamSide>,
    /// The second edge.
    pub b: Vec<SeamSide>,
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

/// One of the edges of a seam, as a scene writes it: one panel side, or
/// several joined end to end in order.
#[derive(Debug, Clone, PartialEq)]
pub enum SeamEdge {
    /// One panel side: `{ panel = "front", side = 2 }`.
    One(SeamSide),
    /// Several: `[{ panel = "front", side = 3 }, { panel = "back", side = 3 }]`.
    Many(Vec<SeamSide>),
}

/// A table is one side, an array several; a mistake inside either is
/// reported as that table's own (an unknown key, a missing `side`).
impl<'de> Deserialize<'de> for SeamEdge {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<SeamEdge, D::Error> {
        struct Edge;
        impl<'de> serde::de::Visitor<'de> for Edge {
            type Value = SeamEdge;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a table { panel, side } or an array of them")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<SeamEdge, A::Error> {
                let one = serde::de::value::MapAccessDeserializer::new(map);
                SeamSide::deserialize(one).map(SeamEdge::One)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<SeamEdge, A::Error> {
                let many = serde::de::value::SeqAccessDeserializer::new(seq);
                Vec::<SeamSide>::deserialize(many).map(SeamEdge::Many)
            }
        }
        d.deserialize_any(Edge)
    }
}

impl SeamEdge {
    /// The panel sides, in order.
    pub fn sides(&self) -> &[SeamSide] {
        match self {
            SeamEdge::One(side) => std::slice::from_ref(side),
            SeamEdge::Many(sides) => sides,
        }
    }
}

/// A panel side: a panel and one of its outline's sides.
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
