//! Contact with fast obstacles: a limb sweeping at 5 m/s through a stretched
//! sheet kept at 1 mm (translating, and turning about a joint), with the
//! implicit and the symplectic Euler integrators, checked at every step; and the obstacle term of the sizing rule following a moving
//! ball; and the shipped tablecloth pull, briefly.
//!
//! Contact is per cloth vertex: the limbs here are thicker than the cloth's
//! cells (a capsule of radius 3 cm, 6 cm across, against cells of 2 cm,
//! diagonals of 2.8 cm), so the limb cannot pass between the vertices, and the
//! checks are made on the vertices. An edge between two vertices that wrap the
//! capsule may still cut into it by the sagitta of its chord (about 3 mm for a
//! 2.8 cm diagonal over a 3.1 mm radius), which edge and triangle contact
//! would remove and this pass does not.
//!
//! The friction half of "contact that keeps up" (cloth resting on a
//! keyframed moving box moves with it) is
//! `keyframes::a_cloth_on_a_moving_turning_platform_moves_with_it`, and for
//! an articulated part `articulated::a_cloth_on_a_turning_part_moves_with_it`.

use drape::collide::obstacle::Body;
use drape::math::{Scalar, Vector};
use drape::scene::{Scene, load_scene_str};
use drape::sim::{Pipeline, Setup, SimParts, SimState, build};

/// Capsule radius, m: three cells across.
const RADIUS: Scalar = 0.03;
/// Cloth thickness kept against the limb, m.
const THICK: Scalar = 0.001;

/// A 0.4 m sheet of 20 x 20 cells at z = 0, held along its left and right
/// edges (u = -0.2 m and +0.2 m), with `obstacle` appended.
fn stretched_sheet(obstacle: &str) -> Scene {
    stretched_sheet_with(obstacle, "implicit")
}

/// [`stretched_sheet`] with the time integrator `integrator`.
fn stretched_sheet_with(obstacle: &str, integrator: &str) -> Scene {
    let text = format!(
        r#"
name = "limb"
[simulation]
duration = 0.1
integrator = "{integrator}"
[cloth]
shape = "rectangle"
width = 0.4
height = 0.4
resolution = 20
position = [0.0, 0.0, 0.0]
[material]
density = 0.15
stretch = 200.0
bending = 1.0e-5
damping = 0.001
[[pin]]
region = "edge:left"
[[pin]]
region = "edge:right"
{obstacle}
"#
    );
    match load_scene_str(&text, "limb.toml", &[]) {
        Ok(s) => s,
        Err(e) => panic!("{e}\n{text}"),
    }
}

/// A capsule of radius [`RADIUS`] lying along y under the sheet (axis at
/// z = -0.05 m, 2 cm below the sheet's plane), driven up through the sheet's
/// plane at 5 m/s for 0.04 s (linear keys), then held 0.15 m above it.
fn rising_capsule() -> String {
    format!(
        r#"[[obstacle]]
shape = "capsule"
radius = {RADIUS}
half_height = 0.3
position = [0.0, 0.0, -0.05]
rotation = [90.0, 0.0, 0.0]
thickness = {THICK}
keyframes = [{{ time = 0.0 }}, {{ time = 0.04, translation = [0.0, 0.0, 0.2] }}]
"#
    )
}

/// A capsule limb of radius [`RADIUS`] on a joint at (0, -0.5, -0.05): its
/// axis runs along +y at rest, 2 cm below the sheet, from 0.15 m to 0.75 m
/// from the joint (the tip, with its cap, 0.78 m out). The joint turns it up
/// about x by 15 deg in 0.041 s (linear keys): 6.4 rad/s, the tip at 5 m/s,
/// the part under the sheet (0.3 m to 0.7 m out) at 1.9 to 4.5 m/s.
fn swinging_limb() -> String {
    format!(
        r#"[[obstacle]]
shape = "articulated"
position = [0.0, -0.5, -0.05]
thickness = {THICK}
[[obstacle.part]]
name = "limb"
shape = "capsule"
radius = {RADIUS}
half_height = 0.3
rotation = [-90.0, 0.0, 0.0]
center = [0.0, 0.0, 0.45]
keyframes = [{{ time = 0.0 }}, {{ time = 0.041, rotation = [15.0, 0.0, 0.0] }}]
"#
    )
}

/// The closest point to `x` on segment `a`-`b`.
fn closest_on_segment(a: Vector, b: Vector, x: Vector) -> Vector {
    let d = b - a;
    let s = ((x - a).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    a + d * s
}

/// What the sweep of a limb did to the sheet over a run.
#[derive(Debug, Default)]
struct Sweep {
    /// Smallest clearance of a vertex from the limb's surface over every step, m
    /// (negative: inside).
    clearance: Scalar,
    /// Vertices found behind the limb (in its shadow, on the side it came
    /// from), summed over the steps.
    behind: usize,
    /// Steps taken (halved ones included).
    steps: usize,
    /// Steps the energy check rejected and that were redone as two halves.
    halved: usize,
    /// Largest height the limb lifted a vertex to, m.
    lifted: Scalar,
}

/// The capsule obstacle a sweep is measured against: its body and the half
/// length of its axis (local z).
struct Limb<'a> {
    body: &'a Body,
    half: Scalar,
}

