//! Pins attached to an obstacle or a part of one (`attach`,
//! `src/kinematics/carrier.rs`): the held vertices follow the part's pose
//! exactly, with its exact velocity, under both kinds of integrator; they let
//! go at their release time; and the scene's mistakes name file, line and key.

use drape::collide::obstacle::Body;
use drape::math::{Scalar, Vector};
use drape::pins::Pins;
use drape::scene::{Scene, load_scene_str};

use crate::common::Sim;

/// A sheet whose top edge is attached to the lower link of a two-link arm:
/// the root (turned 90 deg about z) slides 0.5 m along y and turns back from
/// 1 s to 2 s, the shoulder turns 90 deg about its y from 0 s to 1 s and the
/// elbow turns about a skew axis from 0.2 s to 1.6 s, all smooth.
const ARM: &str = r#"
name = "carried"
[simulation]
duration = 2.0
[cloth]
shape = "rectangle"
width = 0.2
height = 0.2
resolution = 4
position = [1.15, 0.0, -0.35]
[material]
density = 0.15
stretch = 200.0
bending = 1.0e-5
damping = 0.001
[[pin]]
region = "edge:top"
attach = "arm/lower"
[[obstacle]]
name = "arm"
shape = "articulated"
position = [1.0, 0.0, 0.0]
rotation = [0.0, 0.0, 90.0]
easing = "smooth"
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
easing = "smooth"
keyframes = [{ time = 0.0 }, { time = 1.0, rotation = [0.0, 90.0, 0.0] }]
[[obstacle.part]]
name = "lower"
parent = "upper"
joint = [0.0, 0.0, -0.3]
shape = "box"
half_extents = [0.04, 0.04, 0.12]
center = [0.0, 0.0, -0.15]
easing = "smooth"
keyframes = [{ time = 0.2 }, { time = 1.6, rotation = [30.0, 60.0, 10.0] }]
[[obstacle]]
name = "ball"
shape = "sphere"
radius = 0.1
position = [3.0, 0.0, 0.0]
"#;

fn arm(sets: &[&str]) -> Scene {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    load_scene_str(ARM, "arm.toml", &sets).expect("scene")
}

/// Runs `scene` for `steps` steps of `h` and compares every held vertex after
/// every step with the lower link's pose: returns the largest position error
/// (m), the largest difference from the link's point velocity (m/s) and the
/// largest relative difference from the finite difference of its positions.
fn follow(scene: &Scene, h: Scalar, steps: usize) -> (Scalar, Scalar, Scalar) {
    let lower = Body::from_spec(0, &scene.obstacle[0].resolve().expect("resolved"))
        .expect("bodies")
        .remove(1);
    let mut sim = Sim::new(scene);
    let held: Vec<(usize, Vector)> = sim
        .state
        .world
        .pins
        .anchors
        .iter()
        .map(|a| {
            let i = a.vertex as usize;
            (
                i,
                lower
                    .pose(0.0)
                    .inverse_transform_point(sim.state.world.x[i]),
            )
        })
        .collect();
    assert_eq!(held.len(), 5, "the top edge of a 4 x 4 grid");
    let at = |t: Scalar, local: Vector| lower.pose(t).transform_point(local);
    let (mut dx, mut dv, mut dfd): (Scalar, Scalar, Scalar) = (0.0, 0.0, 0.0);
    for _ in 0..steps {
        sim.step(h);
        let w = &sim.state.world;
        let t = w.time;
        for &(i, local) in &held {
            let want = at(t, local);
            dx = dx.max((w.x[i] - want).length());
            dv = dv.max((w.v[i] - lower.point_velocity(t, want)).length());
            // Small, for the smooth keys' jumps in acceleration: there the
            // central difference is off by d |jump| / 4.
            let d = 1e-7;
            let fd = (at(t + d, local) - at(t - d, local)) / (2.0 * d);
            dfd = dfd.max((w.v[i] - fd).length() / fd.length().max(1.0));
        }
    }
    (dx, dv, dfd)
}

