//! GarmentCode's attachments: the labelled edges of a pattern held at the
//! body for a while, as GarmentCode's simulator holds them
//! (`pygarment/meshgen/garment.py`, `_add_attachment_labels`, with its
//! default `attachment_stiffness` 1000 and `attachment_frames` 400).
//!
//! Each label GarmentCode holds keeps its edges on one side of a plane placed
//! by the body's measurements (GarmentCode's body file `*.yaml`, in
//! centimetres, from the floor):
//!
//! | label | plane | kept |
//! |---|---|---|
//! | `lower_interface` | horizontal, at the waist: `height - head_l - waist_line` (or `_waist_level`) | above it |
//! | `strapless_top` | horizontal, under the arms: `height - head_l - armscye_depth` | above it |
//! | `right_collar` | vertical, at x = -(`neck_w` - 2) / 2 | at larger x |
//! | `left_collar` | vertical, at x = +(`neck_w` - 2) / 2 | at smaller x |
//!
//! The planes are in GarmentCode's frame (y up), whose y is drape's z. A body
//! whose lowest point lies below y = 0 is raised by GarmentCode until it
//! stands on it, the pattern with it; drape leaves both where they are, so the
//! heights are lowered by as much.

use std::path::Path;

use super::Labelled;
use crate::math::Scalar;
use crate::spec::SeamSide;

/// The labels GarmentCode holds, in the order it lists them.
pub const HELD_LABELS: [&str; 4] = [
    "lower_interface",
    "right_collar",
    "left_collar",
    "strapless_top",
];

/// How long GarmentCode holds the labelled edges: its `attachment_frames`,
/// 400, at its 60 frames per second, s.
pub const RELEASE: Scalar = 400.0 / 60.0;

/// GarmentCode's attachment stiffness, 1000, taken as drape's stiffness per
/// metre of held side (N/m per m).
pub const STIFFNESS: Scalar = 1000.0;

/// The body measurements the planes need, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurements {
    /// The waist's height above the floor, m.
    pub waist_level: Scalar,
    /// The height under the arms, m.
    pub underarm_level: Scalar,
    /// The neck's width, m.
    pub neck_width: Scalar,
}

/// Why a measurements file cannot be used, naming the file.
#[derive(Debug, thiserror::Error)]
#[error("body measurements {file}: {why}")]
pub struct MeasurementsError {
    /// The file.
    pub file: String,
    /// What is wrong.
    pub why: String,
}

/// One attachment of a pattern: its name (the label), held sides and plane,
/// in drape's world (z up), m.
#[derive(Debug, Clone, PartialEq)]
pub struct PatternAttachment {
    /// The label.
    pub name: String,
    /// The held sides.
    pub sides: Vec<SeamSide>,
    /// A point of the plane, m.
    pub point: [Scalar; 3],
    /// The plane's normal: the side kept.
    pub normal: [Scalar; 3],
}

/// Reads GarmentCode's body measurements file (`body:` then `key: value`
/// lines, centimetres).
pub fn load_measurements(path: &Path) -> Result<Measurements, MeasurementsError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| MeasurementsError {
        file: file.clone(),
        why: format!("cannot read it: {e}"),
    })?;
    parse_measurements(&text).map_err(|why| MeasurementsError { file, why })
}

/// Reads the measurements from the text of a body file.
pub fn parse_measurements(text: &str) -> Result<Measurements, String> {
    let value = |key: &str| -> Option<Scalar> {
        text.lines().find_map(|line| {
            let (k, v) = line.trim().split_once(':')?;
            (k.trim() == key).then(|| v.trim().parse::<Scalar>().ok())?
        })
    };
    let need = |key: &str| {
        value(key)
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("no number `{key}` (centimetres)"))
    };
    let height = need("height")?;
    let head = need("head_l")?;
    let waist = match value("_waist_level") {
        Some(level) => level,
        None => height - head - need("waist_line")?,
    };
    let cm = 0.01;
    Ok(Measurements {
        waist_level: waist * cm,
        underarm_level: (height - head - need("armscye_depth")?) * cm,
        neck_width: (need("neck_w")? - 2.0) * cm,
    })
}

/// The attachments of the labelled sides, one per label GarmentCode holds (in
/// the order GarmentCode lists them), with `floor` the height, m, of the
/// body's lowest point when it is below zero (0 otherwise). Other labels hold
/// nothing.
pub fn attachments(labels: &[Labelled], m: &Measurements, floor: Scalar) -> Vec<PatternAttachment> {
    let raise = floor.min(0.0);
    let half_neck = 0.5 * m.neck_width;
    let planes = [
        (
            "lower_interface",
            [0.0, 0.0, m.waist_level + raise],
            [0.0, 0.0, 1.0],
        ),
        ("right_collar", [-half_neck, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ("left_collar", [half_neck, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        (
            "strapless_top",
            [0.0, 0.0, m.underarm_level + raise],
            [0.0, 0.0, 1.0],
        ),
    ];
    planes
        .iter()
        .filter_map(|&(label, point, normal)| {
            let sides: Vec<SeamSide> = labels
                .iter()
                .filter(|l| l.label == label)
                .map(|l| SeamSide {
                    panel: l.panel.clone(),
                    side: l.side,
                })
                .collect();
            (!sides.is_empty()).then(|| PatternAttachment {
                name: label.into(),
                sides,
                point,
                normal,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const MEAN_ALL: &str = "body:\n  armscye_depth: 12.8679\n  head_l: 26.3262\n  height: \
                            171.99\n  neck_w: 18.9328\n  waist_line: 36.8913\n";

    #[test]
    fn the_waist_lies_height_less_head_less_waist_line_above_the_floor() {
        let m = parse_measurements(MEAN_ALL).unwrap();
        assert!((m.waist_level - (171.99 - 26.3262 - 36.8913) / 100.0).abs() < 1e-12);
        assert!((m.underarm_level - (171.99 - 26.3262 - 12.8679) / 100.0).abs() < 1e-12);
        assert!((m.neck_width - 0.169328).abs() < 1e-12);
    }

    #[test]
    fn a_file_without_a_height_is_refused_naming_the_key() {
        let err = parse_measurements("body:\n  head_l: 20\n").unwrap_err();
        assert!(err.contains("`height`"), "{err}");
    }

    #[test]
    fn each_held_label_becomes_one_attachment_and_others_none() {
        let m = parse_measurements(MEAN_ALL).unwrap();
        let l = |panel: &str, side, label: &str| Labelled {
            panel: panel.into(),
            side,
            label: label.into(),
        };
        let labels = [
            l("front", 2, "lower_interface"),
            l("back", 3, "lower_interface"),
            l("collar", 1, "left_collar"),
            l("front", 4, "hem"),
        ];
        let a = attachments(&labels, &m, -0.1);
        let names: Vec<&str> = a.iter().map(|a| a.name.as_str()).collect();
        assert_eq!(names, ["lower_interface", "left_collar"]);
        assert_eq!(a[0].sides.len(), 2);
        assert!((a[0].point[2] - (m.waist_level - 0.1)).abs() < 1e-12);
        assert_eq!(a[1].normal, [-1.0, 0.0, 0.0]);
    }
}
