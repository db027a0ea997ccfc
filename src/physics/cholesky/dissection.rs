//! Nested dissection of the vertex graph: a fill-reducing ordering that
//! splits the mesh by a separator, orders both halves the same way, and puts
//! the separator last (George 1973). On a planar mesh a breadth-first
//! search's middle level is such a separator, of about the square root of the
//! vertices. Parts of at most [`LEAF`] vertices are ordered by AMD.

use super::{FactorError, amd_order};

/// The largest part ordered by AMD instead of dissected further.
const LEAF: usize = 256;

/// The graph and the marks of one dissection.
struct Graph {
    /// Per vertex, its neighbours: `neighbours[start[v]..start[v + 1]]`.
    start: Vec<u32>,
    neighbours: Vec<u32>,
    /// Per vertex: the part it belongs to now.
    part: Vec<u32>,
    /// Per vertex: its breadth-first level in the last search.
    level: Vec<u32>,
    /// Parts numbered so far.
    parts: u32,
}

/// The elimination order (position to vertex) of the graph given as the lower
/// triangle (`column_start`, `rows`, diagonal included) of `n` vertices.
pub(super) fn nested_dissection(
    n: usize,
    column_start: &[u32],
    rows: &[u32],
) -> Result<Vec<u32>, FactorError> {
    let mut degree = vec![0u32; n + 1];
    for j in 0..n {
        for &i in &rows[column_start[j] as usize..column_start[j + 1] as usize] {
            if i as usize != j {
                degree[i as usize] += 1;
                degree[j] += 1;
            }
        }
    }
    let mut start = vec![0u32; n + 1];
    for v in 0..n {
        start[v + 1] = start[v] + degree[v];
    }
    let mut fill = start.clone();
    let mut neighbours = vec![0u32; start[n] as usize];
    for j in 0..n {
        for &i in &rows[column_start[j] as usize..column_start[j + 1] as usize] {
            if i as usize != j {
                neighbours[fill[i as usize] as usize] = j as u32;
                fill[i as usize] += 1;
                neighbours[fill[j] as usize] = i;
                fill[j] += 1;
            }
        }
    }
    let mut graph = Graph {
        start,
        neighbours,
        part: vec![0; n],
        level: vec![0; n],
        parts: 1,
    };
    let mut order = Vec::with_capacity(n);
    graph.dissect((0..n as u32).collect(), &mut order)?;
    Ok(order)
}

impl Graph {
    /// Appends the order of the vertices `set` (one part) to `order`.
    fn dissect(&mut self, set: Vec<u32>, order: &mut Vec<u32>) -> Result<(), FactorError> {
        if set.len() <= LEAF {
            return self.order_leaf(&set, order);
        }
        let tag = self.tag(&set);
        let far = *self.search(set[0], tag).last().unwrap_or(&set[0]);
        let reached = self.search(far, tag);
        if reached.len() < set.len() {
            // Disconnected: the component found and the rest, each alone.
            let rest: Vec<u32> = set
                .iter()
                .copied()
                .filter(|&v| self.level[v as usize] == u32::MAX)
                .collect();
            self.dissect(reached, order)?;
            return self.dissect(rest, order);
        }
        let middle = self.level[reached[reached.len() / 2] as usize];
        let (mut low, mut high, mut separator) = (Vec::new(), Vec::new(), Vec::new());
        for &v in &reached {
            let l = self.level[v as usize];
            if l < middle {
                low.push(v);
            } else if l > middle {
                high.push(v);
            } else if self.touches_level(v, middle + 1, tag) {
                separator.push(v);
            } else {
                // No neighbour beyond: it separates nothing, so it joins the low side.
                low.push(v);
            }
        }
        if high.is_empty() || low.is_empty() {
            return self.order_leaf(&set, order);
        }
        self.dissect(low, order)?;
        self.dissect(high, order)?;
        order.extend_from_slice(&separator);
        Ok(())
    }

    /// Marks `set` as a new part; returns its tag.
    fn tag(&mut self, set: &[u32]) -> u32 {
        self.parts += 1;
        for &v in set {
            self.part[v as usize] = self.parts;
            self.level[v as usize] = u32::MAX;
        }
        self.parts
    }

    /// Breadth-first search from `from` within the part `tag`: the vertices in
    /// the order found, their levels in `level` (`u32::MAX` for the unreached).
    fn search(&mut self, from: u32, tag: u32) -> Vec<u32> {
        let mut found = Vec::new();
        self.clear_levels(from, tag);
        self.level[from as usize] = 0;
        found.push(from);
        let mut next = 0;
        while next < found.len() {
            let v = found[next] as usize;
            next += 1;
            for k in self.start[v] as usize..self.start[v + 1] as usize {
                let w = self.neighbours[k] as usize;
                if self.part[w] == tag && self.level[w] == u32::MAX {
                    self.level[w] = self.level[v] + 1;
                    found.push(w as u32);
                }
            }
        }
        found
    }

    /// Sets the level of every vertex of part `tag` reachable from `from` to
    /// unreached.
    fn clear_levels(&mut self, from: u32, tag: u32) {
        let mut stack = vec![from];
        let marker = u32::MAX - 1;
        self.level[from as usize] = marker;
        let mut seen = vec![from];
        while let Some(v) = stack.pop() {
            let v = v as usize;
            for k in self.start[v] as usize..self.start[v + 1] as usize {
                let w = self.neighbours[k];
                if self.part[w as usize] == tag && self.level[w as usize] != marker {
                    self.level[w as usize] = marker;
                    stack.push(w);
                    seen.push(w);
                }
            }
        }
        for v in seen {
            self.level[v as usize] = u32::MAX;
        }
    }

    /// True when `v` has a neighbour of part `tag` at `level`.
    fn touches_level(&self, v: u32, level: u32, tag: u32) -> bool {
        let v = v as usize;
        (self.start[v] as usize..self.start[v + 1] as usize).any(|k| {
            let w = self.neighbours[k] as usize;
            self.part[w] == tag && self.level[w] == level
        })
    }

    /// Appends `set` ordered by AMD on its own subgraph.
    fn order_leaf(&mut self, set: &[u32], order: &mut Vec<u32>) -> Result<(), FactorError> {
        let n = set.len();
        if n <= 2 {
            order.extend_from_slice(set);
            return Ok(());
        }
        let tag = self.tag(set);
        // Local numbers in `level` (free again once the leaf is ordered).
        for (local, &v) in set.iter().enumerate() {
            self.level[v as usize] = local as u32;
        }
        let (mut column_start, mut rows) = (Vec::with_capacity(n + 1), Vec::new());
        column_start.push(0u32);
        for (j, &v) in set.iter().enumerate() {
            let v = v as usize;
            let mut column: Vec<u32> = vec![j as u32];
            for k in self.start[v] as usize..self.start[v + 1] as usize {
                let w = self.neighbours[k] as usize;
                if self.part[w] == tag && self.level[w] as usize > j {
                    column.push(self.level[w]);
                }
            }
            column.sort_unstable();
            column.dedup();
            rows.extend_from_slice(&column);
            column_start.push(rows.len() as u32);
        }
        let forward = amd_order(n, &column_start, &rows)?;
        order.extend(forward.iter().map(|&local| set[local as usize]));
        Ok(())
    }
}
