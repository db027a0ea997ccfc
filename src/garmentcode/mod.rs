//! GarmentCode's sewing-pattern specification (`*_specification.json`, MIT,
//! github.com/maria-korosteleva/GarmentCode) read into drape's garment: an
//! input format of the application, like the scene parser.
//!
//! What is read: `pattern.panels` (each with `translation` and `rotation`,
//! degrees, applied as GarmentCode applies them: about x, then y, then z;
//! `vertices`; `edges`, a loop, each with an optional `curvature` and
//! `label`), `pattern.stitches` (two `{ panel, edge }` sides and an optional
//! `"right_wrong"` or `"right_right"`), `pattern.panel_order`, and
//! `properties.units_in_meter` and `properties.curvature_coords`. Edge k of a
//! panel becomes its side k + 1; stitch i becomes the seam `stitchI`, which
//! gathers when its edges differ in length by more than
//! [`crate::garment::SEAM_LENGTH_TOLERANCE`]. The pattern keeps GarmentCode's
//! frame (y up); the scene written from it turns it into drape's z-up world
//! (`scene_text.rs`).

pub mod attach;
pub mod body;
pub mod clearance;
mod convert;
mod facing;
mod json;
pub mod scene_text;

use std::path::Path;

use crate::garment::{GarmentError, build};
use crate::mesh::OutlineError;
use crate::spec::{Garment, PanelSpec, SeamSpec};
use json::SpecFile;

/// A GarmentCode pattern in drape's terms (metres, GarmentCode's y-up frame).
#[derive(Debug, Clone, PartialEq)]
pub struct Pattern {
    /// The panels, in the pattern's panel order.
    pub panels: Vec<PanelSpec>,
    /// The stitches as seams, in the file's order.
    pub seams: Vec<SeamSpec>,
    /// The labelled sides.
    pub labels: Vec<Labelled>,
}

/// A panel side that carries a GarmentCode label (e.g. `lower_interface`).
#[derive(Debug, Clone, PartialEq)]
pub struct Labelled {
    /// The panel.
    pub panel: String,
    /// The side, 1-based (GarmentCode's edge + 1).
    pub side: usize,
    /// The label.
    pub label: String,
}

/// Why a specification file cannot be read, naming the file.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {why}")]
pub struct GarmentCodeError {
    /// The file.
    pub file: String,
    /// What is wrong.
    pub why: Why,
}

/// What is wrong with a specification, naming the panel, edge (numbered
/// from 0, as GarmentCode numbers them) or stitch.
#[derive(Debug, thiserror::Error)]
pub enum Why {
    /// The file cannot be read.
    #[error("cannot read the file: {0}")]
    Io(std::io::Error),
    /// The file is not JSON of the expected shape.
    #[error("not a GarmentCode specification: {0}")]
    Json(serde_json::Error),
    /// `units_in_meter` is not a positive number, or `curvature_coords` unknown.
    #[error("properties: {0}")]
    Properties(String),
    /// The pattern has no panels.
    #[error("the pattern has no panels")]
    NoPanels,
    /// A panel is malformed.
    #[error("panel `{panel}`: {reason}")]
    Panel {
        /// The panel.
        panel: String,
        /// What is wrong.
        reason: String,
    },
    /// An edge is malformed.
    #[error("panel `{panel}`, edge {edge}: {reason}")]
    Edge {
        /// The panel.
        panel: String,
        /// The edge, 0-based.
        edge: usize,
        /// What is wrong.
        reason: String,
    },
    /// An edge's curvature has a type drape does not know.
    #[error(
        "panel `{panel}`, edge {edge}: unknown curvature type {kind}; allowed: \"quadratic\", \
         \"cubic\", \"circle\""
    )]
    UnknownCurvature {
        /// The panel.
        panel: String,
        /// The edge, 0-based.
        edge: usize,
        /// The type given.
        kind: String,
    },
    /// An edge's two corners are the same point.
    #[error("panel `{panel}`, edge {edge}: the edge has zero length (its corners coincide)")]
    ZeroLength {
        /// The panel.
        panel: String,
        /// The edge, 0-based.
        edge: usize,
    },
    /// A panel's outline cannot be meshed.
    #[error("panel `{panel}`: {reason}")]
    Outline {
        /// The panel.
        panel: String,
        /// Why, in GarmentCode's edge numbers.
        reason: String,
    },
    /// The garment cannot be built from the panels and seams.
    #[error("{0}")]
    Garment(String),
    /// A stitch is malformed or names a missing panel or edge.
    #[error("stitch {stitch}: {reason}")]
    Stitch {
        /// The stitch, 0-based.
        stitch: usize,
        /// What is wrong.
        reason: String,
    },
}

