//! Range and consistency checks on a deserialised [`Scene`]. Each check names the
//! key path; `parse.rs` turns the path into a line of the file or a `--set`.

use std::fmt::Display;

use toml::{Table, Value};

use super::error::{Issue, KeyPath, SceneErrorKind as Kind, Seg, dotted, keys, num};
use super::schema;
use super::{Air, Cloth, ClothShape, Pin, PinMotion, Scene, Simulation, TimeStep, Wind};

/// The first problem in `scene`, if any. `doc` is the document it came from
/// (after `--set`), used to tell keys that were written from defaults.
pub(crate) fn validate(scene: &Scene, doc: &Table) -> Result<(), Issue> {
    name(&scene.name)?;
    simulation(&scene.simulation)?;
    cloth(&scene.cloth, section(doc, "cloth"))?;
    super::validate_garment::garment(scene)?;
    super::validate_material::material(
        &scene.material,
        section(doc, "material"),
        scene.simulation.gravity,
    )?;
    let pins = doc.get("pin").and_then(Value::as_array);
    for (i, pin) in scene.pin.iter().enumerate() {
        let written = pins.and_then(|a| a.get(i)).and_then(Value::as_table);
        check_pin(i, pin, scene.cloth.shape, written)?;
    }
    if let Some(a) = &scene.air {
        air(a)?;
    }
    if let Some(w) = &scene.wind {
        wind(w)?;
    }
    let obstacles = doc.get("obstacle").and_then(Value::as_array);
    for (i, o) in scene.obstacle.iter().enumerate() {
        let written = obstacles.and_then(|a| a.get(i)).and_then(Value::as_table);
        super::validate_collide::obstacle(i, o, written)?;
        super::validate_motion::keyframes(i, o, written)?;
        super::validate_body::parts(i, o, written)?;
    }
    super::validate_attach::obstacle_names(&scene.obstacle)?;
    let obstacles = super::validate_attach::resolved(&scene.obstacle)?;
    for (i, pin) in scene.pin.iter().enumerate() {
        super::validate_attach::pin_target(i, pin, &obstacles)?;
    }
    if let Some(s) = &scene.self_collision {
        super::validate_collide::self_collision(s)?;
    }
    if let Some(c) = &scene.camera {
        super::camera::validate(c)?;
    }
    // `method = "none"` is the same as leaving `[adapt]` out: its other keys
    // are not used, so a `--set adapt.method=none` on an adaptive scene is
    // never refused for them.
    let adaptive = scene.adapt.as_ref();
    if let Some(a) = adaptive.filter(|a| a.method != crate::scene::AdaptMethod::None) {
        super::validate_adapt::adapt(
            a,
            scene.simulation.integrator,
            scene.cloth.shape,
            scene.material.stiffness_rule,
        )?;
        if a.refine_obstacle.is_some_and(|r| r != 0.0) && scene.obstacle.is_empty() {
            let path = keys(&["adapt", "refine_obstacle"]);
            let why = "refine_obstacle refines where the cloth leans towards an obstacle, and this scene has no [[obstacle]]";
            return Err(Issue::new(path, Kind::NotApplicable, why));
        }
        if a.method == crate::scene::AdaptMethod::Tensor
            && scene.cloth.diagonals == crate::scene::DiagonalPattern::AlternatingFlipped
        {
            let path = keys(&["cloth", "diagonals"]);
            let why = "the tensor method keeps a regular or alternating grid as it inserts lines; \"alternating_flipped\" is for uniform, red-green and edge-method runs";
            return Err(Issue::new(path, Kind::NotApplicable, why));
        }
    }
    super::validate_measure::measure(scene)
}

fn section<'a>(doc: &'a Table, key: &str) -> Option<&'a Table> {
    doc.get(key).and_then(Value::as_table)
}

pub(super) fn allowed_for(path: &KeyPath) -> String {
    schema::allowed(&dotted(path))
        .unwrap_or("see docs/scenes.md")
        .to_owned()
}

pub(super) fn out_of_range(path: KeyPath, what: impl Display) -> Issue {
    let allowed = allowed_for(&path);
    Issue::new(path, Kind::OutOfRange, what).allowed(allowed)
}

pub(super) fn finite(path: &KeyPath, x: f64) -> Result<(), Issue> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(out_of_range(
            path.clone(),
            format!("{x} is not a finite number"),
        ))
    }
}

pub(super) fn positive(path: KeyPath, x: f64) -> Result<(), Issue> {
    finite(&path, x)?;
    if x > 0.0 {
        Ok(())
    } else {
        Err(out_of_range(
            path,
            format!("{} is out of range: must be > 0", num(x)),
        ))
    }
}

