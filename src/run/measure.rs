//! The textile measurements a scene asks for (`measure`): checked against the
//! built cloth before the run starts, made on its end state.

use super::RunError;
use crate::cantilever::{CantileverSummary, clamps_one_end};
use crate::collide::cusick::CusickSummary;
use crate::scene::{Measurement, Scene};
use crate::sim::Setup;
use crate::world::World;

/// `Err` when a measurement `scene` asks for cannot be made on its built cloth
/// (validation has checked what the scene alone tells).
pub(super) fn check(scene: &Scene, setup: &Setup, world: &World) -> Result<(), RunError> {
    for &measurement in &scene.measure {
        let why = match measurement {
            Measurement::Cantilever if !clamps_one_end(world) => {
                "needs the pins to hold exactly the vertices at one end of the strip (every vertex up to a clamp line across it, none beyond)"
            }
            Measurement::Cusick if !has_cusick_support(scene, setup) => {
                "needs the disk specimen to lie centred on a vertical cylinder of smaller radius (the support disk)"
            }
            _ => continue,
        };
        return Err(RunError::Measurement { measurement, why });
    }
    Ok(())
}

/// True when `scene`'s cloth is a disk specimen centred on a vertical support
/// cylinder of `setup`'s obstacles.
fn has_cusick_support(scene: &Scene, setup: &Setup) -> bool {
    crate::scene::cloth_spec(&scene.cloth, &scene.panel, &scene.seam, &scene.attachment)
        .is_ok_and(|cloth| setup.obstacles.cusick_support(&cloth).is_some())
}

/// The measurements `scene` asks for, made on `world` (its end state).
pub(super) fn at_end(
    scene: &Scene,
    setup: &Setup,
    world: &World,
) -> (Option<CusickSummary>, Option<CantileverSummary>) {
    let asks = |m: Measurement| scene.measure.contains(&m);
    let cusick = asks(Measurement::Cusick)
        .then(|| setup.obstacles.cusick(scene, world))
        .flatten();
    let cantilever = asks(Measurement::Cantilever)
        .then(|| crate::cantilever::for_run(scene, world, &setup.model.material))
        .flatten();
    (cusick, cantilever)
}
