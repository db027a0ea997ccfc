//! A remeshed garment's panel tables: each vertex's home panel and coordinate,
//! and the welded seams' vertices, carried onto the new topology.
//!
//! The triangles' corners come from the remeshing method, each in its own
//! panel's pattern (a split across a welded seam gives each side the midpoint
//! in its own pattern). What is left per vertex is its home: a kept vertex
//! keeps its home panel and takes its coordinate from a new triangle of that
//! panel; a new vertex's home is the panel of the first triangle that uses it.
//! A welded seam keeps its kept vertices, and gains each new midpoint of two
//! of its vertices that lies where the panels meet (its triangles are in
//! different panels or give it different pattern coordinates), so the
//! recording's seam segments follow the refined seam.

use super::transfer::{Origin, PanelCorners};
use crate::math::Vector2;
use crate::mesh::{Hold, Mesh, MeshError, Panels, Pattern, Seam};

/// What the new triangles say about one vertex: its home panel and coordinate,
/// and whether its corners disagree (it lies on a welded seam).
#[derive(Debug, Clone, Copy)]
struct VertexCorners {
    panel: u16,
    at: Vector2,
    on_seam: bool,
}

/// The panel tables of a garment remeshed from `old`, and each new vertex's
/// home coordinate (what [`Mesh::material`] holds). `old_index` maps each old
/// vertex to its new index (`u32::MAX` when dropped), `origin` says where each
/// new vertex came from, `triangles` and `new` are the new mesh's.
pub(super) fn panels_after_remesh(
    old: &Mesh,
    old_index: &[u32],
    origin: &[Origin],
    triangles: &[[u32; 3]],
    new: PanelCorners,
) -> Result<(Pattern, Vec<Vector2>), MeshError> {
    let Some(old_panels) = old.panels() else {
        return Err(MeshError::PanelTables);
    };
    let n = origin.len();
    let want: Vec<Option<u16>> = origin
        .iter()
        .map(|o| match *o {
            Origin::Old(j) => old_panels.of_vertex.get(j as usize).copied(),
            Origin::Midpoint(..) => None,
        })
        .collect();
    let mut seen: Vec<Option<VertexCorners>> = vec![None; n];
    for ((tri, uv), &panel) in triangles.iter().zip(&new.corners).zip(&new.of_triangle) {
        for (&v, &at) in tri.iter().zip(uv) {
            let entry = &mut seen[v as usize];
            match entry {
                None => {
                    *entry = Some(VertexCorners {
                        panel,
                        at,
                        on_seam: false,
                    })
                }
                Some(c) => {
                    let differs = c.panel != panel || c.at != at;
                    c.on_seam |= differs;
                    if differs && want[v as usize] == Some(panel) && c.panel != panel {
                        c.panel = panel;
                        c.at = at;
                    }
                }
            }
        }
    }
    let seen: Vec<VertexCorners> = seen
        .into_iter()
        .collect::<Option<Vec<_>>>()
        .ok_or(MeshError::PanelTables)?;
    let seams = old_panels
        .seams
        .iter()
        .map(|s| carry_seam(s, old_index, origin, &seen))
        .collect::<Result<Vec<_>, _>>()?;
    let holds = carry_holds(&old_panels.holds, old_index, origin);
    let pattern = Pattern::Panels(Panels {
        names: old_panels.names.clone(),
        of_triangle: new.of_triangle,
        corners: new.corners,
        of_vertex: seen.iter().map(|c| c.panel).collect(),
        seams,
        holds,
    });
    Ok((pattern, seen.iter().map(|c| c.at).collect()))
}

/// The attachments' held chains on the new topology: kept vertices stay, and
/// each new midpoint of two neighbours of a chain joins it between them
/// ([`Hold::carried`]).
fn carry_holds(holds: &[Hold], old_index: &[u32], origin: &[Origin]) -> Vec<Hold> {
    if holds.is_empty() {
        return Vec::new();
    }
    let midpoints: std::collections::HashMap<(u32, u32), u32> = origin
        .iter()
        .enumerate()
        .filter_map(|(i, o)| match *o {
            Origin::Midpoint(a, b) => Some(((a.min(b), a.max(b)), i as u32)),
            Origin::Old(_) => None,
        })
        .collect();
    let map = |v: u32| {
        old_index
            .get(v as usize)
            .copied()
            .filter(|&i| i != u32::MAX)
    };
    let midpoint = |a: u32, b: u32| midpoints.get(&(a.min(b), a.max(b))).copied();
    holds.iter().map(|h| h.carried(map, midpoint)).collect()
}

/// Seam `seam` on the new topology. An open seam keeps its pairs (remeshing
/// waits for every seam to be welded, so it never splits one; a dropped pair
/// vertex is an inconsistency). A welded seam keeps its kept vertices and
/// gains the new midpoints between two of them where the panels meet.
fn carry_seam(
    seam: &Seam,
    old_index: &[u32],
    origin: &[Origin],
    seen: &[VertexCorners],
) -> Result<Seam, MeshError> {
    let map = |v: u32| match old_index.get(v as usize) {
        Some(&i) if i != u32::MAX => Ok(i),
        _ => Err(MeshError::PanelTables),
    };
    if seam.is_open() {
        let pairs = seam
            .pairs
            .iter()
            .map(|&[a, b]| Ok([map(a)?, map(b)?]))
            .collect::<Result<Vec<_>, MeshError>>()?;
        return Ok(Seam {
            pairs,
            ..seam.clone()
        });
    }
    let mut on = vec![false; origin.len()];
    for &[a, _] in &seam.pairs {
        if let Ok(i) = map(a) {
            on[i as usize] = true;
        }
    }
    // A midpoint can be the parent of another midpoint; repeat until no more
    // join (each round adds a level of the refinement at most).
    loop {
        let mut grew = false;
        for (i, o) in origin.iter().enumerate() {
            if let Origin::Midpoint(a, b) = *o
                && !on[i]
                && on[a as usize]
                && on[b as usize]
                && seen[i].on_seam
            {
                on[i] = true;
                grew = true;
            }
        }
        if !grew {
            break;
        }
    }
    let pairs = (0..origin.len() as u32)
        .filter(|&i| on[i as usize])
        .map(|i| [i, i])
        .collect();
    Ok(Seam {
        pairs,
        ..seam.clone()
    })
}
