//! Cost of adaptation passes on a tablecloth-sized sheet, a timing harness
//! (ignored; it prints, and asserts nothing): a 1.6 m square at resolution 32
//! (the tablecloth scene's base mesh) is laid over a 1 m table top with a drape
//! whose fold radius breathes in and out, so passes both refine and merge. It
//! uses only the adapter's public API, so it can time two versions of the
//! code against each other.
//!
//! Run: `cargo test --release --test integration adapt_cost -- --ignored --nocapture --test-threads=1`.
//!
//! The whole tablecloth scene's wall time varies by more than the whole
//! adaptation cost, so this isolates the passes.

use std::time::Instant;

use drape::adapt::{AdaptConfig, Adapter};
use drape::math::{Scalar, Vector, Vector2};
use drape::mesh;
use drape::physics::{Elements, MaterialParams};
use drape::scene::{AdaptMethod, BendingModel, DiagonalPattern, StiffnessRule};
use drape::world::World;

/// The draped shape at step `k`: flat over the table, hanging down beyond its
/// edge, with a fold radius between 2 and 22 cm.
pub(crate) fn drape(m: Vector2, k: usize) -> Vector {
    let r = 0.02 + 0.1 * (1.0 + (k as Scalar / 6.0).cos());
    let out = (m.x.abs().max(m.y.abs()) - 0.5).max(0.0);
    // Bend through 90 degrees over an arc of length r * pi / 2, then hang.
    let arc = r * std::f64::consts::FRAC_PI_2;
    let (across, down) = if out < arc {
        let phi = out / r;
        (r * phi.sin(), r * (1.0 - phi.cos()))
    } else {
        (r, r + out - arc)
    };
    let dir = if m.x.abs() >= m.y.abs() {
        Vector2::new(m.x.signum(), 0.0)
    } else {
        Vector2::new(0.0, m.y.signum())
    };
    let flat = m - dir * out + dir * across;
    Vector::new(flat.x, flat.y, 0.78 - down)
}

fn cost(method: AdaptMethod) {
    let m = mesh::rectangle(1.6, 1.6, 32, DiagonalPattern::Alternating).unwrap();
    let x = m.material.iter().map(|p| p.extend(0.78)).collect();
    let mut w = World::new(m, x);
    let config = AdaptConfig {
        max_rollbacks: 3,
        ..crate::common::angle_config(method)
    };
    let mat = MaterialParams {
        density: 0.15,
        stretch: 200.0,
        membrane: drape::physics::Membrane::Springs,
        bending: 1e-5,
        damping: 0.001,
        bending_model: BendingModel::ShapeOperator,
        stiffness_rule: StiffnessRule::Consistent,
        sewing: Default::default(),
    };
    let mut ad = Adapter::new(&config, &w, 0.15).unwrap();
    let (mut pass_s, mut rebuild_s, mut times) = (0.0, 0.0, Vec::new());
    let mut vertices = 0;
    for k in 0..60 {
        for (x, p) in w.x.iter_mut().zip(&w.mesh.material) {
            *x = drape(*p, k);
        }
        let t = Instant::now();
        let changed = ad.remesh(&config, &mut w, k as u64).unwrap();
        let dt = t.elapsed().as_secs_f64();
        pass_s += dt;
        times.push(dt);
        if changed {
            let t = Instant::now();
            std::hint::black_box(Elements::build(&w.mesh, &mat));
            rebuild_s += t.elapsed().as_secs_f64();
        }
        vertices += w.mesh.vertex_count();
    }
    times.sort_by(Scalar::total_cmp);
    let s = ad.stats;
    println!(
        "adapt cost {method:?}: 60 passes, mean {} vertices, {} splits, {} merges, {} flips; \
         passes {:.1} ms total, median {:.3} ms, max {:.3} ms; element builds {:.1} ms; \
         final {} vertices",
        vertices / 60,
        s.splits,
        s.merges,
        s.flips,
        pass_s * 1e3,
        times[30] * 1e3,
        times[59] * 1e3,
        rebuild_s * 1e3,
        w.mesh.vertex_count()
    );
}

#[test]
#[ignore = "timing harness, run by hand"]
fn adapt_cost_red_green_tablecloth_drape() {
    cost(AdaptMethod::RedGreen);
}

#[test]
#[ignore = "timing harness, run by hand"]
fn adapt_cost_edge_tablecloth_drape() {
    cost(AdaptMethod::Edge);
}
