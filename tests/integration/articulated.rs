//! Articulated obstacles (`src/kinematics/skeleton.rs`): forward kinematics
//! against hand-computed poses, exact surface velocities against finite
//! differences, a cloth carried by a turning part, the scene's errors, and
//! the cape demo.

use std::f64::consts::FRAC_1_SQRT_2;
use std::sync::atomic::AtomicBool;

use drape::collide::obstacle::Body;
use drape::math::Vector;
use drape::scene::{Scene, load_scene_str};

/// A two-link arm hanging from a root at (1, 0, 0) turned 90 deg about z:
/// each joint turns 90 deg about its y axis from 0 s to 1 s (linear), and
/// the root slides 0.5 m along y and turns back by 90 deg from 1 s to 2 s.
const ARM: &str = r#"
name = "arm"
[simulation]
duration = 2.0
[cloth]
shape = "rectangle"
width = 0.2
height = 0.2
resolution = 2
position = [5.0, 5.0, 5.0]
[material]
density = 0.15
stretch = 200.0
bending = 1.0e-5
[[obstacle]]
shape = "articulated"
position = [1.0, 0.0, 0.0]
rotation = [0.0, 0.0, 90.0]
keyframes = [
  { time = 1.0 },
  { time = 2.0, translation = [0.0, 0.5, 0.0], rotation = [0.0, 0.0, -90.0] },
]
[[obstacle.part]]
name = "upper"
shape = "capsule"
radius = 0.05
half_height = 0.1
center = [0.0, 0.0, -0.15]
keyframes = [{ time = 0.0 }, { time = 1.0, rotation = [0.0, 90.0, 0.0] }]
[[obstacle.part]]
name = "lower"
parent = "upper"
joint = [0.0, 0.0, -0.3]
shape = "box"
half_extents = [0.04, 0.04, 0.12]
center = [0.0, 0.0, -0.15]
keyframes = [{ time = 0.0 }, { time = 1.0, rotation = [0.0, 90.0, 0.0] }]
"#;

fn arm(sets: &[&str]) -> Scene {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    load_scene_str(ARM, "arm", &sets).expect("scene")
}

fn bodies(scene: &Scene) -> Vec<Body> {
    Body::from_spec(0, &scene.obstacle[0].resolve().expect("resolved")).expect("bodies")
}

/// Where local point `q` of `b`'s shape is at `t`.
fn world(b: &Body, t: f64, q: Vector) -> Vector {
    b.pose(t).transform_point(q)
}

#[test]
fn forward_kinematics_matches_hand_computed_poses() {
    let b = bodies(&arm(&[]));
    assert_eq!(b.len(), 2);
    let s = FRAC_1_SQRT_2;
    // Each joint's frame origin, and the lower part's far end (its shape's
    // centre 0.15 m down its z, plus 0.12 m), by hand: at 0.5 s each joint
    // is at 45 deg; Rz(90) maps (x, y, z) to (-y, x, z).
    let cases = [
        // t, upper joint, lower joint, lower end (local (0, 0, -0.27)).
        (0.0, [1.0, 0.0, 0.0], [1.0, 0.0, -0.3], [1.0, 0.0, -0.57]),
        (
            0.5,
            [1.0, 0.0, 0.0],
            // Ry(45) (0, 0, -0.3) = (-0.3 s, 0, -0.3 s), then Rz(90).
            [1.0, -0.3 * s, -0.3 * s],
            // Ry(90) (0, 0, -0.27) = (-0.27, 0, 0), then Rz(90): (0, -0.27, 0).
            [1.0, -0.3 * s - 0.27, -0.3 * s],
        ),
        (
            2.0,
            // The root back at its rest turn, moved 0.5 m along y: Rz(0).
            [1.0, 0.5, 0.0],
            // Ry(90) (0, 0, -0.3) = (-0.3, 0, 0).
            [0.7, 0.5, 0.0],
            // Ry(180) (0, 0, -0.27) = (0, 0, 0.27).
            [0.7, 0.5, 0.27],
        ),
    ];
    for (t, upper, lower, end) in cases {
        // The capsule's centre sits 0.15 m down its part's z from the joint.
        let upper_joint = world(&b[0], t, Vector::new(0.0, 0.0, 0.15));
        let lower_joint = world(&b[1], t, Vector::new(0.0, 0.0, 0.15));
        let lower_end = world(&b[1], t, Vector::new(0.0, 0.0, -0.12));
        for (what, got, want) in [
            ("upper joint", upper_joint, upper),
            ("lower joint", lower_joint, lower),
            ("lower end", lower_end, end),
        ] {
            let off = (got - Vector::from_array(want)).length();
            println!("t = {t} s: {what} at {got:.4?}, by hand {want:.4?}: off by {off:.1e} m");
            assert!(off < 1e-12, "t = {t} s: {what} off by {off} m");
        }
    }
}

