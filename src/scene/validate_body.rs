//! Checks of an articulated obstacle's parts (`[[obstacle.part]]`): names,
//! parents (known, no cycle), primitive shapes and their sizes, joint keys.
//! Each check names the key path, which `parse.rs` turns into a line of the
//! file or a `--set`.

use toml::{Table, Value};

use super::error::{Issue, KeyPath, SceneErrorKind as Kind, Seg};
use super::validate::{all_finite, allowed_for, out_of_range};
use super::validate_collide::sizes_positive;
use super::validate_motion::{track, unused};
use super::{Obstacle, ObstacleShape, Part};

/// The size keys of each shape a part may have.
fn part_sizes(shape: ObstacleShape) -> Option<&'static [&'static str]> {
    match shape {
        ObstacleShape::Sphere => Some(&["radius"]),
        ObstacleShape::Capsule => Some(&["radius", "half_height"]),
        ObstacleShape::Box => Some(&["half_extents"]),
        _ => None,
    }
}

/// Checks the parts of obstacle `i` when it is articulated; `written` is the
/// obstacle's table as written.
pub(super) fn parts(i: usize, o: &Obstacle, written: Option<&Table>) -> Result<(), Issue> {
    if o.shape != ObstacleShape::Articulated {
        return Ok(());
    }
    let at = |n: usize, k: &str| -> KeyPath {
        vec![
            Seg::Key("obstacle".into()),
            Seg::Index(i),
            Seg::Key("part".into()),
            Seg::Index(n),
            Seg::Key(k.into()),
        ]
    };
    if o.part.is_empty() {
        let path = vec![
            Seg::Key("obstacle".into()),
            Seg::Index(i),
            Seg::Key("part".into()),
        ];
        return Err(out_of_range(
            path,
            "an articulated obstacle needs at least one part",
        ));
    }
    let tables = written
        .and_then(|t| t.get("part"))
        .and_then(Value::as_array);
    for (n, p) in o.part.iter().enumerate() {
        let table = tables.and_then(|a| a.get(n)).and_then(Value::as_table);
        part(o, n, p, table, &|k| at(n, k))?;
    }
    acyclic(&o.part, &at)
}

/// Checks part `n` (`p`) of `o`; `at` gives the path of one of its keys.
fn part(
    o: &Obstacle,
    n: usize,
    p: &Part,
    written: Option<&Table>,
    at: &dyn Fn(&str) -> KeyPath,
) -> Result<(), Issue> {
    let has = |k: &str| written.is_some_and(|t| t.contains_key(k));
    if p.name.trim().is_empty() {
        return Err(
            Issue::new(at("name"), Kind::BadValue, "the part's name is empty")
                .allowed(allowed_for(&at("name"))),
        );
    }
    if let Some(m) = o.part[..n].iter().position(|q| q.name == p.name) {
        let why = format!("part {m} already has the name `{}`", p.name);
        return Err(Issue::new(at("name"), Kind::BadValue, why).allowed(allowed_for(&at("name"))));
    }
    if let Some(parent) = &p.parent
        && !o.part.iter().any(|q| &q.name == parent)
    {
        let names: Vec<String> = o.part.iter().map(|q| format!("\"{}\"", q.name)).collect();
        let why = format!("`{parent}` is not the name of a part of this obstacle");
        return Err(Issue::new(at("parent"), Kind::BadValue, why).allowed(format!(
            "the name of another part ({}), or no parent for a part on the obstacle's own frame",
            names.join(", ")
        )));
    }
    sizes(p, at, &has)?;
    for (k, v) in [
        ("joint", p.joint),
        ("rotation", p.rotation),
        ("center", p.center),
    ] {
        all_finite(at(k), &v)?;
    }
    if p.keyframes.is_empty() {
        return unused(at, &has, "this part has no `keyframes`");
    }
    track(at, &p.keyframes, p.after_last)?;
    if let Some(m) = p.keyframes.iter().position(|k| k.translation != [0.0; 3]) {
        let mut path = at("keyframes");
        path.extend([Seg::Index(m), Seg::Key("translation".into())]);
        let why = "a joint only turns: a part's keys have a time and a rotation (the obstacle's own keyframes move the whole body)";
        return Err(Issue::new(path, Kind::NotApplicable, why));
    }
    Ok(())
}

/// The part's shape is a primitive with its size keys, all > 0, and no other's.
fn sizes(p: &Part, at: &dyn Fn(&str) -> KeyPath, has: &dyn Fn(&str) -> bool) -> Result<(), Issue> {
    let Some(required) = part_sizes(p.shape) else {
        return Err(Issue::new(
            at("shape"),
            Kind::BadValue,
            "a part is a primitive: sphere, capsule or box",
        )
        .allowed(allowed_for(&at("shape"))));
    };
    if let Some(k) = ["radius", "half_height", "half_extents"]
        .into_iter()
        .find(|k| has(k) && !required.contains(k))
    {
        let why = format!("`{k}` does not apply to this part's shape");
        return Err(Issue::new(at(k), Kind::NotApplicable, why)
            .allowed(format!("for this shape: {}", required.join(", ")))
            .because(at("shape")));
    }
    if let Some(k) = required.iter().find(|k| !has(k)) {
        let why = format!("missing required key `{k}` for this part's shape");
        return Err(Issue::new(at(k), Kind::MissingKey, why)
            .allowed(allowed_for(&at(k)))
            .because(at("shape")));
    }
    sizes_positive(at, p.radius, p.half_height, p.half_extents)
}

/// Every chain of parents reaches a part without a parent (the parents are
/// known to exist).
fn acyclic(parts: &[Part], at: &dyn Fn(usize, &str) -> KeyPath) -> Result<(), Issue> {
    let index = |name: &str| parts.iter().position(|q| q.name == name);
    for (n, p) in parts.iter().enumerate() {
        let mut chain = vec![p.name.as_str()];
        let mut next = p.parent.as_deref().and_then(index);
        while let Some(m) = next {
            chain.push(parts[m].name.as_str());
            if m == n {
                let why = format!(
                    "the parents form a cycle ({}): a body's parts form a tree, with the root's parts having no parent",
                    chain.join(" -> ")
                );
                return Err(Issue::new(at(n, "parent"), Kind::BadValue, why));
            }
            if chain.len() > parts.len() {
                break;
            }
            next = parts[m].parent.as_deref().and_then(index);
        }
    }
    Ok(())
}
