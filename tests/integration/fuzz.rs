//! Property ("fuzz") tests of the two parsers that read user files: the scene
//! parser and the OBJ loader never panic, whatever the text; they return a value
//! or a proper error. Each runs a fixed number of cases ([`cases`]: about a second
//! in release) so that CI stays fast; `PROPTEST_CASES=N` runs more.

use std::path::{Path, PathBuf};

use drape::collide::Obstacles;
use drape::mesh::load_obj;
use drape::scene::{Scene, load_scene_str};
use drape::world::World;
use proptest::prelude::*;

/// Cases per fuzz test: 2000 (about a second each in release), or `PROPTEST_CASES`.
fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(2000)
}

/// Keys of the format (and a few that are not), for generated scenes and `--set`s.
const KEYS: [&str; 40] = [
    "name",
    "simulation.duration",
    "simulation.frame_rate",
    "simulation.integrator",
    "simulation.dt",
    "simulation.gravity",
    "simulation.cg_tolerance",
    "simulation.cg_max_iterations",
    "cloth.shape",
    "cloth.width",
    "cloth.height",
    "cloth.radius",
    "cloth.resolution",
    "cloth.diagonals",
    "cloth.path",
    "cloth.uv_scale",
    "cloth.position",
    "cloth.rotation",
    "material.density",
    "material.stretch",
    "material.bending",
    "material.damping",
    "material.stiffness_rule",
    "pin.0.region",
    "pin.0.box_min",
    "pin.0.box_max",
    "pin.0.motion",
    "pin.0.velocity",
    "pin.0.axis",
    "pin.1.release_time",
    "air.drag",
    "wind.velocity",
    "adapt.method",
    "adapt.refine_angle",
    "adapt.coarsen_angle",
    "adapt.max_level",
    "obstacle.0.shape",
    "obstacle.0.radius",
    "self_collision.thickness",
    "colour",
];

/// Values of every TOML type, in range and out of it.
const VALUES: [&str; 34] = [
    "0",
    "1",
    "-1",
    "4",
    "2048",
    "2049",
    "4294967296",
    "0.5",
    "1e-300",
    "1e300",
    "nan",
    "inf",
    "-inf",
    "true",
    "\"\"",
    "\"x/y\"",
    "\"rk4\"",
    "\"implicit\"",
    "\"disk\"",
    "\"obj\"",
    "\"rectangle\"",
    "\"box\"",
    "\"all\"",
    "\"corner:top_left\"",
    "\"circular\"",
    "\"edge\"",
    "\"red_green\"",
    "\"sphere\"",
    "[]",
    "[0, 0, 0]",
    "[1, 2]",
    "[0, 0, -9.81]",
    "{}",
    "[[1]]",
];

/// The shipped scene files.
fn shipped() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("scenes/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|p| std::fs::read_to_string(p).expect("scene"))
        .collect()
}

/// One random edit of `text` at a position chosen by `at` (a fraction of its length).
#[derive(Debug, Clone)]
enum Edit {
    Delete(f64, usize),
    Insert(f64, String),
    Truncate(f64),
    DuplicateLine(f64),
    ReplaceNumber(f64, &'static str),
}

fn edit() -> impl Strategy<Value = Edit> {
    let at = 0.0..1.0f64;
    prop_oneof![
        (at.clone(), 1..20usize).prop_map(|(a, n)| Edit::Delete(a, n)),
        (at.clone(), "[\\[\\]=\"\\.,#{}\\n a-z0-9\\-]{1,12}").prop_map(|(a, s)| Edit::Insert(a, s)),
        at.clone().prop_map(Edit::Truncate),
        at.clone().prop_map(Edit::DuplicateLine),
        (at, prop::sample::select(&VALUES[..])).prop_map(|(a, v)| Edit::ReplaceNumber(a, v)),
    ]
}

/// `text` with `e` applied (at a char boundary).
fn apply(text: &str, e: &Edit) -> String {
    let pos = |a: f64| {
        let mut i = (a * text.len() as f64) as usize;
        while !text.is_char_boundary(i) {
            i -= 1;
        }
        i
    };
    match e {
        Edit::Delete(a, n) => {
            let (i, mut j) = (pos(*a), (pos(*a) + n).min(text.len()));
            while !text.is_char_boundary(j) {
                j -= 1;
            }
            format!("{}{}", &text[..i], &text[j..])
        }
        Edit::Insert(a, s) => format!("{}{s}{}", &text[..pos(*a)], &text[pos(*a)..]),
        Edit::Truncate(a) => text[..pos(*a)].to_owned(),
        Edit::DuplicateLine(a) => {
            let i = pos(*a);
            let start = text[..i].rfind('\n').map_or(0, |k| k + 1);
            let end = text[i..].find('\n').map_or(text.len(), |k| i + k + 1);
            format!("{}{}", &text[..end], &text[start..end])
        }
        Edit::ReplaceNumber(a, v) => {
            // The first number at or after the position, if any.
            let i = pos(*a);
            match text[i..].find(|c: char| c.is_ascii_digit()) {
                None => text.to_owned(),
                Some(k) => {
                    let s = i + k;
                    let len = text[s..]
                        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '.' || c == '-'))
                        .unwrap_or(text.len() - s);
                    format!("{}{v}{}", &text[..s], &text[s + len..])
                }
            }
        }
    }
}

