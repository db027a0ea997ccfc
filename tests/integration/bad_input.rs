//! Bad input of every kind through the `drape` binary (the table of
//! `docs/errors.md`): each is refused with exit status 1 (2 for a command-line usage
//! error), one `error: ...` line that names the file, the line or `--set` and the
//! key, and never a panic. OBJ files and outputs are in `bad_obj.rs`, command
//! lines in `bad_cli.rs`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A scene with every section, so that every key can be given a bad value by `--set`.
/// Obstacle 3 is a mesh read from `q.obj` next to the scene (see [`scene_dir`]).
pub const FULL: &str = r#"name = "bad"
[simulation]
duration = 0.1
frame_rate = 30
dt = 0.01
[cloth]
shape = "rectangle"
width = 1.0
height = 1.0
resolution = 4
[material]
density = 0.15
stretch = 200.0
bending = 1e-5
damping = 0.001
[[pin]]
region = "corner:top_left"
release_time = 1.0
[air]
drag = 0.02
density = 1.2
[wind]
velocity = [1.0, 0.0, 0.0]
coefficient = 1.0
[adapt]
method = "red_green"
refine_angle = 20.0
coarsen_angle = 5.0
[[obstacle]]
shape = "sphere"
radius = 0.2
position = [0.0, 0.0, -1.0]
friction_static = 0.5
friction_kinetic = 0.3
thickness = 0.01
[[obstacle]]
shape = "box"
half_extents = [0.1, 0.1, 0.1]
position = [2.0, 0.0, -1.0]
[[obstacle]]
shape = "capsule"
radius = 0.1
half_height = 0.2
position = [-2.0, 0.0, -1.0]
[[obstacle]]
shape = "mesh"
path = "q.obj"
scale = 0.1
position = [0.0, 2.0, -1.0]
[self_collision]
thickness = 0.005
patch_size = 0.1
"#;

/// A fresh empty directory in the temp dir, unique per process, test and call.
pub fn temp_dir(name: &str) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("drape-bad-{}-{n}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// A temp dir holding `full.toml` ([`FULL`]) and the OBJ it names.
pub fn scene_dir(name: &str) -> PathBuf {
    let dir = temp_dir(name);
    std::fs::write(dir.join("full.toml"), FULL).expect("write scene");
    let quad = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/quad_2x2_uv.obj");
    std::fs::copy(quad, dir.join("q.obj")).expect("copy OBJ");
    dir
}

/// Runs `drape ARGS` in `dir` and prints what it said.
pub fn drape(dir: &Path, args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_drape"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run drape");
    println!(
        "drape {}: exit {:?}\n{}",
        args.join(" "),
        out.status.code(),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Checks that `out` is a refusal with exit status `code`, no panic, nothing on
/// stdout, and a message containing every one of `needles`; returns the message.
pub fn refused(out: &Output, code: i32, needles: &[&str]) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(code), "{err}");
    assert!(!err.contains("panicked"), "a panic: {err}");
    assert!(!err.contains("RUST_BACKTRACE"), "a panic: {err}");
    assert!(err.starts_with("error: "), "{err}");
    if code == 1 {
        assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    }
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    for n in needles {
        assert!(err.contains(n), "`{n}` missing from: {err}");
    }
    err
}

