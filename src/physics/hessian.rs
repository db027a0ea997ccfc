//! Hessian bending: the energy `E = (B/2) * integral |d^2 x / du^2|^2 dA` over the
//! material domain, discretised with one quadratic fit per triangle (the default
//! `bending_model = "hessian"`).
//!
//! # Why this energy
//! The rest state of cloth is flat, so material coordinates `u` are arc-length
//! coordinates. For an isometric deformation `x(u)` the second derivatives are
//! normal vectors, `x_,ab = II_ab n`, so `|d^2 x/du^2|^2 = II_11^2 + 2 II_12^2 +
//! II_22^2 = kappa_1^2 + kappa_2^2`: this is the Kirchhoff plate with Poisson ratio
//! 0, whose beam rigidity per width is exactly `B`, the flexural rigidity of
//! textile testing (Peirce's cantilever). A strip bent along its length has no
//! anticlastic coupling, so the heavy elastica is its exact large-deflection limit.
//! The energy is quadratic in the positions and invariant under rigid motions
//! (the stencils annihilate affine fields and act on each coordinate alike).
//!
//! # Discretisation
//! For each triangle `t` a patch of vertices is chosen: its own three, the tips
//! of the triangles across its interior edges, and (where that leaves fewer than
//! six points or a badly conditioned fit, at boundaries) the nearest further
//! vertices in material space. The second derivatives on `t` are those of the
//! least-squares quadratic through the patch in material coordinates: with the
//! affine part projected out, `Q = (I - P_aff) [u^2/2, u v, v^2/2]` and
//! `H = (Q^T Q)^+ Q^T x`, a fixed linear stencil `H_r = sum_j w_rj x_j` (r =
//! uu, uv, vv). Six points interpolate exactly (the rotation-free "basic shell
//! triangle" of Onate and Zarate 2000). The stencil is exact for quadratic
//! fields, so the energy converges to the continuum on any mesh, uniform or
//! adapted, and with no per-resolution constant. Energy:
//! `E_t = sum_r c_r / 2 |H_r|^2`, `c = B A_t [1, 2, 1]`.
//!
//! The Hessian of the energy is constant, `sum_r c_r w_r w_r^T (x) I_3` per patch
//! (exact, positive semi-definite), so forces are linear in the positions.
//!
//! Boundary: the patches of boundary triangles reach inwards, so every triangle
//! (including those along free edges) carries its full share `A_t`; the
//! `1 - 1/n` free-edge deficit of the edge-hinge model is gone and the natural
//! boundary conditions of the plate come from the minimisation itself.
//!
//! # What was tried first
//! The dihedral hinge (`bending.rs`) measures, on a sheared hinge (tips not
//! opposite each other along the edge, as on every right-triangle grid), the
//! second difference `d^T S d - (e/2)^T S (e/2)` with `d` the tip offset: for the
//! grid's hinges this is `h^2 (S_xx -+ S_xy)`, a normal curvature polluted by the
//! twist. The minimiser exploits the coupling (the diagonal hinges take up twist)
//! and the strip behaves as if its rigidity were about `5/6 B` (measured: 1.32x
//! beam-theory deflection at resolution 28, chord angle 47.7 deg against the
//! elastica's 41.5 at resolution 64). No 4-point stencil can avoid this: a hinge
//! has one second-difference combination only, hence the wider patch here.

use crate::math::{Scalar, Vector, Vector2};
use crate::mesh::{Mesh, NO_TRIANGLE};

/// Most vertices in one bending patch.
pub const PATCH_MAX: usize = 10;

/// Smallest accepted ratio of the extreme eigenvalues of `Q^T Q` (scaled
/// coordinates) before the patch stops growing.
const WELL_CONDITIONED: Scalar = 1e-3;

