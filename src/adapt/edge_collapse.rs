//! The edge method's collapses (`edge.rs`): a short edge at flat vertices is
//! removed by moving one end onto the other, guarded so that the mesh stays
//! manifold, uninverted, above the minimum angle, with its boundary and its
//! garment seams where they were.

use super::edge::{EdgeOp, Limits, min_angle_deg};
use super::soup::{Soup, SoupOp, SoupTri, VertexChange};
use crate::math::Vector2;

impl Soup {
    /// True when vertex `v` lies on the boundary.
    fn on_boundary(&self, v: u32) -> bool {
        self.neighbours(v)
            .into_iter()
            .any(|w| self.tris_at(v, w).len() == 1)
    }

    fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut n: Vec<u32> = self.vert_tris[v as usize]
            .iter()
            .filter_map(|&t| self.tris[t as usize])
            .flat_map(|t| t.into_iter())
            .filter(|&w| w != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    }

    /// Collapses `v` into `u` if every guard allows it; returns true if done.
    pub fn collapse(
        &mut self,
        v: u32,
        u: u32,
        pinned: &[bool],
        limits: &Limits,
        out: &mut Vec<EdgeOp>,
    ) -> bool {
        if self.touched[v as usize]
            || self.touched[u as usize]
            || pinned.get(v as usize).copied().unwrap_or(false)
        {
            return false;
        }
        if self.len2(u, v).sqrt() >= limits.collapse_below {
            return false;
        }
        let shared = self.tris_at(u, v);
        if shared.is_empty() {
            return false;
        }
        // Link condition: the common neighbours are exactly the shared triangles' tips.
        let (nu, nv) = (self.neighbours(u), self.neighbours(v));
        let common = nv.iter().filter(|w| nu.binary_search(w).is_ok()).count();
        if common != shared.len() {
            return false;
        }
        // A vertex on a garment's welded seam has a coordinate in each panel:
        // it stays (a collapse moves triangles in one pattern only).
        if !self.in_one_pattern(v) {
            return false;
        }
        let Some(pu) = shared.iter().find_map(|t| self.corner_at(t, u)) else {
            return false;
        };
        if self.on_boundary(v) && !self.straight_boundary(v, u, pu, &nv, shared.len()) {
            return false;
        }
        let Some(replaced) = self.moved_triangles(v, u, pu, limits) else {
            return false;
        };
        let base = self.tris.len() as u32;
        let mut op = SoupOp {
            vertex: Some(VertexChange::Remove(v)),
            slots: (base, base + replaced.len() as u32),
            ..SoupOp::default()
        };
        op.removed
            .extend(shared.iter().filter_map(|t| self.soup_tri(t)));
        for (k, (old, new)) in replaced.into_iter().enumerate() {
            op.removed.push(old);
            op.added.push(SoupTri {
                slot: base + k as u32,
                ..new
            });
        }
        let mut touched = nv;
        touched.push(v);
        op.touched = self.touching(&touched);
        self.commit(op);
        out.push(EdgeOp::Collapse(v, u));
        true
    }

    /// A boundary vertex `v` (neighbours `nv`) collapses into `u` (at `pu` in
    /// v's pattern) only along a straight boundary: (u, v) is a boundary edge
    /// (one shared triangle) and v's other boundary neighbour continues the
    /// line from u through v.
    fn straight_boundary(&self, v: u32, u: u32, pu: Vector2, nv: &[u32], shared: usize) -> bool {
        if shared != 1 {
            return false;
        }
        let others: Vec<u32> = nv
            .iter()
            .copied()
            .filter(|&w| w != u && self.tris_at(v, w).len() == 1)
            .collect();
        let [w] = others[..] else { return false };
        let Some((pv, pw)) = self
            .tris_at(v, w)
            .iter()
            .find_map(|t| Some((self.corner_at(t, v)?, self.corner_at(t, w)?)))
        else {
            return false;
        };
        if (pv - pu).perp_dot(pw - pv).abs() > 1e-12 * (pv - pu).length_squared().max(1e-300) {
            return false;
        }
        true
    }

    /// The triangles at `v` but not at `u`, each as it is and as it is after
    /// `v` moves onto `u` (at `pu` in their pattern); `None` when one would
    /// invert or fall below `min_angle`.
    fn moved_triangles(
        &self,
        v: u32,
        u: u32,
        pu: Vector2,
        limits: &Limits,
    ) -> Option<Vec<(SoupTri, SoupTri)>> {
        let mut replaced = Vec::new();
        for &t in &self.vert_tris[v as usize] {
            let Some(old) = self.soup_tri(t) else {
                continue;
            };
            if old.tri.contains(&u) {
                continue;
            }
            let mut new = old;
            for k in 0..3 {
                if old.tri[k] == v {
                    new.tri[k] = u;
                    new.uv[k] = pu;
                }
            }
            let p = new.uv;
            if (p[1] - p[0]).perp_dot(p[2] - p[0]) <= 0.0 || min_angle_deg(p) < limits.min_angle {
                return None;
            }
            replaced.push((old, new));
        }
        Some(replaced)
    }
}
