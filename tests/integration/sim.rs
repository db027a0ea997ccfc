//! The simulation state and the public pipeline: a rollback leaves no
//! trace in the work ledger, a frame retry restores the whole state, and a state
//! saved and restored replays bit for bit.

use std::path::Path;

use drape::adapt::{AdaptConfig, edge_angles};
use drape::scene::{Scene, load_scene_file};
use drape::sim::{Pipeline, Setup, SimParts, SimState, build};

/// `scenes/hard/thrash.toml` (a sheet flapping in wind, red-green adaptivity after
/// every step with rollback) with at most one rollback per step, so that a step is
/// exactly: a trial on the old mesh, a refinement, the accepted attempt.
fn thrash() -> Scene {
    let overrides = ["adapt.max_rollbacks=1".to_string()];
    load_scene_file(Path::new("scenes/hard/thrash.toml"), &overrides).expect("thrash scene")
}

/// The setup, initial state and pipeline of `scene`.
fn parts(scene: &Scene) -> (Setup, SimState, Pipeline) {
    let SimParts {
        setup,
        state,
        pipeline,
    } = build(&scene.resolve().expect("resolve")).expect("build");
    (setup, state, pipeline)
}

/// The setup of `scene` with its adaptivity settings changed by `change`.
fn setup_with(scene: &Scene, change: impl Fn(&mut AdaptConfig)) -> Setup {
    let mut setup = parts(scene).0;
    change(setup.settings.adapt.as_mut().expect("adaptive"));
    setup
}

fn rollbacks(state: &SimState) -> u64 {
    state.adapter.as_ref().map_or(0, |a| a.stats.rollbacks)
}

/// Steps `state` until a step rolls back; returns the state before that step (and
/// leaves `twin`, a second simulation run in lockstep, at that same state).
fn until_rollback(
    setup: &Setup,
    state: &mut SimState,
    pipe: &mut Pipeline,
    twin: &mut (SimState, Pipeline),
    h: f64,
) -> SimState {
    for step in 0..400 {
        let saved = state.clone();
        let before = rollbacks(state);
        let outcome = pipe
            .step(setup, state, h)
            .unwrap_or_else(|e| panic!("step {step}: {e}"));
        if rollbacks(state) > before {
            assert_eq!(outcome.rollbacks as u64, rollbacks(state) - before);
            return saved;
        }
        twin.1.step(setup, &mut twin.0, h).expect("step accepted");
    }
    panic!("no step rolled back in 400 steps");
}

/// The wind work of a rolled-back attempt does not stay in `external_work` (a
/// rollback that restored only positions, velocities and time would leave it).
/// A step with one rollback must add exactly the work of its accepted attempt,
/// which is replayed here on a twin simulation: the trial step finds the same
/// marks, then the refined mesh is stepped from the restored start.
#[test]
fn rollback_keeps_only_the_accepted_attempts_work() {
    let scene = thrash();
    let (setup, mut state, mut pipe) = parts(&scene);
    let (_, twin_state, twin_pipe) = parts(&scene);
    let mut twin = (twin_state, twin_pipe);
    let h = pipe.step_size(&setup, &state.world);
    let saved = until_rollback(&setup, &mut state, &mut pipe, &mut twin, h);
    let work0 = saved.ledger.external_work;
    let (mut twin_state, mut twin_pipe) = twin;
    assert_eq!(twin_state.world.x, saved.world.x, "the twin is in lockstep");

    // The trial: the same step without rollback, on the old mesh.
    let trial_setup = setup_with(&scene, |a| {
        a.rollback = false;
        a.every = drape::spec::AdaptEvery::Steps(u32::MAX);
    });
    let mut trial = saved.clone();
    twin_pipe
        .step(&trial_setup, &mut trial, h)
        .expect("step accepted");
    let ad = trial.adapter.as_ref().expect("adaptive");
    let config = setup.settings.adapt.as_ref().expect("adaptive");
    let marks = ad.refinement_marks(config, &trial.world, &edge_angles(&trial.world));
    assert!(!marks.is_empty(), "the trial bends past the threshold");

    // The accepted attempt: refine the start, step once without rollback.
    twin_state.restore(&saved);
    let ad = twin_state.adapter.as_mut().expect("adaptive");
    ad.refine(
        config,
        &mut twin_state.world,
        &marks,
        saved.ledger.steps_done,
    )
    .expect("refine");
    let accepted_setup = setup_with(&scene, |a| a.rollback = false);
    twin_pipe.mesh_changed(&accepted_setup, &mut twin_state);
    twin_pipe
        .step(&accepted_setup, &mut twin_state, h)
        .expect("step accepted");

    let real = state.ledger.external_work - work0;
    let accepted = twin_state.ledger.external_work - work0;
    let rejected = trial.ledger.external_work - work0;
    assert!(
        rejected.abs() > 0.0,
        "the trial does work, so the test can fail"
    );
    assert_eq!(
        real, accepted,
        "a rollback leaves only the accepted attempt's work"
    );
    assert_eq!(
        state.world.x, twin_state.world.x,
        "the replay is bit-identical"
    );
}

