//! `drape bench` on garments: sample points are taken panel by panel (a
//! skirt's front and back share their pattern coordinates), a garment's
//! ladder names its reference by `cloth.max_edge`, and the default garment
//! ladder runs end to end with a lift floor far below every rung's error.

use std::sync::atomic::AtomicBool;

use drape::bench::metric::locate_in_panels;
use drape::bench::{BenchError, BenchOptions, Compare, Ladder, Rung, bench, make_plan};
use drape::scene::load_scene_file;
use drape::world::World;

use crate::bench::temp_dir;

const SKIRT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/skirt.toml");

fn options(scene: &str, ladder: Option<Ladder>) -> BenchOptions {
    BenchOptions {
        scene: scene.into(),
        overrides: vec![],
        ladder,
        time_ladder: false,
        rungs: vec![],
        compare: None,
        step: None,
        reps: 1,
        duration: Some(0.1),
        threads: Some(1),
        cache: false,
        reference_resolution: None,
        grid: 8,
        floor: true,
    }
}

/// The skirt's sample points name their panel; the front's and the back's
/// points at the same pattern coordinates are found in their own panel's
/// triangles, and lie on opposite sides of the body.
#[test]
fn bench_samples_each_garment_panel_in_its_own_pattern() {
    let (plan, points) = make_plan(&options(SKIRT, None)).expect("plan");
    assert_eq!(points.panels.len(), points.points.len());
    let per_panel = [0u16, 1].map(|p| points.panels.iter().filter(|&&q| q == p).count());
    println!(
        "reference {}; {} points: {per_panel:?} per panel",
        plan.reference.set.join(" "),
        points.points.len()
    );
    assert!(per_panel.iter().all(|&n| n == 64), "{per_panel:?}");
    let scene = load_scene_file(SKIRT.as_ref(), &plan.reference.set).expect("scene");
    let world = World::from_scene(&scene).expect("world");
    let at = points.vectors();
    let found = locate_in_panels(&world.mesh, &at, &points.panels);
    assert!(
        found.iter().all(Option::is_some),
        "a point not found in its panel"
    );
    // The first front point and the back point at the same (u, v).
    let back = (0..at.len())
        .find(|&i| points.panels[i] == 1 && at[i] == at[0])
        .expect("the back has the front's grid");
    let [f, b] = [0, back].map(|i| {
        let l = found[i].expect("found");
        let tri = world.mesh.triangles[l.triangle as usize];
        (0..3)
            .map(|k| world.x[tri[k] as usize] * l.weights[k])
            .sum::<drape::math::Vector>()
    });
    println!(
        "pattern point {:?}: front at {f:?}, back at {b:?}, {:.3} m apart",
        at[0],
        f.distance(b)
    );
    assert!(f.distance(b) > 0.2);
}

/// A garment ladder without a reference is refused with what to write.
#[test]
fn a_garment_ladder_must_name_its_reference() {
    let ladder = Ladder {
        reference: None,
        compare: None,
        step: None,
        rung: vec![Rung::new(
            "uniform 0.06 m",
            vec!["adapt.method=none".into(), "cloth.max_edge=0.06".into()],
        )],
    };
    let err = make_plan(&options(SKIRT, Some(ladder))).expect_err("refused");
    println!("{err}");
    assert!(matches!(err, BenchError::Plan(_)));
    assert!(err.to_string().contains("must name its reference"), "{err}");
}

/// Two squares sewn together, hanging from pins: the default garment ladder
/// runs (uniform and red-green rungs against a uniform reference at 2/3 of
/// the scene's edge), every run is compared, and the lift floor is far below
/// the coarsest rung's error.
#[test]
fn a_garment_benches_with_its_default_ladder() {
    let dir = temp_dir("garment");
    let scene = dir.join("squares.toml");
    std::fs::write(&scene, SQUARES).expect("write scene");
    let opts = options(scene.to_str().expect("utf-8"), None);
    let result = bench_in(&dir, &opts);
    for r in &result.rows {
        println!(
            "{}: {} vertices, error {:.3e}, {}",
            r.run.label, r.mean_vertices, r.error, r.status
        );
        assert_eq!(r.status, "ok");
        assert!(r.error.is_finite());
    }
    let error = |label: &str| {
        let row = result.rows.iter().find(|r| r.run.label.starts_with(label));
        row.expect("row").error
    };
    assert!(error("uniform 0.1 m") > 0.0);
    assert!(error("reference lifted") < 1e-3 * error("uniform 0.1 m"));
}

/// Runs that end at rest end at frames of their own: with `compare =
/// "rest"` each run's last frame is compared with the reference's last
/// frame, and the mean over the frames, which the runs do not share, is
/// left out.
#[test]
fn garment_runs_that_end_at_rest_at_different_frames_compare_their_last_frames() {
    let dir = temp_dir("garment-rest");
    let scene = dir.join("squares.toml");
    let resting = SQUARES
        .replace(
            "dt = 0.005\n",
            "dt = 0.005\nrest = { speed = 0.05, window = 0.2 }\n",
        )
        .replace("damping = 0.001", "damping = 0.05")
        .replace(
            "max_edge = 0.05\n",
            "max_edge = 0.05\nsewing = { weld_gap = 0.03 }\n",
        );
    std::fs::write(&scene, resting).expect("write scene");
    let mut opts = options(scene.to_str().expect("utf-8"), None);
    opts.duration = Some(4.0);
    opts.compare = Some(Compare::Rest);
    let result = bench_in(&dir, &opts);
    let mut own_frames = 0;
    for r in &result.rows {
        let last = r.errors.last().map(|e| e.0);
        println!(
            "{}: {} vertices, error at rest {:.3e}, mean {:.3e}, last shared frame {last:?}, {}",
            r.run.label, r.mean_vertices, r.error, r.mean_error, r.status
        );
        assert_eq!(r.status, "ok");
        assert!(r.error.is_finite() && r.error > 0.0);
        own_frames += usize::from(r.mean_error.is_nan());
    }
    assert!(
        own_frames > 0,
        "every run came to rest on the reference's frame"
    );
}

/// The bench of `opts`, written into `dir/out`.
fn bench_in(dir: &std::path::Path, opts: &BenchOptions) -> drape::bench::BenchResult {
    let out = dir.join("out");
    let (result, _) = bench(opts, &out, &AtomicBool::new(false), &mut |_| {}).expect("bench");
    result
}

const SQUARES: &str = r#"
name = "squares"
[simulation]
duration = 0.1
frame_rate = 30
dt = 0.005
[cloth]
shape = "panels"
max_edge = 0.05
[material]
density = 0.2
stretch = 300.0
bending = 2.0e-5
damping = 0.001
[[panel]]
name = "left"
outline = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]]
position = [-0.21, 0.0, 1.0]
rotation = [90.0, 0.0, 0.0]
[[panel]]
name = "right"
outline = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]]
position = [0.01, 0.0, 1.0]
rotation = [90.0, 0.0, 0.0]
[[seam]]
name = "middle"
a = { panel = "left", side = 2 }
b = { panel = "right", side = 4 }
[[pin]]
region = "box"
box_min = [0.0, 0.19]
box_max = [0.2, 0.2]
"#;
