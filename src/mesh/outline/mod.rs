//! Triangulation of a garment panel's 2D outline (a sewing-pattern polygon, m).
//!
//! Each side of the outline is divided into a given number of equal segments
//! (so that the two sides of a seam can be given the same count), the points
//! are joined by a constrained Delaunay triangulation (spade) with the sides as
//! constraints, and the interior is refined (Ruppert-style Delaunay refinement)
//! until its triangles are about the target edge length across. Refinement
//! never splits a side's segments: each side keeps exactly its segment count.

mod polygon;

use spade::handles::FixedVertexHandle;
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, MAX_ALLOWED_VALUE, MIN_ALLOWED_VALUE, Point2,
    RefinementParameters, Triangulation,
};

use crate::math::{Scalar, Vector2};
use polygon::{check_simple, orient, polygon_area};

/// The most points [`mesh_outline`] creates for one outline; an outline whose
/// mesh would need more is refused with [`OutlineError::TooManyPoints`].
pub const MAX_OUTLINE_POINTS: usize = 2_000_000;

/// Smallest angle the interior refinement aims for, degrees. Up to 30 degrees
/// refinement terminates reliably; corners sharper than this keep their angle.
pub const OUTLINE_ANGLE_LIMIT_DEG: Scalar = 28.0;

type Cdt = ConstrainedDelaunayTriangulation<Point2<Scalar>>;

/// A panel's outline meshed: points in pattern coordinates, counter-clockwise
/// triangles, and for each side of the outline the chain of vertex indices along it.
#[derive(Debug, Clone, PartialEq)]
pub struct OutlineMesh {
    /// Pattern (material) coordinates, m: the side points first (side 0 from
    /// corner 0, then side 1, ...), then the interior points. Every point is
    /// used by a triangle.
    pub points: Vec<Vector2>,
    /// Triangles, counter-clockwise in pattern coordinates, all inside the outline.
    pub triangles: Vec<[u32; 3]>,
    /// For side `i` (corner `i` to corner `i + 1`, the last side closing the
    /// outline), the `segments[i] + 1` points along it from corner `i` to
    /// corner `i + 1`, equally spaced.
    pub sides: Vec<Vec<u32>>,
}