/// One triangle's bending element: `E = sum_r c[r] / 2 * |sum_k w[r][k] x[v[k]]|^2`.
///
/// Slots `k >= n` are unused (weight zero, vertex repeated). Its Hessian is the
/// constant `sum_r c[r] w[r] w[r]^T (x) I_3` over the patch vertices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BendPatch {
    /// Patch vertices; the first `n` are used.
    pub v: [u32; PATCH_MAX],
    /// Number of vertices used.
    pub n: u8,
    /// Stencil weights of `x_uu`, `x_uv`, `x_vv`, 1/m^2.
    pub w: [[Scalar; PATCH_MAX]; 3],
    /// Row stiffnesses `B A_t [1, 2, 1]`, N m^3.
    pub c: [Scalar; 3],
}

impl BendPatch {
    /// The used vertices.
    #[inline]
    pub fn vertices(&self) -> &[u32] {
        &self.v[..self.n as usize]
    }

    /// The second derivatives `[x_uu, x_uv, x_vv]` of positions `x`.
    #[inline(always)]
    pub fn second_derivatives(&self, x: &[Vector]) -> [Vector; 3] {
        let mut h = [Vector::ZERO; 3];
        for k in 0..self.n as usize {
            let xk = x[self.v[k] as usize];
            for (r, hr) in h.iter_mut().enumerate() {
                *hr += xk * self.w[r][k];
            }
        }
        h
    }

    /// Elastic energy at positions `x`, J.
    #[inline]
    pub fn energy(&self, x: &[Vector]) -> Scalar {
        let h = self.second_derivatives(x);
        (0..3).map(|r| 0.5 * self.c[r] * h[r].length_squared()).sum()
    }

    /// `out[k] = sum_r scale_r w[r][k] y_r` for a precomputed `y_r = c_r H_r(.)`:
    /// with `y = -c H(x)` these are the forces, with `y = c H(p)` the product of
    /// the Hessian with `p`.
    #[inline(always)]
    pub fn spread(&self, y: [Vector; 3], out: &mut [Vector]) {
        for (k, o) in out.iter_mut().enumerate().take(self.n as usize) {
            *o = y[0] * self.w[0][k] + y[1] * self.w[1][k] + y[2] * self.w[2][k];
        }
    }

    /// Forces on the patch vertices (`-dE/dx`), written to `out[..n]`.
    #[inline(always)]
    pub fn forces(&self, x: &[Vector], out: &mut [Vector]) {
        let h = self.second_derivatives(x);
        self.spread([0, 1, 2].map(|r| h[r] * -self.c[r]), out);
    }

    /// Diagonal of the Hessian at slot `k` (the same in x, y and z).
    #[inline]
    pub fn diagonal(&self, k: usize) -> Scalar {
        (0..3).map(|r| self.c[r] * self.w[r][k] * self.w[r][k]).sum()
    }
}

