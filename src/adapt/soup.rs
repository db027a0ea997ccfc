//! The edge method's working mesh: a triangle soup with incidence tables that
//! changes only through [`SoupOp`] values (ARCSim's `RemeshOp`): each operation
//! says which triangle slots it removes and adds, which vertex it appends or
//! removes, and which vertices it marks as touched. [`Soup::commit`] applies
//! one and keeps it in the pass's journal; [`SoupOp::inverse`] is the exact
//! undo, which [`Soup::undo_to`] uses to take back a chain of splits whose last
//! one was refused, so that a refused split leaves no partial work.
//!
//! Exactness of the undo: triangle ids in the incidence lists are kept sorted
//! (new ids are always the largest, so appending keeps them sorted), so
//! removing the added triangles and putting back the removed ones gives the
//! same lists; the slot count is recorded and restored, so new slots get the
//! same ids again. Putting the removed triangles back in fresh slots instead
//! would not do: the live order, and so the world's triangle order after
//! compaction, would change with each refused split.

use crate::math::Vector2;
use crate::mesh::PairMap;

use super::tri_list::TriList;

fn sorted(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// A change of the soup's vertex set, with the vertex's properties (its
/// material position and the parent edge that the state transfer interpolates
/// from).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VertexChange {
    /// Appends vertex `id` (the current count) at `material`, the midpoint of `parent`.
    Append {
        /// The new vertex.
        id: u32,
        /// Its material coordinates.
        material: Vector2,
        /// The edge it halves.
        parent: (u32, u32),
    },
    /// Removes the last vertex `id` (the inverse of `Append`).
    Pop {
        /// The vertex removed.
        id: u32,
        /// Its material coordinates.
        material: Vector2,
        /// The edge it halved.
        parent: (u32, u32),
    },
    /// Marks a vertex removed (a collapse).
    Remove(u32),
    /// Clears a vertex's removed mark (the inverse of `Remove`).
    Restore(u32),
}

impl VertexChange {
    /// The change that undoes this one.
    pub fn inverse(self) -> VertexChange {
        match self {
            VertexChange::Append {
                id,
                material,
                parent,
            } => VertexChange::Pop {
                id,
                material,
                parent,
            },
            VertexChange::Pop {
                id,
                material,
                parent,
            } => VertexChange::Append {
                id,
                material,
                parent,
            },
            VertexChange::Remove(v) => VertexChange::Restore(v),
            VertexChange::Restore(v) => VertexChange::Remove(v),
        }
    }
}

/// One remeshing operation as a value: apply it with [`Soup::commit`], undo it
/// by applying [`SoupOp::inverse`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SoupOp {
    /// The vertex added or removed, if any.
    pub vertex: Option<VertexChange>,
    /// Triangles removed: slot, corners, level.
    pub removed: Vec<(u32, [u32; 3], u8)>,
    /// Triangles added: slot, corners, level (new slots in increasing order).
    pub added: Vec<(u32, [u32; 3], u8)>,
    /// Number of triangle slots before and after.
    pub slots: (u32, u32),
    /// Vertices whose `touched` flag changes: vertex, before, after.
    pub touched: Vec<(u32, bool, bool)>,
}

impl SoupOp {
    /// The operation that undoes this one exactly.
    pub fn inverse(&self) -> SoupOp {
        SoupOp {
            vertex: self.vertex.map(VertexChange::inverse),
            removed: self.added.clone(),
            added: self.removed.clone(),
            slots: (self.slots.1, self.slots.0),
            touched: self
                .touched
                .iter()
                .rev()
                .map(|&(v, b, a)| (v, a, b))
                .collect(),
        }
    }
}

/// A mutable triangle soup with incidence tables.
#[derive(Debug, Clone, PartialEq)]
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
    pub(super) edge_tris: PairMap<(u32, u32), TriList>,
    pub(super) vert_tris: Vec<Vec<u32>>,
    /// Vertices touched by an operation in this pass (not collapsed again).
    pub(super) touched: Vec<bool>,
    journal: Vec<SoupOp>,
}

impl Soup {
    /// A soup of the given mesh.
    pub fn new(material: &[Vector2], tris: &[[u32; 3]], levels: &[u8]) -> Soup {
        let mut edge_tris = PairMap::default();
        edge_tris.reserve(tris.len() * 3 / 2 + 16);
        let mut s = Soup {
            material: material.to_vec(),
            tris: Vec::with_capacity(tris.len() * 2),
            levels: Vec::with_capacity(tris.len() * 2),
            created: Vec::new(),
            first_new: material.len() as u32,
            removed: vec![false; material.len()],
            edge_tris,
            vert_tris: vec![Vec::new(); material.len()],
            touched: vec![false; material.len()],
            journal: Vec::new(),
        };
        for (t, &tri) in tris.iter().enumerate() {
            s.tris.push(Some(tri));
            s.levels.push(levels[t]);
            s.link(t as u32, tri);
        }
        s
    }

    fn link(&mut self, id: u32, tri: [u32; 3]) {
        for k in 0..3 {
            self.edge_tris
                .entry(sorted(tri[k], tri[(k + 1) % 3]))
                .or_default()
                .insert(id);
            let list = &mut self.vert_tris[tri[k] as usize];
            let at = list.partition_point(|&t| t < id);
            list.insert(at, id);
        }
    }

