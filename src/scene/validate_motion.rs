//! Checks of keyframed motion (`keyframes`, `easing`, `after_last`) of
//! obstacles and pins; each check names the key path, which `parse.rs` turns into a
//! line of the file or a `--set`.

use toml::Table;

use super::error::{Issue, KeyPath, SceneErrorKind as Kind, Seg};
use super::validate::{all_finite, finite, out_of_range};
use super::{Keyframe, KeyframeAfter, Obstacle, ObstacleShape, Pin, PinMotion};
use crate::math::rotation_from_euler_deg;

/// Largest difference between the last and the first key of a loop, m or
/// quaternion components, that still counts as the same pose.
const LOOP_TOLERANCE: f64 = 1e-9;

/// Checks obstacle `i`'s keyframes; `written` is its table as written.
pub(super) fn keyframes(i: usize, o: &Obstacle, written: Option<&Table>) -> Result<(), Issue> {
    let at = |k: &str| -> KeyPath {
        vec![
            Seg::Key("obstacle".into()),
            Seg::Index(i),
            Seg::Key(k.into()),
        ]
    };
    let has = |k: &str| written.is_some_and(|t| t.contains_key(k));
    if o.shape == ObstacleShape::MeshSequence {
        let moves = [
            "keyframes",
            "velocity",
            "angular_velocity",
            "axis",
            "easing",
        ];
        if let Some(k) = moves.into_iter().find(|k| has(k)) {
            let why = format!(
                "`{k}` does not apply to shape = \"mesh_sequence\": its frames move it (`after_last` says what it does after the last frame)"
            );
            return Err(Issue::new(at(k), Kind::NotApplicable, why).because(at("shape")));
        }
        return Ok(());
    }
    if o.keyframes.is_empty() {
        return unused(&at, &has, "this obstacle has no `keyframes`");
    }
    for k in ["velocity", "angular_velocity"] {
        if has(k) {
            let why = format!("`{k}` and `keyframes` both set the motion: give one of them");
            return Err(Issue::new(at(k), Kind::NotApplicable, why).because(at("keyframes")));
        }
    }
    track(&at, &o.keyframes, o.after_last)
}

/// Checks pin `i`'s keyframes: present exactly with `motion = "keyframed"`.
pub(super) fn pin_keyframes(
    p: &Pin,
    at: &dyn Fn(&str) -> KeyPath,
    has: &dyn Fn(&str) -> bool,
) -> Result<(), Issue> {
    if p.motion != PinMotion::Keyframed {
        if has("keyframes") {
            let why = "`keyframes` belongs to motion = \"keyframed\"";
            return Err(Issue::new(at("keyframes"), Kind::NotApplicable, why).because(at("motion")));
        }
        return unused(at, has, "this pin's motion is not \"keyframed\"");
    }
    track(at, &p.keyframes, p.after_last)
}

/// `easing` and `after_last` without keyframes: refused, `why` saying so.
pub(super) fn unused(
    at: &dyn Fn(&str) -> KeyPath,
    has: &dyn Fn(&str) -> bool,
    why: &str,
) -> Result<(), Issue> {
    match ["easing", "after_last"].into_iter().find(|k| has(k)) {
        Some(k) => {
            let why = format!("`{k}` belongs to keyframed motion, and {why}");
            Err(Issue::new(at(k), Kind::NotApplicable, why))
        }
        None => Ok(()),
    }
}

/// At least two keys, finite, at increasing times; a loop that does not jump.
pub(super) fn track(
    at: &dyn Fn(&str) -> KeyPath,
    keys: &[Keyframe],
    after: KeyframeAfter,
) -> Result<(), Issue> {
    if keys.len() < 2 {
        return Err(out_of_range(
            at("keyframes"),
            format!(
                "{} key given: a keyframed motion needs at least two (a still one needs none)",
                keys.len()
            ),
        ));
    }
    let key = |n: usize, k: &str| -> KeyPath {
        let mut p = at("keyframes");
        p.extend([Seg::Index(n), Seg::Key(k.into())]);
        p
    };
    for (n, k) in keys.iter().enumerate() {
        finite(&key(n, "time"), k.time)?;
        all_finite(key(n, "translation"), &k.translation)?;
        all_finite(key(n, "rotation"), &k.rotation)?;
        if n > 0 && k.time <= keys[n - 1].time {
            return Err(out_of_range(
                key(n, "time"),
                format!(
                    "{} s is not after the key before it ({} s): key times must increase",
                    k.time,
                    keys[n - 1].time
                ),
            ));
        }
    }
    if after == KeyframeAfter::Loop {
        looped(keys, at("after_last"))?;
    }
    Ok(())
}

/// A loop's last key must repeat the first key's pose, or the obstacle jumps
/// where the loop wraps around.
fn looped(keys: &[Keyframe], path: KeyPath) -> Result<(), Issue> {
    let (first, last) = (&keys[0], &keys[keys.len() - 1]);
    let quat = |r: [f64; 3]| glam::DQuat::from_mat3(&rotation_from_euler_deg(r)).normalize();
    let moved = first
        .translation
        .iter()
        .zip(last.translation)
        .any(|(a, b)| (a - b).abs() > LOOP_TOLERANCE);
    // q and -q are the same rotation.
    let turned = 1.0 - quat(first.rotation).dot(quat(last.rotation)).abs() > LOOP_TOLERANCE;
    if moved || turned {
        let why = format!(
            "a loop needs the last key (t = {} s) to repeat the first key's translation and rotation, or the obstacle jumps where the loop wraps around",
            last.time
        );
        return Err(Issue::new(path, Kind::BadValue, why));
    }
    Ok(())
}
