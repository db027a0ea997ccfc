//! Paper A's hierarchical refinement: 1-4 ("red") splits kept in a forest,
//! closed by 1-2 ("green") splits so the simulation mesh is always conforming.
//!
//! * The forest's leaves form the *red mesh*, which may have hanging nodes (the
//!   midpoint of a leaf's edge created by the neighbour's split). Neighbours
//!   across an edge differ by at most one red split (1-irregularity): a split
//!   first splits any coarser neighbour, and a merge is refused when it would
//!   leave a neighbour two splits finer.
//! * Closure: a leaf with two or three hanging nodes is split red (paper A's
//!   rule 3); a leaf with one gets a green 1-2 split (rule 2), rebuilt on every
//!   pass from the red mesh (greens are derived, never stored).
//! * Levels (paper A, 2.1): a red split adds 2, a green split adds 1.
//!
//! Vertex ids here are the world's vertex indices; vertices created during a pass
//! are appended, and [`RedGreen::remap`] follows the world's compaction
//! (`red_green/mesh.rs`, which also builds the conforming mesh).
//!
//! Operations are values: every split or merge done is reported as
//! an [`Applied`] that records what it added and removed, and [`RedGreen::undo`]
//! applies its exact inverse (`red_green/undo.rs`). The adapter uses it to keep
//! a pass atomic when the world refuses the new mesh.

mod merge;
mod mesh;
mod undo;

pub use mesh::Built;

use crate::math::Vector2;
use crate::mesh::PairMap;

/// Marks "no node" (a root's parent).
const NONE: u32 = u32::MAX;

/// A triangle of the red forest.
#[derive(Debug, Clone, PartialEq)]
struct Node {
    /// Vertices, counter-clockwise in material space.
    v: [u32; 3],
    /// The material coordinates of the corners, in the node's panel's pattern
    /// (a vertex on a welded seam has one coordinate per panel).
    uv: [Vector2; 3],
    /// The garment panel of the root this node descends from (0 for a cloth
    /// without panels).
    panel: u16,
    /// Paper A level (even: 0, 2, 4, ...).
    level: u8,
    /// Parent node, or [`NONE`].
    parent: u32,
    /// The four children after a 1-4 split: three corners, then the middle.
    children: Option<[u32; 4]>,
}

/// One red-green operation as a value: applying it to the forest and undoing it
/// (the opposite operation on the same node) are exact inverses on the topology.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RedGreenOp {
    /// 1-4 split of a leaf.
    Split(u32),
    /// Merge of the four leaf children of a node back into it.
    Merge(u32),
}

impl RedGreenOp {
    /// The operation that undoes this one.
    pub fn inverse(self) -> RedGreenOp {
        match self {
            RedGreenOp::Split(n) => RedGreenOp::Merge(n),
            RedGreenOp::Merge(n) => RedGreenOp::Split(n),
        }
    }
}

/// What a split or merge did, as a value: for events and counters, and with
/// what it added and removed so that [`RedGreen::undo`] applies its inverse
/// exactly (see `red_green/undo.rs`).
#[derive(Debug, Clone, PartialEq)]
pub struct Applied {
    /// The operation.
    pub op: RedGreenOp,
    /// The node's vertices (for the event position).
    pub vertices: [u32; 3],
    /// Level of the triangles the operation created (children for a split, the
    /// parent for a merge).
    pub level: u8,
    /// True for a split forced by closure or 1-irregularity rather than asked for.
    pub forced: bool,
    /// For a split forced by 1-irregularity: the finer neighbour whose split
    /// forced it (`None` for every other operation).
    pub neighbour: Option<u32>,
    /// The four children the split made or the merge freed.
    pub children: [u32; 4],
    /// Midpoint entries (sorted edge, vertex) the split created (each with a
    /// new vertex) or the merge dropped.
    pub midpoints: Vec<((u32, u32), u32)>,
    /// Split: the node count before, and the earlier contents of the free
    /// slots its children took (restored by the undo).
    nodes_before: u32,
    reused: Vec<Node>,
}

/// The red forest with its lookup tables.
#[derive(Debug, Clone, PartialEq)]
pub struct RedGreen {
    nodes: Vec<Node>,
    roots: Vec<u32>,
    free: Vec<u32>,
    /// Sorted edge -> its midpoint vertex, for every edge split by some red split.
    mid: PairMap<(u32, u32), u32>,
    /// Directed half edge of a split node -> the directed edge it halves.
    half_of: PairMap<(u32, u32), (u32, u32)>,
    /// Directed edge of a leaf (counter-clockwise) -> that leaf.
    leaf_by_edge: PairMap<(u32, u32), u32>,
    /// Material coordinates of every vertex, including those made in this pass.
    material: Vec<Vector2>,
    /// For each vertex made in this pass (id `first_new + k`), its parent edge.
    created: Vec<(u32, u32)>,
    first_new: u32,
}

