//! Paper B's edge-based remeshing: split edges whose angle exceeds the upper
//! threshold at their midpoint, improve the result by Delaunay flips in material
//! space, and coarsen flat regions by collapsing short edges.
//!
//! * Splits use longest-edge bisection (Rivara): before an edge is bisected, any
//!   adjacent triangle whose longest edge is another one has that edge split
//!   first, so triangles are always halved across their longest side and keep
//!   their shape class (right isosceles grid triangles stay right isosceles).
//! * Minimum angle: no split, flip or collapse is applied if it would create a
//!   triangle with an angle below `min_angle`, which is half the smallest angle
//!   of the input mesh (22.5 degrees for the generated grids). The guarantee
//!   holds by construction and `tests/integration/adapt.rs` checks it.
//! * Collapses only remove edges shorter than 0.75 times the input mesh's
//!   shortest edge, so coarsening stops at the input resolution; they never
//!   remove a pinned vertex or a boundary corner, keep boundary vertices on the
//!   boundary, refuse to invert or pinch the mesh (link condition).
//!
//! The pass works on a triangle soup with incidence lists (`soup.rs`); every
//! split, flip and collapse is first planned as a [`SoupOp`] value from the
//! guards' reading of the soup and only then committed, so a refused
//! operation never touches the soup. A split whose longest-edge chain ends in
//! a refusal undoes the chain's committed splits through their inverses.
//! The adapter then compacts the soup and transfers the state
//! (`transfer.rs`).

use crate::math::{Scalar, Vector2};

pub use super::soup::{Soup, SoupOp, VertexChange};

/// One operation of the edge method, for events.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeOp {
    /// Midpoint split of the edge between two vertices.
    Split(u32, u32),
    /// Flip of the edge between two vertices.
    Flip(u32, u32),
    /// Vertex `.0` merged into vertex `.1`.
    Collapse(u32, u32),
}

/// A triangle to be halved by a split: slot `t` with corners `tri`, the split
/// edge running p -> q, `o` the opposite corner.
struct Halved {
    t: u32,
    tri: [u32; 3],
    p: u32,
    q: u32,
    o: u32,
    level: u8,
}

/// A triangle that a collapse moves: its slot, its corners and its corners after
/// the collapse.
type Moved = (u32, [u32; 3], [u32; 3]);

