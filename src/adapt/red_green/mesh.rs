//! The red forest as a mesh: the conforming simulation mesh built from the
//! leaves, and the renumbering that follows the world's vertex compaction.
//!
//! # Alternating diagonals (`adapt.diagonals`)
//! A red split of a grid square's two triangles gives four sub-squares whose
//! diagonals all run the way the square's did, where the uniform grid of the
//! same edge length alternates them in a checkerboard. The mass-spring
//! membrane is not isotropic on either triangulation, and the difference
//! shows: on `hanging_sheet_rest` at rest (error against uniform 96, relative
//! to the diagonal) uniform 64 has 0.114 %, uniform 64 with its diagonals all
//! one way 0.912 %, and base 16 refined everywhere to the same edges 0.163 %.
//! Against a red-green reference the red-green family is the worse
//! discretisation too, so all-one-way diagonals put a floor under every
//! adaptive run's error rather than biasing the reference.
//!
//! So the mesh is emitted with one flip per red split: in a split triangle
//! with a corner of at least 90 degrees (a grid triangle's right angle), the
//! corner child and the middle child form a square (a rectangle at a right
//! angle), and its diagonal is flipped from the midpoint edge to the one from
//! the corner to the midpoint of the opposite side. For a grid triangle that
//! makes the four sub-squares of a split square alternate like the uniform
//! grid, with the same phase at every level, so a grid refined everywhere is
//! the uniform alternating grid triangle for triangle (the test
//! `red_green_refined_everywhere_is_the_uniform_grid`), and `hanging_sheet_rest`
//! refined everywhere has uniform 64's 0.114 %. At an obtuse corner the flip
//! takes the shorter diagonal (the Delaunay one); triangles without such a
//! corner (a disk's) are emitted as split.
//!
//! The flip belongs to the emitted mesh only: the forest, its operations and
//! their inverses are unchanged, and a pair is flipped only while both
//! children are leaves without hanging nodes (else the corner child or the
//! middle one is split further or green-closed, and the children are emitted
//! as before) and the corner child's two outer sides face the boundary or a
//! whole leaf of its own level. That last condition came from a failure: with
//! squares flipped next to a level transition, a green triangle across the
//! flipped square's side had a shape operator blind to a bend (its three
//! folds did not determine the curvature tensor under the per-triangle
//! transition operator the bending then used; `shape.rs` now splits the
//! folds instead): on a sheet refined over `x < -0.15`, six of its sixteen
//! greens carried 0.905 of the continuum's energy for a cylinder about y
//! (test `partly_refined_sheet_bends_like_the_continuum`), and the
//! cantilever's partly refined rungs were up to twice as far from the
//! reference as with the children as split (red_green 10 L6 r0.5: 0.024 %
//! against 0.012 %; with the condition 0.0137 %). The flipped square's two
//! triangles keep the children's level; the one at the corner is owned by the
//! corner child, the other by the middle child, for the marks.
//! `diagonals = "as_split"` keeps paper A's children exactly.

use super::{RedGreen, sorted};
use crate::math::Vector2;
use crate::mesh::PairMap;

impl RedGreen {
    /// The conforming simulation mesh: each leaf, or its two green halves when it
    /// has one hanging node. Returns triangles, their levels and their leaf.
    ///
    /// With `alternate`, a red split of a right (or obtuse) triangle is emitted
    /// with the diagonal of its corner square flipped wherever that corner child
    /// and the middle child are both whole leaves and the square faces no
    /// coarser leaf (module docs, "Alternating diagonals"): the first triangle
    /// of the flipped pair is owned by the corner child, the second by the
    /// middle child.
    pub fn build(&self, alternate: bool) -> (Vec<[u32; 3]>, Vec<u8>, Vec<u32>) {
        let b = self.build_with_corners(alternate);
        (b.triangles, b.levels, b.owner)
    }

    /// [`RedGreen::build`] with each emitted triangle's corners in its panel's
    /// pattern and its panel (what a garment's mesh needs).
    pub fn build_with_corners(&self, alternate: bool) -> Built {
        let leaves = self.leaves();
        let capacity = leaves.len() + leaves.len() / 4;
        let mut out = Built {
            triangles: Vec::with_capacity(capacity),
            levels: Vec::with_capacity(capacity),
            owner: Vec::with_capacity(capacity),
            corners: Vec::with_capacity(capacity),
            panels: Vec::with_capacity(capacity),
        };
        for t in leaves {
            let v = self.vertices(t);
            let level = self.level(t);
            let panel = self.panel(t);
            if alternate {
                match self.flipped_pair(t) {
                    Some(Flip::Middle) => continue, // emitted with its corner child
                    Some(Flip::Corner { pair, middle }) => {
                        for (tri, owner) in pair.into_iter().zip([t, middle]) {
                            let uv = tri.map(|w| self.corner_in(&[t, middle], w));
                            out.push(tri, level, owner, uv, panel);
                        }
                        continue;
                    }
                    None => {}
                }
            }
            match self.hanging_node(t) {
                None => out.push(v, level, t, self.corners(t), panel),
                Some((k, m)) => {
                    let (p, q, o) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
                    let u = self.corners(t);
                    let (up, uq, uo) = (u[k], u[(k + 1) % 3], u[(k + 2) % 3]);
                    let um = (up + uq) * 0.5;
                    out.push([p, m, o], level + 1, t, [up, um, uo], panel);
                    out.push([m, q, o], level + 1, t, [um, uq, uo], panel);
                }
            }
        }
        out
    }