/// Why [`RedGreen::split`] splits a leaf.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Forcing {
    /// Asked for by an operation.
    Asked,
    /// Forced by 1-irregularity: the finer neighbour being split.
    Neighbour(u32),
    /// Forced by closure: two or more hanging nodes.
    Closure,
}

fn sorted(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

fn edges_of(v: [u32; 3]) -> [(u32, u32); 3] {
    [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])]
}

impl RedGreen {
    /// A forest whose roots are the triangles of the input mesh (all level 0).
    pub fn new(triangles: &[[u32; 3]], material: &[Vector2]) -> RedGreen {
        let corners: Vec<[Vector2; 3]> = triangles
            .iter()
            .map(|t| t.map(|v| material[v as usize]))
            .collect();
        let panels = vec![0; triangles.len()];
        RedGreen::with_corners(triangles, material, &corners, &panels)
    }

    /// A forest over a garment's triangles: each root carries its corners'
    /// pattern coordinates and its panel (`corners` and `panels`, one per
    /// triangle), and every node made from it takes its corners from its
    /// parent's, so a split across a welded seam gives each side the midpoint
    /// in its own pattern. `material` is each vertex's home coordinate.
    pub fn with_corners(
        triangles: &[[u32; 3]],
        material: &[Vector2],
        corners: &[[Vector2; 3]],
        panels: &[u16],
    ) -> RedGreen {
        let mut rg = RedGreen {
            nodes: Vec::with_capacity(triangles.len()),
            roots: Vec::with_capacity(triangles.len()),
            free: Vec::new(),
            mid: PairMap::default(),
            half_of: PairMap::default(),
            leaf_by_edge: PairMap::default(),
            material: material.to_vec(),
            created: Vec::new(),
            first_new: material.len() as u32,
        };
        for ((&v, &uv), &panel) in triangles.iter().zip(corners).zip(panels) {
            let id = rg.alloc(Node {
                v,
                uv,
                panel,
                level: 0,
                parent: NONE,
                children: None,
            });
            rg.roots.push(id);
            rg.add_leaf_edges(id);
        }
        rg
    }

    fn alloc(&mut self, node: Node) -> u32 {
        match self.free.pop() {
            Some(id) => {
                self.nodes[id as usize] = node;
                id
            }
            None => {
                self.nodes.push(node);
                (self.nodes.len() - 1) as u32
            }
        }
    }

    fn add_leaf_edges(&mut self, id: u32) {
        for e in edges_of(self.nodes[id as usize].v) {
            self.leaf_by_edge.insert(e, id);
        }
    }

    fn remove_leaf_edges(&mut self, id: u32) {
        for e in edges_of(self.nodes[id as usize].v) {
            self.leaf_by_edge.remove(&e);
        }
    }

    /// True when `n` is a leaf of the forest.
    pub fn is_leaf(&self, n: u32) -> bool {
        self.nodes[n as usize].children.is_none()
    }

    /// Level of node `n`.
    pub fn level(&self, n: u32) -> u8 {
        self.nodes[n as usize].level
    }

    /// Parent of node `n`, if any.
    pub fn parent(&self, n: u32) -> Option<u32> {
        let p = self.nodes[n as usize].parent;
        (p != NONE).then_some(p)
    }

    /// The four children of node `n` after a split.
    pub fn children(&self, n: u32) -> Option<[u32; 4]> {
        self.nodes[n as usize].children
    }

    /// Vertices of node `n`.
    pub fn vertices(&self, n: u32) -> [u32; 3] {
        self.nodes[n as usize].v
    }

    /// Material coordinates of node `n`'s corners, in its panel's pattern.
    pub fn corners(&self, n: u32) -> [Vector2; 3] {
        self.nodes[n as usize].uv
    }

    /// The garment panel of node `n` (0 for a cloth without panels).
    pub fn panel(&self, n: u32) -> u16 {
        self.nodes[n as usize].panel
    }

    /// Material coordinates of all vertices (old and made in this pass).
    pub fn material(&self) -> &[Vector2] {
        &self.material
    }

    /// Parent edges of the vertices made since the last [`RedGreen::remap`].
    pub fn created(&self) -> (u32, &[(u32, u32)]) {
        (self.first_new, &self.created)
    }

    /// Shortest material edge of node `n`, m.
    pub fn shortest_edge(&self, n: u32) -> f64 {
        let p = self.corners(n);
        (0..3)
            .map(|k| p[k].distance(p[(k + 1) % 3]))
            .fold(f64::INFINITY, f64::min)
    }

