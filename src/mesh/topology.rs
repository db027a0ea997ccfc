//! Edge table and manifold checks.

use super::MeshError;

/// Marks the missing second triangle of a boundary edge.
pub const NO_TRIANGLE: u32 = u32::MAX;

/// An undirected edge with the (one or two) triangles that share it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// The two vertices, smaller index first.
    pub vertices: [u32; 2],
    /// The adjacent triangles; the second is [`NO_TRIANGLE`] on the boundary.
    pub triangles: [u32; 2],
}

impl Edge {
    /// True when two triangles share this edge (a bending hinge).
    pub fn is_interior(&self) -> bool {
        self.triangles[1] != NO_TRIANGLE
    }
}

/// Builds the sorted, unique edge list; refuses edges with more than two triangles.
pub(super) fn build_edges(
    triangles: &[[u32; 3]],
    _vertex_count: usize,
) -> Result<Vec<Edge>, MeshError> {
    let mut half: Vec<(u32, u32, u32)> = Vec::with_capacity(triangles.len() * 3);
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            half.push((a.min(b), a.max(b), t as u32));
        }
    }
    half.sort_unstable();
    let mut edges = Vec::with_capacity(half.len() / 2 + 1);
    let mut i = 0;
    while i < half.len() {
        let (a, b, t0) = half[i];
        let mut j = i + 1;
        while j < half.len() && half[j].0 == a && half[j].1 == b {
            j += 1;
        }
        let count = j - i;
        if count > 2 {
            return Err(MeshError::NonManifoldEdge { a, b, count });
        }
        let t1 = if count == 2 {
            half[i + 1].2
        } else {
            NO_TRIANGLE
        };
        edges.push(Edge {
            vertices: [a, b],
            triangles: [t0, t1],
        });
        i = j;
    }
    Ok(edges)
}

/// Checks that every vertex is used, that the triangles around each vertex form a
/// single fan, and that the whole mesh is connected.
pub(super) fn check_vertices(triangles: &[[u32; 3]], vertex_count: usize) -> Result<(), MeshError> {
    let components = check_fans(triangles, vertex_count)?;
    if components > 1 {
        return Err(MeshError::Disconnected { components });
    }
    Ok(())
}

/// Checks that every vertex is used and that the triangles around each vertex
/// form a single fan; returns the number of connected pieces.
pub(super) fn check_fans(triangles: &[[u32; 3]], vertex_count: usize) -> Result<usize, MeshError> {
    // Union-find over triangles, joined through shared edges (whole mesh) and,
    // per vertex, through edges incident to that vertex (fans).
    let mut at_vertex: Vec<Vec<u32>> = vec![Vec::new(); vertex_count];
    for (t, tri) in triangles.iter().enumerate() {
        for &v in tri {
            at_vertex[v as usize].push(t as u32);
        }
    }
    let mut global = UnionFind::new(triangles.len());
    for (v, tris) in at_vertex.iter().enumerate() {
        if tris.is_empty() {
            return Err(MeshError::UnusedVertex { vertex: v as u32 });
        }
        let mut local = UnionFind::new(tris.len());
        for (i, &ti) in tris.iter().enumerate() {
            for (j, &tj) in tris.iter().enumerate().skip(i + 1) {
                if shares_edge_at(&triangles[ti as usize], &triangles[tj as usize], v as u32) {
                    local.union(i, j);
                    global.union(ti as usize, tj as usize);
                }
            }
        }
        let fans = local.count();
        if fans > 1 {
            return Err(MeshError::NonManifoldVertex {
                vertex: v as u32,
                fans,
            });
        }
    }
    Ok(global.count())
}

/// True when triangles `a` and `b` share an edge that has `v` as an endpoint.
fn shares_edge_at(a: &[u32; 3], b: &[u32; 3], v: u32) -> bool {
    a.iter().any(|&w| w != v && b.contains(&w))
}

/// Disjoint sets over `0..n` (the smaller root wins a union; path halving).
pub(super) struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    /// `n` singletons.
    pub(super) fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n).collect(),
        }
    }
    /// The representative of `x`'s set: its smallest member.
    pub(super) fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }
    /// Joins the sets of `a` and `b`.
    pub(super) fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra.max(rb)] = ra.min(rb);
        }
    }
    /// The number of sets.
    pub(super) fn count(&mut self) -> usize {
        (0..self.parent.len())
            .filter(|&i| self.find(i) == i)
            .count()
    }
}
