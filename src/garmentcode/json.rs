//! The parts of a GarmentCode specification file that drape reads, as
//! serde reads them; curvatures and stitch entries stay JSON values here and
//! are read with messages that name their panel, edge or stitch
//! (`convert.rs`).

use std::collections::BTreeMap;

use serde::Deserialize;
use serde_json::Value;

/// A specification file: `{ "pattern": ..., "properties": ... }` (other
/// top-level keys, such as the design parameters, are not read).
#[derive(Debug, Deserialize)]
pub struct SpecFile {
    /// The panels and stitches.
    pub pattern: PatternJson,
    /// Units and the curvature convention.
    #[serde(default)]
    pub properties: Properties,
}

/// `pattern`: the panels by name, the stitches, and the panels' order.
#[derive(Debug, Deserialize)]
pub struct PatternJson {
    /// The panels by name.
    pub panels: BTreeMap<String, PanelJson>,
    /// The stitches: each two `{ panel, edge }` entries and an optional third,
    /// `"right_wrong"` or `"right_right"`.
    #[serde(default)]
    pub stitches: Vec<Vec<Value>>,
    /// The panels in order (absent: by name).
    #[serde(default)]
    pub panel_order: Option<Vec<String>>,
}

/// One panel: its placement (units of `units_in_meter`, degrees), corners and edges.
#[derive(Debug, Deserialize)]
pub struct PanelJson {
    /// Where the panel's origin goes, in the pattern's units.
    #[serde(default)]
    pub translation: [f64; 3],
    /// Euler angles, degrees, applied about x, then y, then z.
    #[serde(default)]
    pub rotation: [f64; 3],
    /// The corners `[x, y]`.
    pub vertices: Vec<[f64; 2]>,
    /// The edges, a closed loop.
    pub edges: Vec<EdgeJson>,
}

/// One edge: its two corners, its curvature and its label.
#[derive(Debug, Deserialize)]
pub struct EdgeJson {
    /// Indices of its start and end corner.
    pub endpoints: [usize; 2],
    /// `{ "type": "quadratic" | "cubic" | "circle", "params": ... }`, or an
    /// older `[x, y]` quadratic control point; absent: straight.
    #[serde(default)]
    pub curvature: Option<Value>,
    /// A label such as `lower_interface`.
    #[serde(default)]
    pub label: Option<String>,
}

/// `properties`: how coordinates are given.
#[derive(Debug, Deserialize)]
pub struct Properties {
    /// `"relative"` (control points in the edge's frame) or `"absolute"`.
    #[serde(default = "relative")]
    pub curvature_coords: String,
    /// Pattern units per metre (100: centimetres).
    #[serde(default = "centimetres")]
    pub units_in_meter: f64,
}

impl Default for Properties {
    fn default() -> Properties {
        Properties {
            curvature_coords: relative(),
            units_in_meter: centimetres(),
        }
    }
}

fn relative() -> String {
    "relative".into()
}

fn centimetres() -> f64 {
    100.0
}
