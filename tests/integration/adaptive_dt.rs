//! `dt = "adaptive"`: error control for the implicit integrator
//! (`sim::step_control`), against the closed form of a falling sheet, on a
//! resting and a landing cloth, at any thread count, and its scene errors.

use std::sync::atomic::AtomicBool;

use drape::math::{Scalar, Vector};
use drape::run::{RunOptions, run};
use drape::scene::{SceneErrorKind as Kind, TimeStep, load_scene_str};
use drape::summary::Summary;

use crate::common::Sim;

/// A 1 m sheet at 8 segments, free: no pins, gravity and air drag only.
const FALLING: &str = r#"name = "falling"
[simulation]
duration = 1.0
integrator = "implicit"
dt = "adaptive"
[cloth]
shape = "rectangle"
width = 1.0
height = 1.0
resolution = 8
position = [0.0, 0.0, 2.0]
[material]
density = 0.15
stretch = 200.0
bending = 1.0e-5
[air]
drag = 0.02
"#;

/// A 0.6 m sheet at 12 segments lying on a 1 m table top (thickness 3 mm).
const RESTING: &str = r#"name = "resting"
[simulation]
duration = 1.0
integrator = "implicit"
dt = "adaptive"
[cloth]
shape = "rectangle"
width = 0.6
height = 0.6
resolution = 12
position = [0.0, 0.0, 0.803]
[material]
density = 0.15
stretch = 200.0
bending = 1.0e-5
[[obstacle]]
shape = "box"
half_extents = [0.5, 0.5, 0.02]
position = [0.0, 0.0, 0.78]
thickness = 0.003
friction_static = 0.6
friction_kinetic = 0.4
"#;

fn sets(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| (*s).to_owned()).collect()
}

/// The run summary of the scene `text` with the overrides `args`.
pub(crate) fn summary(text: &str, args: &[&str]) -> Summary {
    let scene = load_scene_str(text, "test.toml", &sets(args)).expect("scene");
    run(
        &scene,
        &RunOptions::default(),
        &AtomicBool::new(false),
        &mut |_| {},
    )
    .expect("run")
}

/// The run's final positions.
fn final_positions(text: &str, args: &[&str]) -> Vec<Vector> {
    let scene = load_scene_str(text, "test.toml", &sets(args)).expect("scene");
    let mut sim = Sim::new(&scene);
    sim.run_frames(&scene);
    sim.state.world.x
}

/// The height of a point falling from rest under gravity `g` against linear
/// drag `c` (per second) after `t` seconds, relative to its start.
fn fall(g: Scalar, c: Scalar, t: Scalar) -> Scalar {
    -(g / c) * t + (g / (c * c)) * (1.0 - (-c * t).exp())
}

/// A free sheet falls as one point: `z(t)` in closed form. Backward Euler's
/// error in free fall is `h^2 g / 2` a step, which is what the estimate
/// measures, so the deviation after the run is at most the steps times the
/// tolerance, and a tolerance four times smaller halves it (the step goes as
/// its square root).
#[test]
fn a_falling_sheet_stays_within_its_steps_times_the_tolerance_of_the_closed_form() {
    let (g, c) = (9.81, 0.02 / 0.15);
    let exact = 2.0 + fall(g, c, 1.0);
    let deviation = |tolerance: &str| {
        let set = format!("simulation.adaptive_dt.tolerance={tolerance}");
        let x = final_positions(FALLING, &[&set]);
        let s = summary(FALLING, &[&set]);
        let worst = x.iter().map(|p| (p.z - exact).abs()).fold(0.0, Scalar::max);
        let a = s.stepping.adaptive_dt.expect("adaptive figures");
        println!(
            "tolerance {tolerance} m: {} steps of {:.3e} to {:.3e} s, {} refused, largest error estimate {:.3e} m; z {:.6} m against {exact:.6} m, deviation {worst:.3e} m",
            s.extent.steps,
            s.stepping.dt,
            a.max_dt,
            a.refused.total(),
            a.largest_error,
            x[0].z,
        );
        let tol: Scalar = tolerance.parse().expect("number");
        assert!(a.largest_error <= tol, "accepted {:.3e} m", a.largest_error);
        assert!(
            worst <= s.extent.steps as Scalar * tol,
            "deviation {worst:.3e} m above {} steps x {tol:e} m",
            s.extent.steps
        );
        worst
    };
    let (coarse, fine) = (deviation("4e-4"), deviation("1e-4"));
    let ratio = coarse / fine;
    println!("deviation ratio for a 4x tighter tolerance: {ratio:.3} (2 expected)");
    assert!(
        (1.6..=2.5).contains(&ratio),
        "deviation {coarse:.3e} -> {fine:.3e} m, ratio {ratio:.3}"
    );
}

/// A sheet at rest on a table makes no error: the step grows to a frame.
#[test]
fn a_cloth_at_rest_on_a_table_steps_a_frame_at_a_time() {
    let s = summary(RESTING, &[]);
    let a = s.stepping.adaptive_dt.expect("adaptive figures");
    println!(
        "resting: {} steps for {} frames, {:.3e} to {:.3e} s, {} refused, largest error estimate {:.3e} m, penetration {:.3e} m",
        s.extent.steps,
        s.extent.frames - 1,
        s.stepping.dt,
        a.max_dt,
        a.refused.total(),
        a.largest_error,
        s.collision.max_penetration
    );
    assert!(
        (a.max_dt - 1.0 / 30.0).abs() < 1e-12,
        "largest {}",
        a.max_dt
    );
    // 10 ms, 20 ms (a frame of two), then a frame a step.
    assert!(
        s.extent.steps <= s.extent.frames + 4,
        "{} steps",
        s.extent.steps
    );
}

