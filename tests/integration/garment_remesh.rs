//! Remeshing garments: red-green splits and merges and the edge method's
//! splits, flips and collapses across a welded seam keep both panels' pattern
//! coordinates (each vertex on the seam has one coordinate per panel, at the
//! same height on both sides), the panels' areas, the mass and the momentum;
//! red-green merged everything back gives the welded mesh's corners exactly;
//! and a garment scene with `[adapt]` remeshes once its seams are welded,
//! consistent after every step.

use std::collections::HashMap;
use std::f64::consts::PI;

use drape::adapt::red_green::RedGreenOp;
use drape::adapt::transfer::mesh_lumped_masses;
use drape::adapt::{AdaptConfig, Adapter};
use drape::garment::{self, BuiltGarment};
use drape::math::{Scalar, Vector, Vector2};
use drape::mesh::Mesh;
use drape::physics::{Elements, MaterialParams, Membrane};
use drape::scene::{AdaptMethod, BendingModel, StiffnessRule, load_scene_str};
use drape::sim::SeamState;
use drape::spec::{Garment, Gather, PanelSpec, Placement, SeamDirection, SeamSide, SeamSpec};
use drape::world::World;
use proptest::prelude::*;

use crate::common::{Sim, angle_config};

const DENSITY: Scalar = 0.2;
const HEIGHT: Scalar = 0.3;

/// A tube of radius 0.1 m and 0.3 m tall from two welded halves ("front" and
/// "back", each `width` wide), its points moved off the cylinder a little so
/// the velocities and positions are not symmetric.
fn welded_tube() -> (World, Scalar) {
    let r = 0.1;
    let width = PI * r;
    let wrap = |angle: Scalar| Placement::Cylinder {
        radius: r,
        angle,
        position: [0.0; 3],
    };
    welded_halves(width, [wrap(0.0), wrap(180.0)])
}

/// Two `width` x 0.3 m panels ("front" and "back") placed as given, the
/// front's side 2 sewn to the back's side 4 and the back's side 2 to the
/// front's side 4, both seams welded; velocities set to an uneven field.
fn welded_halves(width: Scalar, placements: [Placement; 2]) -> (World, Scalar) {
    let [pf, pb] = placements;
    let half = |name: &str, placement: Placement| PanelSpec {
        name: name.into(),
        outline: vec![[0.0, 0.0], [width, 0.0], [width, HEIGHT], [0.0, HEIGHT]],
        curves: Vec::new(),
        placement,
    };
    let side = |panel: &str, side: usize| SeamSide {
        panel: panel.into(),
        side,
    };
    let seams = vec![
        SeamSpec {
            name: "left".into(),
            a: vec![side("front", 2)],
            b: vec![side("back", 4)],
            direction: SeamDirection::Opposite,
            gather: Gather::None,
        },
        SeamSpec {
            name: "right".into(),
            a: vec![side("back", 2)],
            b: vec![side("front", 4)],
            direction: SeamDirection::Opposite,
            gather: Gather::None,
        },
    ];
    let BuiltGarment { mesh, positions } = garment::build(&Garment {
        panels: vec![half("front", pf), half("back", pb)],
        seams,
        holds: Vec::new(),
        max_edge: 0.06,
    })
    .expect("garment");
    let mat = MaterialParams {
        density: DENSITY,
        stretch: 300.0,
        membrane: Membrane::Springs,
        bending: 1e-3,
        damping: 0.0,
        bending_model: BendingModel::ShapeOperator,
        stiffness_rule: StiffnessRule::Consistent,
        sewing: Default::default(),
    };
    let mut world = World::new(mesh, positions);
    for s in 0..2 {
        let el = Elements::build(&world.mesh, &mat);
        world.weld_seam(s, &el.mass).expect("weld");
    }
    for (i, (x, v)) in world.x.iter_mut().zip(world.v.iter_mut()).enumerate() {
        let f = i as Scalar;
        *x += Vector::new(1e-3 * (0.7 * f).sin(), 1e-3 * (1.3 * f).cos(), 0.0);
        *v = Vector::new((0.3 * f).sin(), (0.5 * f).cos(), 0.1 * (0.9 * f).sin());
    }
    (world, width)
}

/// The rest area of each panel, m^2.
fn panel_areas(mesh: &Mesh) -> Vec<Scalar> {
    let p = mesh.panels().expect("panels");
    let mut a = vec![0.0; p.names.len()];
    for t in 0..mesh.triangles.len() {
        a[p.of_triangle[t] as usize] += mesh.rest_area(t);
    }
    a
}