pub(super) fn non_negative(path: KeyPath, x: f64) -> Result<(), Issue> {
    finite(&path, x)?;
    if x >= 0.0 {
        Ok(())
    } else {
        Err(out_of_range(
            path,
            format!("{} is out of range: must be >= 0", num(x)),
        ))
    }
}

pub(super) fn all_finite(path: KeyPath, v: &[f64]) -> Result<(), Issue> {
    match v.iter().find(|x| !x.is_finite()) {
        None => Ok(()),
        Some(x) => Err(out_of_range(
            path,
            format!("element {x} is not a finite number"),
        )),
    }
}

fn name(name: &str) -> Result<(), Issue> {
    if name.trim().is_empty() || name.contains(['/', '\\']) {
        let path = keys(&["name"]);
        let allowed = allowed_for(&path);
        return Err(Issue::new(
            path,
            Kind::BadValue,
            format!("{name:?} is not a usable name"),
        )
        .allowed(allowed));
    }
    Ok(())
}

fn simulation(s: &Simulation) -> Result<(), Issue> {
    let at = |k: &str| keys(&["simulation", k]);
    positive(at("duration"), s.duration)?;
    positive(at("frame_rate"), s.frame_rate)?;
    if let TimeStep::Fixed(dt) = s.dt {
        positive(at("dt"), dt)?;
        let frame = 1.0 / s.frame_rate;
        if dt > frame * (1.0 + 1e-12) {
            return Err(out_of_range(
                at("dt"),
                format!(
                    "{} s is longer than one frame (1/frame_rate = {} s)",
                    num(dt),
                    num(frame)
                ),
            )
            .because(at("frame_rate")));
        }
    }
    super::validate_step::adaptive_dt(s)?;
    super::limits::counts(s)?;
    all_finite(at("gravity"), &s.gravity)?;
    finite(&at("cg_tolerance"), s.cg_tolerance)?;
    if !(s.cg_tolerance > 0.0 && s.cg_tolerance < 1.0) {
        return Err(out_of_range(
            at("cg_tolerance"),
            format!("{} is out of range: must be in (0, 1)", num(s.cg_tolerance)),
        ));
    }
    if s.cg_max_iterations < 1 {
        return Err(out_of_range(
            at("cg_max_iterations"),
            "0 is out of range: must be >= 1",
        ));
    }
    if s.refactor_iterations < 1 {
        return Err(out_of_range(
            at("refactor_iterations"),
            "0 is out of range: must be >= 1",
        ));
    }
    if !(1..=100).contains(&s.newton_iterations) {
        return Err(out_of_range(
            at("newton_iterations"),
            format!(
                "{} is out of range: must be from 1 to 100",
                s.newton_iterations
            ),
        ));
    }
    if !(1..=100_000).contains(&s.quasi_newton_iterations) {
        return Err(out_of_range(
            at("quasi_newton_iterations"),
            format!(
                "{} is out of range: must be from 1 to 100000",
                s.quasi_newton_iterations
            ),
        ));
    }
    finite(&at("newton_tolerance"), s.newton_tolerance)?;
    if !(s.newton_tolerance > 0.0 && s.newton_tolerance < 1.0) {
        return Err(out_of_range(
            at("newton_tolerance"),
            format!(
                "{} is out of range: must be in (0, 1)",
                num(s.newton_tolerance)
            ),
        ));
    }
    if let Some(rest) = s.rest {
        let key = |k: &str| keys(&["simulation", "rest", k]);
        positive(key("speed"), rest.speed)?;
        positive(key("window"), rest.window)?;
    }
    Ok(())
}

/// Keys that a shape needs, and keys that do not apply to it.
fn shape_keys(
    shape: ClothShape,
) -> (
    &'static str,
    &'static [&'static str],
    &'static [&'static str],
) {
    match shape {
        ClothShape::Rectangle => (
            "rectangle",
            &["width", "height", "resolution"],
            &["radius", "path", "uv_scale", "max_edge", "sewing"],
        ),
        ClothShape::Disk => (
            "disk",
            &["radius", "resolution"],
            &[
                "width",
                "height",
                "diagonals",
                "short_side_segments",
                "path",
                "uv_scale",
                "max_edge",
                "sewing",
            ],
        ),
        ClothShape::Obj => (
            "obj",
            &["path"],
            &[
                "width",
                "height",
                "radius",
                "resolution",
                "short_side_segments",
                "diagonals",
                "max_edge",
            ],
        ),
        ClothShape::Panels => (
            "panels",
            &["max_edge"],
            &[
                "width",
                "height",
                "radius",
                "resolution",
                "short_side_segments",
                "diagonals",
                "path",
                "uv_scale",
            ],
        ),
    }
}