impl Limb<'_> {
    /// Measures every vertex of `x` against the limb at time `t` into `out`:
    /// its clearance from the surface, and whether it lies behind the limb: on
    /// the far side of the axis from where the limb moves (its surface
    /// velocity at the nearest axis point) and within half the limb's width of
    /// the line the axis point sweeps along, the middle of the limb's shadow.
    /// The sheet starts ahead of the limb, so a vertex behind it has gone
    /// through (a vertex wrapped round the limb's sides is not behind).
    fn measure(&self, t: Scalar, x: &[Vector], out: &mut Sweep) {
        let pose = self.body.pose(t);
        let a = pose.transform_point(Vector::new(0.0, 0.0, -self.half));
        let b = pose.transform_point(Vector::new(0.0, 0.0, self.half));
        for &x in x {
            let p = closest_on_segment(a, b, x);
            let off = x - p;
            out.clearance = out.clearance.min(off.length() - RADIUS);
            out.lifted = out.lifted.max(x.z);
            let m = self.body.point_velocity(t, p).normalize_or_zero();
            let ahead = off.dot(m);
            if ahead < 0.0 && (off - m * ahead).length() < 0.5 * RADIUS {
                out.behind += 1;
            }
        }
    }
}

/// Steps `scene` at `h` for `duration` s, measuring the sheet against `limb`
/// after every step ([`Limb::measure`]). A step the health check rejects is
/// redone from its start as two halves, as the frame loop redoes a frame, and
/// counted ([`Sweep::halved`]).
fn sweep(scene: &Scene, limb: &Limb, h: Scalar, duration: Scalar) -> Sweep {
    let SimParts {
        setup,
        mut state,
        pipeline: mut pipe,
    } = build(&scene.resolve().expect("resolve")).expect("simulation");
    let mut out = Sweep {
        clearance: Scalar::INFINITY,
        ..Sweep::default()
    };
    let steps = (duration / h).round() as usize;
    for _ in 0..steps {
        step_checked(&mut pipe, &setup, &mut state, h, limb, &mut out);
    }
    out
}

/// One step of `h` measured against `limb`, or two halves when it is
/// rejected (down to steps of 10 us).
fn step_checked(
    pipe: &mut Pipeline,
    setup: &Setup,
    state: &mut SimState,
    h: Scalar,
    limb: &Limb,
    out: &mut Sweep,
) {
    let saved = state.clone();
    match pipe.step(setup, state, h) {
        Ok(_) => {
            limb.measure(state.world.time, &state.world.x, out);
            out.steps += 1;
        }
        Err(e) if h > 1e-5 => {
            if out.halved == 0 {
                println!("first rejected step, at {:.5} s: {e}", state.world.time);
            }
            state.restore(&saved);
            out.halved += 1;
            for _ in 0..2 {
                step_checked(pipe, setup, state, 0.5 * h, limb, out);
            }
        }
        Err(e) => panic!("step rejected at {} s: {e}", state.world.time),
    }
}

/// The sweeps of `limb` (obstacle TOML) at three steps, up to 10 cm of limb
/// travel per step (more than its 6 cm width): no vertex inside the limb
/// beyond the thickness, none behind it, and no step rejected (the energy
/// check counts the work the limb does by moving vertices out to its
/// surface).
fn sweeps_keep_the_sheet_ahead(what: &str, limb: &str, duration: Scalar) {
    // The implicit integrator at 2, 10 and 20 ms; symplectic Euler at 0.25 ms,
    // inside its stability limit for these 2 cm cells (about 0.5 ms). Both
    // keep every vertex out of the limb and ahead of it.
    let runs = [
        ("implicit", 1.0 / 500.0),
        ("implicit", 1.0 / 100.0),
        ("implicit", 1.0 / 50.0),
        ("symplectic_euler", 1.0 / 4000.0),
    ];
    for (integrator, h) in runs {
        let scene = stretched_sheet_with(limb, integrator);
        let body = Body::from_spec(0, &scene.obstacle[0].resolve().expect("resolved"))
            .expect("body")
            .remove(0);
        let what = format!("{what}, {integrator}");
        let s = sweep(
            &scene,
            &Limb {
                body: &body,
                half: 0.3,
            },
            h,
            duration,
        );
        println!(
            "{what}, step {:.2} ms: {} steps ({} halved), smallest clearance from the limb {:.3} mm \
             (thickness {:.1} mm), {} vertex-steps behind it, sheet lifted to {:.3} m",
            h * 1e3,
            s.steps,
            s.halved,
            s.clearance * 1e3,
            THICK * 1e3,
            s.behind,
            s.lifted
        );
        assert!(
            s.clearance >= -THICK,
            "{what} at {h} s steps: a vertex {:.2} mm inside the limb",
            -s.clearance * 1e3
        );
        assert_eq!(s.behind, 0, "{what} at {h} s steps: vertices went through");
        // Symplectic Euler has rejected steps, redone as halves: the limb's
        // pushes stretch the sheet, and the elastic energy they store (which
        // the ledger does not count as the limb's work) comes back as kinetic
        // energy above the explosion bound. The implicit steps have none.
        if integrator == "implicit" {
            assert_eq!(s.halved, 0, "{what} at {h} s steps: steps rejected");
        }
        assert!(s.lifted > 0.1, "{what}: the limb lifts the sheet");
    }
}

