//! `drape bench`: the ladder file, the Pareto front, plans and jobs, the
//! collector's checks, and the same CSV in-process and through a job list.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::AtomicBool;

use drape::bench::collect::pareto_front;
use drape::bench::ladder::{
    TIME_LADDER_DIVISORS, TIME_LADDER_TOLERANCES, TIME_REFERENCE_DIVISOR, time_ladder,
};
use drape::bench::plan::JOBS_FILE;
use drape::bench::report::CSV_HEADER;
use drape::bench::sampling::{FrameSamples, frame_error};
use drape::bench::{
    BenchError, BenchOptions, Compare, Ladder, Rung, StepPolicy, bench, collect, make_plan, median,
    run_jobs, write_plan,
};

/// A fresh empty directory in the temp dir, unique per process and name.
pub(crate) fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("drape-bench-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// A small hanging sheet (0.5 m, resolution 4, implicit) as a scene file.
pub(crate) fn tiny_scene(dir: &Path) -> PathBuf {
    let path = dir.join("tiny.toml");
    std::fs::write(
        &path,
        r#"name = "tiny"
[simulation]
duration = 0.2
frame_rate = 20
integrator = "implicit"
dt = 0.01
[cloth]
shape = "rectangle"
width = 0.5
height = 0.5
resolution = 4
position = [0.0, 0.0, 1.0]
[material]
density = 0.15
stretch = 200.0
bending = 1.0e-5
damping = 0.001
[[pin]]
region = "corner:top_left"
"#,
    )
    .expect("write scene");
    path
}

fn rung(label: &str, set: &[&str]) -> Rung {
    Rung::new(label, set.iter().map(|s| (*s).to_owned()).collect())
}

/// Two uniform rungs and an adaptive one on the tiny scene.
fn small_ladder() -> Ladder {
    Ladder {
        reference: None,
        compare: None,
        step: None,
        rung: vec![
            rung("uniform 4", &["adapt.method=none", "cloth.resolution=4"]),
            rung("uniform 8", &["adapt.method=none", "cloth.resolution=8"]),
            rung(
                "red_green 4 L2",
                &[
                    "adapt.method=red_green",
                    "cloth.resolution=4",
                    "adapt.max_level=2",
                ],
            ),
        ],
    }
}

/// Options for `ladder` on the tiny scene: 0.15 s, one thread, one
/// repetition, an 8 x 8 sample grid, the cache on, no lift floor.
fn tiny_options(scene: &Path, ladder: Ladder) -> BenchOptions {
    BenchOptions {
        scene: scene.to_path_buf(),
        overrides: vec![],
        ladder: Some(ladder),
        time_ladder: false,
        rungs: vec![],
        compare: None,
        step: None,
        reps: 1,
        duration: Some(0.15),
        threads: Some(1),
        cache: true,
        reference_resolution: None,
        grid: 8,
        floor: false,
    }
}

fn quiet() -> impl FnMut(&str) {
    |_| {}
}

/// Runs `opts` in-process into `dir/out`.
fn bench_out(opts: &BenchOptions, dir: &Path) -> drape::bench::BenchResult {
    let stop = AtomicBool::new(false);
    bench(opts, &dir.join("out"), &stop, &mut quiet())
        .expect("bench")
        .0
}

/// The CSV without its wall-time columns (`wall_s`, `wall_min_s`,
/// `wall_max_s`) and the Pareto flag, which depends on them.
fn csv_without_times(text: &str) -> String {
    let header: Vec<&str> = CSV_HEADER.split(',').collect();
    let timed: Vec<usize> = ["wall_s", "wall_min_s", "wall_max_s", "pareto"]
        .iter()
        .map(|c| header.iter().position(|h| h == c).expect("column"))
        .collect();
    text.lines()
        .map(|line| {
            let cells: Vec<&str> = line.split(',').collect();
            assert_eq!(cells.len(), header.len(), "{line}");
            let kept: Vec<&str> = (0..cells.len())
                .filter(|i| !timed.contains(i))
                .map(|i| cells[i])
                .collect();
            kept.join(",")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn pareto_front_of_hand_made_points() {
    let pts = [
        (1.0, 5.0),
        (2.0, 3.0),
        (3.0, 4.0),
        (4.0, 1.0),
        (f64::NAN, 0.1),
        (2.0, 3.0),
    ];
    let front = pareto_front(&pts);
    assert_eq!(front, [true, true, false, true, false, true]);
    assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
    assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    assert!(median(&[]).is_nan());
}

#[test]
fn ladder_files_read_compare_step_and_floors_and_reject_mistakes() {
    let l = Ladder::parse(
        r#"reference = ["cloth.resolution=16"]
compare = "rest"
step = "own"
[[rung]]
label = "a"
set = ["cloth.resolution=4"]
[[rung]]
label = "fine"
set = ["cloth.resolution=14"]
floor = true
"#,
    )
    .expect("parses");
    assert_eq!(l.compare, Some(Compare::Rest));
    assert_eq!(l.step, Some(StepPolicy::Own));
    assert_eq!(
        l.rung.iter().map(|r| r.floor).collect::<Vec<_>>(),
        [false, true]
    );
    let twice = "[[rung]]\nlabel = \"a\"\n[[rung]]\nlabel = \"a\"\n";
    assert!(
        Ladder::parse(twice)
            .expect_err("two labels")
            .contains("`a`")
    );
    assert!(Ladder::parse("").expect_err("no rung").contains("[[rung]]"));
    let unknown = "[[rung]]\nlabel = \"a\"\nsett = []\n";
    assert!(Ladder::parse(unknown).expect_err("typo").contains("sett"));
}

#[test]
fn time_ladder_halves_the_step_against_a_much_smaller_one() {
    assert_eq!(
        time_ladder(0.01, false).rung.len(),
        TIME_LADDER_DIVISORS.len()
    );
    let l = time_ladder(0.01, true);
    assert_eq!(
        l.rung.len(),
        TIME_LADDER_DIVISORS.len() + TIME_LADDER_TOLERANCES.len()
    );
    for (r, tolerance) in l.rung[TIME_LADDER_DIVISORS.len()..]
        .iter()
        .zip(TIME_LADDER_TOLERANCES)
    {
        assert!(
            r.set.contains(&"simulation.dt=\"adaptive\"".to_owned()),
            "{r:?}"
        );
        let set = format!("simulation.adaptive_dt.tolerance={tolerance:e}");
        assert!(r.set.contains(&set), "{r:?}");
    }
    for (r, k) in l.rung.iter().zip(TIME_LADDER_DIVISORS) {
        let dt: f64 = r
            .set
            .iter()
            .find_map(|s| s.strip_prefix("simulation.dt="))
            .expect("a step")
            .parse()
            .expect("a number");
        assert!((dt - 0.01 / f64::from(k)).abs() < 1e-15, "{}", r.label);
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
fn frame_error_needs_the_same_time_and_measures_an_offset() {
    let f = |time: f64, z: f64| FrameSamples {
        frame: 1,
        time,
        positions: vec![Some([0.0, 0.0, z]), Some([1.0, 0.0, z]), None],
    };
    assert_eq!(frame_error(&f(0.1, 0.0), &f(0.1, 0.0), 2.0), Some(0.0));
    let e = frame_error(&f(0.1, 0.5), &f(0.1, 0.0), 2.0).expect("same time");
    assert!((e - 0.25).abs() < 1e-15, "{e}");
    assert_eq!(frame_error(&f(0.2, 0.0), &f(0.1, 0.0), 2.0), None);
}

/// The same plan run in-process and as a job list through `xargs -P 2` (and
/// once more split in two halves, collected together) gives the same CSV,
/// wall times aside; jobs that ran side by side are reported as such.
#[test]
fn a_job_list_run_through_xargs_gives_the_in_process_csv() {
    let dir = temp_dir("jobs");
    let scene = tiny_scene(&dir);
    let mut opts = tiny_options(&scene, small_ladder());
    opts.reps = 2;
    let local = dir.join("local");
    let (res, _) = bench(&opts, &local, &AtomicBool::new(false), &mut quiet()).expect("bench");
    assert!(res.rows.iter().all(|r| r.status == "ok"), "{:?}", res.rows);
    assert_eq!(res.concurrent, 0, "one job at a time");
    let csv_local = std::fs::read_to_string(local.join("tiny.csv")).expect("csv");
    let (plan, points) = make_plan(&opts).expect("plan");
    let jobs = dir.join("jobs");
    let plan = write_plan(plan, &points, &scene, &jobs, true).expect("written");
    assert_eq!(
        plan.jobs.len(),
        1 + 3 * 2,
        "reference and two repetitions of three runs"
    );
    let bin = Path::new(env!("CARGO_BIN_EXE_drape"))
        .parent()
        .expect("bin dir");
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let run_lines = |lines: &str| {
        let script = format!("printf '%s\\n' {lines} | tr '\\n' '\\0' | xargs -0 -P 2 -n 1 sh -c");
        let out = Command::new("sh")
            .arg("-c")
            .arg(script)
            .current_dir(&jobs)
            .env("PATH", &path)
            .output()
            .expect("xargs runs");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let list = std::fs::read_to_string(jobs.join(JOBS_FILE)).expect("jobs.txt");
    let quoted: Vec<String> = list
        .lines()
        .map(|l| format!("'{}'", l.replace('\'', r"'\''")))
        .collect();
    run_lines(&quoted.join(" "));
    let collected = collect(&jobs).expect("every job's output is there");
    drape::bench::report::write_all(&jobs, &collected).expect("files");
    let csv_jobs = std::fs::read_to_string(jobs.join("tiny.csv")).expect("csv");
    assert_eq!(csv_without_times(&csv_jobs), csv_without_times(&csv_local));
    let md = std::fs::read_to_string(jobs.join("tiny.md")).expect("md");
    assert_eq!(
        collected.concurrent > 0,
        md.contains("ran at the same time as another"),
        "{md}"
    );
    // Re-planned (the reference now cached), run in two halves, collected together.
    let plan = write_plan(
        make_plan(&opts).expect("plan").0,
        &points,
        &scene,
        &jobs,
        true,
    )
    .expect("re-planned");
    assert!(
        plan.jobs.iter().all(|j| j.run.is_some()),
        "the reference is cached"
    );
    let list = std::fs::read_to_string(jobs.join(JOBS_FILE)).expect("jobs.txt");
    let lines: Vec<String> = list
        .lines()
        .map(|l| format!("'{}'", l.replace('\'', r"'\''")))
        .collect();
    let (a, b) = lines.split_at(lines.len() / 2);
    run_lines(&a.join(" "));
    run_lines(&b.join(" "));
    let halves = collect(&jobs).expect("both halves");
    drape::bench::report::write_all(&jobs, &halves).expect("files");
    let csv_halves = std::fs::read_to_string(jobs.join("tiny.csv")).expect("csv");
    assert_eq!(
        csv_without_times(&csv_halves),
        csv_without_times(&csv_local)
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A job that did not run, and one whose output another plan wrote, are
/// named at collect; nothing is dropped silently.
#[test]
fn missing_and_stale_job_outputs_are_named_at_collect() {
    let dir = temp_dir("missing");
    let scene = tiny_scene(&dir);
    let opts = tiny_options(&scene, small_ladder());
    let (plan, points) = make_plan(&opts).expect("plan");
    let plan = write_plan(plan, &points, &scene, &dir.join("b"), true).expect("written");
    run_jobs(&dir.join("b"), &plan, &AtomicBool::new(false), &mut quiet()).expect("jobs");
    let first = dir.join("b").join(&plan.jobs[1].output);
    let second = dir.join("b").join(&plan.jobs[2].output);
    std::fs::remove_file(&first).expect("removed");
    let third = std::fs::read_to_string(dir.join("b").join(&plan.jobs[3].output)).expect("read");
    std::fs::write(&second, third).expect("overwritten");
    let err = collect(&dir.join("b")).expect_err("two jobs are unusable");
    let text = err.to_string();
    assert!(
        matches!(err, BenchError::Jobs(ref v) if v.len() == 2),
        "{text}"
    );
    assert!(
        text.contains("`uniform 4`, repetition 1") && text.contains("missing"),
        "{text}"
    );
    assert!(
        text.contains("`uniform 8`, repetition 1") && text.contains("another plan"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A run that fails numerically is a row marked failed, not a missing job;
/// the reference comes from the cache on the second bench.
#[test]
fn a_failed_rung_is_a_row_and_the_reference_is_cached() {
    let dir = temp_dir("failed");
    let scene = tiny_scene(&dir);
    let mut ladder = small_ladder();
    ladder.rung.push(rung(
        // Far beyond the explicit stability limit even after 4 halvings.
        "blows up",
        &[
            "adapt.method=none",
            "simulation.integrator=symplectic_euler",
            "material.stretch=2e7",
            "simulation.dt=0.001",
        ],
    ));
    let opts = tiny_options(&scene, ladder);
    let out = dir.join("out");
    let (res, files) = bench(&opts, &out, &AtomicBool::new(false), &mut quiet()).expect("bench");
    let failed = &res.rows[3];
    assert!(
        failed.status.starts_with("failed: numerical failure"),
        "{}",
        failed.status
    );
    assert!(failed.error.is_nan() && !failed.pareto);
    assert!(
        res.rows[..3]
            .iter()
            .all(|r| r.status == "ok" && r.error.is_finite())
    );
    assert!(res.rows[0].error > res.rows[1].error, "finer is closer");
    assert_eq!(files.len(), 4);
    let csv = std::fs::read_to_string(out.join("tiny.csv")).expect("csv");
    assert_eq!(csv.lines().next(), Some(CSV_HEADER));
    assert_eq!(csv.lines().count(), 1 + 4);
    let mut log = Vec::new();
    bench(&opts, &out, &AtomicBool::new(false), &mut |l| {
        log.push(l.to_owned())
    })
    .expect("again");
    assert!(
        log.iter().any(|l| l.starts_with("reference: cached")),
        "{log:?}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The lift floor is an ordinary run marked as a floor: on a scene that
/// answers smoothly its error is far below every rung's.
#[test]
fn the_lift_floor_is_a_floor_row_far_below_the_rungs() {
    let dir = temp_dir("floor");
    let scene = tiny_scene(&dir);
    let mut opts = tiny_options(&scene, small_ladder());
    opts.floor = true;
    let res = bench_out(&opts, &dir);
    let floor = res.rows.last().expect("rows");
    assert!(floor.run.floor && !floor.pareto, "{floor:?}");
    let smallest = res.rows.iter().filter(|r| !r.run.floor).map(|r| r.error);
    let smallest = smallest.fold(f64::INFINITY, f64::min);
    assert!(
        floor.error < 1e-3 * smallest,
        "{} vs {smallest}",
        floor.error
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A plan directory holds the scene and the OBJ files it names: moved to
/// another place, its jobs still run.
#[test]
fn a_plan_carries_the_scene_and_its_obj_files() {
    let dir = temp_dir("carry");
    let meshes = dir.join("meshes");
    std::fs::create_dir_all(&meshes).expect("dir");
    let obj = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/quad_2x2_uv.obj");
    std::fs::copy(obj, meshes.join("quad.obj")).expect("copied");
    let scenes = dir.join("scenes");
    std::fs::create_dir_all(&scenes).expect("dir");
    let scene = scenes.join("objcloth.toml");
    let text = std::fs::read_to_string(tiny_scene(&dir)).expect("scene");
    let text = text
        .replace("name = \"tiny\"", "name = \"objcloth\"")
        .replace(
            "shape = \"rectangle\"",
            "shape = \"obj\"\npath = \"../meshes/quad.obj\"",
        )
        .replace("width = 0.5\nheight = 0.5\nresolution = 4\n", "")
        .replace("corner:top_left", "all");
    std::fs::write(&scene, text).expect("scene");
    let ladder = Ladder {
        reference: Some(vec![]),
        compare: None,
        step: None,
        rung: vec![rung("as is", &[])],
    };
    let opts = tiny_options(&scene, ladder);
    let (plan, points) = make_plan(&opts).expect("plan");
    let plan = write_plan(plan, &points, &scene, &dir.join("plan"), false).expect("written");
    let moved = dir.join("elsewhere");
    std::fs::rename(dir.join("plan"), &moved).expect("moved");
    std::fs::remove_dir_all(&meshes).expect("the original mesh is gone");
    run_jobs(&moved, &plan, &AtomicBool::new(false), &mut quiet()).expect("jobs run");
    let res = collect(&moved).expect("collected");
    assert_eq!(res.rows[0].status, "ok");
    assert_eq!(res.rows[0].error, 0.0, "the same run as the reference");
    std::fs::remove_dir_all(&dir).ok();
}

/// The time-step ladder: with backward Euler the error falls with the step.
#[test]
fn time_ladder_end_to_end_error_falls_with_the_step() {
    let dir = temp_dir("time");
    let scene = tiny_scene(&dir);
    let mut opts = tiny_options(&scene, small_ladder());
    opts.ladder = None;
    opts.time_ladder = true;
    opts.overrides = vec!["cloth.resolution=6".into()];
    opts.duration = Some(0.2);
    let res = bench_out(&opts, &dir);
    assert_eq!(res.plan.stem, "tiny-time");
    assert!(res.plan.common_dt.is_none());
    let all: Vec<f64> = res.rows.iter().map(|r| r.error).collect();
    println!("errors: fixed steps, then adaptive at 2e-3, 5e-4, 1.25e-4 m: {all:?}");
    assert_eq!(all.len(), 6, "{all:?}");
    let (e, adaptive) = all.split_at(3);
    assert!(e[0] > e[1] && e[1] > e[2] && e[2] > 0.0, "{e:?}");
    // The implicit scene's adaptive rungs: a tighter tolerance, a smaller error.
    assert!(
        adaptive[0] > adaptive[2] && adaptive[2] > 0.0,
        "adaptive {adaptive:?}"
    );
    assert!(res.rows[3..].iter().all(|r| r.status == "ok"));
    // Backward Euler is first order; the reference's own error (1/8 of the
    // smallest rung's) raises the observed order a little above 1.
    let order = (e[0] / e[2]).log2() / 2.0;
    assert!(
        order > 0.8 && order < 1.5,
        "observed order {order}, errors {e:?}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// `drape bench plan` and `drape bench collect` from the command line; an
/// unknown rung is refused before anything runs.
#[test]
fn bench_cli_plans_collects_and_rejects_unknown_rungs() {
    let dir = temp_dir("cli");
    let scene = tiny_scene(&dir);
    let drape = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_drape"))
            .args(args)
            .current_dir(&dir)
            .output()
            .expect("drape runs")
    };
    let scene = scene.to_str().expect("utf-8");
    let out = drape(&["bench", "plan", scene, "--rungs", "nope", "--out", "p"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no rung labelled `nope`") && err.contains("uniform 16"),
        "{err}"
    );
    let args = [
        "bench",
        "plan",
        scene,
        "--rungs",
        "uniform 16",
        "--duration",
        "0.1",
    ];
    let out = drape(&[&args[..], &["--out", "p", "--no-floor", "--samples", "6"]].concat());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("wrote 2 jobs"), "{text}");
    let out = drape(&["bench", "collect", "p"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the reference") && err.contains("missing"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The default ladder's rungs of the other method turn the red-green sizing
/// rule's strain and obstacle terms off, so that it plans on every shipped
/// scene, including those that set them (the tablecloth, the hanging sheets).
#[test]
fn the_default_ladder_plans_on_every_shipped_adaptive_scene() {
    let dir = temp_dir("default-ladder");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in ["tablecloth", "hanging_sheet", "hanging_sheet_rest", "flag"] {
        let scene = root.join("scenes").join(format!("{name}.toml"));
        let out = Command::new(env!("CARGO_BIN_EXE_drape"))
            .args(["bench", "plan", scene.to_str().expect("utf-8")])
            .args(["--duration", "0.1", "--out", name])
            .current_dir(&dir)
            .output()
            .expect("drape runs");
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
