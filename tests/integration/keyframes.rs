//! Keyframed obstacles (`src/kinematics/motion.rs`): the interpolation, its exact
//! velocities, friction carrying a cloth along, and the scene's errors.

use std::sync::atomic::AtomicBool;

use drape::kinematics::motion::{RigidState, Track};
use drape::math::Vector;
use drape::scene::{Keyframe, KeyframeAfter, KeyframeEasing, load_scene_str};

/// Runs `scene` without recording, showing every frame to `observe`.
fn watch(
    scene: &drape::scene::Scene,
    observe: &mut (dyn FnMut(&drape::run::FrameState) + Send),
) -> Result<drape::summary::Summary, drape::run::RunError> {
    let opts = drape::run::RunOptions::default();
    drape::run::run_observed(scene, &opts, &AtomicBool::new(false), &mut |_| {}, observe)
}

/// Where the vertex at material point `uv` of shipped scene `name` (with
/// `sets`) is at the last frame.
fn vertex_at_end(name: &str, sets: &[&str], uv: [f64; 2]) -> Vector {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(format!("{name}.toml"));
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let scene = drape::scene::load_scene_file(&path, &sets).expect("scene");
    let at = drape::math::Vector2::new(uv[0], uv[1]);
    let mut found = None;
    watch(&scene, &mut |f| {
        let i = f.material.iter().position(|m| m.distance(at) < 1e-9);
        found = i.map(|i| f.positions[i]);
    })
    .expect("run");
    found.unwrap_or_else(|| panic!("{name}: no vertex at {uv:?} (a grid line)"))
}

fn key(time: f64, translation: [f64; 3], rotation: [f64; 3]) -> Keyframe {
    Keyframe {
        time,
        translation,
        rotation,
    }
}

/// Three keys: a move and a turn about z, then a tilt about x and back.
fn keys() -> Vec<Keyframe> {
    vec![
        key(0.0, [0.0; 3], [0.0; 3]),
        key(1.0, [0.5, 0.0, 0.2], [0.0, 0.0, 90.0]),
        key(2.5, [0.5, -0.3, 0.0], [30.0, 0.0, 120.0]),
    ]
}

/// The world angular velocity that turns `a` into `b` over `dt`.
fn omega_between(a: &RigidState, b: &RigidState, dt: f64) -> Vector {
    let (axis, angle) = (b.rotation * a.rotation.inverse()).to_axis_angle();
    axis * (angle / dt)
}

#[test]
fn keyframes_are_reproduced_and_velocities_match_finite_differences() {
    for easing in [KeyframeEasing::Linear, KeyframeEasing::Smooth] {
        let track = Track::new(&keys(), easing, KeyframeAfter::Hold);
        for k in keys() {
            let s = track.state(k.time);
            let q = glam::DQuat::from_mat3(&drape::math::rotation_from_euler_deg(k.rotation));
            let turn = 1.0 - s.rotation.dot(q).abs();
            let shift = (s.shift - Vector::from_array(k.translation)).length();
            println!(
                "{easing:?} key at {} s: shift off by {shift:.1e} m, turn {turn:.1e}",
                k.time
            );
            assert!(
                shift < 1e-12 && turn < 1e-12,
                "{easing:?}: key at {} s",
                k.time
            );
        }
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for t in [0.1, 0.37, 0.8, 1.2, 1.9, 2.4] {
            let (a, b, s) = (track.state(t - h), track.state(t + h), track.state(t));
            let v = (b.shift - a.shift) / (2.0 * h);
            let w = omega_between(&a, &b, 2.0 * h);
            let dv = (v - s.velocity).length() / s.velocity.length().max(1e-3);
            let dw = (w - s.omega).length() / s.omega.length().max(1e-3);
            worst = worst.max(dv).max(dw);
            assert!(
                dv < 1e-6 && dw < 1e-6,
                "{easing:?} at {t} s: {dv:.1e}, {dw:.1e}"
            );
        }
        println!(
            "{easing:?}: largest relative velocity deviation from finite differences {worst:.1e}"
        );
    }
}