#[test]
fn a_limb_at_5_m_per_s_does_not_tunnel_through_a_sheet() {
    sweeps_keep_the_sheet_ahead("capsule rising at 5 m/s", &rising_capsule(), 0.06);
}

#[test]
fn a_limb_turning_about_a_joint_at_5_m_per_s_does_not_tunnel_through_a_sheet() {
    sweeps_keep_the_sheet_ahead("limb turning, tip at 5 m/s", &swinging_limb(), 0.06);
}

/// A 1 m sheet of 16 x 16 cells lying flat at z = 0 without gravity (so only
/// the obstacle term refines it), and a ball of radius 0.1 m passing 2 cm
/// over it: from x = -0.3 m to +0.3 m in 1 s (linear keys).
const BALL_OVER_SHEET: &str = r#"
name = "passing_ball"
[simulation]
duration = 1.0
gravity = [0.0, 0.0, 0.0]
[cloth]
shape = "rectangle"
width = 1.0
height = 1.0
resolution = 16
position = [0.0, 0.0, 0.0]
[material]
density = 0.15
stretch = 200.0
bending = 1.0e-5
damping = 0.001
[adapt]
method = "red_green"
refine_angle = 15.0
refine_obstacle = 0.5
max_level = 4
[[obstacle]]
shape = "sphere"
radius = 0.1
position = [-0.3, 0.0, 0.12]
keyframes = [{ time = 0.0 }, { time = 1.0, translation = [0.6, 0.0, 0.0] }]
"#;

/// The triangles of a state at the finest level (`max_level = 4`: two 1-4
/// splits): their centroids in xy.
fn finest_centroids(state: &SimState) -> Vec<drape::math::Vector2> {
    let mesh = &state.world.mesh;
    mesh.triangles
        .iter()
        .zip(&mesh.levels)
        .filter(|(_, l)| **l >= 4)
        .map(|(t, _)| {
            let c = t.iter().map(|&i| state.world.x[i as usize]).sum::<Vector>() / 3.0;
            c.truncate()
        })
        .collect()
}

#[test]
fn refinement_near_an_obstacle_follows_it_and_coarsens_behind() {
    let scene = load_scene_str(BALL_OVER_SHEET, "passing_ball", &[]).expect("scene");
    let SimParts {
        setup,
        mut state,
        pipeline: mut pipe,
    } = build(&scene.resolve().expect("resolve")).expect("simulation");
    let frame = 1.0 / 30.0;
    let ball_at = |t: Scalar| drape::math::Vector2::new(-0.3 + 0.6 * t, 0.0);
    let mut seen = Vec::new();
    for f in 1..=30 {
        pipe.advance_frame(&setup, &mut state, frame)
            .expect("frame");
        if f == 6 || f == 30 {
            seen.push((state.world.time, finest_centroids(&state)));
        }
    }
    let (early_t, early) = &seen[0];
    let (late_t, late) = &seen[1];
    let mean = |c: &[drape::math::Vector2]| {
        c.iter().copied().sum::<drape::math::Vector2>() / c.len().max(1) as Scalar
    };
    let farthest = |c: &[drape::math::Vector2], p: drape::math::Vector2| {
        c.iter().map(|q| q.distance(p)).fold(0.0, Scalar::max)
    };
    let old = ball_at(*early_t);
    let left_behind = late.iter().filter(|q| q.distance(old) < 0.15).count();
    for (t, c) in &seen {
        println!(
            "t = {t:.3} s: ball over ({:.3}, 0), {} finest triangles, their centre {:.3} m \
             from it (behind it), the farthest {:.3} m",
            ball_at(*t).x,
            c.len(),
            mean(c).distance(ball_at(*t)),
            farthest(c, ball_at(*t))
        );
    }
    println!(
        "at {late_t:.3} s, {left_behind} finest triangles within 0.15 m of where the ball \
         was at {early_t:.3} s ({:.3} m from where it is)",
        old.distance(ball_at(*late_t))
    );
    // The finest region trails the ball a little (merging waits for the lean
    // to fall below half the threshold), and at 1 s the sheet's edge, 0.2 m
    // ahead of the ball, clips its front.
    for (t, c) in &seen {
        assert!(c.len() > 8, "refined at {t} s");
        assert!(mean(c).distance(ball_at(*t)) < 0.08, "centred at {t} s");
        assert!(farthest(c, ball_at(*t)) < 0.25, "near the ball at {t} s");
    }
    assert_eq!(left_behind, 0, "coarsened behind the ball");
    let moved = mean(late).x - mean(early).x;
    println!("the finest region's centre moved {moved:.3} m, the ball 0.480 m");
    assert!((moved - 0.48).abs() < 0.08, "{moved} m");
}

