//! The pattern's derived tables against the searches they replaced: mirrors by
//! per-row cursors, and the shape triangles' dropped blocks from one lookup per
//! pair of slots.

use super::BlockPattern;
use crate::adapt::{AdaptConfig, Adapter};
use crate::mesh::Mesh;
use crate::physics::Model;
use crate::physics::elements::{Elements, MaterialParams};
use crate::scene::default_scene;
use crate::world::World;

/// The default scene's sheet at 12 x 12 and its fabric, and the same grid
/// refined by red-green (the papers' angle criterion) along a crease, so that
/// the pattern has transitions, green triangles and shape tips.
fn meshes() -> (Vec<Mesh>, MaterialParams) {
    let overrides = [
        "cloth.resolution=12",
        "adapt.method=red_green",
        "adapt.criterion=angle",
        "adapt.refine_strain=0",
    ];
    let scene = default_scene(&overrides.map(String::from)).expect("the default scene");
    let grid = World::from_scene(&scene).expect("its sheet").mesh;
    let bent = grid
        .material
        .iter()
        .map(|p| p.extend((p.x - 0.1).max(0.0)))
        .collect();
    let mut world = World::new(grid.clone(), bent);
    let config = AdaptConfig::from_scene(scene.adapt.as_ref()).expect("it adapts");
    let mut adapter = Adapter::new(&config, &world, scene.material.density).unwrap();
    adapter
        .remesh(&config, &mut world, 0)
        .expect("the crease refines");
    assert!(world.mesh.triangles.len() > grid.triangles.len());
    (vec![grid, world.mesh], Model::from_scene(&scene).material)
}

#[test]
fn mirrors_and_dropped_blocks_match_the_searches() {
    let (meshes, material) = meshes();
    for m in meshes {
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
