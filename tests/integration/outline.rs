//! Panel outlines meshed by `mesh_outline`: a square, a trapezoid, a clockwise
//! outline and a concave L at several edge lengths. Each mesh is checked to
//! cover exactly its polygon (area, boundary edges = the side chains, no point
//! outside), to keep its sides' division points (collinear, evenly spaced,
//! corner to corner) and to be a valid manifold for `Mesh::new`; the measured
//! area deviation, longest edge and smallest angle are printed. Every refused
//! input gives its own error.

use std::collections::BTreeSet;

use drape::math::{Scalar, Vector2};
use drape::mesh::{
    MAX_OUTLINE_POINTS, Mesh, OutlineError, OutlineMesh, mesh_outline, segments_for,
};

fn v(x: Scalar, y: Scalar) -> Vector2 {
    Vector2::new(x, y)
}

fn square() -> Vec<Vector2> {
    vec![v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)]
}

fn trapezoid() -> Vec<Vector2> {
    vec![v(-0.6, 0.0), v(0.6, 0.0), v(0.35, 0.7), v(-0.25, 0.7)]
}

/// An L: a 1 m square with its upper right 0.6 m x 0.6 m quarter cut away.
fn l_shape() -> Vec<Vector2> {
    vec![
        v(0.0, 0.0),
        v(1.0, 0.0),
        v(1.0, 0.4),
        v(0.4, 0.4),
        v(0.4, 1.0),
        v(0.0, 1.0),
    ]
}

/// Each side's segment count for edges of `max_edge`.
fn counts(outline: &[Vector2], max_edge: Scalar) -> Vec<usize> {
    (0..outline.len())
        .map(|i| {
            segments_for(
                outline[i].distance(outline[(i + 1) % outline.len()]),
                max_edge,
            )
        })
        .collect()
}

fn polygon_area(outline: &[Vector2]) -> Scalar {
    let n = outline.len();
    0.5 * (0..n)
        .map(|i| outline[i].perp_dot(outline[(i + 1) % n]))
        .sum::<Scalar>()
}

/// Winding number of `outline` around `p` (0 outside; `p` is not on a side).
fn winding(outline: &[Vector2], p: Vector2) -> i32 {
    let n = outline.len();
    let mut w = 0;
    for i in 0..n {
        let (a, b) = (outline[i], outline[(i + 1) % n]);
        let side = (b - a).perp_dot(p - a);
        if a.y <= p.y && b.y > p.y && side > 0.0 {
            w += 1;
        } else if a.y > p.y && b.y <= p.y && side < 0.0 {
            w -= 1;
        }
    }
    w
}

/// Measured quality of a mesh.
struct Quality {
    area_deviation: Scalar,
    edge_ratio: Scalar,
    min_angle_deg: Scalar,
}

/// Checks the side chains of `mesh` against `outline` and `segments`.
fn check_sides(outline: &[Vector2], segments: &[usize], mesh: &OutlineMesh) {
    let n = outline.len();
    assert_eq!(mesh.sides.len(), n);
    for (i, chain) in mesh.sides.iter().enumerate() {
        let (a, b) = (outline[i], outline[(i + 1) % n]);
        assert_eq!(chain.len(), segments[i] + 1, "side {i}'s chain");
        let at = |k: usize| mesh.points[chain[k] as usize];
        assert_eq!(at(0), a, "side {i} starts at corner {i}");
        assert_eq!(at(segments[i]), b, "side {i} ends at the next corner");
        assert_eq!(chain[segments[i]], mesh.sides[(i + 1) % n][0]);
        let (length, step) = (a.distance(b), a.distance(b) / segments[i] as Scalar);
        for k in 0..=segments[i] {
            let off_line = (b - a).perp_dot(at(k) - a).abs() / length;
            assert!(
                off_line <= 1e-12 * length,
                "side {i} point {k} is off its side"
            );
            let along = (at(k) - a).dot(b - a) / length;
            assert!((along - k as Scalar * step).abs() <= 1e-12 * length);
        }
    }
}