/// Builds one patch per triangle for rigidity `bending` (rest areas `area`).
/// A triangle whose neighbourhood cannot determine a quadratic at all (a mesh
/// of fewer than six vertices) gets the least-squares minimum-norm stencil.
pub fn build_patches(mesh: &Mesh, area: &[Scalar], bending: Scalar) -> Vec<BendPatch> {
    let n = mesh.vertex_count();
    let mut vertex_tris: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            vertex_tris[v as usize].push(t as u32);
        }
    }
    let mut tips: Vec<Vec<u32>> = vec![Vec::new(); mesh.triangles.len()];
    for e in mesh.edges.iter().filter(|e| e.is_interior()) {
        let [t0, t1] = e.triangles;
        tips[t0 as usize].push(mesh.opposite_vertex(t1, e));
        tips[t1 as usize].push(mesh.opposite_vertex(t0, e));
    }
    debug_assert!(mesh.edges.iter().all(|e| e.triangles[0] != NO_TRIANGLE));
    (0..mesh.triangles.len())
        .map(|t| {
            let tri = mesh.triangles[t];
            let mut pts: Vec<u32> = tri.to_vec();
            pts.extend(&tips[t]);
            let centre = tri
                .iter()
                .map(|&v| mesh.material[v as usize])
                .sum::<Vector2>()
                / 3.0;
            let scale = (2.0 * area[t]).sqrt();
            let mut fit = fit_quadratic(&mesh.material, &pts, centre, scale);
            // Grow the patch ring by ring, nearest first, until well determined.
            let mut frontier = pts.clone();
            while !(pts.len() >= 6 && fit.1 > WELL_CONDITIONED) && pts.len() < PATCH_MAX {
                let mut ring: Vec<u32> = frontier
                    .iter()
                    .flat_map(|&v| &vertex_tris[v as usize])
                    .flat_map(|&s| mesh.triangles[s as usize])
                    .filter(|v| !pts.contains(v))
                    .collect();
                ring.sort_unstable();
                ring.dedup();
                if ring.is_empty() {
                    break;
                }
                let dist = |v: &u32| mesh.material[*v as usize].distance_squared(centre);
                ring.sort_by(|a, b| dist(a).total_cmp(&dist(b)).then(a.cmp(b)));
                for &v in &ring {
                    if pts.len() >= PATCH_MAX || (pts.len() >= 6 && fit.1 > WELL_CONDITIONED) {
                        break;
                    }
                    pts.push(v);
                    fit = fit_quadratic(&mesh.material, &pts, centre, scale);
                }
                frontier = ring;
            }
            let mut patch = BendPatch {
                v: [tri[0]; PATCH_MAX],
                n: pts.len() as u8,
                w: [[0.0; PATCH_MAX]; 3],
                c: [1.0, 2.0, 1.0].map(|f| f * bending * area[t]),
            };
            patch.v[..pts.len()].copy_from_slice(&pts);
            for r in 0..3 {
                patch.w[r][..pts.len()].copy_from_slice(&fit.0[r]);
            }
            patch
        })
        .collect()
}

/// Stencil weights `[w_uu, w_uv, w_vv]` of the least-squares quadratic through
/// the points `pts` (module docs), and the conditioning ratio of the fit.
fn fit_quadratic(
    material: &[Vector2],
    pts: &[u32],
    centre: Vector2,
    scale: Scalar,
) -> ([Vec<Scalar>; 3], Scalar) {
    let m = pts.len();
    let u: Vec<Vector2> = pts
        .iter()
        .map(|&v| (material[v as usize] - centre) / scale)
        .collect();
    // Affine least squares: G = A^T A with A = [1, u, v].
    let mut g = [[0.0; 3]; 3];
    let rows: Vec<[Scalar; 3]> = u.iter().map(|p| [1.0, p.x, p.y]).collect();
    for a in &rows {
        for i in 0..3 {
            for j in 0..3 {
                g[i][j] += a[i] * a[j];
            }
        }
    }
    let ginv = inverse3(g);
    // Q = (I - A G^-1 A^T) [u^2/2, u v, v^2/2].
    let quad: Vec<[Scalar; 3]> = u
        .iter()
        .map(|p| [0.5 * p.x * p.x, p.x * p.y, 0.5 * p.y * p.y])
        .collect();
    let mut atq = [[0.0; 3]; 3]; // A^T quad
    for (a, q) in rows.iter().zip(&quad) {
        for i in 0..3 {
            for j in 0..3 {
                atq[i][j] += a[i] * q[j];
            }
        }
    }
    let q: Vec<[Scalar; 3]> = (0..m)
        .map(|k| {
            let mut row = quad[k];
            for (j, rj) in row.iter_mut().enumerate() {
                for i in 0..3 {
                    for l in 0..3 {
                        *rj -= rows[k][i] * ginv[i][l] * atq[l][j];
                    }
                }
            }
            row
        })
        .collect();
    let mut qtq = [[0.0; 3]; 3];
    for row in &q {
        for i in 0..3 {
            for j in 0..3 {
                qtq[i][j] += row[i] * row[j];
            }
        }
    }
    let (vals, vecs) = symmetric_eigen3(qtq);
    let top = vals.iter().cloned().fold(0.0, Scalar::max);
    let low = vals.iter().cloned().fold(Scalar::INFINITY, Scalar::min);
    let ratio = if top > 0.0 { low / top } else { 0.0 };
    // Pseudo-inverse, dropping directions the points do not determine.
    let mut pinv = [[0.0; 3]; 3];
    for (l, &lam) in vals.iter().enumerate() {
        if lam > 1e-10 * top {
            for i in 0..3 {
                for j in 0..3 {
                    pinv[i][j] += vecs[i][l] * vecs[j][l] / lam;
                }
            }
        }
    }
    let s2 = scale * scale;
    let w = [0, 1, 2].map(|r| {
        (0..m)
            .map(|k| (0..3).map(|j| pinv[r][j] * q[k][j]).sum::<Scalar>() / s2)
            .collect()
    });
    (w, ratio)
}