/// Steps `scene` 2 x `steps` steps; then replays the second half from a state
/// saved halfway, on a second pipeline built from the scene and attached to that
/// state. Returns the original and the replayed end states and the largest move
/// of a vertex over the second half.
fn replay_on_a_fresh_pipeline(scene: &Scene, steps: usize) -> (SimState, SimState, f64) {
    let (setup, mut state, mut pipe) = parts(scene);
    let h = pipe.step_size(&setup, &state.world);
    for _ in 0..steps {
        pipe.step(&setup, &mut state, h).expect("step accepted");
    }
    let saved = state.clone();
    for _ in 0..steps {
        pipe.step(&setup, &mut state, h).expect("step accepted");
    }
    let (_, _, mut fresh) = parts(scene);
    let mut replay = saved.clone();
    fresh.attach(&setup, &replay);
    for _ in 0..steps {
        fresh.step(&setup, &mut replay, h).expect("step accepted");
    }
    let moved = state
        .world
        .x
        .iter()
        .zip(&saved.world.x)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f64::max);
    (state, replay, moved)
}

/// A state cloned mid-run and stepped again by a second pipeline built from the
/// same scene reproduces the original bit for bit: the pipeline holds no state the
/// result depends on. The explicit case; the implicit one (whose warm start is
/// state) is the next test.
#[test]
fn a_restored_state_replays_bit_for_bit_on_a_fresh_pipeline() {
    let overrides = [
        "simulation.integrator=symplectic_euler".to_string(),
        "simulation.dt=2e-4".to_string(),
    ];
    let scene = load_scene_file(Path::new("scenes/hard/thrash.toml"), &overrides).expect("scene");
    let (state, replay, moved) = replay_on_a_fresh_pipeline(&scene, 50);
    assert!(moved > 0.0, "the sheet moved {moved} m");
    assert_eq!(state.world.mesh.triangles, replay.world.mesh.triangles);
    assert_eq!(state.world.x, replay.world.x);
    assert_eq!(state.world.v, replay.world.v);
    assert_eq!(state.ledger.work(), replay.ledger.work());
}