    /// Applies `ops`: all merges first, decided together, then the splits in
    /// order. Returns what was done (a split may first split coarser neighbours);
    /// operations that do not apply (a merge that would break conformity, a
    /// split of a node that is no longer a leaf) are skipped.
    pub fn apply(&mut self, ops: &[RedGreenOp], out: &mut Vec<Applied>) {
        let merges: Vec<u32> = ops
            .iter()
            .filter_map(|op| match op {
                RedGreenOp::Merge(n) => Some(*n),
                _ => None,
            })
            .collect();
        self.merge_batch(&merges, out);
        for op in ops {
            if let RedGreenOp::Split(n) = *op {
                self.split(n, Forcing::Asked, out);
            }
        }
    }

    /// 1-4 split of leaf `t`, splitting coarser neighbours first.
    fn split(&mut self, t: u32, forcing: Forcing, out: &mut Vec<Applied>) {
        if !self.is_leaf(t) {
            return;
        }
        for (p, q) in edges_of(self.vertices(t)) {
            if self.leaf_by_edge.contains_key(&(q, p)) {
                continue; // a neighbour leaf of the same level
            }
            if let Some(&(pp, qq)) = self.half_of.get(&(p, q))
                && let Some(&coarse) = self.leaf_by_edge.get(&(qq, pp))
            {
                self.split(coarse, Forcing::Neighbour(t), out);
            }
        }
        let [a, b, c] = self.vertices(t);
        let made = self.created.len();
        let (mab, mbc, mca) = (
            self.midpoint(a, b),
            self.midpoint(b, c),
            self.midpoint(c, a),
        );
        let midpoints = (made..self.created.len())
            .map(|k| {
                let (p, q) = self.created[k];
                (sorted(p, q), self.first_new + k as u32)
            })
            .collect();
        let level = self.level(t) + 2;
        let panel = self.panel(t);
        let [ua, ub, uc] = self.corners(t);
        let (uab, ubc, uca) = ((ua + ub) * 0.5, (ub + uc) * 0.5, (uc + ua) * 0.5);
        self.remove_leaf_edges(t);
        let corners = [
            ([a, mab, mca], [ua, uab, uca]),
            ([mab, b, mbc], [uab, ub, ubc]),
            ([mca, mbc, c], [uca, ubc, uc]),
            ([mab, mbc, mca], [uab, ubc, uca]),
        ];
        let mut ids = [0u32; 4];
        let nodes_before = self.nodes.len() as u32;
        let mut reused = Vec::new();
        for (k, (v, uv)) in corners.into_iter().enumerate() {
            if let Some(&slot) = self.free.last() {
                reused.push(self.nodes[slot as usize].clone());
            }
            ids[k] = self.alloc(Node {
                v,
                uv,
                panel,
                level,
                parent: t,
                children: None,
            });
            self.add_leaf_edges(ids[k]);
        }
        for ((p, q), m) in edges_of([a, b, c]).into_iter().zip([mab, mbc, mca]) {
            self.half_of.insert((p, m), (p, q));
            self.half_of.insert((m, q), (p, q));
        }
        self.nodes[t as usize].children = Some(ids);
        out.push(Applied {
            op: RedGreenOp::Split(t),
            vertices: [a, b, c],
            level,
            forced: forcing != Forcing::Asked,
            neighbour: match forcing {
                Forcing::Neighbour(n) => Some(n),
                Forcing::Asked | Forcing::Closure => None,
            },
            children: ids,
            midpoints,
            nodes_before,
            reused,
        });
    }

    /// The midpoint vertex of edge (a, b), made if it does not exist yet.
    fn midpoint(&mut self, a: u32, b: u32) -> u32 {
        if let Some(&m) = self.mid.get(&sorted(a, b)) {
            return m;
        }
        let m = self.material.len() as u32;
        self.material
            .push((self.material[a as usize] + self.material[b as usize]) * 0.5);
        self.created.push((a, b));
        self.mid.insert(sorted(a, b), m);
        m
    }

    /// Number of hanging nodes on the edges of leaf `t`.
    fn hanging(&self, t: u32) -> usize {
        edges_of(self.vertices(t))
            .iter()
            .filter(|&&(p, q)| self.mid.contains_key(&sorted(p, q)))
            .count()
    }

    /// Red-splits every leaf with two or more hanging nodes until none is left.
    pub fn close(&mut self, out: &mut Vec<Applied>) {
        loop {
            let crowded: Vec<u32> = self
                .leaves()
                .into_iter()
                .filter(|&t| self.hanging(t) >= 2)
                .collect();
            if crowded.is_empty() {
                return;
            }
            for t in crowded {
                self.split(t, Forcing::Closure, out);
            }
        }
    }

    /// The leaves in a fixed order (roots in input order, depth first).
    pub fn leaves(&self) -> Vec<u32> {
        let mut out = Vec::new();
        let mut stack: Vec<u32> = self.roots.iter().rev().copied().collect();
        while let Some(n) = stack.pop() {
            match self.nodes[n as usize].children {
                None => out.push(n),
                Some(ch) => stack.extend(ch.iter().rev()),
            }
        }
        out
    }
}