/// Reads the specification file at `path`.
pub fn load(path: &Path) -> Result<Pattern, GarmentCodeError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| GarmentCodeError {
        file: file.clone(),
        why: Why::Io(e),
    })?;
    parse(&text).map_err(|why| GarmentCodeError { file, why })
}

/// Reads a specification from its text.
pub fn parse(text: &str) -> Result<Pattern, Why> {
    let spec: SpecFile = serde_json::from_str(text).map_err(Why::Json)?;
    let units = spec.properties.units_in_meter;
    if !(units.is_finite() && units > 0.0) {
        return Err(Why::Properties(format!(
            "units_in_meter must be a number > 0, got {units}"
        )));
    }
    let coords = spec.properties.curvature_coords.as_str();
    if coords != "relative" && coords != "absolute" {
        return Err(Why::Properties(format!(
            "curvature_coords must be \"relative\" or \"absolute\", got \"{coords}\""
        )));
    }
    // The panel order first, then any panel it leaves out, by name.
    let mut names: Vec<String> = spec.pattern.panel_order.clone().unwrap_or_default();
    for name in spec.pattern.panels.keys() {
        if !names.contains(name) {
            names.push(name.clone());
        }
    }
    if names.is_empty() {
        return Err(Why::NoPanels);
    }
    let mut panels = Vec::with_capacity(names.len());
    let mut clockwise = Vec::with_capacity(names.len());
    let mut labels = Vec::new();
    for name in &names {
        let Some(p) = spec.pattern.panels.get(name) else {
            return Err(Why::Panel {
                panel: name.clone(),
                reason: "named in panel_order but not in panels".into(),
            });
        };
        let converted = convert::panel(&spec, name, p)?;
        panels.push(converted.panel);
        clockwise.push(converted.clockwise);
        labels.extend(converted.labels);
    }
    let seams = spec
        .pattern
        .stitches
        .iter()
        .enumerate()
        .map(|(i, s)| convert::stitch(i, s, &panels))
        .collect::<Result<Vec<_>, _>>()?;
    // drape faces a panel whichever way its outline winds: one GarmentCode
    // faces along -z (clockwise) is turned over, unless a seam needs it facing
    // the other way, and one it faces along +z is turned over where a seam
    // needs it.
    let turned = facing::turned_over(&names, &seams);
    for ((panel, cw), turn) in panels.iter_mut().zip(clockwise).zip(turned) {
        if cw != turn {
            convert::turn_over(panel);
        }
    }
    Ok(Pattern {
        panels,
        seams,
        labels,
    })
}

/// Builds the pattern's garment with triangles about `max_edge` (m) across,
/// to find what cannot be meshed or sewn before a scene is made of it.
pub fn check(pattern: &Pattern, max_edge: f64) -> Result<(), Why> {
    let garment = Garment {
        panels: pattern.panels.clone(),
        seams: pattern.seams.clone(),
        holds: Vec::new(),
        max_edge,
    };
    match build(&garment) {
        Ok(_) => Ok(()),
        Err(GarmentError::Outline { panel, why }) => Err(Why::Outline {
            panel,
            reason: edge_words(&why),
        }),
        Err(other) => Err(Why::Garment(other.to_string())),
    }
}

/// An outline error in GarmentCode's words: edge k is side k (0-based).
fn edge_words(why: &OutlineError) -> String {
    match *why {
        OutlineError::SelfIntersecting { a, b } => format!(
            "the outline crosses itself: edges {a} and {b} cross or touch; a panel must be a \
             simple polygon"
        ),
        OutlineError::ZeroLengthSide { side, .. } => {
            format!("edge {side} has zero length (its corners coincide)")
        }
        OutlineError::NearlyTouching { side } => {
            format!("edge {side}, divided into its segments, touches or crosses another edge")
        }
        ref other => other.to_string(),
    }
}
