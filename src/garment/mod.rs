//! Building a garment from its panels and seams: each outline is meshed (both
//! sides of a seam divided into the same number of segments, each side's
//! points equally spaced along its own length, curved or straight, so their
//! points pair up and a longer side gathers into a shorter one), the panels are gathered into one mesh with per-corner pattern
//! coordinates ([`crate::mesh::Panels`]), and each panel is placed in the
//! garment's frame, flat or wrapped around a cylinder.

mod sides;

use crate::math::{Vector, Vector2, rotation_from_euler_deg};
use crate::mesh::{Hold, Mesh, MeshError, OutlineError, Panels, Seam, mesh_outline};
use crate::spec::{Garment, HoldSpec, Placement, SeamDirection, SeamSide, SeamSpec};
pub use sides::SEAM_LENGTH_TOLERANCE;

/// Why a garment could not be built.
#[derive(Debug, thiserror::Error)]
pub enum GarmentError {
    /// A panel's outline could not be meshed.
    #[error("panel `{panel}`: {}", scene_words(why))]
    Outline {
        /// The panel.
        panel: String,
        /// Why (its sides numbered from 0; the message numbers them from 1).
        why: OutlineError,
    },
    /// A panel's curves name sides that do not exist, or are malformed.
    #[error("panel `{panel}`: {reason}")]
    Curve {
        /// The panel.
        panel: String,
        /// What is wrong.
        reason: String,
    },
    /// A seam names a panel or side that does not exist, or sides that cannot be sewn.
    #[error("seam `{seam}`: {reason}")]
    Seam {
        /// The seam.
        seam: String,
        /// What is wrong.
        reason: String,
    },
    /// An attachment names a panel or side that does not exist.
    #[error("attachment `{attachment}`: {reason}")]
    Attachment {
        /// The attachment.
        attachment: String,
        /// What is wrong.
        reason: String,
    },
    /// The panels do not form a valid mesh, or a seam would weld them twisted.
    #[error("{0}")]
    Mesh(#[from] MeshError),
}

/// An outline error in the scene's words: sides and corners numbered from 1,
/// as `[[panel]] outline` and `[[seam]]` number them.
fn scene_words(e: &OutlineError) -> String {
    match *e {
        OutlineError::SelfIntersecting { a, b } => format!(
            "the outline crosses itself: sides {} and {} cross or touch; an outline must be a \
             simple polygon",
            a + 1,
            b + 1
        ),
        OutlineError::ZeroLengthSide { side, next, .. } => format!(
            "side {} has no length: corners {} and {} are the same point",
            side + 1,
            side + 1,
            next + 1
        ),
        OutlineError::NearlyTouching { side } => format!(
            "side {}, divided into its segments, touches or crosses another side",
            side + 1
        ),
        ref other => other.to_string(),
    }
}

/// A garment's mesh and its start positions in the garment's frame.
pub struct BuiltGarment {
    /// The mesh, with every seam open.
    pub mesh: Mesh,
    /// Start positions in the garment's frame, m.
    pub positions: Vec<Vector>,
}

/// Meshes, gathers and places the panels of `garment`.
pub fn build(garment: &Garment) -> Result<BuiltGarment, GarmentError> {
    for panel in &garment.panels {
        sides::check_curves(panel)?;
    }
    let segments = sides::side_segments(garment)?;
    let mut material = Vec::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut corners = Vec::new();
    let mut of_triangle = Vec::new();
    let mut of_vertex = Vec::new();
    let mut chains: Vec<Vec<Vec<u32>>> = Vec::new();
    for (p, panel) in garment.panels.iter().enumerate() {
        let expanded = sides::expand(panel, &segments[p]);
        let meshed = mesh_outline(&expanded.outline, &expanded.segments, garment.max_edge)
            .map_err(|why| GarmentError::Outline {
                panel: panel.name.clone(),
                why: expanded.renumber(why),
            })?;
        let base = material.len() as u32;
        positions.extend(meshed.points.iter().map(|q| place(&panel.placement, *q)));
        material.extend_from_slice(&meshed.points);
        of_vertex.extend(std::iter::repeat_n(p as u16, meshed.points.len()));
        for t in &meshed.triangles {
            triangles.push(t.map(|v| v + base));
            corners.push(t.map(|v| meshed.points[v as usize]));
            of_triangle.push(p as u16);
        }
        chains.push(
            (0..panel.outline.len())
                .map(|k| {
                    let chain = expanded.chain(&meshed.sides, k);
                    chain.iter().map(|v| v + base).collect()
                })
                .collect(),
        );
    }
    let seams = garment
        .seams
        .iter()
        .map(|s| {
            let (a, b) = (
                edge_sides(garment, s, true)?,
                edge_sides(garment, s, false)?,
            );
            Ok(Seam {
                name: s.name.clone(),
                pairs: seam_pairs(
                    &edge_points(&chains, &a),
                    &edge_points(&chains, &b),
                    s.direction,
                ),
            })
        })
        .collect::<Result<Vec<Seam>, GarmentError>>()?;
    let holds = garment
        .holds
        .iter()
        .map(|h| hold(garment, h, &chains))
        .collect::<Result<Vec<Hold>, GarmentError>>()?;
    let panels = Panels {
        names: garment.panels.iter().map(|p| p.name.clone()).collect(),
        of_triangle,
        corners,
        of_vertex,
        seams,
        holds,
    };
    let mesh = Mesh::from_panels(material, triangles, panels)?;
    check_weldable(&mesh)?;
    Ok(BuiltGarment { mesh, positions })
}

/// The (panel, 0-based side) of each panel side of a seam's first (`first`)
/// or second edge, in order.
fn edge_sides(
    garment: &Garment,
    s: &SeamSpec,
    first: bool,
) -> Result<Vec<(usize, usize)>, GarmentError> {
    let edge = if first { &s.a } else { &s.b };
    if edge.is_empty() {
        return Err(seam_error(
            s,
            "an edge of the seam has no panel side".into(),
        ));
    }
    edge.iter()
        .map(|side| find_side(garment, side).map_err(|reason| seam_error(s, reason)))
        .collect()
}

/// The points of an edge along its panel sides' vertex chains, in order: one
/// vertex each, or at a joint between two sides that do not share their
/// corner (two panels) the two sides' end vertices together.
fn edge_points(chains: &[Vec<Vec<u32>>], sides: &[(usize, usize)]) -> Vec<Vec<u32>> {
    let mut points: Vec<Vec<u32>> = Vec::new();
    for (k, &(p, side)) in sides.iter().enumerate() {
        for (i, &v) in chains[p][side].iter().enumerate() {
            match points.last_mut() {
                Some(joint) if i == 0 && k > 0 => {
                    if !joint.contains(&v) {
                        joint.push(v);
                    }
                }
                _ => points.push(vec![v]),
            }
        }
    }
    points
}

/// The pairs of a seam whose edges have the points `a` and `b` (the same
/// number: [`sides::side_segments`] gives both edges the same segments).
/// Point i of `a` meets point i of `b`, or of `b` reversed for
/// [`SeamDirection::Opposite`]; every vertex of a joint is paired with the
/// point's first vertex, so that the weld joins them all. A pair of one vertex
/// with itself (two adjacent sides of one panel, a dart, share their corner)
/// is joined already and left out.
fn seam_pairs(a: &[Vec<u32>], b: &[Vec<u32>], direction: SeamDirection) -> Vec<[u32; 2]> {
    let b: Vec<&Vec<u32>> = match direction {
        SeamDirection::Opposite => b.iter().rev().collect(),
        SeamDirection::Same => b.iter().collect(),
    };
    debug_assert_eq!(a.len(), b.len(), "the edges' points");
    let mut pairs = Vec::new();
    for (pa, pb) in a.iter().zip(b) {
        let first = pa[0];
        pairs.extend(pa[1..].iter().chain(pb).map(|&v| [first, v]));
    }
    pairs.retain(|p| p[0] != p[1]);
    pairs
}

/// The (panel, 0-based side) of `side`, or why there is none.
fn find_side(garment: &Garment, side: &SeamSide) -> Result<(usize, usize), String> {
    let p = garment
        .panels
        .iter()
        .position(|p| p.name == side.panel)
        .ok_or_else(|| format!("there is no panel `{}`", side.panel))?;
    let count = garment.panels[p].outline.len();
    if side.side == 0 || side.side > count {
        return Err(format!(
            "panel `{}` has sides 1 to {count}, not {}",
            side.panel, side.side
        ));
    }
    Ok((p, side.side - 1))
}

/// The vertices attachment `h` holds: the chain of each of its sides.
fn hold(garment: &Garment, h: &HoldSpec, chains: &[Vec<Vec<u32>>]) -> Result<Hold, GarmentError> {
    let sides = h
        .sides
        .iter()
        .map(|side| {
            let (p, k) = find_side(garment, side).map_err(|reason| GarmentError::Attachment {
                attachment: h.name.clone(),
                reason,
            })?;
            Ok(chains[p][k].clone())
        })
        .collect::<Result<Vec<_>, GarmentError>>()?;
    Ok(Hold {
        name: h.name.clone(),
        chains: sides,
    })
}

fn seam_error(s: &SeamSpec, reason: String) -> GarmentError {
    GarmentError::Seam {
        seam: s.name.clone(),
        reason,
    }
}

/// A pattern point placed in the garment's frame.
fn place(placement: &Placement, q: Vector2) -> Vector {
    match *placement {
        Placement::Flat { position, rotation } => {
            Vector::from_array(position) + rotation_from_euler_deg(rotation) * q.extend(0.0)
        }
        Placement::Cylinder {
            radius,
            angle,
            position,
        } => {
            let phi = angle.to_radians() + q.x / radius;
            Vector::new(radius * phi.sin(), -radius * phi.cos(), q.y) + Vector::from_array(position)
        }
    }
}

/// Every seam can be welded: the panels it joins would face the same way.
/// Checked on a copy at the start, so a twisted seam is refused before the run.
fn check_weldable(mesh: &Mesh) -> Result<(), GarmentError> {
    let count = mesh.seams().len();
    let mut welded = mesh.clone();
    for s in 0..count {
        welded = welded
            .weld(s)
            .map_err(|e| match e {
                MeshError::SeamTwisted { .. } | MeshError::NonManifoldEdge { .. } => {
                    GarmentError::Seam {
                        seam: mesh.seams()[s].name.clone(),
                        reason: format!("it cannot be welded: {e}"),
                    }
                }
                other => GarmentError::Mesh(other),
            })?
            .mesh;
    }
    Ok(())
}
