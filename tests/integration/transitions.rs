//! Transitions two refinement levels deep (bending across adaptive meshes):
//! the sheet's shape-operator energy under a constant curvature, against the
//! unrefined sheet's; and the springs' membrane on green closures.

use drape::adapt::{AdaptConfig, Adapter};
use drape::math::{Scalar, Vector, Vector2};
use drape::mesh::{self, Mesh};
use drape::physics::{Elements, MaterialParams};
use drape::scene::{AdaptMethod, BendingModel, DiagonalPattern, StiffnessRule};
use drape::world::World;

/// Where a refinement applies, by a leaf's centre.
type Region = fn(Vector2) -> bool;

/// The 8 x 8 sheet (1 m) refined one red level where `first` holds of a leaf's
/// centre, then a second where `second` does.
fn two_levels(
    alternate: bool,
    first: impl Fn(Vector2) -> bool,
    second: impl Fn(Vector2) -> bool,
) -> Mesh {
    let m0 = mesh::rectangle(1.0, 1.0, 8, DiagonalPattern::Alternating).unwrap();
    let x0: Vec<Vector> = m0.material.iter().map(|p| p.extend(0.0)).collect();
    let mut world = World::new(m0, x0);
    let config = AdaptConfig {
        alternate_diagonals: alternate,
        ..crate::common::angle_config(AdaptMethod::RedGreen)
    };
    let mut adapter = Adapter::new(&config, &world, 0.15).unwrap();
    for inside in [&first as &dyn Fn(Vector2) -> bool, &second] {
        let h = adapter.hierarchy().expect("red-green");
        let marks: Vec<(u32, Scalar)> = h
            .leaves()
            .into_iter()
            .filter(|&t| {
                let corners = h.vertices(t).map(|i| h.material()[i as usize]);
                inside((corners[0] + corners[1] + corners[2]) / 3.0)
            })
            .map(|t| (t, 20.0))
            .collect();
        adapter
            .refine(&config, &mut world, &marks, 0)
            .expect("refine");
    }
    world.mesh
}

