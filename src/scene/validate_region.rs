//! Checks of a pin's `region` and the keys that go with it: a box's corners,
//! a disk's centre and radius. Each check names the key path, which
//! `parse.rs` turns into a line of the file or a `--set`.

use super::error::{Issue, KeyPath, SceneErrorKind as Kind, Seg, keys};
use super::schema;
use super::validate::{all_finite, allowed_for, out_of_range, positive};
use super::{ClothShape, Pin};

/// A pin's `region` and, for a box, its corners, for a disk, its centre and radius.
pub(super) fn check_pin_region(
    p: &Pin,
    shape: ClothShape,
    at: &dyn Fn(&str) -> Vec<Seg>,
    has: &dyn Fn(&str) -> bool,
) -> Result<(), Issue> {
    let region = p.region.as_str();
    let corner_or_edge = matches!(
        region,
        "corner:top_left"
            | "corner:top_right"
            | "corner:bottom_left"
            | "corner:bottom_right"
            | "edge:top"
            | "edge:bottom"
            | "edge:left"
            | "edge:right"
    );
    if !corner_or_edge && !matches!(region, "box" | "disk" | "all") {
        return Err(Issue::new(
            at("region"),
            Kind::BadValue,
            format!("{region:?} is not a pin region"),
        )
        .allowed(schema::REGIONS));
    }
    if corner_or_edge && shape != ClothShape::Rectangle {
        return Err(Issue::new(
            at("region"),
            Kind::BadValue,
            format!("{region:?} needs shape = \"rectangle\" (corners and edges are named on a rectangle only)"),
        )
        .allowed("\"box\" (with box_min and box_max), \"disk\" (with disk_radius) or \"all\" for this shape")
        .because(keys(&["cloth", "shape"])));
    }
    if region == "box" {
        check_box(p, at)?;
    } else if let Some(k) = ["box_min", "box_max"].into_iter().find(|k| has(k)) {
        return Err(not_for_region(at(k), k, "box", at("region")));
    }
    if region == "disk" {
        check_disk(p, at)?;
    } else if let Some(k) = ["disk_center", "disk_radius"].into_iter().find(|k| has(k)) {
        return Err(not_for_region(at(k), k, "disk", at("region")));
    }
    Ok(())
}

/// A `box` region's corners: both given, finite, the second above the first.
fn check_box(p: &Pin, at: &dyn Fn(&str) -> Vec<Seg>) -> Result<(), Issue> {
    let (Some(lo), Some(hi)) = (p.box_min, p.box_max) else {
        let k = if p.box_min.is_none() {
            "box_min"
        } else {
            "box_max"
        };
        return Err(missing(at(k), k, "box", at("region")));
    };
    all_finite(at("box_min"), &lo)?;
    all_finite(at("box_max"), &hi)?;
    if !(lo[0] < hi[0] && lo[1] < hi[1]) {
        return Err(out_of_range(
            at("box_max"),
            format!("box_max {hi:?} is not above box_min {lo:?} in both coordinates"),
        ));
    }
    Ok(())
}

/// A `disk` region's radius (given, positive) and centre (finite).
fn check_disk(p: &Pin, at: &dyn Fn(&str) -> Vec<Seg>) -> Result<(), Issue> {
    let Some(r) = p.disk_radius else {
        return Err(missing(
            at("disk_radius"),
            "disk_radius",
            "disk",
            at("region"),
        ));
    };
    positive(at("disk_radius"), r)?;
    match p.disk_center {
        Some(c) => all_finite(at("disk_center"), &c),
        None => Ok(()),
    }
}

/// Key `k` (at `path`), which `region` needs, missing.
fn missing(path: KeyPath, k: &str, region: &str, because: KeyPath) -> Issue {
    let allowed = allowed_for(&path);
    Issue::new(
        path,
        Kind::MissingKey,
        format!("missing required key `{k}` for region = \"{region}\""),
    )
    .allowed(allowed)
    .because(because)
}

/// Key `k` (at `path`) written for a region other than `region`.
fn not_for_region(path: KeyPath, k: &str, region: &str, because: KeyPath) -> Issue {
    Issue::new(
        path,
        Kind::NotApplicable,
        format!("`{k}` applies only to region = \"{region}\""),
    )
    .allowed(format!("remove it, or set region = \"{region}\""))
    .because(because)
}
