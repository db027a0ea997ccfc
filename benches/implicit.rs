//! One implicit (backward Euler) step with each linear solver, at about 4k and 16k
//! vertices.
//!
//! The case: a 1 m sheet of the default fabric (0.15 kg/m^2, 200 N/m, 1e-5 N m,
//! damping 0.001 s, drag) pinned at two corners and swinging under gravity, at
//! `dt = 1/120` s (the step of `drape_sphere`). Each benchmark iteration is one step
//! of a running simulation (the state moves on, as in a run), after 30 warm-up
//! steps so the sheet is already falling and folding. Solvers: `direct` (sparse
//! Cholesky reused as the preconditioner, refactored when its iterations cost more
//! than a factorization worth 7 of them: the default), `direct_every_step`
//! (`refactor_iterations = 1`: a factorization counted as one iteration, so nearly
//! every step factors), `direct_single` (the same factor in single precision),
//! `direct_laplacian` (one scalar factor of a weighted graph Laplacian plus the
//! mass as the preconditioner, factored by the same rule), `cg` (matrix-free
//! Jacobi CG), `quasi_newton` (L-BFGS with the scalar Laplacian factor as its
//! initial Hessian, to the default `newton_tolerance`; its iteration cap is
//! the bench sheet's [`sheet::QUASI_NEWTON_ITERATIONS`], since the scenes' 200
//! do not carry it through the warm-up steps and a benchmark of one fixed step
//! cannot retry with halved steps as a run does).
//!
//! After the Criterion groups, the time split per step (assembly, factorization,
//! solve, the rest) of 60 further steps is printed for each case, and for the
//! `direct` case with the shape-operator bending (`direct shape_op`), the
//! scenes' default; the timed steps use dihedral bending. The assembly alone is
//! timed by the `assembly` bench.
//!
//! A second group, `remesh_tables`, times what a remesh rebuilds before the
//! symbolic factorization: the element tables and the block pattern, and the
//! element tables of a local remesh and back, built afresh against rebuilt in
//! place (`Elements::rebuild`), and the symbolic analysis of the new pattern
//! (ordered by vertex, as drape does, and by scalar unknown, as faer does alone).
//!
//! Then `orderings` prints, for the sheet's factored pattern at both
//! resolutions, the factor's stored values and a factorization's time with
//! AMD on the vertex graph (drape's) and with nested dissection.
//!
//! Run with `cargo bench --bench implicit`; the figures at commit 03aac28 are in that
//! commit's `docs/performance.md`.

mod sheet;

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group};
use drape::physics::block::BlockPattern;
use drape::physics::cholesky::{Factorization, Ordering};
use drape::physics::elements::Elements;
use drape::physics::{MaterialParams, Preconditioner, Solver, StepStats};
use drape::scene::{BendingModel, DiagonalPattern, StiffnessRule};
use drape::world::World;
use sheet::setup;

/// The solver cases: label, solver, refactor_iterations, preconditioner.
const CASES: [(&str, Solver, u32, Preconditioner); 6] = [
    ("direct", Solver::Direct, 7, Preconditioner::Factor),
    (
        "direct_every_step",
        Solver::Direct,
        1,
        Preconditioner::Factor,
    ),
    (
        "direct_single",
        Solver::Direct,
        7,
        Preconditioner::FactorSingle,
    ),
    (
        "direct_laplacian",
        Solver::Direct,
        7,
        Preconditioner::Laplacian,
    ),
    ("cg", Solver::Cg, 4, Preconditioner::Factor),
    (
        "quasi_newton",
        Solver::QuasiNewton,
        7,
        Preconditioner::Laplacian,
    ),
];

/// The sheet of a case with `bending`.
fn case_sheet(
    resolution: u32,
    bending: BendingModel,
    (solver, refactor, preconditioner): (Solver, u32, Preconditioner),
) -> sheet::Sheet {
    let mut sheet = setup(resolution, bending, solver, refactor);
    sheet.model.solver.preconditioner = preconditioner;
    sheet
}

fn implicit_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("implicit_step");
    group
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .sample_size(10);
    for resolution in [63u32, 127] {
        for (label, solver, refactor, preconditioner) in CASES {
            let mut sheet = case_sheet(
                resolution,
                BendingModel::Dihedral,
                (solver, refactor, preconditioner),
            );
            let vertices = sheet.world.mesh.vertex_count() as u64;
            group.throughput(Throughput::Elements(vertices));
            group.bench_function(BenchmarkId::new(label, vertices), |b| {
                b.iter(|| sheet.step())
            });
        }
    }
    group.finish();
}

