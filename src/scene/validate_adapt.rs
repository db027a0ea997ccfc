//! Checks of the `[adapt]` table; each check names the key path, which
//! `parse.rs` turns into a line of the file or a `--set`.

use super::error::{Issue, KeyPath, SceneErrorKind as Kind, keys, num};
use super::validate::{finite, non_negative, out_of_range, positive};
use super::{
    Adapt, AdaptCriterion, AdaptEvery, AdaptMethod, ClothShape, Integrator, StiffnessRule,
};

/// The `[adapt]` table's ranges and the keys that do not apply to its settings.
pub(super) fn adapt(
    a: &Adapt,
    integrator: Integrator,
    shape: ClothShape,
    stiffness: StiffnessRule,
) -> Result<(), Issue> {
    let angle = |key: &str, x: f64| -> Result<(), Issue> {
        positive(keys(&["adapt", key]), x)?;
        if x >= 180.0 {
            return Err(out_of_range(
                keys(&["adapt", key]),
                format!("{} degrees is out of range: must be < 180", num(x)),
            ));
        }
        Ok(())
    };
    angle("refine_angle", a.refine_angle)?;
    angle("coarsen_angle", a.coarsen_angle)?;
    if a.coarsen_angle >= a.refine_angle {
        return Err(out_of_range(
            keys(&["adapt", "coarsen_angle"]),
            format!(
                "the lower threshold {} is not below the upper threshold refine_angle = {}",
                a.coarsen_angle, a.refine_angle
            ),
        ));
    }
    if !(1..=254).contains(&a.max_level) {
        return Err(out_of_range(
            keys(&["adapt", "max_level"]),
            format!("{} is out of range", a.max_level),
        ));
    }
    non_negative(keys(&["adapt", "min_edge_length"]), a.min_edge_length)?;
    if a.every == AdaptEvery::Steps(0) {
        return Err(out_of_range(
            keys(&["adapt", "every"]),
            "0 is out of range: must be >= 1",
        ));
    }
    if a.method == AdaptMethod::Edge && a.rollback {
        let path = keys(&["adapt", "rollback"]);
        return Err(Issue::new(
            path,
            Kind::NotApplicable,
            "rollback is paper A's and works with method = \"red_green\" only",
        ));
    }
    if a.method == AdaptMethod::Tensor {
        tensor(a, shape, stiffness)?;
    }
    gate(a)?;
    if a.multirate && integrator == Integrator::Implicit {
        let path = keys(&["adapt", "multirate"]);
        let why = "multirate stepping is for the explicit integrators (symplectic_euler, rk4)";
        return Err(Issue::new(path, Kind::Unsupported, why));
    }
    criterion(a)
}

/// The tensor method works on a rectangle's grid, with an even `max_level`
/// (a halving adds 2), without paper A's rollback, multirate stepping and
/// level-scaled stiffness (built for red-green's levels, where a level is
/// the same along both axes; a tensor cell may be halved one way only).
fn tensor(a: &Adapt, shape: ClothShape, stiffness: StiffnessRule) -> Result<(), Issue> {
    if shape != ClothShape::Rectangle {
        let path = keys(&["adapt", "method"]);
        let why = "method = \"tensor\" refines the grid of a rectangle and needs cloth.shape = \"rectangle\"";
        return Err(Issue::new(path, Kind::NotApplicable, why));
    }
    if !a.max_level.is_multiple_of(2) {
        return Err(out_of_range(
            keys(&["adapt", "max_level"]),
            format!(
                "{} is odd: with method = \"tensor\" each halving of a column or row adds 2, so max_level must be even (2 for one halving)",
                a.max_level
            ),
        ));
    }
    if a.rollback {
        let path = keys(&["adapt", "rollback"]);
        let why = "rollback is paper A's and works with method = \"red_green\" only";
        return Err(Issue::new(path, Kind::NotApplicable, why));
    }
    if a.multirate {
        let path = keys(&["adapt", "multirate"]);
        let why = "multirate stepping works on the levels of method = \"red_green\" or \"edge\", not \"tensor\"";
        return Err(Issue::new(path, Kind::NotApplicable, why));
    }
    if stiffness == StiffnessRule::PaperA {
        let path = keys(&["material", "stiffness_rule"]);
        let why = "stiffness_rule = \"paper_a\" scales springs by red-green's levels; with method = \"tensor\" a cell halved along one axis only would stiffen its other edges too (use \"consistent\")";
        return Err(Issue::new(path, Kind::NotApplicable, why));
    }
    Ok(())
}

