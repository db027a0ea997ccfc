//! Mesh generators for the built-in cloth shapes, centred on the material origin.

use super::{Mesh, MeshError};
use crate::math::{Scalar, Vector2};
use crate::spec::DiagonalPattern;

/// A `width` x `height` grid with `resolution` segments along the longer side
/// (at least one along the shorter), each square split into two right triangles.
/// Material coordinates: u in [-width/2, width/2], v in [-height/2, height/2].
pub fn rectangle(
    width: Scalar,
    height: Scalar,
    resolution: u32,
    pattern: DiagonalPattern,
) -> Result<Mesh, MeshError> {
    rectangle_cells(width, height, resolution, None, pattern)
}

/// [`rectangle`] with `short_side_segments` segments along the shorter side
/// (`None`: as many as make square cells, as [`rectangle`]). Fewer give cells
/// longer across the sheet than along it, each split into two right triangles:
/// for a strip that bends along its length only (the cantilever), where
/// resolution across it buys nothing.
pub fn rectangle_cells(
    width: Scalar,
    height: Scalar,
    resolution: u32,
    short_side_segments: Option<u32>,
    pattern: DiagonalPattern,
) -> Result<Mesh, MeshError> {
    let (nx, ny) = cell_counts(width, height, resolution, short_side_segments);
    rectangle_on_lines(
        &uniform_lines(width, nx),
        &uniform_lines(height, ny),
        pattern,
    )
}

/// Material coordinates at which a generated grid must have lines: the edges
/// of the box pin regions, so that the vertices a box holds are exactly the
/// cloth inside it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GridCuts {
    /// u coordinates of lines of constant u, m.
    pub u: Vec<Scalar>,
    /// v coordinates of lines of constant v, m.
    pub v: Vec<Scalar>,
}

/// The u and v lines of [`rectangle_cells`]'s grid with a line at every cut
/// of `cuts` that falls strictly inside the sheet.
///
/// Where every cut is already on a uniform line (to 1e-9 of the sheet's
/// size) the uniform lines are returned bit for bit, so a scene whose boxes
/// sit on the grid keeps its mesh. Otherwise the cuts split the axis into
/// bands, and each band of length `L` gets `max(1, round(L / h))` equal cells
/// (`h` the uniform cell): every cell of a band is the same, within 0.5 to 1.5
/// `h` (0.75 to 1.25 `h` in a band of two cells or more), and a cell is
/// thinner than half a cell only where the scene's band itself is. Moving the
/// nearest line onto a cut would make neighbouring cells of 0.5 and 1.5 `h`
/// beside uniform ones, and splitting the cell at the cut a sliver as thin as
/// the cut's distance to a line; spreading the change over the band avoids
/// both. The lines are plain base lines: tensor refinement halves their
/// columns as it halves uniform ones.
pub fn fitted_lines(
    width: Scalar,
    height: Scalar,
    resolution: u32,
    short_side_segments: Option<u32>,
    cuts: &GridCuts,
) -> (Vec<Scalar>, Vec<Scalar>) {
    let (nx, ny) = cell_counts(width, height, resolution, short_side_segments);
    let tol = 1e-9 * width.max(height);
    (
        fit_axis(uniform_lines(width, nx), &cuts.u, tol),
        fit_axis(uniform_lines(height, ny), &cuts.v, tol),
    )
}

/// `n` equal cells over `size`, centred on 0 (the uniform grid's lines).
fn uniform_lines(size: Scalar, n: usize) -> Vec<Scalar> {
    (0..=n)
        .map(|i| -0.5 * size + size * i as Scalar / n as Scalar)
        .collect()
}

/// The lines of one axis with a line at every cut inside it ([`fitted_lines`]).
fn fit_axis(uniform: Vec<Scalar>, cuts: &[Scalar], tol: Scalar) -> Vec<Scalar> {
    let (lo, hi) = (uniform[0], uniform[uniform.len() - 1]);
    let mut inner: Vec<Scalar> = cuts
        .iter()
        .copied()
        .filter(|&c| c > lo + tol && c < hi - tol)
        .collect();
    inner.sort_by(Scalar::total_cmp);
    inner.dedup_by(|b, a| *b - *a <= tol);
    let on_a_line = |c: &Scalar| uniform.iter().any(|l| (l - c).abs() <= tol);
    if inner.iter().all(on_a_line) {
        return uniform;
    }
    let h = (hi - lo) / (uniform.len() - 1) as Scalar;
    let knots: Vec<Scalar> = std::iter::once(lo)
        .chain(inner)
        .chain(std::iter::once(hi))
        .collect();
    let mut lines = Vec::with_capacity(uniform.len() + knots.len());
    for band in knots.windows(2) {
        let (a, b) = (band[0], band[1]);
        let cells = ((b - a) / h).round().max(1.0) as usize;
        lines.extend((0..cells).map(|k| a + (b - a) * k as Scalar / cells as Scalar));
    }
    lines.push(hi);
    lines
}

/// A grid over the given u and v lines (each increasing, at least two), each
/// cell split into two right triangles by `pattern` (alternating by the
/// cell's column and row); vertices row by row along u.
pub fn rectangle_on_lines(
    us: &[Scalar],
    vs: &[Scalar],
    pattern: DiagonalPattern,
) -> Result<Mesh, MeshError> {
    let (nx, ny) = (us.len().saturating_sub(1), vs.len().saturating_sub(1));
    let mut material = Vec::with_capacity(us.len() * vs.len());
    for &v in vs {
        material.extend(us.iter().map(|&u| Vector2::new(u, v)));
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut triangles = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            let along_ac = match pattern {
                DiagonalPattern::Regular => true,
                DiagonalPattern::Alternating => (i + j) % 2 == 0,
                DiagonalPattern::AlternatingFlipped => (i + j) % 2 == 1,
            };
            if along_ac {
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            } else {
                triangles.push([a, b, d]);
                triangles.push([b, c, d]);
            }
        }
    }
    Mesh::new(material, triangles)
}