/// Parses `text` with `sets`; an accepted scene of modest size is also built
/// (mesh, pins, obstacles), which must not panic either.
fn parse_and_build(text: &str, sets: &[String]) -> Result<(), TestCaseError> {
    match load_scene_str(text, "fuzz.toml", sets) {
        Err(e) => {
            let msg = e.to_string();
            prop_assert!(msg.starts_with("fuzz.toml"), "{msg}");
            prop_assert!(!msg.trim().is_empty());
        }
        Ok(scene) => build(&scene),
    }
    Ok(())
}

fn build(scene: &Scene) {
    if scene.cloth.resolution.unwrap_or(0) <= 96 {
        // Errors are fine (e.g. a pin box with no vertex); panics are not.
        let _ = World::from_scene(scene);
        let _ = Obstacles::from_scene(scene);
    }
}

/// Keys and values of a minimal valid scene, which random pairs then override.
const MINIMAL: [(&str, &str); 8] = [
    ("name", "\"g\""),
    ("simulation.duration", "0.1"),
    ("cloth.shape", "\"rectangle\""),
    ("cloth.width", "1.0"),
    ("cloth.height", "1.0"),
    ("cloth.resolution", "4"),
    ("material.density", "0.1"),
    ("material.stretch", "100.0"),
];

/// A random scene: top-level dotted keys of the format (and some that are not)
/// with values of every type, over a minimal valid scene.
fn random_scene() -> impl Strategy<Value = String> {
    let pair = (
        prop::sample::select(&KEYS[..]),
        prop::sample::select(&VALUES[..]),
    );
    prop::collection::vec(pair, 0..30).prop_map(|pairs| {
        let mut map: std::collections::BTreeMap<&str, &str> = MINIMAL.into_iter().collect();
        map.extend(pairs);
        map.iter().map(|(k, v)| format!("{k} = {v}\n")).collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    /// Arbitrary text, mutated shipped scenes, and random key/value scenes and
    /// `--set`s: the scene parser returns a scene or a located error, never panics.
    #[test]
    fn fuzz_scene_parser_never_panics(
        noise in "\\PC{0,300}",
        which in any::<prop::sample::Index>(),
        edits in prop::collection::vec(edit(), 1..6),
        generated in random_scene(),
        sets in prop::collection::vec(
            (prop::sample::select(&KEYS[..]), prop::sample::select(&VALUES[..])), 0..6),
    ) {
        parse_and_build(&noise, &[])?;
        let scenes = shipped();
        let mut text = which.get(&scenes).clone();
        for e in &edits {
            text = apply(&text, e);
        }
        parse_and_build(&text, &[])?;
        parse_and_build(&generated, &[])?;
        let sets: Vec<String> = sets.iter().map(|(k, v)| format!("{k}={v}")).collect();
        parse_and_build(drape::scene::DEFAULT_SCENE_TOML, &sets)?;
    }
}

/// Numbers as an OBJ file may hold them, sensible and not.
const NUMBERS: [&str; 16] = [
    "0", "1", "-1", "0.5", "2", "1e-200", "1e300", "-1e300", "nan", "inf", "-inf", "x", "",
    "1.5.2", "0x10", "3",
];

/// One random OBJ line: vertices, texture coordinates, faces of any arity with
/// any index forms (`v`, `v/vt`, `v//vn`, negative, 0, out of range), `l`
/// elements (sewing edges) of 0 to 3 vertices, and noise.
fn obj_line() -> impl Strategy<Value = String> {
    let num = prop::sample::select(&NUMBERS[..]);
    let index = prop_oneof![(-4i32..12).prop_map(|i| i.to_string()), Just(String::new())];
    let corner = prop_oneof![
        index.clone(),
        (index.clone(), index.clone()).prop_map(|(v, t)| format!("{v}/{t}")),
        (index.clone(), index).prop_map(|(v, n)| format!("{v}//{n}")),
    ];
    prop_oneof![
        4 => prop::collection::vec(num.clone(), 0..5).prop_map(|c| format!("v {}", c.join(" "))),
        2 => prop::collection::vec(num, 0..4).prop_map(|c| format!("vt {}", c.join(" "))),
        4 => prop::collection::vec(corner.clone(), 0..6).prop_map(|c| format!("f {}", c.join(" "))),
        2 => prop::collection::vec(corner, 0..4).prop_map(|c| format!("l {}", c.join(" "))),
        1 => "[a-z#/ 0-9.\\-]{0,20}",
        1 => Just("o second".to_owned()),
    ]
}

/// The OBJ files under `tests/data`.
fn obj_samples() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("tests/data")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|p| String::from_utf8_lossy(&std::fs::read(p).expect("OBJ")).into_owned())
        .collect()
}