fn cloth(c: &Cloth, written: Option<&Table>) -> Result<(), Issue> {
    let at = |k: &str| keys(&["cloth", k]);
    let (shape, required, foreign) = shape_keys(c.shape);
    let has = |k: &str| written.is_some_and(|t| t.contains_key(k));
    if let Some(k) = foreign.iter().find(|k| has(k)) {
        return Err(Issue::new(
            at(k),
            Kind::NotApplicable,
            format!("`{k}` does not apply to shape = \"{shape}\""),
        )
        .allowed(format!("for shape = \"{shape}\": {}", required.join(", ")))
        .because(at("shape")));
    }
    if let Some(k) = required.iter().find(|k| !has(k)) {
        let allowed = allowed_for(&at(k));
        return Err(Issue::new(
            at(k),
            Kind::MissingKey,
            format!("missing required key `{k}` for shape = \"{shape}\""),
        )
        .allowed(allowed)
        .because(at("shape")));
    }
    for (k, v) in [
        ("width", c.width),
        ("height", c.height),
        ("radius", c.radius),
    ] {
        if let Some(x) = v {
            positive(at(k), x)?;
        }
    }
    if c.resolution == Some(0) {
        return Err(out_of_range(
            at("resolution"),
            "0 is out of range: must be >= 1",
        ));
    }
    super::limits::resolution(c.resolution)?;
    super::limits::short_side_segments(c.short_side_segments)?;
    if c.path.as_deref().is_some_and(|p| p.trim().is_empty()) {
        let allowed = allowed_for(&at("path"));
        return Err(Issue::new(at("path"), Kind::BadValue, "the path is empty").allowed(allowed));
    }
    positive(at("uv_scale"), c.uv_scale)?;
    if let Some(e) = c.max_edge {
        positive(at("max_edge"), e)?;
    }
    super::validate_garment::sewing(&c.sewing)?;
    all_finite(at("position"), &c.position)?;
    all_finite(at("rotation"), &c.rotation)
}

fn check_pin(i: usize, p: &Pin, shape: ClothShape, written: Option<&Table>) -> Result<(), Issue> {
    let at = |k: &str| vec![Seg::Key("pin".into()), Seg::Index(i), Seg::Key(k.into())];
    let has = |k: &str| written.is_some_and(|t| t.contains_key(k));
    super::validate_region::check_pin_region(p, shape, &at, &has)?;
    if p.attach.is_some() {
        return super::validate_attach::pin_keys(p, &at, &has);
    }
    check_pin_motion(p, &at, &has)
}

/// A pin's motion and the keys that belong to it.
fn check_pin_motion(
    p: &Pin,
    at: &dyn Fn(&str) -> Vec<Seg>,
    has: &dyn Fn(&str) -> bool,
) -> Result<(), Issue> {
    let (motion, foreign): (&str, &[&str]) = match p.motion {
        PinMotion::Fixed => (
            "fixed",
            &[
                "velocity",
                "acceleration",
                "center",
                "axis",
                "angular_velocity",
            ],
        ),
        PinMotion::Linear => ("linear", &["center", "axis", "angular_velocity"]),
        PinMotion::Circular => ("circular", &["velocity", "acceleration"]),
        PinMotion::Keyframed => (
            "keyframed",
            &["velocity", "acceleration", "axis", "angular_velocity"],
        ),
    };
    if let Some(k) = foreign.iter().find(|k| has(k)) {
        return Err(Issue::new(at(k), Kind::NotApplicable, format!("`{k}` does not apply to motion = \"{motion}\""))
            .allowed("velocity and acceleration for \"linear\"; center, axis and angular_velocity for \"circular\"; keyframes and center for \"keyframed\"")
            .because(at("motion")));
    }
    all_finite(at("velocity"), &p.velocity)?;
    all_finite(at("acceleration"), &p.acceleration)?;
    all_finite(at("center"), &p.center)?;
    all_finite(at("axis"), &p.axis)?;
    finite(&at("angular_velocity"), p.angular_velocity)?;
    let len2: f64 = p.axis.iter().map(|a| a * a).sum();
    if p.motion == PinMotion::Circular && !(len2 > 0.0 && len2.is_finite()) {
        return Err(out_of_range(
            at("axis"),
            format!(
                "{:?} has no usable direction (zero or overflowing length)",
                p.axis
            ),
        ));
    }
    if let Some(t) = p.release_time {
        non_negative(at("release_time"), t)?;
    }
    super::validate_motion::pin_keyframes(p, at, has)
}

fn air(a: &Air) -> Result<(), Issue> {
    non_negative(keys(&["air", "drag"]), a.drag)?;
    positive(keys(&["air", "density"]), a.density)
}

fn wind(w: &Wind) -> Result<(), Issue> {
    all_finite(keys(&["wind", "velocity"]), &w.velocity)?;
    non_negative(keys(&["wind", "coefficient"]), w.coefficient)
}