#[test]
fn smooth_easing_stops_at_keys_and_hold_stays_after_the_last() {
    let track = Track::new(&keys(), KeyframeEasing::Smooth, KeyframeAfter::Hold);
    for t in [0.0, 1.0, 2.5] {
        let s = track.state(t);
        assert!(
            s.velocity.length() < 1e-12 && s.omega.length() < 1e-12,
            "{t} s"
        );
    }
    let (end, later) = (track.state(2.5), track.state(7.0));
    assert_eq!(end.shift, later.shift);
    assert_eq!(later.velocity, Vector::ZERO);
    // Linear easing moves at a constant velocity within an interval.
    let linear = Track::new(&keys(), KeyframeEasing::Linear, KeyframeAfter::Hold);
    assert!((linear.state(0.2).velocity - linear.state(0.9).velocity).length() < 1e-12);
}

#[test]
fn rotation_takes_the_shortest_arc_and_a_loop_wraps_without_a_jump() {
    // 0 -> 350 deg about z is a turn of -10 deg, not +350.
    let spin = [
        key(0.0, [0.0; 3], [0.0; 3]),
        key(1.0, [0.0; 3], [0.0, 0.0, 350.0]),
    ];
    let track = Track::new(&spin, KeyframeEasing::Linear, KeyframeAfter::Hold);
    let w = track.state(0.5).omega;
    println!("0 -> 350 deg in 1 s: angular velocity {w:?} rad/s");
    assert!((w.z + 10f64.to_radians()).abs() < 1e-9, "{w:?}");
    // A loop whose last key repeats the first: continuous across the wrap.
    let there_and_back = [
        key(0.0, [0.0; 3], [0.0; 3]),
        key(1.0, [0.4, 0.0, 0.0], [0.0, 0.0, 45.0]),
        key(2.0, [0.0; 3], [0.0, 0.0, 360.0]),
    ];
    let track = Track::new(&there_and_back, KeyframeEasing::Smooth, KeyframeAfter::Loop);
    let (before, after) = (track.state(2.0 - 1e-9), track.state(2.0 + 1e-9));
    let jump = (before.shift - after.shift).length();
    let turn = 1.0 - before.rotation.dot(after.rotation).abs();
    println!("loop wrap: shift jump {jump:.1e} m, turn jump {turn:.1e}");
    assert!(jump < 1e-9 && turn < 1e-12);
    let (a, b) = (track.state(0.3), track.state(4.3));
    assert!((a.shift - b.shift).length() < 1e-12, "the period is 2 s");
}

/// A 0.6 m sheet dropped onto a box platform that, after it has landed, moves
/// 0.2 m along x and turns 90 deg about z (smooth keys, 0.5 s to 1.5 s).
const PLATFORM: &str = r#"
name = "platform"
[simulation]
duration = 2.0
[cloth]
shape = "rectangle"
width = 0.6
height = 0.6
resolution = 12
position = [0.0, 0.0, 0.32]
[material]
density = 0.15
stretch = 200.0
bending = 1.0e-5
damping = 0.001
[[obstacle]]
shape = "box"
half_extents = [0.4, 0.4, 0.05]
position = [0.0, 0.0, 0.25]
friction_static = 0.8
friction_kinetic = 0.6
easing = "smooth"
keyframes = [
  { time = 0.5 },
  { time = 1.5, translation = [0.2, 0.0, 0.0], rotation = [0.0, 0.0, 90.0] },
]
"#;

