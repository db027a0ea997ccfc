//! The comparison for a `disk` region. A disk's rings follow a circle where
//! a ring lies on it: the held cloth is then the ring's polygon, as the
//! specimen itself is its outer ring's. So the check is on the held cloth's
//! edge: every held vertex next to free cloth lies on the circle, and every
//! mesh edge that bounds the held cloth runs between two such vertices.

use super::{PinMismatch, held_by, m_tol};
use crate::math::{Scalar, Vector2};
use crate::mesh::{Mesh, NO_TRIANGLE};

/// The comparison for the disk of centre `c` and radius `r` of pin `p`;
/// `None` when the disk holds no vertex.
pub(super) fn measure(
    p: usize,
    c: Vector2,
    r: Scalar,
    mesh: &Mesh,
    tol: Scalar,
) -> Option<PinMismatch> {
    let (held, held_box) = held_by(mesh, |m| m.distance(c) <= r + tol);
    let held_box = held_box?;
    let (lo, hi) = mesh.material_bounds();
    let region_box = [
        (c.x - r).max(lo.x),
        (c.y - r).max(lo.y),
        (c.x + r).min(hi.x),
        (c.y + r).min(hi.y),
    ];
    // How far inside the circle a vertex lies (0 on it).
    let inside = |v: u32| (r - mesh.material[v as usize].distance(c)).max(0.0);
    let borders_free = |t: u32| {
        t != NO_TRIANGLE
            && mesh.triangles[t as usize]
                .iter()
                .any(|&v| !held[v as usize])
    };
    let (mut largest_gap, mut edge_length, mut uncovered): (Scalar, Scalar, Scalar) =
        (0.0, 0.0, 0.0);
    for t in mesh
        .triangles
        .iter()
        .filter(|t| t.iter().any(|&v| !held[v as usize]))
    {
        for &v in t.iter().filter(|&&v| held[v as usize]) {
            largest_gap = largest_gap.max(inside(v));
        }
    }
    for e in &mesh.edges {
        let [a, b] = e.vertices;
        let bounds_held =
            held[a as usize] && held[b as usize] && e.triangles.iter().any(|&t| borders_free(t));
        if !bounds_held {
            continue;
        }
        let len = mesh.material[a as usize].distance(mesh.material[b as usize]);
        edge_length += len;
        if inside(a).max(inside(b)) > m_tol(tol) {
            uncovered += len;
        }
    }
    Some(PinMismatch {
        pin: p,
        region: "disk",
        region_box,
        held_box,
        largest_gap,
        edge_length,
        uncovered_length: uncovered,
    })
}
