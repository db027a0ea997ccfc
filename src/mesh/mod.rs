//! Index-based triangle mesh of the cloth in material (rest) space.
//!
//! Every vertex carries material coordinates (2D). All rest quantities (lengths,
//! areas, masses) derive from them, so any mesh of the same cloth describes the
//! same physical sheet. Topology is index-based: triangles reference vertices,
//! edges reference their two triangles (the hinge).

mod curve;
mod generate;
mod holds;
mod obj;
mod outline;
mod pairmap;
mod panels;
mod rest_space;
mod topology;

pub use curve::{CURVE_STEPS, side_length, side_points};
pub use generate::{
    GridCuts, cell_counts, disk, fitted_lines, rectangle, rectangle_cells, rectangle_on_lines,
};
pub use holds::Hold;
pub use obj::{ObjCloth, ObjError, load_obj};
pub use outline::{
    MAX_OUTLINE_POINTS, OUTLINE_ANGLE_LIMIT_DEG, OutlineError, OutlineMesh, mesh_outline,
    segments_for,
};
pub use pairmap::{PairHasher, PairMap, PairSet};
pub use panels::{Panels, Pattern, Seam, Weld};
pub use topology::{Edge, NO_TRIANGLE};

use crate::math::{Scalar, Vector2};

/// Why a mesh was refused.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MeshError {
    /// The mesh has no triangles.
    #[error("the mesh has no triangles")]
    Empty,
    /// A triangle references a vertex that does not exist.
    #[error("triangle {triangle} references vertex {vertex}, but the mesh has {count} vertices")]
    BadIndex {
        /// Triangle index.
        triangle: usize,
        /// Offending vertex index.
        vertex: u32,
        /// Number of vertices.
        count: usize,
    },
    /// A triangle has zero (or nearly zero) area in material space.
    #[error("triangle {triangle} is degenerate: its rest area is {area:.3e} m^2")]
    Degenerate {
        /// Triangle index.
        triangle: usize,
        /// Its signed rest area.
        area: Scalar,
    },
    /// An edge is shared by more than two triangles.
    #[error("non-manifold mesh: the edge between vertices {a} and {b} has {count} triangles")]
    NonManifoldEdge {
        /// First vertex of the edge.
        a: u32,
        /// Second vertex of the edge.
        b: u32,
        /// Number of triangles at the edge.
        count: usize,
    },
    /// The triangles around a vertex do not form a single fan (a "bow tie").
    #[error("non-manifold mesh: the triangles around vertex {vertex} form {fans} separate fans")]
    NonManifoldVertex {
        /// The vertex.
        vertex: u32,
        /// Number of separate fans.
        fans: usize,
    },
    /// Two neighbouring triangles have opposite orientation in material space (folded rest shape).
    #[error(
        "triangles {a} and {b} overlap in material space (the rest shape folds over at their shared edge)"
    )]
    Folded {
        /// First triangle.
        a: usize,
        /// Second triangle.
        b: usize,
    },
    /// The mesh falls into several pieces.
    #[error(
        "the mesh is disconnected: it has {components} separate pieces; drape simulates one connected cloth"
    )]
    Disconnected {
        /// Number of connected pieces.
        components: usize,
    },
    /// A material coordinate is NaN or infinite.
    #[error("vertex {vertex} has a material coordinate that is not a finite number: {value}")]
    NonFinite {
        /// The vertex.
        vertex: u32,
        /// The offending coordinate.
        value: Scalar,
    },
    /// The mesh is so large or so small that its squared lengths (areas) leave
    /// double precision: overflow to infinity or underflow below the normal range.
    #[error(
        "the mesh spans {size:e} m in material space: its square is outside the normal \
         double-precision range, so areas cannot be computed; allowed: a mesh about \
         1.5e-154 m to 1.3e154 m across"
    )]
    OutOfScale {
        /// Diagonal of the material-space bounding box, m.
        size: Scalar,
    },
    /// A vertex is used by no triangle.
    #[error("vertex {vertex} is not used by any triangle")]
    UnusedVertex {
        /// The vertex.
        vertex: u32,
    },
    /// Two panels joined at a seam would face opposite ways (one is turned over).
    #[error(
        "the seam between panels {a} and {b} joins them twisted: a seam sews its sides end to \
         start, which joins two outlines that run the same way round (both counter-clockwise, \
         say); these run opposite ways"
    )]
    SeamTwisted {
        /// One panel's name.
        a: String,
        /// The other's.
        b: String,
    },
    /// A seam cannot be sewn as given.
    #[error("seam `{seam}`: {reason}")]
    BadSeam {
        /// The seam's name.
        seam: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A seam index past the mesh's seams (or a mesh without panels).
    #[error("the mesh has no seam {seam}")]
    NoSuchSeam {
        /// The index asked for.
        seam: usize,
    },
    /// The panel tables do not match the mesh (an internal inconsistency).
    #[error("the panel tables do not match the mesh's vertices and triangles")]
    PanelTables,
}

