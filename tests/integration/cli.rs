//! The `drape` binary end to end: `run` with its recording, summary JSON, OBJ export,
//! overrides and thread counts; `check` on the shipped scenes; exit codes and error
//! messages for bad scenes, bad options and unwritable outputs.
//!
//! Runs use the embedded default scene shortened to 0.2 s (7 frames, well under a
//! second each).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

use crate::recording::decode;

/// Short runs: 0.2 s at 30 fps is 6 frames after the initial one.
const SHORT: &str = "simulation.duration=0.2";
const SHORT_FRAMES: u64 = 7;

/// A fresh empty directory in the temp dir, unique per process, test and call.
fn temp_dir(name: &str) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir =
        std::env::temp_dir().join(format!("drape-cli-test-{}-{n}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// Runs `drape ARGS` in `cwd` and prints what it said.
pub(crate) fn drape(args: &[&str], cwd: &Path) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_drape"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("run drape");
    println!(
        "drape {}: exit {:?}\n{}{}",
        args.join(" "),
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).expect("summary written");
    serde_json::from_str(&text).expect("summary is JSON")
}

fn num(v: &Value, key: &str) -> f64 {
    v.pointer(key)
        .and_then(Value::as_f64)
        .unwrap_or_else(|| panic!("summary field {key} is a number: {v}"))
}

fn int(v: &Value, key: &str) -> u64 {
    v.pointer(key)
        .and_then(Value::as_u64)
        .unwrap_or_else(|| panic!("summary field {key} is an integer: {v}"))
}

fn path_str(p: &Path) -> &str {
    p.to_str().expect("utf-8 temp path")
}

/// A scene file in `dir`: a small sheet, plus `extra` lines at the end of `[cloth]`.
fn write_scene(dir: &Path, name: &str, extra_cloth: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!(
            "name = \"small\"\n\
             [simulation]\n\
             duration = 0.1\n\
             [cloth]\n\
             shape = \"rectangle\"\n\
             width = 1.0\n\
             height = 1.0\n\
             resolution = 4\n\
             {extra_cloth}\n\
             [material]\n\
             density = 0.15\n\
             stretch = 200.0\n"
        ),
    )
    .expect("write scene");
    path
}

