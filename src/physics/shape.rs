//! Shape-operator bending (the default, `bending_model = "shape_operator"`): per
//! triangle, the curvature tensor built from the dihedral angles of its three
//! edges, and the plate energy `(B/2) A_t |S_t|^2`.
//!
//! # The element
//! Triangle `t` with rest area `A`, edges `a = 0, 1, 2` (edge `a` opposite its
//! vertex `a`), rest lengths `L_a` and in-plane unit edge normals `t_a` (material
//! space). With `theta_a` the dihedral angle at edge `a` (zero on a boundary edge),
//! the triangle's shape operator is (Grinspun et al. 2006, "Computing discrete
//! shape operators on general meshes"; each edge's bend shared by its two
//! triangles)
//! `S_t = 1/(2A) sum_a theta_a L_a t_a t_a^T`,
//! and its energy, the Kirchhoff plate with Poisson ratio 0 whose beam rigidity
//! per width is exactly `B` (the textile cantilever's flexural rigidity):
//! `E_t = (B A / 2) |S_t|_F^2 = (1/2) theta^T M theta`,
//! `M_ab = (B / (4 A)) L_a L_b (t_a . t_b)^2` (constant, positive semi-definite).
//! Forces: `f = -sum_a (M theta)_a grad theta_a`. For the implicit solver the
//! Gauss-Newton Hessian is `J^T M J (x) ` with `J` the 3 x 18 matrix whose rows are
//! the angle gradients (each over 4 of the element's 6 vertices: the triangle's
//! own three and the tips across its interior edges); the dropped curvature term
//! `sum_a (M theta)_a Hess theta_a` is indefinite, as for the hinges.
//!
//! # Why it converges where the edge hinges do not
//! `sum_t A_t S_t = sum_e theta_e L_e t_e t_e^T` is exactly the integral of the
//! distributional Hessian of the piecewise-linear surface (the jump of its
//! gradient across each edge). So any fluctuation of the vertices that is periodic
//! on the mesh scale adds nothing to the mean curvature, and by Jensen's
//! inequality `sum_t A_t |S_t|^2 >= |sum_t A_t S_t|^2 / A`: the sheet cannot bend
//! more cheaply than the continuum. For a strip bent along one grid direction the
//! three angles of every triangle give `S_t` exactly, so the bound is attained:
//! the energy is `B/2 kappa^2` per area, at every resolution.
//!
//! The per-edge hinge energy `k_e theta_e^2` (`bending = "dihedral"`) only has the
//! edges' diagonal terms. On a right-triangle grid the bending of a strip can then
//! be shared by the across-length hinges and the diagonal ones (the diagonals carry
//! half of their bend in the along-length component), and the minimiser does so:
//! measured, the strip settles at 1.32x beam theory at resolution 28 and
//! our clamped strip's chord angle is off by +3.8 deg at resolution 64 (tables in
//! the elastica tests). A first attempt here, the second derivatives of a
//! least-squares quadratic through each triangle and its neighbours (exact for
//! quadratic fields, "basic shell triangle" style), was softer still: 1.38x /
//! 1.39x / 1.42x / 1.42x beam theory at resolutions 8 / 16 / 32 / 64, because a
//! least-squares fit is exact for smooth fields but lets mesh-scale zigzags
//! produce mean curvature (it has no discrete integration-by-parts identity).
//!
//! # Clamps
//! Each edge's angle is shared by its two triangles (equally on a uniform mesh;
//! by area in general, see "Sharing" below) because a piecewise-linear fold
//! stands for curvature spread over both sides. A triangle
//! held by one never-released pin (a clamp) cannot bend, so at the edge of a
//! clamp the whole fold belongs to the free side: the free triangle takes the
//! angle with share 2 (`M_ab` scaled by `s_a s_b`) and the held triangle has no
//! element. Sharing it instead puts half the bend inside the clamp, which acts as
//! a clamp half a cell further back: measured on the clamped strip, tip
//! deflection (1 + 1/N)^2 times beam theory (1.265 / 1.128 / 1.063 / 1.031 at
//! N = 8 / 16 / 32 / 64 cells over the overhang) and chord angles +6.7 / +3.4 /
//! +1.7 / +0.9 deg off the elastica. The same 1D analysis (a finite-difference
//! beam, the clamp hinge weighted w) gives (1 + 1/N)^2 for w = 1 and 1 + 1/(8 N^2)
//! for w = 2: the clamp treatment makes the clamp second-order accurate. It uses
//! no resolution-dependent constant.
//!
//! # Sharing between triangles of different sizes
//! Where the two triangles at an edge differ in size (a refined region next to
//! a coarse one, red-green's green closure triangles), an equal split of the
//! fold overstates the small triangle's curvature: the fold stands for the
//! curvature between the two centroids, at distances `h_t / 3` and `h_o / 3`
//! from the edge, so the small triangle covers less than half of it. Each
//! triangle takes the part over it, `A_t / (A_t + A_o)` (the heights in
//! proportion, for the shared edge), which is one half on a uniform mesh and
//! keeps `sum_t A_t S_t = sum_e theta_e L_e t_e t_e^T` (the shares of an edge
//! sum to 1), so the Jensen bound above still holds. Measured with the equal
//! split on a cylinder imposed on the cantilever strip after 8 red-green splits
//! near its clamp: the refined triangles carried 1.5 (level 2) and 1.9 (green,
//! level 1) times the exact energy density `B / (2 R^2)` on average, up to 3.2
//! times, and the settled strip's chord angle was 36.26 deg against 41.97 deg
//! unrefined (elastica 41.5).
//!
//! Boundary edges have no angle, so an imposed curvature across a free edge loses
//! the outer half row of triangles' share (the `1 - 1/n` of the cylinder test).
//! At a free edge the plate's natural boundary condition is zero moment, so a
//! settled sheet has no curvature across it there, and no energy is lost.

