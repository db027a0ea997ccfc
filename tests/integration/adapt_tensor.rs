//! Adaptive meshing, method `tensor` (`src/adapt/tensor.rs`): whole grid lines
//! inserted where a rectangle bends, along the bend only; the state carried
//! onto the old surface; coarse again once flat; refined everywhere it is the
//! uniform grid.

use drape::adapt::{AdaptConfig, Adapter, check_consistency};
use drape::math::{Scalar, Vector, Vector2};
use drape::mesh::{self, Mesh};
use drape::scene::{AdaptCriterion, AdaptMethod, DiagonalPattern, SceneErrorKind, load_scene_str};
use drape::world::World;

const DENSITY: Scalar = 0.15;

fn tensor_config(refine_angle: Scalar, max_level: u8) -> AdaptConfig {
    AdaptConfig {
        refine_angle,
        coarsen_angle: refine_angle / 10.0,
        max_level,
        ..crate::common::angle_config(AdaptMethod::Tensor)
    }
}

/// A 1 m x 0.5 m sheet of `nu` x `nv` cells, shaped by `shape(u, v)`.
fn sheet(nu: u32, nv: u32, pattern: DiagonalPattern, shape: impl Fn(Vector2) -> Vector) -> World {
    let m = mesh::rectangle_cells(1.0, 0.5, nu, Some(nv), pattern).unwrap();
    let x = m.material.iter().map(|&p| shape(p)).collect();
    World::new(m, x)
}

/// A cylinder about the v axis over `u > 0` (flat before it), radius `r`:
/// bent along u only.
fn bent_along_u(r: Scalar) -> impl Fn(Vector2) -> Vector {
    move |p: Vector2| {
        if p.x <= 0.0 {
            Vector::new(p.x, p.y, 0.0)
        } else {
            let a = p.x / r;
            Vector::new(r * a.sin(), p.y, r * (1.0 - a.cos()))
        }
    }
}

/// Puts every vertex of `w` at `shape` of its material point.
fn shape_world(w: &mut World, shape: impl Fn(Vector2) -> Vector) {
    w.x = w.mesh.material.iter().map(|&p| shape(p)).collect();
}

/// Each world position's height interpolated linearly on `old` at material
/// point `p`: the old mesh's surface there (`None` if no triangle holds it).
fn on_surface(old: &Mesh, x: &[Vector], p: Vector2) -> Option<Vector> {
    old.triangles.iter().find_map(|t| {
        let [a, b, c] = t.map(|v| old.material[v as usize]);
        let d = (b - a).perp_dot(c - a);
        let l1 = (p - a).perp_dot(c - a) / d;
        let l2 = (b - a).perp_dot(p - a) / d;
        let l0 = 1.0 - l1 - l2;
        let tol = -1e-12;
        (l0 >= tol && l1 >= tol && l2 >= tol)
            .then(|| x[t[0] as usize] * l0 + x[t[1] as usize] * l1 + x[t[2] as usize] * l2)
    })
}

/// A sheet bent about one axis is refined along that axis only: the u-lines
/// multiply where it bends, the v-lines stay as they were, and every new
/// vertex lies on the old mesh's surface.
#[test]
fn a_sheet_bent_along_u_is_halved_along_u_only() {
    let mut w = sheet(8, 4, DiagonalPattern::Alternating, bent_along_u(0.3));
    let cfg = tensor_config(10.0, 4);
    let mut ad = Adapter::new(&cfg, &w, DENSITY).expect("a grid");
    let (u0, v0) = ad.tensor_grid().expect("tensor").lines();
    let old = w.mesh.clone();
    let old_x = w.x.clone();
    assert!(ad.remesh(&cfg, &mut w, 0).unwrap(), "the bend refines");
    let (u1, v1) = ad.tensor_grid().expect("tensor").lines();
    assert_eq!(v1, v0, "a bend along u does not halve rows");
    assert!(u1.len() > u0.len(), "u-lines {} -> {}", u0.len(), u1.len());
    let added: Vec<Scalar> = u1.iter().copied().filter(|u| !u0.contains(u)).collect();
    // Flat for u <= 0: the only columns there that may split are the one at
    // the crease and its neighbour (the one-halving rule).
    assert!(added.iter().all(|&u| u > -0.2), "added {added:?}");
    assert_eq!(w.mesh.vertex_count(), u1.len() * v1.len());
    let mut worst: Scalar = 0.0;
    for (i, p) in w.mesh.material.iter().enumerate() {
        let s = on_surface(&old, &old_x, *p).expect("inside the sheet");
        worst = worst.max((s - w.x[i]).length());
    }
    assert!(worst < 1e-12, "{worst:e}");
    check_consistency(&w, DENSITY, 0.5, 3.0).unwrap();
    ad.check(&w).unwrap();
}

