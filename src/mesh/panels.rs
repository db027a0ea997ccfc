//! Garment panels: a cloth cut from several pattern pieces and sewn at seams.
//!
//! World-space vertices (one position, velocity and mass each) are separate from
//! material-space corners, as ARCSim separates nodes from vertices: a vertex on a
//! welded seam belongs to two panels and has one pattern coordinate in each. Each
//! triangle therefore stores its own corners' material coordinates, and every rest
//! quantity (area, edge length, bending and membrane rest state, mass) comes from
//! them. A vertex's entry in [`Mesh::material`] is its coordinate in its *home*
//! panel (the panel it started in), used where one point per vertex is needed (pin
//! regions, the export's texture coordinates of that panel).
//!
//! A seam pairs vertices on two boundary chains. While it is open, sewing springs
//! pull each pair together; once every pair is closer than the weld tolerance the
//! two sides become one: [`Mesh::weld`] merges each pair into one vertex and the
//! edge table then joins the panels, so bending acts across the seam with the flat
//! rest angle its two triangles' rest shapes give.

use super::{Mesh, MeshError, topology};
use crate::math::{Scalar, Vector, Vector2};

/// Where each triangle's corners lie in material space.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Pattern {
    /// One piece (or several unsewn ones): every corner uses its vertex's
    /// material coordinate.
    #[default]
    PerVertex,
    /// Garment panels: corners carry their panel's coordinates, so a vertex on a
    /// welded seam has one coordinate per panel.
    Panels(Panels),
}

/// The panels of a garment and its seams.
#[derive(Debug, Clone, PartialEq)]
pub struct Panels {
    /// Panel names, in scene (or file) order.
    pub names: Vec<String>,
    /// The panel of each triangle.
    pub of_triangle: Vec<u16>,
    /// The material coordinates of each triangle's corners, in its panel's pattern, m.
    pub corners: Vec<[Vector2; 3]>,
    /// The home panel of each vertex (whose pattern [`Mesh::material`] is in).
    pub of_vertex: Vec<u16>,
    /// The seams, open or welded.
    pub seams: Vec<Seam>,
    /// The vertices each attachment holds, in scene order.
    pub holds: Vec<super::Hold>,
}

/// A seam: vertex pairs on two panel boundaries, sewn together. The mesh holds
/// only which vertices a seam pairs; how it is sewn is the physics model's
/// (`spec::Sewing` in `physics::MaterialParams`) and when it was welded the
/// simulation state's (`sim::SeamState`).
#[derive(Debug, Clone, PartialEq)]
pub struct Seam {
    /// The seam's name (from the scene, or `l1`, `l2`, ... from an OBJ).
    pub name: String,
    /// The sewn pairs: a vertex of the first side and its partner on the second.
    /// While the seam is open every pair names two vertices; once it is welded
    /// both entries of every pair name the same vertex.
    pub pairs: Vec<[u32; 2]>,
}

impl Seam {
    /// True while the seam is open: its pairs are distinct vertices, which
    /// sewing springs pull together. A welded seam's pairs are single vertices.
    pub fn is_open(&self) -> bool {
        self.pairs.iter().any(|p| p[0] != p[1])
    }

    /// Each pair's share of the seam's rest length, m: half of each seam segment
    /// (a boundary edge between two of the first side's vertices) at its vertex.
    pub fn pair_lengths(&self, mesh: &Mesh) -> Vec<Scalar> {
        let index: std::collections::HashMap<u32, usize> = self
            .pairs
            .iter()
            .enumerate()
            .map(|(i, p)| (p[0], i))
            .collect();
        let mut share = vec![0.0; self.pairs.len()];
        for (e, edge) in mesh.edges.iter().enumerate() {
            let [a, b] = edge.vertices;
            if let (Some(&i), Some(&j)) = (index.get(&a), index.get(&b)) {
                let half = 0.5 * mesh.rest_length(e);
                share[i] += half;
                share[j] += half;
            }
        }
        share
    }

    /// The largest distance between a pair's two vertices at positions `x`, m.
    pub fn gap(&self, x: &[Vector]) -> Scalar {
        self.pairs
            .iter()
            .map(|&[a, b]| x[a as usize].distance(x[b as usize]))
            .fold(0.0, Scalar::max)
    }
}

/// The outcome of welding a seam: the new mesh and where each old vertex went.
#[derive(Debug, Clone)]
pub struct Weld {
    /// The mesh with the seam's pairs merged.
    pub mesh: Mesh,
    /// The new index of each old vertex (both vertices of a pair map to one).
    pub new_index: Vec<u32>,
    /// The number of vertices the weld merged away.
    pub merged: usize,
}