/// `drape check full.toml --set KEY=VALUE` for each pair: refused, naming the `--set`,
/// the key and `what`.
fn refused_sets(name: &str, cases: &[(&str, &str)], what: &str) {
    let dir = scene_dir(name);
    for (key, value) in cases {
        let set = format!("{key}={value}");
        let out = drape(&dir, &["check", "full.toml", "--set", &set]);
        let key = format!("key `{key}`");
        refused(
            &out,
            1,
            &["error: full.toml", &format!("--set {set}: "), &key, what],
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `drape check full.toml` with each of `sets` alone: accepted.
fn accepted_sets(name: &str, sets: &[&str]) {
    let dir = scene_dir(name);
    for set in sets {
        let out = drape(&dir, &["check", "full.toml", "--set", set]);
        assert_eq!(out.status.code(), Some(0), "{set}: {out:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `drape check full.toml` with all of `sets` at once: accepted.
fn accepted_together(name: &str, sets: &[&str]) {
    let dir = scene_dir(name);
    let mut args = vec!["check", "full.toml"];
    for set in sets {
        args.extend(["--set", set]);
    }
    let out = drape(&dir, &args);
    assert_eq!(out.status.code(), Some(0), "{sets:?}: {out:?}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `drape check full.toml` with `set` and then `other`: refused, naming the
/// file, `set`'s key and `why` (a key valid alone that does not apply to the
/// settings `other` makes).
fn refused_with(name: &str, set: &str, other: &str, why: &str) {
    let dir = scene_dir(name);
    let out = drape(&dir, &["check", "full.toml", "--set", set, "--set", other]);
    let key = set.split('=').next().unwrap_or(set);
    refused(&out, 1, &["error: full.toml", &format!("key `{key}`"), why]);
    std::fs::remove_dir_all(&dir).ok();
}

/// `drape check bad.toml` with `text` as the scene: refused with `needles`.
fn refused_file(text: &[u8], needles: &[&str]) {
    let dir = temp_dir("file");
    std::fs::write(dir.join("bad.toml"), text).expect("write scene");
    let out = drape(&dir, &["check", "bad.toml"]);
    refused(&out, 1, needles);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_full_scene_is_valid() {
    let dir = scene_dir("valid");
    let out = drape(&dir, &["check", "full.toml"]);
    assert_eq!(out.status.code(), Some(0));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn malformed_toml_is_refused_at_its_line() {
    let cases: [(&[u8], &[&str]); 5] = [
        (
            b"name = \"x\"\n[simulation\n",
            &["bad.toml:2: TOML syntax error"],
        ),
        (
            b"name = \"x\nduration = 1\n",
            &["bad.toml:1: TOML syntax error"],
        ),
        (
            b"name = \"x\"\nname = \"y\"\n",
            &["bad.toml:2:", "duplicate key"],
        ),
        (
            b"name = \"x\"\n[cloth]\nwidth = \n",
            &["bad.toml:3: TOML syntax error"],
        ),
        (
            b"name = \"x\"\n\xff\xfe = 1\n",
            &["bad.toml: cannot read the scene file", "UTF-8"],
        ),
    ];
    for (text, needles) in cases {
        refused_file(text, needles);
    }
    // An empty file is valid TOML without the required keys.
    refused_file(b"", &["bad.toml: key `name`: missing required key"]);
}

#[test]
fn unknown_keys_and_sections_are_refused() {
    let edit = |from: &str, to: &str| FULL.replacen(from, to, 1).into_bytes();
    refused_file(
        &edit("[material]\n", "[material]\ncolour = \"red\"\n"),
        &["bad.toml:12: key `material.colour`: unknown key; allowed: "],
    );
    refused_file(
        &edit("name = \"bad\"\n", "name = \"bad\"\ncolour = 1\n"),
        &["bad.toml:2: key `colour`: unknown key"],
    );
    refused_file(
        &edit("[air]\n", "[gravity]\nz = 1\n[air]\n"),
        &["bad.toml:19: key `gravity`: unknown key"],
    );
    refused_sets("unknown", &[("material.colour", "1")], "unknown key");
}

#[test]
fn wrong_types_are_refused() {
    refused_sets(
        "types",
        &[
            ("cloth.resolution", "\"high\""),
            ("cloth.resolution", "1.5"),
            ("simulation.duration", "[1.0]"),
            ("simulation.gravity", "1.0"),
            ("name", "3"),
            ("material.density", "true"),
            ("adapt.rollback", "1"),
            ("simulation", "3"),
        ],
        "wrong type",
    );
}

#[test]
fn an_unknown_fabric_preset_is_refused_with_the_known_names() {
    refused_sets(
        "preset",
        &[("material.preset", "\"satin\"")],
        "no fabric preset is called \"satin\"; allowed: one of \"tango-red-jet-set\"",
    );
}

#[test]
fn zero_and_negative_physical_values_are_refused() {
    // Every physical parameter: > 0 where zero is meaningless, >= 0 otherwise.
    let positive = [
        "simulation.duration",
        "simulation.frame_rate",
        "simulation.dt",
        "cloth.width",
        "cloth.height",
        "material.density",
        "material.stretch",
        "air.density",
        "adapt.refine_angle",
        "adapt.coarsen_angle",
        "obstacle.0.radius",
        "obstacle.0.thickness",
        "obstacle.2.radius",
        "obstacle.2.half_height",
        "obstacle.3.scale",
        "self_collision.thickness",
        "self_collision.patch_size",
    ];
    for value in ["0", "-1"] {
        let cases: Vec<(&str, &str)> = positive.iter().map(|k| (*k, value)).collect();
        refused_sets("positive", &cases, "out of range: must be > 0");
    }
    let non_negative = [
        "material.bending",
        "material.damping",
        "air.drag",
        "wind.coefficient",
        "pin.0.release_time",
        "adapt.min_edge_length",
        "obstacle.0.friction_static",
        "obstacle.0.friction_kinetic",
    ];
    let cases: Vec<(&str, &str)> = non_negative.iter().map(|k| (*k, "-0.5")).collect();
    refused_sets("non-negative", &cases, "out of range: must be >= 0");
    let sizes = [
        ("obstacle.1.half_extents", "[0.1, 0, 0.1]"),
        ("obstacle.1.half_extents", "[0.1, -1, 0.1]"),
    ];
    refused_sets("half-extents", &sizes, "has a size that is not > 0");
    // The keys of other shapes: a disk's radius, an OBJ cloth's uv_scale.
    let disk = FULL.replacen("width = 1.0\nheight = 1.0\n", "radius = 0.0\n", 1);
    let disk = disk.replacen("shape = \"rectangle\"", "shape = \"disk\"", 1);
    let disk = disk.replacen("corner:top_left", "all", 1);
    refused_file(
        disk.as_bytes(),
        &["bad.toml:8: key `cloth.radius`: 0 is out of range"],
    );
}

#[test]
fn non_finite_numbers_are_refused() {
    for value in ["nan", "inf", "-inf"] {
        let cases = [
            ("simulation.duration", value),
            ("material.stretch", value),
            ("material.bending", value),
            ("cloth.width", value),
            ("pin.0.release_time", value),
            ("obstacle.0.angular_velocity", value),
        ];
        refused_sets("non-finite", &cases, "is not a finite number");
        let arrays = [
            ("simulation.gravity", format!("[0, 0, {value}]")),
            ("cloth.position", format!("[{value}, 0, 0]")),
            ("wind.velocity", format!("[0, {value}, 0]")),
        ];
        let arrays: Vec<(&str, &str)> = arrays.iter().map(|(k, v)| (*k, v.as_str())).collect();
        refused_sets("non-finite-array", &arrays, "is not a finite number");
    }
}

#[test]
fn a_lower_threshold_above_the_upper_is_refused() {
    refused_sets(
        "thresholds",
        &[("adapt.coarsen_angle", "30"), ("adapt.coarsen_angle", "20")],
        "the lower threshold",
    );
    refused_sets(
        "friction",
        &[("obstacle.0.friction_kinetic", "0.9")],
        "kinetic friction cannot exceed static friction",
    );
    refused_sets("dt", &[("simulation.dt", "0.1")], "longer than one frame");
    refused_sets("angle", &[("adapt.refine_angle", "180")], "must be < 180");
    // The sizing criterion (the default) merges by hysteresis, which must exceed 1.
    refused_sets(
        "hysteresis",
        &[("adapt.hysteresis", "1"), ("adapt.hysteresis", "0.5")],
        "must be > 1",
    );
}

#[test]
fn refine_strain_needs_the_sizing_rule_on_red_green_and_a_positive_value() {
    // With the full scene's red_green and the default sizing rule it is valid;
    // 0 is "off" and valid with any method, so that one `--set` undoes it.
    accepted_sets("strain", &["adapt.refine_strain=0.01"]);
    accepted_together(
        "strain-off",
        &["adapt.refine_strain=0", "adapt.method=\"edge\""],
    );
    for other in ["adapt.criterion=\"angle\"", "adapt.method=\"edge\""] {
        refused_with(
            "strain",
            "adapt.refine_strain=0.01",
            other,
            "refine_strain belongs to criterion = \"sizing\" with method = \"red_green\"",
        );
    }
    refused_sets(
        "strain-range",
        &[("adapt.refine_strain", "-0.1")],
        "must be > 0 (or 0: off)",
    );
}

/// `cloth.diagonals = "alternating_flipped"` (every square's diagonal
/// turned, for `drape bench --pattern-floor`) is a rectangle's pattern like
/// the others, and refused with the tensor method, which keeps a regular or
/// alternating grid as it inserts lines.
#[test]
fn flipped_diagonals_are_a_pattern_but_not_for_the_tensor_method() {
    accepted_sets("flipped", &["cloth.diagonals=\"alternating_flipped\""]);
    refused_with(
        "flipped-tensor",
        "cloth.diagonals=\"alternating_flipped\"",
        "adapt.method=\"tensor\"",
        "the tensor method keeps a regular or alternating grid",
    );
}

/// `refine_obstacle` (`src/adapt/proximity.rs`) is the sizing rule's obstacle
/// term on red-green, and a positive fraction.
#[test]
fn refine_obstacle_needs_the_sizing_rule_on_red_green_and_a_positive_value() {
    accepted_sets("obstacle", &["adapt.refine_obstacle=1.0"]);
    accepted_together(
        "obstacle-off",
        &["adapt.refine_obstacle=0", "adapt.criterion=\"angle\""],
    );
    for other in ["adapt.criterion=\"angle\"", "adapt.method=\"edge\""] {
        refused_with(
            "obstacle",
            "adapt.refine_obstacle=1.0",
            other,
            "refine_obstacle belongs to criterion = \"sizing\" with method = \"red_green\"",
        );
    }
    refused_sets(
        "obstacle-range",
        &[("adapt.refine_obstacle", "-1")],
        "must be > 0 (or 0: off)",
    );
}

/// Regression: `refine_obstacle` on a scene without obstacles was accepted
/// and did nothing (the sizing rule had no plane to lean towards).
#[test]
fn refine_obstacle_without_an_obstacle_is_refused() {
    let dir = temp_dir("obstacle-none");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hanging_sheet.toml");
    let scene = scene.to_str().expect("a UTF-8 path");
    let out = drape(
        &dir,
        &["check", scene, "--set", "adapt.refine_obstacle=1.0"],
    );
    refused(
        &out,
        1,
        &[
            "hanging_sheet.toml",
            "key `adapt.refine_obstacle`",
            "this scene has no [[obstacle]]",
        ],
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The tensor method (`src/adapt/tensor.rs`) refines a rectangle's grid,
/// with an even `max_level`, and without rollback, multirate stepping or
/// level-scaled stiffness.
#[test]
fn the_tensor_method_refuses_what_it_cannot_do() {
    accepted_sets("tensor", &["adapt.method=\"tensor\""]);
    for (set, why) in [
        (
            "adapt.rollback=true",
            "rollback is paper A's and works with method = \"red_green\" only",
        ),
        (
            "adapt.multirate=true",
            "multirate stepping works on the levels of method = \"red_green\" or \"edge\", not \"tensor\"",
        ),
        (
            "adapt.max_level=5",
            "5 is odd: with method = \"tensor\" each halving of a column or row adds 2",
        ),
        (
            "material.stiffness_rule=\"paper_a\"",
            "stiffness_rule = \"paper_a\" scales springs by red-green's levels",
        ),
    ] {
        refused_with("tensor", set, "adapt.method=\"tensor\"", why);
    }
    refused_file(
        b"name = \"t\"\n[simulation]\nduration = 0.1\n[cloth]\nshape = \"disk\"\nradius = 0.5\nresolution = 8\n[material]\ndensity = 0.15\nstretch = 200.0\n[adapt]\nmethod = \"tensor\"\n",
        &[
            "bad.toml:12: key `adapt.method`",
            "needs cloth.shape = \"rectangle\"",
        ],
    );
}

#[test]
fn red_green_diagonals_are_named_and_belong_to_red_green() {
    accepted_sets(
        "diagonals",
        &[
            "adapt.diagonals=\"alternating\"",
            "adapt.diagonals=\"as_split\"",
        ],
    );
    refused_with(
        "diagonals",
        "adapt.diagonals=\"as_split\"",
        "adapt.method=\"edge\"",
        "diagonals belongs to method = \"red_green\"",
    );
    refused_sets(
        "diagonals-name",
        &[("adapt.diagonals", "\"regular\""), ("adapt.diagonals", "1")],
        "\"alternating\" or \"as_split\"",
    );
}

#[test]
fn adapt_every_is_a_step_count_or_frame() {
    refused_sets(
        "every",
        &[
            ("adapt.every", "0"),
            ("adapt.every", "-3"),
            ("adapt.every", "\"often\""),
            ("adapt.every", "2.5"),
        ],
        "an integer >= 1 (steps) or \"frame\"",
    );
}

#[test]
fn resolution_zero_or_above_the_cap_is_refused() {
    refused_sets(
        "res-zero",
        &[("cloth.resolution", "0")],
        "0 is out of range: must be >= 1",
    );
    refused_sets(
        "res-negative",
        &[("cloth.resolution", "-3")],
        "out of range",
    );
    // Used to abort on a failed allocation (`memory allocation failed`, SIGABRT).
    let cap = drape::scene::MAX_RESOLUTION;
    let above = (cap + 1).to_string();
    for value in [above.as_str(), "100000", "4294967295", "4294967296"] {
        refused_sets("res-huge", &[("cloth.resolution", value)], "out of range");
    }
    refused_sets(
        "res-cap",
        &[("cloth.resolution", "100000")],
        &format!("must be <= {cap}"),
    );
}

#[test]
fn counts_no_run_can_reach_are_refused() {
    // Used to be accepted: a run that could never finish (and frame counts beyond u64).
    refused_sets(
        "duration",
        &[("simulation.duration", "1e300")],
        "more than any run can count",
    );
    refused_sets(
        "dt",
        &[("simulation.dt", "1e-300")],
        "more than any run can count",
    );
}

#[test]
fn bad_pins_are_refused() {
    refused_sets(
        "region",
        &[("pin.0.region", "corner:middle")],
        "is not a pin region",
    );
    refused_sets(
        "axis",
        &[("pin.0.axis", "[0, 0, 1]")],
        "does not apply to motion",
    );
    let dir = scene_dir("pin-empty");
    // The file's line of the pin, the --set that made box_min required, and the key.
    let out = drape(&dir, &["check", "full.toml", "--set", "pin.0.region=box"]);
    let needles =
        ["full.toml:16: --set pin.0.region=box: key `pin.0.box_min`: missing required key"];
    refused(&out, 1, &needles);
    let args = ["check", "full.toml", "--set", "pin.0.region=box"];
    let args = [
        &args[..],
        &[
            "--set",
            "pin.0.box_min=[5, 5]",
            "--set",
            "pin.0.box_max=[6, 6]",
        ],
    ]
    .concat();
    refused(
        &drape(&dir, &args),
        1,
        &["pin 0: region `box` contains no vertex of the cloth"],
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A measurement the scene asks for that its built cloth cannot give is refused
/// before the run starts, with the reason: the cantilever clamped in the middle
/// of the strip, the Cusick support moved from under the specimen.
#[test]
fn a_measurement_the_built_cloth_cannot_give_stops_the_run_before_it_starts() {
    let cases = [
        (
            "scenes/cantilever.toml",
            ["pin.0.box_min=[-0.01,-0.02]", "pin.0.box_max=[0.01,0.02]"],
            "the cantilever measurement needs the pins to hold exactly the vertices at one end",
        ),
        (
            "scenes/cusick.toml",
            [
                "obstacle.0.position=[0.3,0.0,0.0]",
                "simulation.duration=0.05",
            ],
            "the cusick measurement needs the disk specimen to lie centred on a vertical cylinder",
        ),
    ];
    for (file, sets, needle) in cases {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let scene = drape::scene::load_scene_file(std::path::Path::new(file), &sets)
            .expect("the scene alone allows it");
        let e = drape::run::run(
            &scene,
            &drape::run::RunOptions::default(),
            &std::sync::atomic::AtomicBool::new(false),
            &mut |_| {},
        )
        .expect_err("refused");
        assert!(
            matches!(e, drape::run::RunError::Measurement { .. }),
            "{file}: {e}"
        );
        assert!(e.to_string().contains(needle), "{file}: {e}");
    }
}