#[test]
fn a_cloth_on_a_moving_turning_platform_moves_with_it() {
    let scene = load_scene_str(PLATFORM, "platform", &[]).expect("scene");
    let mut at_start = None;
    let mut last = None;
    let mut ends = [0usize; 2];
    let summary = watch(&scene, &mut |f| {
        // The sheet's u axis: the centres of its left and right edges.
        for (end, u) in ends.iter_mut().zip([-0.3, 0.3]) {
            let at = drape::math::Vector2::new(u, 0.0);
            *end = f
                .material
                .iter()
                .position(|m| m.distance(at) < 1e-9)
                .unwrap_or(0);
        }
        let snapshot = f.positions.to_vec();
        if f.sim_time <= 0.5 + 1e-9 {
            at_start = Some(snapshot);
        } else {
            last = Some(snapshot);
        }
    })
    .expect("run");
    let (p0, p1) = (at_start.expect("frames"), last.expect("frames"));
    let centre = |p: &[Vector]| p.iter().copied().sum::<Vector>() / p.len() as f64;
    let moved = centre(&p1) - centre(&p0);
    // The platform's rotation turns the cloth's centre about the platform's
    // origin too: (c0 rotated by 90 deg) + 0.2 x.
    let c0 = centre(&p0);
    let expected = glam::DQuat::from_rotation_z(90f64.to_radians()) * Vector::new(c0.x, c0.y, 0.0)
        + Vector::new(0.2, 0.0, 0.0)
        - Vector::new(c0.x, c0.y, 0.0);
    let off = (moved - expected).truncate().length();
    let axis = |p: &[Vector]| (p[ends[1]] - p[ends[0]]).truncate();
    assert_ne!(ends[0], ends[1], "the edge centres are mesh vertices");
    let turned = axis(&p0).angle_to(axis(&p1)).to_degrees();
    println!(
        "platform moved 0.2 m and turned 90 deg: cloth centre moved {moved:?} (off by {off:.4} m), \
         its u axis turned {turned:.2} deg; max penetration {} m",
        summary.collision.max_penetration
    );
    assert!(
        off < 0.01,
        "the cloth follows the platform within 1 cm: off by {off} m"
    );
    assert!((turned - 90.0).abs() < 2.0, "turned {turned} deg");
}

/// `drape`-style loading of PLATFORM with `sets`: the error's text.
fn refused(sets: &[&str]) -> String {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    load_scene_str(PLATFORM, "platform", &sets)
        .expect_err("refused")
        .to_string()
}

#[test]
fn keyframe_mistakes_name_the_key() {
    let cases: [(&[&str], &str); 6] = [
        (
            &["obstacle.0.keyframes.1.time=0.5"],
            "key `obstacle.0.keyframes.1.time`: 0.5 s is not after the key before it",
        ),
        (
            &["obstacle.0.keyframes.1.time=0.2"],
            "not after the key before it (0.5 s)",
        ),
        (
            &["obstacle.0.keyframes=[{time = 0.5}]"],
            "a keyframed motion needs at least two",
        ),
        (
            &["obstacle.0.keyframes.0.translation=[nan, 0, 0]"],
            "key `obstacle.0.keyframes.0.translation`",
        ),
        (
            &["obstacle.0.velocity=[1, 0, 0]"],
            "`velocity` and `keyframes` both set the motion",
        ),
        (
            &["obstacle.0.after_last=\"loop\""],
            "a loop needs the last key (t = 1.5 s) to repeat the first key's",
        ),
    ];
    for (sets, needle) in cases {
        let e = refused(sets);
        println!("{sets:?}: {e}");
        assert!(e.contains(needle), "{sets:?}: {e}");
    }
    let still = PLATFORM.replace("easing = \"smooth\"", "").replace(
        "keyframes = [\n  { time = 0.5 },\n  { time = 1.5, translation = [0.2, 0.0, 0.0], rotation = [0.0, 0.0, 90.0] },\n]",
        "after_last = \"loop\"",
    );
    let e = load_scene_str(&still, "still", &[])
        .expect_err("refused")
        .to_string();
    assert!(
        e.contains("`after_last` belongs to keyframed motion"),
        "{e}"
    );
}