#[test]
fn surface_velocities_match_finite_differences() {
    for easing in ["linear", "smooth"] {
        let e = format!("\"{easing}\"");
        let scene = arm(&[
            &format!("obstacle.0.easing={e}"),
            &format!("obstacle.0.part.0.easing={e}"),
            &format!("obstacle.0.part.1.easing={e}"),
            // Joints moving while the root moves.
            "obstacle.0.part.1.keyframes=[{time = 0.5}, {time = 1.7, rotation = [30.0, 60.0, 10.0]}]",
        ]);
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for b in bodies(&scene) {
            for t in [0.25, 0.6, 1.2, 1.55, 1.9] {
                for q in [
                    Vector::ZERO,
                    Vector::new(0.04, 0.04, 0.12),
                    Vector::new(-0.05, 0.02, -0.1),
                ] {
                    let fd = (world(&b, t + h, q) - world(&b, t - h, q)) / (2.0 * h);
                    let exact = b.point_velocity(t, world(&b, t, q));
                    let err = (fd - exact).length() / exact.length().max(1e-3);
                    worst = worst.max(err);
                }
            }
        }
        println!("{easing}: worst relative velocity error {worst:.1e}");
        assert!(worst < 1e-6, "{easing}: {worst}");
    }
}

/// A 0.3 m sheet lying on a tray (a box) at the end of an arm whose joint
/// turns 60 deg about z from 0.5 s to 1.5 s while the root slides 0.1 m
/// along x: the sheet rides along by friction relative to the tray's surface.
const TRAY: &str = r#"
name = "tray"
[simulation]
duration = 2.0
[cloth]
shape = "rectangle"
width = 0.3
height = 0.3
resolution = 8
position = [0.5, 0.0, 0.557]
[material]
density = 0.15
stretch = 200.0
bending = 1.0e-5
damping = 0.001
[[obstacle]]
shape = "articulated"
position = [0.0, 0.0, 0.5]
friction_static = 0.9
friction_kinetic = 0.7
easing = "smooth"
keyframes = [{ time = 0.5 }, { time = 1.5, translation = [0.1, 0.0, 0.0] }]
[[obstacle.part]]
name = "post"
shape = "sphere"
radius = 0.04
[[obstacle.part]]
name = "tray"
parent = "post"
shape = "box"
half_extents = [0.25, 0.25, 0.025]
center = [0.5, 0.0, 0.0]
easing = "smooth"
keyframes = [{ time = 0.5 }, { time = 1.5, rotation = [0.0, 0.0, 60.0] }]
"#;

