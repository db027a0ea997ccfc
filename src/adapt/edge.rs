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
//! The pass works on a triangle soup with incidence lists; the adapter then
//! compacts it and transfers the state (`transfer.rs`).

use std::collections::HashMap;

use crate::math::{Scalar, Vector2};

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

/// A mutable triangle soup with incidence lists.
pub struct Soup {
    /// Material coordinates (old vertices first, then new ones).
    pub material: Vec<Vector2>,
    /// Triangles (counter-clockwise); dead ones are `None`.
    pub tris: Vec<Option<[u32; 3]>>,
    /// Level (split depth) of each triangle.
    pub levels: Vec<u8>,
    /// Parent edge of each vertex created in this pass (id `first_new + k`).
    pub created: Vec<(u32, u32)>,
    /// Id of the first vertex created in this pass.
    pub first_new: u32,
    /// Vertices removed by collapses.
    pub removed: Vec<bool>,
    edge_tris: HashMap<(u32, u32), Vec<u32>>,
    vert_tris: Vec<Vec<u32>>,
    /// Vertices touched by an operation in this pass (not collapsed again).
    touched: Vec<bool>,
}

impl Soup {
    /// A soup of the given mesh.
    pub fn new(material: &[Vector2], tris: &[[u32; 3]], levels: &[u8]) -> Soup {
        let mut s = Soup {
            material: material.to_vec(),
            tris: Vec::with_capacity(tris.len() * 2),
            levels: Vec::with_capacity(tris.len() * 2),
            created: Vec::new(),
            first_new: material.len() as u32,
            removed: vec![false; material.len()],
            edge_tris: HashMap::new(),
            vert_tris: vec![Vec::new(); material.len()],
            touched: vec![false; material.len()],
        };
        for (t, &tri) in tris.iter().enumerate() {
            s.add(tri, levels[t]);
        }
        s
    }

    fn add(&mut self, tri: [u32; 3], level: u8) -> u32 {
        let id = self.tris.len() as u32;
        self.tris.push(Some(tri));
        self.levels.push(level);
        for k in 0..3 {
            self.edge_tris
                .entry(sorted(tri[k], tri[(k + 1) % 3]))
                .or_default()
                .push(id);
            self.vert_tris[tri[k] as usize].push(id);
        }
        id
    }

    fn kill(&mut self, id: u32) {
        let Some(tri) = self.tris[id as usize].take() else {
            return;
        };
        for k in 0..3 {
            let key = sorted(tri[k], tri[(k + 1) % 3]);
            if let Some(list) = self.edge_tris.get_mut(&key) {
                list.retain(|&t| t != id);
                if list.is_empty() {
                    self.edge_tris.remove(&key);
                }
            }
            self.vert_tris[tri[k] as usize].retain(|&t| t != id);
        }
    }

    fn corners(&self, tri: [u32; 3]) -> [Vector2; 3] {
        tri.map(|v| self.material[v as usize])
    }

    fn len2(&self, a: u32, b: u32) -> Scalar {
        self.material[a as usize].distance_squared(self.material[b as usize])
    }

    /// Triangles at edge (a, b).
    pub fn triangles_at(&self, a: u32, b: u32) -> Vec<u32> {
        self.edge_tris
            .get(&sorted(a, b))
            .cloned()
            .unwrap_or_default()
    }

