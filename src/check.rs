//! `drape check`: the resolved model of a scene, in words.

use std::fmt::Write;

use crate::adapt::AdaptConfig;
use crate::collide::{Collider, Obstacles};
use crate::physics::{Elements, ExternalForces, MaterialParams, Membrane, Model, Stepper};
use crate::pins::PinPath;
use crate::run::RunError;
use crate::scene::{
    AdaptCriterion, AdaptMethod, BendingModel, ClothShape, PinMotion, Scene, StiffnessRule,
};
use crate::sim::SimBuildError;
use crate::world::World;

mod step;

use step::describe_time_step;

// Writing to a String cannot fail: every `writeln!` below ignores its `Ok(())`.

/// Describes what a run of `scene` will compute: mesh, forces (and what is not
/// modelled), integrator and time step, pins.
pub fn describe(scene: &Scene) -> Result<String, RunError> {
    let world = World::from_scene(scene)?;
    let model = Model::from_scene(scene);
    let stepper = Stepper::new(&model, &world);
    let mut s = String::new();
    let _ = writeln!(s, "scene `{}`", scene.name);
    describe_cloth(&mut s, scene, &world, &stepper.elements);
    describe_material(&mut s, scene);
    let (ext, mat) = (&model.external, &model.material);
    describe_forces(&mut s, &world, &stepper.elements, mat, ext);
    let adapt = AdaptConfig::from_scene(scene.adapt.as_ref());
    let obstacles = Obstacles::from_scene(scene).map_err(SimBuildError::from)?;
    let collider = Collider::new(&obstacles, scene.self_collision.as_ref());
    let absent = not_modelled(mat, ext, adapt.as_ref(), &obstacles, collider.as_ref());
    let _ = writeln!(s, "not modelled: {}", absent.join(", "));
    if let Some(c) = &collider {
        let _ = writeln!(s, "collisions:");
        for line in obstacles
            .describe()
            .into_iter()
            .chain(c.describe_self_collision())
        {
            let _ = writeln!(s, "  {line}");
        }
    }
    if let Some(a) = &adapt {
        describe_adapt(&mut s, scene, a);
    }
    let adaptive = adapt.is_some();
    describe_time_step(
        &mut s,
        &scene.simulation,
        &model,
        &stepper,
        &world,
        adaptive,
    );
    describe_pins(&mut s, scene, &world);
    Ok(s)
}

/// The `cloth:` line: shape (a rectangle's grid of cells), mesh size, rest
/// area and mass.
fn describe_cloth(s: &mut String, scene: &Scene, world: &World, el: &Elements) {
    let c = &scene.cloth;
    let grid = match (c.shape, c.width, c.height, c.resolution) {
        (ClothShape::Rectangle, Some(w), Some(h), Some(r)) => {
            let cuts = crate::pins::box_cuts(&scene.pin);
            let lines = crate::mesh::fitted_lines(w, h, r, c.short_side_segments, &cuts);
            grid_description(w, h, &lines)
        }
        _ => String::new(),
    };
    let _ = writeln!(
        s,
        "cloth: {:?}{grid}, {} vertices, {} triangles, {} edges ({} interior); rest area {:.6} m^2, mass {:.6} kg",
        scene.cloth.shape,
        world.mesh.vertex_count(),
        world.mesh.triangles.len(),
        world.mesh.edges.len(),
        world.mesh.edges.iter().filter(|e| e.is_interior()).count(),
        world.mesh.total_rest_area(),
        el.total_mass()
    );
}

/// The `material:` line: the area density, and the measured fabric whose
/// values fill the keys the scene does not write.
fn describe_material(s: &mut String, scene: &Scene) {
    let m = &scene.material;
    let preset = m.preset.as_deref().and_then(crate::scene::presets::find);
    let preset = preset.map_or(String::new(), |f| {
        format!(", preset \"{}\" ({}; Wang, O'Brien and Ramamoorthi 2011, linearised at zero strain and curvature)", f.name, f.description)
    });
    let _ = writeln!(s, "material: density {} kg/m^2{preset}", m.density);
}

