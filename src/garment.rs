//! Building a garment from its panels and seams: each outline is meshed (both
//! sides of a seam divided into the same number of segments, so their points
//! pair up), the panels are gathered into one mesh with per-corner pattern
//! coordinates ([`crate::mesh::Panels`]), and each panel is placed in the
//! garment's frame, flat or wrapped around a cylinder.

use crate::math::{Scalar, Vector, Vector2, rotation_from_euler_deg};
use crate::mesh::{
    Mesh, MeshError, OutlineError, Panels, Seam, SeamState, mesh_outline, segments_for,
};
use crate::spec::{Garment, Placement, SeamSpec};

/// The relative difference in length the two sides of a seam may have: sewn
/// point to point, longer differences would gather the cloth.
pub const SEAM_LENGTH_TOLERANCE: Scalar = 0.05;

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
    /// A seam names a panel or side that does not exist, or sides that cannot be sewn.
    #[error("seam `{seam}`: {reason}")]
    Seam {
        /// The seam.
        seam: String,
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
    let segments = side_segments(garment)?;
    let mut material = Vec::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut corners = Vec::new();
    let mut of_triangle = Vec::new();
    let mut of_vertex = Vec::new();
    let mut sides: Vec<Vec<Vec<u32>>> = Vec::new();
    for (p, panel) in garment.panels.iter().enumerate() {
        let outline: Vec<Vector2> = panel
            .outline
            .iter()
            .map(|c| Vector2::from_array(*c))
            .collect();
        let meshed = mesh_outline(&outline, &segments[p], garment.max_edge).map_err(|why| {
            GarmentError::Outline {
                panel: panel.name.clone(),
                why,
            }
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
        sides.push(
            meshed
                .sides
                .iter()
                .map(|s| s.iter().map(|v| v + base).collect())
                .collect(),
        );
    }
    let seams = garment
        .seams
        .iter()
        .map(|s| {
            let (a, b) = (
                side_index(garment, s, true)?,
                side_index(garment, s, false)?,
            );
            let (chain_a, chain_b) = (&sides[a.0][a.1], &sides[b.0][b.1]);
            Ok(Seam {
                name: s.name.clone(),
                pairs: chain_a
                    .iter()
                    .zip(chain_b.iter().rev())
                    .map(|(&u, &w)| [u, w])
                    .collect(),
                state: SeamState::Open,
                sewing: garment.sewing,
            })
        })
        .collect::<Result<Vec<Seam>, GarmentError>>()?;
    let panels = Panels {
        names: garment.panels.iter().map(|p| p.name.clone()).collect(),
        of_triangle,
        corners,
        of_vertex,
        seams,
    };
    let mesh = Mesh::from_panels(material, triangles, panels)?;
    check_weldable(&mesh)?;
    Ok(BuiltGarment { mesh, positions })
}

/// Segments per side of every panel: each side gets `max_edge`'s share of its
/// length; both sides of a seam get the larger of their two counts.
fn side_segments(garment: &Garment) -> Result<Vec<Vec<usize>>, GarmentError> {
    let mut segments: Vec<Vec<usize>> = garment
        .panels
        .iter()
        .map(|p| {
            (0..p.outline.len())
                .map(|k| segments_for(side_length(&p.outline, k), garment.max_edge))
                .collect()
        })
        .collect();
    let mut used_sides: Vec<(usize, usize)> = Vec::new();
    for s in &garment.seams {
        let (a, b) = (
            side_index(garment, s, true)?,
            side_index(garment, s, false)?,
        );
        if a == b {
            return Err(seam_error(s, "both sides are the same panel side".into()));
        }
        for side in [a, b] {
            if let Some(k) = used_sides.iter().position(|&u| u == side) {
                // Two sides per seam, in seam order.
                let name = &garment.seams[k / 2].name;
                return Err(seam_error(
                    s,
                    format!(
                        "side {} of panel `{}` is already sewn by seam `{name}`",
                        side.1 + 1,
                        garment.panels[side.0].name
                    ),
                ));
            }
            used_sides.push(side);
        }
        let len = |(p, k): (usize, usize)| side_length(&garment.panels[p].outline, k);
        let (la, lb) = (len(a), len(b));
        if (la - lb).abs() > SEAM_LENGTH_TOLERANCE * la.max(lb) {
            return Err(seam_error(
                s,
                format!(
                    "its sides are {la:.4} m and {lb:.4} m long, {:.1} % apart; allowed: at most \
                     {:.0} % (the sides are sewn point to point)",
                    100.0 * (la - lb).abs() / la.max(lb),
                    100.0 * SEAM_LENGTH_TOLERANCE
                ),
            ));
        }
        let n = segments[a.0][a.1].max(segments[b.0][b.1]);
        segments[a.0][a.1] = n;
        segments[b.0][b.1] = n;
    }
    Ok(segments)
}

/// The (panel, 0-based side) of a seam's first (`first`) or second side.
fn side_index(
    garment: &Garment,
    s: &SeamSpec,
    first: bool,
) -> Result<(usize, usize), GarmentError> {
    let side = if first { &s.a } else { &s.b };
    let p = garment
        .panels
        .iter()
        .position(|p| p.name == side.panel)
        .ok_or_else(|| seam_error(s, format!("there is no panel `{}`", side.panel)))?;
    let count = garment.panels[p].outline.len();
    if side.side == 0 || side.side > count {
        return Err(seam_error(
            s,
            format!(
                "panel `{}` has sides 1 to {count}, not {}",
                side.panel, side.side
            ),
        ));
    }
    Ok((p, side.side - 1))
}

fn seam_error(s: &SeamSpec, reason: String) -> GarmentError {
    GarmentError::Seam {
        seam: s.name.clone(),
        reason,
    }
}

/// The length of side `k` (0-based) of an outline, m.
fn side_length(outline: &[[f64; 2]], k: usize) -> Scalar {
    let a = Vector2::from_array(outline[k]);
    let b = Vector2::from_array(outline[(k + 1) % outline.len()]);
    a.distance(b)
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
    let count = mesh.panels().map_or(0, |p| p.seams.len());
    let mut welded = mesh.clone();
    for s in 0..count {
        welded = welded
            .weld(s, 0.0)
            .map_err(|e| match e {
                MeshError::SeamTwisted { .. } | MeshError::NonManifoldEdge { .. } => {
                    GarmentError::Seam {
                        seam: mesh
                            .panels()
                            .map_or(String::new(), |p| p.seams[s].name.clone()),
                        reason: format!("it cannot be welded: {e}"),
                    }
                }
                other => GarmentError::Mesh(other),
            })?
            .mesh;
    }
    Ok(())
}