/// The shipped tablecloth pull for its first 0.3 s (the yank starts at
/// 0.1 s): the pulled edge is where its keys say, the whole cloth has slid
/// off the top, and no vertex ever went below an obstacle's surface.
#[test]
fn the_tablecloth_pull_scene_pulls_the_cloth_off_the_table() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/tablecloth_pull.toml");
    let sets = ["simulation.duration=0.3".to_string()];
    let scene = drape::scene::load_scene_file(&path, &sets).expect("scene");
    let (mut first, mut last) = (None, None);
    let opts = drape::run::RunOptions::default();
    let summary = drape::run::run_observed(
        &scene,
        &opts,
        &std::sync::atomic::AtomicBool::new(false),
        &mut |_| {},
        &mut |f| {
            // The pulled edge (u = -0.65 m) and the far edge (u = +0.65 m).
            let edge = |u: Scalar| {
                let on: Vec<Vector> = f
                    .material
                    .iter()
                    .zip(f.positions)
                    .filter(|(m, _)| (m.x - u).abs() < 1e-9)
                    .map(|(_, p)| *p)
                    .collect();
                on.iter().copied().sum::<Vector>() / on.len().max(1) as Scalar
            };
            let now = (edge(-0.65), edge(0.65));
            first.get_or_insert(now);
            last = Some(now);
        },
    )
    .expect("run");
    let ((pulled0, far0), (pulled1, far1)) = (first.expect("frames"), last.expect("frames"));
    // Linear keys from 0.1 s to 0.35 s: 1.15 m along -x, 4/5 of it by 0.3 s.
    let want = pulled0 + Vector::new(-1.15, 0.0, 0.0) * 0.8;
    println!(
        "at 0.3 s: pulled edge {pulled0:.3?} -> {pulled1:.3?} (keys: {want:.3?}), far edge \
         {far0:.3?} -> {far1:.3?}; max penetration {} m, mean contacts {:.0}",
        summary.collision.max_penetration, summary.collision.contacts
    );
    assert!((pulled1 - want).length() < 1e-6, "the pin follows its keys");
    assert!(
        far1.x < -0.5 && far0.x > 0.49,
        "the far edge, at the table's right edge at the start, has passed its left edge: {far1:?}"
    );
    assert!(
        summary.collision.max_penetration < 1e-3,
        "{} m",
        summary.collision.max_penetration
    );
}

/// A fast obstacle that lifts the cloth does work on it by moving its
/// vertices out to its surface as well as by changing their velocities, and
/// the energy check counts both: the capsule rising at 5 m/s lifts the
/// pinned sheet 0.2 m at 10 ms steps with no step rejected as an explosion.
#[test]
fn a_fast_obstacle_lifting_the_cloth_is_not_an_explosion() {
    let scene = stretched_sheet(&rising_capsule());
    let SimParts {
        setup,
        mut state,
        pipeline: mut pipe,
    } = build(&scene.resolve().expect("resolve")).expect("simulation");
    let bound = state.ledger.bound;
    for _ in 0..6 {
        if let Err(e) = pipe.step(&setup, &mut state, 0.01) {
            panic!(
                "step to {:.2} s rejected: {e} (work counted {:.4} J)",
                state.world.time,
                state.ledger.work()
            );
        }
        let e = pipe.stepper().energy(&setup.model, &state.world);
        let w = state.ledger.work();
        println!(
            "t = {:.2} s: kinetic + gravitational {:.4} J (limit {:.4} J), total {:.4} J, \
             work {w:.4} J",
            state.world.time,
            e.kinetic + e.gravitational,
            bound.initial + w + bound.scale + w.abs(),
            e.total()
        );
    }
    let top = state.world.x.iter().map(|p| p.z).fold(0.0, Scalar::max);
    println!("the sheet lifted to {top:.3} m");
    assert!(
        top > 0.17,
        "the capsule lifts the sheet to its top: {top} m"
    );
}