/// Why an outline cannot be meshed. Sides and corners are numbered from 0.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OutlineError {
    /// Fewer than three corners.
    #[error("an outline needs at least 3 corners, this one has {count}")]
    TooFewCorners {
        /// Number of corners given.
        count: usize,
    },
    /// The segment counts do not match the sides.
    #[error("the outline has {sides} sides but {counts} segment counts were given (one per side)")]
    SegmentCountMismatch {
        /// Number of sides (= corners).
        sides: usize,
        /// Number of segment counts given.
        counts: usize,
    },
    /// A side is to be divided into zero segments.
    #[error("side {side} (0-based) is to be divided into 0 segments; each side needs at least 1")]
    ZeroSegments {
        /// The side, 0-based.
        side: usize,
    },
    /// The target edge length is not a positive finite number.
    #[error("the target edge length must be a positive finite number of metres, got {max_edge}")]
    BadMaxEdge {
        /// The value given.
        max_edge: Scalar,
    },
    /// A corner coordinate is NaN or infinite.
    #[error("corner {corner} (0-based) has a coordinate that is not a finite number: {value}")]
    NonFinite {
        /// The corner, 0-based.
        corner: usize,
        /// The offending coordinate.
        value: Scalar,
    },
    /// A point is too far out or too close to zero for the triangulator.
    #[error(
        "the point ({x:e}, {y:e}) is out of the triangulator's range: coordinates must be 0 \
         or between {MIN_ALLOWED_VALUE:e} and {MAX_ALLOWED_VALUE:e} m in magnitude"
    )]
    OutOfRange {
        /// The point's x coordinate, m.
        x: Scalar,
        /// The point's y coordinate, m.
        y: Scalar,
    },
    /// Two consecutive corners coincide.
    #[error(
        "side {side} (0-based) has zero length: corners {side} and {next} are both at ({x}, {y})"
    )]
    ZeroLengthSide {
        /// The side, 0-based.
        side: usize,
        /// The corner it ends at, 0-based.
        next: usize,
        /// The corners' x coordinate, m.
        x: Scalar,
        /// The corners' y coordinate, m.
        y: Scalar,
    },
    /// Two sides cross or touch (other than adjacent sides at their shared corner).
    #[error(
        "the outline intersects itself: sides {a} and {b} (0-based) cross or touch; \
         a panel outline must be a simple polygon"
    )]
    SelfIntersecting {
        /// The first side, 0-based.
        a: usize,
        /// The second side, 0-based.
        b: usize,
    },
    /// The division points of a side touch or cross another side within rounding.
    #[error(
        "side {side} (0-based), divided into its segments, touches or crosses another side \
         within rounding: the outline comes too close to itself there"
    )]
    NearlyTouching {
        /// The side, 0-based.
        side: usize,
    },
    /// The mesh would need more points than [`MAX_OUTLINE_POINTS`].
    #[error(
        "meshing this outline (area {area:.4e} m^2, {boundary} side points) with edges of \
         {max_edge:e} m needs about {estimate:.3e} points, more than the limit of {limit}; \
         use a longer edge length or fewer segments"
    )]
    TooManyPoints {
        /// The outline's area, m^2.
        area: Scalar,
        /// Number of points along the sides.
        boundary: Scalar,
        /// The target edge length, m.
        max_edge: Scalar,
        /// The estimated number of points.
        estimate: Scalar,
        /// The limit, [`MAX_OUTLINE_POINTS`].
        limit: usize,
    },
    /// Refinement did not finish within its budget of points.
    #[error(
        "refining the outline's interior did not finish within {budget} points (about \
         {expected} expected); the outline may have features far finer than the edge length"
    )]
    RefinementUnfinished {
        /// The number of points refinement was allowed.
        budget: usize,
        /// The number of points expected.
        expected: usize,
    },
    /// The outline is so thin somewhere that a triangle comes out with (nearly) zero area.
    #[error(
        "the outline is too thin to triangulate near ({x}, {y}): a triangle there has an \
         area of {area:e} m^2, under 1e-12 of its longest edge squared ({longest:e} m long)"
    )]
    Degenerate {
        /// x of the triangle's first corner, m.
        x: Scalar,
        /// y of the triangle's first corner, m.
        y: Scalar,
        /// The triangle's area, m^2.
        area: Scalar,
        /// Its longest edge, m.
        longest: Scalar,
    },
}

/// How many equal segments a side of `length` needs so that none is longer than
/// `max_edge`: `ceil(length / max_edge)`, at least 1. A length within a relative
/// 1e-9 above a whole multiple of `max_edge` counts as that multiple (so that
/// rounding in the length does not add a segment). Both arguments are expected
/// to be positive and finite; otherwise the answer is 1.
pub fn segments_for(length: Scalar, max_edge: Scalar) -> usize {
    let ratio = length / max_edge;
    if !ratio.is_finite() || ratio <= 0.0 {
        return 1;
    }
    ((ratio * (1.0 - 1e-9)).ceil() as usize).max(1)
}

