//! `drape inspect` on a recording with known contents, and its errors; `--spawn` and
//! `--connect` failing before any simulation.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use drape::math::Vector;
use drape::record::{EdgeDisplay, EventMark, FrameView, RecordTarget, Recorder};

fn temp_path(name: &str) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!("drape-insp-{}-{n}-{name}", std::process::id()))
}

fn drape(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_drape"))
        .args(args)
        .output()
        .expect("run drape")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn mark(kind: &'static str, level: u8, step: u64) -> EventMark {
    EventMark {
        kind,
        position: Vector::new(0.5, 0.5, 0.0),
        level,
        angle: Some(20.0),
        step,
        weld: None,
        reason: String::new(),
        corners: None,
    }
}

/// Three frames of a unit square (two triangles, levels 0 and 1, five edges with angles
/// 0, 0, 10, 0, 0 degrees): frame 1 has a split and a merge, frame 2 a rollback.
fn known_recording(path: &Path) {
    let positions = [
        Vector::new(0.0, 0.0, 0.0),
        Vector::new(1.0, 0.0, 0.0),
        Vector::new(1.0, 1.0, 0.0),
        Vector::new(0.0, 1.0, 0.0),
    ];
    let normals = [Vector::Z; 4];
    let edges = [[0, 1], [1, 2], [0, 2], [2, 3], [0, 3]];
    let angles = [0.0, 0.0, 10.0, 0.0, 0.0];
    let events = [
        vec![],
        vec![mark("split", 1, 3), mark("merge", 0, 4)],
        vec![mark("rollback", 1, 7)],
    ];
    let target = RecordTarget::file(path);
    let mut rec = Recorder::open(&target, "known", EdgeDisplay::All).expect("open");
    for (f, ev) in events.iter().enumerate() {
        let vertices = [("mesh/vertices", 4.0), ("energy/total", f as f64)];
        rec.record_frame(&FrameView {
            frame: f as u64,
            sim_time: f as f64 * 0.5,
            positions: &positions,
            vertex_normals: &normals,
            triangles: &[[0, 1, 2], [0, 2, 3]],
            triangle_levels: &[0, 1],
            edges: &edges,
            edge_angles: &angles,
            pinned: &[3],
            scalars: &vertices,
            events: ev,
            garment: None,
            decisions: None,
        })
        .expect("frame");
    }
    rec.finish().expect("finish");
}

#[test]
fn inspect_prints_the_overview_and_a_frame() {
    let path = temp_path("known.rrd");
    known_recording(&path);
    let p = path.to_str().expect("utf-8");
    let out = drape(&["inspect", p]);
    let s = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let id = drape::record::recording_id("known");
    for want in [
        "complete (stream footer present)".to_owned(),
        format!("application drape, recording id {id}"),
        "frames: 3 recorded, 0 to 2; sim_time 0.0000 s to 1.0000 s".to_owned(),
        "vertices: 4 to 4; triangles: 2 to 2; levels: 0 to 1".to_owned(),
        "mesh topology logged on 1 of 3 frames".to_owned(),
        "edges per frame: 5 to 5; largest angle 10.00 deg".to_owned(),
        "events: 3 (merge 1, rollback 1, split 1)".to_owned(),
        "frames with the most events: 1 (2), 2 (1)".to_owned(),
    ] {
        assert!(s.contains(&want), "missing {want:?} in:\n{s}");
    }
    let rows = |entity: &str| {
        s.lines()
            .find(|l| l.split_whitespace().next() == Some(entity))
            .map(|l| l.split_whitespace().skip(1).collect::<Vec<_>>())
    };
    assert_eq!(rows("/cloth/mesh"), Some(vec!["3", "0"]));
    // One static row: the annotation context of the angle classes.
    assert_eq!(rows("/cloth/edges"), Some(vec!["3", "1"]));
    assert_eq!(rows("/events/log"), Some(vec!["3", "0"]));
    assert_eq!(rows("/plots/energy/total"), Some(vec!["3", "0"]));
    assert_eq!(rows("/cloth"), Some(vec!["0", "1"]));

    let out = drape(&["inspect", p, "--frame", "1"]);
    let s = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    for want in [
        "frame 1, sim_time 0.5000 s",
        "mesh: 2 triangles, 4 vertices (topology as last logged)",
        "triangles per level (2 values): level 0: 1, level 1: 1",
        "edges: 5 recorded, largest angle 10.00 deg",
        "  energy/total = 1",
        "events: 2",
        "  split after step 3: level 1, angle 20.00 deg, at (0.500, 0.500, 0.000) m",
        "  merge after step 4: level 0",
    ] {
        assert!(s.contains(want), "missing {want:?} in:\n{s}");
    }

    let out = drape(&["inspect", p, "--frame", "9"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("frame 9 is not in the recording (it holds frames 0 to 2)"),
        "{err}"
    );
    std::fs::remove_file(&path).ok();
}

/// `drape inspect --frames`: one line per frame with its time, mesh size, triangles
/// at the recording's finest level, operations, contacts and stepping time, `-`
/// where nothing was logged, and the stepping time summed; `--frame` and
/// `--frames` together are refused.
#[test]
fn inspect_frames_prints_a_line_per_frame_and_the_stepping_total() {
    let path = temp_path("frames.rrd");
    let positions = [
        Vector::new(0.0, 0.0, 0.0),
        Vector::new(1.0, 0.0, 0.0),
        Vector::new(1.0, 1.0, 0.0),
        Vector::new(0.0, 1.0, 0.0),
    ];
    let target = RecordTarget::file(&path);
    let mut rec = Recorder::open(&target, "frames", EdgeDisplay::All).expect("open");
    for f in 0..3u64 {
        let mut scalars = vec![("mesh/vertices", 4.0), ("timing/sim_ms", 12.5 * f as f64)];
        if f > 0 {
            scalars.push(("adapt/splits", 3.0 * f as f64));
        }
        rec.record_frame(&FrameView {
            frame: f,
            sim_time: f as f64 * 0.25,
            positions: &positions,
            vertex_normals: &[Vector::Z; 4],
            triangles: &[[0, 1, 2], [0, 2, 3]],
            triangle_levels: &[0, 2],
            edges: &[[0, 1], [1, 2], [0, 2], [2, 3], [0, 3]],
            edge_angles: &[0.0; 5],
            pinned: &[],
            scalars: &scalars,
            events: &[],
            garment: None,
            decisions: None,
        })
        .expect("frame");
    }
    rec.finish().expect("finish");
    let p = path.to_str().expect("utf-8");
    let out = drape(&["inspect", p, "--frames"]);
    let s = text(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let rows: Vec<Vec<&str>> = s.lines().map(|l| l.split_whitespace().collect()).collect();
    assert_eq!(
        rows[0],
        [
            "frame",
            "time",
            "s",
            "vertices",
            "triangles",
            "at",
            "level",
            "2",
            "splits",
            "merges",
            "rollbacks",
            "contacts",
            "sim",
            "ms"
        ]
    );
    assert_eq!(
        rows[1],
        ["0", "0.0000", "4", "2", "1", "-", "-", "-", "-", "0.0"]
    );
    assert_eq!(
        rows[2],
        ["1", "0.2500", "4", "2", "1", "3", "-", "-", "-", "12.5"]
    );
    assert_eq!(
        rows[3],
        ["2", "0.5000", "4", "2", "1", "6", "-", "-", "-", "25.0"]
    );
    assert_eq!(
        s.lines().nth(4),
        Some("stepping time over the frames: 37.5 ms")
    );
    assert_eq!(s.lines().count(), 5);

    let out = drape(&["inspect", p, "--frames", "--frame", "1"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("cannot be used with"), "{err}");
    std::fs::remove_file(&path).ok();
}

/// Regression: `drape inspect FILE | head` panicked in `print!` once `head` had
/// closed the pipe ("failed printing to stdout: Broken pipe", exit code 101 and a
/// backtrace). The reading end is closed here before drape writes anything; it
/// must end quietly with code 0, as `drape bench --list` already did. (Checked to
/// fail with the old `print!`.)
#[test]
fn inspect_into_a_closed_pipe_ends_quietly() {
    use std::process::Stdio;
    let path = temp_path("pipe.rrd");
    known_recording(&path);
    let p = path.to_str().expect("utf-8");
    for args in [vec!["inspect", p], vec!["inspect", p, "--frame", "1"]] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_drape"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("run drape");
        drop(child.stdout.take());
        let out = child.wait_with_output().expect("wait for drape");
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let _ = std::fs::remove_file(&path);
}

#[test]
fn inspect_refuses_missing_and_non_rrd_files() {
    let out = drape(&["inspect", "/nonexistent-dir/x.rrd"]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("error: cannot read /nonexistent-dir/x.rrd"),
        "{err}"
    );

    let toml = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/flag.toml");
    let out = drape(&["inspect", toml.to_str().expect("utf-8")]);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("is not a Rerun .rrd recording"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

#[test]
fn live_viewer_errors_come_before_simulating() {
    let dir = temp_path("live");
    std::fs::create_dir_all(&dir).expect("dir");
    // A 1000 s run would take minutes: these must fail at once.
    let run = |extra: &[&str], path: &str| {
        Command::new(env!("CARGO_BIN_EXE_drape"))
            .args([
                "run",
                "--set",
                "simulation.duration=1000",
                "-q",
                "--out",
                "x.rrd",
            ])
            .args(extra)
            .current_dir(&dir)
            .env("PATH", path)
            .output()
            .expect("run drape")
    };
    let out = run(&["--spawn"], dir.to_str().expect("utf-8"));
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--spawn needs the Rerun viewer 0.36.3 as `rerun` on PATH"),
        "{err}"
    );

    let out = run(&["--connect", "not a url"], "/usr/bin:/bin");
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("not a url"), "{err}");
    assert!(err.contains("rerun+http://127.0.0.1:9876/proxy"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
