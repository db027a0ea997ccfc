//! The sewing springs' maximum force (`[cloth.sewing] max_force`): the capped
//! force is minus the gradient of its Huber energy and its stiffness the
//! derivative of the force, on both sides of the cap, alone and in the
//! assembled model; a bad cap is refused naming file, line and key, and an OBJ
//! garment's `[cloth.sewing]` carries it (runs with a cap:
//! `sewing_cap_runs.rs`).

use drape::math::{Scalar, Vector};
use drape::physics::forces::{ForceScratch, element_pass, energy, gather};
use drape::physics::sewing::{capped_spring_energy, capped_spring_force, capped_spring_stiffness};
use drape::physics::{Elements, ExternalForces};
use drape::scene::load_scene_str;
use drape::spec::ClothMesh;

use crate::common::Sim;
use crate::garments::{TWO_SQUARES, garment_sim};

/// Stiffness and cap of the lone spring tests: the cap is reached at 2 cm.
const K: Scalar = 2.5;
const CAP: Scalar = 0.05;
/// Gaps on both sides of the cap, m.
const GAPS: [Scalar; 6] = [0.004, 0.012, 0.0199, 0.0201, 0.03, 0.25];

/// The first end and the unit axis of the lone spring tests.
fn lone_spring() -> (Vector, Vector) {
    let xa = Vector::new(0.1, -0.3, 0.7);
    (xa, Vector::new(0.3, -0.8, 0.52).normalize())
}

#[test]
fn capped_sewing_force_is_minus_the_huber_energy_gradient_on_both_sides_of_the_cap() {
    let (xa, axis) = lone_spring();
    let h = 1e-7;
    let mut worst: [Scalar; 2] = [0.0; 2];
    for d in GAPS {
        let xb = xa + axis * d;
        let f = capped_spring_force(xa, xb, Vector::ZERO, Vector::ZERO, K, 0.0, CAP);
        let e = |xa: Vector| capped_spring_energy(xb.distance(xa), K, CAP);
        let mut error: Scalar = 0.0;
        for j in 0..3 {
            let (mut plus, mut minus) = (xa, xa);
            plus[j] += h;
            minus[j] -= h;
            let fd = -(e(plus) - e(minus)) / (2.0 * h);
            error = error.max((fd - f[j]).abs());
        }
        let beyond = K * d > CAP;
        println!(
            "gap {d:.4} m ({}): |f| {:.6} N (k d {:.6}, cap {CAP}), E {:.6e} J, |f + dE/dx| / |f| = {:.2e}",
            if beyond {
                "beyond the cap"
            } else {
                "below the cap"
            },
            f.length(),
            K * d,
            e(xa),
            error / f.length()
        );
        worst[beyond as usize] = worst[beyond as usize].max(error / f.length());
        assert!(f.dot(axis) > 0.0, "the spring pulls its ends together");
        assert!(
            f.length() <= CAP * (1.0 + 1e-15),
            "{} above the cap",
            f.length()
        );
    }
    assert!(worst[0] < 1e-6 && worst[1] < 1e-6, "{worst:?}");
    // The energy and its slope are continuous at the cap: across a step of
    // 2e-12 d0 it changes by the cap times the step.
    let d0 = CAP / K;
    let (below, above) = (
        capped_spring_energy(d0 * (1.0 - 1e-12), K, CAP),
        capped_spring_energy(d0 * (1.0 + 1e-12), K, CAP),
    );
    let slope = (above - below) / (2e-12 * d0);
    println!("at the cap: E {below:.15e} J below, {above:.15e} J above, slope {slope:.4} N");
    assert!((slope - CAP).abs() < 1e-2 * CAP, "{slope}");
}

