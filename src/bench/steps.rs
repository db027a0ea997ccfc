//! The benchmark's time steps: the one step every run of a spatial ladder
//! shares ([`StepPolicy::Common`](super::ladder::StepPolicy::Common)), and the
//! time-step ladder (`drape bench --time-ladder`), which keeps one mesh and
//! shrinks the step to show the temporal error on its own.

use super::BenchError;
use super::ladder::{Ladder, Rung, StepPolicy};
use crate::math::Scalar;
use crate::physics::timestep::fit_to_frame;
use crate::physics::{Model, Stepper};
use crate::run::RunError;
use crate::scene::{Scene, TimeStep};
use crate::world::World;

/// The steps of the time-step ladder's rungs, as divisors of the scene's step.
pub const TIME_LADDER_DIVISORS: [u32; 3] = [1, 2, 4];

/// The time-step ladder's reference step, as a divisor of the scene's step: 8
/// times below the smallest rung's, so that for a first-order integrator the
/// reference's own error is about 1/8 of that rung's.
pub const TIME_REFERENCE_DIVISOR: u32 = 32;

/// The step `scene` takes, fitted to fill its frames exactly: its fixed step,
/// or its automatic one on its initial mesh (the implicit integrator's cap, or
/// the explicit integrators' stability estimate; without multirate).
pub fn scene_step(scene: &Scene) -> Result<Scalar, BenchError> {
    let target = match scene.simulation.dt {
        TimeStep::Fixed(dt) => dt,
        TimeStep::Auto => {
            let world = World::from_scene(scene).map_err(RunError::from)?;
            let model = Model::from_scene(scene);
            let mut stepper = Stepper::new(&model, &world);
            stepper.multirate = false;
            stepper.auto_dt(&model, &world)
        }
    };
    Ok(fit_to_frame(target, scene.simulation.frame_interval()).1)
}

/// How `scene` sets its step, in words (for the report).
pub fn step_origin(scene: &Scene) -> &'static str {
    match (scene.simulation.dt, scene.simulation.integrator) {
        (TimeStep::Fixed(_), _) => "the scene's fixed step",
        (TimeStep::Auto, crate::scene::Integrator::Implicit) => {
            "the implicit integrator's automatic step"
        }
        (TimeStep::Auto, _) => "the explicit stability estimate on the reference's mesh",
    }
}

/// The override that sets a step, in a form that reads back to the same number.
pub fn dt_override(dt: Scalar) -> String {
    format!("simulation.dt={dt:e}")
}

/// The time-step ladder on one uniform mesh (the scene's resolution): rungs at
/// `dt / k` for `k` in [`TIME_LADDER_DIVISORS`], the reference at
/// `dt / TIME_REFERENCE_DIVISOR` on the same mesh. `dt` is the scene's step
/// ([`scene_step`] of the uniform scene).
pub fn time_ladder(dt: Scalar) -> Ladder {
    let uniform = [
        "adapt.method=none".to_owned(),
        "adapt.multirate=false".to_owned(),
    ];
    let rung = TIME_LADDER_DIVISORS
        .iter()
        .map(|&k| {
            let h = dt / Scalar::from(k);
            let mut set = uniform.to_vec();
            set.push(dt_override(h));
            Rung {
                label: if k == 1 {
                    format!("dt {h:.3e}")
                } else {
                    format!("dt/{k} {h:.3e}")
                },
                set,
            }
        })
        .collect();
    let mut reference = uniform.to_vec();
    reference.push(dt_override(dt / Scalar::from(TIME_REFERENCE_DIVISOR)));
    Ladder {
        reference: Some(reference),
        compare: None,
        step: Some(StepPolicy::Own),
        rung,
    }
}