/// Loads `bytes` as a cloth OBJ (from a temp file): a mesh that passes is valid.
fn load_bytes(bytes: &[u8], uv_scale: f64, name: &str) -> Result<(), TestCaseError> {
    let path = std::env::temp_dir().join(format!("drape-fuzz-{}-{name}.obj", std::process::id()));
    std::fs::write(&path, bytes).expect("write temp OBJ");
    let loaded = load_obj(&path, uv_scale);
    // The same file as an obstacle mesh (a different loader, in `collide`).
    let sets = [
        "obstacle.0.shape=mesh".to_owned(),
        format!("obstacle.0.path=\"{}\"", path.display()),
    ];
    let scene = drape::scene::default_scene(&sets).expect("an obstacle scene");
    let _ = Obstacles::from_scene(&scene);
    std::fs::remove_file(&path).ok();
    match loaded {
        Err(e) => prop_assert!(!e.to_string().is_empty()),
        Ok(cloth) => {
            let m = &cloth.mesh;
            prop_assert_eq!(cloth.positions.len(), m.material.len());
            prop_assert!(m.material.iter().all(|p| p.is_finite()));
            prop_assert!(cloth.positions.iter().all(|p| p.is_finite()));
            prop_assert!((0..m.triangles.len()).all(|t| m.rest_area(t) > 0.0));
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    /// Random OBJ text, mutated test meshes and raw bytes: the OBJ loader returns a
    /// valid mesh or an error, never panics.
    #[test]
    fn fuzz_obj_loader_never_panics(
        lines in prop::collection::vec(obj_line(), 0..24),
        which in any::<prop::sample::Index>(),
        edits in prop::collection::vec(edit(), 1..6),
        bytes in prop::collection::vec(any::<u8>(), 0..200),
        uv_scale in prop::sample::select(&[1.0, 1e-3, 1e200, 1e-200][..]),
    ) {
        load_bytes(lines.join("\n").as_bytes(), uv_scale, "lines")?;
        let samples = obj_samples();
        let mut text = which.get(&samples).clone();
        for e in &edits {
            text = apply(&text, e);
        }
        load_bytes(text.as_bytes(), uv_scale, "mutated")?;
        load_bytes(&bytes, uv_scale, "bytes")?;
    }
}
