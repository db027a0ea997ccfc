//! Scene errors name the file, the line and the key.

use drape::scene::{
    ClothShape, Integrator, SceneError, SceneErrorKind as Kind, TimeStep, default_scene,
    load_scene_file, load_scene_str,
};

/// A valid scene; line numbers are asserted below.
const BASE: &str = r#"name = "t"
[simulation]
duration = 1.0
[cloth]
shape = "rectangle"
width = 1.0
height = 1.0
resolution = 4
[material]
density = 0.15
stretch = 200.0
[[pin]]
region = "corner:top_left"
[[pin]]
region = "corner:top_right"
"#;

/// `BASE` with `from` replaced by `to` (which must occur).
fn edit(from: &str, to: &str) -> String {
    assert!(BASE.contains(from), "test bug: {from:?} not in BASE");
    BASE.replacen(from, to, 1)
}

fn sets(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| (*s).to_owned()).collect()
}

/// The error for `text`, checked to name the file, `line` and `key` in its message.
fn error_at(text: &str, line: usize, key: &str, kind: Kind) -> SceneError {
    let e = match load_scene_str(text, "test.toml", &[]) {
        Ok(_) => panic!("expected an error at {key}"),
        Err(e) => e,
    };
    let msg = e.to_string();
    assert_eq!(e.kind, kind, "{msg}");
    assert_eq!(e.line, Some(line), "{msg}");
    assert_eq!(e.key.as_deref(), Some(key), "{msg}");
    assert!(
        msg.starts_with(&format!("test.toml:{line}: key `{key}`: ")),
        "{msg}"
    );
    e
}

/// The error for `BASE` with `args` as `--set`, checked to name the file, the
/// `--set` and the key, with no line.
fn set_error(args: &[&str], key: &str, kind: Kind) -> SceneError {
    let e = match load_scene_str(BASE, "test.toml", &sets(args)) {
        Ok(_) => panic!("expected an error at {key}"),
        Err(e) => e,
    };
    let msg = e.to_string();
    assert_eq!(e.kind, kind, "{msg}");
    assert_eq!(e.line, None, "{msg}");
    assert_eq!(e.key.as_deref(), Some(key), "{msg}");
    assert!(msg.starts_with("test.toml: --set "), "{msg}");
    assert!(msg.contains(&format!("key `{key}`")), "{msg}");
    e
}

#[test]
fn base_scene_is_valid() {
    let s = load_scene_str(BASE, "test.toml", &[]).expect("BASE is valid");
    assert_eq!(s.cloth.shape, ClothShape::Rectangle);
    assert_eq!(s.pin.len(), 2);
    assert_eq!(s.simulation.dt, TimeStep::Auto);
}

#[test]
fn malformed_toml_names_file_and_line() {
    let e = load_scene_str(
        &edit("density = 0.15", "density = = 0.15"),
        "test.toml",
        &[],
    )
    .expect_err("syntax error");
    assert_eq!(e.kind, Kind::Syntax);
    assert_eq!(e.line, Some(10), "{e}");
    assert!(
        e.to_string().starts_with("test.toml:10: TOML syntax error"),
        "{e}"
    );
    let e = load_scene_str(&edit("[material]", "[material"), "test.toml", &[]).expect_err("syntax");
    assert_eq!(e.line, Some(9), "{e}");
}

#[test]
fn unknown_key_lists_allowed_keys() {
    let e = error_at(
        &edit("resolution = 4\n", "resolution = 4\ncolour = \"red\"\n"),
        9,
        "cloth.colour",
        Kind::UnknownKey,
    );
    let msg = e.to_string();
    assert!(
        msg.contains("unknown key") && msg.contains("`width`") && msg.contains("`diagonals`"),
        "{msg}"
    );
    error_at(
        &edit("duration = 1.0", "duration = 1.0\nspeed = 2"),
        4,
        "simulation.speed",
        Kind::UnknownKey,
    );
    error_at(
        &format!("{BASE}[weather]\nrain = true\n"),
        16,
        "weather",
        Kind::UnknownKey,
    );
    let e = error_at(
        &format!("{BASE}colour = 1\n"),
        16,
        "pin.1.colour",
        Kind::UnknownKey,
    );
    assert!(e.to_string().contains("`release_time`"), "{e}");
}