/// A rectangle's grid in words: its cells, and their range of sizes where
/// the lines are fitted to box pin regions.
fn grid_description(w: f64, h: f64, (us, vs): &(Vec<f64>, Vec<f64>)) -> String {
    let widths = |l: &[f64]| {
        l.windows(2)
            .map(|p| p[1] - p[0])
            .fold((f64::INFINITY, 0.0_f64), |(a, b), w| (a.min(w), b.max(w)))
    };
    let ((u0, u1), (v0, v1)) = (widths(us), widths(vs));
    let (nx, ny) = (us.len() - 1, vs.len() - 1);
    if u1 - u0 <= 1e-12 * u1 && v1 - v0 <= 1e-12 * v1 {
        format!(
            " ({nx} x {ny} cells of {:.4} x {:.4} m)",
            w / nx as f64,
            h / ny as f64
        )
    } else {
        let range = |(a, b): (f64, f64)| {
            if b - a <= 1e-12 * b {
                format!("{:.3}", b * 1e3)
            } else {
                format!("{:.3} to {:.3}", a * 1e3, b * 1e3)
            }
        };
        format!(
            " ({nx} x {ny} cells of {} x {} mm: grid lines on the pin boxes' edges)",
            range((u0, u1)),
            range((v0, v1))
        )
    }
}

