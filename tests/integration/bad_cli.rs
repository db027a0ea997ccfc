//! Bad command lines through the `drape` binary: malformed `--set` overrides, a
//! missing scene file, and usage errors (unknown options and subcommands, bad
//! option values), which clap answers with exit status 2.

use crate::bad_input::{drape, refused, scene_dir, temp_dir};

#[test]
fn bad_overrides_are_refused() {
    let dir = scene_dir("overrides");
    for (set, needle) in [
        ("cloth.resolution", "expected `dotted.path=value`"),
        ("=3", "has an empty part"),
        ("cloth..width=1", "has an empty part"),
        (
            "pin.7.region=all",
            "index 7 is out of range: the scene has 1",
        ),
        (
            "pin.region=all",
            "is an array: address an element by its index",
        ),
        ("simulation.duration.x=1", "is a float, not a table"),
    ] {
        refused(
            &drape(&dir, &["check", "full.toml", "--set", set]),
            1,
            &[needle],
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn set_adds_the_first_obstacle_to_a_scene_without_any_regression() {
    // `--set obstacle.0.shape=...` on a scene with no [[obstacle]] used to create a
    // table and fail with "key `obstacle`: wrong type: found map".
    let dir = temp_dir("first-obstacle");
    let sets = ["obstacle.0.shape=sphere", "obstacle.0.radius=0.2"];
    let out = drape(&dir, &["check", "--set", sets[0], "--set", sets[1]]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = drape(
        &dir,
        &["check", "--set", sets[0], "--set", "obstacle.0.radius=0"],
    );
    refused(&out, 1, &["key `obstacle.0.radius`: 0 is out of range"]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_missing_or_unreadable_scene_file_is_refused() {
    let dir = temp_dir("no-scene");
    refused(
        &drape(&dir, &["check", "nope.toml"]),
        1,
        &["nope.toml: cannot read the scene file"],
    );
    refused(
        &drape(&dir, &["run", "."]),
        1,
        &[".: cannot read the scene file"],
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn command_line_usage_errors_exit_2() {
    let dir = temp_dir("usage");
    for (args, needle) in [
        (&["frobnicate"][..], "unrecognized subcommand 'frobnicate'"),
        (&["run", "--bogus"], "unexpected argument '--bogus'"),
        (
            &["run", "--threads", "0"],
            "invalid value '0' for '--threads <N>'",
        ),
        (&["run", "--threads", "many"], "invalid value 'many'"),
        // Used to be accepted and run for minutes (10000 threads on 2 cores).
        (
            &["run", "--threads", "10000"],
            "invalid value '10000' for '--threads <N>': 10000 is not in 1..=256",
        ),
        (
            &["run", "--out"],
            "a value is required for '--out <FILE.rrd>'",
        ),
        (
            &["check", "a.toml", "b.toml"],
            "unexpected argument 'b.toml'",
        ),
        (&[], "Usage: drape <COMMAND>"),
    ] {
        let out = drape(&dir, args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(err.contains(needle), "`{needle}` missing from: {err}");
    }
    assert_eq!(
        std::fs::read_dir(&dir).expect("list").count(),
        0,
        "nothing written"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Regression: a listing piped into `head` panicked ("failed printing to
/// stdout: Broken pipe", exit 101) when the reader closed the pipe early. The
/// read end is closed here before drape writes anything.
#[test]
fn bench_plan_into_a_closed_pipe_does_not_panic() {
    let out_dir = std::env::temp_dir().join(format!("drape-closed-pipe-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out_dir);
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cantilever.toml");
    let ladder =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/bench/cantilever.toml");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_drape"))
        .args(["bench", "plan", "--ladder"])
        .arg(&ladder)
        .arg(&scene)
        .arg("--out")
        .arg(&out_dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("drape runs");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("drape ends");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "stderr: {stderr}");
    std::fs::remove_dir_all(&out_dir).ok();
}

#[test]
fn colouring_by_decisions_without_them_is_refused_before_the_run() {
    let dir = temp_dir("colour-no-decisions");
    for colour in ["ratio", "state"] {
        refused(
            &drape(
                &dir,
                &[
                    "run",
                    "--no-decisions",
                    "--colour-by",
                    colour,
                    "-o",
                    "x.rrd",
                ],
            ),
            1,
            &[&format!("--colour-by {colour}"), "--no-decisions"],
        );
        assert!(!dir.join("x.rrd").exists(), "no recording is started");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn colouring_by_decisions_on_a_scene_that_does_not_adapt_is_refused_before_the_run() {
    let dir = temp_dir("colour-no-adapt");
    let args = [
        "run",
        "--set",
        "adapt.method=none",
        "--colour-by",
        "state",
        "-o",
        "x.rrd",
    ];
    refused(
        &drape(&dir, &args),
        1,
        &["--colour-by ratio and --colour-by state", "does not adapt"],
    );
    assert!(!dir.join("x.rrd").exists(), "no recording is started");
    std::fs::remove_dir_all(&dir).ok();
}
