//! The error metric (`docs/bench.md`, "The error").
//!
//! Fixed sample points in material space are located in each mesh through the
//! material coordinates (the same cloth point on any mesh, uniform or adapted),
//! and their world positions are interpolated barycentrically. The error of a
//! run at a time is the RMS distance between its samples and the reference's,
//! divided by the cloth's diagonal (in material space).

use crate::math::{Scalar, Vector, Vector2};
use crate::mesh::Mesh;

/// Where a material point lies in a mesh: its triangle and barycentric weights.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Located {
    /// Triangle index.
    pub triangle: u32,
    /// Barycentric weights of the triangle's three vertices (sum 1).
    pub weights: [Scalar; 3],
}

/// Sample points on a regular `n` x `n` grid over the mesh's material bounds,
/// kept where they fall inside the cloth (for a disk or an OBJ outline).
pub fn grid_samples(mesh: &Mesh, n: usize) -> Vec<Vector2> {
    panel_grid_samples(mesh, n)
        .into_iter()
        .map(|(p, _)| p)
        .collect()
}

/// Sample points with their panel: for a garment, a regular `n` x `n` grid over
/// each panel's pattern bounds, kept where it falls inside that panel; for one
/// piece, [`grid_samples`]' points, all in panel 0.
pub fn panel_grid_samples(mesh: &Mesh, n: usize) -> Vec<(Vector2, u16)> {
    let panels = mesh.panels().map_or(1, |p| p.names.len()) as u16;
    let n = n.max(1);
    let mut out = Vec::new();
    for panel in 0..panels {
        let (lo, hi) = panel_bounds(mesh, panel);
        let mut grid = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                // Cell centres: never exactly on the boundary.
                let t = Vector2::new(
                    (i as Scalar + 0.5) / n as Scalar,
                    (j as Scalar + 0.5) / n as Scalar,
                );
                grid.push(lo + (hi - lo) * t);
            }
        }
        let in_panel = vec![panel; grid.len()];
        let located = locate_in_panels(mesh, &grid, &in_panel);
        out.extend(
            grid.into_iter()
                .zip(located)
                .filter_map(|(p, l)| l.map(|_| (p, panel))),
        );
    }
    out
}

/// The bounds of panel `panel`'s corners in its pattern (the whole mesh's
/// material bounds for one piece).
fn panel_bounds(mesh: &Mesh, panel: u16) -> (Vector2, Vector2) {
    let mut lo = Vector2::splat(Scalar::INFINITY);
    let mut hi = Vector2::splat(Scalar::NEG_INFINITY);
    for t in (0..mesh.triangles.len()).filter(|&t| mesh.panel_of(t) == panel) {
        for c in mesh.corners(t) {
            lo = lo.min(c);
            hi = hi.max(c);
        }
    }
    (lo, hi)
}

/// Finds each point's triangle, or `None` outside the cloth. Uses a uniform
/// bucket grid over the triangles' material bounding boxes.
pub fn locate(mesh: &Mesh, points: &[Vector2]) -> Vec<Option<Located>> {
    locate_in_panels(mesh, points, &vec![0; points.len()])
}