/// Meshes a panel outline: side `i` (from corner `i` to corner `i + 1`, the last
/// side closing the polygon) is divided into `segments[i]` equal segments, and
/// the interior is filled with triangles about `max_edge` across (largest area
/// about that of an equilateral triangle of side `max_edge`, smallest angle
/// about [`OUTLINE_ANGLE_LIMIT_DEG`] where the outline's corners allow it;
/// the longest edges come out about 1.4 `max_edge`).
///
/// The outline may run clockwise or counter-clockwise: the triangles are
/// counter-clockwise in pattern coordinates either way, while `sides` keeps the
/// caller's numbering and direction. The outline must be a simple polygon
/// (no two sides crossing or touching). The result is deterministic: the same
/// input gives the same mesh.
///
/// # Errors
///
/// [`OutlineError`] names what is wrong with the input: too few corners,
/// mismatched or zero segment counts, a bad edge length, a non-finite or
/// out-of-range coordinate, a zero-length side, crossing or touching sides, an
/// outline too thin to triangulate, or a mesh of more than
/// [`MAX_OUTLINE_POINTS`] points.
pub fn mesh_outline(
    outline: &[Vector2],
    segments: &[usize],
    max_edge: Scalar,
) -> Result<OutlineMesh, OutlineError> {
    validate(outline, segments, max_edge)?;
    check_simple(outline)?;
    let area = polygon_area(outline).abs();
    let boundary = segments.iter().map(|&s| s as Scalar).sum::<Scalar>();
    // An equilateral mesh of edge h has one point per sqrt(3)/2 h^2 of area.
    let estimate = boundary + area / (0.75_f64.sqrt() * max_edge * max_edge);
    if estimate.is_nan() || estimate > MAX_OUTLINE_POINTS as Scalar {
        return Err(OutlineError::TooManyPoints {
            area,
            boundary,
            max_edge,
            estimate,
            limit: MAX_OUTLINE_POINTS,
        });
    }
    let (points, sides) = side_points(outline, segments);
    let mut cdt = constrained(&points, &sides)?;
    // Refinement typically lands within twice the estimate; the budget leaves
    // room for graded regions near short sides and sharp corners.
    let expected = estimate.ceil() as usize;
    let budget = (4 * expected + 10_000).min(MAX_OUTLINE_POINTS);
    let parameters = RefinementParameters::<Scalar>::new()
        .exclude_outer_faces(true)
        .keep_constraint_edges()
        .with_max_allowed_area(0.75_f64.sqrt() / 2.0 * max_edge * max_edge)
        .with_angle_limit(AngleLimit::from_deg(OUTLINE_ANGLE_LIMIT_DEG))
        .with_max_additional_vertices(budget.saturating_sub(points.len()));
    if !cdt.refine(parameters).refinement_complete {
        return Err(OutlineError::RefinementUnfinished { budget, expected });
    }
    let (points, triangles) = inside_mesh(&cdt, points.len())?;
    Ok(OutlineMesh {
        points,
        triangles,
        sides,
    })
}

/// Checks the counts, the edge length and the corners' coordinates.
fn validate(outline: &[Vector2], segments: &[usize], max_edge: Scalar) -> Result<(), OutlineError> {
    let n = outline.len();
    if n < 3 {
        return Err(OutlineError::TooFewCorners { count: n });
    }
    if segments.len() != n {
        return Err(OutlineError::SegmentCountMismatch {
            sides: n,
            counts: segments.len(),
        });
    }
    if !(max_edge.is_finite() && max_edge > 0.0) {
        return Err(OutlineError::BadMaxEdge { max_edge });
    }
    for (corner, p) in outline.iter().enumerate() {
        if let Some(value) = [p.x, p.y].into_iter().find(|c| !c.is_finite()) {
            return Err(OutlineError::NonFinite { corner, value });
        }
        let in_range =
            |c: Scalar| c == 0.0 || (MIN_ALLOWED_VALUE..=MAX_ALLOWED_VALUE).contains(&c.abs());
        if !(in_range(p.x) && in_range(p.y)) {
            return Err(OutlineError::OutOfRange { x: p.x, y: p.y });
        }
    }
    if let Some(side) = segments.iter().position(|&s| s == 0) {
        return Err(OutlineError::ZeroSegments { side });
    }
    for side in 0..n {
        let next = (side + 1) % n;
        let p = outline[side];
        if p == outline[next] {
            return Err(OutlineError::ZeroLengthSide {
                side,
                next,
                x: p.x,
                y: p.y,
            });
        }
    }
    Ok(())
}

/// The points dividing each side into its segments (each corner once, at the
/// start of its side) and each side's chain of point indices.
fn side_points(outline: &[Vector2], segments: &[usize]) -> (Vec<Vector2>, Vec<Vec<u32>>) {
    let n = outline.len();
    let total: usize = segments.iter().sum();
    let mut points = Vec::with_capacity(total);
    let mut sides = Vec::with_capacity(n);
    for (i, &count) in segments.iter().enumerate() {
        let (a, b) = (outline[i], outline[(i + 1) % n]);
        let start = points.len();
        points.extend((0..count).map(|k| a + (b - a) * (k as Scalar / count as Scalar)));
        let end = if i + 1 == n { 0 } else { start + count };
        let mut chain: Vec<u32> = (start..start + count).map(|v| v as u32).collect();
        chain.push(end as u32);
        sides.push(chain);
    }
    (points, sides)
}