/// Cells along u and v of [`rectangle_cells`].
pub fn cell_counts(
    width: Scalar,
    height: Scalar,
    resolution: u32,
    short_side_segments: Option<u32>,
) -> (usize, usize) {
    let (mut nx, mut ny) = grid_counts(width, height, resolution);
    if let Some(short) = short_side_segments {
        let short = short.max(1) as usize;
        if width >= height {
            ny = short;
        } else {
            nx = short;
        }
    }
    (nx, ny)
}

/// Segments along u and v for a rectangle.
pub(crate) fn grid_counts(width: Scalar, height: Scalar, resolution: u32) -> (usize, usize) {
    let r = resolution.max(1) as Scalar;
    let (long, short) = (width.max(height), width.min(height));
    let along_short = ((r * short / long).round() as usize).max(1);
    if width >= height {
        (resolution.max(1) as usize, along_short)
    } else {
        (along_short, resolution.max(1) as usize)
    }
}

/// A disk of the given radius: concentric rings of nearly equilateral triangles,
/// ring spacing `2 * radius / resolution` (so `resolution` segments span the diameter).
pub fn disk(radius: Scalar, resolution: u32) -> Result<Mesh, MeshError> {
    let rings = (resolution.max(1) as usize).div_ceil(2);
    let mut material = vec![Vector2::ZERO];
    let mut ring_start = vec![0usize];
    for k in 1..=rings {
        ring_start.push(material.len());
        let count = 6 * k;
        let r = radius * k as Scalar / rings as Scalar;
        for m in 0..count {
            let a = std::f64::consts::TAU * m as Scalar / count as Scalar;
            material.push(Vector2::new(r * a.cos(), r * a.sin()));
        }
    }
    let mut triangles = Vec::new();
    for k in 1..=rings {
        let (inner_n, outer_n) = (if k == 1 { 1 } else { 6 * (k - 1) }, 6 * k);
        let inner = |i: usize| (ring_start[k - 1] + i % inner_n) as u32;
        let outer = |o: usize| (ring_start[k] + o % outer_n) as u32;
        if k == 1 {
            for o in 0..outer_n {
                triangles.push([0, outer(o), outer(o + 1)]);
            }
            continue;
        }
        // Zip the two rings by angle: advance whichever ring's next vertex comes first.
        let (mut i, mut o) = (0usize, 0usize);
        while i < inner_n || o < outer_n {
            let next_inner = (i + 1) as Scalar / inner_n as Scalar;
            let next_outer = (o + 1) as Scalar / outer_n as Scalar;
            if o < outer_n && (i == inner_n || next_outer <= next_inner) {
                triangles.push([inner(i), outer(o), outer(o + 1)]);
                o += 1;
            } else {
                triangles.push([inner(i), outer(o), inner(i + 1)]);
                i += 1;
            }
        }
    }
    Mesh::new(material, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangle_counts_and_area() {
        let m = rectangle(2.0, 1.0, 8, DiagonalPattern::Alternating).unwrap();
        assert_eq!(m.vertex_count(), 9 * 5);
        assert_eq!(m.triangles.len(), 2 * 8 * 4);
        assert!((m.total_rest_area() - 2.0).abs() < 1e-12);
        let interior = m.edges.iter().filter(|e| e.is_interior()).count();
        // Euler: E = V + F - 1 for a disk-like surface.
        assert_eq!(m.edges.len(), m.vertex_count() + m.triangles.len() - 1);
        assert!(interior > 0);
    }

    /// The flipped checkerboard splits every square along the other diagonal
    /// than the alternating one, over the same vertices.
    #[test]
    fn flipped_alternating_turns_every_diagonal() {
        let a = rectangle(2.0, 1.0, 8, DiagonalPattern::Alternating).unwrap();
        let f = rectangle(2.0, 1.0, 8, DiagonalPattern::AlternatingFlipped).unwrap();
        assert_eq!(a.material, f.material);
        assert_eq!(a.triangles.len(), f.triangles.len());
        // Each square's pair of triangles shares its diagonal: the two meshes
        // have no interior edge in common that is a diagonal.
        let diagonal = |m: &Mesh, k: usize| {
            let (s, t) = (m.triangles[2 * k], m.triangles[2 * k + 1]);
            let mut shared: Vec<u32> = s.iter().copied().filter(|v| t.contains(v)).collect();
            shared.sort_unstable();
            shared
        };
        for k in 0..a.triangles.len() / 2 {
            let (da, df) = (diagonal(&a, k), diagonal(&f, k));
            assert_eq!((da.len(), df.len()), (2, 2));
            assert_ne!(da, df, "square {k} keeps its diagonal");
        }
    }

    #[test]
    fn disk_is_manifold_with_exact_polygon_area() {
        for res in [1, 2, 7, 16] {
            let m = disk(0.5, res).unwrap();
            let rings = (res as usize).div_ceil(2);
            assert_eq!(m.vertex_count(), 1 + 3 * rings * (rings + 1));
            // The outer ring is a regular 6n-gon inscribed in the circle.
            let n = 6.0 * rings as f64;
            let polygon = 0.5 * n * 0.25 * (std::f64::consts::TAU / n).sin();
            assert!((m.total_rest_area() - polygon).abs() < 1e-12, "res {res}");
            assert!(
                m.triangles
                    .iter()
                    .enumerate()
                    .all(|(t, _)| m.rest_area(t) > 0.0)
            );
        }
    }
}