/// Checks a mesh of `outline` (its longest edge at most `edge_bound` times
/// `max_edge`) and returns its measured quality.
fn check(
    outline: &[Vector2],
    segments: &[usize],
    max_edge: Scalar,
    edge_bound: Scalar,
) -> (OutlineMesh, Quality) {
    let mesh = mesh_outline(outline, segments, max_edge).expect("the outline meshes");
    check_sides(outline, segments, &mesh);
    let (mut area, mut longest, mut min_angle) = (0.0, 0.0 as Scalar, Scalar::INFINITY);
    let mut used = vec![false; mesh.points.len()];
    for tri in &mesh.triangles {
        let [a, b, c] = tri.map(|k| mesh.points[k as usize]);
        let twice = (b - a).perp_dot(c - a);
        assert!(twice > 0.0, "triangle {tri:?} is counter-clockwise");
        area += 0.5 * twice;
        for (p, q, r) in [(a, b, c), (b, c, a), (c, a, b)] {
            longest = longest.max(p.distance(q));
            min_angle = min_angle.min((q - p).angle_to(r - p).abs().to_degrees());
        }
        assert_ne!(
            winding(outline, (a + b + c) / 3.0),
            0,
            "triangle {tri:?} is inside"
        );
        tri.iter().for_each(|&k| used[k as usize] = true);
    }
    assert!(used.iter().all(|&u| u), "every point is used");
    let exact = polygon_area(outline).abs();
    let quality = Quality {
        area_deviation: (area - exact).abs() / exact,
        edge_ratio: longest / max_edge,
        min_angle_deg: min_angle,
    };
    assert!(
        quality.area_deviation < 1e-12,
        "area {area} against {exact}"
    );
    assert!(quality.edge_ratio <= edge_bound, "longest edge {longest} m");
    // The mesh is a valid manifold whose boundary is exactly the side chains.
    let cloth = Mesh::new(mesh.points.clone(), mesh.triangles.clone()).expect("a valid mesh");
    let boundary: BTreeSet<[u32; 2]> = cloth
        .edges
        .iter()
        .filter(|e| !e.is_interior())
        .map(|e| e.vertices)
        .collect();
    let chains: BTreeSet<[u32; 2]> = mesh
        .sides
        .iter()
        .flat_map(|c| c.windows(2).map(|w| [w[0].min(w[1]), w[0].max(w[1])]))
        .collect();
    assert_eq!(boundary, chains, "the mesh boundary is the side chains");
    (mesh, quality)
}

/// Meshes `outline` at each edge length with `segments_for` counts and prints the figures.
fn ladder(name: &str, outline: &[Vector2], edges: &[Scalar]) {
    for &h in edges {
        let (mesh, q) = check(outline, &counts(outline, h), h, 1.5);
        report(name, h, &mesh, &q);
    }
}

fn report(name: &str, h: Scalar, mesh: &OutlineMesh, q: &Quality) {
    println!(
        "{name} h={h}: {} points, {} triangles; area deviation {:.2e}, \
         longest edge {:.3} h, smallest angle {:.1} deg",
        mesh.points.len(),
        mesh.triangles.len(),
        q.area_deviation,
        q.edge_ratio,
        q.min_angle_deg
    );
}

#[test]
fn outline_square_at_several_edge_lengths() {
    ladder("square", &square(), &[0.3, 0.1, 0.037, 0.01]);
}

#[test]
fn outline_trapezoid_at_several_edge_lengths() {
    ladder("trapezoid", &trapezoid(), &[0.3, 0.1, 0.037, 0.01]);
}

#[test]
fn outline_concave_l_shape_stays_inside() {
    ladder("L", &l_shape(), &[0.25, 0.1, 0.03]);
}

#[test]
fn outline_sharp_corner_and_short_side() {
    // An 11.3 degree corner at the origin and a 2 cm side next to 1 m sides:
    // the smallest angle is the corner's, which refinement cannot widen.
    let sharp = vec![v(0.0, 0.0), v(1.0, 0.0), v(1.0, 0.02), v(0.8, 0.16)];
    for h in [0.05, 0.01] {
        let (mesh, q) = check(&sharp, &counts(&sharp, h), h, 1.5);
        report("sharp corner", h, &mesh, &q);
    }
}

#[test]
fn outline_clockwise_keeps_the_callers_sides() {
    let ccw = trapezoid();
    let cw: Vec<Vector2> = ccw.iter().rev().copied().collect();
    let h = 0.1;
    let (fwd, qf) = check(&ccw, &counts(&ccw, h), h, 1.5);
    let (rev, qr) = check(&cw, &counts(&cw, h), h, 1.5);
    println!(
        "clockwise trapezoid h={h}: area deviation {:.2e} (counter-clockwise {:.2e}), \
         {} and {} points",
        qr.area_deviation,
        qf.area_deviation,
        rev.points.len(),
        fwd.points.len()
    );
    // The clockwise outline's side 0 runs from its corner 0 to its corner 1
    // (check_sides), which is the counter-clockwise outline's last side reversed.
    let (a, b) = (rev.sides[0][0], *rev.sides[0].last().expect("points"));
    assert_eq!(
        (rev.points[a as usize], rev.points[b as usize]),
        (cw[0], cw[1])
    );
}

