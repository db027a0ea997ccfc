//! The implicit step's assembly alone, at about 4k and 16k vertices, per element.
//!
//! The case: the swinging sheet of the `implicit` bench (`sheet` module) with the
//! scenes' default bending, the shape operator, and the membrane as springs,
//! after its 30 warm-up steps. One iteration is what a step counts as assembly
//! (`Stepper::assemble_implicit`): the linearisation (spring blocks, fold angles
//! and shape Jacobians, right-hand side), the block matrix gathered into the
//! direct solver's pattern, the diagonal compensation of the blocks the
//! factorization drops, `A dv_c` and the projected system. The state does not
//! move on between iterations (the sheet stays where its warm-up left it).
//!
//! Each resolution runs twice: with the default exact bending matrix
//! (`shape_operator`) and with the shape triangles' second-ring blocks
//! lumped on the diagonal (`shape_operator_first_ring`,
//! `simulation.bending_matrix = "first_ring"`).
//!
//! An element is one spring, one bending element (shape triangle or hinge) or
//! one membrane triangle: Criterion's throughput is in elements, and after the
//! group the time per element and per assembly is printed for each case, from
//! 200 further assemblies.
//!
//! Run with `cargo bench --bench assembly`.

mod sheet;

use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group};
use drape::physics::{BendingMatrix, Solver};
use drape::scene::BendingModel;
use sheet::{DT, Sheet, setup_with};

/// The sheet at each resolution (64 x 64 and 128 x 128 vertices).
const RESOLUTIONS: [u32; 2] = [63, 127];

/// The elements the assembly visits (module docs).
fn elements(sheet: &Sheet) -> u64 {
    let e = &sheet.stepper.elements;
    (e.kinds.springs.springs.len()
        + e.kinds.hinges.hinges.len()
        + e.kinds.shapes.triangles.len()
        + e.kinds.membrane.triangles.len()) as u64
}

/// The bending matrices of the cases, with their names.
const MATRICES: [(BendingMatrix, &str); 2] = [
    (BendingMatrix::Exact, "shape_operator"),
    (BendingMatrix::FirstRing, "shape_operator_first_ring"),
];

/// The sheet with the shape operator and the default direct solver with
/// `matrix`.
fn shape_operator_sheet(resolution: u32, matrix: BendingMatrix) -> Sheet {
    setup_with(
        resolution,
        BendingModel::ShapeOperator,
        Solver::Direct,
        7,
        matrix,
    )
}

fn assembly(c: &mut Criterion) {
    let mut group = c.benchmark_group("assembly");
    group
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .sample_size(20);
    for (resolution, (matrix, name)) in RESOLUTIONS
        .into_iter()
        .flat_map(|r| MATRICES.map(|m| (r, m)))
    {
        let mut sheet = shape_operator_sheet(resolution, matrix);
        let vertices = sheet.world.mesh.vertex_count();
        group.throughput(Throughput::Elements(elements(&sheet)));
        group.bench_function(BenchmarkId::new(name, vertices), |b| {
            b.iter(|| {
                let Sheet {
                    world,
                    model,
                    stepper,
                    ..
                } = &mut sheet;
                stepper.assemble_implicit(model, world, DT)
            })
        });
    }
    group.finish();
}

/// Time per assembly and per element over 200 assemblies, for each case.
fn per_element() {
    println!("assembly over 200 repetitions (shape operator, direct solver):");
    for (resolution, (matrix, name)) in RESOLUTIONS
        .into_iter()
        .flat_map(|r| MATRICES.map(|m| (r, m)))
    {
        let mut sheet = shape_operator_sheet(resolution, matrix);
        let Sheet {
            world,
            model,
            stepper,
            ..
        } = &mut sheet;
        let e = &stepper.elements;
        let (springs, bending, membrane) = (
            e.kinds.springs.springs.len(),
            e.kinds.hinges.hinges.len() + e.kinds.shapes.triangles.len(),
            e.kinds.membrane.triangles.len(),
        );
        let count = (springs + bending + membrane) as f64;
        stepper.assemble_implicit(model, world, DT);
        let before = stepper.stats.assembly_s;
        let started = Instant::now();
        for _ in 0..200 {
            stepper.assemble_implicit(model, world, DT);
        }
        let wall = started.elapsed().as_secs_f64() / 200.0;
        let counted = (stepper.stats.assembly_s - before) / 200.0;
        println!(
            "  {name}: {:>5} vertices, {count} elements ({springs} springs, {bending} bending, \
             {membrane} membrane): {:.3} ms per assembly ({:.3} ms counted as assembly_s), \
             {:.1} ns per element",
            world.mesh.vertex_count(),
            1e3 * wall,
            1e3 * counted,
            1e9 * wall / count
        );
    }
}

criterion_group!(benches, assembly);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
    per_element();
}