/// Checks that every vertex has one pattern coordinate per panel, and that a
/// vertex with coordinates in both panels lies on both panels' seam sides at
/// the same height. Returns the number of such seam vertices.
fn check_seam_coordinates(mesh: &Mesh, width: Scalar) -> Result<usize, String> {
    let p = mesh.panels().expect("panels");
    let mut at: HashMap<(u32, u16), Vector2> = HashMap::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            let c = p.corners[t][k];
            let key = (v, p.of_triangle[t]);
            if let Some(&seen) = at.get(&key)
                && seen != c
            {
                return Err(format!("vertex {v} has two coordinates in panel {}", key.1));
            }
            at.insert(key, c);
        }
    }
    let mut on_seam = 0;
    for v in 0..mesh.vertex_count() as u32 {
        let (Some(f), Some(b)) = (at.get(&(v, 0)), at.get(&(v, 1))) else {
            continue;
        };
        on_seam += 1;
        let sides = [0.0, width];
        let on_side = |u: Scalar| sides.iter().any(|s| (u - s).abs() < 1e-12);
        if !on_side(f.x) || !on_side(b.x) || (f.y - b.y).abs() > 1e-12 || f.x == b.x {
            return Err(format!("seam vertex {v}: front {f:?}, back {b:?}"));
        }
    }
    Ok(on_seam)
}

/// Total mass and momentum of `world`.
fn mass_and_momentum(world: &World) -> (Scalar, Vector) {
    let m = mesh_lumped_masses(&world.mesh, DENSITY);
    let p = m.iter().zip(&world.v).map(|(&m, &v)| v * m).sum();
    (m.iter().sum(), p)
}

/// Each triangle's corners, keyed by position, sorted (for comparing meshes
/// whose vertices are numbered differently).
fn corner_sets(mesh: &Mesh) -> Vec<[(u64, u64); 3]> {
    let mut out: Vec<[(u64, u64); 3]> = (0..mesh.triangles.len())
        .map(|t| {
            let mut c = mesh.corners(t).map(|p| (p.x.to_bits(), p.y.to_bits()));
            c.sort_unstable();
            c
        })
        .collect();
    out.sort_unstable();
    out
}