#[test]
fn capped_sewing_stiffness_is_the_force_derivative_and_never_above_k() {
    let (xa, axis) = lone_spring();
    let transverse = axis.any_orthonormal_vector();
    let h = 1e-8;
    let mut worst: Scalar = 0.0;
    for d in GAPS {
        let xb = xa + axis * d;
        let stiff = capped_spring_stiffness(xb - xa, K, CAP);
        // The force on a is dE/dx_b, so its derivative by x_b is the Hessian.
        let force =
            |xb: Vector| capped_spring_force(xa, xb, Vector::ZERO, Vector::ZERO, K, 0.0, CAP);
        let mut error: Scalar = 0.0;
        for j in 0..3 {
            let (mut plus, mut minus) = (xb, xb);
            plus[j] += h;
            minus[j] -= h;
            let fd = (force(plus) - force(minus)) / (2.0 * h);
            error = error.max((fd - stiff.col(j)).abs().max_element());
        }
        let (along, across) = (axis.dot(stiff * axis), transverse.dot(stiff * transverse));
        println!(
            "gap {d:.4} m: stiffness along {along:.6} N/m, across {across:.6} N/m (k {K}, F/d {:.6}); |K - finite difference| / k = {:.2e}",
            CAP / d,
            error / K
        );
        worst = worst.max(error / K);
        assert!(
            (stiff - stiff.transpose())
                .abs()
                .to_cols_array()
                .iter()
                .all(|&e| e == 0.0)
        );
        for s in [along, across] {
            assert!((-1e-12..=K * (1.0 + 1e-12)).contains(&s), "{s}");
        }
        if K * d > CAP {
            assert!(along.abs() < 1e-12 && (across - CAP / d).abs() < 1e-12 * K);
        }
    }
    assert!(worst < 1e-6, "{worst}");
}

/// The two squares with the right panel at `position` (the seam's gap is
/// `position + 0.02` m) and further overrides.
pub(crate) fn two_squares(position: Scalar, sets: &[&str]) -> Sim {
    let at = format!("panel.1.position=[{position}, 0.0, 0.0]");
    let mut all = vec![at.as_str()];
    all.extend_from_slice(sets);
    garment_sim(TWO_SQUARES, &all)
}

/// Per capped spring of `el` at `x`, at rest (no damping): its force on the
/// first end as the element pass leaves it, its cap and its uncapped pull `k d`.
pub(crate) fn capped_forces(
    el: &Elements,
    triangles: &[[u32; 3]],
    x: &[Vector],
) -> Vec<(Vector, Scalar, Scalar)> {
    let v = vec![Vector::ZERO; x.len()];
    let mut scratch = ForceScratch::default();
    element_pass(
        el,
        &ExternalForces::default(),
        triangles,
        x,
        &v,
        &mut scratch,
    );
    el.kinds
        .springs
        .caps
        .iter()
        .map(|c| {
            let sp = &el.kinds.springs.springs[c.spring as usize];
            let d = x[sp.v[1] as usize].distance(x[sp.v[0] as usize]);
            (
                scratch.kinds.springs[c.spring as usize],
                c.max_force,
                sp.k * d,
            )
        })
        .collect()
}

#[test]
fn capped_seam_forces_in_the_assembled_model_are_minus_the_energy_gradient() {
    // Cap reached at 5 cm; the right panel turned away about its seam's
    // bottom end, so that its pairs' gaps run from 4 cm to about 10 cm, on
    // both sides of the cap.
    let sim = two_squares(0.02, &["cloth.sewing.max_force=2.5"]);
    let w = &sim.state.world;
    let panels = w.mesh.panels().expect("panels");
    let pivot = Vector::new(0.02, 0.0, 0.0);
    let turn = drape::math::Matrix3::from_axis_angle(Vector::new(0.2, 0.3, 1.0).normalize(), -0.3);
    let mut x: Vec<Vector> = (0..w.x.len())
        .map(|i| match panels.of_vertex[i] {
            0 => w.x[i],
            _ => pivot + turn * (w.x[i] - pivot),
        })
        .collect();
    let el = Elements::build(&w.mesh, &sim.setup.model.material);
    let ext = sim.setup.model.external;
    let caps = capped_forces(&el, &w.mesh.triangles, &x);
    let beyond = caps.iter().filter(|(_, cap, kd)| kd > cap).count();
    println!("{} capped pairs, {beyond} beyond the cap", caps.len());
    assert!(beyond > 0 && beyond < caps.len(), "both sides of the cap");
    let v = vec![Vector::ZERO; x.len()];
    let mut scratch = ForceScratch::default();
    element_pass(&el, &ext, &w.mesh.triangles, &x, &v, &mut scratch);
    let f: Vec<Vector> = (0..x.len())
        .map(|i| gather(&el, &ext, &scratch, i, v[i]))
        .collect();
    let total = |x: &[Vector]| {
        let e = energy(&el, &ext, x, &v);
        e.elastic + e.gravitational
    };
    let seam: Vec<usize> = panels.seams[0]
        .pairs
        .iter()
        .flatten()
        .map(|&i| i as usize)
        .collect();
    let scale = seam.iter().map(|&i| f[i].length()).fold(0.0, Scalar::max);
    let h = 1e-7;
    let mut worst: Scalar = 0.0;
    for &i in &seam {
        for d in 0..3 {
            let x0 = x[i][d];
            x[i][d] = x0 + h;
            let ep = total(&x);
            x[i][d] = x0 - h;
            let em = total(&x);
            x[i][d] = x0;
            worst = worst.max((-(ep - em) / (2.0 * h) - f[i][d]).abs());
        }
    }
    println!(
        "{} seam vertices: largest |f + dE/dx| {worst:.3e} N, largest |f| {scale:.3e} N",
        seam.len()
    );
    assert!(worst < 1e-6 * scale, "{worst} vs {scale}");
}