#[test]
fn a_cloth_on_a_turning_part_moves_with_it() {
    let scene = load_scene_str(TRAY, "tray", &[]).expect("scene");
    let (mut first, mut last) = (None, None);
    let opts = drape::run::RunOptions::default();
    let summary = drape::run::run_observed(
        &scene,
        &opts,
        &AtomicBool::new(false),
        &mut |_| {},
        &mut |f| {
            let c = f.positions.iter().copied().sum::<Vector>() / f.positions.len() as f64;
            if f.sim_time <= 0.5 + 1e-9 {
                first = Some(c);
            } else {
                last = Some(c);
            }
        },
    )
    .expect("run");
    let (c0, c1) = (first.expect("frames"), last.expect("frames"));
    // The joint at (0, 0, 0.5) turns c0 about z by 60 deg, then the root
    // moves it 0.1 m along x.
    let joint = Vector::new(0.0, 0.0, 0.5);
    let want = glam::DQuat::from_rotation_z(60f64.to_radians()) * (c0 - joint)
        + joint
        + Vector::new(0.1, 0.0, 0.0);
    let off = (c1 - want).truncate().length();
    println!(
        "tray turned 60 deg and moved 0.1 m: cloth centre {c0:.4?} -> {c1:.4?}, expected {want:.4?}, \
         off by {off:.4} m; max penetration {} m",
        summary.collision.max_penetration
    );
    assert!(
        off < 0.01,
        "the cloth follows the tray within 1 cm: {off} m"
    );
    assert!(summary.collision.max_penetration < 1e-3);
}

/// ARM with the last occurrence of `from` replaced by `to`.
fn edit(from: &str, to: &str) -> String {
    let at = ARM
        .rfind(from)
        .unwrap_or_else(|| panic!("{from} is not in ARM"));
    format!("{}{to}{}", &ARM[..at], &ARM[at + from.len()..])
}

/// The message of ARM edited by [`edit`], which must be refused.
fn refused(from: &str, to: &str) -> String {
    load_scene_str(&edit(from, to), "arm.toml", &[])
        .expect_err("refused")
        .to_string()
}

/// The 1-based line of ARM where `needle` first occurs.
fn line_of(needle: &str) -> usize {
    ARM.lines()
        .position(|l| l.contains(needle))
        .expect("in ARM")
        + 1
}

#[test]
fn articulated_mistakes_name_file_line_and_key() {
    // The last occurrence: the lower part's keys.
    let lower_keys = "keyframes = [{ time = 0.0 }, { time = 1.0, rotation = [0.0, 90.0, 0.0] }]";
    let cases: [(&str, &str, &str, &str); 8] = [
        (
            "parent = \"upper\"",
            "parent = \"uper\"",
            "key `obstacle.0.part.1.parent`: `uper` is not the name of a part",
            "parent = ",
        ),
        (
            "name = \"upper\"\n",
            "name = \"upper\"\nparent = \"lower\"\n",
            "key `obstacle.0.part.0.parent`: the parents form a cycle (upper -> lower -> upper)",
            "parent = \"lower\"",
        ),
        (
            "radius = 0.05",
            "radius = -0.05",
            "key `obstacle.0.part.0.radius`: -0.05 is out of range: must be > 0",
            "radius = ",
        ),
        (
            "half_extents = [0.04, 0.04, 0.12]",
            "half_extents = [0.04, 0.04, 0.12]\nradius = 0.1",
            "key `obstacle.0.part.1.radius`: `radius` does not apply to this part's shape",
            "radius = 0.1",
        ),
        (
            "shape = \"box\"",
            "shape = \"cylinder\"",
            "key `obstacle.0.part.1.shape`: a part is a primitive",
            "shape = \"cylinder\"",
        ),
        (
            lower_keys,
            "keyframes = [{ time = 1.0 }, { time = 0.5, rotation = [0.0, 90.0, 0.0] }]",
            "key `obstacle.0.part.1.keyframes.1.time`: 0.5 s is not after the key before it",
            "time = 0.5",
        ),
        (
            lower_keys,
            "keyframes = [{ time = 0.0 }, { time = 1.0, translation = [0.1, 0.0, 0.0] }]",
            "key `obstacle.0.part.1.keyframes.1.translation`: a joint only turns",
            "translation = [0.1",
        ),
        (
            "name = \"lower\"",
            "name = \"upper\"",
            "key `obstacle.0.part.1.name`: part 0 already has the name `upper`",
            "name = \"upper\"\nparent",
        ),
    ];
    for (from, to, needle, at) in cases {
        let e = refused(from, to);
        println!("{e}");
        assert!(e.contains(needle), "{e}");
        // The line of the offending key in the edited text.
        let text = edit(from, to);
        let first = at.lines().next().unwrap_or(at);
        let lines: Vec<usize> = text
            .lines()
            .enumerate()
            .filter(|(_, l)| l.contains(first))
            .map(|(i, _)| i + 1)
            .collect();
        assert!(
            lines
                .iter()
                .any(|n| e.starts_with(&format!("arm.toml:{n}: "))),
            "{e}: expected one of lines {lines:?}"
        );
    }
    // Keys of another shape: `part` on a sphere, `radius` on the body.
    let e = refused(
        "shape = \"articulated\"",
        "shape = \"sphere\"\nradius = 0.1",
    );
    assert!(
        e.contains("`part` does not apply to shape = \"sphere\""),
        "{e}"
    );
    let e = refused("rotation = [0.0, 0.0, 90.0]", "radius = 0.1");
    assert!(
        e.starts_with(&format!(
            "arm.toml:{}: key `obstacle.0.radius`",
            line_of("rotation = [0.0, 0.0, 90.0]")
        )),
        "{e}"
    );
}