/// A dome bends both ways, so lines are inserted along both axes and the
/// cell centres (midpoints of the old cells' diagonals) come out on the old
/// surface too, with either diagonal pattern. It would fail if the centre
/// took the other diagonal's midpoint (measured with that mistake: 1.04e-2 m
/// off; as it is: 5.6e-17 m).
#[test]
fn cell_centres_lie_on_the_old_diagonal() {
    for pattern in [DiagonalPattern::Alternating, DiagonalPattern::Regular] {
        let dome =
            |p: Vector2| Vector::new(p.x, p.y, 2.0 * p.x * p.x + 3.0 * p.y * p.y + p.x * p.y);
        let mut w = sheet(6, 4, pattern, dome);
        let cfg = tensor_config(5.0, 2);
        let mut ad = Adapter::new(&cfg, &w, DENSITY).expect("a grid");
        let old = w.mesh.clone();
        let old_x = w.x.clone();
        assert!(ad.remesh(&cfg, &mut w, 0).unwrap());
        let (u, v) = ad.tensor_grid().unwrap().lines();
        assert_eq!((u.len(), v.len()), (13, 9), "refined both ways");
        let worst = w
            .mesh
            .material
            .iter()
            .enumerate()
            .map(|(i, p)| (on_surface(&old, &old_x, *p).unwrap() - w.x[i]).length())
            .fold(0.0, Scalar::max);
        assert!(worst < 1e-12, "{pattern:?}: {worst:e}");
    }
}

/// Refined everywhere, the tensor grid is the uniform grid of its finest
/// cells: the same vertices in the same order and the same triangles with
/// the same diagonals, for both patterns.
#[test]
fn refined_everywhere_it_is_the_uniform_grid() {
    for pattern in [DiagonalPattern::Alternating, DiagonalPattern::Regular] {
        let bowl = |p: Vector2| Vector::new(p.x, p.y, 3.0 * (p.x * p.x + p.y * p.y));
        let mut w = sheet(4, 2, pattern, bowl);
        let cfg = tensor_config(0.5, 4);
        let mut ad = Adapter::new(&cfg, &w, DENSITY).expect("a grid");
        for step in 0..4 {
            shape_world(&mut w, bowl);
            ad.remesh(&cfg, &mut w, step).unwrap();
        }
        let uniform = mesh::rectangle_cells(1.0, 0.5, 16, Some(8), pattern).unwrap();
        assert_eq!(w.mesh.material, uniform.material, "{pattern:?}");
        assert_eq!(w.mesh.triangles, uniform.triangles, "{pattern:?}");
        assert!(w.mesh.levels.iter().all(|&l| l == 4));
    }
}

