//! The direct solver's factor fill with the shape triangles' bending blocks
//! kept whole or lumped to the first ring (`simulation.bending_matrix`,
//! `docs/model.md`, "The shape triangles' matrix"): a scene is run for a
//! while (its mesh adapting, when it does), then, on its mesh, the block
//! pattern of each matrix is built and analysed, and its blocks and the
//! factor's stored values are printed: the exact matrix factored whole
//! (every block), the exact matrix's reduced factor (second ring left out,
//! compensated on the diagonal), and the first-ring matrix (whose factor
//! is exact).
//!
//! ```sh
//! cargo run --release --example factor_fill -- scenes/tablecloth.toml 0.3
//! cargo run --release --example factor_fill -- grid 64
//! ```
//!
//! `grid N`: the default scene's sheet at resolution `N` (`N + 1` vertices a
//! side), not run.

use std::path::Path;

use anyhow::Context;
use drape::physics::block::BlockPattern;
use drape::physics::cholesky::Factorization;
use drape::physics::{Elements, Model};
use drape::scene::{default_scene, load_scene_file};
use drape::sim::{SimParts, build};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (scene, run_for) = match args.as_slice() {
        [grid, n] if grid == "grid" => {
            let overrides = [format!("cloth.resolution={n}"), "adapt.method=none".into()];
            (default_scene(&overrides)?, 0.0)
        }
        [path, seconds] => (
            load_scene_file(Path::new(path), &[])?,
            seconds.parse().context("a duration in seconds")?,
        ),
        _ => anyhow::bail!("usage: factor_fill SCENE SECONDS | factor_fill grid N"),
    };
    let model = Model::from_scene(&scene);
    let SimParts {
        setup,
        mut state,
        pipeline: mut pipe,
    } = build(&scene.resolve()?)?;
    let frame = 1.0 / 30.0;
    while state.world.time + 0.5 * frame < run_for {
        pipe.advance_frame(&setup, &mut state, frame)?;
    }
    let mesh = &state.world.mesh;
    let n = mesh.vertex_count();
    println!(
        "{}: {n} vertices, {} triangles at t = {:.3} s",
        scene.name,
        mesh.triangles.len(),
        state.world.time
    );
    let exact = Elements::build(mesh, &model.material);
    let mut lumped = exact.clone();
    lumped.kinds.shapes.lump_second_ring = true;
    for (label, elements, every_block) in [
        ("exact, every block factored", &exact, true),
        ("exact, reduced factor", &exact, false),
        ("first ring", &lumped, false),
    ] {
        let pattern = BlockPattern::build(n, elements, every_block);
        let mut factor = Factorization::default();
        factor.analyse(&pattern)?;
        let stored = factor.stored_values().context("an analysed factor")?;
        println!(
            "  {label}: {} blocks ({:.1} a row), factor {stored} stored values",
            pattern.blocks(),
            pattern.blocks() as f64 / n as f64
        );
    }
    Ok(())
}