#[test]
fn a_bad_max_force_is_refused_naming_file_line_and_key() {
    for bad in ["0", "-2.0", "nan", "inf"] {
        let text = format!("{TWO_SQUARES}[cloth.sewing]\nmax_force = {bad}\n");
        let line = text
            .lines()
            .position(|l| l.starts_with("max_force"))
            .expect("line")
            + 1;
        let err = load_scene_str(&text, "garment.toml", &[])
            .err()
            .unwrap_or_else(|| panic!("max_force = {bad} accepted"))
            .to_string();
        println!("{err}");
        let want = format!("garment.toml:{line}: key `cloth.sewing.max_force`: ");
        assert!(err.contains(&want), "got: {err}\nwant: {want}");
        assert!(
            err.contains("allowed: a finite number > 0 (N per m of seam)"),
            "{err}"
        );
    }
    let set = ["cloth.sewing.max_force=-1".to_string()];
    let err = load_scene_str(TWO_SQUARES, "garment.toml", &set)
        .expect_err("refused")
        .to_string();
    println!("{err}");
    assert!(err.contains("--set cloth.sewing.max_force=-1: key `cloth.sewing.max_force`: -1 is out of range: must be > 0"));
}

#[test]
fn an_obj_garments_seams_take_max_force_from_cloth_sewing() {
    let dir = crate::obj_garments::temp_dir("capped");
    std::fs::write(dir.join("g.obj"), crate::obj_garments::TWO_PANELS).expect("write obj");
    let scene = "name = \"g\"\n[simulation]\nduration = 0.1\n[cloth]\nshape = \"obj\"\npath = \"g.obj\"\n\
                 [cloth.sewing]\nstiffness = 80.0\nmax_force = 30.0\n[material]\ndensity = 0.2\nstretch = 100.0\n";
    std::fs::write(dir.join("g.toml"), scene).expect("write scene");
    let scene = drape::scene::load_scene_file(&dir.join("g.toml"), &[]).expect("scene");
    let spec = scene.resolve().expect("resolve");
    assert!(
        matches!(spec.cloth.mesh, ClothMesh::Obj { .. }),
        "an OBJ cloth"
    );
    let sewing = spec.model.material.sewing;
    assert_eq!((sewing.stiffness, sewing.max_force), (80.0, Some(30.0)));
    let sim = Sim::new(&scene);
    std::fs::remove_dir_all(&dir).ok();
    let seams = &sim.state.world.mesh.panels().expect("a garment").seams;
    let el = &sim.pipe.stepper().elements;
    let caps: Scalar = el.kinds.springs.caps.iter().map(|c| c.max_force).sum();
    println!(
        "{} seams, {} capped pairs, caps sum to {caps:.12} N (30 N/m over the 1 m seam)",
        seams.len(),
        el.kinds.springs.caps.len()
    );
    assert!(seams.iter().all(|s| s.is_open()));
    assert!((caps - 30.0).abs() < 1e-9, "{caps}");
}