/// [`locate`] for points that each name their panel (`panels`, one per point;
/// all 0 for one piece): a point is found only among its panel's triangles, by
/// their corners in that panel's pattern.
pub fn locate_in_panels(mesh: &Mesh, points: &[Vector2], panels: &[u16]) -> Vec<Option<Located>> {
    let mut lo = Vector2::splat(Scalar::INFINITY);
    let mut hi = Vector2::splat(Scalar::NEG_INFINITY);
    for t in 0..mesh.triangles.len() {
        for c in mesh.corners(t) {
            lo = lo.min(c);
            hi = hi.max(c);
        }
    }
    let cells = ((mesh.triangles.len() as Scalar).sqrt().ceil() as usize).max(1);
    let size = (hi - lo).max(Vector2::splat(Scalar::MIN_POSITIVE)) / cells as Scalar;
    let cell_of = |p: Vector2| {
        let c = ((p - lo) / size).floor();
        (
            c.x.clamp(0.0, (cells - 1) as Scalar) as usize,
            c.y.clamp(0.0, (cells - 1) as Scalar) as usize,
        )
    };
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); cells * cells];
    for t in 0..mesh.triangles.len() {
        let corners = mesh.corners(t);
        let (a, b) = (
            corners[0].min(corners[1]).min(corners[2]),
            corners[0].max(corners[1]).max(corners[2]),
        );
        let ((x0, y0), (x1, y1)) = (cell_of(a), cell_of(b));
        for y in y0..=y1 {
            for x in x0..=x1 {
                buckets[y * cells + x].push(t as u32);
            }
        }
    }
    points
        .iter()
        .zip(panels)
        .map(|(&p, &panel)| {
            let (x, y) = cell_of(p);
            buckets[y * cells + x]
                .iter()
                .filter(|&&t| mesh.panel_of(t as usize) == panel)
                .find_map(|&t| {
                    let w = barycentric(mesh, t, p)?;
                    Some(Located {
                        triangle: t,
                        weights: w,
                    })
                })
        })
        .collect()
}

/// Barycentric weights of `p` in triangle `t`, if it lies inside (with a small
/// tolerance so that points on shared edges are found).
fn barycentric(mesh: &Mesh, t: u32, p: Vector2) -> Option<[Scalar; 3]> {
    let [a, b, c] = mesh.corners(t as usize);
    let area = (b - a).perp_dot(c - a);
    if area == 0.0 {
        return None;
    }
    let wa = (b - p).perp_dot(c - p) / area;
    let wb = (c - p).perp_dot(a - p) / area;
    let wc = 1.0 - wa - wb;
    let tol = -1e-12;
    (wa >= tol && wb >= tol && wc >= tol).then_some([wa, wb, wc])
}

/// World positions of located samples for positions `x` of `mesh`'s vertices.
pub fn sample_positions(mesh: &Mesh, x: &[Vector], located: &[Located]) -> Vec<Vector> {
    located
        .iter()
        .map(|l| {
            let tri = mesh.triangles[l.triangle as usize];
            (0..3).map(|k| x[tri[k] as usize] * l.weights[k]).sum()
        })
        .collect()
}

/// RMS distance between two sample sets, divided by `scale` (the diagonal).
pub fn relative_rms(a: &[Vector], b: &[Vector], scale: Scalar) -> Scalar {
    if a.is_empty() {
        return 0.0;
    }
    let sum: Scalar = a.iter().zip(b).map(|(p, q)| p.distance_squared(*q)).sum();
    (sum / a.len() as Scalar).sqrt() / scale
}

/// The mean displacement from `b` to `a` (the rigid translation part of their
/// difference), its length relative to `scale`. With `e = relative_rms(a, b,
/// scale)` and `o` this offset, `sqrt(e^2 - o^2)` is the RMS of what is left once
/// the translation is taken out (the sum of squares splits into the mean's and
/// the deviations' parts); `drape bench` reports `o` beside `e` so that a run
/// whose error is mostly a shift of the whole cloth can be told from one whose
/// shape is off.
pub fn relative_offset(a: &[Vector], b: &[Vector], scale: Scalar) -> Scalar {
    mean_displacement(a, b).length() / scale
}

/// The mean of `a[i] - b[i]`, m (zero for no points).
pub fn mean_displacement(a: &[Vector], b: &[Vector]) -> Vector {
    if a.is_empty() {
        return Vector::ZERO;
    }
    a.iter().zip(b).map(|(p, q)| *p - *q).sum::<Vector>() / a.len() as Scalar
}

/// The cloth's diagonal in material space, m.
pub fn diagonal(mesh: &Mesh) -> Scalar {
    let (lo, hi) = mesh.material_bounds();
    lo.distance(hi)
}
