//! `material.preset`: the measured fabrics. An unknown name is a located
//! error, a preset gives the values docs/fabrics.md derives from ARCSim's
//! data files, explicit keys override it, and every preset simulates.

use std::sync::atomic::AtomicBool;

use drape::physics::{Membrane, Orthotropic};
use drape::run::{RunOptions, run};
use drape::scene::presets::FABRICS;
use drape::scene::{Material, MembraneModel, SceneErrorKind as Kind, load_scene_str};

/// ARCSim's `materials/gray-interlock.json` as distributed (Wang, O'Brien and
/// Ramamoorthi 2011).
const GRAY_INTERLOCK_JSON: &str = r#"{
    "density": 0.187,
    "stretching": [
        [16.593832, -14.695990, 34.477123, 36.860302],
        [46.364765, 53.694656, 261.013855, -29.691301],
        [49.285110, 87.596100, 206.373993, 22.768457],
        [123.989220, 105.181770, 365.966217, 44.217571],
        [139.686325, 73.592560, 413.553162, -174.43853],
        [127.443810, 85.848587, 405.872833, 32.238411]
    ],
    "bending": [
        [23.191698e-6, 32.932217e-6, 34.406498e-6, 39.014420e-6, 23.382786e-6],
        [24.749964e-6, 18.651314e-6, 16.370552e-6, 25.095791e-6, 8.860165e-6],
        [14.267624e-6, 7.052906e-6, 14.515154e-6, 24.665127e-6, 19.383726e-6]
    ]
}"#;

/// ARCSim's `materials/11oz-black-denim.json` as distributed.
const BLACK_DENIM_JSON: &str = r#"{
    "density": 0.324,
    "stretching": [
        [205.352005, 10.234077, 1013.88629, 53.387184],
        [232.027634, 40.646339, 1052.84289, 64.980499],
        [224.592209, 40.384563, 1054.43444, 67.184807],
        [225.951050, 62.095657, 1059.59741, 83.992020],
        [226.039566, 40.502792, 1058.27771, 75.118423],
        [225.767487, 40.917892, 1051.55712, 71.810631]
    ],
    "bending": [
        [64.196457e-6, 60.286175e-6, 60.943428e-6, 62.433697e-6, 19.824701e-6],
        [73.384567e-6, 59.671982e-6, 61.080757e-6, 68.242569e-6, 36.033474e-6],
        [96.951576e-6, 107.848228e-6, 113.060738e-6, 120.569740e-6, 79.781021e-6]
    ]
}"#;

/// A 0.3 m sheet hung by its top edge for 0.5 s; `material` is the `[material]` table's body.
fn scene(material: &str) -> String {
    format!(
        "name = \"preset\"\n[simulation]\nduration = 0.5\n[cloth]\nshape = \"rectangle\"\n\
         width = 0.3\nheight = 0.3\nresolution = 6\n[material]\n{material}\n\
         [[pin]]\nregion = \"edge:top\"\n"
    )
}

fn material(body: &str) -> Material {
    load_scene_str(&scene(body), "test.toml", &[])
        .unwrap_or_else(|e| panic!("{e}"))
        .material
}