/// The `forces computed:` block: stretch always, then each force the scene declares.
fn describe_forces(
    s: &mut String,
    world: &World,
    el: &Elements,
    mat: &MaterialParams,
    ext: &ExternalForces,
) {
    let _ = writeln!(s, "forces computed:");
    let rule = match mat.stiffness_rule {
        StiffnessRule::Consistent => "consistent (Van Gelder: k = stretch * sum(A) / L^2)",
        StiffnessRule::PaperA => "paper_a (k = stretch * 2^(level/2) per spring)",
    };
    let stretch_springs = match mat.membrane {
        Membrane::Springs => {
            let _ = writeln!(
                s,
                "  stretch: membrane \"springs\", {} springs, {} N/m, rule {}",
                world.mesh.edges.len(),
                mat.stretch,
                rule
            );
            world.mesh.edges.len()
        }
        Membrane::Triangles(m) => {
            let _ = writeln!(
                s,
                "  stretch: membrane \"triangles\" (constant-strain, orthotropic St. Venant-Kirchhoff), {} triangles, warp {} N/m, weft {} N/m, shear {} N/m",
                el.kinds.membrane.triangles.len(),
                m.warp,
                m.weft,
                m.shear
            );
            0
        }
    };
    if mat.bending > 0.0 {
        describe_bending(s, el, mat, stretch_springs);
    }
    if mat.damping > 0.0 {
        let _ = writeln!(
            s,
            "  {}",
            match mat.membrane {
                Membrane::Springs => format!(
                    "spring damping: {} s times each spring's stiffness (paper B eq. 2)",
                    mat.damping
                ),
                Membrane::Triangles(_) => format!(
                    "membrane damping: {} s times the strain rate's stress (stiffness proportional)",
                    mat.damping
                ),
            }
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
}

/// The `bending:` line of the bending model in use. The hinge springs of paper A are
/// the springs beyond the `stretch_springs` (one per edge).
fn describe_bending(s: &mut String, el: &Elements, mat: &MaterialParams, stretch_springs: usize) {
    match mat.bending_model {
        BendingModel::ShapeOperator => {
            let _ = writeln!(
                s,
                "  bending: shape operator (curvature tensor per triangle from its edge angles), {} triangles, rigidity {} N m",
                el.kinds.shapes.triangles.len(),
                mat.bending
            );
        }
        BendingModel::Dihedral => {
            let _ = writeln!(
                s,
                "  bending: dihedral angle, {} hinges, rigidity {} N m",
                el.kinds.hinges.hinges.len(),
                mat.bending
            );
        }
        BendingModel::HingeSpring => {
            let _ = writeln!(
                s,
                "  bending: hinge springs (paper A), {} springs, rigidity {} N m",
                el.kinds.springs.springs.len() - stretch_springs,
                mat.bending
            );
        }
    }
}

/// What the scene leaves out, in the order `drape check` names it.
fn not_modelled(
    mat: &MaterialParams,
    ext: &ExternalForces,
    adapt: Option<&AdaptConfig>,
    obstacles: &Obstacles,
    collider: Option<&Collider>,
) -> Vec<&'static str> {
    let mut absent = Vec::new();
    if mat.bending <= 0.0 {
        absent.push("bending");
    }
    if mat.damping <= 0.0 {
        absent.push(match mat.membrane {
            Membrane::Springs => "spring damping",
            Membrane::Triangles(_) => "membrane damping",
        });
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
    if adapt.is_none() {
        absent.push("adaptive meshing");
    }
    if obstacles.is_empty() {
        absent.push("obstacles and collisions");
    }
    if !collider.is_some_and(Collider::has_self_collision) {
        absent.push("self-collision");
    }
    absent
}

/// The `adaptive meshing:` line (and the multirate note when it is on).
fn describe_adapt(s: &mut String, scene: &Scene, a: &AdaptConfig) {
    let _ = writeln!(
        s,
        "adaptive meshing: {}, {}, levels 0..{}, {}{}{}{}",
        match a.method {
            AdaptMethod::Edge =>
                "edge (paper B: longest-edge splits, Delaunay flips, guarded collapses)",
            AdaptMethod::Tensor =>
                "tensor (whole grid lines of the rectangle inserted and removed: anisotropic)",
            _ if a.alternate_diagonals => "red_green (paper A; red splits' diagonals alternating)",
            _ => "red_green (paper A; red splits' diagonals as split)",
        },
        match a.criterion {
            AdaptCriterion::Angle => format!(
                "angle criterion: refine above {} deg, coarsen below {} deg (and below half the upper threshold)",
                a.refine_angle, a.coarsen_angle
            ),
            AdaptCriterion::Sizing => format!(
                "sizing criterion: refine where curvature x spacing exceeds {} deg{}, merge where the parent would carry at most {} deg (hysteresis {})",
                a.refine_angle,
                a.refine_strain
                    .map(|j| format!(" or the strain jumps by more than {j} at an edge"))
                    .unwrap_or_default()
                    + &a.refine_obstacle
                        .map(|r| format!(
                            " or an edge leans towards an obstacle by more than {r} of its height"
                        ))
                        .unwrap_or_default(),
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
        },
        match a.gate {
            Some(g) => format!(
                ", a pass applied when it replaces at least {} of the triangles or a split reads {} or more",
                g.min_change, g.urgent_ratio
            ),
            None => String::new(),
        }
    );
    if scene.adapt.as_ref().is_some_and(|x| x.multirate) {
        let _ = writeln!(
            s,
            "  multirate (paper A): level L takes 2^ceil(L/2) substeps per macro step; the time step below is the macro step"
        );
    }
}

/// One line per pin: region, vertex count, motion and release time (or `pins: none`).
fn describe_pins(s: &mut String, scene: &Scene, world: &World) {
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
        let carrier = world.pins.scripts.get(p).and_then(|s| match &s.path {
            PinPath::Attached(c) => Some(c.describe()),
            _ => None,
        });
        let motion = carrier.unwrap_or_else(|| pin_motion(pin));
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
    for m in crate::pins::mismatches(&scene.pin, &world.mesh) {
        let _ = writeln!(s, "  differs from the scene: {}", m.describe());
    }
}

/// A pin's own `motion`, in words.
fn pin_motion(pin: &crate::scene::Pin) -> String {
    match pin.motion {
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
        PinMotion::Keyframed => format!(
            "keyframed: {} keys from {} s to {} s about {:?}, {:?} easing, then {:?}",
            pin.keyframes.len(),
            pin.keyframes.first().map_or(0.0, |k| k.time),
            pin.keyframes.last().map_or(0.0, |k| k.time),
            pin.center,
            pin.easing,
            pin.after_last
        )
        .to_lowercase(),
    }
}