use super::bending::dihedral_angle_and_gradient;
use crate::math::{Scalar, Vector, Vector2};
use crate::mesh::Mesh;

/// Vertex slots of a shape triangle: its three vertices, then the tips across
/// edges 0, 1, 2.
pub const SHAPE_SLOTS: usize = 6;

/// Slots of the hinge of edge `a` in the order of [`dihedral_angle_and_gradient`]:
/// the edge (counter-clockwise in the triangle), the triangle's own opposite
/// vertex, the tip across.
const HINGE_SLOTS: [[usize; 4]; 3] = [[1, 2, 0, 3], [2, 0, 1, 4], [0, 1, 2, 5]];

/// One triangle's bending element (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeTriangle {
    /// Vertices: the triangle's three (counter-clockwise in material space), then
    /// the tips across edges 0, 1, 2 (edge `a` is opposite vertex `a`); a boundary
    /// edge's tip slot repeats vertex `a` and is unused.
    pub v: [u32; SHAPE_SLOTS],
    /// Which edges are interior (have an angle).
    pub interior: [bool; 3],
    /// The constant matrix `M` of `E = theta^T M theta / 2`, N m.
    pub m: [[Scalar; 3]; 3],
}

/// Angles of a shape triangle's edges and their gradients by slot.
pub type ShapeJacobian = [[Vector; SHAPE_SLOTS]; 3];

impl ShapeTriangle {
    /// The used slots with their vertices.
    pub fn slots(&self) -> impl Iterator<Item = (usize, u32)> + '_ {
        (0..SHAPE_SLOTS)
            .filter(|&k| k < 3 || self.interior[k - 3])
            .map(|k| (k, self.v[k]))
    }

    /// The three edge angles and their gradients (zero on boundary edges).
    #[inline(always)]
    pub fn angles(&self, x: &[Vector]) -> ([Scalar; 3], ShapeJacobian) {
        let mut theta = [0.0; 3];
        let mut jac = [[Vector::ZERO; SHAPE_SLOTS]; 3];
        for a in 0..3 {
            if !self.interior[a] {
                continue;
            }
            let s = HINGE_SLOTS[a];
            let (th, g) = dihedral_angle_and_gradient(s.map(|k| x[self.v[k] as usize]));
            theta[a] = th;
            for (j, &k) in s.iter().enumerate() {
                jac[a][k] = g[j];
            }
        }
        (theta, jac)
    }

    /// `M y`.
    #[inline(always)]
    pub fn times_m(&self, y: [Scalar; 3]) -> [Scalar; 3] {
        [0, 1, 2].map(|a| (0..3).map(|b| self.m[a][b] * y[b]).sum())
    }

    /// Elastic energy at positions `x`, J.
    pub fn energy(&self, x: &[Vector]) -> Scalar {
        let (theta, _) = self.angles(x);
        let mt = self.times_m(theta);
        0.5 * (0..3).map(|a| theta[a] * mt[a]).sum::<Scalar>()
    }

    /// Forces `-sum_a (M theta)_a grad theta_a` by slot, into `out[..6]`.
    #[inline(always)]
    pub fn forces(&self, x: &[Vector], out: &mut [Vector]) {
        let (theta, jac) = self.angles(x);
        spread(&jac, self.times_m(theta).map(|c| -c), out);
    }
}

