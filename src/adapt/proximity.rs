//! The obstacle term of the sizing criterion (`refine_obstacle`, off by
//! default): refine the cloth where it comes near an obstacle at an angle, so
//! that the mesh is fine where it will fold over the obstacle before the fold
//! forms, instead of after.
//!
//! Why. Compared frame by frame on `tablecloth` (`docs/speed-vs-error-history.md`),
//! the adaptive runs are already far behind uniform 64 in the first frame
//! after the cloth lands on the table (t = 0.33 s: edge 16 L4 0.677 % of the
//! diagonal, red_green 16 L4 0.698 %, uniform 64 0.232 %, uniform 32 0.731 %):
//! the sheet falls flat, so the curvature rule leaves it at the base mesh
//! until it hits the table's edges, and the crease over each edge forms on
//! the coarse mesh. Refining afterwards cannot undo where the crease formed.
//!
//! The measure is the obstacle metric of Narain, Pfaff and O'Brien (2013,
//! "Folding and crumpling adaptive sheets", the obstacle term of ARCSim's
//! sizing field), taken edge by edge. Each vertex `v` gets the tangent plane
//! of the nearest obstacle surface point (outward normal `n_v`, surface point
//! `s_v`). The heights of an edge's two ends above the plane of one end,
//! `h_a = n_a . (x_a - s_a)` and `h_b = n_a . (x_b - s_a)`, differ by
//! `|h_b - h_a|`: how far the edge leans towards the obstacle over its length.
//! An edge leaning by more than a fraction of its height would reach the
//! surface before it could bend to follow it, so it is too long there; the
//! measure of the edge is the larger over its two ends of
//!
//! ```text
//! r = |h_b - h_a| / max(h_a, thickness)
//! ```
//!
//! (the obstacle's contact thickness, the height the cloth rests at, is the
//! floor: a vertex in contact is at about that height, and the floor keeps a
//! vertex pushed slightly inside from dividing by nothing). A leaf splits
//! where `r > refine_obstacle` at one of its edges; `r` halves with the
//! edge's length, as the curvature measure `kappa * D` does, so four children
//! merge when twice their largest `r` is at most `refine_obstacle / H` (the
//! same hysteresis). A sheet lying flat on a flat surface has `r = 0`, and so
//! has a sheet falling parallel to it; a sheet over a ball is refined ahead of
//! the contact where it is not parallel to the ball's surface, and one draped
//! over a table's edge along the edge (the nearest point there is on the
//! edge, whose normal leans at 45 degrees to both faces).
//!
//! Measured (`docs/speed-vs-error-history.md`, "Eighth sitting"): over the
//! tablecloth's landing (0.6 s) `refine_obstacle = 0.5` brings red_green 16 L4
//! from 1.72 to 1.26 times uniform 64's error at 0.63 instead of 0.46 of its
//! time; over 2 s the settings scatter (1.09, 1.59, 1.35 at 1, 0.5, 0.25); on
//! `drape_sphere` the sheet lies on the ball and the term refines nearly all
//! of it, at more error (1.54 against 1.11). Of these only the first
//! frames of the landing are resolved by the comparison (at 0.33 s 0.698 ->
//! 0.326 % against a mesh floor of 0.249 %); over the landing and on
//! `drape_sphere` the differences are below the mesh floor (0.251 % and
//! 0.762 %; `docs/speed-vs-error-history.md`, "Ninth sitting"). Tried and dropped: counting an
//! end only while it approaches the surface and would reach it within two
//! adaptation intervals (velocity against the normal, horizon 0.03 s on the
//! tablecloth, 0.067 s on `drape_sphere`), so that cloth at rest on an
//! obstacle is not refined for being near it: the refinement before the
//! landing went with it (landing errors 0.451 to 0.461 % against 0.449 %
//! without the term and 0.328 % with it), and `drape_sphere` stayed worse
//! than without the term (0.834 to 0.916 % against 0.575 to 0.671 %).
//!
//! Tried and dropped in the thirteenth sitting (`docs/speed-vs-error-history.md`),
//! over `drape_sphere`'s contact (to 0.533 s, against uniform 192): a
//! separate arrival term that split a leaf while one of its vertices, not in
//! contact, would reach its contact height (gap over its speed towards the
//! surface) within `k + 1` adaptation intervals, `k` the splits the leaf
//! still lacked, and kept its parent from merging. It refined the first
//! contact in time (0.0019 % at 0.333 s against uniform 128's 0.0023 % and
//! 0.028 % without it) but not the skirt that buckles around the ball after
//! it: over the window red_green 32 L4 went from 0.220 to 0.255 % (uniform
//! 128 0.040 %), 64 L2 8 deg from 0.150 to 0.171 %. Keeping cloth in contact
//! at the finest level too (0.255 %), or adding the curvature of the shape
//! extrapolated along the velocities over the same horizon (0.250 %), did
//! not help either, nor did refining at 2 deg (0.254 % without the term,
//! 0.249 % with it) or with `refine_strain = 0.005` (0.187 % without the
//! term, 0.259 % with it). Nor is it the triangulation seeding
//! the skirt's folds: uniform 192 with every diagonal turned is 0.025 % from
//! the reference (the pattern floor, `crate::bench::floor`). What is known:
//! the sheet refined everywhere before the contact is uniform 128 to the
//! digit (0.040 %), while refining only part of it does worse than not
//! refining at all (64 L2 8 deg 0.150 % against uniform 64's 0.139 %), and a
//! scratch variant that split every leaf once any vertex arrived within the
//! horizon (the whole sheet refined about 0.1 s before the contact) gave
//! 0.040 %, uniform 128's error to the digit, with 0.50 to 0.65 of its mean
//! vertices. Our reading (a calculation, `docs/speed-vs-error-history.md`): the
//! impact reaches the whole sheet within one adaptation interval, so all of
//! it must be fine when the centre touches.
//!
//! Red-green with the sizing criterion only. The rollback check does not see
//! it (it is measured in the adaptation pass, where the obstacles are known).

use crate::math::{Scalar, Vector};
use crate::mesh::Edge;

/// The tangent plane of the obstacle surface point nearest to one cloth vertex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObstaclePlane {
    /// The nearest surface point, world coordinates, m.
    pub point: Vector,
    /// The outward unit normal there.
    pub normal: Vector,
    /// The obstacle's contact thickness, m: the smallest height the measure
    /// divides by.
    pub thickness: Scalar,
}

/// How far edge `e` leans towards the obstacle nearest to its ends, relative
/// to its height above it (module docs): the larger over both ends of
/// `|h_b - h_a| / max(h_a, thickness)`. 0 when `planes` is empty.
pub fn edge_obstacle_lean(x: &[Vector], planes: &[ObstaclePlane], e: &Edge) -> Scalar {
    if planes.is_empty() {
        return 0.0;
    }
    let [a, b] = e.vertices.map(|v| v as usize);
    let lean = |own: usize, other: usize| {
        let p = &planes[own];
        let h_own = p.normal.dot(x[own] - p.point);
        let h_other = p.normal.dot(x[other] - p.point);
        (h_other - h_own).abs() / h_own.max(p.thickness)
    };
    lean(a, b).max(lean(b, a))
}