/// The sheet dropped 10 cm onto the table: the landing shrinks the step, and
/// no accepted step is above the tolerances.
#[test]
fn a_landing_shrinks_the_step_and_no_accepted_step_exceeds_a_tolerance() {
    let drop = ["cloth.position=[0.0, 0.0, 0.9]", "simulation.duration=0.6"];
    let s = summary(RESTING, &drop);
    let a = s.stepping.adaptive_dt.expect("adaptive figures");
    println!(
        "landing: {} steps, {:.3e} to {:.3e} s, refused {:?}, largest error estimate {:.3e} m, penetration {:.3e} m",
        s.extent.steps,
        s.stepping.dt,
        a.max_dt,
        a.refused,
        a.largest_error,
        s.collision.max_penetration
    );
    assert!(
        s.stepping.dt < 2e-3,
        "smallest step {:.3e} s",
        s.stepping.dt
    );
    assert!(a.max_dt > 2e-2, "largest step {:.3e} s", a.max_dt);
    assert!(a.largest_error <= drape::sim::DEFAULT_STEP_TOLERANCE);
    assert!(s.collision.max_penetration <= drape::sim::DEFAULT_STEP_PENETRATION);
}

#[test]
fn adaptive_steps_are_identical_at_any_thread_count() {
    let drop = ["cloth.position=[0.0, 0.0, 0.9]", "simulation.duration=0.4"];
    let at = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| final_positions(RESTING, &drop))
    };
    let (one, three) = (at(1), at(3));
    let moved = one.iter().map(|p| (p.z - 0.9).abs()).fold(0.0, Scalar::max);
    println!("the sheet moved up to {moved:.4} m; positions compared bit for bit");
    assert!(moved > 0.05);
    assert_eq!(one, three);
}

#[test]
fn adaptive_dt_needs_the_implicit_integrator_and_a_fixed_step_leaves_its_table_unused() {
    let rk4 = load_scene_str(FALLING, "test.toml", &sets(&["simulation.integrator=rk4"]))
        .expect_err("rk4 with an adaptive step");
    let msg = rk4.to_string();
    println!("{msg}");
    assert_eq!(rk4.kind, Kind::NotApplicable, "{msg}");
    assert_eq!(rk4.key.as_deref(), Some("simulation.dt"), "{msg}");
    assert_eq!(rk4.line, Some(5), "{msg}");
    assert!(msg.contains("integrator = \"implicit\""), "{msg}");

    // A fixed step set over a scene that steps adaptively leaves its table
    // unused, so the scene runs at that step, as `[adapt]` with
    // `method = "none"` runs on the base mesh.
    let text = FALLING.replace(
        "dt = \"adaptive\"",
        "dt = \"adaptive\"\n[simulation.adaptive_dt]\ntolerance = 1e-3",
    );
    let fixed = load_scene_str(&text, "test.toml", &sets(&["simulation.dt=0.01"]))
        .expect("a fixed step over a scene with the table");
    assert_eq!(fixed.simulation.dt, TimeStep::Fixed(0.01));

    for (set, key) in [
        (
            "simulation.adaptive_dt.tolerance=0",
            "simulation.adaptive_dt.tolerance",
        ),
        (
            "simulation.adaptive_dt.penetration=-1e-3",
            "simulation.adaptive_dt.penetration",
        ),
        (
            "simulation.adaptive_dt.min=0.1",
            "simulation.adaptive_dt.min",
        ),
    ] {
        let e = load_scene_str(FALLING, "test.toml", &sets(&[set])).expect_err(set);
        println!("{e}");
        assert_eq!(e.kind, Kind::OutOfRange, "{e}");
        assert_eq!(e.key.as_deref(), Some(key), "{e}");
    }
    let e = load_scene_str(
        FALLING,
        "test.toml",
        &sets(&[
            "simulation.adaptive_dt.min=1e-3",
            "simulation.adaptive_dt.max=1e-4",
        ]),
    )
    .expect_err("max below min");
    println!("{e}");
    assert_eq!(e.key.as_deref(), Some("simulation.adaptive_dt.max"), "{e}");
}

/// A tolerance no step can meet stops the run with the reason instead of
/// accepting a step above it.
#[test]
fn a_tolerance_no_step_meets_stops_the_run_with_the_reason() {
    let scene = load_scene_str(
        FALLING,
        "test.toml",
        &sets(&[
            "simulation.adaptive_dt.tolerance=1e-12",
            "simulation.adaptive_dt.min=1e-4",
        ]),
    )
    .expect("scene");
    let e = run(
        &scene,
        &RunOptions::default(),
        &AtomicBool::new(false),
        &mut |_| {},
    )
    .expect_err("no step meets 1e-12 m");
    let msg = e.to_string();
    println!("{msg}");
    assert!(msg.contains("simulation.adaptive_dt.tolerance"), "{msg}");
    assert!(msg.contains("simulation.adaptive_dt.min"), "{msg}");
}
