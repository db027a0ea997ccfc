//! `drape bench`'s separation of errors: ladder keys (`compare`, `step`), the
//! observed order of convergence, the target's 10 % band, the time-step
//! ladder end to end, and uniform runs at 16, 32 and 64 segments on a
//! quasi-static scene whose error at rest falls with resolution.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use super::bench::{row, temp_dir, tiny_scene};
use drape::bench::order::{loglog_slope, spatial, temporal};
use drape::bench::report::{pct, target_checks};
use drape::bench::steps::{TIME_LADDER_DIVISORS, TIME_REFERENCE_DIVISOR, time_ladder};
use drape::bench::{BenchOptions, Compare, Ladder, Row, Rung, StepPolicy, bench};

#[test]
fn ladder_files_read_compare_and_step() {
    let text = r#"
compare = "rest"
step = "own"
reference = ["cloth.resolution=8"]
[[rung]]
label = "a"
set = ["cloth.resolution=4"]
"#;
    let l = Ladder::parse(text).expect("valid ladder");
    assert_eq!(l.compare, Some(Compare::Rest));
    assert_eq!(l.step, Some(StepPolicy::Own));
    assert_eq!(l.reference, Some(vec!["cloth.resolution=8".to_owned()]));
    let plain = Ladder::parse("[[rung]]\nlabel = \"a\"\n").expect("valid ladder");
    assert_eq!((plain.compare, plain.step), (None, None));
    let bad = Ladder::parse("compare = \"sometimes\"\n[[rung]]\nlabel = \"a\"\n");
    assert!(bad.is_err_and(|e| e.contains("sometimes")));
    assert!(Ladder::parse("stepp = \"own\"\n[[rung]]\nlabel = \"a\"\n").is_err());
    assert!(Ladder::parse("compare = \"rest\"\n").is_err_and(|e| e.contains("no `[[rung]]`")));
    assert_eq!("rest".parse::<Compare>(), Ok(Compare::Rest));
    assert!("own".parse::<Compare>().is_err());
    assert_eq!("common".parse::<StepPolicy>(), Ok(StepPolicy::Common));
}

#[test]
fn small_errors_keep_their_digits_in_the_report() {
    assert_eq!(pct(0.012344), "1.234");
    assert_eq!(pct(2.586e-8), "2.59e-6");
    assert_eq!(pct(0.0), "0.000");
    assert_eq!(pct(f64::NAN), "-");
}

#[test]
fn loglog_slope_recovers_a_power_law() {
    let pts: Vec<(f64, f64)> = [0.1, 0.05, 0.025, 0.0125]
        .iter()
        .map(|&h| (h, 3.0 * h * h))
        .collect();
    let p = loglog_slope(&pts).expect("four points");
    assert!((p - 2.0).abs() < 1e-12, "{p}");
    assert_eq!(loglog_slope(&pts[..1]), None);
    assert_eq!(loglog_slope(&[(0.1, 1.0), (0.1, 2.0)]), None, "one h only");
    assert_eq!(loglog_slope(&[(0.1, 1.0), (0.05, 0.0)]), None, "zero error");
}

