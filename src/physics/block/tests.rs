//! The pattern's derived tables against the searches they replaced: mirrors by
//! per-row cursors, and the shape triangles' dropped blocks from one lookup per
//! pair of slots (the "cheaper block pattern" of docs/performance.md).

use super::BlockPattern;
use crate::adapt::{AdaptConfig, Adapter};
use crate::math::Scalar;
use crate::mesh;
use crate::physics::elements::{Elements, MaterialParams};
use crate::spec::{
    AdaptCriterion, AdaptEvery, AdaptMethod, BendingModel, DiagonalPattern, StiffnessRule,
};
use crate::world::World;

/// A 12 x 12 grid, and the same grid refined by red-green along a crease (so
/// that the pattern has transitions, green triangles and shape tips).
fn meshes() -> Vec<mesh::Mesh> {
    let grid = mesh::rectangle(1.0, 1.0, 12, DiagonalPattern::Alternating).expect("grid");
    let bent = grid
        .material
        .iter()
        .map(|p| p.extend((p.x - 0.1).max(0.0) as Scalar))
        .collect();
    let mut world = World::new(grid.clone(), bent);
    let config = AdaptConfig {
        method: AdaptMethod::RedGreen,
        refine_angle: 15.0,
        coarsen_angle: 1.5,
        max_level: 4,
        min_edge_length: 0.0,
        every: AdaptEvery::Steps(1),
        rollback: false,
        max_rollbacks: 0,
        criterion: AdaptCriterion::Angle,
        hysteresis: 2.0,
        refine_strain: None,
        alternate_diagonals: true,
    };
    let mut adapter = Adapter::new(config, &world, 0.15);
    adapter.pass(&mut world, 0).expect("the crease refines");
    assert!(world.mesh.triangles.len() > grid.triangles.len());
    vec![grid, world.mesh]
}

#[test]
fn mirrors_and_dropped_blocks_match_the_searches() {
    let material = MaterialParams {
        density: 0.15,
        stretch: 200.0,
        bending: 1e-5,
        damping: 0.001,
        bending_model: BendingModel::ShapeOperator,
        stiffness_rule: StiffnessRule::Consistent,
    };
    for m in meshes() {
        let elements = Elements::build(&m, &material);
        let n = m.vertex_count();
        for factor_tips in [false, true] {
            let p = BlockPattern::build(n, &elements, factor_tips);
            for b in 0..p.blocks() {
                assert_eq!(p.mirror[b], p.slot(p.columns[b], p.rows[b]), "block {b}");
            }
            let mut dropped: Vec<(u32, (u32, u8, u8))> = Vec::new();
            for (ti, t) in elements.shape_triangles.iter().enumerate() {
                for (k, i) in t.slots() {
                    for (l, j) in t.slots() {
                        if i != j && !p.factored[p.slot(i, j) as usize] {
                            dropped.push((i, (ti as u32, k as u8, l as u8)));
                        }
                    }
                }
            }
            let (start, items) = super::group_by_key(n, &dropped);
            assert_eq!(p.shape_dropped_start, start);
            assert_eq!(p.shape_dropped, items);
            assert_eq!(
                p.shape_dropped.is_empty(),
                factor_tips,
                "the reduced pattern drops tip blocks, the full one none"
            );
        }
    }
}
