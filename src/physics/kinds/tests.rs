//! Every kind's forces against its energy, and the elastic energy's sum.

use super::*;
use crate::math::Vector;
use crate::mesh::Mesh;
use crate::physics::Model;
use crate::physics::elements::{Incidence, MaterialParams};
use crate::physics::membrane::{Membrane, Orthotropic};
use crate::scene::{BendingModel, default_scene};
use crate::world::World;

/// The default scene's sheet at 8 x 8 and its fabric.
fn sheet() -> (Mesh, MaterialParams) {
    let scene = default_scene(&["cloth.resolution=8".to_string()]).expect("the default scene");
    let mesh = World::from_scene(&scene).expect("its sheet").mesh;
    (mesh, Model::from_scene(&scene).material)
}

/// `mesh` bent along `x = 0.1`, rippled and stretched, so that every element
/// is loaded.
fn bent(mesh: &Mesh) -> Vec<Vector> {
    mesh.material
        .iter()
        .map(|p| {
            let z = 0.5 * (p.x - 0.1).max(0.0) + 0.01 * (9.0 * p.y).sin() * (7.0 * p.x).cos();
            Vector::new(1.02 * p.x, 0.99 * p.y, z)
        })
        .collect()
}

/// The elements of every kind: the shape operator with springs, and dihedral
/// hinges with the membrane triangles and one extra spring.
fn element_sets() -> Vec<(Elements, Vec<Vector>)> {
    let (mesh, fabric) = sheet();
    let x = bent(&mesh);
    let shape = MaterialParams {
        bending_model: BendingModel::ShapeOperator,
        membrane: Membrane::Springs,
        damping: 0.0,
        ..fabric
    };
    let dihedral = MaterialParams {
        bending_model: BendingModel::Dihedral,
        membrane: Membrane::Triangles(Orthotropic::isotropic(200.0)),
        damping: 0.0,
        ..fabric
    };
    let mut with_spring = Elements::build(&mesh, &dihedral);
    with_spring.kinds.springs.springs.push(Spring {
        v: [0, 40],
        rest: 0.01,
        k: 3.0,
        c: 0.0,
    });
    let n = mesh.vertex_count();
    let set = &mut with_spring.kinds.springs;
    set.first = incidence(n, &set.springs, 0);
    set.second = incidence(n, &set.springs, 1);
    vec![
        (Elements::build(&mesh, &shape), x.clone()),
        (with_spring, x),
    ]
}

/// The springs at each vertex where it is end `end`.
fn incidence(n: usize, springs: &[Spring], end: usize) -> Incidence {
    let mut lists = vec![Vec::new(); n];
    for (s, sp) in springs.iter().enumerate() {
        lists[sp.v[end] as usize].push(s as u32);
    }
    let mut offsets = vec![0];
    for l in &lists {
        offsets.push(offsets.last().copied().unwrap_or(0) + l.len() as u32);
    }
    Incidence {
        offsets,
        entries: lists.concat(),
    }
}

/// The kind's force on each vertex is minus its energy's gradient (central
/// differences, no damping, velocities zero).
fn forces_are_the_energy_gradient<K: ForceKind>(el: &Elements, x: &[Vector]) {
    let v = vec![Vector::ZERO; x.len()];
    let mut out = K::Forces::default();
    K::forces(el, x, &v, &mut out);
    let h = 1e-6;
    let mut largest: Scalar = 0.0;
    let mut worst: Scalar = 0.0;
    for i in (0..x.len()).step_by(7) {
        let mut f = Vector::ZERO;
        K::gather_force(el, &out, i, &mut f);
        largest = largest.max(f.abs().max_element());
        for axis in 0..3 {
            let mut moved = x.to_vec();
            moved[i][axis] += h;
            let up = K::energy(el, &moved);
            moved[i][axis] -= 2.0 * h;
            let down = K::energy(el, &moved);
            worst = worst.max((f[axis] + (up - down) / (2.0 * h)).abs());
        }
    }
    assert!(
        worst <= 1e-4 * largest.max(1e-6),
        "{}: forces off the energy gradient by {worst:e} (largest force {largest:e})",
        std::any::type_name::<K>()
    );
}

#[test]
fn every_kinds_forces_are_its_energy_gradient() {
    for (el, x) in element_sets() {
        forces_are_the_energy_gradient::<Springs>(&el, &x);
        forces_are_the_energy_gradient::<Hinges>(&el, &x);
        forces_are_the_energy_gradient::<ShapeTriangles>(&el, &x);
        forces_are_the_energy_gradient::<MembraneTriangles>(&el, &x);
    }
}

#[test]
fn elastic_energy_sums_the_kinds_springs_membrane_hinges_shape() {
    for (el, x) in element_sets() {
        let springs = Springs::energy(&el, &x);
        let membrane = MembraneTriangles::energy(&el, &x);
        let hinges = Hinges::energy(&el, &x);
        let shape = ShapeTriangles::energy(&el, &x);
        assert!(springs > 0.0 && hinges + shape > 0.0);
        let expected = springs + membrane + hinges + shape;
        assert_eq!(elastic_energy(&el, &x).to_bits(), expected.to_bits());
    }
}
