//! Moving the world's state onto a remeshed topology.
//!
//! New vertices take the midpoint of their parent edge's position and velocity
//! (kept vertices keep their resting contacts: [`carry_contacts`]);
//! masses are rebuilt from material areas (so total mass is exact). Lumped masses
//! change around the modified region, which would change the linear momentum
//! `sum m v`; the difference is given back as one common velocity change of the
//! vertices whose mass changed, so momentum is conserved to round-off and the
//! correction stays local to the remeshed region.
//!
//! A new vertex goes on the chord, not on the curved surface (the PN-triangle
//! edge midpoint, which adds the sagitta `L^2 / 8R`): the curved midpoint
//! changes no benchmark error by more than the comparison resolves, and it
//! leaves the old surface, which the tensor method's checks rely on.
//!
//! # Vertex order
//! Compaction chooses the new mesh's vertex numbering (`VertexOrder`). Kept
//! in creation order, the vertices of a refined patch are the old ones
//! wherever they were and the midpoints appended at the end of the arrays, so
//! a vertex's neighbours lie far apart in memory: on a 32 x 32 grid refined
//! twice around one patch, the two ends of an edge were 0.198 of the vertex
//! count apart in index on average (test
//! `red_green_numbers_vertices_in_triangle_order`). Every per-vertex gather of
//! the implicit step (the block rows of the matrix, the force sums) then
//! reads scattered memory, and an adaptive run paid more per vertex for its
//! assembly than a uniform one (`hanging_sheet_rest`, red-green 8 L6: 1.01 s
//! for 1,146 vertices against uniform 64's 3.13 s for 4,225, 20 % more per
//! vertex and step). Red-green's triangles come out of its forest depth first
//! (roots in input order), so numbering the vertices in the order the
//! triangle list first uses them keeps neighbours close (0.013 of the count in
//! that test; the grid itself 0.020) at the cost of renumbering every vertex
//! at each remesh, which the hierarchy's `remap` follows. The edge method keeps
//! creation order: its triangle list is in slot order, which carries no
//! locality for a numbering to follow.
//!
//! A renumbered midpoint may come before its parents, so positions,
//! velocities and pins are transferred in [`Remeshed::parents_first`] order
//! (ascending old ids), where every midpoint follows both ends of its edge.

use super::transfer_panels::panels_after_remesh;
use crate::math::{Scalar, Vector, Vector2};
use crate::mesh::{Mesh, MeshError, signed_area};
use crate::physics::Contact;
use crate::pins::Anchor;
use crate::world::World;

/// Where a vertex of the new mesh comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// The old vertex with this index.
    Old(u32),
    /// The midpoint of two vertices of the new mesh (which come before it in
    /// [`Remeshed::parents_first`]).
    Midpoint(u32, u32),
}

/// A new topology for the world's cloth.
#[derive(Debug, Clone, PartialEq)]
pub struct Remeshed {
    /// Material coordinates of the new vertices.
    pub material: Vec<Vector2>,
    /// Triangles over the new vertices.
    pub triangles: Vec<[u32; 3]>,
    /// Level of each triangle.
    pub levels: Vec<u8>,
    /// Origin of each new vertex.
    pub origin: Vec<Origin>,
    /// The new vertices in an order where a midpoint comes after its parents.
    pub parents_first: Vec<u32>,
    /// A garment's corners and panels, one per triangle (`None` for a cloth
    /// without panels, whose corners are its vertices' material coordinates).
    pub corners: Option<PanelCorners>,
}

/// A remeshed garment's triangles in its panels' patterns.
#[derive(Debug, Clone, PartialEq)]
pub struct PanelCorners {
    /// Each triangle's corners in its panel's pattern, m.
    pub corners: Vec<[Vector2; 3]>,
    /// Each triangle's panel.
    pub of_triangle: Vec<u16>,
}

impl Remeshed {
    /// Rest area of triangle `t`, m^2 (from its corners for a garment).
    fn rest_area(&self, t: usize) -> Scalar {
        match &self.corners {
            None => signed_area(&self.material, &self.triangles[t]),
            Some(p) => {
                let [a, b, c] = p.corners[t];
                0.5 * (b - a).perp_dot(c - a)
            }
        }
    }

    /// Lumped vertex masses `density * sum(A_t) / 3` of the new mesh.
    fn lumped_masses(&self, density: Scalar) -> Vec<Scalar> {
        let areas = (0..self.triangles.len()).map(|t| self.rest_area(t));
        lump(self.material.len(), &self.triangles, areas, density)
    }
}

