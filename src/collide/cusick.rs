//! The Cusick drape test's measurements: drape coefficient and number of nodes (folds).
//!
//! A circular specimen of radius `R` lies centred on a support disk of radius `r`
//! and drapes over its edge. The drape coefficient is
//! `(shadow area - pi r^2) / (pi R^2 - pi r^2)`, where the shadow is the specimen's
//! vertical projection (the union of its projected triangles), measured here by
//! rasterising the projected triangles on a grid of [`GRID`] cells across the
//! specimen's diameter. 1 means no drape, 0 a specimen hanging straight down.
//!
//! Nodes are the waves of the draped edge: the outline's radius seen from the disk's
//! centre, `rho(phi)`, is sampled in [`BINS`] angular bins (largest projected radius of
//! the boundary vertices per bin, empty bins filled from their neighbours), smoothed by a
//! circular moving average over [`SMOOTH_BINS`] bins each side, and its local maxima are
//! counted whose prominence (height above the deeper of the two neighbouring minima)
//! exceeds [`NODE_PROMINENCE`] times `R - r`.

use serde::Serialize;

use super::Obstacles;
use super::obstacle::Body;
use crate::math::{Scalar, Vector};
use crate::mesh::Mesh;
use crate::spec::{ClothMesh, ClothSpec, ObstacleShape};
use crate::world::World;

impl Obstacles {
    /// The Cusick drape measurements, when the cloth is a disk specimen lying on a
    /// vertical cylinder (the support disk) centred under it.
    pub fn cusick_of(&self, cloth: &ClothSpec, world: &World) -> Option<CusickSummary> {
        let (top, specimen, disk) = self.cusick_support(cloth)?;
        Some(measure(&world.mesh, &world.x, top, specimen, disk))
    }

    /// The support of a Cusick test: the top centre of the vertical cylinder
    /// centred under the disk specimen `cloth`, the specimen's radius and the
    /// support's (smaller) radius; `None` when the cloth is not such a specimen.
    pub fn cusick_support(&self, cloth: &ClothSpec) -> Option<(Vector, Scalar, Scalar)> {
        let ClothMesh::Disk {
            radius: specimen, ..
        } = cloth.mesh
        else {
            return None;
        };
        let centre = Vector::from_array(cloth.position);
        let (top, disk) = self
            .bodies
            .iter()
            .filter(|b| b.kind == ObstacleShape::Cylinder)
            .find_map(Body::vertical_cylinder_top)?;
        let off = (top - centre).truncate().length();
        (off < 0.25 * disk && disk < specimen).then_some((top, specimen, disk))
    }
}

/// Raster cells across the specimen's diameter.
pub const GRID: usize = 600;
/// Angular bins of the outline.
pub const BINS: usize = 360;
/// Half-width of the circular moving average, bins.
pub const SMOOTH_BINS: usize = 4;
/// Smallest prominence of a node, as a fraction of the overhang `R - r`.
pub const NODE_PROMINENCE: Scalar = 0.03;

/// The Cusick measurements at the end of a run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CusickSummary {
    /// `(shadow - disk) / (specimen - disk)`, dimensionless.
    pub drape_coefficient: Scalar,
    /// Number of nodes (folds) of the draped edge.
    pub nodes: u32,
    /// Area of the vertical projection of the specimen, m^2.
    pub shadow_area: Scalar,
    /// Specimen radius, m.
    pub specimen_radius: Scalar,
    /// Support disk radius, m.
    pub disk_radius: Scalar,
}

/// Measures a draped disk specimen (`mesh`, positions `x`) of radius `specimen` over a
/// support of radius `disk` centred at `centre` (only its x and y matter).
pub fn measure(
    mesh: &Mesh,
    x: &[Vector],
    centre: Vector,
    specimen: Scalar,
    disk: Scalar,
) -> CusickSummary {
    let shadow = shadow_area(&mesh.triangles, x, centre, specimen);
    let pi = std::f64::consts::PI;
    let dc = (shadow - pi * disk * disk) / (pi * (specimen * specimen - disk * disk));
    CusickSummary {
        drape_coefficient: dc,
        nodes: count_nodes(mesh, x, centre, specimen - disk),
        shadow_area: shadow,
        specimen_radius: specimen,
        disk_radius: disk,
    }
}

