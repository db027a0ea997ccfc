//! Runs with a sewing cap (`[cloth.sewing] max_force`): the force never
//! exceeds the cap while a wide seam closes; a capped seam still closes and
//! welds; one implicit step pulls with the capped force; a cap that is never
//! reached changes no bit of a run; the explicit integrators' multirate steps
//! apply the cap.

use drape::math::{Scalar, Vector};
use drape::sim::SeamState;

use crate::common::Sim;
use crate::garments::seam_state;
use crate::sewing_cap::{capped_forces, two_squares};

/// Steps `sim` by `h` until its seam is welded or `steps` steps are done;
/// the weld time, or `None`.
fn weld(sim: &mut Sim, h: Scalar, steps: usize) -> Option<Scalar> {
    for _ in 0..steps {
        if let SeamState::Welded { time } = seam_state(sim, 0) {
            return Some(time);
        }
        sim.step(h);
    }
    match seam_state(sim, 0) {
        SeamState::Welded { time } => Some(time),
        SeamState::Open => None,
    }
}

#[test]
fn sewing_force_never_exceeds_its_cap_while_a_10_cm_seam_closes() {
    // 50 N/m per m capped at 0.5 N/m: the cap holds beyond 1 cm.
    let mut sim = two_squares(0.08, &["cloth.sewing.max_force=0.5"]);
    let (mut worst, mut uncapped, mut steps): (Scalar, Scalar, usize) = (0.0, 0.0, 0);
    while seam_state(&sim, 0) == SeamState::Open && steps < 200 {
        let el = &sim.pipe.stepper().elements;
        assert!(!el.kinds.springs.caps.is_empty());
        for (f, cap, kd) in capped_forces(el, &sim.state.world.mesh.triangles, &sim.state.world.x) {
            worst = worst.max(f.length() / cap);
            uncapped = uncapped.max(kd / cap);
        }
        sim.step(0.005);
        steps += 1;
    }
    let SeamState::Welded { time } = seam_state(&sim, 0) else {
        panic!("the 10 cm seam still open after {steps} steps");
    };
    let mut free = two_squares(0.08, &[]);
    let free_time = weld(&mut free, 0.005, 200).expect("the uncapped seam welds");
    println!(
        "10 cm gap, cap 0.5 N/m: largest |f| / cap {worst:.15} over {steps} steps \
         (uncapped k d / cap up to {uncapped:.3}); welded at {time:.3} s, uncapped at {free_time:.3} s"
    );
    assert!(worst <= 1.0 + 1e-12, "{worst}");
    assert!(worst > 1.0 - 1e-12, "the cap was reached");
    assert!(
        uncapped > 9.0,
        "the uncapped pull would have been 10 times the cap"
    );
    assert!(time < 0.5, "welded at {time} s");
}

#[test]
fn a_capped_5_cm_seam_still_closes_and_welds() {
    for solver in ["direct", "cg"] {
        let solver_set = format!("simulation.solver={solver}");
        let sets = ["cloth.sewing.max_force=0.5", solver_set.as_str()];
        let mut sim = two_squares(0.03, &sets);
        let before = sim.state.world.mesh.vertex_count();
        let pairs = sim.state.world.mesh.panels().expect("panels").seams[0]
            .pairs
            .len();
        let time = weld(&mut sim, 0.005, 200).expect("the capped 5 cm seam welds within 1 s");
        let mut free = two_squares(0.03, &[solver_set.as_str()]);
        let free_time = weld(&mut free, 0.005, 200).expect("the uncapped seam welds");
        let mesh = &sim.state.world.mesh;
        let boundary: Scalar = (0..mesh.edges.len())
            .filter(|&e| !mesh.edges[e].is_interior())
            .map(|e| mesh.rest_length(e))
            .sum();
        println!(
            "{solver}: 5 cm gap, cap 0.5 N/m: welded at {time:.3} s (uncapped {free_time:.3} s), \
             {before} -> {} vertices, boundary {boundary:.6} m",
            mesh.vertex_count()
        );
        assert!(time < 0.5, "welded at {time} s");
        assert_eq!(mesh.vertex_count(), before - pairs);
        assert!((boundary - 1.2).abs() < 1e-9, "boundary {boundary}");
    }
}

/// Positions, velocities and seam state after `steps` steps of `h`.
fn run(mut sim: Sim, h: Scalar, steps: usize) -> (Vec<[Scalar; 3]>, Vec<[Scalar; 3]>, SeamState) {
    for _ in 0..steps {
        sim.step(h);
    }
    let w = &sim.state.world;
    let state = seam_state(&sim, 0);
    let x = w.x.iter().map(|p| p.to_array()).collect();
    (x, w.v.iter().map(|p| p.to_array()).collect(), state)
}

