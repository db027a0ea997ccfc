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
use crate::mesh::Mesh;

pub use super::soup::{Soup, SoupOp, SoupTri, VertexChange};

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

/// A triangle to be halved by a split: `old` as it is, the split edge running
/// p -> q, `o` the opposite corner, and their pattern coordinates with the
/// midpoint's (`um`, in this triangle's panel).
struct Halved {
    old: SoupTri,
    p: u32,
    q: u32,
    o: u32,
    uv: [Vector2; 3],
    um: Vector2,
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
        if self.len2(a, b).sqrt() * 0.5 < limits.min_edge {
            return false;
        }
        let mut plan = Vec::new();
        for t in around.iter() {
            let Some(old) = self.soup_tri(t) else {
                continue;
            };
            let Some(half) = self.halve(old, a, b, limits) else {
                return false;
            };
            plan.push(half);
        }
        let Some(first) = plan.first() else {
            return false;
        };
        let m = self.material.len() as u32;
        let base = self.tris.len() as u32;
        let mut op = SoupOp {
            vertex: Some(VertexChange::Append {
                id: m,
                material: first.um,
                parent: (a, b),
            }),
            slots: (base, base + 2 * plan.len() as u32),
            ..SoupOp::default()
        };
        let mut touched = Vec::new();
        for (k, h) in plan.iter().enumerate() {
            let slot = base + 2 * k as u32;
            let [up, uq, uo] = h.uv;
            let (level, panel) = (h.old.level + 1, h.old.panel);
            op.removed.push(h.old);
            op.added.push(SoupTri {
                slot,
                tri: [h.p, m, h.o],
                level,
                uv: [up, h.um, uo],
                panel,
            });
            op.added.push(SoupTri {
                slot: slot + 1,
                tri: [m, h.q, h.o],
                level,
                uv: [h.um, uq, uo],
                panel,
            });
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

    /// Triangle `old` halved across its edge (a, b) at its midpoint in the
    /// triangle's pattern; `None` when a half would go past `max_level` or
    /// below `min_angle`.
    fn halve(&self, old: SoupTri, a: u32, b: u32, limits: &Limits) -> Option<Halved> {
        let tri = old.tri;
        let k = (0..3)
            .find(|&k| sorted(tri[k], tri[(k + 1) % 3]) == sorted(a, b))
            .unwrap_or(0);
        let (p, q, o) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
        if old.level as u32 + 1 > limits.max_level as u32 {
            return None;
        }
        let (mp, mq, mo) = (old.uv[k], old.uv[(k + 1) % 3], old.uv[(k + 2) % 3]);
        let um = (mp + mq) * 0.5;
        if min_angle_deg([mp, um, mo]) < limits.min_angle
            || min_angle_deg([um, mq, mo]) < limits.min_angle
        {
            return None;
        }
        Some(Halved {
            old,
            p,
            q,
            o,
            uv: [mp, mq, mo],
            um,
        })
    }

    /// Flips interior edges at the given vertices while that improves the
    /// Delaunay criterion in material space (never below `min_angle`).
    pub fn flip_around(&mut self, seeds: &[u32], limits: &Limits, out: &mut Vec<EdgeOp>) {
        let mut queue = self.edges_at(seeds);
        let mut budget = 16 * queue.len() + 16;
        while let Some((a, b)) = queue.pop() {
            budget = budget.saturating_sub(1);
            if budget == 0 {
                break;
            }
            let Some([a, b, c, d]) = self.flip(a, b, limits) else {
                continue;
            };
            queue.extend([sorted(a, c), sorted(c, b), sorted(b, d), sorted(d, a)]);
            out.push(EdgeOp::Flip(a, b));
        }
    }

    /// The edges of the triangles at the vertices `seeds`, sorted and without repeats.
    fn edges_at(&self, seeds: &[u32]) -> Vec<(u32, u32)> {
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
        queue
    }

    /// Flips the interior edge `a`-`b` into `c`-`d` when that improves the
    /// Delaunay criterion in material space (never below `min_angle`), and
    /// returns `[a, b, c, d]` with `a -> b` the direction of the first
    /// triangle; `None` when the edge stays.
    fn flip(&mut self, a: u32, b: u32, limits: &Limits) -> Option<[u32; 4]> {
        let ts = self.tris_at(a, b).to_pair()?;
        let (s0, s1) = (self.soup_tri(ts[0])?, self.soup_tri(ts[1])?);
        let (t0, t1) = (s0.tri, s1.tri);
        let opp = |t: [u32; 3]| t.into_iter().find(|&v| v != a && v != b).unwrap_or(a);
        let (c, d) = (opp(t0), opp(t1));
        if self.has_edge(c, d) {
            return None; // flipping would duplicate an edge
        }
        // Orient: t0 runs a -> b, so the flipped pair is (c, a, d), (d, b, c).
        let runs_ab = (0..3).any(|k| t0[k] == a && t0[(k + 1) % 3] == b);
        let (a, b) = if runs_ab { (a, b) } else { (b, a) };
        let at = |t: u32, v: u32| {
            self.corner_at(t, v)
                .expect("a flip's four vertices are corners of its two triangles")
        };
        let (pa, pb, pc, pd) = (at(ts[0], a), at(ts[0], b), at(ts[0], c), at(ts[1], d));
        // A garment's welded seam is not flipped: its two triangles lie in
        // different patterns.
        if s0.panel != s1.panel || at(ts[1], a) != pa || at(ts[1], b) != pb {
            return None;
        }
        let [new0, new1] = flipped_if_better([pa, pb, pc, pd], limits)?;
        let level = s0.level.max(s1.level);
        let base = self.tris.len() as u32;
        let added = |slot: u32, tri: [u32; 3], uv: [Vector2; 3]| SoupTri {
            slot,
            tri,
            level,
            uv,
            panel: s0.panel,
        };
        let op = SoupOp {
            vertex: None,
            removed: vec![s0, s1],
            added: vec![
                added(base, [c, a, d], new0),
                added(base + 1, [d, b, c], new1),
            ],
            slots: (base, base + 2),
            touched: self.touching(&[a, b, c, d]),
        };
        self.commit(op);
        Some([a, b, c, d])
    }
}

/// The material-space triangles `(c, a, d)` and `(d, b, c)` of flipping the
/// edge `a`-`b` of the triangles `(a, b, c)` and `(b, a, d)` (corners
/// `[pa, pb, pc, pd]`), when the four make a convex quadrilateral that is not
/// Delaunay and the flip raises the smallest angle to at least `min_angle`.
fn flipped_if_better(corners: [Vector2; 4], limits: &Limits) -> Option<[[Vector2; 3]; 2]> {
    let [pa, pb, pc, pd] = corners;
    let new0 = [pc, pa, pd];
    let new1 = [pd, pb, pc];
    let area = |p: [Vector2; 3]| (p[1] - p[0]).perp_dot(p[2] - p[0]);
    if area(new0) <= 0.0 || area(new1) <= 0.0 {
        return None; // not a convex quadrilateral
    }
    let angle_at = |x: Vector2, p: Vector2, q: Vector2| {
        (p - x).perp_dot(q - x).abs().atan2((p - x).dot(q - x))
    };
    if angle_at(pc, pa, pb) + angle_at(pd, pa, pb) <= std::f64::consts::PI + 1e-9 {
        return None; // already Delaunay
    }
    let before = min_angle_deg([pa, pb, pc]).min(min_angle_deg([pb, pa, pd]));
    let after = min_angle_deg(new0).min(min_angle_deg(new1));
    if after < limits.min_angle || after <= before {
        return None;
    }
    Some([new0, new1])
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
    /// 0.75 of its shortest edge (in its triangles' patterns).
    pub fn for_mesh(mesh: &Mesh, max_level: u8, min_edge: Scalar) -> Limits {
        let corners = (0..mesh.triangles.len()).map(|t| mesh.corners(t));
        let min_angle = corners.clone().map(min_angle_deg).fold(180.0, Scalar::min);
        let shortest = corners
            .flat_map(|p| (0..3).map(move |k| p[k].distance(p[(k + 1) % 3])))
            .fold(Scalar::INFINITY, Scalar::min);
        Limits {
            min_angle: 0.5 * min_angle,
            min_edge,
            collapse_below: 0.75 * shortest,
            max_level,
        }
    }
}