#[test]
fn the_cape_scene_drapes_and_turns_with_the_mannequin() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cape.toml");
    let sets = ["simulation.duration=2.75".to_string()];
    let scene = drape::scene::load_scene_file(&path, &sets).expect("scene");
    let mut last = Vec::new();
    let opts = drape::run::RunOptions::default();
    let summary = drape::run::run_observed(
        &scene,
        &opts,
        &AtomicBool::new(false),
        &mut |_| {},
        &mut |f| {
            last = f.positions.to_vec();
        },
    )
    .expect("run");
    // Half the turn (smooth keys from 2 s to 3.5 s: 45 deg at 2.75 s): the
    // cape, behind the back (+y) at rest, is carried round with the body.
    let c = last.iter().copied().sum::<Vector>() / last.len() as f64;
    let angle = (-c.x).atan2(c.y).to_degrees();
    let lowest = last.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
    println!(
        "cape at 2.75 s: centre {c:.3?}, turned {angle:.1} deg about the body's axis (body 45 deg), \
         lowest point {lowest:.2} m; max penetration {} m, mean contacts {:.0}",
        summary.collision.max_penetration, summary.collision.contacts
    );
    assert!((25.0..60.0).contains(&angle), "turned {angle} deg");
    assert!(
        lowest < 1.0,
        "the cape hangs down the back: lowest {lowest} m"
    );
    assert!(summary.collision.max_penetration < 5e-3);
}

#[test]
fn moving_parts_are_logged_once_and_placed_every_frame() {
    let out = std::env::temp_dir().join(format!("drape-articulated-{}.rrd", std::process::id()));
    let scene = arm(&["simulation.duration=0.2"]);
    let opts = drape::run::RunOptions {
        record: Some(out.clone()),
        ..drape::run::RunOptions::default()
    };
    let summary =
        drape::run::run(&scene, &opts, &AtomicBool::new(false), &mut |_| {}).expect("run");
    let ins = drape::record::inspect::inspect(&out).expect("decodes");
    for part in ["upper", "lower"] {
        let rows = &ins.entities[&format!("/obstacles/obstacle_0_part_{part}")];
        println!("{part}: {rows:?} over {} frames", summary.extent.frames);
        // The mesh once (static), the transform at every recorded frame.
        assert_eq!(rows.static_rows, 1, "{part}");
        assert_eq!(rows.temporal as u64, summary.extent.frames, "{part}");
    }
    std::fs::remove_file(&out).ok();
}