    /// The corner coordinate of vertex `v` in the first of `nodes` that has it.
    fn corner_in(&self, nodes: &[u32], v: u32) -> Vector2 {
        nodes
            .iter()
            .find_map(|&n| {
                let k = self.vertices(n).iter().position(|&w| w == v)?;
                Some(self.corners(n)[k])
            })
            .expect("a flipped pair's vertices are corners of its two children")
    }

    /// The first edge of leaf `t` (from corner k to k + 1) that carries a
    /// hanging node, with that node.
    fn hanging_node(&self, t: u32) -> Option<(usize, u32)> {
        let v = self.vertices(t);
        (0..3).find_map(|k| {
            let (p, q) = (v[k], v[(k + 1) % 3]);
            self.mid.get(&sorted(p, q)).map(|&m| (k, m))
        })
    }

    /// The corner of node `n` whose angle is at least a right angle (to a
    /// relative 1e-9, so that a grid's right angles count despite rounding),
    /// if any.
    fn square_corner(&self, n: u32) -> Option<usize> {
        let v = self.corners(n);
        (0..3).find(|&k| {
            let (a, b) = (v[(k + 2) % 3] - v[k], v[(k + 1) % 3] - v[k]);
            a.dot(b) <= 1e-9 * a.length() * b.length()
        })
    }

    /// Whether the two outer sides of corner child `corner` (at corner `k` of
    /// its parent) each face the mesh boundary or a leaf of its own level that
    /// is emitted whole (module docs: a flipped triangle next to a green one
    /// left that green's curvature blind to a bend under the bending model
    /// this condition was measured with).
    fn level_outside(&self, corner: u32, k: usize) -> bool {
        let c = self.vertices(corner);
        [(c[k], c[(k + 1) % 3]), (c[(k + 2) % 3], c[k])]
            .into_iter()
            .all(|(p, q)| match self.leaf_by_edge.get(&(q, p)) {
                Some(&n) => self.hanging_node(n).is_none(),
                // No leaf across: a boundary side, or one of a coarser leaf
                // (the side is half of the parent's edge, whose other side
                // is a leaf).
                None => self
                    .half_of
                    .get(&(p, q))
                    .is_none_or(|&(pp, qq)| !self.leaf_by_edge.contains_key(&(qq, pp))),
            })
    }

    /// Whether leaf `t` is half of a flipped pair (module docs).
    fn flipped_pair(&self, t: u32) -> Option<Flip> {
        let parent = self.parent(t)?;
        let children = self.children(parent)?;
        let k = self.square_corner(parent)?;
        let (corner, middle) = (children[k], children[3]);
        if (t != corner && t != middle)
            || !self.is_leaf(corner)
            || !self.is_leaf(middle)
            || self.hanging_node(corner).is_some()
            || self.hanging_node(middle).is_some()
            || !self.level_outside(corner, k)
        {
            return None;
        }
        if t == middle {
            return Some(Flip::Middle);
        }
        // The corner child holds v_k at position k, then m_next (the midpoint
        // of the edge from v_k, counter-clockwise) and m_prev (`split` makes
        // them so); the middle child holds m_opp, the midpoint of the edge
        // opposite v_k, at position k + 1. Their common square v_k, m_next,
        // m_opp, m_prev (counter-clockwise) gets the diagonal v_k - m_opp
        // instead of m_next - m_prev.
        let c = self.vertices(corner);
        let (v_k, m_next, m_prev) = (c[k], c[(k + 1) % 3], c[(k + 2) % 3]);
        let m_opp = self.vertices(middle)[(k + 1) % 3];
        Some(Flip::Corner {
            pair: [[v_k, m_next, m_opp], [v_k, m_opp, m_prev]],
            middle,
        })
    }

    /// Follows the world's vertex compaction: `map[old]` is the new index of
    /// every surviving vertex (`u32::MAX` for removed ones).
    ///
    /// Incremental: compaction keeps the surviving vertices
    /// in order, so every id below the first removed one keeps its index. Only
    /// the table entries and nodes that name a later vertex are rekeyed, in
    /// place; after a pass that only refined, nothing is. Rekeying in place
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

/// The conforming mesh [`RedGreen::build_with_corners`] emits, one entry per
/// triangle in each list.
#[derive(Debug, Clone, PartialEq)]
pub struct Built {
    /// Triangles over the forest's vertices, counter-clockwise in their pattern.
    pub triangles: Vec<[u32; 3]>,
    /// Paper A level of each triangle.
    pub levels: Vec<u8>,
    /// The leaf of the forest that owns each triangle.
    pub owner: Vec<u32>,
    /// Each triangle's corners in its panel's pattern, m.
    pub corners: Vec<[Vector2; 3]>,
    /// Each triangle's garment panel (0 for a cloth without panels).
    pub panels: Vec<u16>,
}

impl Built {
    fn push(&mut self, tri: [u32; 3], level: u8, owner: u32, uv: [Vector2; 3], panel: u16) {
        self.triangles.push(tri);
        self.levels.push(level);
        self.owner.push(owner);
        self.corners.push(uv);
        self.panels.push(panel);
    }
}

/// A leaf's part in a flipped pair.
enum Flip {
    /// The corner child: emits the pair.
    Corner {
        /// The two triangles of the flipped square, counter-clockwise.
        pair: [[u32; 3]; 2],
        /// The middle child, which owns the second triangle.
        middle: u32,
    },
    /// The middle child: emits nothing.
    Middle,
}
