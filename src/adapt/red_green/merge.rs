//! Merging: a node's four children back into it (the inverse of a red split),
//! alone or in a batch with its neighbours, with the checks that keep the mesh
//! conforming.

use super::{Applied, RedGreen, RedGreenOp, edges_of, sorted};

impl RedGreen {
    /// True when `n`'s children are leaves and no neighbour is two splits finer
    /// along `n`'s edges (merging would leave a hanging node at a quarter point).
    pub(super) fn children_mergeable(&self, n: u32) -> bool {
        let Some(children) = self.nodes[n as usize].children else {
            return false;
        };
        if !children.iter().all(|&c| self.is_leaf(c)) {
            return false;
        }
        edges_of(self.vertices(n))
            .iter()
            .all(|&(p, q)| match self.mid.get(&sorted(p, q)) {
                Some(&m) => {
                    !self.mid.contains_key(&sorted(p, m)) && !self.mid.contains_key(&sorted(m, q))
                }
                None => false,
            })
    }

    /// The leaf across `n`'s edge (p, q) that uses its midpoint `m`, if any.
    fn outside_user(&self, p: u32, q: u32, m: u32) -> Option<u32> {
        self.leaf_by_edge
            .get(&(q, m))
            .or_else(|| self.leaf_by_edge.get(&(m, p)))
            .copied()
    }

    /// Midpoints of `n`'s edges that stay in use by neighbours after merging `n`
    /// together with the nodes in `merging` (sorted).
    fn persisting_uses(&self, n: u32, merging: &[u32]) -> usize {
        edges_of(self.vertices(n))
            .iter()
            .filter(|&&(p, q)| {
                let m = self.mid[&sorted(p, q)];
                self.outside_user(p, q, m).is_some_and(|u| {
                    self.parent(u)
                        .is_none_or(|up| merging.binary_search(&up).is_err())
                })
            })
            .count()
    }

    /// Merges a set of nodes together. A node is dropped from the set while more
    /// than one of its edge midpoints would stay in use by neighbours that are
    /// not merging too (closure would split it again at once); the rest merge.
    pub fn merge_batch(&mut self, candidates: &[u32], out: &mut Vec<Applied>) {
        for n in self.select_merges(candidates).0 {
            self.merge(n, out);
        }
    }

    /// The nodes [`RedGreen::merge_batch`] would merge out of `candidates`
    /// (sorted), and those it would drop while their children may merge, each
    /// with the number of its edge midpoints that neighbours keep in use.
    pub fn select_merges(&self, candidates: &[u32]) -> (Vec<u32>, Vec<(u32, usize)>) {
        let mut set: Vec<u32> = candidates
            .iter()
            .copied()
            .filter(|&n| self.children_mergeable(n))
            .collect();
        set.sort_unstable();
        set.dedup();
        let mut dropped = Vec::new();
        loop {
            let mut keep = Vec::with_capacity(set.len());
            for &n in &set {
                match self.persisting_uses(n, &set) {
                    0 | 1 => keep.push(n),
                    uses => dropped.push((n, uses)),
                }
            }
            if keep.len() == set.len() {
                break;
            }
            set = keep;
        }
        (set, dropped)
    }

    pub(super) fn merge(&mut self, n: u32, out: &mut Vec<Applied>) {
        let Some(children) = self.nodes[n as usize].children else {
            return;
        };
        for &c in &children {
            self.remove_leaf_edges(c);
        }
        let mut midpoints = Vec::new();
        for (p, q) in edges_of(self.vertices(n)) {
            let m = self.mid[&sorted(p, q)];
            self.half_of.remove(&(p, m));
            self.half_of.remove(&(m, q));
            if self.outside_user(p, q, m).is_none() {
                self.mid.remove(&sorted(p, q));
                midpoints.push((sorted(p, q), m));
            }
        }
        self.nodes[n as usize].children = None;
        self.add_leaf_edges(n);
        self.free.extend(children);
        let level = self.level(n);
        out.push(Applied {
            op: RedGreenOp::Merge(n),
            vertices: self.vertices(n),
            level,
            forced: false,
            neighbour: None,
            children,
            midpoints,
            nodes_before: self.nodes.len() as u32,
            reused: Vec::new(),
        });
    }

    /// Nodes whose four children are leaves and could merge (alone or together
    /// with neighbours), in leaf order.
    pub fn mergeable_parents(&self) -> Vec<u32> {
        self.leaf_parents()
            .into_iter()
            .filter_map(|(p, mergeable)| mergeable.then_some(p))
            .collect()
    }

    /// Nodes whose four children are leaves, in leaf order, each with whether
    /// they could merge (false: a neighbour is two splits finer along its
    /// edges).
    pub fn leaf_parents(&self) -> Vec<(u32, bool)> {
        let mut seen: Vec<(u32, bool)> = Vec::new();
        for t in self.leaves() {
            if let Some(p) = self.parent(t)
                && seen.last().map(|s| s.0) != Some(p)
                && self
                    .children(p)
                    .is_some_and(|ch| ch.iter().all(|&c| self.is_leaf(c)))
            {
                seen.push((p, self.children_mergeable(p)));
            }
        }
        seen
    }
}