#[test]
fn outline_uneven_segment_counts_are_kept() {
    // A seam may ask for more or fewer segments than the edge length gives
    // (side 1's 0.5 m segments are longer than the 0.2 m edge length).
    let segments = [7, 2, 13, 3];
    let (mesh, q) = check(&square(), &segments, 0.2, Scalar::INFINITY);
    let lengths: Vec<usize> = mesh.sides.iter().map(Vec::len).collect();
    println!(
        "square with segments {segments:?}: chains of {lengths:?} points, longest edge {:.3} h",
        q.edge_ratio
    );
}

#[test]
fn outline_is_deterministic() {
    let outline = l_shape();
    let segments = counts(&outline, 0.05);
    let first = mesh_outline(&outline, &segments, 0.05).expect("meshes");
    let second = mesh_outline(&outline, &segments, 0.05).expect("meshes");
    assert_eq!(first, second);
}

#[test]
fn outline_segments_for() {
    assert_eq!(segments_for(1.0, 0.3), 4);
    assert_eq!(
        segments_for(0.9, 0.3),
        3,
        "a whole multiple within rounding"
    );
    assert_eq!(segments_for(0.1, 0.3), 1);
    assert_eq!(segments_for(0.0, 0.3), 1);
}

/// The error for meshing `outline` with one segment per side at 0.1 m.
fn refused(outline: &[Vector2]) -> OutlineError {
    let err = mesh_outline(outline, &vec![1; outline.len()], 0.1).expect_err("refused");
    println!("{err}");
    err
}

#[test]
fn outline_refuses_bad_input() {
    use OutlineError::*;
    let sq = square();
    assert_eq!(refused(&sq[..2]), TooFewCorners { count: 2 });
    let nan = vec![v(0.0, 0.0), v(Scalar::NAN, 0.0), v(1.0, 1.0)];
    assert!(matches!(refused(&nan), NonFinite { corner: 1, .. }));
    let huge = vec![v(0.0, 0.0), v(1e70, 0.0), v(1.0, 1.0)];
    assert!(matches!(refused(&huge), OutOfRange { .. }));
    let repeated = vec![v(0.0, 0.0), v(1.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)];
    assert!(matches!(
        refused(&repeated),
        ZeroLengthSide {
            side: 1,
            next: 2,
            ..
        }
    ));
    let bow_tie = vec![v(0.0, 0.0), v(1.0, 1.0), v(1.0, 0.0), v(0.0, 1.0)];
    assert_eq!(refused(&bow_tie), SelfIntersecting { a: 0, b: 2 });
    // Corner 3 lies on side 0 (side 3 also doubles back along side 0).
    let touching = vec![v(0.0, 0.0), v(2.0, 0.0), v(2.0, 2.0), v(1.0, 0.0)];
    assert_eq!(refused(&touching), SelfIntersecting { a: 0, b: 2 });
    let flat = vec![v(0.0, 0.0), v(1.0, 0.0), v(2.0, 0.0)];
    assert_eq!(refused(&flat), SelfIntersecting { a: 0, b: 2 });
    let err = mesh_outline(&sq, &[1, 1, 1], 0.1).expect_err("refused");
    assert_eq!(
        err,
        SegmentCountMismatch {
            sides: 4,
            counts: 3
        }
    );
    let err = mesh_outline(&sq, &[1, 1, 0, 1], 0.1).expect_err("refused");
    assert_eq!(err, ZeroSegments { side: 2 });
    for bad in [0.0, -0.1, Scalar::NAN, Scalar::INFINITY] {
        let err = mesh_outline(&sq, &[1; 4], bad).expect_err("refused");
        assert!(matches!(err, BadMaxEdge { .. }), "{err}");
    }
    let err = mesh_outline(&sq, &[1; 4], 1e-4).expect_err("refused");
    println!("{err}");
    assert!(matches!(
        err,
        TooManyPoints {
            limit: MAX_OUTLINE_POINTS,
            ..
        }
    ));
    assert!(err.to_string().contains(&MAX_OUTLINE_POINTS.to_string()));
}

#[test]
fn outline_refuses_a_needle() {
    // A triangle 1 m long and 1 nm wide at its base meshes; one a hundred
    // femtometres wide gives triangles too thin for `Mesh::new`, and is refused.
    let needle = |width| vec![v(0.0, 0.0), v(1.0, 0.0), v(0.0, width)];
    let thin = mesh_outline(&needle(1e-9), &[10, 10, 1], 0.1).expect("meshes");
    Mesh::new(thin.points, thin.triangles).expect("a valid mesh");
    let err = mesh_outline(&needle(1e-13), &[10, 10, 1], 0.1).expect_err("refused");
    println!("{err}");
    assert!(matches!(err, OutlineError::Degenerate { .. }));
}