#[test]
fn a_cap_that_is_never_reached_changes_no_bit_of_a_run() {
    let never = "cloth.sewing.max_force=1e9";
    // Implicit through the weld (0.3 s); RK4 at a stable step for 0.02 s.
    for (integrator, steps) in [("implicit", 60), ("rk4", 150)] {
        let set = format!("simulation.integrator={integrator}");
        let without = two_squares(0.03, &[set.as_str()]);
        let with = two_squares(0.03, &[set.as_str(), never]);
        assert!(!with.pipe.stepper().elements.kinds.springs.caps.is_empty());
        let h = match integrator {
            "implicit" => 0.005,
            _ => {
                0.5 * without
                    .pipe
                    .stepper()
                    .auto_dt(&without.setup.model, &without.state.world)
            }
        };
        let (a, b) = (run(without, h, steps), run(with, h, steps));
        println!(
            "{integrator}: {steps} steps of {h:.3e} s, seam {:?}; identical: {}",
            a.2,
            a == b
        );
        assert_eq!(a, b, "{integrator}");
    }
}

#[test]
fn multirate_steps_apply_the_cap_as_the_plain_explicit_steps_do() {
    for integrator in ["symplectic_euler", "rk4"] {
        let set = format!("simulation.integrator={integrator}");
        let capped = [set.as_str(), "cloth.sewing.max_force=0.5"];
        let plain = two_squares(0.03, &capped);
        let multirate = [
            capped[0],
            capped[1],
            "adapt.method=red_green",
            "adapt.multirate=true",
        ];
        let multi = two_squares(0.03, &multirate);
        let free = two_squares(0.03, &[set.as_str()]);
        let h = 0.5
            * plain
                .pipe
                .stepper()
                .auto_dt(&plain.setup.model, &plain.state.world);
        let x0 = plain.state.world.x.clone();
        let steps = 400;
        let (p, m, f) = (
            run(plain, h, steps),
            run(multi, h, steps),
            run(free, h, steps),
        );
        let largest = |a: &[[Scalar; 3]], b: &[[Scalar; 3]]| {
            a.iter()
                .zip(b)
                .map(|(p, q)| (Vector::from_array(*p) - Vector::from_array(*q)).length())
                .fold(0.0, Scalar::max)
        };
        let moved: Vec<[Scalar; 3]> = x0.iter().map(|p| p.to_array()).collect();
        let (apart, uncapped, travel) = (
            largest(&p.0, &m.0),
            largest(&p.0, &f.0),
            largest(&p.0, &moved),
        );
        println!(
            "{integrator}: {steps} steps of {h:.3e} s: multirate vs plain {apart:.3e} m; \
             capped vs uncapped {uncapped:.3e} m; largest travel {travel:.3e} m"
        );
        assert!(apart <= 1e-12, "{integrator}: {apart}");
        assert!(uncapped > 1e-6, "the cap changes the run");
    }
}

#[test]
fn an_implicit_step_pulls_the_panels_together_with_the_capped_force() {
    // From rest, one short backward Euler step changes the right panel's
    // momentum by h times the sewing springs' pull on it (its own springs
    // cancel): the cap's 0.5 N/m over the 0.2 m seam, not the 1 N of the
    // uncapped springs at a 10 cm gap.
    let h = 1e-5;
    for solver in ["direct", "cg"] {
        let solver_set = format!("simulation.solver={solver}");
        let pull = |sets: &[&str]| {
            let mut all = vec![solver_set.as_str()];
            all.extend_from_slice(sets);
            let mut sim = two_squares(0.08, &all);
            sim.step(h);
            let w = &sim.state.world;
            let (panels, mass) = (
                w.mesh.panels().expect("panels"),
                &sim.pipe.stepper().elements.mass,
            );
            let momentum: Vector = (0..w.v.len())
                .filter(|&i| panels.of_vertex[i] == 1)
                .map(|i| w.v[i] * mass[i])
                .sum();
            -momentum.x / h
        };
        let (capped, free) = (pull(&["cloth.sewing.max_force=0.5"]), pull(&[]));
        println!(
            "{solver}: pull on the right panel {capped:.9} N capped (0.1 expected), {free:.9} N uncapped (1.0)"
        );
        assert!((capped - 0.1).abs() < 1e-4, "{capped}");
        assert!((free - 1.0).abs() < 1e-3, "{free}");
    }
}
