//! The triangle membrane in runs: an OBJ cloth with texture coordinates
//! simulated with both membranes, momentum and mass, Newton's iterations and
//! the two linear solvers on it, what `drape check` prints, and the scene
//! errors of its keys.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use drape::math::{Scalar, Vector};
use drape::mesh;
use drape::physics::forces::{ForceScratch, element_pass, gather};
use drape::physics::{
    Elements, ExternalForces, Membrane, Model, Orthotropic, Solver, SolverSettings,
};
use drape::run::{RunOptions, run};
use drape::scene::{
    DiagonalPattern, Integrator, SceneErrorKind as Kind, load_scene_file, load_scene_str,
};
use drape::world::World;

use crate::membrane::{membrane_material, uniform};

/// Woven-like moduli: warp, weft and shear an order of magnitude apart.
const WOVEN: Orthotropic = Orthotropic {
    warp: 300.0,
    weft: 120.0,
    shear: 25.0,
};

/// `tests/data/NAME`.
fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The 2 x 2 OBJ cloth bulging out of its plane (`vt` = position / 4, so
/// `uv_scale = 4` makes the rest shape flat and the bulge stretched), hung by
/// its top edge, run for 0.3 s with each membrane: both finish with the same
/// mass, and the stretched bulge starts with elastic energy under both.
#[test]
fn obj_cloth_with_texture_coordinates_runs_with_both_membranes() {
    let dir = std::env::temp_dir().join(format!("drape-membrane-obj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::copy(data("quad_2x2_uv.obj"), dir.join("cloth.obj")).expect("copy fixture");
    let scene_path = dir.join("scene.toml");
    std::fs::write(
        &scene_path,
        "name = \"obj_membrane\"\n\n[simulation]\nduration = 0.3\n\n[cloth]\nshape = \"obj\"\n\
         path = \"cloth.obj\"\nuv_scale = 4.0\n\n[material]\ndensity = 0.15\nstretch = 200.0\n\
         bending = 1e-5\ndamping = 0.001\n\n[[pin]]\nregion = \"box\"\n\
         box_min = [-0.1, 1.9]\nbox_max = [2.1, 2.1]\n",
    )
    .expect("write scene");
    let mut masses = Vec::new();
    for membrane in ["springs", "triangles"] {
        let overrides = [format!("material.membrane=\"{membrane}\"")];
        let scene = load_scene_file(&scene_path, &overrides).expect("the scene loads");
        let summary = run(
            &scene,
            &RunOptions::default(),
            &AtomicBool::new(false),
            &mut |_| {},
        )
        .unwrap_or_else(|e| panic!("{membrane}: {e}"));
        assert!(
            summary.extent.frames > 0 && summary.conservation.energy.r#final.is_finite(),
            "{membrane}"
        );
        masses.push(summary.conservation.mass_final);
        let world = World::from_scene(&scene).expect("the world");
        let model = Model::from_scene(&scene);
        let el = Elements::build(&world.mesh, &model.material);
        let v = vec![Vector::ZERO; world.x.len()];
        let elastic =
            drape::physics::forces::energy(&el, &ExternalForces::default(), &world.x, &v).elastic;
        assert!(
            elastic > 0.0,
            "{membrane}: the bulge is stretched ({elastic} J)"
        );
        if membrane == "triangles" {
            assert_eq!(
                el.kinds.membrane.triangles.len(),
                world.mesh.triangles.len()
            );
            assert!(
                el.kinds.springs.springs.is_empty(),
                "no stretch springs with triangles"
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(
        masses[0], masses[1],
        "the lumped mass does not depend on the membrane"
    );
}

/// Membrane forces (elastic and damping) on a randomly moved, moving sheet sum
/// to zero force and zero torque, and the lumped masses are the springs' to
/// the bit.
#[test]
fn triangle_membrane_conserves_momentum_and_keeps_the_lumped_mass() {
    let m = crate::membrane::jittered_grid(16, 0.4, 9);
    let tri = drape::physics::MaterialParams {
        damping: 0.01,
        ..membrane_material(Membrane::Triangles(WOVEN))
    };
    let el = Elements::build(&m, &tri);
    let springs = Elements::build(&m, &membrane_material(Membrane::Springs));
    assert_eq!(el.mass, springs.mass);
    let total: Scalar = el.mass.iter().sum();
    assert!((total / (0.15 * m.total_rest_area()) - 1.0).abs() < 1e-13);
    let mut next = uniform(21);
    let x: Vec<Vector> = m
        .material
        .iter()
        .map(|p| p.extend(0.0) + Vector::new(next(), next(), next()) * 0.02)
        .collect();
    let v: Vec<Vector> = (0..x.len())
        .map(|_| Vector::new(next(), next(), next()))
        .collect();
    let ext = ExternalForces::default();
    let mut scratch = ForceScratch::default();
    element_pass(&el, &ext, &m.triangles, &x, &v, &mut scratch);
    let (mut force, mut torque, mut magnitude) = (Vector::ZERO, Vector::ZERO, 0.0);
    for i in 0..x.len() {
        let f = gather(&el, &ext, &scratch, i, v[i]);
        force += f;
        torque += x[i].cross(f);
        magnitude += f.length();
    }
    assert!(force.length() < 1e-13 * magnitude, "force {force:?}");
    assert!(torque.length() < 1e-13 * magnitude, "torque {torque:?}");
}

/// A 1 m sheet at resolution 16 held along its four edges, moving, and with
/// the triangle membrane (woven moduli, bending and damping as given).
fn held_sheet(
    stretch: Scalar,
    bending: Scalar,
    damping: Scalar,
) -> (World, drape::physics::MaterialParams) {
    let m = mesh::rectangle(1.0, 1.0, 16, DiagonalPattern::Alternating).unwrap();
    let x: Vec<Vector> = m
        .material
        .iter()
        .map(|p| {
            Vector::new(
                stretch * p.x,
                stretch * p.y,
                1.0 + 0.02 * (6.0 * p.x).sin() * (4.0 * p.y).cos(),
            )
        })
        .collect();
    let mut world = World::new(m, x);
    world.v = world
        .mesh
        .material
        .iter()
        .map(|p| Vector::new(0.1 * p.y, 0.0, -0.5 * p.x))
        .collect();
    let pins = ["edge:left", "edge:right", "edge:top", "edge:bottom"].map(crate::common::pin);
    world.pins = drape::pins::Pins::select(&pins, &world.mesh, &world.x).unwrap();
    let material = drape::physics::MaterialParams {
        bending,
        damping,
        ..membrane_material(Membrane::Triangles(WOVEN))
    };
    (world, material)
}

/// Three implicit steps of `world` with `solver`; the final positions and the
/// Newton iterations taken.
fn implicit_steps(
    world: &World,
    material: drape::physics::MaterialParams,
    solver: Solver,
    newton_iterations: u32,
) -> (Vec<Vector>, u64) {
    let model = Model {
        material,
        external: ExternalForces {
            gravity: Some(Vector::new(0.0, 0.0, -9.81)),
            ..Default::default()
        },
        integrator: Integrator::Implicit,
        cg_tolerance: 1e-13,
        cg_max_iterations: 20000,
        attachments: Vec::new(),
        solver: SolverSettings {
            solver,
            newton_iterations,
            newton_tolerance: 1e-10,
            ..SolverSettings::default()
        },
    };
    let mut w = world.clone();
    let mut st = crate::common::BareStepper::new(model, &w);
    for _ in 0..3 {
        st.step(&mut w, 0.002).expect("the step converges");
    }
    (w.x, st.stepper.stats.newton_iterations)
}

/// Newton's iterations on the triangle membrane in tension (a sheet stretched
/// by 3 % and held along its edges, no bending or damping, where the solver's
/// stiffness is the exact Hessian) converge to 1e-10 in a few iterations a
/// step with either linear solver (a Hessian inconsistent with the forces
/// would converge linearly at best), and the two solvers agree on a
/// linearised step with bending and damping on.
#[test]
fn implicit_steps_with_the_triangle_membrane_converge_with_both_solvers() {
    let (world, material) = held_sheet(1.03, 0.0, 0.0);
    for solver in [Solver::Direct, Solver::Cg] {
        let (_, newton) = implicit_steps(&world, material, solver, 30);
        println!("{solver:?}: {newton} Newton iterations in 3 steps");
        assert!(
            newton <= 3 * 5,
            "{solver:?}: {newton} Newton iterations in 3 steps"
        );
    }
    let (world, material) = held_sheet(1.0, 1e-5, 0.001);
    let (direct, _) = implicit_steps(&world, material, Solver::Direct, 1);
    let (cg, _) = implicit_steps(&world, material, Solver::Cg, 1);
    let off = direct
        .iter()
        .zip(&cg)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, Scalar::max);
    assert!(off < 1e-9, "the solvers differ by {off} m");
}

/// `drape check` names the membrane and its moduli, the shorthand's included.
#[test]
fn drape_check_prints_the_membrane_and_its_moduli() {
    let check = |sets: &[&str]| {
        let mut args = vec!["check"];
        for s in sets {
            args.extend(["--set", s]);
        }
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_drape"))
            .args(&args)
            .output()
            .expect("run drape check");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let springs = check(&[]);
    assert!(springs.contains("membrane \"springs\""), "{springs}");
    let iso = check(&["material.membrane=\"triangles\"", "material.stretch=400"]);
    assert!(
        iso.contains("membrane \"triangles\"")
            && iso.contains("warp 400 N/m, weft 400 N/m, shear 200 N/m"),
        "{iso}"
    );
    let woven = check(&[
        "material.membrane=\"triangles\"",
        "material.weft=120",
        "material.shear=25",
    ]);
    assert!(woven.contains("weft 120 N/m, shear 25 N/m"), "{woven}");
}

/// A scene with `membrane = "triangles"` and `extra` in its `[material]`.
fn with_material(extra: &str) -> String {
    format!(
        "name = \"t\"\n[simulation]\nduration = 1.0\n[cloth]\nshape = \"rectangle\"\nwidth = 1.0\n\
         height = 1.0\nresolution = 4\n[material]\ndensity = 0.15\nstretch = 200.0\n{extra}\n"
    )
}

/// Negative, zero and non-finite moduli, moduli given to the springs and an
/// unknown membrane are errors naming the file, the line and the key.
#[test]
fn bad_membrane_keys_are_errors_naming_the_key() {
    let triangles = "membrane = \"triangles\"";
    for (extra, line, key, kind) in [
        (
            format!("{triangles}\nwarp = -300.0"),
            13,
            "material.warp",
            Kind::OutOfRange,
        ),
        (
            format!("{triangles}\nweft = nan"),
            13,
            "material.weft",
            Kind::OutOfRange,
        ),
        (
            format!("{triangles}\nshear = 0.0"),
            13,
            "material.shear",
            Kind::OutOfRange,
        ),
        (
            format!("{triangles}\nwarp = inf"),
            13,
            "material.warp",
            Kind::OutOfRange,
        ),
        (
            "shear = 25.0".to_string(),
            12,
            "material.shear",
            Kind::NotApplicable,
        ),
        (
            "membrane = \"quads\"".to_string(),
            12,
            "material.membrane",
            Kind::BadValue,
        ),
    ] {
        let e = match load_scene_str(&with_material(&extra), "test.toml", &[]) {
            Ok(_) => panic!("{extra}: expected an error at {key}"),
            Err(e) => e,
        };
        let msg = e.to_string();
        assert_eq!(e.kind, kind, "{msg}");
        assert_eq!(e.key.as_deref(), Some(key), "{msg}");
        assert!(
            msg.starts_with(&format!("test.toml:{line}: key `{key}`: ")),
            "{msg}"
        );
    }
    let ok = load_scene_str(
        &with_material(&format!("{triangles}\nwarp = 300.0")),
        "test.toml",
        &[],
    );
    let scene = ok.expect("valid moduli load");
    assert_eq!(
        scene.material.membrane(),
        Membrane::Triangles(Orthotropic {
            warp: 300.0,
            weft: 200.0,
            shear: 100.0
        })
    );
}
