//! Incremental element tables: after a remesh,
//! `Elements::rebuild` reuses the previous build's buffers and keeps the matrix
//! of every shape triangle whose stencil came through unchanged; the result must
//! equal a fresh build bit for bit.

use std::path::Path;

use drape::adapt::{AdaptConfig, Adapter};
use drape::math::Vector2;
use drape::mesh::{self, Mesh};
use drape::physics::{Elements, MaterialParams};
use drape::scene::{
    AdaptCriterion, AdaptMethod, BendingModel, DiagonalPattern, StiffnessRule, load_scene_file,
};
use drape::sim::{SimParts, build};
use drape::world::World;
use proptest::prelude::*;

fn material(bending_model: BendingModel) -> MaterialParams {
    crate::physics::material(bending_model, StiffnessRule::Consistent)
}

/// A made-up clamp: the vertices left of `x = -0.5` are held by pin 0, so that
/// the triangles there are held and their neighbours bend against a clamp.
fn clamp_left(mesh: &Mesh) -> Vec<u32> {
    let clamped = |p: &Vector2| if p.x < -0.5 { 0 } else { u32::MAX };
    mesh.material.iter().map(clamped).collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Property: over random remeshes (a sheet draped into random folds,
    /// adapted after every `cadence`-th one, by either method, with either
    /// diagonal setting, each bending model, with and without a clamp), the
    /// elements rebuilt in place after each pass equal a fresh build of the new
    /// mesh; over the sequence, the shape model kept some matrices.
    #[test]
    fn rebuilt_elements_equal_a_fresh_build_over_random_remeshes(
        shapes in prop::collection::vec(0usize..60, 6..14),
        cadence in 1usize..3,
        edge_method in any::<bool>(),
        alternate in any::<bool>(),
        model in 0usize..3,
        clamp in any::<bool>(),
    ) {
        let method = if edge_method { AdaptMethod::Edge } else { AdaptMethod::RedGreen };
        let bending_model =
            [BendingModel::ShapeOperator, BendingModel::Dihedral, BendingModel::HingeSpring][model];
        let mat = material(bending_model);
        let m = mesh::rectangle(1.6, 1.6, 8, DiagonalPattern::Alternating).unwrap();
        let x = m.material.iter().map(|p| p.extend(0.78)).collect();
        let mut w = World::new(m, x);
        let config = AdaptConfig {
            criterion: AdaptCriterion::Angle,
            alternate_diagonals: alternate,
            ..crate::common::angle_config(method)
        };
        let mut ad = Adapter::new(&config, &w, 0.15)
        .expect("the adapter starts");
        let clamped = |mesh: &Mesh| if clamp { clamp_left(mesh) } else { Vec::new() };
        let mut el = Elements::build_clamped(&w.mesh, &mat, &clamped(&w.mesh));
        let mut kept = 0;
        for (j, &k) in shapes.iter().enumerate() {
            for (x, p) in w.x.iter_mut().zip(&w.mesh.material) {
                *x = crate::adapt_cost::drape(*p, k);
            }
            if j % cadence != 0 || !ad.remesh(&config, &mut w, j as u64).unwrap() {
                continue;
            }
            let c = clamped(&w.mesh);
            el.rebuild(&w.mesh, &mat, &c);
            let fresh = Elements::build_clamped(&w.mesh, &mat, &c);
            prop_assert!(el == fresh, "pass after shape {}: the rebuilt elements differ from a fresh build", j);
            kept += el.kinds.shapes.last_rebuild().kept;
        }
        if bending_model == BendingModel::ShapeOperator && ad.stats.splits > 0 {
            prop_assert!(kept > 0, "no shape triangle was kept over {} splits", ad.stats.splits);
        }
    }
}

/// A rebuild keeps nothing across a change of material or mesh it cannot
/// match: a different rigidity recomputes every matrix, and so does a build
/// from nothing.
#[test]
fn a_rebuild_keeps_nothing_it_cannot_match() {
    let m = mesh::rectangle(1.0, 1.0, 8, DiagonalPattern::Alternating).unwrap();
    let mat = material(BendingModel::ShapeOperator);
    let mut el = Elements::build(&m, &mat);
    let all = m.triangles.len();
    assert_eq!(
        el.kinds.shapes.last_rebuild().computed,
        all,
        "a build from nothing"
    );
    el.rebuild(&m, &mat, &[]);
    assert_eq!(
        el.kinds.shapes.last_rebuild().kept,
        all,
        "the same mesh again keeps every matrix: {:?}",
        el.kinds.shapes.last_rebuild()
    );
    let stiffer = MaterialParams {
        bending: 2e-5,
        ..mat
    };
    el.rebuild(&m, &stiffer, &[]);
    assert_eq!(
        el.kinds.shapes.last_rebuild().computed,
        all,
        "another rigidity"
    );
    assert!(el == Elements::build(&m, &stiffer));
}

/// The pipeline's remeshes rebuild incrementally: over 1 s of the adaptive
/// cantilever (a clamped strip, red-green at 5 / 1 deg, shape-operator bending), the
/// stepper's elements after every frame equal a fresh build, and most matrices
/// were kept.
#[test]
fn the_pipelines_remeshes_rebuild_incrementally() {
    let overrides = [
        "simulation.duration=1.0",
        "adapt.method=red_green",
        "cloth.resolution=10",
        "adapt.max_level=4",
        "adapt.refine_angle=5.0",
        "adapt.coarsen_angle=1.0",
    ]
    .map(String::from);
    let scene = load_scene_file(Path::new("scenes/cantilever.toml"), &overrides).expect("scene");
    let SimParts {
        setup,
        mut state,
        mut pipeline,
    } = build(&scene.resolve().expect("resolve")).expect("build");
    let frames = 30;
    let (mut kept, mut computed, mut remeshes) = (0, 0, 0);
    for frame in 0..frames {
        let before = state
            .adapter
            .as_ref()
            .map_or(0, |a| a.stats.splits + a.stats.merges);
        pipeline
            .advance_frame(&setup, &mut state, 1.0 / 30.0)
            .unwrap_or_else(|e| panic!("frame {frame}: {e}"));
        let after = state
            .adapter
            .as_ref()
            .map_or(0, |a| a.stats.splits + a.stats.merges);
        let el = &pipeline.stepper().elements;
        let w = &state.world;
        let fresh = Elements::build_clamped(
            &w.mesh,
            &setup.model.material,
            &w.pins.clamped(w.mesh.vertex_count()),
        );
        assert!(
            *el == fresh,
            "frame {frame}: the stepper's elements differ from a fresh build"
        );
        if after > before {
            remeshes += 1;
            kept += el.kinds.shapes.last_rebuild().kept;
            computed += el.kinds.shapes.last_rebuild().computed;
        }
    }
    assert!(remeshes > 0, "the cantilever should remesh");
    assert!(
        kept > computed,
        "most stencils come through a remesh unchanged: at the last of {remeshes} remeshes \
         ({frames} frames) {kept} matrices kept, {computed} computed"
    );
}