#[test]
fn convergence_series_use_the_uniform_runs_only() {
    let mut rows = vec![
        row("uniform 8", false, 8, 8, 0.1, 4e-2),
        row("uniform 16", false, 16, 16, 0.4, 1e-2),
        row("uniform 32", false, 32, 32, 1.6, 2.5e-3),
        row("adaptive", true, 8, 32, 0.3, 1e-3),
        row("failed", false, 64, 64, f64::NAN, f64::NAN),
    ];
    rows[4].status = "failed: numerical failure".into();
    let s = spatial(&rows).expect("three uniform resolutions");
    assert_eq!(s.points.len(), 3);
    assert!((s.order - 2.0).abs() < 1e-12, "{}", s.order);
    assert_eq!(s.local.len(), 2);
    assert_eq!(s.points[0].0, "uniform 8", "coarse first");
    assert_eq!(temporal(&rows), None, "no two runs on one mesh");
    // Two runs at one h (square and stretched cells, as in the tensor
    // ladder): the local orders are between distinct h only, from the first
    // run at each (they used to include a 0 / 0 slope, printed as NaN).
    let mut shared = rows[..3].to_vec();
    shared.insert(2, row("uniform 16 across 1", false, 16, 16, 0.1, 1.1e-2));
    let s = spatial(&shared).expect("three resolutions");
    println!("local orders with a shared h: {:?}", s.local);
    assert_eq!(s.local.len(), 2);
    assert!(
        s.local.iter().all(|&p| (p - 2.0).abs() < 1e-12),
        "{:?}",
        s.local
    );
    // A time-step ladder: one mesh, three steps, first order.
    let steps: Vec<Row> = [("0.01", 0.04), ("0.005", 0.02), ("0.0025", 0.01)]
        .iter()
        .map(|&(dt, e)| {
            let mut r = row(dt, false, 16, 16, 1.0, e);
            r.dt = dt.into();
            r
        })
        .collect();
    let t = temporal(&steps).expect("three steps");
    assert!((t.order - 1.0).abs() < 1e-12, "{}", t.order);
    assert_eq!(spatial(&steps), None, "one resolution per step");
}

#[test]
fn target_needs_the_error_within_ten_percent() {
    let rows = vec![
        row("uniform 8", false, 8, 8, 4.0, 0.010),
        row("close, a tenth", true, 4, 8, 0.3, 0.0105),
        row("close, a fifth", true, 4, 8, 0.8, 0.0109),
        row("11 % worse", true, 4, 8, 0.3, 0.0111),
    ];
    let c = target_checks(&rows);
    assert_eq!(c.len(), 3);
    assert!(c[0].within_10 && c[0].met && c[0].met_tenth);
    assert!(c[1].within_10 && c[1].met && !c[1].met_tenth);
    assert!(!c[2].within_10 && !c[2].met && !c[2].met_tenth);
}

#[test]
fn time_ladder_halves_the_step_against_a_much_smaller_one() {
    let l = time_ladder(0.01);
    assert_eq!(l.rung.len(), TIME_LADDER_DIVISORS.len());
    for (r, k) in l.rung.iter().zip(TIME_LADDER_DIVISORS) {
        let dt: f64 = r
            .set
            .iter()
            .find_map(|s| s.strip_prefix("simulation.dt="))
            .expect("a step")
            .parse()
            .expect("a number");
        assert!((dt - 0.01 / f64::from(k)).abs() < 1e-15, "{}", r.label);
        assert!(r.set.contains(&"adapt.method=none".to_owned()));
    }
    let reference = l.reference.expect("its own reference");
    let expected = format!(
        "simulation.dt={:e}",
        0.01 / f64::from(TIME_REFERENCE_DIVISOR)
    );
    assert!(reference.contains(&expected), "{reference:?}");
    assert_eq!(l.step, Some(StepPolicy::Own));
}

#[test]
fn time_ladder_end_to_end_error_falls_with_the_step() {
    let dir = temp_dir("time");
    let scene = tiny_scene(&dir);
    let opts = BenchOptions {
        scene,
        overrides: vec!["cloth.resolution=6".into()],
        ladder: None,
        time_ladder: true,
        rungs: vec![],
        compare: None,
        step: None,
        reps: 1,
        duration: Some(0.2),
        threads: Some(1),
        out_dir: dir.join("out"),
        cache: false,
        reference_resolution: None,
        mesh_floor: None,
        pattern_floor: false,
        grid: 8,
        floor: false,
    };
    let res = bench(&opts, &AtomicBool::new(false), &mut |_| {}).expect("bench");
    assert!(res.time_ladder && res.common_dt.is_none());
    let e: Vec<f64> = res.rows.iter().map(|r| r.error).collect();
    println!("time ladder errors (dt, dt/2, dt/4): {e:?}");
    assert_eq!(e.len(), 3);
    assert!(e[0] > e[1] && e[1] > e[2] && e[2] > 0.0, "{e:?}");
    let t = temporal(&res.rows).expect("one mesh, three steps");
    println!("observed order in the step: {:.2}", t.order);
    // Backward Euler is first order; the reference's own error (1/8 of the
    // smallest rung's) raises the observed order a little above 1.
    assert!(t.order > 0.8 && t.order < 1.5, "{}", t.order);
    for name in ["tiny-time.csv", "tiny-time.md", "tiny-time.svg"] {
        assert!(dir.join("out").join(name).is_file(), "{name}");
    }
    let md = std::fs::read_to_string(dir.join("out/tiny-time.md")).expect("md");
    assert!(md.contains("observed order") && md.contains("time step"));
}

