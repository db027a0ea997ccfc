//! Benchmarking a garment: its meshes are set by `cloth.max_edge`, not a
//! resolution, so its ladder names its reference, and the default ladder is
//! built from the scene's `max_edge`. (Its sample points are taken panel by
//! panel: `metric.rs`.)

use super::ladder::{Ladder, Rung};
use super::{BenchError, BenchOptions};
use crate::math::Scalar;
use crate::scene::Scene;

/// The default ladder for a garment (`shape = "panels"`), whose meshes are set
/// by `cloth.max_edge` (`e`, the scene's): uniform meshes at `2e`, `1.5e` and
/// `e`, red-green runs whose finest edges are `e` (base `2e` up to level 2,
/// base `4e` up to level 4), and a uniform reference at `e / 1.5`. Fails on a
/// scene without `max_edge` (which scene validation refuses for a garment).
pub fn default_garment_ladder(scene: &Scene) -> Result<Ladder, BenchError> {
    let e = scene.cloth.max_edge.ok_or_else(|| {
        BenchError::Plan("a garment's default ladder needs the scene's `cloth.max_edge`".into())
    })?;
    let edge = |x: Scalar| format!("cloth.max_edge={}", metres(x));
    let mut rung: Vec<Rung> = [2.0, 1.5, 1.0]
        .iter()
        .map(|&f| {
            let set = vec!["adapt.method=none".into(), edge(f * e)];
            Rung::new(format!("uniform {} m", metres(f * e)), set)
        })
        .collect();
    for (base, level) in [(2.0, 2), (4.0, 4)] {
        let set = vec![
            "adapt.method=red_green".into(),
            edge(base * e),
            format!("adapt.max_level={level}"),
        ];
        let label = format!("red_green {} m L{level}", metres(base * e));
        rung.push(Rung::new(label, set));
    }
    Ok(Ladder {
        reference: Some(vec!["adapt.method=none".into(), edge(e / 1.5)]),
        compare: None,
        step: None,
        rung,
    })
}

/// A length in metres with at most four decimals, trailing zeros dropped
/// (0.02 for 0.019999999999999997).
fn metres(x: Scalar) -> String {
    let s = format!("{x:.4}");
    let s = s.trim_end_matches('0');
    s.strip_suffix('.').unwrap_or(s).to_owned()
}

/// True for a garment (`shape = "panels"`).
pub(super) fn is_garment(scene: &Scene) -> bool {
    scene.cloth.shape == crate::scene::ClothShape::Panels
}

/// A garment's runs are set by `cloth.max_edge`, not a resolution: its ladder
/// must name its reference (the default garment ladder does), and
/// `--reference-resolution` does not apply.
pub(super) fn check_garment_ladder(opts: &BenchOptions, ladder: &Ladder) -> Result<(), BenchError> {
    if opts.reference_resolution.is_some() {
        return Err(BenchError::Plan(
            "--reference-resolution: a garment's meshes are set by `cloth.max_edge`; \
             name the reference in the ladder file (reference = [\"cloth.max_edge=...\"])"
                .into(),
        ));
    }
    if ladder.reference.is_none() && !opts.time_ladder {
        return Err(BenchError::Plan(
            "a garment's ladder must name its reference, a uniform run finer than every rung \
             (reference = [\"adapt.method=none\", \"cloth.max_edge=...\"]): its meshes are \
             set by `cloth.max_edge`, which the bench cannot refine on its own"
                .into(),
        ));
    }
    Ok(())
}
