//! Red-green operations as plans: [`RedGreen::undo`] applies the inverse of a
//! split or merge that [`RedGreen::apply`] or [`RedGreen::close`] reported, and
//! [`RedGreen::check_tables`] compares the incrementally kept lookup tables with
//! tables rebuilt from the forest.
//!
//! The inverse is exact, the forest compares equal afterwards (free list, node
//! slots and vertex arrays included), when the reported operations are undone
//! newest first and before [`RedGreen::remap`]; `tests/integration/remesh_ops.rs`
//! checks it on random operation sequences.
//!
//! * Inverse of a split of `t`: drop the children's leaf edges and the six half
//!   edges, drop the midpoint entries (and vertices) the split created, give
//!   `t` its leaf edges back, and return the children's slots: pop the ones
//!   pushed, put back the earlier contents of the free slots taken (in reverse,
//!   so the free list is in its old order).
//! * Inverse of a merge of `n`: take the four children back off the free list
//!   (their nodes were left as they were), restore the dropped midpoint entries,
//!   the half edges and the children's leaf edges.

use super::{Applied, RedGreen, RedGreenOp, edges_of, sorted};
use crate::mesh::PairMap;

impl RedGreen {
    /// Applies the inverse of `done`, one of the operations this forest
    /// reported (undo them newest first, before [`RedGreen::remap`]).
    pub fn undo(&mut self, done: &Applied) {
        match done.op.inverse() {
            RedGreenOp::Merge(t) => self.unsplit(t, done),
            RedGreenOp::Split(n) => self.unmerge(n, done),
        }
    }

    fn unsplit(&mut self, t: u32, done: &Applied) {
        for &c in &done.children {
            self.remove_leaf_edges(c);
        }
        for (p, q) in edges_of(self.vertices(t)) {
            let m = self.mid[&sorted(p, q)];
            self.half_of.remove(&(p, m));
            self.half_of.remove(&(m, q));
        }
        for &(edge, m) in done.midpoints.iter().rev() {
            self.mid.remove(&edge);
            debug_assert_eq!(m as usize + 1, self.material.len(), "newest vertex");
            self.material.pop();
            self.created.pop();
        }
        self.nodes[t as usize].children = None;
        self.add_leaf_edges(t);
        let mut reused = done.reused.iter().rev();
        for &c in done.children.iter().rev() {
            if c >= done.nodes_before {
                debug_assert_eq!(c as usize + 1, self.nodes.len(), "newest node");
                self.nodes.pop();
            } else if let Some(node) = reused.next() {
                self.nodes[c as usize] = node.clone();
                self.free.push(c);
            }
        }
    }

    fn unmerge(&mut self, n: u32, done: &Applied) {
        let kept = self.free.len() - done.children.len();
        debug_assert_eq!(
            self.free[kept..],
            done.children,
            "children on the free list"
        );
        self.free.truncate(kept);
        self.remove_leaf_edges(n);
        for &(edge, m) in &done.midpoints {
            self.mid.insert(edge, m);
        }
        for (p, q) in edges_of(self.vertices(n)) {
            let m = self.mid[&sorted(p, q)];
            self.half_of.insert((p, m), (p, q));
            self.half_of.insert((m, q), (p, q));
        }
        self.nodes[n as usize].children = Some(done.children);
        for &c in &done.children {
            self.add_leaf_edges(c);
        }
    }

    /// Compares the lookup tables kept up to date operation by operation with
    /// tables built from scratch from the forest; `Err` names the first that
    /// differs.
    pub fn check_tables(&self) -> Result<(), String> {
        let mut mid = PairMap::default();
        let mut half_of = PairMap::default();
        let mut leaf_by_edge = PairMap::default();
        for n in self.live_nodes() {
            let node = &self.nodes[n as usize];
            match node.children {
                None => {
                    for e in edges_of(node.v) {
                        leaf_by_edge.insert(e, n);
                    }
                }
                Some(ch) => {
                    // The middle child's corners are the midpoints of the edges
                    // (a, b), (b, c), (c, a) in that order.
                    let mids = self.nodes[ch[3] as usize].v;
                    for ((p, q), m) in edges_of(node.v).into_iter().zip(mids) {
                        mid.insert(sorted(p, q), m);
                        half_of.insert((p, m), (p, q));
                        half_of.insert((m, q), (p, q));
                    }
                }
            }
        }
        for (name, same) in [
            ("midpoint", mid == self.mid),
            ("half edge", half_of == self.half_of),
            ("leaf edge", leaf_by_edge == self.leaf_by_edge),
        ] {
            if !same {
                return Err(format!("red-green {name} table differs from a rebuild"));
            }
        }
        Ok(())
    }
}
