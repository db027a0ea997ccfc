//! Checks of the collision sections, `[[obstacle]]` and `[self_collision]`; each check
//! names the key path, which `parse.rs` turns into a line of the file or a `--set`.

use toml::Table;

use super::error::{Issue, KeyPath, SceneErrorKind as Kind, Seg, keys};
use super::validate::{all_finite, allowed_for, finite, non_negative, out_of_range, positive};
use super::{Obstacle, ObstacleShape, SelfCollision, SequenceFiles};

/// Keys each obstacle shape needs, and the shape-specific keys that do not apply to it.
fn shape_keys(shape: ObstacleShape) -> (&'static str, &'static [&'static str]) {
    match shape {
        ObstacleShape::Sphere => ("sphere", &["radius"]),
        ObstacleShape::Box => ("box", &["half_extents"]),
        ObstacleShape::Plane => ("plane", &[]),
        ObstacleShape::Capsule => ("capsule", &["radius", "half_height"]),
        ObstacleShape::Cylinder => ("cylinder", &["radius", "half_height"]),
        ObstacleShape::Mesh => ("mesh", &["path"]),
        ObstacleShape::Articulated => ("articulated", &["part"]),
        ObstacleShape::MeshSequence => ("mesh_sequence", &["files", "frame_rate"]),
    }
}

/// Keys that only some shapes have; every other shape refuses them.
const SHAPE_SPECIFIC: [(&str, &[ObstacleShape]); 11] = [
    (
        "radius",
        &[
            ObstacleShape::Sphere,
            ObstacleShape::Capsule,
            ObstacleShape::Cylinder,
        ],
    ),
    (
        "half_height",
        &[ObstacleShape::Capsule, ObstacleShape::Cylinder],
    ),
    ("half_extents", &[ObstacleShape::Box]),
    ("normal", &[ObstacleShape::Plane]),
    ("path", &[ObstacleShape::Mesh]),
    ("scale", &[ObstacleShape::Mesh, ObstacleShape::MeshSequence]),
    ("part", &[ObstacleShape::Articulated]),
    ("surface", &[ObstacleShape::Articulated]),
    ("files", &[ObstacleShape::MeshSequence]),
    ("frame_rate", &[ObstacleShape::MeshSequence]),
    ("first_frame", &[ObstacleShape::MeshSequence]),
];

/// Checks obstacle `i`; `written` is its table as written (to tell keys from defaults).
pub(super) fn obstacle(i: usize, o: &Obstacle, written: Option<&Table>) -> Result<(), Issue> {
    let at = |k: &str| -> KeyPath {
        vec![
            Seg::Key("obstacle".into()),
            Seg::Index(i),
            Seg::Key(k.into()),
        ]
    };
    let has = |k: &str| written.is_some_and(|t| t.contains_key(k));
    let (shape, required) = shape_keys(o.shape);
    if let Some((k, _)) = SHAPE_SPECIFIC
        .iter()
        .find(|(k, shapes)| has(k) && !shapes.contains(&o.shape))
    {
        let needs = if required.is_empty() {
            "no size keys (position, rotation and normal place it)".to_string()
        } else {
            required.join(", ")
        };
        return Err(Issue::new(
            at(k),
            Kind::NotApplicable,
            format!("`{k}` does not apply to shape = \"{shape}\""),
        )
        .allowed(format!("for shape = \"{shape}\": {needs}"))
        .because(at("shape")));
    }
    if let Some(k) = required.iter().find(|k| !has(k)) {
        return Err(Issue::new(
            at(k),
            Kind::MissingKey,
            format!("missing required key `{k}` for shape = \"{shape}\""),
        )
        .allowed(allowed_for(&at(k)))
        .because(at("shape")));
    }
    sizes_positive(&at, o.radius, o.half_height, o.half_extents)?;
    direction(at("normal"), o.normal)?;
    if o.path.as_deref().is_some_and(|p| p.trim().is_empty()) {
        return Err(Issue::new(at("path"), Kind::BadValue, "the path is empty")
            .allowed(allowed_for(&at("path"))));
    }
    positive(at("scale"), o.scale)?;
    sequence(&at, o)?;
    all_finite(at("position"), &o.position)?;
    all_finite(at("rotation"), &o.rotation)?;
    non_negative(at("friction_static"), o.friction_static)?;
    if let Some(k) = o.friction_kinetic {
        non_negative(at("friction_kinetic"), k)?;
        if k > o.friction_static {
            return Err(out_of_range(
                at("friction_kinetic"),
                format!(
                    "{k} is larger than friction_static = {}: kinetic friction cannot exceed static friction",
                    o.friction_static
                ),
            )
            .because(at("friction_static")));
        }
    }
    positive(at("thickness"), o.thickness)?;
    all_finite(at("velocity"), &o.velocity)?;
    finite(&at("angular_velocity"), o.angular_velocity)?;
    if o.angular_velocity != 0.0 || has("axis") {
        direction(at("axis"), o.axis)?;
    }
    Ok(())
}

/// The size keys given (`radius`, `half_height`, `half_extents`) are all > 0;
/// `at` gives a key's path. Obstacles and articulated parts share it.
pub(super) fn sizes_positive(
    at: &dyn Fn(&str) -> KeyPath,
    radius: Option<f64>,
    half_height: Option<f64>,
    half_extents: Option<[f64; 3]>,
) -> Result<(), Issue> {
    for (k, v) in [("radius", radius), ("half_height", half_height)] {
        if let Some(x) = v {
            positive(at(k), x)?;
        }
    }
    if let Some(h) = half_extents {
        all_finite(at("half_extents"), &h)?;
        if h.iter().any(|&x| x <= 0.0) {
            return Err(out_of_range(
                at("half_extents"),
                format!("{h:?} has a size that is not > 0"),
            ));
        }
    }
    Ok(())
}

/// A `mesh_sequence`'s keys: a positive frame rate, files that are a pattern
/// with one placeholder or a non-empty list; no motion keys (the frames move it).
fn sequence(at: &dyn Fn(&str) -> KeyPath, o: &Obstacle) -> Result<(), Issue> {
    if let Some(r) = o.frame_rate {
        positive(at("frame_rate"), r)?;
    }
    match &o.files {
        Some(SequenceFiles::Pattern(p)) => {
            if let Err(why) = super::sequence_files::placeholder(p) {
                return Err(
                    Issue::new(at("files"), Kind::BadValue, why).allowed(allowed_for(&at("files")))
                );
            }
        }
        Some(SequenceFiles::List(l)) if l.is_empty() || l.iter().any(|f| f.trim().is_empty()) => {
            return Err(Issue::new(
                at("files"),
                Kind::BadValue,
                "the list of files is empty or names an empty path",
            )
            .allowed(allowed_for(&at("files"))));
        }
        _ => {}
    }
    if o.first_frame.is_some() && !matches!(o.files, Some(SequenceFiles::Pattern(_))) {
        return Err(Issue::new(
            at("first_frame"),
            Kind::NotApplicable,
            "`first_frame` numbers the frames of a `files` pattern, and `files` is a list",
        )
        .because(at("files")));
    }
    Ok(())
}

/// A direction: finite and not zero.
fn direction(path: KeyPath, v: [f64; 3]) -> Result<(), Issue> {
    all_finite(path.clone(), &v)?;
    let len2: f64 = v.iter().map(|a| a * a).sum();
    if !(len2 > 0.0 && len2.is_finite()) {
        return Err(out_of_range(
            path,
            format!("{v:?} has no usable direction (zero or overflowing length)"),
        ));
    }
    Ok(())
}

/// Checks `[self_collision]`.
pub(super) fn self_collision(s: &SelfCollision) -> Result<(), Issue> {
    let at = |k: &str| keys(&["self_collision", k]);
    positive(at("thickness"), s.thickness)?;
    if s.iterations < 1 {
        return Err(out_of_range(
            at("iterations"),
            "0 is out of range: must be >= 1",
        ));
    }
    if let Some(p) = s.patch_size {
        positive(at("patch_size"), p)?;
    }
    Ok(())
}