/// A bend that goes away leaves the sheet coarse again: after it is
/// flattened, the passes remove every line they added, within `max_level /
/// 2` passes, and the mesh is the base grid again. Both criteria.
#[test]
fn a_flattened_sheet_returns_to_the_base_grid() {
    for criterion in [AdaptCriterion::Angle, AdaptCriterion::Sizing] {
        let config = AdaptConfig {
            criterion,
            ..tensor_config(3.0, 6)
        };
        let mut w = sheet(8, 2, DiagonalPattern::Alternating, bent_along_u(0.2));
        let base = w.mesh.clone();
        let mut ad = Adapter::new(&config, &w, DENSITY).expect("a grid");
        for step in 0..3 {
            shape_world(&mut w, bent_along_u(0.2));
            ad.remesh(&config, &mut w, step).unwrap();
        }
        let refined = w.mesh.vertex_count();
        w.x = w.mesh.material.iter().map(|p| p.extend(0.0)).collect();
        let mut passes = 0;
        while ad.remesh(&config, &mut w, 10 + passes).unwrap() {
            ad.check(&w).expect("consistent after the pass");
            passes += 1;
            assert!(
                passes <= 3,
                "{criterion:?}: still coarsening after 3 passes"
            );
        }
        assert!(
            refined > base.vertex_count(),
            "{criterion:?}: {refined} vertices bent"
        );
        assert_eq!(w.mesh.material, base.material);
        assert_eq!(w.mesh.triangles, base.triangles);
        let stats = ad.stats;
        assert_eq!(stats.splits, stats.merges, "{stats:?}");
    }
}

/// Neighbouring columns differ by one halving at most: a split next to a
/// coarser column forces that column's split. A crease at u = 0 grades the
/// grid down to it; moved to u = 1/16, a line inside the refined patch, it
/// splits the columns at that line, whose outer neighbour is coarser.
#[test]
fn neighbouring_columns_differ_by_one_halving() {
    let crease = |at: Scalar| {
        move |p: Vector2| {
            let d = (p.x - at).max(0.0);
            Vector::new(p.x.min(at) + 0.6 * d, p.y, 0.8 * d)
        }
    };
    let mut w = sheet(4, 1, DiagonalPattern::Regular, crease(0.0));
    let cfg = tensor_config(1.0, 8);
    let mut ad = Adapter::new(&cfg, &w, DENSITY).expect("a grid");
    for step in 0..6 {
        let at = if step < 2 { 0.0 } else { 0.0625 };
        shape_world(&mut w, crease(at));
        ad.remesh(&cfg, &mut w, step).unwrap();
        ad.check(&w).expect("consistent after the pass");
        let (u, _) = ad.tensor_grid().unwrap().lines();
        let widths: Vec<Scalar> = u.windows(2).map(|p| p[1] - p[0]).collect();
        for p in widths.windows(2) {
            let r = p[0].max(p[1]) / p[0].min(p[1]);
            assert!(r < 2.0 + 1e-9, "pass {step}: neighbouring widths {p:?}");
        }
    }
    let (u, _) = ad.tensor_grid().unwrap().lines();
    assert!(
        u.windows(2).any(|p| p[1] - p[0] < 0.25 / 16.0 + 1e-12),
        "refined to level 8"
    );
    assert!(ad.stats.closure_splits > 0, "{:?}", ad.stats);
}

