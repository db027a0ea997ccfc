//! `drape stability` end to end: the built-in hard cases run from any
//! directory, `--suite DIR` runs a folder of scenes instead, and a bad case
//! name, a missing or empty folder or a bad scene is an error that says so.

use std::path::Path;

use drape::stability::CASES;

use crate::bad_input::temp_dir;
use crate::cli::drape;

/// A small sheet hanging from its top edge for 0.1 s, without adaptivity.
const TINY: &str = "name = \"tiny\"\n\
    [simulation]\n\
    duration = 0.1\n\
    [cloth]\n\
    shape = \"rectangle\"\n\
    width = 0.5\n\
    height = 0.5\n\
    resolution = 4\n\
    [material]\n\
    density = 0.15\n\
    stretch = 200.0\n\
    [[pin]]\n\
    region = \"edge:top\"\n";

#[test]
fn stability_runs_its_built_in_scenes_from_any_directory() {
    // The sliver case also reads its OBJ mesh, which is built in too.
    let cwd = temp_dir("stability-anywhere");
    let out = drape(
        &["stability", "--quick", "--case", "sliver", "--threads", "2"],
        &cwd,
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0));
    assert!(stdout.contains("| case | integrator | adaptive |"));
    assert!(stdout.contains("| sliver | implicit | on |"));
    assert!(stdout.contains("| sliver | implicit | off |"));
    assert!(stdout.contains("2 runs, 2 passed, 0 failed"));
    let left: Vec<_> = std::fs::read_dir(&cwd).expect("cwd").collect();
    assert!(
        left.is_empty(),
        "the suite wrote into the working directory"
    );
}

#[test]
fn an_unknown_case_is_an_error_listing_every_built_in_case() {
    let out = drape(
        &["stability", "--case", "nosuch"],
        &temp_dir("stability-nosuch"),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("no hard case named `nosuch`"));
    let names: Vec<&str> = CASES.iter().map(|c| c.name).collect();
    assert!(stderr.contains(&names.join(", ")), "{stderr}");
}

#[test]
fn built_in_cases_are_the_scene_files_of_scenes_hard() {
    let hard = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hard");
    let mut on_disk: Vec<String> = std::fs::read_dir(&hard)
        .expect("scenes/hard")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| p.file_stem().expect("stem").to_string_lossy().into_owned())
        .collect();
    on_disk.sort();
    let mut built_in: Vec<String> = CASES.iter().map(|c| c.name.to_string()).collect();
    built_in.sort();
    assert_eq!(on_disk, built_in);
    for case in CASES {
        let text = std::fs::read_to_string(hard.join(format!("{}.toml", case.name)));
        assert_eq!(text.expect("scene"), case.toml, "{}", case.name);
        for (name, body) in case.files {
            let file = std::fs::read_to_string(hard.join(name)).expect("file");
            assert_eq!(&file, body, "{name}");
        }
    }
}

#[test]
fn stability_suite_runs_every_scene_of_a_folder() {
    let dir = temp_dir("stability-suite");
    std::fs::write(dir.join("tiny.toml"), TINY).expect("write scene");
    std::fs::write(dir.join("notes.txt"), "not a scene").expect("write notes");
    let suite = dir.to_str().expect("utf-8 temp path");
    let out = drape(
        &["stability", "--suite", suite, "--quick", "--threads", "2"],
        &temp_dir("stability-suite-cwd"),
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0));
    // No [adapt]: each integrator once, adaptivity off.
    for integrator in ["symplectic_euler", "rk4", "implicit"] {
        assert!(stdout.contains(&format!("| tiny | {integrator} | off |")));
    }
    assert!(!stdout.contains("| on |"));
    assert!(stdout.contains("3 runs, 3 passed, 0 failed"));
}

#[test]
fn stability_suite_of_a_missing_or_empty_folder_is_an_error() {
    let cwd = temp_dir("stability-bad-suite");
    let missing = cwd.join("nowhere");
    let out = drape(
        &["stability", "--suite", missing.to_str().expect("utf-8")],
        &cwd,
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("cannot read the suite folder"), "{stderr}");
    assert!(stderr.contains("nowhere"), "{stderr}");

    let empty = temp_dir("stability-empty-suite");
    let out = drape(
        &["stability", "--suite", empty.to_str().expect("utf-8")],
        &cwd,
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("holds no scene file (*.toml)"), "{stderr}");
}

#[test]
fn a_bad_scene_in_a_suite_folder_is_named_with_its_line_before_any_run() {
    let dir = temp_dir("stability-bad-scene");
    std::fs::write(dir.join("tiny.toml"), TINY).expect("write scene");
    let bad = TINY.replace("stretch = 200.0", "stretch = -1.0");
    std::fs::write(dir.join("zbad.toml"), bad).expect("write scene");
    let out = drape(
        &["stability", "--suite", dir.to_str().expect("utf-8")],
        &dir,
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("zbad.toml:11:"), "{stderr}");
    assert!(stderr.contains("material.stretch"), "{stderr}");
    assert!(!stderr.contains("[1/"), "a run started: {stderr}");
}
