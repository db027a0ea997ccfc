//! Bad OBJ files (missing, broken, non-manifold) and unwritable outputs through the
//! `drape` binary: refused with exit status 1 and a clear one-line message, never a
//! panic, and before any simulation.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::bad_input::{drape, refused, scene_dir, temp_dir};

/// A scene whose cloth is `m.obj` next to it.
const OBJ_SCENE: &str = "name = \"o\"\n[simulation]\nduration = 0.1\n[cloth]\n\
shape = \"obj\"\npath = \"m.obj\"\n[material]\ndensity = 0.1\nstretch = 100.0\n";

/// `drape check` of [`OBJ_SCENE`] with `obj` as `m.obj`: refused with `needles`.
fn refused_obj(obj: &[u8], needles: &[&str]) {
    let dir = temp_dir("obj");
    std::fs::write(dir.join("o.toml"), OBJ_SCENE).expect("write scene");
    std::fs::write(dir.join("m.obj"), obj).expect("write OBJ");
    let out = drape(&dir, &["check", "o.toml"]);
    let mut all = vec!["error: cloth mesh: m.obj"];
    all.extend_from_slice(needles);
    refused(&out, 1, &all);
    std::fs::remove_dir_all(&dir).ok();
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
const TEXCOORDS: &str = "vt 0 0\nvt 1 0\nvt 0 1\n";

#[test]
fn a_valid_obj_cloth_is_accepted() {
    let dir = temp_dir("obj-ok");
    std::fs::write(dir.join("o.toml"), OBJ_SCENE).expect("write scene");
    std::fs::write(dir.join("m.obj"), format!("{TRIANGLE}f 1 2 3\n")).expect("write OBJ");
    let out = drape(&dir, &["check", "o.toml"]);
    assert_eq!(out.status.code(), Some(0));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_missing_obj_is_refused_at_its_line() {
    let dir = temp_dir("obj-missing");
    std::fs::write(dir.join("o.toml"), OBJ_SCENE).expect("write scene");
    let out = drape(&dir, &["check", "o.toml"]);
    refused(
        &out,
        1,
        &["o.toml:6: key `cloth.path`: no such file: `m.obj`"],
    );
    std::fs::create_dir(dir.join("m.obj")).expect("a directory named m.obj");
    let out = drape(&dir, &["check", "o.toml"]);
    refused(
        &out,
        1,
        &["o.toml:6: key `cloth.path`: `m.obj` is a directory, not an OBJ file"],
    );
    let dir2 = scene_dir("obstacle-missing");
    let out = drape(
        &dir2,
        &["check", "full.toml", "--set", "obstacle.3.path=gone.obj"],
    );
    refused(
        &out,
        1,
        &["key `obstacle.3.path`: no such file: `gone.obj`"],
    );
    std::fs::remove_dir_all(&dir).ok();
    std::fs::remove_dir_all(&dir2).ok();
}

#[test]
fn a_broken_obj_is_refused() {
    let tri_vt = format!("{TRIANGLE}{TEXCOORDS}");
    let cases: Vec<(String, &str)> = vec![
        (String::new(), "the mesh has no triangles"),
        (
            "hello world\nthis is not a mesh\n".into(),
            "the mesh has no triangles",
        ),
        (TRIANGLE.into(), "the mesh has no triangles"),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1".into(),
            "cannot read OBJ: position parse error",
        ),
        (
            "v 0 0 zero\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".into(),
            "position parse error",
        ),
        (
            format!("{TRIANGLE}f 1 2 x\n"),
            "cannot read OBJ: face parse error",
        ),
        (format!("{TRIANGLE}f 1 2"), "the mesh has no triangles"),
        (
            format!("{TRIANGLE}f 1 2 9\n"),
            "face vertex index out of bounds",
        ),
        (
            format!("{TRIANGLE}f 1 2 -9\n"),
            "face vertex index out of bounds",
        ),
        (
            format!("{TRIANGLE}f 1 2 0\n"),
            "m.obj:4: face corner `0` has index 0",
        ),
        (
            format!("{tri_vt}f 1/1 2/2 3/9\n"),
            "face texcoord index out of bounds",
        ),
        (
            format!("{tri_vt}f 1/1 2/2 3/0\n"),
            "m.obj:7: face corner `3/0` has index 0",
        ),
        (format!("{TRIANGLE}f 1 2\n"), "the mesh has no triangles"),
        (format!("{TRIANGLE}f 1\n"), "the mesh has no triangles"),
        (format!("{TRIANGLE}f\n"), "cannot read OBJ: invalid polygon"),
        (
            "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".into(),
            "m.obj:1: `v` has a coordinate that is not a finite number: NaN",
        ),
        (
            "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n".into(),
            "m.obj:2: `v` has a coordinate that is not a finite number: inf",
        ),
        (
            format!("v 0 0 nan\nv 1 0 0\nv 0 1 0\n{TEXCOORDS}f 1/1 2/2 3/3\n"),
            "m.obj:1: `v` has a coordinate",
        ),
        (
            format!("{TRIANGLE}vt 0 0\nvt 1 -inf\nvt 0 1\nf 1/1 2/2 3/3\n"),
            "m.obj:5: `vt` has a coordinate that is not a finite number: -inf",
        ),
        (
            format!("{TRIANGLE}vt 0 0\nvt 1e300 0\nvt 0 1e300\nf 1/1 2/2 3/3\n"),
            "the mesh spans 1.4142135623730952e300 m in material space",
        ),
        (
            format!("{TRIANGLE}vt 0 0\nvt 1e-200 0\nvt 0 1e-200\nf 1/1 2/2 3/3\n"),
            "its square is outside the normal double-precision range",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n".into(),
            "no texture coordinates and is not flat",
        ),
        (
            format!("{tri_vt}f 1/1 2/2 3/3\nv 1 1 0\nf 2 4 3\n"),
            "some faces have texture coordinates and some do not",
        ),
    ];
    for (text, needle) in &cases {
        refused_obj(text.as_bytes(), &[needle]);
    }
    // Bytes that are not text at all (fixed, so that the test is repeatable).
    let bytes: Vec<u8> = (0..2000u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
        .collect();
    refused_obj(
        &bytes,
        &["cannot read OBJ: not a text file (it is not valid UTF-8)"],
    );
}

#[test]
fn a_bad_obj_leaves_no_recording_behind() {
    // `drape run` used to open the recording first and leave an empty `o.rrd`.
    let dir = temp_dir("obj-run");
    std::fs::write(dir.join("o.toml"), OBJ_SCENE).expect("write scene");
    std::fs::write(dir.join("m.obj"), format!("{TRIANGLE}f 1 2 9\n")).expect("write OBJ");
    std::fs::write(dir.join("old.rrd"), "keep").expect("an older recording");
    for args in [
        &["run", "o.toml"][..],
        &["run", "o.toml", "--out", "old.rrd"],
    ] {
        refused(&drape(&dir, args), 1, &["m.obj", "index out of bounds"]);
    }
    assert!(!dir.join("o.rrd").exists(), "no empty recording");
    let old = std::fs::read_to_string(dir.join("old.rrd")).expect("still there");
    assert_eq!(old, "keep", "an existing recording is not truncated");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_non_manifold_obj_is_refused() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    for (file, needle) in [
        (
            "nonmanifold_edge.obj",
            "non-manifold mesh: the edge between vertices",
        ),
        (
            "bowtie.obj",
            "non-manifold mesh: the triangles around vertex 0 form 2 separate fans",
        ),
        ("degenerate.obj", "is degenerate"),
    ] {
        let obj = std::fs::read(data.join(file)).expect("test data");
        refused_obj(&obj, &[needle]);
    }
}

/// Spawns `drape ARGS` in `dir` and waits at most 20 s: a run of 1000 simulated
/// seconds that fails in time has failed before simulating.
fn fails_fast(dir: &Path, args: &[&str]) -> std::process::Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_drape"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn drape");
    let start = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if start.elapsed() > Duration::from_secs(20) {
            child.kill().ok();
            child.wait().ok();
            panic!("drape {args:?} simulated before failing");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("output");
    println!(
        "drape {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[test]
fn unwritable_outputs_are_refused_before_simulating() {
    let dir = temp_dir("outputs");
    std::fs::write(dir.join("afile"), "").expect("a plain file");
    std::fs::create_dir(dir.join("adir")).expect("a directory");
    let long = ["run", "-q", "--set", "simulation.duration=1000"];
    for (extra, needle) in [
        (
            &["--out", "missing/x.rrd"][..],
            "cannot create recording file missing/x.rrd",
        ),
        (&["--out", "afile/x.rrd"], "Not a directory"),
        (&["--out", "adir"], "Is a directory"),
        (
            &["--no-record", "--summary", "missing/s.json"],
            "cannot write summary missing/s.json",
        ),
        (
            &["--no-record", "--summary", "adir"],
            "cannot write summary adir: Is a directory",
        ),
        (
            &["--out", "x.rrd", "--obj-dir", "afile"],
            "cannot create the OBJ directory afile: a file of that name exists",
        ),
        (
            &["--no-record", "--obj-dir", "afile/objs"],
            "cannot create the OBJ directory afile/objs",
        ),
    ] {
        let out = fails_fast(&dir, &[&long[..], extra].concat());
        refused(&out, 1, &[needle]);
    }
    // Nothing was left behind: no recording next to the unusable OBJ directory.
    let mut left: Vec<String> = std::fs::read_dir(&dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["adir", "afile"]);
    std::fs::remove_dir_all(&dir).ok();
}