/// The method needs a rectangle's grid, an even `max_level`, and no rollback,
/// multirate or level-scaled stiffness: the scene says so at the key, and the
/// library refuses another mesh.
#[test]
fn tensor_needs_a_rectangle() {
    let base = r#"name = "t"
[simulation]
duration = 1.0
[cloth]
shape = "disk"
radius = 0.5
resolution = 8
[material]
density = 0.15
stretch = 200.0
[adapt]
method = "tensor"
"#;
    let e = load_scene_str(base, "t.toml", &[]).expect_err("a disk");
    assert_eq!(
        (e.kind, e.key.as_deref(), e.line),
        (
            SceneErrorKind::NotApplicable,
            Some("adapt.method"),
            Some(12)
        ),
        "{e}"
    );
    let rect = base.replace(
        "shape = \"disk\"\nradius = 0.5",
        "shape = \"rectangle\"\nwidth = 1.0\nheight = 1.0",
    );
    load_scene_str(&rect, "t.toml", &[]).expect("a rectangle");
    for (set, key, kind) in [
        (
            "adapt.rollback=true",
            "adapt.rollback",
            SceneErrorKind::NotApplicable,
        ),
        (
            "simulation.integrator=rk4",
            "",
            SceneErrorKind::NotApplicable,
        ),
        (
            "adapt.max_level=5",
            "adapt.max_level",
            SceneErrorKind::OutOfRange,
        ),
        (
            "material.stiffness_rule=paper_a",
            "material.stiffness_rule",
            SceneErrorKind::NotApplicable,
        ),
    ] {
        let mut sets = vec![set.to_owned()];
        let key = if key.is_empty() {
            // Multirate needs an explicit integrator before it reaches the method.
            sets.push("adapt.multirate=true".to_owned());
            "adapt.multirate"
        } else {
            key
        };
        let e = load_scene_str(&rect, "t.toml", &sets).expect_err(set);
        assert_eq!((e.kind, e.key.as_deref()), (kind, Some(key)), "{e}");
    }
    let disk = mesh::disk(0.5, 8).unwrap();
    let x = disk.material.iter().map(|p| p.extend(0.0)).collect();
    let cfg = tensor_config(5.0, 4);
    let e = Adapter::new(&cfg, &World::new(disk, x), DENSITY).expect_err("not a grid");
    assert!(
        e.to_string()
            .contains("needs the grid of a generated rectangle"),
        "{e}"
    );
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]
    /// Random sequences of creases (where, which way, how sharp; a crease
    /// moving away leaves lines to remove while others are inserted, on
    /// either axis): after every pass every vertex lies on the old mesh's
    /// surface, the world's mesh is the grid of the kept lines (vertices,
    /// triangles, diagonals, each line the middle of its parent column), and
    /// neighbouring columns differ by one halving at most.
    #[test]
    fn random_passes_keep_the_mesh_the_grid(
        creases in proptest::collection::vec((-0.9f64..0.9, proptest::bool::ANY, 0.0f64..1.2), 1..8),
        alternating in proptest::bool::ANY,
    ) {
        let pattern = if alternating { DiagonalPattern::Alternating } else { DiagonalPattern::Regular };
        let mut w = sheet(6, 3, pattern, |p: Vector2| p.extend(0.0));
        let cfg = tensor_config(5.0, 6);
        let mut ad = Adapter::new(&cfg, &w, DENSITY).expect("a grid");
        for (step, &(at, along_u, angle)) in creases.iter().enumerate() {
            // Within the sheet: |u| < 0.5, |v| < 0.25.
            let at = at * if along_u { 0.5 } else { 0.25 };
            let fold = |p: Vector2| {
                let (s, t) = if along_u { (p.x, p.y) } else { (p.y, p.x) };
                let d = (s - at).max(0.0);
                let (bent_s, z) = (s.min(at) + d * angle.cos(), d * angle.sin());
                if along_u { Vector::new(bent_s, t, z) } else { Vector::new(t, bent_s, z) }
            };
            shape_world(&mut w, fold);
            let (old, old_x) = (w.mesh.clone(), w.x.clone());
            ad.remesh(&cfg, &mut w, step as u64).unwrap();
            for (i, p) in w.mesh.material.iter().enumerate() {
                let s = on_surface(&old, &old_x, *p).expect("inside the sheet");
                proptest::prop_assert!((s - w.x[i]).length() < 1e-12, "pass {}: vertex {} off the old surface", step, i);
            }
            let checked = ad.check(&w);
            proptest::prop_assert!(checked.is_ok(), "pass {}: {:?}", step, checked);
        }
    }
}