/// Lumped vertex masses `density * sum(A_t) / 3`.
pub fn lumped_masses(material: &[Vector2], triangles: &[[u32; 3]], density: Scalar) -> Vec<Scalar> {
    let areas = triangles.iter().map(|t| signed_area(material, t));
    lump(material.len(), triangles, areas, density)
}

/// Lumped vertex masses of `mesh` from its triangles' rest areas (a garment's
/// from their corners in their panels' patterns).
pub fn mesh_lumped_masses(mesh: &Mesh, density: Scalar) -> Vec<Scalar> {
    let areas = (0..mesh.triangles.len()).map(|t| mesh.rest_area(t));
    lump(mesh.vertex_count(), &mesh.triangles, areas, density)
}

/// A third of each triangle's mass (`density` times its area, from `areas`) at
/// each of its corners.
fn lump(
    vertices: usize,
    triangles: &[[u32; 3]],
    areas: impl Iterator<Item = Scalar>,
    density: Scalar,
) -> Vec<Scalar> {
    let mut m = vec![0.0; vertices];
    for (t, area) in triangles.iter().zip(areas) {
        let share = density * area / 3.0;
        for &v in t {
            m[v as usize] += share;
        }
    }
    m
}

/// The resting contacts of a remeshed world from the old one's (`old`, one per
/// old vertex; `origins`, one per new vertex, from [`transfer`]): a kept vertex
/// keeps its contact, a new vertex has none (the step's collision response
/// deals with it). `None` when `old` does not match the old mesh
/// (`old_vertices`). Without carried contacts, the implicit step after a
/// remesh would solve the cloth as if it could sink into the obstacle
/// (`src/physics/implicit.rs`, "Pins and contacts").
///
/// A midpoint gets no contact even where both ends of its edge rest: a
/// midpoint of two vertices on either side of a table's edge would get a
/// normal at 45 degrees that it does not rest on, and the tablecloth's landing
/// retries frames for energy gain.
pub fn carry_contacts(
    old: &[Contact],
    old_vertices: usize,
    origins: &[Origin],
) -> Option<Vec<Contact>> {
    if old.len() != old_vertices || old.is_empty() {
        return None;
    }
    origins
        .iter()
        .map(|o| match *o {
            Origin::Old(j) => old.get(j as usize).copied(),
            Origin::Midpoint(..) => Some(Contact::default()),
        })
        .collect()
}

/// Replaces the world's mesh by `new`, carrying positions, velocities and pins;
/// returns where each new vertex came from (for state kept outside the world:
/// [`carry_contacts`]).
pub fn transfer(
    world: &mut World,
    density: Scalar,
    new: Remeshed,
) -> Result<Vec<Origin>, MeshError> {
    let old_mass = mesh_lumped_masses(&world.mesh, density);
    let new_mass = new.lumped_masses(density);
    let n = new.origin.len();
    let mut x = vec![Vector::ZERO; n];
    let mut v = vec![Vector::ZERO; n];
    let mut kept = vec![false; world.x.len()];
    let mut old_index = vec![u32::MAX; world.x.len()];
    for &i in &new.parents_first {
        let i = i as usize;
        match new.origin[i] {
            Origin::Old(j) => {
                x[i] = world.x[j as usize];
                v[i] = world.v[j as usize];
                kept[j as usize] = true;
                old_index[j as usize] = i as u32;
            }
            Origin::Midpoint(a, b) => {
                x[i] = (x[a as usize] + x[b as usize]) * 0.5;
                v[i] = (v[a as usize] + v[b as usize]) * 0.5;
            }
        }
    }
    conserve_momentum(
        world,
        &old_mass,
        &new_mass,
        &kept,
        &old_index,
        &new.origin,
        &mut v,
    );
    let anchor_of = carry_pins(world, &old_index, &new);
    // The only fallible step comes before the world changes, so a refused
    // mesh leaves the world as it was.
    let mesh = match new.corners {
        None => Mesh::from_parts(new.material, new.triangles, new.levels)?,
        Some(corners) => {
            let (pattern, home) = panels_after_remesh(
                &world.mesh,
                &old_index,
                &new.origin,
                &new.triangles,
                corners,
            )?;
            Mesh::from_parts_with_pattern(home, new.triangles, new.levels, pattern)?
        }
    };
    world.pins.anchors = anchor_of.into_iter().flatten().collect();
    world.mesh = mesh;
    world.x = x;
    world.v = v;
    Ok(new.origin)
}