fn sorted(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Smallest interior angle of a material-space triangle, degrees.
pub fn min_angle_deg(p: [Vector2; 3]) -> Scalar {
    (0..3)
        .map(|k| {
            let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            let (u, v) = (b - a, c - a);
            u.perp_dot(v).abs().atan2(u.dot(v)).to_degrees()
        })
        .fold(180.0, Scalar::min)
}

impl Soup {
    /// Longest-edge bisection of edge (a, b); returns the operations done.
    /// Refused (returns false) if a needed split would go past `max_level`,
    /// below `min_len`, or below `min_angle`. Atomic: a refused split undoes
    /// the neighbour splits it did first and reports nothing (test
    /// `refused_edge_split_leaves_no_partial_work`).
    pub fn split(
        &mut self,
        a: u32,
        b: u32,
        limits: &Limits,
        out: &mut Vec<EdgeOp>,
        depth: u32,
    ) -> bool {
        let (mark, reported) = (self.journal().len(), out.len());
        let done = self.split_chain(a, b, limits, out, depth);
        if !done {
            self.undo_to(mark);
            out.truncate(reported);
        }
        done
    }

    /// [`Soup::split`] without the undo on refusal.
    fn split_chain(
        &mut self,
        a: u32,
        b: u32,
        limits: &Limits,
        out: &mut Vec<EdgeOp>,
        depth: u32,
    ) -> bool {
        if depth > 64 || !self.has_edge(a, b) {
            return false;
        }
        if !self.split_longer_edges_at(a, b, limits, out, depth) {
            return false;
        }
        let around = self.tris_at(a, b);
        if around.is_empty() {
            return false;
        }
        let m_pos = (self.material[a as usize] + self.material[b as usize]) * 0.5;
        if self.len2(a, b).sqrt() * 0.5 < limits.min_edge {
            return false;
        }
        let mut plan = Vec::new();
        for t in around.iter() {
            let Some(tri) = self.tris[t as usize] else {
                continue;
            };
            let Some(half) = self.halve(t, tri, a, b, m_pos, limits) else {
                return false;
            };
            plan.push(half);
        }
        let m = self.material.len() as u32;
        let base = self.tris.len() as u32;
        let mut op = SoupOp {
            vertex: Some(VertexChange::Append {
                id: m,
                material: m_pos,
                parent: (a, b),
            }),
            slots: (base, base + 2 * plan.len() as u32),
            ..SoupOp::default()
        };
        let mut touched = Vec::new();
        for (k, h) in plan.iter().enumerate() {
            let slot = base + 2 * k as u32;
            op.removed.push((h.t, h.tri, h.level));
            op.added.push((slot, [h.p, m, h.o], h.level + 1));
            op.added.push((slot + 1, [m, h.q, h.o], h.level + 1));
            touched.extend([h.p, h.q, h.o]);
        }
        // The new vertex is not in the soup yet: its flag starts false.
        op.touched = vec![(m, false, true)];
        op.touched.extend(self.touching(&touched));
        self.commit(op);
        out.push(EdgeOp::Split(a, b));
        true
    }

    /// Splits the longest edge of each triangle at (a, b) first, until (a, b) is
    /// the longest edge of every triangle at it (Rivara). False when a needed
    /// split is refused.
    fn split_longer_edges_at(
        &mut self,
        a: u32,
        b: u32,
        limits: &Limits,
        out: &mut Vec<EdgeOp>,
        depth: u32,
    ) -> bool {
        'settle: loop {
            for t in self.tris_at(a, b).iter() {
                let Some(tri) = self.tris[t as usize] else {
                    continue;
                };
                let (mut la, mut lb, mut best) = (a, b, self.len2(a, b));
                for k in 0..3 {
                    let (p, q) = (tri[k], tri[(k + 1) % 3]);
                    if self.len2(p, q) > best * (1.0 + 1e-9) {
                        (la, lb, best) = (p, q, self.len2(p, q));
                    }
                }
                if sorted(la, lb) != sorted(a, b) {
                    if !self.split(la, lb, limits, out, depth + 1) {
                        return false;
                    }
                    continue 'settle;
                }
            }
            return true;
        }
    }

    /// Triangle `t` (corners `tri`) halved across its edge (a, b) at the material
    /// point `m_pos`; `None` when a half would go past `max_level` or below
    /// `min_angle`.
    fn halve(
        &self,
        t: u32,
        tri: [u32; 3],
        a: u32,
        b: u32,
        m_pos: Vector2,
        limits: &Limits,
    ) -> Option<Halved> {
        let k = (0..3)
            .find(|&k| sorted(tri[k], tri[(k + 1) % 3]) == sorted(a, b))
            .unwrap_or(0);
        let (p, q, o) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
        let level = self.levels[t as usize];
        if level as u32 + 1 > limits.max_level as u32 {
            return None;
        }
        let mp = self.material[p as usize];
        let (mq, mo) = (self.material[q as usize], self.material[o as usize]);
        if min_angle_deg([mp, m_pos, mo]) < limits.min_angle
            || min_angle_deg([m_pos, mq, mo]) < limits.min_angle
        {
            return None;
        }
        Some(Halved {
            t,
            tri,
            p,
            q,
            o,
            level,
        })
    }

    /// Flips interior edges at the given vertices while that improves the
    /// Delaunay criterion in material space (never below `min_angle`).
    pub fn flip_around(&mut self, seeds: &[u32], limits: &Limits, out: &mut Vec<EdgeOp>) {
        let mut queue: Vec<(u32, u32)> = Vec::new();
        for &v in seeds {
            for &t in &self.vert_tris[v as usize] {
                if let Some(tri) = self.tris[t as usize] {
                    queue.extend((0..3).map(|k| sorted(tri[k], tri[(k + 1) % 3])));
                }
            }
        }
        queue.sort_unstable();
        queue.dedup();
        let mut budget = 16 * queue.len() + 16;
        while let Some((a, b)) = queue.pop() {
            budget = budget.saturating_sub(1);
            if budget == 0 {
                break;
            }
            let ts = match self.tris_at(a, b).to_pair() {
                Some(pair) => pair,
                None => continue,
            };
            let (Some(t0), Some(t1)) = (self.tris[ts[0] as usize], self.tris[ts[1] as usize])
            else {
                continue;
            };
            let opp = |t: [u32; 3]| t.into_iter().find(|&v| v != a && v != b).unwrap_or(a);
            let (c, d) = (opp(t0), opp(t1));
            if self.has_edge(c, d) {
                continue; // flipping would duplicate an edge
            }
            // Orient: t0 runs a -> b, so the flipped pair is (c, a, d), (d, b, c).
            let runs_ab = (0..3).any(|k| t0[k] == a && t0[(k + 1) % 3] == b);
            let (a, b) = if runs_ab { (a, b) } else { (b, a) };
            let (pa, pb, pc, pd) = (
                self.material[a as usize],
                self.material[b as usize],
                self.material[c as usize],
                self.material[d as usize],
            );
            let new0 = [pc, pa, pd];
            let new1 = [pd, pb, pc];
            let area = |p: [Vector2; 3]| (p[1] - p[0]).perp_dot(p[2] - p[0]);
            if area(new0) <= 0.0 || area(new1) <= 0.0 {
                continue; // not a convex quadrilateral
            }
            let angle_at = |x: Vector2, p: Vector2, q: Vector2| {
                (p - x).perp_dot(q - x).abs().atan2((p - x).dot(q - x))
            };
            if angle_at(pc, pa, pb) + angle_at(pd, pa, pb) <= std::f64::consts::PI + 1e-9 {
                continue; // already Delaunay
            }
            let before = min_angle_deg([pa, pb, pc]).min(min_angle_deg([pb, pa, pd]));
            let after = min_angle_deg(new0).min(min_angle_deg(new1));
            if after < limits.min_angle || after <= before {
                continue;
            }
            let (l0, l1) = (self.levels[ts[0] as usize], self.levels[ts[1] as usize]);
            let base = self.tris.len() as u32;
            let op = SoupOp {
                vertex: None,
                removed: vec![(ts[0], t0, l0), (ts[1], t1, l1)],
                added: vec![
                    (base, [c, a, d], l0.max(l1)),
                    (base + 1, [d, b, c], l0.max(l1)),
                ],
                slots: (base, base + 2),
                touched: self.touching(&[a, b, c, d]),
            };
            self.commit(op);
            queue.extend([sorted(a, c), sorted(c, b), sorted(b, d), sorted(d, a)]);
            out.push(EdgeOp::Flip(a, b));
        }
    }

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
        if self.on_boundary(v) && !self.straight_boundary(v, u, &nv, shared.len()) {
            return false;
        }
        let Some(replaced) = self.moved_triangles(v, u, limits) else {
            return false;
        };
        let base = self.tris.len() as u32;
        let mut op = SoupOp {
            vertex: Some(VertexChange::Remove(v)),
            slots: (base, base + replaced.len() as u32),
            ..SoupOp::default()
        };
        for t in shared.iter() {
            if let Some(tri) = self.tris[t as usize] {
                op.removed.push((t, tri, self.levels[t as usize]));
            }
        }
        for (k, &(t, old, new)) in replaced.iter().enumerate() {
            let level = self.levels[t as usize];
            op.removed.push((t, old, level));
            op.added.push((base + k as u32, new, level));
        }
        let mut touched = nv;
        touched.push(v);
        op.touched = self.touching(&touched);
        self.commit(op);
        out.push(EdgeOp::Collapse(v, u));
        true
    }

    /// A boundary vertex `v` (neighbours `nv`) collapses into `u` only along a
    /// straight boundary: (u, v) is a boundary edge (one shared triangle) and v's
    /// other boundary neighbour continues the line from u through v.
    fn straight_boundary(&self, v: u32, u: u32, nv: &[u32], shared: usize) -> bool {
        if shared != 1 {
            return false;
        }
        let others: Vec<u32> = nv
            .iter()
            .copied()
            .filter(|&w| w != u && self.tris_at(v, w).len() == 1)
            .collect();
        let [w] = others[..] else { return false };
        let (pu, pv, pw) = (
            self.material[u as usize],
            self.material[v as usize],
            self.material[w as usize],
        );
        if (pv - pu).perp_dot(pw - pv).abs() > 1e-12 * (pv - pu).length_squared().max(1e-300) {
            return false;
        }
        true
    }

    /// The triangles at `v` but not at `u`, each with its corners after `v`
    /// moves onto `u`; `None` when one would invert or fall below `min_angle`.
    fn moved_triangles(&self, v: u32, u: u32, limits: &Limits) -> Option<Vec<Moved>> {
        let mut replaced = Vec::new();
        for &t in &self.vert_tris[v as usize] {
            let Some(tri) = self.tris[t as usize] else {
                continue;
            };
            if tri.contains(&u) {
                continue;
            }
            let new = tri.map(|w| if w == v { u } else { w });
            let p = self.corners(new);
            if (p[1] - p[0]).perp_dot(p[2] - p[0]) <= 0.0 || min_angle_deg(p) < limits.min_angle {
                return None;
            }
            replaced.push((t, tri, new));
        }
        Some(replaced)
    }
}

/// Limits of the edge method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// No operation creates an angle below this, degrees.
    pub min_angle: Scalar,
    /// No split makes an edge shorter than this, m.
    pub min_edge: Scalar,
    /// Collapse only edges shorter than this, m.
    pub collapse_below: Scalar,
    /// Deepest split level.
    pub max_level: u8,
}

impl Limits {
    /// Limits for an input mesh: half its smallest angle, and collapses below
    /// 0.75 of its shortest edge.
    pub fn for_mesh(
        material: &[Vector2],
        tris: &[[u32; 3]],
        max_level: u8,
        min_edge: Scalar,
    ) -> Limits {
        let min_angle = tris
            .iter()
            .map(|t| min_angle_deg(t.map(|v| material[v as usize])))
            .fold(180.0, Scalar::min);
        let shortest = tris
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .map(|(a, b)| material[a as usize].distance(material[b as usize]))
            .fold(Scalar::INFINITY, Scalar::min);
        Limits {
            min_angle: 0.5 * min_angle,
            min_edge,
            collapse_below: 0.75 * shortest,
            max_level,
        }
    }
}
