//! The red forest as a mesh: the conforming simulation mesh built from the
//! leaves, and the renumbering that follows the world's vertex compaction.

use super::{RedGreen, sorted};
use crate::math::Vector2;
use crate::mesh::PairMap;

impl RedGreen {
    /// The conforming simulation mesh: each leaf, or its two green halves when it
    /// has one hanging node. Returns triangles, their levels and their leaf.
    pub fn build(&self) -> (Vec<[u32; 3]>, Vec<u8>, Vec<u32>) {
        let leaves = self.leaves();
        let mut tris = Vec::with_capacity(leaves.len() + leaves.len() / 4);
        let mut levels = Vec::with_capacity(tris.capacity());
        let mut owner = Vec::with_capacity(tris.capacity());
        for t in leaves {
            let v = self.vertices(t);
            let level = self.level(t);
            let hanging = (0..3).find_map(|k| {
                let (p, q) = (v[k], v[(k + 1) % 3]);
                self.mid.get(&sorted(p, q)).map(|&m| (k, m))
            });
            match hanging {
                None => {
                    tris.push(v);
                    levels.push(level);
                    owner.push(t);
                }
                Some((k, m)) => {
                    let (p, q, o) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
                    tris.extend([[p, m, o], [m, q, o]]);
                    levels.extend([level + 1, level + 1]);
                    owner.extend([t, t]);
                }
            }
        }
        (tris, levels, owner)
    }

    /// Follows the world's vertex compaction: `map[old]` is the new index of
    /// every surviving vertex (`u32::MAX` for removed ones).
    ///
    /// Incremental (issue 13, item 5): compaction keeps the surviving vertices
    /// in order, so every id below the first removed one keeps its index. Only
    /// the table entries and nodes that name a later vertex are rekeyed, in
    /// place; after a pass that only refined, nothing is. (Before, all three
    /// maps were rebuilt from scratch after every remesh.) Rekeying in place
    /// cannot collide: the map is one to one on the surviving vertices, so a
    /// rekeyed entry never lands on an entry that kept its key.
    pub fn remap(&mut self, map: &[u32], material: &[Vector2]) {
        let first = map
            .iter()
            .enumerate()
            .position(|(v, &to)| to != v as u32)
            .unwrap_or(map.len()) as u32;
        if (first as usize) < map.len() {
            let m = |v: u32| map[v as usize];
            for n in self.live_nodes() {
                let node = &mut self.nodes[n as usize];
                if node.v.iter().any(|&v| v >= first) {
                    node.v = node.v.map(m);
                }
            }
            rekey(
                &mut self.mid,
                first,
                |v| v >= first,
                |(a, b), v| (sorted(m(a), m(b)), m(v)),
            );
            rekey(
                &mut self.half_of,
                first,
                |(p, q)| p >= first || q >= first,
                |(a, b), (p, q)| ((m(a), m(b)), (m(p), m(q))),
            );
            // Values are node ids, which compaction does not change.
            rekey(
                &mut self.leaf_by_edge,
                first,
                |_| false,
                |(a, b), n| ((m(a), m(b)), n),
            );
        }
        self.material = material.to_vec();
        self.created.clear();
        self.first_new = material.len() as u32;
    }

    /// Every node reachable from the roots (leaves and split nodes).
    pub(super) fn live_nodes(&self) -> Vec<u32> {
        let mut out = Vec::new();
        let mut stack = self.roots.clone();
        while let Some(n) = stack.pop() {
            out.push(n);
            if let Some(ch) = self.nodes[n as usize].children {
                stack.extend(ch);
            }
        }
        out
    }
}

/// Moves the entries of `table` whose key names a vertex at or above `first`,
/// or whose value does (`names`), to their keys and values under `f`.
fn rekey<V: Copy>(
    table: &mut PairMap<(u32, u32), V>,
    first: u32,
    names: impl Fn(V) -> bool,
    f: impl Fn((u32, u32), V) -> ((u32, u32), V),
) {
    let mut moved = Vec::new();
    table.retain(|&(a, b), v| {
        let stays = a < first && b < first && !names(*v);
        if !stays {
            moved.push(f((a, b), *v));
        }
        stays
    });
    table.extend(moved);
}