fn config() -> AdaptConfig {
    AdaptConfig {
        max_level: 6,
        ..angle_config(AdaptMethod::RedGreen)
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random red-green splits and merges on a tube welded from two panels:
    /// after each, the adapter's consistency checks pass, every seam vertex
    /// has one coordinate in each panel at the same height, each panel keeps
    /// its area, and mass and momentum are unchanged; merging everything back
    /// gives the welded mesh's corners exactly.
    #[test]
    fn red_green_across_a_welded_seam_keeps_both_panels_pattern_coordinates(
        picks in prop::collection::vec((any::<bool>(), any::<u16>()), 1..24),
    ) {
        let (mut world, width) = welded_tube();
        let c = config();
        let mut ad = Adapter::new(&c, &world, DENSITY).expect("red-green on a welded garment");
        let base = corner_sets(&world.mesh);
        let areas = panel_areas(&world.mesh);
        let (m0, p0) = mass_and_momentum(&world);
        let seam0 = check_seam_coordinates(&world.mesh, width).map_err(TestCaseError::fail)?;
        prop_assert!(seam0 > 0);
        for (step, &(refine, pick)) in picks.iter().enumerate() {
            let h = ad.hierarchy().expect("red-green");
            let op = if refine {
                let leaves: Vec<u32> =
                    h.leaves().into_iter().filter(|&l| h.level(l) + 2 <= 6).collect();
                RedGreenOp::Split(leaves[pick as usize % leaves.len()])
            } else {
                let parents = h.mergeable_parents();
                if parents.is_empty() {
                    continue;
                }
                RedGreenOp::Merge(parents[pick as usize % parents.len()])
            };
            ad.apply(&c, &mut world, &[(op, None)], step as u64).expect("remesh");
            ad.check(&world).map_err(|e| TestCaseError::fail(e.to_string()))?;
            check_seam_coordinates(&world.mesh, width).map_err(TestCaseError::fail)?;
            for (a, a0) in panel_areas(&world.mesh).iter().zip(&areas) {
                prop_assert!((a - a0).abs() <= 1e-14, "panel area {a} != {a0}");
            }
            let (m, p) = mass_and_momentum(&world);
            prop_assert!((m - m0).abs() <= 1e-15, "mass {m} != {m0}");
            prop_assert!((p - p0).length() <= 1e-14, "momentum {p:?} != {p0:?}");
        }
        loop {
            let parents = ad.hierarchy().expect("red-green").mergeable_parents();
            if parents.is_empty() {
                break;
            }
            let ops: Vec<_> = parents.iter().map(|&n| (RedGreenOp::Merge(n), None)).collect();
            ad.apply(&c, &mut world, &ops, 0).expect("merge");
        }
        prop_assert_eq!(world.mesh.triangles.len(), base.len());
        prop_assert!(corner_sets(&world.mesh) == base, "merged back, the corners differ");
    }
}

/// The tube's positions unrolled into the plane y = 0 (x = arc length from
/// the +x axis, the seam at the back opened up), or rolled back.
fn reshape(x: &mut [Vector], unroll: bool) {
    let r = 0.1;
    for p in x.iter_mut() {
        *p = match unroll {
            true => Vector::new(r * p.y.atan2(p.x), 0.0, p.z),
            false => Vector::new(r * (p.x / r).cos(), r * (p.x / r).sin(), p.z),
        };
    }
}

fn edge_config(refine_angle: Scalar, coarsen_angle: Scalar) -> AdaptConfig {
    AdaptConfig {
        refine_angle,
        coarsen_angle,
        max_level: 4,
        ..angle_config(AdaptMethod::Edge)
    }
}

/// One edge pass on `world` at thresholds (`refine`, `coarsen`) degrees, then
/// the checks of the red-green test.
fn edge_pass_and_check(
    ad: &mut Adapter,
    world: &mut World,
    (refine, coarsen): (Scalar, Scalar),
    before: (&[Scalar], Scalar, Vector),
    width: Scalar,
) -> Result<bool, TestCaseError> {
    let changed = ad
        .remesh(&edge_config(refine, coarsen), world, 0)
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    ad.check(world)
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    check_seam_coordinates(&world.mesh, width).map_err(TestCaseError::fail)?;
    for (a, a0) in panel_areas(&world.mesh).iter().zip(before.0) {
        prop_assert!((a - a0).abs() <= 1e-14, "panel area {a} != {a0}");
    }
    let (m, p) = mass_and_momentum(world);
    prop_assert!((m - before.1).abs() <= 1e-15, "mass {m} != {}", before.1);
    prop_assert!(
        (p - before.2).length() <= 1e-14,
        "momentum {p:?} != {:?}",
        before.2
    );
    Ok(changed)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    /// The edge method on a tube welded from two panels, rolled and unrolled
    /// at random between passes at random thresholds (splits where it is
    /// rolled, collapses and flips where it is flat): after every pass the
    /// checks of the red-green test hold.
    #[test]
    fn edge_method_across_a_welded_seam_keeps_both_panels_pattern_coordinates(
        rounds in prop::collection::vec((10.0f64..60.0, 0.5f64..5.0, any::<bool>()), 1..6),
    ) {
        let (mut world, width) = welded_tube();
        let mut ad = Adapter::new(&edge_config(15.0, 1.5), &world, DENSITY)
            .expect("edge method on a welded garment");
        let areas = panel_areas(&world.mesh);
        let (m0, p0) = mass_and_momentum(&world);
        let mut unrolled = false;
        for &(refine, coarsen, unroll) in &rounds {
            if unroll != unrolled {
                reshape(&mut world.x, unroll);
                unrolled = unroll;
            }
            let thresholds = (refine, coarsen.min(0.5 * refine));
            edge_pass_and_check(&mut ad, &mut world, thresholds, (&areas, m0, p0), width)?;
        }
    }
}

/// The edge method splits the welded seam's edges where the tube is rolled
/// (the new vertices join the seam, one coordinate per panel), and where it
/// is unrolled flat it collapses interior vertices but never a seam vertex.
#[test]
fn edge_splits_a_welded_seam_and_never_collapses_it() {
    let (mut world, width) = welded_tube();
    let mut ad = Adapter::new(&edge_config(15.0, 1.5), &world, DENSITY).expect("adapter");
    let before = (panel_areas(&world.mesh), mass_and_momentum(&world));
    let seam0 = check_seam_coordinates(&world.mesh, width).expect("seam");
    let at = (&before.0[..], before.1.0, before.1.1);
    edge_pass_and_check(&mut ad, &mut world, (10.0, 1.0), at, width).expect("split pass");
    let split = check_seam_coordinates(&world.mesh, width).expect("seam");
    let n_split = world.mesh.vertex_count();
    reshape(&mut world.x, true);
    for _ in 0..3 {
        edge_pass_and_check(&mut ad, &mut world, (60.0, 5.0), at, width).expect("flat pass");
    }
    let after = check_seam_coordinates(&world.mesh, width).expect("seam");
    println!(
        "seam vertices {seam0} -> {split} after the split pass ({n_split} vertices) -> {after} after three flat passes ({} vertices; stats {:?})",
        world.mesh.vertex_count(),
        ad.stats
    );
    assert!(split > seam0, "no seam edge split");
    assert!(world.mesh.vertex_count() < n_split, "nothing collapsed");
    assert!(after >= split, "a seam vertex collapsed");
}

/// Splitting every triangle along the seam puts the new midpoints on the seam:
/// each has one coordinate per panel, and the welded seams list them (what the
/// recording's seam segments follow).
#[test]
fn a_split_along_a_welded_seam_adds_its_midpoints_to_the_seam() {
    let (mut world, width) = welded_tube();
    let c = config();
    let mut ad = Adapter::new(&c, &world, DENSITY).expect("adapter");
    let before = check_seam_coordinates(&world.mesh, width).expect("seam");
    let listed = |w: &World| -> usize {
        let p = w.mesh.panels().expect("panels");
        p.seams.iter().map(|s| s.pairs.len()).sum()
    };
    let listed_before = listed(&world);
    let leaves = ad.hierarchy().expect("red-green").leaves();
    let ops: Vec<_> = leaves
        .iter()
        .map(|&l| (RedGreenOp::Split(l), None))
        .collect();
    ad.apply(&c, &mut world, &ops, 0).expect("split");
    ad.check(&world).expect("consistent");
    let after = check_seam_coordinates(&world.mesh, width).expect("seam");
    println!(
        "seam vertices {before} -> {after}; listed in the welded seams {listed_before} -> {}",
        listed(&world)
    );
    // Each seam's n vertices gain n - 1 midpoints.
    assert_eq!(after, 2 * before - 2);
    assert_eq!(listed(&world), after);
}

/// The skirt at a coarse base edge with red-green: no remeshing while the
/// seams are open, then the seams' neighbourhoods refine and the checks pass
/// after every step.
#[test]
fn a_garment_scene_remeshes_once_its_seams_are_welded() {
    let text = std::fs::read_to_string("scenes/skirt.toml").expect("skirt scene");
    let text = format!(
        "{text}\n[adapt]\nmethod = \"red_green\"\nrefine_angle = 8.0\nmax_level = 2\nrollback = false\n"
    );
    let sets = ["cloth.max_edge=0.06".to_string()];
    let scene = load_scene_str(&text, "skirt.toml", &sets).expect("scene");
    let mut sim = Sim::new(&scene);
    let (m0, _) = mass_and_momentum(&sim.state.world);
    let mut first_remesh = None;
    for step in 0..60 {
        let open = sim
            .state
            .world
            .mesh
            .panels()
            .expect("panels")
            .seams
            .iter()
            .any(|s| s.is_open());
        let triangles = sim.state.world.mesh.triangles.len();
        sim.step(0.005);
        let ad = sim.state.adapter.as_ref().expect("adapter");
        ad.check(&sim.state.world)
            .expect("consistent after the step");
        if open {
            assert!(
                sim.state.world.mesh.levels.iter().all(|&l| l == 0),
                "remeshed while a seam was open"
            );
        } else if first_remesh.is_none() && sim.state.world.mesh.triangles.len() != triangles {
            first_remesh = Some(step);
        }
    }
    let stats = sim.state.adapter.as_ref().expect("adapter").stats;
    assert!(!stats.awaiting_welds);
    let welded_at = sim.state.seams.iter().map(|s| match *s {
        SeamState::Welded { time } => time,
        SeamState::Open => Scalar::INFINITY,
    });
    let last_weld = welded_at.fold(0.0, Scalar::max);
    println!(
        "last weld at {last_weld:.3} s, remeshing from {:.3} s",
        stats.started_at
    );
    assert!(stats.started_at >= last_weld && stats.started_at < last_weld + 0.03);
    let w = &sim.state.world;
    let (m1, _) = mass_and_momentum(w);
    let refined = w.mesh.levels.iter().filter(|&&l| l > 0).count();
    println!(
        "first remesh after step {first_remesh:?}; {refined} of {} triangles refined; mass {m0:.15} -> {m1:.15} kg",
        w.mesh.triangles.len()
    );
    assert!(first_remesh.is_some(), "never remeshed");
    assert!((m1 - m0).abs() <= 1e-14);
}