#[test]
fn wrong_type_names_key_and_expectation() {
    let e = error_at(
        &edit("resolution = 4", "resolution = \"high\""),
        8,
        "cloth.resolution",
        Kind::WrongType,
    );
    assert!(e.to_string().contains("an integer from 1 to 2048"), "{e}");
    error_at(
        &edit("width = 1.0", "width = [1.0]"),
        6,
        "cloth.width",
        Kind::WrongType,
    );
    error_at(
        &edit("duration = 1.0", "duration = 1.0\ngravity = [0.0, -9.8]"),
        4,
        "simulation.gravity",
        Kind::WrongType,
    );
    error_at(
        &edit(
            "duration = 1.0",
            "duration = 1.0\ngravity = [0.0, 0.0, \"down\"]",
        ),
        4,
        "simulation.gravity",
        Kind::WrongType,
    );
}

#[test]
fn bad_enum_value_lists_allowed_values() {
    let e = error_at(
        &edit("duration = 1.0", "duration = 1.0\nintegrator = \"verlet\""),
        4,
        "simulation.integrator",
        Kind::BadValue,
    );
    let msg = e.to_string();
    assert!(
        msg.contains("verlet") && msg.contains("\"symplectic_euler\", \"rk4\" or \"implicit\""),
        "{msg}"
    );
    error_at(
        &edit("\"rectangle\"", "\"square\""),
        5,
        "cloth.shape",
        Kind::BadValue,
    );
    error_at(
        &edit("duration = 1.0", "duration = 1.0\ndt = \"fast\""),
        4,
        "simulation.dt",
        Kind::BadValue,
    );
    error_at(
        &edit(
            "stretch = 200.0",
            "stretch = 200.0\nbending_model = \"beam\"",
        ),
        12,
        "material.bending_model",
        Kind::BadValue,
    );
    error_at(
        &edit(
            "\"corner:top_right\"",
            "\"corner:top_right\"\nmotion = \"spin\"",
        ),
        16,
        "pin.1.motion",
        Kind::BadValue,
    );
}

#[test]
fn missing_required_key_points_at_its_section() {
    let e = error_at(
        &edit("density = 0.15\n", ""),
        9,
        "material.density",
        Kind::MissingKey,
    );
    assert!(e.to_string().contains("missing required key"), "{e}");
    error_at(
        &edit("duration = 1.0\n", ""),
        2,
        "simulation.duration",
        Kind::MissingKey,
    );
    error_at(
        &edit("region = \"corner:top_right\"\n", "motion = \"fixed\"\n"),
        14,
        "pin.1.region",
        Kind::MissingKey,
    );
    let e = load_scene_str(&edit("name = \"t\"\n", ""), "test.toml", &[]).expect_err("no name");
    assert_eq!(
        (e.kind, e.line, e.key.as_deref()),
        (Kind::MissingKey, None, Some("name")),
        "{e}"
    );
}