/// The cloth mesh: material coordinates, triangles, edges and per-triangle levels.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Material (rest) coordinates of each vertex, m (for a garment, in the
    /// vertex's home panel: see [`Pattern`]).
    pub material: Vec<Vector2>,
    /// Triangles, counter-clockwise in material space.
    pub triangles: Vec<[u32; 3]>,
    /// Refinement level of each triangle (0 for the input mesh).
    pub levels: Vec<u8>,
    /// Unique edges with their adjacent triangles.
    pub edges: Vec<Edge>,
    /// Where the triangles' corners lie in material space (garment panels).
    pub pattern: Pattern,
}

impl Mesh {
    /// Builds and validates a mesh. Triangles are re-oriented counter-clockwise in
    /// material space; the mesh must be a connected manifold without degenerate
    /// triangles or unused vertices.
    pub fn new(material: Vec<Vector2>, mut triangles: Vec<[u32; 3]>) -> Result<Mesh, MeshError> {
        check_input(&material, &triangles)?;
        check_scale(&material)?;
        let n = material.len();
        // Degeneracy is relative to the mesh's scale: a triangle whose area is a
        // vanishing fraction of its longest edge squared is refused. Each triangle
        // is then wound counter-clockwise on its own (OBJ winding is unreliable).
        for (t, tri) in triangles.iter_mut().enumerate() {
            let area = signed_area(&material, tri);
            let longest = longest_edge_sq(&material, tri);
            if area.abs() <= 1e-12 * longest || longest == 0.0 {
                return Err(MeshError::Degenerate { triangle: t, area });
            }
            if area < 0.0 {
                tri.swap(1, 2);
            }
        }
        let edges = topology::build_edges(&triangles, n)?;
        check_unfolded(&triangles, &edges)?;
        topology::check_vertices(&triangles, n)?;
        let levels = vec![0; triangles.len()];
        Ok(Mesh {
            material,
            triangles,
            levels,
            edges,
            pattern: Pattern::PerVertex,
        })
    }

    /// A mesh produced by remeshing a valid mesh: rebuilds the edge table (which
    /// still refuses non-manifold edges) but skips the per-vertex fan and
    /// connectivity checks, which [`crate::adapt::check_consistency`] covers.
    pub fn from_parts(
        material: Vec<Vector2>,
        triangles: Vec<[u32; 3]>,
        levels: Vec<u8>,
    ) -> Result<Mesh, MeshError> {
        let edges = topology::build_edges(&triangles, material.len())?;
        Ok(Mesh {
            material,
            triangles,
            levels,
            edges,
            pattern: Pattern::PerVertex,
        })
    }

    /// [`Mesh::from_parts`] with the triangles' corners in `pattern` (a remeshed
    /// garment); checks that the panel tables match the mesh.
    pub fn from_parts_with_pattern(
        material: Vec<Vector2>,
        triangles: Vec<[u32; 3]>,
        levels: Vec<u8>,
        pattern: Pattern,
    ) -> Result<Mesh, MeshError> {
        if let Pattern::Panels(p) = &pattern
            && (p.corners.len() != triangles.len()
                || p.of_triangle.len() != triangles.len()
                || p.of_vertex.len() != material.len())
        {
            return Err(MeshError::PanelTables);
        }
        let mut mesh = Mesh::from_parts(material, triangles, levels)?;
        mesh.pattern = pattern;
        Ok(mesh)
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.material.len()
    }

    /// Rest (material-space) area of triangle `t`, m^2.
    pub fn rest_area(&self, t: usize) -> Scalar {
        let [a, b, c] = self.corners(t);
        0.5 * (b - a).perp_dot(c - a)
    }

