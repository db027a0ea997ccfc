//! Seams over several panel sides: a waistband's long side sewn to the tops
//! of a skirt's front and back, as one seam. The edge's sides share its
//! segments in proportion to their lengths, each pair joins points at the same
//! place along both edges, the joint between the two panels is sewn to one
//! point of the band, and the whole garment welds.

use std::sync::atomic::AtomicBool;

use drape::run::{RunOptions, run};
use drape::scene::load_scene_str;
use drape::world::World;

/// A front and a back (0.2 m squares, side by side, joined by `middle`) and a
/// 0.4 x 0.05 m band 1 cm above them, its bottom side (side 1) sewn to the
/// tops of both (side 3 of each, back first: the two edges run in opposite
/// directions).
const BAND: &str = r#"
name = "band"
[simulation]
duration = 0.2
frame_rate = 30
dt = 0.005
[cloth]
shape = "panels"
max_edge = 0.05
sewing = { weld_gap = 0.03 }
[material]
density = 0.2
stretch = 300.0
bending = 2.0e-5
damping = 0.001
[[panel]]
name = "front"
outline = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]]
position = [-0.2, 0.0, 1.0]
rotation = [90.0, 0.0, 0.0]
[[panel]]
name = "back"
outline = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]]
position = [0.0, 0.0, 1.0]
rotation = [90.0, 0.0, 0.0]
[[panel]]
name = "band"
outline = [[0.0, 0.0], [0.4, 0.0], [0.4, 0.05], [0.0, 0.05]]
position = [-0.2, 0.0, 1.21]
rotation = [90.0, 0.0, 0.0]
[[seam]]
name = "middle"
a = { panel = "front", side = 2 }
b = { panel = "back", side = 4 }
[[seam]]
name = "waist"
a = { panel = "band", side = 1 }
b = [{ panel = "back", side = 3 }, { panel = "front", side = 3 }]
"#;

#[test]
fn a_seam_over_two_panels_pairs_points_along_both_edges_and_welds() {
    let scene = load_scene_str(BAND, "band.toml", &[]).expect("scene");
    let world = World::from_scene(&scene).expect("world");
    let seams = world.mesh.seams();
    let waist = seams.iter().find(|s| s.name == "waist").expect("waist");
    // The band's 0.4 m side has 8 segments (9 points); the tops share them 4
    // and 4, and their joint (two vertices) meets the band's middle point: 10
    // pairs.
    assert_eq!(waist.pairs.len(), 10, "{:?}", waist.pairs);
    let mut largest = 0.0_f64;
    for &[u, w] in &waist.pairs {
        let (p, q) = (world.x[u as usize], world.x[w as usize]);
        // Along the seam (x) the two ends of a pair lie at the same place; the
        // band starts 1 cm above the tops.
        largest = largest.max((p.x - q.x).abs());
        assert!((p - q).length() < 0.0101, "pair {u}-{w}: {p:?} and {q:?}");
    }
    println!("largest offset along the seam between paired points: {largest:.2e} m");
    let summary = run(
        &scene,
        &RunOptions::default(),
        &AtomicBool::new(false),
        &mut |_| {},
    )
    .expect("run");
    for seam in &summary.checks.seams {
        println!(
            "{}: welded at {:?}, gap {:.2e} m",
            seam.name, seam.welded_at, seam.gap
        );
        assert!(seam.welded_at.is_some(), "{} open", seam.name);
    }
    // Every seam's pairs are joined: the band's 9 bottom points take the
    // tops' 10 vertices (the joint's two, already one by `middle`).
    assert_eq!(summary.checks.seams.len(), 2);
}

#[test]
fn a_side_sewn_twice_an_empty_edge_and_a_mistyped_key_are_refused_naming_the_key() {
    let twice = BAND.replace(
        "b = [{ panel = \"back\", side = 3 }, { panel = \"front\", side = 3 }]",
        "b = [{ panel = \"back\", side = 3 }, { panel = \"band\", side = 1 }]",
    );
    let err = load_scene_str(&twice, "band.toml", &[]).expect_err("refused");
    assert_eq!(
        err.to_string(),
        "band.toml:38: key `seam.1.b`: side 1 of panel `band` is on the seam twice; a panel \
         side is sewn once"
    );
    let empty = BAND.replace(
        "b = [{ panel = \"back\", side = 3 }, { panel = \"front\", side = 3 }]",
        "b = []",
    );
    let err = load_scene_str(&empty, "band.toml", &[]).expect_err("refused");
    println!("{err}");
    assert!(
        err.to_string()
            .contains("the array of panel sides is empty"),
        "{err}"
    );
    let typo = BAND.replace(
        "b = [{ panel = \"back\", side = 3 }",
        "b = [{ panel = \"back\", sdie = 3 }",
    );
    let err = load_scene_str(&typo, "band.toml", &[]).expect_err("refused");
    assert!(
        err.to_string()
            .starts_with("band.toml:38: key `seam.1.b.0.sdie`: unknown key"),
        "{err}"
    );
}