impl Mesh {
    /// Builds and validates a garment mesh. `material` holds each vertex's home
    /// coordinate; `panels` gives every triangle's panel and corner coordinates.
    /// Triangles are re-oriented counter-clockwise in their own corners; the
    /// pieces need not be connected (open seams join them later).
    pub fn from_panels(
        material: Vec<Vector2>,
        mut triangles: Vec<[u32; 3]>,
        mut panels: Panels,
    ) -> Result<Mesh, MeshError> {
        check_panel_lengths(&material, &triangles, &panels)?;
        for (t, (tri, corners)) in triangles
            .iter_mut()
            .zip(panels.corners.iter_mut())
            .enumerate()
        {
            orient_corners(t, tri, corners)?;
        }
        let edges = topology::build_edges(&triangles, material.len())?;
        super::check_unfolded(&triangles, &edges).map_err(|e| match e {
            MeshError::Folded { a, b } if panels.of_triangle[a] != panels.of_triangle[b] => {
                MeshError::SeamTwisted {
                    a: panels.names[panels.of_triangle[a] as usize].clone(),
                    b: panels.names[panels.of_triangle[b] as usize].clone(),
                }
            }
            other => other,
        })?;
        topology::check_fans(&triangles, material.len())?;
        check_seams(&panels.seams, material.len(), &edges)?;
        let mut held = panels.holds.iter().flat_map(|h| h.chains.iter().flatten());
        if held.any(|&v| v as usize >= material.len()) {
            return Err(MeshError::PanelTables);
        }
        let levels = vec![0; triangles.len()];
        Ok(Mesh {
            material,
            triangles,
            levels,
            edges,
            pattern: Pattern::Panels(panels),
        })
    }

    /// The panels, when the cloth is a garment.
    pub fn panels(&self) -> Option<&Panels> {
        match &self.pattern {
            Pattern::PerVertex => None,
            Pattern::Panels(p) => Some(p),
        }
    }

    /// The garment's seams, open or welded (none for a cloth without panels).
    pub fn seams(&self) -> &[Seam] {
        self.panels().map_or(&[], |p| &p.seams)
    }

    /// The vertices the garment's attachments hold (none for a cloth without
    /// panels).
    pub fn holds(&self) -> &[super::Hold] {
        self.panels().map_or(&[], |p| &p.holds)
    }

    /// True while a seam of the garment is open.
    pub fn has_open_seam(&self) -> bool {
        self.seams().iter().any(Seam::is_open)
    }

    /// Material coordinates of triangle `t`'s corners, in its panel's pattern.
    #[inline]
    pub fn corners(&self, t: usize) -> [Vector2; 3] {
        match &self.pattern {
            Pattern::PerVertex => self.triangles[t].map(|v| self.material[v as usize]),
            Pattern::Panels(p) => p.corners[t],
        }
    }

    /// The material coordinate of vertex `v` as a corner of triangle `t`.
    ///
    /// # Panics
    /// When `v` is not a corner of `t`.
    pub fn corner_at(&self, t: usize, v: u32) -> Vector2 {
        let k = self.triangles[t]
            .iter()
            .position(|&w| w == v)
            .unwrap_or_else(|| panic!("vertex {v} is not a corner of triangle {t}"));
        self.corners(t)[k]
    }

    /// The panel of triangle `t` (0 for a cloth without panels).
    pub fn panel_of(&self, t: usize) -> u16 {
        self.panels().map_or(0, |p| p.of_triangle[t])
    }