    fn unlink(&mut self, id: u32, tri: [u32; 3]) {
        for k in 0..3 {
            let key = sorted(tri[k], tri[(k + 1) % 3]);
            if let Some(list) = self.edge_tris.get_mut(&key) {
                list.remove(id);
                if list.is_empty() {
                    self.edge_tris.remove(&key);
                }
            }
            self.vert_tris[tri[k] as usize].retain(|&t| t != id);
        }
    }

    /// Applies `op` to the soup and appends it to the journal.
    pub fn commit(&mut self, op: SoupOp) {
        self.apply(&op);
        self.journal.push(op);
    }

    /// Undoes the journal's operations after the first `mark`, newest first.
    pub fn undo_to(&mut self, mark: usize) {
        while self.journal.len() > mark {
            if let Some(op) = self.journal.pop() {
                self.apply(&op.inverse());
            }
        }
    }

    /// The operations committed so far, oldest first.
    pub fn journal(&self) -> &[SoupOp] {
        &self.journal
    }

    /// Applies `op` (see [`SoupOp`]); a valid operation for the current soup is
    /// assumed (checked in debug builds).
    pub fn apply(&mut self, op: &SoupOp) {
        debug_assert_eq!(self.tris.len() as u32, op.slots.0, "slot count");
        if let Some(VertexChange::Append {
            id,
            material,
            parent,
        }) = op.vertex
        {
            debug_assert_eq!(id as usize, self.material.len());
            self.material.push(material);
            self.created.push(parent);
            self.removed.push(false);
            self.vert_tris.push(Vec::new());
            self.touched.push(false);
        }
        for &(slot, tri, _) in &op.removed {
            debug_assert_eq!(self.tris[slot as usize], Some(tri), "removed triangle");
            self.tris[slot as usize] = None;
            self.unlink(slot, tri);
        }
        for &(slot, tri, level) in &op.added {
            if slot as usize == self.tris.len() {
                self.tris.push(Some(tri));
                self.levels.push(level);
            } else {
                debug_assert_eq!(self.tris[slot as usize], None, "added slot is free");
                self.tris[slot as usize] = Some(tri);
                self.levels[slot as usize] = level;
            }
            self.link(slot, tri);
        }
        debug_assert!(self.tris[op.slots.1 as usize..].iter().all(Option::is_none));
        self.tris.truncate(op.slots.1 as usize);
        self.levels.truncate(op.slots.1 as usize);
        for &(v, _, after) in &op.touched {
            self.touched[v as usize] = after;
        }
        match op.vertex {
            Some(VertexChange::Pop { id, .. }) => {
                debug_assert_eq!(id as usize + 1, self.material.len());
                debug_assert!(self.vert_tris[id as usize].is_empty());
                self.material.pop();
                self.created.pop();
                self.removed.pop();
                self.vert_tris.pop();
                self.touched.pop();
            }
            Some(VertexChange::Remove(v)) => self.removed[v as usize] = true,
            Some(VertexChange::Restore(v)) => self.removed[v as usize] = false,
            _ => {}
        }
    }

    /// Triangles at edge (a, b), ascending, without allocating (two or fewer).
    pub(super) fn tris_at(&self, a: u32, b: u32) -> TriList {
        self.edge_tris
            .get(&sorted(a, b))
            .cloned()
            .unwrap_or_default()
    }

    /// Material coordinates of a triangle's corners.
    pub(super) fn corners(&self, tri: [u32; 3]) -> [Vector2; 3] {
        tri.map(|v| self.material[v as usize])
    }

    /// Squared material length of (a, b).
    pub(super) fn len2(&self, a: u32, b: u32) -> crate::math::Scalar {
        self.material[a as usize].distance_squared(self.material[b as usize])
    }

    /// True when some triangle has the edge (a, b).
    pub(super) fn has_edge(&self, a: u32, b: u32) -> bool {
        self.edge_tris.contains_key(&sorted(a, b))
    }

    /// `(vertex, before, true)` for the vertices in `vs`, without repeats.
    pub(super) fn touching(&self, vs: &[u32]) -> Vec<(u32, bool, bool)> {
        let mut out: Vec<(u32, bool, bool)> = Vec::with_capacity(vs.len());
        for &v in vs {
            if !out.iter().any(|e| e.0 == v) {
                out.push((v, self.touched[v as usize], true));
            }
        }
        out
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

    /// Checks the incrementally kept incidence tables against tables built from
    /// scratch from the live triangles; `Err` names the first difference.
    pub fn check_tables(&self) -> Result<(), String> {
        let mut fresh = Soup::new(&self.material, &[], &[]);
        fresh.tris.clone_from(&self.tris);
        for (t, tri) in self.tris.iter().enumerate() {
            if let Some(tri) = *tri {
                fresh.link(t as u32, tri);
            }
        }
        if fresh.vert_tris != self.vert_tris {
            let v = (0..self.vert_tris.len())
                .find(|&v| fresh.vert_tris[v] != self.vert_tris[v])
                .unwrap_or(0);
            return Err(format!(
                "triangles at vertex {v}: kept {:?}, rebuilt {:?}",
                self.vert_tris[v], fresh.vert_tris[v]
            ));
        }
        if fresh.edge_tris != self.edge_tris {
            return Err(format!(
                "edge table: kept {} edges, rebuilt {}",
                self.edge_tris.len(),
                fresh.edge_tris.len()
            ));
        }
        Ok(())
    }
}