#[test]
fn out_of_range_values_are_errors() {
    let cases: &[(&str, &str, usize, &str)] = &[
        (
            "duration = 1.0",
            "duration = -1.0",
            3,
            "simulation.duration",
        ),
        ("duration = 1.0", "duration = inf", 3, "simulation.duration"),
        (
            "duration = 1.0",
            "duration = 1.0\nframe_rate = 0",
            4,
            "simulation.frame_rate",
        ),
        (
            "duration = 1.0",
            "duration = 1.0\ndt = 0.0",
            4,
            "simulation.dt",
        ),
        (
            "duration = 1.0",
            "duration = 1.0\ndt = 0.1",
            4,
            "simulation.dt",
        ),
        (
            "duration = 1.0",
            "duration = 1.0\ngravity = [0, 0, nan]",
            4,
            "simulation.gravity",
        ),
        (
            "duration = 1.0",
            "duration = 1.0\ncg_tolerance = 1.0",
            4,
            "simulation.cg_tolerance",
        ),
        (
            "duration = 1.0",
            "duration = 1.0\ncg_tolerance = 0.0",
            4,
            "simulation.cg_tolerance",
        ),
        (
            "duration = 1.0",
            "duration = 1.0\ncg_max_iterations = 0",
            4,
            "simulation.cg_max_iterations",
        ),
        ("width = 1.0", "width = 0.0", 6, "cloth.width"),
        ("resolution = 4", "resolution = 0", 8, "cloth.resolution"),
        (
            "resolution = 4",
            "resolution = 4\nposition = [0, -inf, 0]",
            9,
            "cloth.position",
        ),
        ("density = 0.15", "density = 0.0", 10, "material.density"),
        (
            "stretch = 200.0",
            "stretch = -200.0",
            11,
            "material.stretch",
        ),
        (
            "stretch = 200.0",
            "stretch = 200.0\nbending = -1e-5",
            12,
            "material.bending",
        ),
        (
            "stretch = 200.0",
            "stretch = 200.0\ndamping = -0.1",
            12,
            "material.damping",
        ),
        (
            "name = \"t\"",
            "name = \"t\"\n[air]\ndrag = -0.5",
            3,
            "air.drag",
        ),
        (
            "name = \"t\"",
            "name = \"t\"\n[air]\ndrag = 0.5\ndensity = 0",
            4,
            "air.density",
        ),
        (
            "name = \"t\"",
            "name = \"t\"\n[wind]\nvelocity = [1, 0, 0]\ncoefficient = -1",
            4,
            "wind.coefficient",
        ),
    ];
    for (from, to, line, key) in cases {
        let e = error_at(&edit(from, to), *line, key, Kind::OutOfRange);
        assert!(e.to_string().contains("; allowed: "), "{e}");
    }
    let e = error_at(
        &edit("duration = 1.0", "duration = 1.0\ndt = 0.1"),
        4,
        "simulation.dt",
        Kind::OutOfRange,
    );
    assert!(e.to_string().contains("frame_rate"), "{e}");
    // The largest resolution is accepted; above it is an error, not an aborted
    // allocation (resolution 100000 used to abort the process).
    let max = drape::scene::MAX_RESOLUTION;
    load_scene_str(
        &edit("resolution = 4", &format!("resolution = {max}")),
        "t",
        &[],
    )
    .expect("the cap itself is allowed");
    let e = error_at(
        &edit("resolution = 4", "resolution = 100000"),
        8,
        "cloth.resolution",
        Kind::OutOfRange,
    );
    assert!(e.to_string().contains(&format!("must be <= {max}")), "{e}");
}