    /// Longest-edge bisection of edge (a, b); returns the operations done.
    /// Refused (returns false) if a needed split would go past `max_level`,
    /// below `min_len`, or below `min_angle`.
    pub fn split(
        &mut self,
        a: u32,
        b: u32,
        limits: &Limits,
        out: &mut Vec<EdgeOp>,
        depth: u32,
    ) -> bool {
        if depth > 64 || !self.edge_tris.contains_key(&sorted(a, b)) {
            return false;
        }
        // Split the longest edge of each adjacent triangle first, until (a, b)
        // is the longest edge of every triangle at it.
        'settle: loop {
            for t in self.triangles_at(a, b) {
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
            break;
        }
        let around = self.triangles_at(a, b);
        if around.is_empty() {
            return false;
        }
        let m_pos = (self.material[a as usize] + self.material[b as usize]) * 0.5;
        if self.len2(a, b).sqrt() * 0.5 < limits.min_edge {
            return false;
        }
        let mut plan = Vec::new();
        for &t in &around {
            let Some(tri) = self.tris[t as usize] else {
                continue;
            };
            let k = (0..3)
                .find(|&k| sorted(tri[k], tri[(k + 1) % 3]) == sorted(a, b))
                .unwrap_or(0);
            let (p, q, o) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let level = self.levels[t as usize];
            if level as u32 + 1 > limits.max_level as u32 {
                return false;
            }
            let mp = self.material[p as usize];
            let (mq, mo) = (self.material[q as usize], self.material[o as usize]);
            if min_angle_deg([mp, m_pos, mo]) < limits.min_angle
                || min_angle_deg([m_pos, mq, mo]) < limits.min_angle
            {
                return false;
            }
            plan.push((t, p, q, o, level));
        }
        let m = self.material.len() as u32;
        self.material.push(m_pos);
        self.created.push((a, b));
        self.removed.push(false);
        self.vert_tris.push(Vec::new());
        self.touched.push(true);
        for (t, p, q, o, level) in plan {
            self.kill(t);
            self.add([p, m, o], level + 1);
            self.add([m, q, o], level + 1);
            for v in [p, q, o] {
                self.touched[v as usize] = true;
            }
        }
        out.push(EdgeOp::Split(a, b));
        true
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
            let ts = self.triangles_at(a, b);
            if ts.len() != 2 {
                continue;
            }
            let (Some(t0), Some(t1)) = (self.tris[ts[0] as usize], self.tris[ts[1] as usize])
            else {
                continue;
            };
            let opp = |t: [u32; 3]| t.into_iter().find(|&v| v != a && v != b).unwrap_or(a);
            let (c, d) = (opp(t0), opp(t1));
            if self.edge_tris.contains_key(&sorted(c, d)) {
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
            self.kill(ts[0]);
            self.kill(ts[1]);
            self.add([c, a, d], l0.max(l1));
            self.add([d, b, c], l0.max(l1));
            for v in [a, b, c, d] {
                self.touched[v as usize] = true;
            }
            queue.extend([sorted(a, c), sorted(c, b), sorted(b, d), sorted(d, a)]);
            out.push(EdgeOp::Flip(a, b));
        }
    }

    /// True when vertex `v` lies on the boundary.
    fn on_boundary(&self, v: u32) -> bool {
        self.neighbours(v)
            .into_iter()
            .any(|w| self.triangles_at(v, w).len() == 1)
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
        let shared = self.triangles_at(u, v);
        if shared.is_empty() {
            return false;
        }
        // Link condition: the common neighbours are exactly the shared triangles' tips.
        let (nu, nv) = (self.neighbours(u), self.neighbours(v));
        let common = nv.iter().filter(|w| nu.binary_search(w).is_ok()).count();
        if common != shared.len() {
            return false;
        }
        if self.on_boundary(v) {
            // Only along a straight boundary: (u, v) is a boundary edge and v's
            // other boundary neighbour continues the line from u through v.
            if shared.len() != 1 {
                return false;
            }
            let others: Vec<u32> = nv
                .iter()
                .copied()
                .filter(|&w| w != u && self.triangles_at(v, w).len() == 1)
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
        }
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
                return false;
            }
            replaced.push((t, new));
        }
        for &t in &shared {
            self.kill(t);
        }
        for (t, new) in replaced {
            let level = self.levels[t as usize];
            self.kill(t);
            self.add(new, level);
        }
        self.removed[v as usize] = true;
        for w in nv {
            self.touched[w as usize] = true;
        }
        self.touched[v as usize] = true;
        out.push(EdgeOp::Collapse(v, u));
        true
    }

    /// Live triangles and levels.
    pub fn live(&self) -> (Vec<[u32; 3]>, Vec<u8>) {
        let mut tris = Vec::new();
        let mut levels = Vec::new();
        for (t, tri) in self.tris.iter().enumerate() {
            if let Some(tri) = tri {
                tris.push(*tri);
                levels.push(self.levels[t]);
            }
        }
        (tris, levels)
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