/// `out[k] = sum_a c_a jac[a][k]` (slot forces or products `J^T c`).
#[inline(always)]
pub fn spread(jac: &ShapeJacobian, c: [Scalar; 3], out: &mut [Vector]) {
    for (k, o) in out.iter_mut().enumerate().take(SHAPE_SLOTS) {
        *o = jac[0][k] * c[0] + jac[1][k] * c[1] + jac[2][k] * c[2];
    }
}

/// `J p`: the rates of the three angles for vertex velocities (or directions) `p`.
#[inline(always)]
pub fn rates(t: &ShapeTriangle, jac: &ShapeJacobian, p: &[Vector]) -> [Scalar; 3] {
    [0, 1, 2].map(|a| {
        (0..SHAPE_SLOTS)
            .map(|k| jac[a][k].dot(p[t.v[k] as usize]))
            .sum()
    })
}

/// One shape triangle per mesh triangle not held by a clamp, for rigidity
/// `bending` (rest areas `area`; `clamped`: per vertex the pin holding it for
/// good or `u32::MAX`, or empty for no clamp).
pub fn build_shape_triangles(
    mesh: &Mesh,
    area: &[Scalar],
    bending: Scalar,
    clamped: &[u32],
) -> Vec<ShapeTriangle> {
    let held = |t: usize| {
        let [a, b, c] = mesh.triangles[t].map(|v| clamped.get(v as usize).copied());
        a.is_some_and(|p| p != u32::MAX) && a == b && b == c
    };
    let mut share = vec![[1.0 as Scalar; 3]; mesh.triangles.len()];
    let mut out: Vec<ShapeTriangle> = mesh
        .triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            let p = tri.map(|v| mesh.material[v as usize]);
            // Edge a runs from vertex a+1 to a+2.
            let e: [Vector2; 3] = [0, 1, 2].map(|a| p[(a + 2) % 3] - p[(a + 1) % 3]);
            let len = e.map(|v| v.length());
            let mut m = [[0.0; 3]; 3];
            for a in 0..3 {
                for b in 0..3 {
                    // (t_a . t_b)^2 = (e_a . e_b)^2 / (L_a L_b)^2.
                    let c = e[a].dot(e[b]) / (len[a] * len[b]);
                    m[a][b] = bending / (4.0 * area[t]) * len[a] * len[b] * c * c;
                }
            }
            ShapeTriangle {
                v: [tri[0], tri[1], tri[2], tri[0], tri[1], tri[2]],
                interior: [false; 3],
                m,
            }
        })
        .collect();
    for e in mesh.edges.iter().filter(|e| e.is_interior()) {
        for (side, other) in [(0, 1), (1, 0)] {
            let (t, o) = (e.triangles[side] as usize, e.triangles[other]);
            let tri = mesh.triangles[t];
            let a = (0..3)
                .find(|&a| !e.vertices.contains(&tri[a]))
                .expect("an edge's triangle has a vertex off the edge");
            out[t].v[3 + a] = mesh.opposite_vertex(o, e);
            out[t].interior[a] = true;
            // Twice the triangle's part of the fold (module docs, "Sharing"):
            // all of it next to a clamp, else in proportion to area.
            share[t][a] = if held(o as usize) {
                2.0
            } else {
                2.0 * area[t] / (area[t] + area[o as usize])
            };
        }
    }
    for (t, st) in out.iter_mut().enumerate() {
        for a in 0..3 {
            for b in 0..3 {
                st.m[a][b] *= share[t][a] * share[t][b];
            }
        }
    }
    (0..out.len())
        .filter(|&t| !held(t))
        .map(|t| out[t])
        .collect()
}
