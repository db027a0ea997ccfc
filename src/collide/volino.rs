//! Volino's curvature-based self-collision culling (Volino and Magnenat-Thalmann 1994).
//!
//! A connected surface patch cannot intersect itself when (1) there is a direction `V`
//! with `n . V > 0` for the normal `n` of every triangle of the patch (the normals lie in
//! an open half-sphere), and (2) the patch's boundary, projected onto the plane orthogonal
//! to `V`, does not cross itself. Under (1) the projection is a local homeomorphism that
//! keeps every triangle's orientation; with (2) it is one-to-one, so two points of the
//! patch never coincide in space.
//!
//! Here the patches are a fixed partition of the current mesh: the triangles whose
//! material-space centroid falls in the same square cell of side `patch_size`, split into
//! edge-connected pieces. They are rebuilt whenever the mesh's triangles change
//! (adaptivity). Each step the test runs on the start-of-step and the end-of-step
//! positions with the same `V` (the normalised sum of the area-weighted normals of both):
//! - normal test: `n . V >= NORMAL_MARGIN` for every triangle at both times;
//! - boundary test: every boundary edge of the patch (an edge with one patch triangle) is
//!   projected onto the plane orthogonal to `V` and tested against every other boundary
//!   edge that shares no vertex with it; any crossing or touching (a fold of the
//!   boundary over itself) fails the test. Done at both times.
//!
//! A patch passing both needs no self-test; pairs between different patches are always
//! tested.

use crate::math::{Scalar, Vector};
use crate::mesh::Mesh;

use super::geometry::segments_cross_2d;

/// Smallest `n . V` accepted (a small margin against round-off and motion within the step).
pub const NORMAL_MARGIN: Scalar = 0.05;

/// Triangles per patch side when `patch_size` is not given.
pub const AUTO_PATCH_TRIANGLES: Scalar = 12.0;

/// A boundary edge projected onto the test plane: its vertices and both projected ends.
pub type ProjectedEdge = ([u32; 2], [Scalar; 2], [Scalar; 2]);

/// A fixed partition of the mesh's triangles into patches.
#[derive(Debug, Clone, Default)]
pub struct Patches {
    /// Triangles of each patch, ascending.
    pub triangles: Vec<Vec<u32>>,
    /// Boundary edges (vertex pairs) of each patch.
    pub boundary: Vec<Vec<[u32; 2]>>,
}

impl Patches {
    /// Partitions `mesh` into patches of side `size` in material space
    /// (`None`: [`AUTO_PATCH_TRIANGLES`] mean triangle sizes).
    pub fn build(mesh: &Mesh, size: Option<Scalar>) -> Patches {
        let n = mesh.triangles.len();
        let mean_area = mesh.total_rest_area() / n.max(1) as Scalar;
        let side = size.unwrap_or(AUTO_PATCH_TRIANGLES * (2.0 * mean_area).sqrt());
        let cell = |t: usize| {
            let [a, b, c] = mesh.corners(t);
            let m = (a + b + c) / 3.0;
            ((m.x / side).floor() as i64, (m.y / side).floor() as i64)
        };
        let cells: Vec<(i64, i64)> = (0..n).map(cell).collect();
        // Union-find over triangles joined through interior edges within one cell.
        let mut parent: Vec<usize> = (0..n).collect();
        fn find(p: &mut [usize], mut x: usize) -> usize {
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        for e in mesh.edges.iter().filter(|e| e.is_interior()) {
            let (a, b) = (e.triangles[0] as usize, e.triangles[1] as usize);
            if cells[a] == cells[b] {
                let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                parent[ra.max(rb)] = ra.min(rb);
            }
        }
        let mut id = vec![usize::MAX; n];
        let mut triangles: Vec<Vec<u32>> = Vec::new();
        for t in 0..n {
            let r = find(&mut parent, t);
            if id[r] == usize::MAX {
                id[r] = triangles.len();
                triangles.push(Vec::new());
            }
            triangles[id[r]].push(t as u32);
        }
        let mut patch_of = vec![0usize; n];
        for (p, tris) in triangles.iter().enumerate() {
            for &t in tris {
                patch_of[t as usize] = p;
            }
        }
        let mut boundary = vec![Vec::new(); triangles.len()];
        for e in &mesh.edges {
            let a = e.triangles[0] as usize;
            let inner = e.is_interior() && patch_of[e.triangles[1] as usize] == patch_of[a];
            if !inner {
                boundary[patch_of[a]].push(e.vertices);
                if e.is_interior() {
                    boundary[patch_of[e.triangles[1] as usize]].push(e.vertices);
                }
            }
        }
        Patches {
            triangles,
            boundary,
        }
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// True when there are no patches.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Volino's test for patch `p` at both positions `x0` and `x1` (see the module docs).
    /// `segs` is scratch for the projected boundary (kept by the caller between steps).
    pub fn cannot_self_intersect(
        &self,
        p: usize,
        tris: &[[u32; 3]],
        x0: &[Vector],
        x1: &[Vector],
        segs: &mut Vec<ProjectedEdge>,
    ) -> bool {
        let normal = |x: &[Vector], t: u32| {
            let [a, b, c] = tris[t as usize].map(|i| x[i as usize]);
            (b - a).cross(c - a)
        };
        let ts = &self.triangles[p];
        let sum: Vector = ts.iter().map(|&t| normal(x0, t) + normal(x1, t)).sum();
        let Some(v) = sum.try_normalize() else {
            return false;
        };
        for x in [x0, x1] {
            if !ts.iter().all(|&t| {
                let n = normal(x, t);
                n.dot(v) >= NORMAL_MARGIN * n.length() && n != Vector::ZERO
            }) {
                return false;
            }
        }
        let u = v.any_orthonormal_vector();
        let w = v.cross(u);
        let bnd = &self.boundary[p];
        for x in [x0, x1] {
            let proj = |i: u32| {
                let q = x[i as usize];
                [q.dot(u), q.dot(w)]
            };
            segs.clear();
            segs.extend(bnd.iter().map(|&e| (e, proj(e[0]), proj(e[1]))));
            for (i, a) in segs.iter().enumerate() {
                for b in &segs[i + 1..] {
                    let shared = a.0.iter().any(|v| b.0.contains(v));
                    if !shared && segments_cross_2d(a.1, a.2, b.1, b.2) {
                        return false;
                    }
                }
            }
        }
        true
    }
}