/// Per-step time split over 60 steps after the warm-up, for each case with
/// dihedral bending, and for the default direct solver with the shape operator
/// (the scenes' default bending).
fn time_split() {
    println!("time split per step over 60 steps (after 30 warm-up steps), dt = 1/120 s:");
    for resolution in [63u32, 127] {
        let dihedral = CASES.map(|(label, solver, refactor, p)| {
            (label, BendingModel::Dihedral, (solver, refactor, p))
        });
        let shape = (
            "direct shape_op",
            BendingModel::ShapeOperator,
            (Solver::Direct, 7, Preconditioner::Factor),
        );
        let shape_single = (
            "single shape_op",
            BendingModel::ShapeOperator,
            (Solver::Direct, 7, Preconditioner::FactorSingle),
        );
        for (label, bending, case) in dihedral.into_iter().chain([shape, shape_single]) {
            let mut sheet = case_sheet(resolution, bending, case);
            let before = sheet.stepper.stats;
            let started = Instant::now();
            for _ in 0..60 {
                sheet.step();
            }
            let wall = started.elapsed().as_secs_f64();
            let d = difference(&sheet.stepper.stats, &before);
            let ms = |s: f64| 1e3 * s / 60.0;
            println!(
                "  {:>5} vertices {label:>17}: {:.2} ms/step = assembly {:.2} + factorization {:.2} + solve {:.2} + rest {:.2}; \
                 {:.2} factorizations, {:.2} CG (quasi-Newton) iterations per step",
                sheet.world.mesh.vertex_count(),
                ms(wall),
                ms(d.assembly_s),
                ms(d.factorization_s),
                ms(d.solve_s),
                ms(wall - d.assembly_s - d.factorization_s - d.solve_s),
                d.factorizations as f64 / 60.0,
                d.cg_iterations as f64 / 60.0
            );
        }
    }
}

fn difference(a: &StepStats, b: &StepStats) -> StepStats {
    StepStats {
        factorizations: a.factorizations - b.factorizations,
        cg_iterations: a.cg_iterations - b.cg_iterations + a.quasi_newton_iterations
            - b.quasi_newton_iterations,
        assembly_s: a.assembly_s - b.assembly_s,
        factorization_s: a.factorization_s - b.factorization_s,
        solve_s: a.solve_s - b.solve_s,
        ..StepStats::default()
    }
}

/// The sheet's fabric with the shape-operator bending (the scenes' default).
fn shape_operator_fabric() -> MaterialParams {
    MaterialParams {
        density: 0.15,
        stretch: 200.0,
        membrane: drape::physics::Membrane::Springs,
        bending: 1e-5,
        damping: 0.001,
        bending_model: BendingModel::ShapeOperator,
        stiffness_rule: StiffnessRule::Consistent,
        sewing: Default::default(),
    }
}

/// What a remesh costs the implicit solver before its symbolic factorization:
/// the element tables and the block pattern of the new mesh, with the default
/// shape-operator bending (`pattern_build`: `BlockPattern::build` alone).
fn remesh_tables(c: &mut Criterion) {
    let mut group = c.benchmark_group("remesh_tables");
    group
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .sample_size(10);
    for resolution in [63u32, 127] {
        let mesh = drape::mesh::rectangle(1.0, 1.0, resolution, DiagonalPattern::Alternating)
            .expect("valid rectangle");
        let material = shape_operator_fabric();
        let vertices = mesh.vertex_count();
        group.throughput(Throughput::Elements(vertices as u64));
        group.bench_function(BenchmarkId::new("elements_build", vertices), |b| {
            b.iter(|| Elements::build(black_box(&mesh), &material))
        });
        let elements = Elements::build(&mesh, &material);
        group.bench_function(BenchmarkId::new("pattern_build", vertices), |b| {
            b.iter(|| BlockPattern::build(vertices, black_box(&elements), false))
        });
        // The symbolic analysis that follows every remesh: drape's (AMD on the
        // vertex graph, `Factorization::analyse`) against faer's AMD on the scalar
        // pattern (`Ordering::ByUnknown`), which drape used before; stored values
        // of the factor printed.
        let pattern = BlockPattern::build(vertices, &elements, false);
        let mut factorization = Factorization::default();
        group.bench_function(BenchmarkId::new("analyse_by_vertex", vertices), |b| {
            b.iter(|| factorization.analyse(black_box(&pattern)))
        });
        let by_vertex = factorization.stored_values();
        group.bench_function(BenchmarkId::new("analyse_by_unknown", vertices), |b| {
            b.iter(|| factorization.analyse_with(black_box(&pattern), Ordering::ByUnknown))
        });
        println!(
            "  factor stored values: {by_vertex:?} ordered by vertex, {:?} by unknown",
            factorization.stored_values()
        );
        // A local remesh and back: the sheet refined along one crease, then the
        // original grid again; built afresh, and rebuilt in place (keeping the
        // shape matrices whose stencils did not change).
        let creased = creased(&mesh);
        group.bench_function(
            BenchmarkId::new("elements_build_remesh_and_back", vertices),
            |b| {
                b.iter(|| {
                    let there = Elements::build(black_box(&creased), &material);
                    let back = Elements::build(black_box(&mesh), &material);
                    (there, back)
                })
            },
        );
        let mut rebuilt = Elements::build(&mesh, &material);
        group.bench_function(
            BenchmarkId::new("elements_rebuild_remesh_and_back", vertices),
            |b| {
                b.iter(|| {
                    rebuilt.rebuild(black_box(&creased), &material, &[]);
                    rebuilt.rebuild(black_box(&mesh), &material, &[]);
                })
            },
        );
        rebuilt.rebuild(&creased, &material, &[]);
        println!(
            "  {} -> {} triangles: {:?}",
            mesh.triangles.len(),
            creased.triangles.len(),
            rebuilt.kinds.shapes.last_rebuild()
        );
    }
    group.finish();
}

