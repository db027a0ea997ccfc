//! Validation of `dt = "adaptive"` and its `[simulation.adaptive_dt]` table.

use super::error::{Issue, SceneErrorKind as Kind, keys, num};
use super::validate::{out_of_range, positive};
use super::{Integrator, Simulation, TimeStep};

/// `dt = "adaptive"` needs the implicit integrator (its error estimate is
/// backward Euler's), and its tolerances are positive, its steps ordered and
/// no longer than a frame. With another `dt` the `[simulation.adaptive_dt]`
/// table is neither used nor checked, as `[adapt]` is with `method = "none"`:
/// `--set simulation.dt=0.005` runs a scene that steps adaptively at a fixed
/// step (the time-step ladder does so).
pub(super) fn adaptive_dt(s: &Simulation) -> Result<(), Issue> {
    let at = |k: &str| keys(&["simulation", "adaptive_dt", k]);
    if s.dt != TimeStep::Adaptive {
        return Ok(());
    }
    if s.integrator != Integrator::Implicit {
        return Err(Issue::new(
            keys(&["simulation", "dt"]),
            Kind::NotApplicable,
            "dt = \"adaptive\" controls backward Euler's error and needs integrator = \"implicit\"; the explicit integrators take dt = \"auto\" (their stability limit) or a fixed step",
        )
        .allowed("\"auto\" or a finite number of seconds > 0")
        .because(keys(&["simulation", "integrator"])));
    }
    let a = s.adaptive_dt.unwrap_or_default();
    positive(at("tolerance"), a.tolerance)?;
    positive(at("penetration"), a.penetration)?;
    positive(at("min"), a.min)?;
    let frame = s.frame_interval();
    if a.min > frame * (1.0 + 1e-12) {
        return Err(out_of_range(
            at("min"),
            format!(
                "{} s is longer than one frame (1/frame_rate = {} s)",
                num(a.min),
                num(frame)
            ),
        )
        .because(keys(&["simulation", "frame_rate"])));
    }
    if let Some(max) = a.max {
        positive(at("max"), max)?;
        if max < a.min {
            return Err(out_of_range(
                at("max"),
                format!("{} s is below min = {} s", num(max), num(a.min)),
            )
            .because(at("min")));
        }
    }
    Ok(())
}
