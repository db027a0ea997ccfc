//! A garment's phases: it sews weightless while a seam is open
//! (`cloth.sewing.weightless`), and a run with `simulation.rest` ends at the
//! frame it comes to rest, recorded in the summary.

use serde_json::Value;

use crate::bad_input::{drape, temp_dir};
use crate::garments::TWO_SQUARES;

/// The lowest z of the cloth at frame 3 (0.1 s) of a run of `text`.
fn lowest_at_frame_3(name: &str, text: &str) -> f64 {
    let dir = temp_dir(name);
    std::fs::write(dir.join("g.toml"), text).expect("write scene");
    let args = [
        "run",
        "g.toml",
        "--no-record",
        "-q",
        "--obj-dir",
        "frames",
        "--set",
        "simulation.duration=0.1",
    ];
    assert_eq!(drape(&dir, &args).status.code(), Some(0));
    let obj = std::fs::read_to_string(dir.join("frames/frame_00003.obj")).expect("frame 3");
    std::fs::remove_dir_all(&dir).ok();
    obj.lines()
        .filter_map(|l| l.strip_prefix("v "))
        .filter_map(|l| l.split_whitespace().nth(2)?.parse::<f64>().ok())
        .fold(f64::MAX, f64::min)
}

#[test]
fn a_garment_sewing_weightless_does_not_fall_until_its_seams_are_welded() {
    // Two squares 4 cm apart sewn at a weak pull: the seam stays open for
    // longer than the 0.1 s watched.
    let text = TWO_SQUARES
        .replace("position = [0.02, 0.0, 0.0]", "position = [0.04, 0.0, 0.0]")
        .replace("gravity = [0.0, 0.0, 0.0]", "gravity = [0.0, 0.0, -9.81]")
        .replace(
            "max_edge = 0.025",
            "max_edge = 0.025\n[cloth.sewing]\nstiffness = 5.0",
        );
    let weightless = text.replace("stiffness = 5.0", "stiffness = 5.0\nweightless = 1.0");
    let falls = lowest_at_frame_3("falls", &text);
    let floats = lowest_at_frame_3("floats", &weightless);
    println!("lowest z after 0.1 s: {falls:.4} m with gravity, {floats:.4} m weightless");
    // Free fall for 0.1 s drops 49 mm.
    assert!(
        falls < -0.04,
        "with gravity the squares fell only to {falls}"
    );
    assert!(
        floats.abs() < 1e-6,
        "weightless the squares fell to {floats}"
    );
}

/// A 0.4 m sheet dropped 5 cm onto a box, with the scene's `rest` table.
const SHEET_ON_BOX: &str = r#"
name = "rest"
[simulation]
duration = 6.0
rest = { speed = 0.01, window = 0.3 }
[cloth]
shape = "rectangle"
width = 0.4
height = 0.4
resolution = 8
position = [0.0, 0.0, 0.35]
[material]
density = 0.2
stretch = 300.0
bending = 1.0e-4
damping = 0.01
[[obstacle]]
shape = "box"
half_extents = [0.5, 0.5, 0.15]
position = [0.0, 0.0, 0.15]
friction_static = 0.8
"#;

fn run_summary(name: &str, text: &str) -> Value {
    let dir = temp_dir(name);
    std::fs::write(dir.join("rest.toml"), text).expect("write scene");
    let out = drape(
        &dir,
        &[
            "run",
            "rest.toml",
            "--no-record",
            "-q",
            "--summary",
            "s.json",
        ],
    );
    assert_eq!(out.status.code(), Some(0));
    let summary = std::fs::read_to_string(dir.join("s.json")).expect("summary");
    std::fs::remove_dir_all(&dir).ok();
    serde_json::from_str(&summary).expect("json")
}

#[test]
fn a_run_with_a_rest_criterion_ends_at_the_frame_it_comes_to_rest() {
    let s = run_summary("rest", SHEET_ON_BOX);
    let rest = &s["rest"];
    println!("{rest}, sim_time {}", s["sim_time"]);
    assert_eq!(rest["at_rest"], Value::Bool(true));
    let time = rest["time"].as_f64().expect("a rest time");
    assert!(time < 5.0, "came to rest only at {time} s");
    assert!((s["sim_time"].as_f64().expect("sim_time") - time).abs() < 1e-9);
    assert!(rest["speed"].as_f64().expect("speed") <= 0.01);
}

#[test]
fn a_run_that_does_not_come_to_rest_runs_its_duration_and_says_so() {
    let text = SHEET_ON_BOX
        .replace("duration = 6.0", "duration = 0.2")
        .replace("speed = 0.01", "speed = 1e-6");
    let s = run_summary("no-rest", &text);
    assert_eq!(s["rest"]["at_rest"], Value::Bool(false));
    assert_eq!(s["rest"]["time"], Value::Null);
    assert!((s["sim_time"].as_f64().expect("sim_time") - 0.2).abs() < 1e-9);
}
