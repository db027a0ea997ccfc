//! Force equals minus the gradient of the energy for the whole assembled model:
//! the total force on every vertex (springs, bending
//! elements and gravity gathered together, as the integrators see it) against a
//! central finite difference of the total energy, on a bent and stretched grid, an
//! irregular disk and an adapted mesh, for every bending model.

use drape::adapt::{AdaptConfig, Adapter};
use drape::math::{Scalar, Vector};
use drape::mesh::{self, Mesh};
use drape::physics::forces::{ForceScratch, element_pass, energy, gather};
use drape::physics::{Elements, ExternalForces, MaterialParams};
use drape::scene::{AdaptMethod, BendingModel, DiagonalPattern, StiffnessRule};
use drape::world::World;

/// A bent, stretched and slightly rough placement of material point `p`.
fn place(p: drape::math::Vector2, i: usize) -> Vector {
    let rough = ((i * 7919 % 104729) as Scalar / 104729.0 - 0.5) * 2e-3;
    let (r, s) = (0.4, 1.03);
    let a = s * p.x / r;
    Vector::new(
        r * a.sin(),
        0.98 * p.y + 0.1 * p.x * p.y,
        r * (1.0 - a.cos()) + rough,
    )
}

/// A mesh adapted by red-green refinement around a bent fold.
fn adapted_mesh() -> Mesh {
    let m = mesh::rectangle(1.0, 1.0, 8, DiagonalPattern::Alternating).unwrap();
    let x = m
        .material
        .iter()
        .map(|p| Vector::new(p.x, p.y, 0.3 * (-(p.x * p.x) / 0.02).exp()))
        .collect();
    let mut world = World::new(m, x);
    let config = AdaptConfig {
        refine_angle: 10.0,
        coarsen_angle: 1.0,
        ..crate::common::angle_config(AdaptMethod::RedGreen)
    };
    let mut adapter = Adapter::new(&config, &world, 0.15).expect("the adapter starts");
    for pass in 0..3 {
        adapter.remesh(&config, &mut world, pass).unwrap();
    }
    world.mesh
}

#[test]
fn total_force_is_minus_the_energy_gradient() {
    let meshes = [
        (
            "grid",
            mesh::rectangle(1.0, 0.6, 10, DiagonalPattern::Alternating).unwrap(),
        ),
        ("disk", mesh::disk(0.5, 9).unwrap()),
        ("adapted", adapted_mesh()),
    ];
    assert!(
        meshes[2].1.levels.iter().any(|&l| l > 0),
        "mesh not adapted"
    );
    for (name, m) in &meshes {
        for model in [
            BendingModel::ShapeOperator,
            BendingModel::Dihedral,
            BendingModel::HingeSpring,
        ] {
            let mat = MaterialParams {
                density: 0.15,
                // Soft enough that bending forces are as large as the stretch ones.
                stretch: 0.5,
                membrane: drape::physics::Membrane::Springs,
                bending: 1e-3,
                damping: 0.0,
                bending_model: model,
                stiffness_rule: StiffnessRule::Consistent,
                sewing: Default::default(),
            };
            let el = Elements::build(m, &mat);
            let ext = ExternalForces {
                gravity: Some(Vector::new(0.3, 0.0, -9.81)),
                ..Default::default()
            };
            let mut x: Vec<Vector> = m
                .material
                .iter()
                .enumerate()
                .map(|(i, p)| place(*p, i))
                .collect();
            let v = vec![Vector::ZERO; x.len()];
            let mut scratch = ForceScratch::default();
            element_pass(&el, &ext, &m.triangles, &x, &v, &mut scratch);
            let f: Vec<Vector> = (0..x.len())
                .map(|i| gather(&el, &ext, &scratch, i, v[i]))
                .collect();
            let scale = f.iter().map(|f| f.length()).fold(0.0, Scalar::max);
            let total = |x: &[Vector]| {
                let e = energy(&el, &ext, x, &v);
                e.elastic + e.gravitational
            };
            let h = 1e-6;
            let mut worst: Scalar = 0.0;
            for i in 0..x.len() {
                for d in 0..3 {
                    let x0 = x[i][d];
                    x[i][d] = x0 + h;
                    let ep = total(&x);
                    x[i][d] = x0 - h;
                    let em = total(&x);
                    x[i][d] = x0;
                    let fd = -(ep - em) / (2.0 * h);
                    worst = worst.max((fd - f[i][d]).abs());
                }
            }
            assert!(worst < 1e-5 * scale, "{name} {model:?}: {worst} vs {scale}");
        }
    }
}
