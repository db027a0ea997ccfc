//! The obstacle term of the sizing criterion (`refine_obstacle`, off by
//! default): refine the cloth where it comes near an obstacle at an angle, so
//! that the mesh is fine where it will fold over the obstacle before the fold
//! forms, instead of after. A sheet falling flat keeps the base mesh under the
//! curvature rule until it hits an obstacle's edge, and a crease that forms on
//! the coarse mesh stays where it formed when the mesh is refined afterwards.
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
//! It is off by default because its gains on the benchmark scenes are below
//! what the comparison resolves, and on a sheet resting on a ball it refines
//! nearly all of it. Counting only vertices that approach the surface, so that
//! cloth at rest is not refined, loses the refinement before a landing.
//!
//! Red-green with the sizing criterion only. The rollback check does not see
//! it (it is measured in the adaptation pass, where the obstacles are known).

use crate::collide::ObstaclePlane;
use crate::math::{Scalar, Vector};
use crate::mesh::Edge;

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