/// Inverse of a 3x3 matrix (rows), by cofactors.
fn inverse3(m: [[Scalar; 3]; 3]) -> [[Scalar; 3]; 3] {
    let c = |i: usize, j: usize| {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
        m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = c(j, i) / det;
        }
    }
    inv
}

/// Eigenvalues and eigenvectors (columns) of a symmetric 3x3 matrix (Jacobi).
fn symmetric_eigen3(mut a: [[Scalar; 3]; 3]) -> ([Scalar; 3], [[Scalar; 3]; 3]) {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let diag = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off <= 1e-15 * diag || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let (c, s) = (1.0 / (t * t + 1.0).sqrt(), t / (t * t + 1.0).sqrt());
            for k in 0..3 {
                let (akp, akq) = (a[k][p], a[k][q]);
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let (apk, aqk) = (a[p][k], a[q][k]);
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in v.iter_mut() {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2]], v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::DiagonalPattern;

    /// Every patch reproduces the second derivatives of a quadratic field exactly
    /// and annihilates affine fields, on both grid patterns and a disk.
    #[test]
    fn patches_are_exact_for_quadratic_fields() {
        let meshes = [
            crate::mesh::rectangle(1.0, 0.5, 8, DiagonalPattern::Alternating).unwrap(),
            crate::mesh::rectangle(0.3, 1.0, 7, DiagonalPattern::Regular).unwrap(),
            crate::mesh::rectangle(1.0, 0.25, 8, DiagonalPattern::Alternating).unwrap(),
            crate::mesh::disk(0.5, 9).unwrap(),
        ];
        let (huu, huv, hvv) = (
            Vector::new(0.3, -1.2, 2.0),
            Vector::new(-0.7, 0.4, 1.1),
            Vector::new(0.9, 0.2, -0.5),
        );
        for m in &meshes {
            let area: Vec<Scalar> = (0..m.triangles.len()).map(|t| m.rest_area(t)).collect();
            let patches = build_patches(m, &area, 1.0);
            let x: Vec<Vector> = m
                .material
                .iter()
                .map(|p| {
                    Vector::new(0.1, 2.0, -1.0) + Vector::new(p.x, p.y, 0.3 * p.x)
                        + huu * (0.5 * p.x * p.x)
                        + huv * (p.x * p.y)
                        + hvv * (0.5 * p.y * p.y)
                })
                .collect();
            for p in &patches {
                let h = p.second_derivatives(&x);
                for (got, want) in h.iter().zip([huu, huv, hvv]) {
                    assert!((*got - want).length() < 1e-8, "{got} vs {want}");
                }
                for r in 0..3 {
                    let s: Scalar = p.w[r].iter().sum();
                    assert!(s.abs() < 1e-6 * p.w[r].iter().map(|w| w.abs()).sum::<Scalar>());
                }
            }
            let sizes: Vec<u8> = patches.iter().map(|p| p.n).collect();
            assert!(sizes.iter().all(|&n| (6..=PATCH_MAX as u8).contains(&n)));
        }
    }
}