/// `mesh` after one red-green pass over a sheet bent 45 degrees along the line
/// `x = 0.1` (15 / 1.5 deg, levels up to 2): refined along that crease only.
fn creased(mesh: &drape::mesh::Mesh) -> drape::mesh::Mesh {
    use drape::adapt::{AdaptConfig, Adapter};
    use drape::scene::{AdaptCriterion, AdaptEvery, AdaptMethod};
    let x = mesh
        .material
        .iter()
        .map(|p| p.extend((p.x - 0.1).max(0.0)))
        .collect();
    let mut world = World::new(mesh.clone(), x);
    let config = AdaptConfig {
        method: AdaptMethod::RedGreen,
        refine_angle: 15.0,
        coarsen_angle: 1.5,
        max_level: 2,
        min_edge_length: 0.0,
        every: AdaptEvery::Steps(1),
        rollback: false,
        max_rollbacks: 0,
        criterion: AdaptCriterion::Angle,
        hysteresis: 2.0,
        refine_strain: None,
        refine_obstacle: None,
        alternate_diagonals: true,
        gate: None,
    };
    let mut adapter = Adapter::new(&config, &world, 0.15).expect("the adapter starts");
    adapter
        .remesh(&config, &mut world, 0)
        .expect("a crease refines");
    world.mesh
}

criterion_group!(benches, implicit_step, remesh_tables);

/// The fill-reducing orderings side by side on the sheet's pattern (shape
/// operator, reduced factor): the factor's stored values and the median of 7
/// numerical factorizations of a positive definite matrix on that pattern
/// (a graph Laplacian plus the identity in every block: the time of a
/// supernodal factorization depends on the pattern, not on the values).
fn orderings() {
    println!("orderings of the factored pattern (median of 7 factorizations):");
    for resolution in [63u32, 127] {
        let mesh = drape::mesh::rectangle(1.0, 1.0, resolution, DiagonalPattern::Alternating)
            .expect("valid rectangle");
        let material = shape_operator_fabric();
        let elements = Elements::build(&mesh, &material);
        let pattern = BlockPattern::build(mesh.vertex_count(), &elements, false);
        let blocks = laplacian_blocks(&pattern);
        let extra = vec![drape::math::Matrix3::ZERO; pattern.vertices()];
        for ordering in [Ordering::ByVertex, Ordering::NestedDissection] {
            let mut f = Factorization::default();
            let started = Instant::now();
            f.analyse_with(&pattern, ordering).expect("analysed");
            let analysis = started.elapsed().as_secs_f64();
            let mut times: Vec<f64> = (0..7)
                .map(|_| {
                    let started = Instant::now();
                    f.factor(&pattern, &blocks, &extra).expect("factored");
                    started.elapsed().as_secs_f64()
                })
                .collect();
            times.sort_by(f64::total_cmp);
            println!(
                "  {:>5} vertices {ordering:?}: {} stored values, analysis {:.1} ms, factorization {:.2} ms",
                pattern.vertices(),
                f.stored_values().unwrap_or(0),
                1e3 * analysis,
                1e3 * times[3]
            );
        }
    }
}

/// Blocks of `L (x) I + I` on `pattern`, `L` the graph Laplacian of its
/// factored blocks.
fn laplacian_blocks(pattern: &BlockPattern) -> Vec<drape::math::Matrix3> {
    use drape::math::{Matrix3, Vector};
    let (column_start, rows) = pattern.vertex_structure();
    let slots = pattern.vertex_structure_blocks();
    let n = pattern.vertices();
    let mut degree = vec![0.0; n];
    for j in 0..n {
        for &i in &rows[column_start[j] as usize..column_start[j + 1] as usize] {
            if i as usize != j {
                degree[i as usize] += 1.0;
                degree[j] += 1.0;
            }
        }
    }
    let mut blocks = vec![Matrix3::ZERO; pattern.blocks()];
    for j in 0..n {
        for k in column_start[j] as usize..column_start[j + 1] as usize {
            let i = rows[k] as usize;
            let value = if i == j { degree[i] + 1.0 } else { -1.0 };
            blocks[slots[k] as usize] = Matrix3::from_diagonal(Vector::splat(value));
        }
    }
    blocks
}

fn main() {
    if std::env::var_os("DRAPE_BENCH_SPLIT_ONLY").is_none() {
        benches();
        Criterion::default().configure_from_args().final_summary();
    }
    orderings();
    time_split();
}