    /// Total rest area, m^2.
    pub fn total_rest_area(&self) -> Scalar {
        (0..self.triangles.len()).map(|t| self.rest_area(t)).sum()
    }

    /// Rest length of edge `e`, m.
    pub fn rest_length(&self, e: usize) -> Scalar {
        let edge = &self.edges[e];
        let [a, b] = edge.vertices;
        match self.pattern {
            Pattern::PerVertex => self.material[a as usize].distance(self.material[b as usize]),
            Pattern::Panels(_) => {
                let t = edge.triangles[0] as usize;
                self.corner_at(t, a).distance(self.corner_at(t, b))
            }
        }
    }

    /// The vertex of triangle `t` that is not on edge `e` (the hinge's wing tip).
    pub fn opposite_vertex(&self, t: u32, e: &Edge) -> u32 {
        let tri = self.triangles[t as usize];
        tri.into_iter()
            .find(|&v| v != e.vertices[0] && v != e.vertices[1])
            .unwrap_or(tri[0])
    }

    /// Axis-aligned bounding box of the material coordinates: (min, max).
    pub fn material_bounds(&self) -> (Vector2, Vector2) {
        bounds(&self.material)
    }
}

fn bounds(points: &[Vector2]) -> (Vector2, Vector2) {
    let mut lo = Vector2::splat(Scalar::INFINITY);
    let mut hi = Vector2::splat(Scalar::NEG_INFINITY);
    for p in points {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    (lo, hi)
}

/// Signed area of a triangle in material space (positive when counter-clockwise).
pub fn signed_area(material: &[Vector2], tri: &[u32; 3]) -> Scalar {
    let [a, b, c] = tri.map(|v| material[v as usize]);
    0.5 * (b - a).perp_dot(c - a)
}

/// The checks every mesh's input gets: some triangles, finite material
/// coordinates, and triangles that index existing vertices.
fn check_input(material: &[Vector2], triangles: &[[u32; 3]]) -> Result<(), MeshError> {
    if triangles.is_empty() {
        return Err(MeshError::Empty);
    }
    if let Some((vertex, value)) = material.iter().enumerate().find_map(|(v, p)| {
        [p.x, p.y]
            .into_iter()
            .find(|c| !c.is_finite())
            .map(|c| (v as u32, c))
    }) {
        return Err(MeshError::NonFinite { vertex, value });
    }
    let n = material.len();
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(&v) = tri.iter().find(|&&v| v as usize >= n) {
            return Err(MeshError::BadIndex {
                triangle: t,
                vertex: v,
                count: n,
            });
        }
    }
    Ok(())
}

/// Areas of points spanning this much must stay in double precision's normal
/// range (no points: nothing to check).
fn check_scale(points: &[Vector2]) -> Result<(), MeshError> {
    if points.is_empty() {
        return Ok(());
    }
    let (lo, hi) = bounds(points);
    let size = (hi.x - lo.x).hypot(hi.y - lo.y);
    if size > 0.0 && !(size * size).is_normal() {
        return Err(MeshError::OutOfScale { size });
    }
    Ok(())
}

/// Unfolded neighbours run their shared edge in opposite directions; if both run
/// it the same way, their tips lie on the same side: the rest shape folds (or, at
/// a seam, one panel is turned over).
fn check_unfolded(triangles: &[[u32; 3]], edges: &[Edge]) -> Result<(), MeshError> {
    for e in edges {
        if e.is_interior() {
            let (a, b) = (e.triangles[0] as usize, e.triangles[1] as usize);
            if runs_forward(&triangles[a], e.vertices) == runs_forward(&triangles[b], e.vertices) {
                return Err(MeshError::Folded { a, b });
            }
        }
    }
    Ok(())
}

/// True when triangle `tri` runs from `v[0]` to `v[1]` along one of its sides.
fn runs_forward(tri: &[u32; 3], v: [u32; 2]) -> bool {
    (0..3).any(|k| tri[k] == v[0] && tri[(k + 1) % 3] == v[1])
}

fn longest_edge_sq(material: &[Vector2], tri: &[u32; 3]) -> Scalar {
    let [a, b, c] = tri.map(|v| material[v as usize]);
    a.distance_squared(b)
        .max(b.distance_squared(c))
        .max(c.distance_squared(a))
}