#[test]
fn attached_pins_follow_a_turning_part_exactly() {
    for (integrator, h, steps) in [("implicit", 0.005, 390), ("symplectic_euler", 2.5e-4, 7800)] {
        let scene = arm(&[&format!("simulation.integrator=\"{integrator}\"")]);
        let (dx, dv, dfd) = follow(&scene, h, steps);
        println!(
            "{integrator}: {steps} steps of {h} s to {} s: held vertices off the part's pose by at most \
             {dx:.1e} m, off its point velocity by {dv:.1e} m/s, off the finite difference by {dfd:.1e} (relative)",
            h * steps as Scalar
        );
        assert!(dx < 1e-12, "{integrator}: {dx} m");
        assert!(dv < 1e-12, "{integrator}: {dv} m/s");
        assert!(dfd < 1e-6, "{integrator}: {dfd}");
    }
}

#[test]
fn attached_pins_let_go_at_their_release_time() {
    let scene = arm(&["pin.0.release_time=0.5"]);
    let lower = Body::from_spec(0, &scene.obstacle[0].resolve().expect("resolved"))
        .expect("bodies")
        .remove(1);
    let mut sim = Sim::new(&scene);
    let i = sim.state.world.pins.anchors[0].vertex as usize;
    let local = lower
        .pose(0.0)
        .inverse_transform_point(sim.state.world.x[i]);
    let mut off = Vec::new();
    for _ in 0..200 {
        sim.step(0.005);
        let t = sim.state.world.time;
        if (t - 0.45).abs() < 1e-9 || (t - 1.0).abs() < 1e-9 {
            off.push((sim.state.world.x[i] - lower.pose(t).transform_point(local)).length());
        }
    }
    println!(
        "a vertex released at 0.5 s is off the part by {:.1e} m at 0.45 s and {:.1e} m at 1 s",
        off[0], off[1]
    );
    assert!(off[0] < 1e-12, "held before 0.5 s: {}", off[0]);
    assert!(off[1] > 1e-3, "free after 0.5 s: {}", off[1]);
}

#[test]
fn a_pin_attached_to_a_still_obstacle_stays_put() {
    let scene = arm(&["pin.0.attach=\"ball\""]);
    let mut sim = Sim::new(&scene);
    let start = sim.state.world.x.clone();
    for _ in 0..20 {
        sim.step(0.005);
    }
    let w = &sim.state.world;
    for a in &w.pins.anchors {
        let i = a.vertex as usize;
        assert_eq!(w.x[i], start[i]);
        assert_eq!(w.v[i], Vector::ZERO);
    }
}

/// ARM with the first occurrence of `from` replaced by `to`.
fn edit(from: &str, to: &str) -> String {
    let at = ARM
        .find(from)
        .unwrap_or_else(|| panic!("{from} is not in ARM"));
    format!("{}{to}{}", &ARM[..at], &ARM[at + from.len()..])
}