/// The implicit solver's warm start (its first guess, the last step's velocity
/// change) is part of the state, not the pipeline: with `solver = "cg"` (no
/// stored factorization) a fresh pipeline continues bit for bit, on a flapping
/// adaptive sheet (wind, rollback) and on a sheet draped on a ball (contacts).
/// A pipeline-owned warm start would start the next solve cold and drift by up
/// to the CG tolerance (2.3e-7 m on the draped sheet). The direct solver's
/// stored factorization is a cache (a preconditioner): a fresh pipeline factors
/// afresh and agrees within the solve's tolerance.
#[test]
fn a_rebuilt_pipeline_continues_a_run_bit_identically() {
    // The draped sheet starts just above the ball, so it touches from the start.
    let on_the_ball = ["cloth.position=[0.0,0.0,0.504]", "cloth.resolution=24"];
    let cases = [
        // Remeshing every third step, so that the last of the 20 steps keeps
        // its warm start (a remesh clears it).
        ("scenes/hard/thrash.toml", "cg", &["adapt.every=3"][..]),
        ("scenes/drape_sphere.toml", "cg", &on_the_ball[..]),
        ("scenes/drape_sphere.toml", "direct", &on_the_ball[..]),
    ];
    let steps = 20;
    for (file, solver, extra) in cases {
        let mut overrides = vec![
            "simulation.integrator=implicit".to_string(),
            format!("simulation.solver={solver}"),
        ];
        overrides.extend(extra.iter().map(|s| s.to_string()));
        let scene = load_scene_file(Path::new(file), &overrides).expect("scene");
        let (state, replay, moved) = replay_on_a_fresh_pipeline(&scene, steps);
        let deviation = state
            .world
            .x
            .iter()
            .zip(&replay.world.x)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f64::max);
        assert!(
            moved > 0.0 && !state.warm_start.is_empty(),
            "{file}, solver {solver}: moved {moved} m, warm start of {} vertices",
            state.warm_start.len()
        );
        if file.contains("drape_sphere") {
            assert!(state.ledger.collision.contacts > 0, "it touches the ball");
        }
        assert_eq!(state.world.mesh.triangles, replay.world.mesh.triangles);
        if solver == "cg" {
            // Compared whole; the message names what differs, not thousands of vectors.
            assert!(state.world.x == replay.world.x, "{file}: positions");
            assert!(state.world.v == replay.world.v, "{file}: velocities");
            assert!(state.warm_start == replay.warm_start, "{file}: warm start");
        } else {
            assert!(
                deviation < 1e-3 * moved,
                "{file}: deviation {deviation:.3e} m"
            );
        }
    }
}

/// An adaptive sheet (both methods) draped on a sphere with self-collision, large
/// enough that every parallel pass splits into chunks (4,225 base vertices and
/// about 12,500 springs, against chunk sizes of 256 to 8,192): the positions of
/// every frame are bit-identical at 1, 2 and 4 threads; also with the sphere
/// keyframed, rising into the sheet and turning under it (friction against a
/// moving surface, the obstacle's work counted).
#[test]
fn adaptive_contact_runs_are_identical_at_1_2_and_4_threads() {
    let moving = "keyframes = [{ time = 0.0 }, \
                  { time = 0.1, translation = [0.0, 0.0, 0.05], rotation = [0.0, 0.0, 30.0] }]";
    for (method, motion) in [("red_green", ""), ("edge", ""), ("red_green", moving)] {
        let text = format!(
            r#"
name = "threads"
[simulation]
duration = 0.1
frame_rate = 30
integrator = "implicit"
dt = 0.004
[cloth]
shape = "rectangle"
width = 1.2
height = 1.2
resolution = 64
position = [0.0, 0.0, 0.505]
[material]
density = 0.15
stretch = 200.0
bending = 1.0e-5
damping = 0.001
[adapt]
method = "{method}"
refine_angle = 8.0
coarsen_angle = 1.0
max_level = 2
[[obstacle]]
shape = "sphere"
radius = 0.5
position = [0.0, 0.0, 0.0]
thickness = 0.003
{motion}
[self_collision]
thickness = 0.003
"#
        );
        let scene = drape::scene::load_scene_str(&text, "threads.toml", &[]).expect("scene");
        let run = |threads: usize| {
            let opts = drape::run::RunOptions {
                threads: Some(threads),
                ..Default::default()
            };
            let mut frames: Vec<(Vec<[u32; 3]>, Vec<drape::math::Vector>)> = Vec::new();
            let summary = drape::run::run_observed(
                &scene,
                &opts,
                &std::sync::atomic::AtomicBool::new(false),
                &mut |_| {},
                &mut |f| frames.push((f.triangles.to_vec(), f.positions.to_vec())),
            )
            .expect("run");
            (frames, summary)
        };
        let (one, s1) = run(1);
        assert!(
            s1.adaptivity.splits > 0 && s1.collision.contacts > 0.0,
            "it adapts and touches"
        );
        for threads in [2, 4] {
            let (other, _) = run(threads);
            assert_eq!(one.len(), other.len());
            for (f, (a, b)) in one.iter().zip(&other).enumerate() {
                assert_eq!(
                    a.0, b.0,
                    "{method}: triangles of frame {f} at {threads} threads"
                );
                assert!(
                    a.1 == b.1,
                    "{method}: positions of frame {f} differ at {threads} threads"
                );
            }
        }
    }
}