#[test]
fn run_default_scene_writes_a_decodable_recording_and_a_complete_summary() {
    let dir = temp_dir("run");
    let (rrd, json) = (dir.join("x.rrd"), dir.join("s.json"));
    // The default scene on a uniform 24-segment mesh, whose counts are fixed.
    let out = drape(
        &[
            "run",
            "--set",
            SHORT,
            "--set",
            "adapt.method=none",
            "--set",
            "cloth.resolution=24",
            "--out",
            path_str(&rrd),
            "--summary",
            path_str(&json),
            "-q",
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(stderr(&out).is_empty(), "quiet: {}", stderr(&out));
    assert!(
        stdout(&out).starts_with("default: 7 frames"),
        "{}",
        stdout(&out)
    );

    let s = read_json(&json);
    assert_eq!(s["scene"], "default");
    let frames = int(&s, "/frames");
    assert_eq!(frames, SHORT_FRAMES, "duration * 30 + 1");
    assert!(int(&s, "/steps") >= frames - 1);
    assert!((num(&s, "/sim_time") - 0.2).abs() < 1e-9);
    assert!(num(&s, "/wall_time_s") > 0.0);
    // The default sheet: 24 x 24 squares, 25 x 25 vertices, constant (no remeshing).
    for (key, n) in [("vertices", 625.0), ("triangles", 1152.0)] {
        for stat in ["min", "mean", "max"] {
            assert_eq!(num(&s, &format!("/{key}/{stat}")), n, "{key}.{stat}");
        }
    }
    // 1 m^2 at 0.15 kg/m^2, exactly conserved.
    let (m0, m1) = (num(&s, "/mass_initial"), num(&s, "/mass_final"));
    assert!((m0 - 0.15).abs() < 1e-12, "mass {m0}");
    assert_eq!(m0, m1, "mass is conserved");
    // At rest, unstretched, 1 m up: the energy is m g h; it can only drop (damping, drag).
    let (e0, e1, emax) = (
        num(&s, "/energy/initial"),
        num(&s, "/energy/final"),
        num(&s, "/energy/max"),
    );
    assert!((e0 - 0.15 * 9.81 * 1.0).abs() < 1e-9, "initial energy {e0}");
    assert!(e1.is_finite() && e1 < e0, "final energy {e1}");
    assert!(emax >= e0 && emax >= e1, "max energy {emax}");
    assert_eq!(int(&s, "/nan_recoveries"), 0);
    assert_eq!(s["interrupted"], false);

    // The recording: the summary names it with its size, and it decodes to one
    // `cloth/mesh` row per recorded frame.
    assert_eq!(s["recording"]["path"], path_str(&rrd));
    let size = std::fs::metadata(&rrd).expect("rrd written").len();
    assert_eq!(int(&s, "/recording/bytes"), size);
    let decoded = decode(&rrd);
    assert_eq!(
        decoded.rows.get("/cloth/mesh").copied(),
        Some(frames as usize),
        "{:?}",
        decoded.rows
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn no_record_writes_no_rrd_and_a_null_recording() {
    let dir = temp_dir("no-record");
    let out = drape(
        &[
            "run",
            "--set",
            SHORT,
            "--no-record",
            "--summary",
            "s.json",
            "-q",
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(stdout(&out).contains("No recording."), "{}", stdout(&out));
    let s = read_json(&dir.join("s.json"));
    assert!(s["recording"].is_null(), "recording: {}", s["recording"]);
    let files: Vec<_> = std::fs::read_dir(&dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(files, ["s.json"], "nothing but the summary");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn default_output_is_the_scene_name_rrd_in_the_cwd() {
    let dir = temp_dir("default-out");
    let out = drape(&["run", "--set", SHORT, "--summary", "s.json", "-q"], &dir);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let rrd = dir.join("default.rrd");
    let s = read_json(&dir.join("s.json"));
    assert_eq!(s["recording"]["path"], "default.rrd");
    assert_eq!(
        int(&s, "/recording/bytes"),
        std::fs::metadata(&rrd).expect("default.rrd").len()
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn out_and_no_record_conflict() {
    let dir = temp_dir("conflict");
    let out = drape(&["run", "--no-record", "--out", "x.rrd"], &dir);
    assert_eq!(out.status.code(), Some(2), "clap usage error");
    assert!(
        stderr(&out).contains("cannot be used with"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("x.rrd").exists());
    std::fs::remove_dir_all(&dir).ok();
}

/// The first run a user makes shows adaptivity: the embedded default scene
/// refines where the sheet folds and coarsens again within its first second.
#[test]
fn the_default_scene_refines_and_coarsens() {
    let dir = temp_dir("default-adapts");
    let args = ["run", "--set", "simulation.duration=1.0", "--no-record"];
    let out = drape(&[&args[..], &["--summary", "s.json", "-q"]].concat(), &dir);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let s = read_json(&dir.join("s.json"));
    let (splits, merges) = (int(&s, "/splits"), int(&s, "/merges"));
    assert!(splits > 0 && merges > 0, "splits {splits}, merges {merges}");
    assert!(int(&s, "/max_level") >= 2, "max level {}", s["max_level"]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn obj_dir_gets_one_obj_per_recorded_frame() {
    let dir = temp_dir("obj-dir");
    let objs = dir.join("frames");
    let out = drape(
        &[
            "run",
            "--set",
            SHORT,
            "--set",
            "cloth.resolution=4",
            "--set",
            "adapt.method=none",
            "--no-record",
            "--obj-dir",
            path_str(&objs),
            "-q",
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let mut names: Vec<String> = std::fs::read_dir(&objs)
        .expect("obj dir created")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let expected: Vec<String> = (0..SHORT_FRAMES)
        .map(|f| format!("frame_{f:05}.obj"))
        .collect();
    assert_eq!(names, expected);
    for name in &names {
        let text = std::fs::read_to_string(objs.join(name)).expect("read obj");
        let count = |tag: &str| {
            text.lines()
                .filter(|l| l.split_whitespace().next() == Some(tag))
                .count()
        };
        // 4 x 4 squares: 25 vertices, 32 triangles.
        assert_eq!(
            (count("v"), count("vt"), count("f")),
            (25, 25, 32),
            "{name}"
        );
    }
    // The files read back as the same mesh.
    let (models, _) =
        tobj::load_obj(objs.join(&names[6]), &tobj::GPU_LOAD_OPTIONS).expect("tobj reads it");
    assert_eq!(models[0].mesh.indices.len(), 3 * 32);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn set_cloth_resolution_changes_the_vertex_count() {
    let dir = temp_dir("resolution");
    let out = drape(
        &[
            "run",
            "--set",
            SHORT,
            "--set",
            "cloth.resolution=8",
            "--set",
            "adapt.method=none",
            "--no-record",
            "--summary",
            "s.json",
            "-q",
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let s = read_json(&dir.join("s.json"));
    assert_eq!(num(&s, "/vertices/mean"), 81.0, "9 x 9 vertices");
    assert_eq!(num(&s, "/triangles/mean"), 128.0);
    // Same sheet, same mass, on any mesh.
    assert!((num(&s, "/mass_initial") - 0.15).abs() < 1e-12);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn thread_count_does_not_change_the_result() {
    let dir = temp_dir("threads");
    let mut finals = Vec::new();
    for threads in ["1", "2"] {
        let json = format!("s{threads}.json");
        let out = drape(
            &[
                "run",
                "--set",
                SHORT,
                "--no-record",
                "--threads",
                threads,
                "--summary",
                &json,
                "-q",
            ],
            &dir,
        );
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let s = read_json(&dir.join(&json));
        // As printed in the JSON: the shortest round-trip decimal, so equal text is equal bits.
        finals.push((s["energy"]["final"].to_string(), s["steps"].clone()));
    }
    assert_eq!(finals[0], finals[1], "energy.final with 1 and 2 threads");
    // A zero thread count is refused by the parser.
    let out = drape(&["run", "--threads", "0", "--no-record"], &dir);
    assert_eq!(out.status.code(), Some(2));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn check_flag_lists_wind_and_rk4() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let out = drape(&["check", "flag.toml"], &scenes);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out).to_lowercase();
    assert!(text.contains("wind:"), "{text}");
    assert!(text.contains("rk4"), "{text}");
    assert!(text.contains("scene `flag`"), "{text}");
}

#[test]
fn check_prints_a_rectangles_cells() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let out = drape(
        &[
            "check",
            "cantilever.toml",
            "--set",
            "cloth.short_side_segments=2",
        ],
        &scenes,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    // 20 segments along the 5 cm, 2 across the 2 cm.
    assert!(
        text.contains("cloth: Rectangle (20 x 2 cells of 0.0025 x 0.0100 m), 63 vertices"),
        "{text}"
    );
}

#[test]
fn check_unknown_key_names_file_line_and_key() {
    let dir = temp_dir("unknown-key");
    let scene = write_scene(&dir, "bad.toml", "colour = \"red\"");
    let out = drape(&["check", "bad.toml"], &dir);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.starts_with("error: "), "{err}");
    // `colour` is on line 9 of the file.
    let line = std::fs::read_to_string(&scene)
        .expect("read scene")
        .lines()
        .position(|l| l.starts_with("colour"))
        .expect("colour line")
        + 1;
    assert!(err.contains(&format!("bad.toml:{line}:")), "{err}");
    assert!(err.contains("cloth.colour"), "{err}");
    assert!(stdout(&out).is_empty());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn unknown_cli_option_is_a_usage_error() {
    let dir = temp_dir("bad-option");
    for sub in ["run", "check"] {
        let out = drape(&[sub, "--bogus"], &dir);
        assert_ne!(out.status.code(), Some(0));
        assert!(
            stderr(&out).contains("unexpected argument '--bogus'"),
            "{}",
            stderr(&out)
        );
    }
    // Nothing ran, nothing was written.
    assert_eq!(std::fs::read_dir(&dir).expect("list").count(), 0);
    std::fs::remove_dir_all(&dir).ok();
}

/// Waits for `child` at most `limit`; kills it and fails if it takes longer.
fn wait_at_most(mut child: std::process::Child, limit: Duration) -> Output {
    let start = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if start.elapsed() > limit {
            child.kill().ok();
            child.wait().ok();
            panic!("still running after {limit:?}: it simulated before failing");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("output")
}

#[test]
fn unwritable_out_fails_before_simulating() {
    let dir = temp_dir("unwritable");
    // A 1000 s run would take minutes: failing within seconds means nothing was simulated.
    let child = Command::new(env!("CARGO_BIN_EXE_drape"))
        .args([
            "run",
            "--set",
            "simulation.duration=1000",
            "--out",
            "/nonexistent-dir/x.rrd",
            "--summary",
            "s.json",
            "-q",
        ])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn drape");
    let out = wait_at_most(child, Duration::from_secs(20));
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains("/nonexistent-dir/x.rrd"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(stdout(&out).is_empty(), "no summary paragraph");
    assert!(!dir.join("s.json").exists(), "no summary file");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn every_shipped_scene_and_the_default_pass_check() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(root.join("scenes"))
        .expect("scenes/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 2, "{scenes:?}");
    for scene in &scenes {
        let out = drape(&["check", path_str(scene)], root);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}: {}",
            scene.display(),
            stderr(&out)
        );
        assert!(stdout(&out).starts_with("scene `"), "{}", scene.display());
    }
    let out = drape(&["check"], root);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(stdout(&out).starts_with("scene `default`"));
}

/// Regression: the flag (held along one edge, in wind) got a cantilever report
/// ("chord angle 8.94 deg, elastica 90.19 deg"); the test needs gravity alone.
/// The measurement is now made only where a scene asks for it (`measure`):
/// the cantilever scene does and gets the report, the flag does not and gets
/// none, and the flag asking for it is refused with the reason.
#[test]
fn cantilever_report_only_for_a_strip_under_gravity_alone() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = temp_dir("cantilever-report");
    for (scene, expect) in [("flag", false), ("cantilever", true)] {
        let path = root.join("scenes").join(format!("{scene}.toml"));
        let summary = dir.join(format!("{scene}.json"));
        let args = [
            "run",
            path_str(&path),
            "--set",
            "simulation.duration=0.05",
            "--no-record",
            "--summary",
            path_str(&summary),
            "-q",
        ];
        let out = drape(&args, &dir);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let s = read_json(&summary);
        assert_eq!(
            !s["cantilever"].is_null(),
            expect,
            "{scene}: {}",
            s["cantilever"]
        );
        assert_eq!(stdout(&out).contains("Cantilever:"), expect, "{scene}");
    }
    let flag = root.join("scenes/flag.toml");
    let args = [
        "run",
        path_str(&flag),
        "--set",
        "measure=[\"cantilever\"]",
        "--no-record",
        "-q",
    ];
    let out = drape(&args, &dir);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("key `measure`: the cantilever measurement compares with the elastica under gravity alone, and this scene has [wind]"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&dir).ok();
}
