//! `drape check`'s time stepping lines: the integrator, the implicit solver's
//! settings, the time step and the run's length.

use std::fmt::Write;

use crate::physics::timestep::fit_to_frame;
use crate::physics::{Model, Stepper};
use crate::scene::{Integrator, Preconditioner, Refactor, Simulation, Solver, TimeStep};
use crate::world::World;

/// The integrator (with the implicit solver's settings), the time step fitted to the
/// frame interval, and the run's length in frames and steps.
pub(super) fn describe_time_step(
    s: &mut String,
    sim: &Simulation,
    model: &Model,
    stepper: &Stepper,
    world: &World,
    adaptive: bool,
) {
    let interval = sim.frame_interval();
    if sim.dt == TimeStep::Adaptive {
        let _ = writeln!(s, "integrator: {:?}", sim.integrator);
        describe_implicit_solver(s, sim);
        describe_adaptive_step(s, sim);
        return;
    }
    let (target, how) = match sim.dt {
        TimeStep::Adaptive => unreachable!("described above"),
        TimeStep::Fixed(dt) => (dt, "fixed".to_string()),
        TimeStep::Auto => {
            let how = match sim.integrator {
                Integrator::Implicit => "auto: implicit accuracy cap".to_string(),
                _ if adaptive => format!(
                    "auto: stability estimate {:.3e} s on the initial mesh, recomputed whenever the mesh changes",
                    stepper.auto_dt(model, world)
                ),
                _ => format!(
                    "auto: stability estimate {:.3e} s",
                    stepper.auto_dt(model, world)
                ),
            };
            (stepper.auto_dt(model, world), how)
        }
    };
    let (steps, dt) = fit_to_frame(target, interval);
    let _ = writeln!(s, "integrator: {:?}", sim.integrator);
    if sim.integrator == Integrator::Implicit {
        describe_implicit_solver(s, sim);
    }
    let _ = writeln!(s, "time step: {dt:.4e} s ({how}); {steps} steps per frame");
    let frames = sim.frame_count();
    let _ = writeln!(
        s,
        "run: {} s, {} fps: {} frames after the initial one, {} steps",
        sim.duration,
        sim.frame_rate,
        frames,
        frames * steps
    );
}

/// `dt = "adaptive"`: the tolerances and the step's bounds.
fn describe_adaptive_step(s: &mut String, sim: &Simulation) {
    let a = sim.adaptive_dt.unwrap_or_default();
    let interval = sim.frame_interval();
    let largest = a.max.map_or(interval, |m| m.min(interval));
    let _ = writeln!(
        s,
        "time step: adaptive, from {:.3e} s to {largest:.4e} s (first {:.3e} s); a step is refused above an error estimate of {:e} m or a penetration of {:e} m",
        a.min,
        crate::sim::step_control::FIRST_STEP.min(largest),
        a.tolerance,
        a.penetration
    );
    let _ = writeln!(
        s,
        "run: {} s, {} fps: {} frames after the initial one",
        sim.duration,
        sim.frame_rate,
        sim.frame_count()
    );
}

/// The implicit integrator's linear solver, its tolerances and the Newton iterations.
fn describe_implicit_solver(s: &mut String, sim: &Simulation) {
    let solver = match sim.solver {
        Solver::Direct => match sim.refactor {
            Refactor::Cost => format!(
                "direct (sparse Cholesky, reused as the preconditioner of conjugate gradients, refactored when an older factor's iterations outweigh a factorization worth {} of them)",
                sim.refactor_iterations
            ),
            Refactor::EverySolve => {
                "direct (sparse Cholesky of every solve's matrix, the preconditioner of conjugate gradients)".to_string()
            }
            Refactor::PerMesh => {
                "direct (sparse Cholesky of each mesh's first matrix, kept as the preconditioner of conjugate gradients until the mesh changes or a solve reaches the iteration cap)".to_string()
            }
        },
        Solver::Cg => "cg (matrix-free, Jacobi preconditioner)".to_string(),
        Solver::QuasiNewton => format!(
            "quasi_newton (L-BFGS, {} pairs, on the backward Euler equations; initial Hessian one scalar Cholesky factor of a weighted graph Laplacian plus the mass, refactored when a step needs {} iterations more than the step after the last factorization; relative residual {:e}, at most {} iterations)",
            crate::physics::implicit::QUASI_NEWTON_HISTORY,
            sim.refactor_iterations,
            sim.newton_tolerance,
            sim.quasi_newton_iterations
        ),
    };
    let _ = writeln!(s, "  linear solver: {solver}");
    if sim.solver == Solver::Direct {
        let factor = match sim.preconditioner {
            Preconditioner::Factor => "the 3x3-block Cholesky factor, double precision",
            Preconditioner::FactorSingle => "the 3x3-block Cholesky factor, single precision",
            Preconditioner::Laplacian => {
                "one scalar Cholesky factor of a weighted graph Laplacian plus the mass, for x, y and z"
            }
        };
        let _ = writeln!(s, "  factored preconditioner: {factor}");
    }
    let _ = writeln!(
        s,
        "  linear solves: relative residual {:e}, at most {} iterations (else the step fails and is retried)",
        sim.cg_tolerance, sim.cg_max_iterations
    );
    let _ = writeln!(
        s,
        "  Newton iterations: at most {}{}",
        sim.newton_iterations,
        if sim.newton_iterations > 1 {
            format!(", relative residual {:e}", sim.newton_tolerance)
        } else {
            " (the linearised step)".to_string()
        }
    );
}
