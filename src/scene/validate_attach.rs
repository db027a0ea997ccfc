//! Checks of pins attached to obstacles: the obstacles' `name`s, a pin's
//! `attach` (a named obstacle with a rigid frame, or a part of one) and the
//! keys that do not go with it. Each check names the key path, which
//! `parse.rs` turns into a line of the file or a `--set`.

use super::error::{Issue, KeyPath, SceneErrorKind as Kind, Seg};
use super::validate::{allowed_for, non_negative};
use super::{Obstacle, Pin};
use crate::kinematics::carrier::{locate, targets};
use crate::spec::ObstacleSpec;

/// The keys of a pin's own motion, which an attached pin does not have.
const MOTION_KEYS: [&str; 9] = [
    "motion",
    "velocity",
    "acceleration",
    "center",
    "axis",
    "angular_velocity",
    "keyframes",
    "easing",
    "after_last",
];

/// Every obstacle `name` is non-empty, has no `/` (which separates a part
/// in `attach`) and is unique.
pub(super) fn obstacle_names(obstacles: &[Obstacle]) -> Result<(), Issue> {
    for (i, o) in obstacles.iter().enumerate() {
        let Some(name) = &o.name else { continue };
        let path = vec![
            Seg::Key("obstacle".into()),
            Seg::Index(i),
            Seg::Key("name".into()),
        ];
        let why = if name.trim().is_empty() {
            "the obstacle's name is empty".to_owned()
        } else if name.contains('/') {
            format!(
                "`{name}` contains `/`, which separates an obstacle from its part in a pin's `attach`"
            )
        } else if let Some(m) = obstacles[..i]
            .iter()
            .position(|q| q.name.as_deref() == Some(name))
        {
            format!("obstacle {m} already has the name `{name}`")
        } else {
            continue;
        };
        let allowed = allowed_for(&path);
        return Err(Issue::new(path, Kind::BadValue, why).allowed(allowed));
    }
    Ok(())
}

/// The keys of attached pin `p`: none of its own motion's, and a release
/// time that is not negative.
pub(super) fn pin_keys(
    p: &Pin,
    at: &dyn Fn(&str) -> KeyPath,
    has: &dyn Fn(&str) -> bool,
) -> Result<(), Issue> {
    if let Some(k) = MOTION_KEYS.into_iter().find(|k| has(k)) {
        let why = if k == "motion" {
            "`motion` and `attach` both say how the pin moves: give one of them".to_owned()
        } else {
            format!(
                "`{k}` does not apply to a pin with `attach`: the body it is attached to moves it"
            )
        };
        return Err(Issue::new(at(k), Kind::NotApplicable, why)
            .allowed("remove it, or remove `attach` and give the pin its own motion")
            .because(at("attach")));
    }
    match p.release_time {
        Some(t) => non_negative(at("release_time"), t),
        None => Ok(()),
    }
}

/// The obstacles resolved for the engine (after their own checks, which report a missing
/// key first with its line; a key missing here is reported at the obstacle).
pub(super) fn resolved(obstacles: &[Obstacle]) -> Result<Vec<ObstacleSpec>, Issue> {
    obstacles
        .iter()
        .enumerate()
        .map(|(i, o)| {
            o.resolve().map_err(|e| {
                let path = vec![Seg::Key("obstacle".into()), Seg::Index(i)];
                Issue::new(path, Kind::MissingKey, e)
            })
        })
        .collect()
}

/// Pin `i`'s `attach` names an obstacle of `obstacles` that can carry it.
pub(super) fn pin_target(i: usize, p: &Pin, obstacles: &[ObstacleSpec]) -> Result<(), Issue> {
    let Some(attach) = &p.attach else {
        return Ok(());
    };
    let path = vec![
        Seg::Key("pin".into()),
        Seg::Index(i),
        Seg::Key("attach".into()),
    ];
    let Err(e) = locate(obstacles, attach) else {
        return Ok(());
    };
    let known = targets(obstacles);
    let allowed = if known.is_empty() {
        "the `name` of an [[obstacle]] (this scene names none), or \"NAME/PART\" for a part of an articulated one".to_owned()
    } else {
        format!("one of {}", known.join(", "))
    };
    Err(Issue::new(path, Kind::BadValue, e).allowed(allowed))
}
