//! `drape check`: the resolved model of a scene, in words.

use std::fmt::Write;

use crate::collide::Collider;
use crate::physics::timestep::fit_to_frame;
use crate::physics::{Model, Stepper};
use crate::run::RunError;
use crate::scene::{BendingModel, Integrator, PinMotion, Scene, StiffnessRule, TimeStep};
use crate::world::World;

/// Describes what a run of `scene` will compute: mesh, forces (and what is not
/// modelled), integrator and time step, pins.
pub fn describe(scene: &Scene) -> Result<String, RunError> {
    let world = World::from_scene(scene)?;
    let model = Model::from_scene(scene);
    let stepper = Stepper::new(model, &world);
    let (el, ext, mat) = (
        &stepper.elements,
        &stepper.model.external,
        &stepper.model.material,
    );
    let mut s = String::new();
    let sim = &scene.simulation;
    let frames = sim.frame_count();
    // Writing to a String cannot fail.
    let _ = writeln!(s, "scene `{}`", scene.name);
    let _ = writeln!(
        s,
        "cloth: {:?}, {} vertices, {} triangles, {} edges ({} interior); rest area {:.6} m^2, mass {:.6} kg",
        scene.cloth.shape,
        world.mesh.vertex_count(),
        world.mesh.triangles.len(),
        world.mesh.edges.len(),
        world.mesh.edges.iter().filter(|e| e.is_interior()).count(),
        world.mesh.total_rest_area(),
        el.total_mass()
    );
    let _ = writeln!(s, "forces computed:");
    let rule = match mat.stiffness_rule {
        StiffnessRule::Consistent => "consistent (Van Gelder: k = stretch * sum(A) / L^2)",
        StiffnessRule::PaperA => "paper_a (k = stretch * 2^(level/2) per spring)",
    };
    let stretch_springs = world.mesh.edges.len();
    let _ = writeln!(
        s,
        "  stretch: {} springs, {} N/m, rule {}",
        stretch_springs, mat.stretch, rule
    );
    if mat.bending > 0.0 {
        match mat.bending_model {
            BendingModel::ShapeOperator => {
                let _ = writeln!(
                    s,
                    "  bending: shape operator (curvature tensor per triangle from its edge angles), {} triangles, rigidity {} N m",
                    el.shape_triangles.len(),
                    mat.bending
                );
            }
            BendingModel::Dihedral => {
                let _ = writeln!(
                    s,
                    "  bending: dihedral angle, {} hinges, rigidity {} N m",
                    el.hinges.len(),
                    mat.bending
                );
            }
            BendingModel::HingeSpring => {
                let _ = writeln!(
                    s,
                    "  bending: hinge springs (paper A), {} springs, rigidity {} N m",
                    el.springs.len() - stretch_springs,
                    mat.bending
                );
            }
        }
    }
    if mat.damping > 0.0 {
        let _ = writeln!(
            s,
            "  spring damping: {} s times each spring's stiffness (paper B eq. 2)",
            mat.damping
        );
    }
    if let Some(g) = ext.gravity {
        let _ = writeln!(s, "  gravity: [{}, {}, {}] m/s^2", g.x, g.y, g.z);
    }
    if let Some(d) = ext.drag {
        let _ = writeln!(
            s,
            "  air drag: {d} kg/(m^2 s) against air moving at {:?} m/s",
            ext.air_velocity.to_array()
        );
    }
    if let Some(w) = &ext.wind {
        let _ = writeln!(
            s,
            "  wind: {:?} m/s, pressure coefficient {}, air density {} kg/m^3",
            w.velocity.to_array(),
            w.coefficient,
            w.air_density
        );
    }
    let mut absent = Vec::new();
    if mat.bending <= 0.0 {
        absent.push("bending");
    }
    if mat.damping <= 0.0 {
        absent.push("spring damping");
    }
    if ext.gravity.is_none() {
        absent.push("gravity");
    }
    if ext.drag.is_none() {
        absent.push("air drag");
    }
    if ext.wind.is_none() {
        absent.push("wind");
    }
    let adapt = crate::adapt::AdaptConfig::from_scene(scene.adapt.as_ref());
    if adapt.is_none() {
        absent.push("adaptive meshing");
    }
    let collider = Collider::from_scene(scene)?;
    if !collider.as_ref().is_some_and(Collider::has_obstacles) {
        absent.push("obstacles and collisions");
    }
    if !collider.as_ref().is_some_and(Collider::has_self_collision) {
        absent.push("self-collision");
    }
    let _ = writeln!(s, "not modelled: {}", absent.join(", "));
    if let Some(c) = &collider {
        let _ = writeln!(s, "collisions:");
        for line in c.describe() {
            let _ = writeln!(s, "  {line}");
        }
    }
    if let Some(a) = &adapt {
        let _ = writeln!(
            s,
            "adaptive meshing: {}, {}, levels 0..{}, every {} steps{}{}",
            match a.method {
                crate::scene::AdaptMethod::Edge =>
                    "edge (paper B: longest-edge splits, Delaunay flips, guarded collapses)",
                _ => "red_green (paper A)",
            },
            match a.criterion {
                crate::scene::AdaptCriterion::Angle => format!(
                    "angle criterion: refine above {} deg, coarsen below {} deg (and below half the upper threshold)",
                    a.refine_angle, a.coarsen_angle
                ),
                crate::scene::AdaptCriterion::Sizing => format!(
                    "sizing criterion: refine where curvature x spacing exceeds {} deg, merge where the parent would carry at most {} deg (hysteresis {})",
                    a.refine_angle,
                    a.refine_angle / a.hysteresis,
                    a.hysteresis
                ),
            },
            a.max_level,
            a.every,
            if a.min_edge_length > 0.0 {
                format!(", edges >= {} m", a.min_edge_length)
            } else {
                String::new()
            },
            if a.rollback {
                format!(", rollback (up to {} per step)", a.max_rollbacks)
            } else {
                String::new()
            }
        );
        if scene.adapt.as_ref().is_some_and(|x| x.multirate) {
            let _ = writeln!(
                s,
                "  multirate (paper A): level L takes 2^ceil(L/2) substeps per macro step; the time step below is the macro step"
            );
        }
    }
    let interval = sim.frame_interval();
    let (target, how) = match sim.dt {
        TimeStep::Fixed(dt) => (dt, "fixed".to_string()),
        TimeStep::Auto => {
            let how = match sim.integrator {
                Integrator::Implicit => "auto: implicit accuracy cap".to_string(),
                _ if adapt.is_some() => format!(
                    "auto: stability estimate {:.3e} s on the initial mesh, recomputed whenever the mesh changes",
                    stepper.auto_dt(&world)
                ),
                _ => format!("auto: stability estimate {:.3e} s", stepper.auto_dt(&world)),
            };
            (stepper.auto_dt(&world), how)
        }
    };
    let (steps, dt) = fit_to_frame(target, interval);
    let _ = writeln!(s, "integrator: {:?}", sim.integrator);
    if sim.integrator == Integrator::Implicit {
        let solver = match sim.solver {
            crate::scene::Solver::Direct => format!(
                "direct (sparse Cholesky, reused as the preconditioner of conjugate gradients, refactored after {} iterations)",
                sim.refactor_iterations
            ),
            crate::scene::Solver::Cg => "cg (matrix-free, Jacobi preconditioner)".to_string(),
        };
        let _ = writeln!(s, "  linear solver: {solver}");
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
    let _ = writeln!(s, "time step: {dt:.4e} s ({how}); {steps} steps per frame");
    let _ = writeln!(
        s,
        "run: {} s, {} fps: {} frames after the initial one, {} steps",
        sim.duration,
        sim.frame_rate,
        frames,
        frames * steps
    );
    if scene.pin.is_empty() {
        let _ = writeln!(s, "pins: none");
    }
    for (p, pin) in scene.pin.iter().enumerate() {
        let count = world
            .pins
            .anchors
            .iter()
            .filter(|a| a.pin as usize == p)
            .count();
        let motion = match pin.motion {
            PinMotion::Fixed => "fixed".to_string(),
            PinMotion::Linear => format!(
                "linear, v {:?} m/s, a {:?} m/s^2",
                pin.velocity, pin.acceleration
            ),
            PinMotion::Circular => {
                format!(
                    "circular about {:?} through {:?} at {} rad/s",
                    pin.axis, pin.center, pin.angular_velocity
                )
            }
        };
        let release = pin
            .release_time
            .map(|t| format!(", released at {t} s"))
            .unwrap_or_default();
        let _ = writeln!(
            s,
            "pin {p}: `{}`, {count} vertices, {motion}{release}",
            pin.region
        );
    }
    Ok(s)
}