/// The constrained Delaunay triangulation of the side points with every side
/// segment a constraint. Point `k` is the triangulation's vertex `k`.
fn constrained(points: &[Vector2], sides: &[Vec<u32>]) -> Result<Cdt, OutlineError> {
    let mut cdt = Cdt::new();
    for (k, p) in points.iter().enumerate() {
        let handle = cdt
            .insert(Point2::new(p.x, p.y))
            .map_err(|_| OutlineError::OutOfRange { x: p.x, y: p.y })?;
        if handle.index() != k {
            // The point coincides with an earlier one: two sides touch.
            let side = side_of(sides, k);
            return Err(OutlineError::NearlyTouching { side });
        }
    }
    for (side, chain) in sides.iter().enumerate() {
        for pair in chain.windows(2) {
            let [from, to] = [pair[0], pair[1]].map(|v| FixedVertexHandle::from_index(v as usize));
            // One new constraint edge from `from` to `to`, or the segment runs
            // into another side's constraint (crossing) or point (touching).
            if cdt.try_add_constraint(from, to).len() != 1 || !cdt.exists_constraint(from, to) {
                return Err(OutlineError::NearlyTouching { side });
            }
        }
    }
    Ok(cdt)
}

/// The side whose chain starts at or before side point `k`.
fn side_of(sides: &[Vec<u32>], k: usize) -> usize {
    sides
        .iter()
        .rposition(|chain| chain.first().is_some_and(|&s| s as usize <= k))
        .unwrap_or(0)
}

/// The triangles inside the outline (faces not reachable from the convex hull
/// without crossing a side) and the points they use: the `boundary` side points
/// first, in order, then the interior points in the order the triangles first
/// use them.
fn inside_mesh(cdt: &Cdt, boundary: usize) -> Result<(Vec<Vector2>, Vec<[u32; 3]>), OutlineError> {
    let outside = outside_faces(cdt);
    let mut index = vec![u32::MAX; cdt.num_vertices()];
    for (k, slot) in index.iter_mut().take(boundary).enumerate() {
        *slot = k as u32;
    }
    let mut points: Vec<Vector2> = cdt
        .vertices()
        .take(boundary)
        .map(|v| Vector2::new(v.position().x, v.position().y))
        .collect();
    let mut triangles = Vec::new();
    for face in cdt.inner_faces() {
        if outside[face.fix().index()] {
            continue;
        }
        let mut tri = [0u32; 3];
        for (slot, v) in tri.iter_mut().zip(face.vertices()) {
            let k = v.fix().index();
            if index[k] == u32::MAX {
                index[k] = points.len() as u32;
                points.push(Vector2::new(v.position().x, v.position().y));
            }
            *slot = index[k];
        }
        let [a, b, c] = tri.map(|v| points[v as usize]);
        let longest = (b - a)
            .length_squared()
            .max((c - b).length_squared())
            .max((a - c).length_squared());
        // The same test as `Mesh::new`'s for a degenerate triangle.
        let area = 0.5 * orient(a, b, c);
        if area <= 1e-12 * longest {
            return Err(OutlineError::Degenerate {
                x: a.x,
                y: a.y,
                area,
                longest: longest.sqrt(),
            });
        }
        triangles.push(tri);
    }
    Ok((points, triangles))
}

/// Marks the faces outside the outline: those reached from the convex hull
/// without crossing a side (a constraint edge). Indexed by face index.
fn outside_faces(cdt: &Cdt) -> Vec<bool> {
    let mut outside = vec![false; cdt.num_all_faces()];
    let mut stack: Vec<_> = cdt.convex_hull().map(|e| e.rev().fix()).collect();
    while let Some(edge) = stack.pop() {
        let edge = cdt.directed_edge(edge);
        if edge.is_constraint_edge() {
            continue;
        }
        if let Some(face) = edge.face().as_inner() {
            let index = face.fix().index();
            if !outside[index] {
                outside[index] = true;
                stack.push(edge.prev().rev().fix());
                stack.push(edge.next().rev().fix());
            }
        }
    }
    outside
}