/// The sizing criterion's own keys: `hysteresis` > 1, and only with `criterion =
/// "sizing"`; `refine_strain` and `refine_obstacle` > 0, and only with the sizing
/// criterion on red-green (0 turns either off, so that one `--set` line can
/// undo a scene's value).
fn criterion(a: &Adapt) -> Result<(), Issue> {
    if a.diagonals.is_some() && a.method != AdaptMethod::RedGreen {
        let path = keys(&["adapt", "diagonals"]);
        let why = "diagonals belongs to method = \"red_green\" (the edge method splits edges one at a time; the tensor method keeps the cloth's own `diagonals`)";
        return Err(Issue::new(path, Kind::NotApplicable, why));
    }
    if let Some(s) = a.refine_strain.filter(|s| *s != 0.0) {
        let path = keys(&["adapt", "refine_strain"]);
        if a.criterion != AdaptCriterion::Sizing || a.method != AdaptMethod::RedGreen {
            let why = "refine_strain belongs to criterion = \"sizing\" with method = \"red_green\"";
            return Err(Issue::new(path, Kind::NotApplicable, why));
        }
        positive_or_off(path, s)?;
    }
    if let Some(r) = a.refine_obstacle.filter(|r| *r != 0.0) {
        let path = keys(&["adapt", "refine_obstacle"]);
        if a.criterion != AdaptCriterion::Sizing || a.method != AdaptMethod::RedGreen {
            let why =
                "refine_obstacle belongs to criterion = \"sizing\" with method = \"red_green\"";
            return Err(Issue::new(path, Kind::NotApplicable, why));
        }
        positive_or_off(path, r)?;
    }
    let Some(h) = a.hysteresis else {
        return Ok(());
    };
    let path = keys(&["adapt", "hysteresis"]);
    if a.criterion != AdaptCriterion::Sizing {
        let why =
            "hysteresis belongs to criterion = \"sizing\" (the angle criterion uses coarsen_angle)";
        return Err(Issue::new(path, Kind::NotApplicable, why));
    }
    finite(&path, h)?;
    if h <= 1.0 {
        return Err(out_of_range(
            path,
            format!(
                "{} is out of range: must be > 1 (at 1 a merged parent would split again at once)",
                num(h)
            ),
        ));
    }
    Ok(())
}

/// The remesh gate's keys: `min_change` in [0, 1] (0: off), with red-green
/// only; `urgent_ratio` >= 1.
fn gate(a: &Adapt) -> Result<(), Issue> {
    let path = keys(&["adapt", "urgent_ratio"]);
    finite(&path, a.urgent_ratio)?;
    if a.urgent_ratio < 1.0 {
        let why = format!(
            "{} is out of range: must be >= 1 (a ratio of the criterion, 1 at its threshold)",
            num(a.urgent_ratio)
        );
        return Err(out_of_range(path, why));
    }
    let path = keys(&["adapt", "min_change"]);
    finite(&path, a.min_change)?;
    if !(0.0..=1.0).contains(&a.min_change) {
        let why = format!(
            "{} is out of range: must be in [0, 1] (a fraction of the triangles; 0: off)",
            num(a.min_change)
        );
        return Err(out_of_range(path, why));
    }
    if a.min_change > 0.0 && a.method != AdaptMethod::RedGreen {
        let why = "min_change gates the passes of method = \"red_green\" only";
        return Err(Issue::new(path, Kind::NotApplicable, why));
    }
    Ok(())
}

/// A threshold that is > 0, or 0 (handled by the caller) to turn its term off.
fn positive_or_off(path: KeyPath, x: f64) -> Result<(), Issue> {
    finite(&path, x)?;
    if x > 0.0 {
        return Ok(());
    }
    let why = format!("{} is out of range: must be > 0 (or 0: off)", num(x));
    Err(out_of_range(path, why))
}
