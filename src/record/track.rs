//! Following a point of the cloth through a recording's frames (`drape inspect --at`): the
//! point is the nearest point of the cloth at the frame asked about, held in its triangle by
//! barycentric coordinates. While the topology stays the same the point stays at those
//! coordinates of the same triangle; across a remesh (the simulated mesh's triangles are
//! renumbered) it moves to the nearest point of the new mesh to where it was in the frame
//! before (after, going back in time). The recording holds no material coordinates, so this
//! is a spatial match: exact on a frame without a remesh, and across a remesh as close as the
//! cloth moved in one frame.

use std::collections::BTreeMap;

use super::history::MeshAt;
use crate::collide::geometry::closest_on_triangle;
use crate::math::Vector;

/// Where the point is on one frame's mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Place {
    /// The triangle it is on (index into the simulated mesh).
    pub triangle: usize,
    /// Its barycentric coordinates in that triangle.
    pub bary: [f64; 3],
    /// Its position, m.
    pub position: [f64; 3],
}

type P = [f64; 3];

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The point at barycentric coordinates `w` of triangle `t`.
fn at(t: [P; 3], w: [f64; 3]) -> P {
    [0, 1, 2].map(|i| w[0] * t[0][i] + w[1] * t[1][i] + w[2] * t[2][i])
}

/// The barycentric coordinates of the point of triangle `t` nearest to `p`
/// ([`closest_on_triangle`], the collision code's).
pub(super) fn closest_bary(t: [P; 3], p: P) -> [f64; 3] {
    let [a, b, c] = t.map(Vector::from_array);
    closest_on_triangle(Vector::from_array(p), a, b, c)
}

/// The distance from `p` to triangle `t`, m.
pub(super) fn distance_to(t: [P; 3], p: P) -> f64 {
    let q = at(t, closest_bary(t, p));
    dot(sub(p, q), sub(p, q)).sqrt()
}

/// The corners of triangle `t` of `mesh`.
fn corners(mesh: &MeshAt, t: usize) -> [P; 3] {
    mesh.triangles[t].map(|v| mesh.positions[v as usize])
}

/// The point of `mesh` nearest to `p`, and its distance; `None` for a mesh without
/// triangles.
pub(super) fn nearest(mesh: &MeshAt, p: P) -> Option<(Place, f64)> {
    (0..mesh.triangles.len())
        .map(|t| {
            let tri = corners(mesh, t);
            let bary = closest_bary(tri, p);
            let q = at(tri, bary);
            let place = Place {
                triangle: t,
                bary,
                position: q,
            };
            (place, dot(sub(p, q), sub(p, q)).sqrt())
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// The point at `place` on `from`'s mesh carried to `to`: the same triangle and coordinates
/// when `to` has the same topology, the nearest point otherwise.
fn carry(place: Place, from: &MeshAt, to: &MeshAt) -> Place {
    if from.topology_frame == to.topology_frame && place.triangle < to.triangles.len() {
        return Place {
            position: at(corners(to, place.triangle), place.bary),
            ..place
        };
    }
    nearest(to, place.position).map_or(place, |n| n.0)
}

/// Follows `place`, on the mesh of frame `start`, through every frame of `meshes` (forward
/// and back from `start`); each frame with its mesh.
pub(super) fn follow(
    mut meshes: BTreeMap<i64, MeshAt>,
    start: i64,
    place: Place,
) -> BTreeMap<i64, (Place, MeshAt)> {
    let mut out = BTreeMap::new();
    let Some(first) = meshes.remove(&start) else {
        return out;
    };
    let later: Vec<i64> = meshes.range(start..).map(|(&f, _)| f).collect();
    let earlier: Vec<i64> = meshes.range(..start).rev().map(|(&f, _)| f).collect();
    out.insert(start, (place, first));
    for frames in [later, earlier] {
        let mut prev = start;
        for f in frames {
            let Some(mesh) = meshes.remove(&f) else {
                continue;
            };
            let (p, from) = &out[&prev];
            let next = carry(*p, from, &mesh);
            out.insert(f, (next, mesh));
            prev = f;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nearest_point_of_a_triangle_is_inside_or_on_its_edge() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let inside = closest_bary(t, [0.25, 0.25, 0.3]);
        assert!((inside[1] - 0.25).abs() < 1e-12 && (inside[2] - 0.25).abs() < 1e-12);
        assert!((distance_to(t, [0.25, 0.25, 0.3]) - 0.3).abs() < 1e-12);
        assert_eq!(closest_bary(t, [-1.0, -1.0, 0.0]), [1.0, 0.0, 0.0]);
        assert!((distance_to(t, [1.0, 1.0, 0.0]) - 0.5f64.sqrt()).abs() < 1e-12);
    }
}