/// Area of the union of the triangles projected onto the xy plane (grid rasterisation).
fn shadow_area(tris: &[[u32; 3]], x: &[Vector], centre: Vector, radius: Scalar) -> Scalar {
    let half = radius * 1.05;
    let cell = 2.0 * half / GRID as Scalar;
    let mut covered = vec![false; GRID * GRID];
    let to_grid = |p: Vector| {
        (
            (p.x - centre.x + half) / cell,
            (p.y - centre.y + half) / cell,
        )
    };
    for t in tris {
        let [a, b, c] = t.map(|i| to_grid(x[i as usize]));
        let area2 = (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0);
        if area2 == 0.0 {
            continue;
        }
        let lo = |u: Scalar| (u.floor().max(0.0) as usize).min(GRID - 1);
        let (i0, i1) = (lo(a.0.min(b.0).min(c.0)), lo(a.0.max(b.0).max(c.0)));
        let (j0, j1) = (lo(a.1.min(b.1).min(c.1)), lo(a.1.max(b.1).max(c.1)));
        let edge = |p: (Scalar, Scalar), q: (Scalar, Scalar), s: (Scalar, Scalar)| {
            ((q.0 - p.0) * (s.1 - p.1) - (q.1 - p.1) * (s.0 - p.0)) * area2.signum()
        };
        for j in j0..=j1 {
            for i in i0..=i1 {
                let s = (i as Scalar + 0.5, j as Scalar + 0.5);
                if edge(a, b, s) >= 0.0 && edge(b, c, s) >= 0.0 && edge(c, a, s) >= 0.0 {
                    covered[j * GRID + i] = true;
                }
            }
        }
    }
    covered.iter().filter(|&&c| c).count() as Scalar * cell * cell
}

/// Number of waves of the outline (see the module docs).
fn count_nodes(mesh: &Mesh, x: &[Vector], centre: Vector, overhang: Scalar) -> u32 {
    let mut rho = vec![Scalar::NAN; BINS];
    for e in mesh.edges.iter().filter(|e| !e.is_interior()) {
        for &v in &e.vertices {
            let d = x[v as usize] - centre;
            let phi = d.y.atan2(d.x).rem_euclid(std::f64::consts::TAU);
            let bin = ((phi / std::f64::consts::TAU * BINS as Scalar) as usize).min(BINS - 1);
            let r = d.truncate().length();
            if rho[bin].is_nan() || r > rho[bin] {
                rho[bin] = r;
            }
        }
    }
    let known: Vec<usize> = (0..BINS).filter(|&b| !rho[b].is_nan()).collect();
    if known.len() < 3 {
        return 0;
    }
    // Fill empty bins from the nearest known bin (circularly).
    let filled: Vec<Scalar> = (0..BINS)
        .map(|b| {
            let dist = |k: usize| {
                let d = k.abs_diff(b);
                d.min(BINS - d)
            };
            known
                .iter()
                .min_by_key(|&&k| dist(k))
                .map_or(0.0, |&k| rho[k])
        })
        .collect();
    let smooth: Vec<Scalar> = (0..BINS)
        .map(|b| {
            let w = 2 * SMOOTH_BINS + 1;
            (0..w)
                .map(|k| filled[(b + BINS + k - SMOOTH_BINS) % BINS])
                .sum::<Scalar>()
                / w as Scalar
        })
        .collect();
    let threshold = NODE_PROMINENCE * overhang;
    // Walk around the circle from the global minimum, counting rises and falls of at
    // least `threshold` (a hysteresis count of the peaks).
    let start = (0..BINS)
        .min_by(|&a, &b| smooth[a].total_cmp(&smooth[b]))
        .unwrap_or(0);
    let mut nodes = 0;
    let (mut low, mut high, mut rising) = (smooth[start], smooth[start], true);
    for k in 1..=BINS {
        let r = smooth[(start + k) % BINS];
        if rising {
            high = high.max(r);
            if high - r >= threshold && high - low >= threshold {
                nodes += 1;
                rising = false;
                low = r;
            }
        } else {
            low = low.min(r);
            if r - low >= threshold {
                rising = true;
                high = r;
            }
        }
    }
    nodes
}