    /// Welds seam `s`: merges each pair into the first side's vertex (placed and
    /// moving as the caller decides, see [`crate::world::World::weld_seam`]) and
    /// renumbers the vertices densely. Another open seam whose every pair this
    /// joins is welded with it.
    pub fn weld(&self, s: usize) -> Result<Weld, MeshError> {
        let Pattern::Panels(panels) = &self.pattern else {
            return Err(MeshError::NoSuchSeam { seam: s });
        };
        let seam = panels
            .seams
            .get(s)
            .ok_or(MeshError::NoSuchSeam { seam: s })?;
        let n = self.vertex_count();
        let mut target: Vec<u32> = (0..n as u32).collect();
        for &[a, b] in &seam.pairs {
            target[b as usize] = target[a as usize];
        }
        // Follow chains (a vertex on two seams merges into one representative).
        for v in 0..n {
            let mut r = target[v];
            while target[r as usize] != r {
                r = target[r as usize];
            }
            target[v] = r;
        }
        let mut new_index = vec![u32::MAX; n];
        let mut kept = 0u32;
        for v in 0..n {
            if target[v] == v as u32 {
                new_index[v] = kept;
                kept += 1;
            }
        }
        for v in 0..n {
            new_index[v] = new_index[target[v] as usize];
        }
        let keep = |v: usize| target[v] == v as u32;
        let material = (0..n)
            .filter(|&v| keep(v))
            .map(|v| self.material[v])
            .collect();
        let mut next = panels.clone();
        next.of_vertex = (0..n)
            .filter(|&v| keep(v))
            .map(|v| panels.of_vertex[v])
            .collect();
        for other in &mut next.seams {
            let open = other.is_open();
            for pair in &mut other.pairs {
                *pair = pair.map(|v| new_index[v as usize]);
            }
            // A pair this weld joined (the corner where this seam and another
            // meet) is closed already; a seam whose every pair is joined is
            // welded, and one with pairs left open keeps only those.
            if open && other.is_open() {
                other.pairs.retain(|p| p[0] != p[1]);
            }
        }
        for hold in &mut next.holds {
            *hold = hold.renumbered(&new_index);
        }
        let triangles = self
            .triangles
            .iter()
            .map(|t| t.map(|v| new_index[v as usize]))
            .collect();
        let mut mesh = Mesh::from_panels(material, triangles, next)?;
        mesh.levels.clone_from(&self.levels);
        Ok(Weld {
            mesh,
            new_index,
            merged: n - kept as usize,
        })
    }
}

fn check_panel_lengths(
    material: &[Vector2],
    triangles: &[[u32; 3]],
    panels: &Panels,
) -> Result<(), MeshError> {
    super::check_input(material, triangles)?;
    let n = material.len();
    let counts = [
        panels.of_triangle.len(),
        panels.corners.len(),
        triangles.len(),
    ];
    if counts[0] != counts[2] || counts[1] != counts[2] || panels.of_vertex.len() != n {
        return Err(MeshError::PanelTables);
    }
    let bad_panel = |p: &u16| *p as usize >= panels.names.len();
    if panels.of_triangle.iter().any(bad_panel) || panels.of_vertex.iter().any(bad_panel) {
        return Err(MeshError::PanelTables);
    }
    // Corners that are not finite are refused, naming their triangle, by
    // `orient_corners`.
    let finite: Vec<Vector2> = panels
        .corners
        .iter()
        .flatten()
        .copied()
        .filter(|p| p.is_finite())
        .collect();
    super::check_scale(&finite)
}

/// Refuses a degenerate triangle and winds it counter-clockwise in its corners.
fn orient_corners(
    t: usize,
    tri: &mut [u32; 3],
    corners: &mut [Vector2; 3],
) -> Result<(), MeshError> {
    let [a, b, c] = *corners;
    if let Some(value) = [a, b, c]
        .iter()
        .flat_map(|p| [p.x, p.y])
        .find(|c| !c.is_finite())
    {
        return Err(MeshError::NonFinite {
            vertex: tri[0],
            value,
        });
    }
    let area = 0.5 * (b - a).perp_dot(c - a);
    let longest = a
        .distance_squared(b)
        .max(b.distance_squared(c))
        .max(c.distance_squared(a));
    if area.abs() <= 1e-12 * longest || longest == 0.0 {
        return Err(MeshError::Degenerate { triangle: t, area });
    }
    if area < 0.0 {
        tri.swap(1, 2);
        corners.swap(1, 2);
    }
    Ok(())
}

/// Each open seam pairs two distinct boundary vertices, each vertex at most once
/// per seam.
fn check_seams(seams: &[Seam], n: usize, edges: &[super::Edge]) -> Result<(), MeshError> {
    let mut on_boundary = vec![false; n];
    for e in edges.iter().filter(|e| !e.is_interior()) {
        for v in e.vertices {
            on_boundary[v as usize] = true;
        }
    }
    for (s, seam) in seams.iter().enumerate() {
        if seam.pairs.is_empty() {
            return Err(MeshError::BadSeam {
                seam: seam.name.clone(),
                reason: "it pairs no vertices".into(),
            });
        }
        for &[a, b] in &seam.pairs {
            let bad = |reason: String| MeshError::BadSeam {
                seam: seams[s].name.clone(),
                reason,
            };
            if a as usize >= n || b as usize >= n {
                return Err(bad(format!("it names vertex {} of {n}", a.max(b))));
            }
            if !seam.is_open() {
                continue;
            }
            if a == b {
                return Err(bad(format!("it pairs vertex {a} with itself")));
            }
            if let Some(v) = [a, b].into_iter().find(|&v| !on_boundary[v as usize]) {
                return Err(bad(format!(
                    "vertex {v} is not on a panel's boundary (a seam joins boundary edges)"
                )));
            }
        }
    }
    Ok(())
}
