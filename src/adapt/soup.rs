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
use crate::mesh::{Mesh, PairMap};

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

/// A triangle of the soup as an operation adds or removes it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SoupTri {
    /// Its slot.
    pub slot: u32,
    /// Its vertices, counter-clockwise in its pattern.
    pub tri: [u32; 3],
    /// Its level (split depth).
    pub level: u8,
    /// Its corners' material coordinates, in its panel's pattern (a vertex on
    /// a garment's welded seam has one coordinate per panel).
    pub uv: [Vector2; 3],
    /// Its garment panel (0 for a cloth without panels).
    pub panel: u16,
}

/// One remeshing operation as a value: apply it with [`Soup::commit`], undo it
/// by applying [`SoupOp::inverse`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SoupOp {
    /// The vertex added or removed, if any.
    pub vertex: Option<VertexChange>,
    /// Triangles removed.
    pub removed: Vec<SoupTri>,
    /// Triangles added (new slots in increasing order).
    pub added: Vec<SoupTri>,
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
    /// Each triangle's corners in its panel's pattern (the vertices' material
    /// coordinates for a cloth without panels).
    pub uv: Vec<[Vector2; 3]>,
    /// Each triangle's garment panel (0 for a cloth without panels).
    pub panels: Vec<u16>,
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
    /// A soup of the given mesh (in one piece: every corner at its vertex's
    /// material coordinate).
    pub fn new(material: &[Vector2], tris: &[[u32; 3]], levels: &[u8]) -> Soup {
        let uv: Vec<[Vector2; 3]> = tris
            .iter()
            .map(|t| t.map(|v| material[v as usize]))
            .collect();
        Soup::with_corners(material, tris, levels, &uv, &vec![0; tris.len()])
    }

    /// A soup of `mesh`, a garment's triangles with their panels' corners.
    pub fn of_mesh(mesh: &Mesh) -> Soup {
        let n = mesh.triangles.len();
        let uv: Vec<[Vector2; 3]> = (0..n).map(|t| mesh.corners(t)).collect();
        let panels: Vec<u16> = (0..n).map(|t| mesh.panel_of(t)).collect();
        Soup::with_corners(&mesh.material, &mesh.triangles, &mesh.levels, &uv, &panels)
    }

    /// A soup whose triangles carry their corners `uv` and `panels`.
    pub fn with_corners(
        material: &[Vector2],
        tris: &[[u32; 3]],
        levels: &[u8],
        uv: &[[Vector2; 3]],
        panels: &[u16],
    ) -> Soup {
        let mut edge_tris = PairMap::default();
        edge_tris.reserve(tris.len() * 3 / 2 + 16);
        let mut s = Soup {
            material: material.to_vec(),
            tris: Vec::with_capacity(tris.len() * 2),
            levels: Vec::with_capacity(tris.len() * 2),
            uv: Vec::with_capacity(tris.len() * 2),
            panels: Vec::with_capacity(tris.len() * 2),
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
            s.uv.push(uv[t]);
            s.panels.push(panels[t]);
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
        for r in &op.removed {
            debug_assert_eq!(self.tris[r.slot as usize], Some(r.tri), "removed triangle");
            self.tris[r.slot as usize] = None;
            self.unlink(r.slot, r.tri);
        }
        for a in &op.added {
            let slot = a.slot as usize;
            if slot == self.tris.len() {
                self.tris.push(Some(a.tri));
                self.levels.push(a.level);
                self.uv.push(a.uv);
                self.panels.push(a.panel);
            } else {
                debug_assert_eq!(self.tris[slot], None, "added slot is free");
                self.tris[slot] = Some(a.tri);
                self.levels[slot] = a.level;
                self.uv[slot] = a.uv;
                self.panels[slot] = a.panel;
            }
            self.link(a.slot, a.tri);
        }
        debug_assert!(self.tris[op.slots.1 as usize..].iter().all(Option::is_none));
        let slots = op.slots.1 as usize;
        self.tris.truncate(slots);
        self.levels.truncate(slots);
        self.uv.truncate(slots);
        self.panels.truncate(slots);
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

    /// The triangle of slot `t` as an operation removes it.
    pub(super) fn soup_tri(&self, t: u32) -> Option<SoupTri> {
        let tri = self.tris[t as usize]?;
        Some(SoupTri {
            slot: t,
            tri,
            level: self.levels[t as usize],
            uv: self.uv[t as usize],
            panel: self.panels[t as usize],
        })
    }

    /// The material coordinate of vertex `v` as a corner of slot `t` (in its
    /// panel's pattern), if it is one.
    pub(super) fn corner_at(&self, t: u32, v: u32) -> Option<Vector2> {
        let tri = self.tris[t as usize]?;
        let k = tri.iter().position(|&w| w == v)?;
        Some(self.uv[t as usize][k])
    }

    /// Squared material length of (a, b), in the first triangle at it (the
    /// vertices' distance when none is).
    pub(super) fn len2(&self, a: u32, b: u32) -> crate::math::Scalar {
        let in_triangle = self.tris_at(a, b).iter().find_map(|t| {
            let (pa, pb) = (self.corner_at(t, a)?, self.corner_at(t, b)?);
            Some(pa.distance_squared(pb))
        });
        in_triangle.unwrap_or_else(|| {
            self.material[a as usize].distance_squared(self.material[b as usize])
        })
    }

    /// True when every triangle at `v` is in one panel and gives `v` one
    /// coordinate (always, for a cloth without panels): `v` is not on a welded
    /// seam, and so may move onto a neighbour in that panel's pattern.
    pub(super) fn in_one_pattern(&self, v: u32) -> bool {
        let mut seen: Option<(u16, Vector2)> = None;
        for &t in &self.vert_tris[v as usize] {
            let Some(at) = self.corner_at(t, v) else {
                continue;
            };
            let here = (self.panels[t as usize], at);
            match seen {
                None => seen = Some(here),
                Some(s) if s != here => return false,
                Some(_) => {}
            }
        }
        true
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

    /// The live triangles' corners and panels, in [`Soup::live`]'s order.
    pub fn live_corners(&self) -> (Vec<[Vector2; 3]>, Vec<u16>) {
        let live = (0..self.tris.len()).filter(|&t| self.tris[t].is_some());
        live.map(|t| (self.uv[t], self.panels[t])).unzip()
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