#[test]
fn shape_keys_must_match_the_shape() {
    let e = error_at(
        &edit("resolution = 4", "resolution = 4\nradius = 0.5"),
        9,
        "cloth.radius",
        Kind::NotApplicable,
    );
    assert!(
        e.to_string()
            .contains("does not apply to shape = \"rectangle\""),
        "{e}"
    );
    error_at(
        &edit("resolution = 4", "resolution = 4\nuv_scale = 2.0"),
        9,
        "cloth.uv_scale",
        Kind::NotApplicable,
    );
    error_at(
        &edit("height = 1.0\n", ""),
        4,
        "cloth.height",
        Kind::MissingKey,
    );
    error_at(
        &edit("resolution = 4", "resolution = 4\nshort_side_segments = 0"),
        9,
        "cloth.short_side_segments",
        Kind::OutOfRange,
    );
    error_at(
        &edit(
            "resolution = 4",
            "resolution = 4\nshort_side_segments = 4096",
        ),
        9,
        "cloth.short_side_segments",
        Kind::OutOfRange,
    );
    let two = load_scene_str(
        &edit("resolution = 4", "resolution = 4\nshort_side_segments = 2"),
        "t",
        &[],
    )
    .expect("short_side_segments on a rectangle");
    assert_eq!(two.cloth.short_side_segments, Some(2));
    let disk = "shape = \"disk\"\nradius = 0.5\nresolution = 4\n";
    let rect = "shape = \"rectangle\"\nwidth = 1.0\nheight = 1.0\nresolution = 4\n";
    let pins = "[[pin]]\nregion = \"corner:top_left\"\n[[pin]]\nregion = \"corner:top_right\"\n";
    let disk_scene = BASE
        .replacen(rect, disk, 1)
        .replacen(pins, "[[pin]]\nregion = \"all\"\n", 1);
    load_scene_str(&disk_scene, "t", &[]).expect("disk scene is valid");
    let e = load_scene_str(
        &disk_scene.replacen("radius = 0.5\n", "", 1),
        "test.toml",
        &[],
    )
    .expect_err("disk without radius");
    assert_eq!(
        (e.kind, e.line, e.key.as_deref()),
        (Kind::MissingKey, Some(4), Some("cloth.radius")),
        "{e}"
    );
    // Rectangle-only keys on a disk.
    for (line, key) in [
        ("short_side_segments = 2", "cloth.short_side_segments"),
        ("width = 1.0", "cloth.width"),
    ] {
        let e = load_scene_str(
            &disk_scene.replacen("radius = 0.5", &format!("radius = 0.5\n{line}"), 1),
            "test.toml",
            &[],
        )
        .expect_err(line);
        assert_eq!(
            (e.kind, e.line, e.key.as_deref()),
            (Kind::NotApplicable, Some(7), Some(key)),
            "{e}"
        );
    }
    let obj_scene = BASE.replacen(rect, "shape = \"obj\"\n", 1);
    let e = load_scene_str(&obj_scene, "test.toml", &[]).expect_err("obj without path");
    assert_eq!(
        (e.kind, e.key.as_deref()),
        (Kind::MissingKey, Some("cloth.path")),
        "{e}"
    );
}

#[test]
fn pin_errors() {
    let region = |r: &str| edit("\"corner:top_right\"", r);
    let e = error_at(
        &region("\"corner:middle\""),
        15,
        "pin.1.region",
        Kind::BadValue,
    );
    assert!(
        e.to_string().contains("edge:left") && e.to_string().contains("\"all\""),
        "{e}"
    );
    error_at(
        &region("\"box\"\nbox_max = [0.1, 0.1]"),
        14,
        "pin.1.box_min",
        Kind::MissingKey,
    );
    error_at(
        &region("\"box\"\nbox_min = [0.1, 0.0]\nbox_max = [0.2, 0.0]"),
        17,
        "pin.1.box_max",
        Kind::OutOfRange,
    );
    load_scene_str(
        &region("\"box\"\nbox_min = [0.1, 0.0]\nbox_max = [0.2, 0.1]"),
        "t",
        &[],
    )
    .expect("valid box");
    error_at(
        &region("\"all\"\nbox_min = [0.1, 0.0]"),
        16,
        "pin.1.box_min",
        Kind::NotApplicable,
    );
    error_at(
        &region("\"all\"\nmotion = \"circular\"\naxis = [0, 0, 0]"),
        17,
        "pin.1.axis",
        Kind::OutOfRange,
    );
    error_at(
        &region("\"all\"\nvelocity = [1, 0, 0]"),
        16,
        "pin.1.velocity",
        Kind::NotApplicable,
    );
    error_at(
        &region("\"all\"\nrelease_time = -1.0"),
        16,
        "pin.1.release_time",
        Kind::OutOfRange,
    );
    let disk = BASE
        .replacen("width = 1.0\nheight = 1.0", "radius = 0.5", 1)
        .replacen("\"rectangle\"", "\"disk\"", 1);
    let e = load_scene_str(&disk, "test.toml", &[]).expect_err("corner on a disk");
    assert_eq!(
        (e.kind, e.line, e.key.as_deref()),
        (Kind::BadValue, Some(12), Some("pin.0.region")),
        "{e}"
    );
}