/// A curtain's top edge on keyframed pins: moved 0.5 m along x, then turned a
/// quarter turn about z through `center` (the origin) as it moves.
const CURTAIN: &str = r#"
name = "curtain"
[simulation]
duration = 2.0
[cloth]
shape = "rectangle"
width = 1.0
height = 1.0
resolution = 12
position = [0.0, 0.0, 1.0]
rotation = [90.0, 0.0, 0.0]
[material]
density = 0.15
stretch = 200.0
bending = 1.0e-5
damping = 0.001
[[pin]]
region = "edge:top"
motion = "keyframed"
easing = "smooth"
keyframes = [
  { time = 0.0 },
  { time = 1.0, translation = [0.5, 0.0, 0.0] },
  { time = 2.0, translation = [0.5, 0.0, 0.0], rotation = [0.0, 0.0, 90.0] },
]
"#;

#[test]
fn keyframed_pins_hold_the_cloth_where_the_keys_say() {
    let scene = load_scene_str(CURTAIN, "curtain", &[]).expect("scene");
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    watch(&scene, &mut |f| {
        for (m, p) in f.material.iter().zip(f.positions) {
            if (m.y - 0.5).abs() > 1e-12 {
                continue;
            }
            // The top edge starts at (u, 0, 1.5).
            let expected = if (f.sim_time - 1.0).abs() < 1e-9 {
                Some(Vector::new(m.x + 0.5, 0.0, 1.5))
            } else if (f.sim_time - 2.0).abs() < 1e-9 {
                Some(Vector::new(0.5, m.x, 1.5))
            } else {
                None
            };
            if let Some(e) = expected {
                worst = worst.max((*p - e).length());
                checked += 1;
            }
        }
    })
    .expect("run");
    println!("{checked} pinned positions at the keys, largest deviation {worst:.1e} m");
    assert_eq!(checked, 26, "13 top-edge vertices at two keys");
    assert!(worst < 1e-9, "{worst} m");
    let e = load_scene_str(CURTAIN, "curtain", &["pin.0.motion=fixed".into()])
        .expect_err("keyframes without the motion")
        .to_string();
    assert!(
        e.contains("`keyframes` belongs to motion = \"keyframed\""),
        "{e}"
    );
    let e = load_scene_str(CURTAIN, "curtain", &["pin.0.keyframes=[]".into()])
        .expect_err("the motion without keyframes")
        .to_string();
    assert!(e.contains("needs at least two"), "{e}");
}

/// The shipped curtain (nine keyframed rings drawn along a rail) runs, and
/// its last ring has travelled as far as its keys say by 1.5 s (halfway
/// through its smooth 0.5 to 2.5 s move: half of its 1.6 m).
#[test]
fn the_curtain_scene_draws_its_rings_along_the_rail() {
    let ring = vertex_at_end("curtain", &["simulation.duration=1.5"], [1.0, 0.75]);
    let x = ring.x;
    println!("the last ring's vertex at x = {x:.6} m at 1.5 s (keys: 1.0 - 0.8 = 0.2 m)");
    assert!((x - 0.2).abs() < 1e-9, "{x}");
}

/// The shipped turning flag: its clamped second column (its top vertex) orbits the pole's
/// axis, 120 deg round at 2 s, as the keys say (run at 16 segments, whose
/// grid gets a line on the clamp's edge).
#[test]
fn the_turning_flags_pole_turns_its_clamped_column() {
    let sets = ["simulation.duration=2.0", "cloth.resolution=16"];
    let p = vertex_at_end("flag_turning", &sets, [-0.703125, 0.5]);
    let r = 0.046875;
    let a = 120f64.to_radians();
    let expected = Vector::new(-0.75 + r * a.cos(), r * a.sin(), 2.0);
    let off = (p - expected).length();
    println!("clamped column at 2 s: {p:?}, off the keys' pose by {off:.1e} m");
    assert!(off < 1e-9, "{off} m");
}