/// Gives the momentum that the changed lumped masses took or added back as one
/// common velocity change of the new vertices whose mass changed (module docs).
/// `kept` and `old_index`: per old vertex, whether it survives and its new index.
fn conserve_momentum(
    world: &World,
    old_mass: &[Scalar],
    new_mass: &[Scalar],
    kept: &[bool],
    old_index: &[u32],
    origin: &[Origin],
    v: &mut [Vector],
) {
    // Momentum of the region whose masses change, before and after.
    let mut before = Vector::ZERO;
    for (j, &k) in kept.iter().enumerate() {
        let changed =
            !k || (new_mass[old_index[j] as usize] - old_mass[j]).abs() > 1e-14 * old_mass[j];
        if changed {
            before += world.v[j] * old_mass[j];
        }
    }
    let affected: Vec<usize> = (0..origin.len())
        .filter(|&i| match origin[i] {
            Origin::Old(j) => {
                (new_mass[i] - old_mass[j as usize]).abs() > 1e-14 * old_mass[j as usize]
            }
            Origin::Midpoint(..) => true,
        })
        .collect();
    let after: Vector = affected.iter().map(|&i| v[i] * new_mass[i]).sum();
    let region_mass: Scalar = affected.iter().map(|&i| new_mass[i]).sum();
    if region_mass > 0.0 {
        let dv = (before - after) / region_mass;
        for &i in &affected {
            v[i] += dv;
        }
    }
}

/// The pin anchor of each new vertex: kept vertices keep their anchor; a midpoint
/// of two vertices held by the same pin is held by it too (pin regions are convex
/// in material space).
fn carry_pins(world: &World, old_index: &[u32], new: &Remeshed) -> Vec<Option<Anchor>> {
    let mut anchor_of: Vec<Option<Anchor>> = vec![None; new.origin.len()];
    for a in &world.pins.anchors {
        let i = old_index[a.vertex as usize];
        if i != u32::MAX {
            anchor_of[i as usize] = Some(Anchor { vertex: i, ..*a });
        }
    }
    for &i in &new.parents_first {
        let i = i as usize;
        if let Origin::Midpoint(a, b) = new.origin[i]
            && let (Some(pa), Some(pb)) = (anchor_of[a as usize], anchor_of[b as usize])
            && pa.pin == pb.pin
        {
            anchor_of[i] = Some(Anchor {
                vertex: i as u32,
                pin: pa.pin,
                start: (pa.start + pb.start) * 0.5,
            });
        }
    }
    anchor_of
}

/// The order of the vertices of a compacted mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum VertexOrder {
    /// The surviving ids in ascending order: old vertices first, then the new
    /// ones in the order they were created (the edge method, whose triangle
    /// list is in slot order and so carries no locality to follow).
    Kept,
    /// In the order the triangle list first uses them (red-green, whose
    /// triangles come depth first out of its forest): module docs, "Vertex
    /// order".
    FirstUse,
}

/// Keeps the vertices the triangles use, in `order`: returns the map from
/// old ids to new indices (`u32::MAX` for dropped ones) and the new topology.
/// Ids below `first_new` are old world vertices; `created[k]` is the parent edge
/// of vertex `first_new + k`.
pub(super) fn compact(
    material: &[Vector2],
    (first_new, created): (u32, &[(u32, u32)]),
    tris: &[[u32; 3]],
    levels: Vec<u8>,
    order: VertexOrder,
) -> (Vec<u32>, Remeshed) {
    let mut map = vec![u32::MAX; material.len()];
    let mut kept = Vec::new();
    match order {
        VertexOrder::Kept => {
            let mut used = vec![false; material.len()];
            for &v in tris.iter().flatten() {
                used[v as usize] = true;
            }
            for (v, _) in used.iter().enumerate().filter(|(_, u)| **u) {
                map[v] = kept.len() as u32;
                kept.push(v);
            }
        }
        VertexOrder::FirstUse => {
            for &v in tris.iter().flatten() {
                if map[v as usize] == u32::MAX {
                    map[v as usize] = kept.len() as u32;
                    kept.push(v as usize);
                }
            }
        }
    }
    // Ascending old ids put every midpoint after its parent edge's ends: old
    // vertices come first and a new vertex is created after its parents.
    let mut parents_first: Vec<u32> = (0..kept.len() as u32).collect();
    parents_first.sort_unstable_by_key(|&i| kept[i as usize]);
    let origin = kept
        .iter()
        .map(|&v| {
            if (v as u32) < first_new {
                Origin::Old(v as u32)
            } else {
                let (a, b) = created[v - first_new as usize];
                Origin::Midpoint(map[a as usize], map[b as usize])
            }
        })
        .collect();
    let remeshed = Remeshed {
        material: kept.iter().map(|&v| material[v]).collect(),
        triangles: tris.iter().map(|t| t.map(|v| map[v as usize])).collect(),
        levels,
        origin,
        parents_first,
        corners: None,
    };
    (map, remeshed)
}