#[test]
fn planned_adapt_options_are_reported_honestly() {
    let section = "[adapt]\nmethod = \"red_green\"\nmultirate = true\n";
    let e = error_at(
        &format!("{BASE}{section}"),
        18,
        "adapt.multirate",
        Kind::Unsupported,
    );
    assert!(e.to_string().contains("multirate"), "{e}");
    // The implemented methods load.
    load_scene_str(
        &format!("{BASE}[adapt]\nmethod = \"edge\"\n"),
        "test.toml",
        &[],
    )
    .expect("edge");
    load_scene_str(
        &format!("{BASE}[adapt]\nmethod = \"red_green\"\n"),
        "test.toml",
        &[],
    )
    .expect("red_green");
}

#[test]
fn overrides_apply_before_validation() {
    let s = load_scene_str(
        BASE,
        "t",
        &sets(&[
            "cloth.resolution=64",
            "simulation.integrator=rk4",
            "simulation.gravity=[0,0,-1]",
            "simulation.dt=0.001",
            "pin.0.region=corner:bottom_left",
            "wind.velocity=[3,0,0]",
        ]),
    )
    .expect("valid overrides");
    assert_eq!(s.cloth.resolution, Some(64));
    assert_eq!(s.simulation.integrator, Integrator::Rk4);
    assert_eq!(s.simulation.gravity, [0.0, 0.0, -1.0]);
    assert_eq!(s.simulation.dt, TimeStep::Fixed(0.001));
    assert_eq!(s.pin[0].region, "corner:bottom_left");
    assert_eq!(s.wind.as_ref().map(|w| w.velocity), Some([3.0, 0.0, 0.0]));
}

#[test]
fn override_errors_name_the_set() {
    let e = set_error(
        &["cloth.resolution=0"],
        "cloth.resolution",
        Kind::OutOfRange,
    );
    assert!(e.to_string().contains("--set cloth.resolution=0"), "{e}");
    set_error(&["cloth.colour=red"], "cloth.colour", Kind::UnknownKey);
    set_error(
        &["simulation.integrator=verlet"],
        "simulation.integrator",
        Kind::BadValue,
    );
    set_error(
        &["cloth.resolution=high"],
        "cloth.resolution",
        Kind::WrongType,
    );
    set_error(&["wind.coefficient=2"], "wind.velocity", Kind::MissingKey);
    // A requirement introduced by a --set: the file's line and the --set.
    let e = load_scene_str(BASE, "test.toml", &sets(&["pin.1.region=box"])).expect_err("box");
    assert_eq!(
        (e.line, e.set.as_deref()),
        (Some(14), Some("pin.1.region=box")),
        "{e}"
    );
    assert!(
        e.to_string()
            .starts_with("test.toml:14: --set pin.1.region=box: key `pin.1.box_min`"),
        "{e}"
    );
    set_error(&["pin.7.region=all"], "pin", Kind::BadOverride);
    set_error(
        &["adapt.method=edge", "adapt.rollback=true"],
        "adapt.rollback",
        Kind::NotApplicable,
    );
    set_error(
        &[
            "adapt.method=red_green",
            "adapt.criterion=angle",
            "adapt.hysteresis=2",
        ],
        "adapt.hysteresis",
        Kind::NotApplicable,
    );
    set_error(
        &[
            "adapt.method=red_green",
            "adapt.criterion=sizing",
            "adapt.hysteresis=1",
        ],
        "adapt.hysteresis",
        Kind::OutOfRange,
    );
    set_error(
        &["adapt.criterion=curvature"],
        "adapt.criterion",
        Kind::BadValue,
    );
    let e = load_scene_str(BASE, "test.toml", &sets(&["cloth.resolution"])).expect_err("no =");
    assert_eq!(e.kind, Kind::BadOverride, "{e}");
    assert!(e.to_string().contains("--set cloth.resolution"), "{e}");
    // A later --set wins; an error in the file itself still has its line.
    let e = load_scene_str(
        &edit("density = 0.15", "density = -1"),
        "test.toml",
        &sets(&["cloth.resolution=8"]),
    )
    .expect_err("bad density");
    assert_eq!((e.line, e.set.as_deref()), (Some(10), None), "{e}");
}