/// A double cantilever: a strip 6.4 cm x 0.8 cm clamped over its middle 8 mm
/// (the clamp's edges at +-4 mm are mesh lines at 16, 32, 64 and 128 segments,
/// so every mesh holds the same clamp), two 2.8 cm arms bending under their
/// weight, with the cantilever scene's material and heavy air drag, so that it
/// is at rest after 2.5 s. (Clamped at the middle rather than at one end: a
/// one-end clamp makes every run also compute the cantilever summary's exact
/// elastica, about 2 s of CPU each, which this test does not need.)
fn strip_scene(dir: &Path) -> PathBuf {
    let path = dir.join("strip.toml");
    std::fs::write(
        &path,
        r#"name = "strip"
[simulation]
duration = 2.5
frame_rate = 10
integrator = "implicit"
dt = 0.02
[cloth]
shape = "rectangle"
width = 0.064
height = 0.008
resolution = 16
position = [0.0, 0.0, 0.5]
[material]
density = 0.15
stretch = 1.0e4
bending_length = 0.02
damping = 0.0005
[air]
drag = 4.0
[[pin]]
region = "box"
box_min = [-0.0041, -0.01]
box_max = [0.0041, 0.01]
"#,
    )
    .expect("write scene");
    path
}

#[test]
fn uniform_error_at_rest_falls_with_resolution() {
    let dir = temp_dir("convergence");
    let rungs = [16, 32, 64].map(|n| Rung {
        label: format!("uniform {n}"),
        set: vec![format!("cloth.resolution={n}")],
    });
    let opts = BenchOptions {
        scene: strip_scene(&dir),
        overrides: vec![],
        ladder: Some(Ladder {
            reference: Some(vec!["cloth.resolution=128".into()]),
            compare: Some(Compare::Rest),
            step: None,
            rung: rungs.to_vec(),
        }),
        time_ladder: false,
        rungs: vec![],
        compare: None,
        step: None,
        reps: 1,
        duration: None,
        threads: None,
        out_dir: dir.join("out"),
        cache: false,
        reference_resolution: None,
        mesh_floor: None,
        pattern_floor: false,
        grid: 24,
        floor: false,
    };
    let res = bench(&opts, &AtomicBool::new(false), &mut |l| eprintln!("{l}")).expect("bench");
    let e: Vec<f64> = res.rows.iter().map(|r| r.error).collect();
    let motion = res.reference_last_motion.expect("frames");
    println!(
        "errors at rest, 16 / 32 / 64 segments against 128: {e:?}; the reference moved {motion:e} over its last frame"
    );
    assert!(
        res.rows
            .iter()
            .all(|r: &Row| r.status == "ok" && r.compare == Compare::Rest)
    );
    // The reference has settled: its last frame moves it far less than the
    // smallest error measured.
    assert!(motion < 0.1 * e[2], "{motion} vs {}", e[2]);
    assert!(e[0] > e[1] && e[1] > e[2] && e[2] > 0.0, "{e:?}");
    let s = spatial(&res.rows).expect("three resolutions");
    println!("observed order {:.2} (local {:?})", s.order, s.local);
    // Linear triangles approximate a smooth bent shape to O(h^2); first order
    // or worse would mean the model does not converge as it should.
    assert!(s.order > 1.5, "{}", s.order);
}
