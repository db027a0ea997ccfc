//! Checks of the `measure` key: every textile measurement a scene asks for must
//! apply to it. What can be told from the scene alone is checked here; whether
//! the pins hold exactly one end of the strip, or the support cylinder stands
//! centred under the specimen, is checked on the built cloth before the run
//! starts (`crate::run`).

use super::error::{Issue, SceneErrorKind as Kind, keys};
use super::{ClothShape, Measurement, ObstacleShape, PinMotion, Scene};

/// The first measurement in `scene.measure` that cannot apply to it, if any.
pub(super) fn measure(scene: &Scene) -> Result<(), Issue> {
    for (i, &m) in scene.measure.iter().enumerate() {
        if scene.measure[..i].contains(&m) {
            let why = format!("\"{m}\" is listed twice");
            return Err(Issue::new(keys(&["measure"]), Kind::BadValue, why));
        }
        let refused = match m {
            Measurement::Cantilever => cantilever(scene),
            Measurement::Cusick => cusick(scene),
        };
        if let Some(why) = refused {
            let message = format!("the {m} measurement {why}");
            return Err(Issue::new(keys(&["measure"]), Kind::NotApplicable, message));
        }
    }
    Ok(())
}

/// Why the cantilever test cannot apply to `scene`: it needs a rectangle held
/// over one end by fixed pins, under gravity alone.
fn cantilever(scene: &Scene) -> Option<String> {
    let fixed = |p: &super::Pin| {
        p.motion == PinMotion::Fixed && p.attach.is_none() && p.release_time.is_none()
    };
    let why = if scene.cloth.shape != ClothShape::Rectangle {
        "needs a rectangular strip (cloth.shape = \"rectangle\")"
    } else if scene.pin.is_empty() {
        "needs [[pin]] tables that clamp one end of the strip, and this scene has none"
    } else if !scene.pin.iter().all(fixed) {
        "needs every pin fixed (motion = \"fixed\") and never released"
    } else if scene.wind.is_some() {
        "compares with the elastica under gravity alone, and this scene has [wind]"
    } else if !scene.obstacle.is_empty() {
        "compares with the elastica under gravity alone, and this scene has [[obstacle]]"
    } else if scene.simulation.gravity == [0.0; 3] {
        "needs gravity (simulation.gravity is zero)"
    } else {
        return None;
    };
    Some(why.to_string())
}

/// Why the Cusick drape test cannot apply to `scene`: it needs a disk specimen
/// and a cylinder obstacle to support it.
fn cusick(scene: &Scene) -> Option<String> {
    let why = if scene.cloth.shape != ClothShape::Disk {
        "needs a disk specimen (cloth.shape = \"disk\")"
    } else if !scene
        .obstacle
        .iter()
        .any(|o| o.shape == ObstacleShape::Cylinder)
    {
        "needs a support disk: a cylinder [[obstacle]] under the specimen"
    } else {
        return None;
    };
    Some(why.to_string())
}