#[test]
fn shipped_scenes_are_valid() {
    let s = default_scene(&[]).expect("default scene");
    assert_eq!(
        (s.name.as_str(), s.cloth.resolution, s.pin.len()),
        ("default", Some(8), 2)
    );
    let adapt = s.adapt.as_ref().expect("the default scene adapts");
    assert_eq!(adapt.method, drape::scene::AdaptMethod::RedGreen);
    assert!(s.air.is_some() && s.wind.is_none());
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let s = load_scene_file(&dir.join("hanging_sheet.toml"), &[]).expect("hanging_sheet");
    assert_eq!(s.simulation.duration, 4.0);
    let a = s.adapt.as_ref().expect("hanging_sheet adapts");
    assert_eq!(a.method, drape::scene::AdaptMethod::RedGreen);
    // Its uniform twin has the same finest edges: a red 1-4 split adds two
    // levels and halves the edges.
    let finest = s.cloth.resolution.map(|r| r << (a.max_level / 2));
    let u = load_scene_file(&dir.join("hanging_sheet_uniform.toml"), &[]).expect("uniform");
    assert_eq!((u.cloth.resolution, u.adapt.is_none()), (finest, true));
    let s = load_scene_file(&dir.join("flag.toml"), &[]).expect("flag");
    assert_eq!(s.simulation.integrator, Integrator::Rk4);
    assert_eq!(s.cloth.rotation, [90.0, 0.0, 0.0]);
    assert_eq!(s.wind.map(|w| w.velocity), Some([6.0, 0.0, 0.5]));
    let e = default_scene(&sets(&["material.density=0"])).expect_err("bad override");
    assert!(
        e.to_string()
            .starts_with("<default scene>: --set material.density=0: key `material.density`"),
        "{e}"
    );
}

