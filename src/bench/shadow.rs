//! The cloth's shadow: the area of its projection on the ground plane (the
//! xy plane; every scene here has z up), the quantity of the textile drape
//! test (the drape coefficient is the shadow's area beyond the support over
//! the specimen's beyond it). It depends on how far the cloth hangs and
//! spreads, not on where each fold lies, so it can compare runs whose folds
//! formed in different places. Measured (`docs/speed-vs-error-history.md`, "The
//! shadow"): on the falling sheets it does not converge either (a mesh two
//! segments finer than the reference changes it by 0.8 to 2.1 %, 0.67 to 1.5
//! times uniform 64's difference), because how far a sheet spreads depends
//! on how many folds it makes.
//!
//! # How
//! The surface is the sample grid's (the bench's `n` x `n` material points at
//! cell centres, so half a sample cell inside the cloth's edge), each grid
//! square split into two triangles, projected along z. Their union is
//! rasterised on square cells of a fixed size anchored at the world origin
//! (the same geometry gives the same count in every run), and the covered
//! cells' area summed. The raster's own error is at most a row of cells
//! along each straight stretch of the outline (the test
//! `bench::the_shadow_of_a_flat_and_a_tilted_square`: 1.3e-6 and 2.3e-3
//! relative on a 0.875 m square and its 60 degree tilt, cells of 1 mm);
//! with cells of 1/2000 of the diagonal (1.1 mm on the 1.6 m sheets) that
//! is at most 0.14 % of a flat sheet's shadow per straight side, less on a
//! draped outline, whose cells err either way.

use super::sampling::FrameSamples;
use crate::math::Scalar;

/// Raster cells per diagonal of the cloth's material bounds.
pub const CELLS_PER_DIAGONAL: Scalar = 2000.0;

/// The shadow's area of one frame, m^2, on square cells of `cell` m: `None`
/// when the samples are not a complete square grid (a disk or an OBJ
/// outline, or a point not found in the mesh).
pub fn shadow_area(frame: &FrameSamples, cell: Scalar) -> Option<Scalar> {
    let len = frame.positions.len();
    let n = (len as Scalar).sqrt().round() as usize;
    if n < 2 || n * n != len || cell.is_nan() || cell <= 0.0 {
        return None;
    }
    let p: Vec<[Scalar; 2]> = frame
        .positions
        .iter()
        .map(|q| q.map(|q| [q[0] / cell, q[1] / cell]))
        .collect::<Option<_>>()?;
    let (mut lo, mut hi) = ([Scalar::INFINITY; 2], [Scalar::NEG_INFINITY; 2]);
    for q in &p {
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    if !(lo[0].is_finite() && lo[1].is_finite() && hi[0].is_finite() && hi[1].is_finite()) {
        return None;
    }
    // Cell (i, j) covers [i, i + 1) x [j, j + 1) in cell units; its centre
    // decides whether it is covered.
    let (i0, j0) = (lo[0].floor() as i64, lo[1].floor() as i64);
    let (w, h) = (
        (hi[0].floor() as i64 - i0 + 1) as usize,
        (hi[1].floor() as i64 - j0 + 1) as usize,
    );
    let mut covered = vec![false; w * h];
    let id = |i: usize, j: usize| j * n + i;
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            for tri in [[p[a], p[b], p[c]], [p[a], p[c], p[d]]] {
                fill(tri, (i0, j0), (w, h), &mut covered);
            }
        }
    }
    Some(covered.iter().filter(|&&c| c).count() as Scalar * cell * cell)
}

/// Marks the cells whose centres lie in triangle `t` (either orientation;
/// a degenerate one covers nothing).
fn fill(t: [[Scalar; 2]; 3], (i0, j0): (i64, i64), (w, h): (usize, usize), out: &mut [bool]) {
    let cross = |o: [Scalar; 2], a: [Scalar; 2], b: [Scalar; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let area = cross(t[0], t[1], t[2]);
    if area == 0.0 {
        return;
    }
    let s = area.signum();
    let min = |k: usize| t[0][k].min(t[1][k]).min(t[2][k]);
    let max = |k: usize| t[0][k].max(t[1][k]).max(t[2][k]);
    let (ia, ib) = ((min(0) - 0.5).ceil() as i64, (max(0) - 0.5).floor() as i64);
    let (ja, jb) = ((min(1) - 0.5).ceil() as i64, (max(1) - 0.5).floor() as i64);
    for j in ja.max(j0)..=jb.min(j0 + h as i64 - 1) {
        for i in ia.max(i0)..=ib.min(i0 + w as i64 - 1) {
            let c = [i as Scalar + 0.5, j as Scalar + 0.5];
            let inside = (0..3).all(|k| s * cross(t[k], t[(k + 1) % 3], c) >= 0.0);
            if inside {
                out[(j - j0) as usize * w + (i - i0) as usize] = true;
            }
        }
    }
}

/// `(time, |A_run - A_ref| / A_ref)` for the frames both runs have at the
/// same time, on cells of `cell` m; empty when a shadow cannot be taken.
pub fn shadow_errors(
    run: &[FrameSamples],
    reference: &[FrameSamples],
    cell: Scalar,
) -> Vec<(Scalar, Scalar)> {
    run.iter()
        .zip(reference)
        .filter(|(a, b)| a.frame == b.frame)
        .map_while(|(a, b)| {
            let (sa, sb) = (shadow_area(a, cell)?, shadow_area(b, cell)?);
            (sb > 0.0).then(|| (b.time, (sa - sb).abs() / sb))
        })
        .collect()
}
