//! Cost of the membrane per step: the springs against the triangles.
//!
//! Cases: a free 1 m sheet, rippled out of its plane and stretched by 1 %, at
//! resolution 63 (64 x 64 = 4,096 vertices) and 127 (128 x 128 = 16,384),
//! with stretch only (no bending, no damping), `stretch = 200` as springs or as
//! the triangles' isotropic shorthand:
//! * `membrane_forces`: one force pass (element pass and per-vertex gather),
//!   what an explicit step costs per stage;
//! * `membrane_implicit_step`: one backward Euler step with the direct solver,
//!   whose assembly (forces, stiffness blocks, right-hand side and block matrix)
//!   is printed per step after the timing, from the stepper's counters.
//!
//! Run with `cargo bench --bench membrane`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group};
use drape::math::{Scalar, Vector};
use drape::physics::forces::{ForceScratch, element_pass, gather};
use drape::physics::{
    ExternalForces, MaterialParams, Membrane, Model, Orthotropic, SolverSettings, Stepper,
};
use drape::scene::{BendingModel, DiagonalPattern, Integrator, StiffnessRule};
use drape::world::World;

/// The two membranes of the same `stretch`, with their labels.
fn membranes() -> [(&'static str, Membrane); 2] {
    [
        ("springs", Membrane::Springs),
        (
            "triangles",
            Membrane::Triangles(Orthotropic::isotropic(200.0)),
        ),
    ]
}

/// The bench sheet at `resolution` and its implicit model with `membrane`.
fn setup(resolution: u32, membrane: Membrane) -> (World, Model) {
    let mesh = drape::mesh::rectangle(1.0, 1.0, resolution, DiagonalPattern::Alternating)
        .expect("valid rectangle");
    let x = mesh
        .material
        .iter()
        .map(|p| {
            Vector::new(
                1.01 * p.x,
                1.01 * p.y,
                0.01 * (7.0 * p.x).sin() * (5.0 * p.y).cos(),
            )
        })
        .collect();
    let world = World::new(mesh, x);
    let model = Model {
        material: MaterialParams {
            density: 0.15,
            stretch: 200.0,
            membrane,
            bending: 0.0,
            damping: 0.0,
            bending_model: BendingModel::ShapeOperator,
            stiffness_rule: StiffnessRule::Consistent,
            sewing: Default::default(),
        },
        external: ExternalForces {
            gravity: Some(Vector::new(0.0, 0.0, -9.81)),
            ..Default::default()
        },
        integrator: Integrator::Implicit,
        cg_tolerance: 1e-6,
        cg_max_iterations: 500,
        attachments: Vec::new(),
        solver: SolverSettings::default(),
    };
    (world, model)
}

/// One force pass (element pass plus gather) per iteration.
fn forces(c: &mut Criterion) {
    let mut group = c.benchmark_group("membrane_forces");
    group
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(2))
        .sample_size(20);
    for resolution in [63u32, 127] {
        for (label, membrane) in membranes() {
            let (world, model) = setup(resolution, membrane);
            let stepper = Stepper::new(&model, &world);
            let el = &stepper.elements;
            let n = world.mesh.vertex_count();
            let mut scratch = ForceScratch::default();
            let mut out = vec![Vector::ZERO; n];
            group.throughput(Throughput::Elements(n as u64));
            group.bench_function(BenchmarkId::new(label, n), |b| {
                b.iter(|| {
                    let ext = &model.external;
                    element_pass(
                        el,
                        ext,
                        &world.mesh.triangles,
                        &world.x,
                        &world.v,
                        &mut scratch,
                    );
                    for (i, f) in out.iter_mut().enumerate() {
                        *f = gather(el, ext, &scratch, i, world.v[i]);
                    }
                    black_box(&out);
                })
            });
        }
    }
    group.finish();
}

/// One implicit step (direct solver) per iteration, from the same state each time.
fn implicit_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("membrane_implicit_step");
    group
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .sample_size(10);
    let mut assembly = Vec::new();
    for resolution in [63u32, 127] {
        for (label, membrane) in membranes() {
            let (start, model) = setup(resolution, membrane);
            let mut stepper = Stepper::new(&model, &start);
            let n = start.mesh.vertex_count();
            let mut world = start.clone();
            group.throughput(Throughput::Elements(n as u64));
            group.bench_function(BenchmarkId::new(label, n), |b| {
                b.iter(|| {
                    world.x.clone_from(&start.x);
                    world.v.clone_from(&start.v);
                    stepper
                        .step(&model, black_box(&mut world), &mut Vec::new(), 0.01)
                        .expect("the step is solved")
                })
            });
            let s = &stepper.stats;
            let per_step = |t: f64| t / s.steps as Scalar * 1e3;
            assembly.push(format!(
                "{label:>9} {n:>6} vertices: assembly {:.3} ms, factorization {:.3} ms, solve {:.3} ms per step ({} steps)",
                per_step(s.assembly_s),
                per_step(s.factorization_s),
                per_step(s.solve_s),
                s.steps
            ));
        }
    }
    group.finish();
    for line in assembly {
        println!("{line}");
    }
}

criterion_group!(benches, forces, implicit_step);

/// `criterion_main!`, written out.
fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
