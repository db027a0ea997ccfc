//! Throughput of one explicit step (symplectic Euler) on uniform sheets.
//!
//! Cases: stretch springs + bending + spring damping + gravity on a square sheet
//! of about 4k vertices (resolution 63, 64 x 64) and about 66k vertices
//! (resolution 256, 257 x 257), with paper A's hinge springs and with the default
//! dihedral bending. The 66k hinge-spring case is also measured inside explicit
//! rayon pools of 1 and 2 threads. Throughput is reported as vertex-steps per
//! second (`Throughput::Elements(vertices)` per iteration of one step).
//!
//! Run with `cargo bench --bench step`; the figures at commit 03aac28 are in that
//! commit's `docs/performance.md`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group};
use drape::math::{Scalar, Vector};
use drape::physics::{ExternalForces, MaterialParams, Model, Stepper};
use drape::scene::{BendingModel, DiagonalPattern, Integrator, StiffnessRule};
use drape::world::World;

/// A bench sheet: its world, model, stepper and automatic step.
struct Setup {
    world: World,
    model: Model,
    stepper: Stepper,
    dt: Scalar,
}

/// A free (unpinned) 1 m x 1 m sheet at `resolution`, gently rippled out of its
/// plane so that no hinge is exactly flat, with its stepper and automatic step.
fn setup(resolution: u32, bending_model: BendingModel) -> Setup {
    let mesh = drape::mesh::rectangle(1.0, 1.0, resolution, DiagonalPattern::Alternating)
        .expect("valid rectangle");
    let x = mesh
        .material
        .iter()
        .map(|p| p.extend(0.01 * (7.0 * p.x).sin() * (5.0 * p.y).cos()))
        .collect();
    let world = World::new(mesh, x);
    let model = Model {
        material: MaterialParams {
            density: 0.15,
            stretch: 200.0,
            membrane: drape::physics::Membrane::Springs,
            bending: 1e-5,
            damping: 0.001,
            bending_model,
            stiffness_rule: StiffnessRule::Consistent,
            sewing: Default::default(),
        },
        external: ExternalForces {
            gravity: Some(Vector::new(0.0, 0.0, -9.81)),
            ..Default::default()
        },
        integrator: Integrator::SymplecticEuler,
        cg_tolerance: 1e-6,
        cg_max_iterations: 500,
        attachments: Vec::new(),
        solver: drape::physics::SolverSettings::default(),
    };
    let stepper = Stepper::new(&model, &world);
    let dt = stepper.auto_dt(&model, &world);
    Setup {
        world,
        model,
        stepper,
        dt,
    }
}

/// Label of a bending model in benchmark ids.
fn label(model: BendingModel) -> &'static str {
    match model {
        BendingModel::HingeSpring => "hinge_spring",
        BendingModel::Dihedral => "dihedral",
        BendingModel::ShapeOperator => "shape_operator",
    }
}

/// One step on the global rayon pool (as many threads as cores), both bending models.
fn step_default_pool(c: &mut Criterion) {
    let mut group = c.benchmark_group("symplectic_euler_step");
    group
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .sample_size(20);
    for resolution in [63u32, 256] {
        for model in [
            BendingModel::HingeSpring,
            BendingModel::Dihedral,
            BendingModel::ShapeOperator,
        ] {
            let Setup {
                mut world,
                model: physics,
                mut stepper,
                dt,
            } = setup(resolution, model);
            let vertices = world.mesh.vertex_count() as u64;
            group.throughput(Throughput::Elements(vertices));
            group.bench_function(BenchmarkId::new(label(model), vertices), |b| {
                b.iter(|| {
                    stepper
                        .step(&physics, black_box(&mut world), &mut Vec::new(), dt)
                        .expect("explicit steps cannot fail")
                })
            });
        }
    }
    group.finish();
}

/// The 66k hinge-spring step inside explicit pools of 1 and 2 threads.
fn step_thread_scaling(c: &mut Criterion) {
    let mut group = c.benchmark_group("symplectic_euler_step_66k_hinge_spring");
    group
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .sample_size(20);
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("rayon pool");
        let Setup {
            mut world,
            model: physics,
            mut stepper,
            dt,
        } = setup(256, BendingModel::HingeSpring);
        group.throughput(Throughput::Elements(world.mesh.vertex_count() as u64));
        group.bench_function(BenchmarkId::new("threads", threads), |b| {
            pool.install(|| {
                b.iter(|| {
                    stepper
                        .step(&physics, black_box(&mut world), &mut Vec::new(), dt)
                        .expect("explicit steps cannot fail")
                })
            })
        });
    }
    group.finish();
}

/// Prints the step and the mean height after a number of steps for the
/// hinge-spring sheet, to compare with the C reference kernel's output line
/// (`benches/c_kernel/run.sh RES STEPS`): the two must agree up to rounding.
fn consistency_check(spec: &str) {
    let mut parts = spec.split(',').map(|s| s.trim().parse::<u32>());
    let (Some(Ok(resolution)), Some(Ok(steps))) = (parts.next(), parts.next()) else {
        panic!("DRAPE_BENCH_CHECK must be RES,STEPS, got {spec:?}");
    };
    let Setup {
        mut world,
        model: physics,
        mut stepper,
        dt,
    } = setup(resolution, BendingModel::HingeSpring);
    for _ in 0..steps {
        stepper
            .step(&physics, &mut world, &mut Vec::new(), dt)
            .expect("explicit steps cannot fail");
    }
    let n = world.x.len();
    let mean = |f: &dyn Fn(usize) -> Scalar| (0..n).map(f).sum::<Scalar>() / n as Scalar;
    let mean_z = mean(&|i| world.x[i].z);
    let rms_z = mean(&|i| world.x[i].z * world.x[i].z).sqrt();
    let rms_vxy = mean(&|i| world.v[i].truncate().length_squared()).sqrt();
    let stretch = world.mesh.edges.len();
    println!(
        "drape: {n} vertices, {stretch} stretch + {} hinge springs, dt {dt:.4e} s, \
         after {steps} steps: mean z {mean_z:.9e}, rms z {rms_z:.9e}, \
         rms in-plane speed {rms_vxy:.9e}",
        stepper.elements.kinds.springs.springs.len() - stretch
    );
}

criterion_group!(benches, step_default_pool, step_thread_scaling);

/// `criterion_main!` plus an opt-in consistency check (`DRAPE_BENCH_CHECK=RES,STEPS`).
fn main() {
    if let Ok(spec) = std::env::var("DRAPE_BENCH_CHECK") {
        consistency_check(&spec);
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
