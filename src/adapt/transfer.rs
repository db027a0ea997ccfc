//! Moving the world's state onto a remeshed topology.
//!
//! New vertices take the midpoint of their parent edge's position and velocity;
//! masses are rebuilt from material areas (so total mass is exact). Lumped masses
//! change around the modified region, which would change the linear momentum
//! `sum m v`; the difference is given back as one common velocity change of the
//! vertices whose mass changed, so momentum is conserved to round-off and the
//! correction stays local to the remeshed region.

use crate::math::{Scalar, Vector, Vector2};
use crate::mesh::{Mesh, MeshError, signed_area};
use crate::physics::pins::Anchor;
use crate::world::World;

/// Where a vertex of the new mesh comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// The old vertex with this index.
    Old(u32),
    /// The midpoint of two vertices of the new mesh with smaller indices.
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
}

/// Lumped vertex masses `density * sum(A_t) / 3`.
pub fn lumped_masses(material: &[Vector2], triangles: &[[u32; 3]], density: Scalar) -> Vec<Scalar> {
    let mut m = vec![0.0; material.len()];
    for t in triangles {
        let share = density * signed_area(material, t) / 3.0;
        for &v in t {
            m[v as usize] += share;
        }
    }
    m
}

/// Replaces the world's mesh by `new`, carrying positions, velocities and pins.
pub fn transfer(world: &mut World, density: Scalar, new: Remeshed) -> Result<(), MeshError> {
    let old_mass = lumped_masses(&world.mesh.material, &world.mesh.triangles, density);
    let new_mass = lumped_masses(&new.material, &new.triangles, density);
    let n = new.origin.len();
    let mut x = Vec::with_capacity(n);
    let mut v = Vec::with_capacity(n);
    let mut kept = vec![false; world.x.len()];
    let mut old_index = vec![u32::MAX; world.x.len()];
    for (i, o) in new.origin.iter().enumerate() {
        match *o {
            Origin::Old(j) => {
                x.push(world.x[j as usize]);
                v.push(world.v[j as usize]);
                kept[j as usize] = true;
                old_index[j as usize] = i as u32;
            }
            Origin::Midpoint(a, b) => {
                x.push((x[a as usize] + x[b as usize]) * 0.5);
                v.push((v[a as usize] + v[b as usize]) * 0.5);
            }
        }
    }
    // Momentum of the region whose masses change, before and after.
    let mut before = Vector::ZERO;
    for (j, &k) in kept.iter().enumerate() {
        let changed =
            !k || (new_mass[old_index[j] as usize] - old_mass[j]).abs() > 1e-14 * old_mass[j];
        if changed {
            before += world.v[j] * old_mass[j];
        }
    }
    let affected: Vec<usize> = (0..n)
        .filter(|&i| match new.origin[i] {
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
    // Pins: kept vertices keep their anchor; a midpoint of two vertices held by the
    // same pin is held by it too (pin regions are convex in material space).
    let mut anchor_of: Vec<Option<Anchor>> = vec![None; n];
    for a in &world.pins.anchors {
        let i = old_index[a.vertex as usize];
        if i != u32::MAX {
            anchor_of[i as usize] = Some(Anchor { vertex: i, ..*a });
        }
    }
    for i in 0..n {
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
    // The only fallible step comes before the world changes, so a refused
    // mesh leaves the world as it was.
    let mesh = Mesh::from_parts(new.material, new.triangles, new.levels)?;
    world.pins.anchors = anchor_of.into_iter().flatten().collect();
    world.mesh = mesh;
    world.x = x;
    world.v = v;
    Ok(())
}

/// Keeps the vertices the triangles use, in their order: returns the map from
/// old ids to new indices (`u32::MAX` for dropped ones) and the new topology.
/// Ids below `first_new` are old world vertices; `created[k]` is the parent edge
/// of vertex `first_new + k`.
pub(super) fn compact(
    material: &[Vector2],
    first_new: u32,
    created: &[(u32, u32)],
    tris: &[[u32; 3]],
    levels: Vec<u8>,
) -> (Vec<u32>, Remeshed) {
    let mut used = vec![false; material.len()];
    for t in tris {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut map = vec![u32::MAX; material.len()];
    let mut kept = Vec::new();
    for (v, _) in used.iter().enumerate().filter(|(_, u)| **u) {
        map[v] = kept.len() as u32;
        kept.push(v);
    }
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
    };
    (map, remeshed)
}
