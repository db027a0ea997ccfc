//! The remesh gate (`adapt.min_change`, `adapt.urgent_ratio`;
//! `src/adapt/gate.rs`): a pass that would change few triangles, none of them
//! urgently, is deferred and changes nothing; a pass with a split whose reading
//! reaches the urgent ratio is applied however small it is. Shapes are
//! prescribed from material coordinates (no dynamics), with the angle
//! criterion, whose reading is the edge angle over `refine_angle`.

use drape::adapt::{AdaptConfig, Adapter, RemeshGate};
use drape::math::{Scalar, Vector, Vector2};
use drape::mesh;
use drape::scene::{AdaptMethod, DiagonalPattern};
use drape::world::World;

use crate::common::angle_config;

const DENSITY: Scalar = 0.15;

/// A flat 8 x 8 sheet (material x in [-0.5, 0.5]) with a crease along its
/// middle grid line x = 0 that turns it by `degrees`: the one edge angle is
/// there, so only the triangles with an edge on the line (an eighth of them)
/// want to split.
fn creased(degrees: Scalar) -> World {
    let m = mesh::rectangle(1.0, 1.0, 8, DiagonalPattern::Alternating).expect("valid sheet");
    let turn = degrees.to_radians();
    let x = m
        .material
        .iter()
        .map(|&p: &Vector2| match p.x <= 0.0 {
            true => p.extend(0.0),
            false => Vector::new(p.x * turn.cos(), p.y, p.x * turn.sin()),
        })
        .collect();
    World::new(m, x)
}

/// The angle criterion (15 deg) gated at `min_change`, urgent at twice the
/// threshold (30 deg).
fn gated(min_change: Scalar) -> AdaptConfig {
    AdaptConfig {
        gate: Some(RemeshGate {
            min_change,
            urgent_ratio: 2.0,
        }),
        ..angle_config(AdaptMethod::RedGreen)
    }
}

/// The largest reading at the world's triangles, and the share of them that
/// read above 1.
fn readings(config: &AdaptConfig, adapter: &Adapter, world: &World) -> (Scalar, Scalar) {
    let d = adapter.decisions(config, world, &[]);
    let worst = d.iter().map(|t| t.reading.ratio).fold(0.0, Scalar::max);
    let above = d.iter().filter(|t| t.reading.ratio > 1.0).count();
    (worst, above as Scalar / d.len() as Scalar)
}

#[test]
fn a_pass_that_changes_few_triangles_mildly_is_deferred() {
    let config = gated(0.5);
    let mut world = creased(20.0);
    let mut adapter = Adapter::new(&config, &world, DENSITY).expect("the adapter starts");
    let (worst, share) = readings(&config, &adapter, &world);
    assert!(worst > 1.0 && worst < 2.0, "a mild crease reads {worst}");
    assert!(
        share > 0.0 && share < 0.5,
        "{share} of the triangles want a split"
    );
    let before = world.mesh.triangles.clone();
    assert!(!adapter.remesh(&config, &mut world, 0).expect("pass"));
    assert_eq!(
        world.mesh.triangles, before,
        "a deferred pass changed the mesh"
    );
    let s = adapter.stats;
    assert_eq!((s.passes, s.deferred_passes, s.changed_passes), (1, 1, 0));
    assert_eq!(s.splits, 0);
    assert!(
        adapter.take_events().is_empty(),
        "a deferred pass logged events"
    );

    // The same pass, ungated, refines: the gate is what held it back.
    let ungated = AdaptConfig {
        gate: None,
        ..config
    };
    assert!(adapter.remesh(&ungated, &mut world, 1).expect("pass"));
    assert_eq!(adapter.stats.deferred_passes, 1);
}

#[test]
fn a_pass_that_changes_enough_triangles_is_applied() {
    // An eighth of the triangles read above 1: past a min_change of 0.1.
    let config = gated(0.1);
    let mut world = creased(20.0);
    let mut adapter = Adapter::new(&config, &world, DENSITY).expect("the adapter starts");
    assert!(adapter.remesh(&config, &mut world, 0).expect("pass"));
    assert_eq!(adapter.stats.deferred_passes, 0);
}

#[test]
fn an_urgent_split_is_never_deferred() {
    // min_change = 1: no pass is large enough by its size, so only the
    // urgent ratio applies one.
    let config = gated(1.0);
    for degrees in [31.0, 60.0, 120.0] {
        let mut world = creased(degrees);
        let mut adapter = Adapter::new(&config, &world, DENSITY).expect("the adapter starts");
        let (worst, _) = readings(&config, &adapter, &world);
        assert!(worst >= 2.0, "a {degrees} deg crease reads {worst}");
        assert!(
            adapter.remesh(&config, &mut world, 0).expect("pass"),
            "a {degrees} deg crease (reading {worst}) was deferred"
        );
        assert_eq!(adapter.stats.deferred_passes, 0);
        assert!(adapter.stats.splits > 0);
    }
}

#[test]
fn a_deferred_crease_is_refined_once_it_sharpens() {
    let config = gated(1.0);
    let mut world = creased(20.0);
    let mut adapter = Adapter::new(&config, &world, DENSITY).expect("the adapter starts");
    assert!(!adapter.remesh(&config, &mut world, 0).expect("pass"));
    world.x = creased(40.0).x;
    assert!(adapter.remesh(&config, &mut world, 1).expect("pass"));
    let s = adapter.stats;
    assert_eq!((s.passes, s.deferred_passes, s.changed_passes), (2, 1, 1));
}