#[test]
fn obj_path_is_relative_to_the_scene_file() {
    let dir = std::env::temp_dir().join(format!("drape-scene-test-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("meshes")).expect("temp dir");
    std::fs::write(
        dir.join("meshes/patch.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .expect("obj");
    let text = BASE
        .replacen(
            "shape = \"rectangle\"\nwidth = 1.0\nheight = 1.0\nresolution = 4\n",
            "shape = \"obj\"\npath = \"meshes/patch.obj\"\n",
            1,
        )
        .replacen("corner:top_left", "all", 1)
        .replacen("corner:top_right", "all", 1);
    let scene_path = dir.join("obj_scene.toml");
    std::fs::write(&scene_path, &text).expect("scene");
    let s = load_scene_file(&scene_path, &[]).expect("obj scene");
    let resolved = s.cloth.path.expect("path");
    assert_eq!(
        std::path::Path::new(&resolved),
        dir.join("meshes/patch.obj")
    );
    std::fs::write(&scene_path, text.replacen("patch.obj", "missing.obj", 1)).expect("scene");
    let e = load_scene_file(&scene_path, &[]).expect_err("missing obj");
    assert_eq!(
        (e.line, e.key.as_deref()),
        (Some(6), Some("cloth.path")),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn unreadable_file_is_an_error() {
    let e = load_scene_file(std::path::Path::new("/nonexistent/scene.toml"), &[]).expect_err("io");
    assert_eq!(e.kind, Kind::Io);
    assert!(
        e.to_string()
            .starts_with("/nonexistent/scene.toml: cannot read"),
        "{e}"
    );
}

#[test]
fn dotted_keys_and_inline_tables_are_located() {
    let text = "name = \"t\"\nsimulation = { duration = 1.0 }\ncloth.shape = \"rectangle\"\n\
                cloth.width = 1.0\ncloth.height = \"tall\"\ncloth.resolution = 4\n\
                material = { density = 0.15, stretch = 200.0 }\n";
    error_at(text, 5, "cloth.height", Kind::WrongType);
    let text = text
        .replace("\"tall\"", "1.0")
        .replace("stretch = 200.0", "stretch = 0.0");
    error_at(&text, 7, "material.stretch", Kind::OutOfRange);
}

#[test]
fn every_shipped_scene_file_is_valid() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let entries = std::fs::read_dir(&dir).expect("scenes/ exists");
    let mut count = 0;
    for entry in entries {
        let path = entry.expect("dir entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            if let Err(e) = load_scene_file(&path, &[]) {
                panic!("{e}");
            }
            count += 1;
        }
    }
    assert!(
        count >= 2,
        "expected the shipped scenes in {}",
        dir.display()
    );
}

#[test]
fn bending_length_is_an_alternative_to_bending() {
    let with = |extra: &str| edit("stretch = 200.0\n", &format!("stretch = 200.0\n{extra}"));
    // Converted with the density and |gravity| (the default 9.81 m/s^2).
    let scene = load_scene_str(&with("bending_length = 0.02\n"), "test.toml", &[]).unwrap();
    let b = scene.material.rigidity(scene.simulation.gravity);
    assert!((b - 0.15 * 9.81 * 0.02f64.powi(3)).abs() < 1e-15, "{b}");
    // Both given: located at bending_length, caused by bending.
    let e = error_at(
        &with("bending = 1e-5\nbending_length = 0.02\n"),
        13,
        "material.bending_length",
        Kind::NotApplicable,
    );
    assert!(e.to_string().contains("material.bending"), "{e}");
    error_at(
        &with("bending_length = 0.0\n"),
        12,
        "material.bending_length",
        Kind::OutOfRange,
    );
    // Without gravity it cannot be converted.
    let text = with("bending_length = 0.02\n").replacen(
        "duration = 1.0\n",
        "duration = 1.0\ngravity = [0.0, 0.0, 0.0]\n",
        1,
    );
    let e = error_at(&text, 13, "material.bending_length", Kind::NotApplicable);
    assert!(e.to_string().contains("gravity"), "{e}");
}

/// `measure` asks for textile measurements; one that cannot apply to the scene
/// is refused at its line with the reason, and a scene that asks for none (or
/// for one that applies) loads.
#[test]
fn a_measurement_that_does_not_apply_names_the_measure_key() {
    let asked = |m: &str| {
        edit(
            "name = \"t\"\n",
            &format!("name = \"t\"\nmeasure = [{m}]\n"),
        )
    };
    // BASE pins two corners: a rectangle under gravity alone, so the scene
    // allows the cantilever (whether its pins clamp one end is a run check).
    load_scene_str(&asked("\"cantilever\""), "test.toml", &[]).expect("cantilever allowed");
    let e = error_at(&asked("\"cusick\""), 2, "measure", Kind::NotApplicable);
    assert!(e.to_string().contains("needs a disk specimen"), "{e}");
    let windy = asked("\"cantilever\"") + "[wind]\nvelocity = [1.0, 0.0, 0.0]\n";
    let e = error_at(&windy, 2, "measure", Kind::NotApplicable);
    assert!(
        e.to_string()
            .contains("gravity alone, and this scene has [wind]"),
        "{e}"
    );
    let twice = asked("\"cantilever\", \"cantilever\"");
    let e = error_at(&twice, 2, "measure", Kind::BadValue);
    assert!(
        e.to_string().contains("\"cantilever\" is listed twice"),
        "{e}"
    );
    let e = error_at(&asked("\"drape\""), 2, "measure", Kind::BadValue);
    assert!(e.to_string().contains("\"cantilever\", \"cusick\""), "{e}");
}