/// Two red levels in the middle of the 8 x 8 sheet (1 m): the bending energy
/// of constant curvatures `H = xx`, `yy`, sphere and saddle (height fields of
/// curvature 1/50, so the folds are the height field's to 1e-4), minimised
/// over the fold splits, against the unrefined sheet's under the same shape.
/// The refined regions stay off the free edges, whose triangles lose the
/// same part of the energy on both meshes (the cylinder test in
/// `physics.rs`), so the two agree where the transitions bend like the
/// grid. Printed per probe (measured: within 0.0006 of the unrefined sheet
/// on all three, both diagonal settings); the test fails beyond `TOLERANCE`.
#[test]
fn second_level_transitions_bend_like_the_unrefined_sheet() {
    const TOLERANCE: Scalar = 0.002;
    let probes: [(&str, Region, Region); 3] = [
        (
            "|x|, |y| < 0.3, then |x|, |y| < 0.1",
            |c| c.x.abs() < 0.3 && c.y.abs() < 0.3,
            |c| c.x.abs() < 0.1 && c.y.abs() < 0.1,
        ),
        (
            "|x|, |y| < 0.3, then x < -0.05 inside it",
            |c| c.x.abs() < 0.3 && c.y.abs() < 0.3,
            |c| c.x < -0.05 && c.x > -0.3 && c.y.abs() < 0.3,
        ),
        (
            "disks r < 0.375, then r < 0.15",
            |c| c.length() < 0.375,
            |c| c.length() < 0.15,
        ),
    ];
    let curvatures: [[Scalar; 2]; 4] = [[1.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, -1.0]];
    let rs: Scalar = 50.0;
    let mat = MaterialParams {
        bending: 1e-3,
        ..crate::physics::material(BendingModel::ShapeOperator, StiffnessRule::Consistent)
    };
    let energy = |m: &Mesh, h: [Scalar; 2]| {
        let el = Elements::build(m, &mat);
        let height = |p: &Vector2| (h[0] * p.x * p.x + h[1] * p.y * p.y) / (2.0 * rs);
        let x: Vec<Vector> = m.material.iter().map(|p| p.extend(height(p))).collect();
        let splits = drape::physics::kinds::splits_at(&el, &x);
        el.kinds
            .shapes
            .triangles
            .iter()
            .map(|t| t.energy(&x, &splits))
            .sum::<Scalar>()
    };
    let base = mesh::rectangle(1.0, 1.0, 8, DiagonalPattern::Alternating).unwrap();
    let mut failures = Vec::new();
    for alternate in [false, true] {
        for (name, first, second) in probes {
            let m = two_levels(alternate, first, second);
            assert!(m.levels.iter().any(|&l| l >= 3), "{name}: two levels");
            let ratios = curvatures.map(|h| energy(&m, h) / energy(&base, h));
            println!(
                "{name} (alternate {alternate}): xx, yy, sphere, saddle {ratios:.4?} of the unrefined sheet"
            );
            if ratios.iter().any(|r| (r - 1.0).abs() >= TOLERANCE) {
                failures.push(format!("{name} (alternate {alternate}): {ratios:.4?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// The membrane is not exact on graded meshes (the mass-spring patch test):
/// a 1 m sheet at resolution 16 or 32 with a round patch refined two red
/// levels, stretched by a uniform 1 % strain (every vertex moved by the same
/// affine map, no relaxation), against the same sheet unrefined (which the
/// grid four times finer matches to 1e-5). Measured: equal biaxial stretch
/// is exact (the consistent spring rule is built for it); a stretch along x
/// stores 0.73 % less energy at 16 and 0.39 % less at 32, shear 3.84 % and
/// 1.88 % more. The differences halve with the green closure triangles'
/// area (0.080 and 0.038 of the sheet), so they sit in the greens: 9 to 10 %
/// softer along an axis and 48 to 50 % stiffer in shear there. Nothing is tuned
/// away here; this pins what a red-green mesh gives up (a graded sheet hangs
/// lower than the grid's would).
#[test]
fn green_closures_stretch_unlike_the_grid() {
    let material = MaterialParams {
        density: 0.15,
        stretch: 200.0,
        membrane: drape::physics::Membrane::Springs,
        bending: 0.0,
        damping: 0.0,
        bending_model: BendingModel::ShapeOperator,
        stiffness_rule: StiffnessRule::Consistent,
        sewing: Default::default(),
    };
    let e = 0.01;
    let cases: [(&str, [[Scalar; 2]; 2]); 4] = [
        ("along x", [[1.0 + e, 0.0], [0.0, 1.0]]),
        ("along y", [[1.0, 0.0], [0.0, 1.0 + e]]),
        ("biaxial", [[1.0 + e, 0.0], [0.0, 1.0 + e]]),
        ("shear", [[1.0, e], [e, 1.0]]),
    ];
    let energy = |m: &Mesh, f: [[Scalar; 2]; 2]| {
        let el = Elements::build(m, &material);
        let x: Vec<Vector> = m
            .material
            .iter()
            .map(|p| {
                Vector::new(
                    f[0][0] * p.x + f[0][1] * p.y,
                    f[1][0] * p.x + f[1][1] * p.y,
                    0.0,
                )
            })
            .collect();
        let v = vec![Vector::ZERO; x.len()];
        let ext = drape::physics::ExternalForces {
            gravity: None,
            drag: None,
            air_velocity: Vector::ZERO,
            wind: None,
        };
        drape::physics::forces::energy(&el, &ext, &x, &v).elastic
    };
    let mut deficits = Vec::new();
    for res in [16u32, 32] {
        let grid = mesh::rectangle(1.0, 1.0, res, DiagonalPattern::Alternating).unwrap();
        let x0: Vec<Vector> = grid.material.iter().map(|p| p.extend(0.0)).collect();
        let mut world = World::new(grid.clone(), x0);
        let config = AdaptConfig {
            max_level: 6,
            ..crate::common::angle_config(AdaptMethod::RedGreen)
        };
        let mut adapter = Adapter::new(&config, &world, 0.15).unwrap();
        let centre = Vector2::new(0.1, -0.05);
        crate::common::refine_around(&mut adapter, &config, &mut world, (centre, 0.25), 2);
        let green: Scalar = world
            .mesh
            .triangles
            .iter()
            .zip(&world.mesh.levels)
            .filter(|(_, l)| **l % 2 == 1)
            .map(|(t, _)| mesh::signed_area(&world.mesh.material, t))
            .sum();
        let fine = mesh::rectangle(1.0, 1.0, 4 * res, DiagonalPattern::Alternating).unwrap();
        let mut ratios = Vec::new();
        for (name, f) in cases {
            let (g, u, r) = (energy(&world.mesh, f), energy(&grid, f), energy(&fine, f));
            assert!(
                (r / u - 1.0).abs() < 1e-5,
                "the grid's energy depends on its resolution: {name}, grid {res} x 4 / grid {}",
                r / u
            );
            ratios.push(g / u);
        }
        assert!((ratios[2] - 1.0).abs() < 1e-12, "biaxial: {}", ratios[2]);
        assert!(
            ratios[0] < 1.0 && ratios[1] < 1.0 && ratios[3] > 1.0,
            "{ratios:?}"
        );
        assert!(
            ratios[3] - 1.0 < 0.05 && 1.0 - ratios[0] < 0.01,
            "{ratios:?}"
        );
        deficits.push(((1.0 - ratios[0]) / green, (ratios[3] - 1.0) / green));
    }
    // The same per green area at both resolutions: the error is the greens'.
    for k in 0..2 {
        let (a, b) = (
            [deficits[0].0, deficits[0].1][k],
            [deficits[1].0, deficits[1].1][k],
        );
        assert!((a / b - 1.0).abs() < 0.25, "{a} against {b}");
    }
}
