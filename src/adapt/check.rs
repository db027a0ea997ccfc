//! Consistency checks after remeshing: manifold, conforming, positive rest
//! areas, exact mass.

use crate::adapt::transfer::mesh_lumped_masses;
use crate::math::Scalar;
use crate::mesh::{Mesh, MeshError};
use crate::world::World;

/// A broken invariant of the adapted mesh.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ConsistencyError {
    /// Not a valid manifold mesh.
    #[error("adapted mesh: {0}")]
    Mesh(#[from] MeshError),
    /// A triangle is not counter-clockwise with positive area in material space.
    #[error("adapted mesh: triangle {triangle} has rest area {area:e}")]
    Area {
        /// Triangle.
        triangle: usize,
        /// Its signed rest area.
        area: Scalar,
    },
    /// The triangles do not cover the original cloth.
    #[error("adapted mesh: rest area {got} differs from the cloth's {want}")]
    TotalArea {
        /// Sum of rest areas.
        got: Scalar,
        /// Original area.
        want: Scalar,
    },
    /// The boundary is longer than the cloth's: some edge has a hanging node.
    #[error(
        "adapted mesh is not conforming: boundary length {got} differs from the cloth's {want}"
    )]
    Conforming {
        /// Boundary length of the mesh.
        got: Scalar,
        /// Boundary length of the original cloth.
        want: Scalar,
    },
    /// Lumped masses do not add up to density times area.
    #[error("adapted mesh: masses sum to {got} kg instead of {want} kg")]
    Mass {
        /// Sum of lumped masses.
        got: Scalar,
        /// Density times area.
        want: Scalar,
    },
    /// An incrementally kept lookup table differs from a rebuild.
    #[error("adapted mesh: {0}")]
    Tables(String),
    /// Position and velocity arrays do not match the mesh.
    #[error("world has {arrays} positions/velocities for {vertices} vertices")]
    Arrays {
        /// Length of the arrays.
        arrays: usize,
        /// Vertices of the mesh.
        vertices: usize,
    },
}

/// Material-space boundary length of a mesh, m.
pub fn boundary_length(mesh: &Mesh) -> Scalar {
    (0..mesh.edges.len())
        .filter(|&e| !mesh.edges[e].is_interior())
        .map(|e| mesh.rest_length(e))
        .sum()
}

/// Checks `world` against the original cloth's rest `area` and `boundary` length.
pub fn check_consistency(
    world: &World,
    density: Scalar,
    area: Scalar,
    boundary: Scalar,
) -> Result<(), ConsistencyError> {
    let mesh = &world.mesh;
    if world.x.len() != mesh.vertex_count() || world.v.len() != mesh.vertex_count() {
        return Err(ConsistencyError::Arrays {
            arrays: world.x.len(),
            vertices: mesh.vertex_count(),
        });
    }
    for t in 0..mesh.triangles.len() {
        let a = mesh.rest_area(t);
        if a.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(ConsistencyError::Area {
                triangle: t,
                area: a,
            });
        }
    }
    match mesh.panels() {
        None => Mesh::new(mesh.material.clone(), mesh.triangles.clone())?,
        Some(p) => Mesh::from_panels(mesh.material.clone(), mesh.triangles.clone(), p.clone())?,
    };
    let got = mesh.total_rest_area();
    if (got - area).abs() > 1e-12 * area {
        return Err(ConsistencyError::TotalArea { got, want: area });
    }
    let b = boundary_length(mesh);
    if (b - boundary).abs() > 1e-9 * boundary {
        return Err(ConsistencyError::Conforming {
            got: b,
            want: boundary,
        });
    }
    let mass: Scalar = mesh_lumped_masses(mesh, density).iter().sum();
    if (mass - density * area).abs() > 1e-12 * density * area {
        return Err(ConsistencyError::Mass {
            got: mass,
            want: density * area,
        });
    }
    Ok(())
}