/// A sheet sheared and stretched unevenly in its plane, flat, does not
/// refine: the measure is the grid lines' bend out of the surface, not their
/// curving within it (with the whole turn, the first version's measure, the
/// pass made 12 splits here).
#[test]
fn a_flat_sheet_distorted_in_its_plane_does_not_refine() {
    let swirl = |p: Vector2| Vector::new(p.x + 0.3 * p.y * p.y, p.y + 0.2 * p.x * p.x, 0.0);
    let mut w = sheet(8, 4, DiagonalPattern::Alternating, swirl);
    let cfg = tensor_config(2.0, 4);
    let mut ad = Adapter::new(&cfg, &w, DENSITY).expect("a grid");
    let changed = ad.remesh(&cfg, &mut w, 0).unwrap();
    assert!(!changed, "in-plane distortion refined: {:?}", ad.stats);
    // The same sheet rolled out of its plane refines.
    let rolled = |p: Vector2| {
        let q = swirl(p);
        Vector::new(q.x, 0.3 * q.y.sin(), 0.3 * (1.0 - q.y.cos()))
    };
    shape_world(&mut w, rolled);
    assert!(ad.remesh(&cfg, &mut w, 1).unwrap());
}

/// Pins, `min_edge_length` and events: a line inserted across a pinned
/// edge pins its midpoints with the same pin (and removing it drops them);
/// no split makes a column narrower than `min_edge_length`; each inserted
/// line is one split event at its level with the angle that asked for it.
#[test]
fn pins_min_edge_and_events() {
    let config = AdaptConfig {
        min_edge_length: 0.05,
        ..tensor_config(5.0, 8)
    };
    let mut w = sheet(8, 2, DiagonalPattern::Alternating, bent_along_u(0.2));
    let top = |w: &World| -> Vec<u32> {
        (0..w.mesh.vertex_count() as u32)
            .filter(|&v| w.mesh.material[v as usize].y == 0.25)
            .collect()
    };
    let pinned_top = |w: &World| {
        let mut p: Vec<u32> = w.pins.anchors.iter().map(|a| a.vertex).collect();
        p.sort_unstable();
        p
    };
    w.pins.anchors = top(&w)
        .into_iter()
        .map(|v| drape::pins::Anchor {
            vertex: v,
            pin: 0,
            start: w.x[v as usize],
        })
        .collect();
    let mut ad = Adapter::new(&config, &w, DENSITY).expect("a grid");
    for step in 0..4 {
        shape_world(&mut w, bent_along_u(0.2));
        ad.remesh(&config, &mut w, step).unwrap();
        assert_eq!(
            pinned_top(&w),
            top(&w),
            "pass {step}: the top edge is pinned"
        );
    }
    let (u, _) = ad.tensor_grid().unwrap().lines();
    let narrowest = u.windows(2).map(|p| p[1] - p[0]).fold(1.0, Scalar::min);
    assert!((0.05 - 1e-12..0.1).contains(&narrowest), "{narrowest}");
    let events = ad.take_events();
    let asked: Vec<_> = events
        .iter()
        .filter(|e| e.kind == drape::adapt::EventKind::Split)
        .collect();
    assert_eq!(
        asked.len() as u64 + ad.stats.closure_splits,
        ad.stats.splits,
        "split events at levels {:?}",
        asked.iter().map(|e| e.level).collect::<Vec<_>>()
    );
    assert_eq!(
        ad.stats.splits as usize,
        u.len() - 9,
        "one split per inserted line"
    );
    assert!(
        asked
            .iter()
            .all(|e| e.angle.is_some_and(|a| a > 5.0) && e.level % 2 == 0 && e.level >= 2)
    );
    // Flat again: every inserted line goes, with its pinned midpoints.
    w.x = w.mesh.material.iter().map(|p| p.extend(0.0)).collect();
    for step in 4..10 {
        ad.remesh(&config, &mut w, step).unwrap();
    }
    assert_eq!(w.mesh.vertex_count(), 9 * 3);
    assert_eq!(pinned_top(&w), top(&w));
}