fn moduli(m: &Material) -> Orthotropic {
    match m.membrane() {
        Membrane::Triangles(o) => o,
        Membrane::Springs => panic!("expected the triangle membrane"),
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs()
}

/// The documented linearisation of one ARCSim data file: density, and warp,
/// weft, shear and bending from the zero-strain row and the zero-curvature
/// column (docs/fabrics.md).
fn linearised(json: &str) -> [f64; 5] {
    let v: serde_json::Value = serde_json::from_str(json).expect("the JSON parses");
    let s = |j: usize| v["stretching"][0][j].as_f64().expect("a number");
    let b = |i: usize| v["bending"][i][0].as_f64().expect("a number");
    // ARCSim doubles the file's k; drape's shear is half the doubled k3.
    let (warp, weft, shear) = (2.0 * s(0), 2.0 * s(2), 2.0 * s(3) / 2.0);
    // B = ke / 4, the mean of the hinges along v (row 2) and along u (row 0).
    let bending = 0.5 * (b(2) / 4.0 + b(0) / 4.0);
    let density = v["density"].as_f64().expect("a number");
    [density, warp, weft, shear, bending]
}

#[test]
fn an_unknown_preset_is_an_error_naming_file_line_and_key() {
    let text = scene("density = 0.2\npreset = \"satin\"");
    let e = load_scene_str(&text, "test.toml", &[]).expect_err("satin is no preset");
    let msg = e.to_string();
    assert_eq!(e.kind, Kind::BadValue, "{msg}");
    assert_eq!(e.line, Some(11), "{msg}");
    assert_eq!(e.key.as_deref(), Some("material.preset"), "{msg}");
    assert!(
        msg.starts_with("test.toml:11: key `material.preset`: ") && msg.contains("\"satin\""),
        "{msg}"
    );
    for f in &FABRICS {
        assert!(msg.contains(&format!("\"{}\"", f.name)), "{msg}");
    }

    let set = ["material.preset=\"silk\"".to_owned()];
    let e = load_scene_str(&scene("preset = \"gray-interlock\""), "test.toml", &set)
        .expect_err("silk is no preset");
    assert_eq!(e.line, None, "{e}");
    assert_eq!(e.set.as_deref(), Some("material.preset=\"silk\""), "{e}");
    assert_eq!(e.key.as_deref(), Some("material.preset"), "{e}");

    let e = load_scene_str(&scene("preset = 3"), "test.toml", &[]).expect_err("not a string");
    assert_eq!(e.kind, Kind::WrongType, "{e}");
    assert_eq!(e.key.as_deref(), Some("material.preset"), "{e}");
}

#[test]
fn a_preset_gives_the_linearised_values_of_its_data_file() {
    for (name, json) in [
        ("gray-interlock", GRAY_INTERLOCK_JSON),
        ("11oz-black-denim", BLACK_DENIM_JSON),
    ] {
        let [density, warp, weft, shear, bending] = linearised(json);
        let m = material(&format!("preset = \"{name}\""));
        assert_eq!(m.preset.as_deref(), Some(name));
        assert_eq!(m.membrane, MembraneModel::Triangles, "{name}");
        let o = moduli(&m);
        assert!(close(m.density, density), "{name}: {}", m.density);
        assert!(close(o.warp, warp), "{name}: warp {} vs {warp}", o.warp);
        assert!(close(o.weft, weft), "{name}: weft {} vs {weft}", o.weft);
        assert!(
            close(o.shear, shear),
            "{name}: shear {} vs {shear}",
            o.shear
        );
        let b = m.rigidity([0.0, 0.0, -9.81]);
        assert!(close(b, bending), "{name}: bending {b} vs {bending}");
    }
}

#[test]
fn explicit_keys_override_the_preset() {
    let [_, warp, _, shear, bending] = linearised(GRAY_INTERLOCK_JSON);
    let m = material("preset = \"gray-interlock\"\ndensity = 0.5\nweft = 250.0\nbending = 2e-5");
    let o = moduli(&m);
    assert_eq!((m.density, o.weft, m.bending), (0.5, 250.0, 2e-5));
    assert!(close(o.warp, warp) && close(o.shear, shear), "{o:?}");

    // `stretch` is the isotropic shorthand: it replaces warp, weft and shear.
    let m = material("preset = \"gray-interlock\"\nstretch = 400.0");
    assert_eq!(moduli(&m), Orthotropic::isotropic(400.0));

    // `bending_length` replaces the preset's rigidity.
    let m = material("preset = \"gray-interlock\"\nbending_length = 0.02");
    let b = m.rigidity([0.0, 0.0, -9.81]);
    assert!(close(b, 0.187 * 9.81 * 0.02f64.powi(3)), "{b}");
    assert!(!close(b, bending));

    // The springs take one constant, the mean of warp and weft.
    let [_, warp, weft, _, _] = linearised(GRAY_INTERLOCK_JSON);
    let m = material("preset = \"gray-interlock\"\nmembrane = \"springs\"");
    assert_eq!(m.membrane(), Membrane::Springs);
    assert!(close(m.stretch, 0.5 * (warp + weft)), "{}", m.stretch);
    assert_eq!((m.warp, m.weft, m.shear), (None, None, None));

    // A --set overrides a preset's value as a written key does.
    let set = ["material.warp=90.0".to_owned()];
    let s = load_scene_str(&scene("preset = \"gray-interlock\""), "t.toml", &set).expect("loads");
    assert_eq!(moduli(&s.material).warp, 90.0);
}

#[test]
fn check_names_the_preset() {
    let s = load_scene_str(&scene("preset = \"royal-target\""), "t.toml", &[]).expect("loads");
    let text = drape::check::describe(&s).expect("describes");
    assert!(
        text.contains("material: density 0.22 kg/m^2, preset \"royal-target\" (pants;"),
        "{text}"
    );
    let s = load_scene_str(&scene("density = 0.2\nstretch = 100.0"), "t.toml", &[]).expect("loads");
    let text = drape::check::describe(&s).expect("describes");
    assert!(text.contains("material: density 0.2 kg/m^2\n"), "{text}");
}

#[test]
fn every_preset_runs_a_hanging_sheet() {
    for f in &FABRICS {
        let scene = load_scene_str(
            &scene(&format!("preset = \"{}\"\ndamping = 0.01", f.name)),
            "test.toml",
            &[],
        )
        .unwrap_or_else(|e| panic!("{}: {e}", f.name));
        let summary = run(
            &scene,
            &RunOptions::default(),
            &AtomicBool::new(false),
            &mut |_| {},
        )
        .unwrap_or_else(|e| panic!("{}: {e}", f.name));
        assert_eq!(summary.extent.frames, 16, "{}", f.name);
        assert_eq!(summary.effort.nan_recoveries, 0, "{}", f.name);
        assert!(
            summary.conservation.energy.r#final.is_finite(),
            "{}",
            f.name
        );
        assert!(
            close(summary.conservation.mass_final, f.density * 0.09),
            "{}",
            f.name
        );
    }
}