#[test]
fn attach_mistakes_name_file_line_and_key() {
    let attach = "attach = \"arm/lower\"";
    let cases: [(&str, &str, &str, &str); 8] = [
        (
            attach,
            "attach = \"leg\"",
            "key `pin.0.attach`: no obstacle is named `leg`; allowed: one of \"arm\", \"arm/upper\", \"arm/lower\", \"ball\"",
            "attach = ",
        ),
        (
            attach,
            "attach = \"arm/elbow\"",
            "key `pin.0.attach`: obstacle `arm` has no part named `elbow`",
            "attach = ",
        ),
        (
            attach,
            "attach = \"ball/top\"",
            "key `pin.0.attach`: obstacle `ball` is a sphere, which has no parts",
            "attach = ",
        ),
        (
            attach,
            "attach = \"arm/\"",
            "key `pin.0.attach`: `arm/` is not of the form \"NAME\"",
            "attach = ",
        ),
        (
            attach,
            "attach = \"arm/lower\"\nmotion = \"fixed\"",
            "key `pin.0.motion`: `motion` and `attach` both say how the pin moves",
            "motion = ",
        ),
        (
            attach,
            "attach = \"arm/lower\"\ncenter = [0.0, 0.0, 1.0]",
            "key `pin.0.center`: `center` does not apply to a pin with `attach`",
            "center = [0.0, 0.0, 1.0]",
        ),
        (
            "name = \"ball\"",
            "name = \"arm\"",
            "key `obstacle.1.name`: obstacle 0 already has the name `arm`",
            "name = \"arm\"\nshape = \"sphere\"",
        ),
        (
            "name = \"ball\"",
            "name = \"a/b\"",
            "key `obstacle.1.name`: `a/b` contains `/`",
            "name = \"a/b\"",
        ),
    ];
    for (from, to, needle, at) in cases {
        let text = edit(from, to);
        let e = load_scene_str(&text, "arm.toml", &[])
            .expect_err("refused")
            .to_string();
        println!("{e}");
        assert!(e.contains(needle), "{e}");
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
    // Given by --set, the message names the --set.
    let e = load_scene_str(ARM, "arm.toml", &["pin.0.attach=\"arm/hand\"".into()])
        .expect_err("refused")
        .to_string();
    assert!(
        e.starts_with("arm.toml: --set pin.0.attach=\"arm/hand\": key `pin.0.attach`"),
        "{e}"
    );
    // A mesh sequence has no rigid frame.
    let dir = std::env::temp_dir().join(format!("drape-attach-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    for f in ["f0.obj", "f1.obj"] {
        std::fs::write(dir.join(f), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("frame");
    }
    let text = edit(attach, "attach = \"seq\"")
        + "[[obstacle]]\nname = \"seq\"\nshape = \"mesh_sequence\"\nfiles = [\"f0.obj\", \"f1.obj\"]\nframe_rate = 1.0\n";
    let path = dir.join("arm.toml");
    std::fs::write(&path, &text).expect("scene");
    let e = drape::scene::load_scene_file(&path, &[])
        .expect_err("refused")
        .to_string();
    println!("{e}");
    let line = text
        .lines()
        .position(|l| l.contains("attach = "))
        .expect("attach")
        + 1;
    assert!(
        e.starts_with(&format!(
            "{}:{line}: key `pin.0.attach`: obstacle `seq` is a mesh sequence",
            path.display()
        )),
        "{e}"
    );
    assert!(
        e.contains("to an articulated obstacle's root frame or to one of its parts"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
    // Without obstacles the engine refuses it too.
    let scene = arm(&[]);
    let world = drape::world::World::from_scene(&scene).expect("world");
    let e = Pins::select(&scene.pin, &world.mesh, &world.x).expect_err("no obstacles");
    assert_eq!(e.to_string(), "pin 0: attach: no obstacle is named `arm`");
}

#[test]
fn the_capes_attached_pin_moves_as_the_roots_keys_did() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cape.toml");
    let scene = drape::scene::load_scene_file(&path, &[]).expect("scene");
    // The same pin with its own keys: the root's, about the root's position
    // (the torso turns only with the root).
    let mut keyed = scene.clone();
    let root = &scene.obstacle[0];
    let pin = &mut keyed.pin[0];
    pin.attach = None;
    pin.motion = drape::scene::PinMotion::Keyframed;
    pin.center = root.position;
    pin.easing = root.easing;
    pin.keyframes = root.keyframes.clone();
    let a = drape::world::World::from_scene(&scene).expect("attached");
    let b = drape::world::World::from_scene(&keyed).expect("keyed");
    let mut worst: Scalar = 0.0;
    for t in [0.0, 1.0, 2.3, 2.75, 3.4, 4.1, 5.0] {
        for (p, q) in a.pins.anchors.iter().zip(&b.pins.anchors) {
            let ((xa, va), (xb, vb)) = (a.pins.target(p, t), b.pins.target(q, t));
            worst = worst.max((xa - xb).length()).max((va - vb).length());
        }
    }
    println!("attached and keyed cape pins differ by at most {worst:.1e} (m, m/s)");
    assert!(worst < 1e-12, "{worst}");
}

#[test]
fn attached_pins_are_identical_at_any_thread_count() {
    // 25 x 25 vertices, so that the per-vertex passes split over threads;
    // the sheet starts 1 cm into the lower link, which pushes it out.
    let scene = arm(&["cloth.resolution=24", "cloth.position=[1.13, 0.0, -0.35]"]);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let mut sim = Sim::new(&scene);
            for _ in 0..120 {
                sim.step(0.005);
            }
            (sim.state.world.x, sim.state.ledger.collision.contacts)
        })
    };
    let (a, b) = (run(1), run(3));
    println!("{} contacts with 1 and with 3 threads: {}", a.1, b.1);
    assert_eq!(a.1, b.1);
    assert!(
        a.0.iter()
            .zip(&b.0)
            .all(|(p, q)| p.to_array() == q.to_array())
    );
}
