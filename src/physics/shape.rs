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
//! (Triangles at a refinement transition use another constant `M`, from the
//! same three angles: "Transitions" below.)
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
//! (This identity is given up at refinement transitions, where each triangle is
//! made exact for constant curvature instead: see "Transitions".)
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
//! (Splitting by the heights over the shared edge, or by the centroids'
//! distances `h / 3` from it, is the same split: the edge is common, so the
//! heights are in proportion to the areas. Splitting by inradius was tried and
//! is worse: on the probe below, green triangles 1.325 and red ones 1.148 for
//! the cylinder about x, against 1.052 / 1.108 by area.)
//!
//! # Transitions
//! Area shares fix the sizes, not the shapes. Probe (the test
//! `partly_refined_sheet_bends_like_the_continuum`, and a scratch program, not
//! kept, doing the same on more meshes): impose `f = x^T H x / 2` for constant `H` on a partly refined sheet,
//! take the folds of its linear interpolant, and compare each class's energy
//! with `B/2 |H|^2` over its area (classes: coarse level 0, green 1-2 closure
//! triangles, red refined ones; triangles with all edges interior). With area
//! shares, on the 8 x 8 sheet refined one red level over `|y| < 0.2` (a jagged
//! band), coarse / green / red: cylinder about x (`H = e_y e_y`) 1.000 / 1.052
//! / 1.108, about y 1.056 / 1.179 / 1.081, sphere 0.861 / 1.056 / 1.152, saddle
//! 1.194 / 1.175 / 1.038 (single triangles up to 2.1 times); on a straight band
//! `|y| < 0.15` the green triangles carry 2.56 times for the cylinder bent
//! along the band and 2.03 times for the sphere (single ones 4.6 times); in a
//! refined disk 1.74 / 1.88; the level-3 greens of a second red level 2.04 /
//! 2.14. The uniform sheet is exact for all four. Equal halves are worse
//! (greens 1.679 for the first cylinder).
//!
//! The cause: the folds are right (their sum is the curvature's integral),
//! their sharing is not. A green split adds an edge that is not along the
//! grid (directions like (1, 2)); under a bend along x its fold carries, per
//! unit of its length, `xy` and `yy` parts as well as `xx`, and on the uniform
//! grid those parts are cancelled inside every triangle by the folds of its
//! other edges. At a transition the folds that should cancel them sit on edges
//! of other sizes and shapes (a hanging-node half edge, a coarse hypotenuse),
//! so each triangle keeps a residue, the residues cancel only in the sum over
//! the patch, and by Jensen the energy of the parts exceeds that of the sum.
//! On the straight band bent along it (`H = kappa e_x e_x`) the two green
//! halves of a coarse triangle get `S = [[2/3, 1/6], [1/6, 1/4]] kappa` (the
//! obtuse one) and `[[2, 1/2], [1/2, 1/4]] kappa` (the right-angled one,
//! 4.56 times the continuum's energy density). No scalar share per edge
//! can fix this: a triangle has three shares and six conditions (exact `S` for
//! `H = xx` and `H = yy`).
//!
//! So a transition triangle (all three edges interior, and a free neighbour of
//! another level, as a green one's red neighbour always is) gets the operator that is exact for every
//! constant `H`: with `C` the shared-fold operator above (`S = C theta`, as
//! `[S_xx, S_yy, S_xy]`) and `Theta` the 3 x 3 map from `H` to this triangle's
//! three folds (from its own and its neighbours' rest corners; a held
//! neighbour keeps the tangent plane of `f` at the edge's midpoint, which
//! reproduces the clamp's share of 2),
//! `S = P theta`, `P = C + (I - C Theta) Theta^+`,
//! (`Theta^+` a pseudo-inverse: a green triangle whose three folds are all
//! zero under a twist, which happens, cannot see the twist, and `P` leaves it
//! as `C` does), and `M = B A P^T W P`, `W = diag(1, 1, 2)`. Where `C` is exact
//! already the correction is zero; every other triangle keeps `C` bit for bit,
//! so a mesh of one level is unchanged. Measured on the same probes: every
//! class 1.000 for both cylinders, the sphere and the saddle, on all the
//! meshes above (the test: 1.000 / 0.998 / 1.000 with its exact, strongly bent
//! cylinders). `P` stays well conditioned: `|det P / det C|` 0.44 to 1.9 and
//! the trace of `P^T W P` 0.41 to 1.47 times `C`'s over the transition
//! triangles. The cantilever (resolution 10, red-green, 8 splits near the
//! clamp): chord angle 37.78 -> 41.92 deg (41.97 unrefined, elastica 41.5);
//! with 40 splits (`refine_angle = 3`) 41.47 -> 41.67.
//!
//! What is given up, and what was not done:
//! * A transition triangle whose three folds cannot tell some constant `H`
//!   from zero (a singular `Theta`; the pseudo-inverse then leaves that part
//!   as `C` does) is not exact for it. Measured (2026-11-23, scratch probes,
//!   not kept): a first-level green next to a flipped corner square (the
//!   case `adapt/red_green/mesh.rs` now avoids) has `Theta` with singular
//!   values 0.113 m, 0.094 m and 0 (folds per unit curvature, 1 m sheet),
//!   null direction 0.555 xx - 0.832 xy, so it is blind to part of a bend
//!   along x (0.905 of the continuum's energy for the cylinder about y); with
//!   the square as split its null direction is pure twist. On the 8 x 8
//!   sheet refined one red level over `x < b1` and a second over `x < b2`,
//!   for `(b1, b2)` = (-0.15, -0.3), (-0.1, -0.2) and (0.1, -0.05), 6, 8 and
//!   6 (triangle, shape) pairs were more than 5 % from the continuum over
//!   the four shapes of `partly_refined_sheet_bends_like_the_continuum`
//!   (worst |ratio - 1| 0.0947), with red-green's children as split and with
//!   alternating diagonals alike; (0, -0.25) had none. Which triangles they
//!   are and whether their `Theta` is singular was not checked. Reading a
//!   fourth fold (a neighbour's) where `Theta` is singular might fix it; not
//!   done.
//! * `sum_t A_t S_t` is no longer exactly the distributional Hessian across a
//!   transition rim, so the Jensen argument above holds in the uniform parts
//!   only; in the rim each triangle is instead exact for constant curvature,
//!   and `P` has full rank (no fold pattern is free there).
//! * The exact operator everywhere would change uniform meshes: on the
//!   alternating grid `C` is exact for `H` diagonal in the grid axes but not
//!   for twist (`xy`: 2.00 times the continuum, a cylinder at 45 deg 1.50),
//!   which the exact operator would make 1.00. Transition triangles get 1.00
//!   for those, except greens blind to twist (0.50 on the straight band).
//! * Triangles with a boundary edge keep `C`: taking the boundary's fold as a
//!   zero row of `Theta` fixes some (a green on the straight band, bent along
//!   the band, 1.56 -> 1.00) but makes the operator read curvature across the
//!   free edge from the other two folds (a red one, cylinder about x, 1.000 ->
//!   0.965), against the zero-moment condition below.
//!
//! Boundary edges have no angle, so an imposed curvature across a free edge loses
//! the outer half row of triangles' share (the `1 - 1/n` of the cylinder test).
//! At a free edge the plate's natural boundary condition is zero moment, so a
//! settled sheet has no curvature across it there, and no energy is lost.

use super::bending::dihedral_angle_and_gradient;
use crate::math::{Matrix3, Scalar, Vector, Vector2};
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
    let mut across = vec![[usize::MAX; 3]; mesh.triangles.len()];
    for e in mesh.edges.iter().filter(|e| e.is_interior()) {
        for (side, other) in [(0, 1), (1, 0)] {
            let (t, o) = (e.triangles[side] as usize, e.triangles[other]);
            let tri = mesh.triangles[t];
            let a = (0..3)
                .find(|&a| !e.vertices.contains(&tri[a]))
                .expect("an edge's triangle has a vertex off the edge");
            out[t].v[3 + a] = mesh.opposite_vertex(o, e);
            out[t].interior[a] = true;
            across[t][a] = o as usize;
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
    // Refinement transitions (module docs, "Transitions"): a triangle with all
    // three edges interior next to a free triangle of another level.
    for (t, st) in out.iter_mut().enumerate() {
        let o = across[t];
        let transition = o.iter().all(|&o| o != usize::MAX)
            && o.iter()
                .any(|&o| !held(o) && mesh.levels[o] != mesh.levels[t]);
        if transition && !held(t) {
            st.m = transition_m(mesh, t, o, o.map(held), share[t], area[t], bending);
        }
    }
    (0..out.len())
        .filter(|&t| !held(t))
        .map(|t| out[t])
        .collect()
}

/// A symmetric 2 x 2 tensor as `[xx, yy, xy]`.
type Sym = [Scalar; 3];

/// The 3 x 3 matrix with these rows (glam's matrices are built from columns).
fn from_rows(rows: [[Scalar; 3]; 3]) -> Matrix3 {
    Matrix3::from_cols_array_2d(&rows).transpose()
}

/// Pseudo-inverse of `a` (regularised: `(a^T a + eps I)^-1 a^T` with `eps`
/// 1e-9 of the trace), so that directions `a` does not see (or barely sees) are
/// left alone rather than amplified.
fn pseudo_inverse(a: Matrix3) -> Matrix3 {
    let g = a.transpose() * a;
    let eps = 1e-9 * (g.x_axis.x + g.y_axis.y + g.z_axis.z);
    (g + Matrix3::from_diagonal(Vector::splat(eps))).inverse() * a.transpose()
}

/// `M` of a transition triangle (module docs, "Transitions"): the shape operator
/// `S = P theta` with `P = C + (I - C Theta) Theta^+`, where `C` is the shared-fold
/// operator of the other triangles and `Theta` maps a constant curvature tensor
/// to the three folds the triangle and its neighbours `across` give it; then
/// `M = B A P^T W P` with `W = diag(1, 1, 2)` (the Frobenius norm of `[xx, yy, xy]`).
fn transition_m(
    mesh: &Mesh,
    t: usize,
    across: [usize; 3],
    held: [bool; 3],
    share: [Scalar; 3],
    area: Scalar,
    bending: Scalar,
) -> [[Scalar; 3]; 3] {
    let corners = |t: usize| mesh.triangles[t].map(|v| mesh.material[v as usize]);
    let p = corners(t);
    let origin = (p[0] + p[1] + p[2]) / 3.0;
    let local = |q: [Vector2; 3]| q.map(|v| v - origin);
    let p = local(p);
    let e: [Vector2; 3] = [0, 1, 2].map(|a| p[(a + 2) % 3] - p[(a + 1) % 3]);
    // Outward in-plane unit normals (the triangle is counter-clockwise).
    let n = e.map(|v| Vector2::new(v.y, -v.x) / v.length());
    // C: S = C theta.
    let mut c = [[0.0; 3]; 3];
    for a in 0..3 {
        let q: Sym = [n[a].x * n[a].x, n[a].y * n[a].y, n[a].x * n[a].y];
        for k in 0..3 {
            c[k][a] = share[a] * e[a].length() * q[k] / (2.0 * area);
        }
    }
    // Theta: the folds of the linear interpolant of f = x^T H x / 2 for the
    // three unit tensors H; a held neighbour keeps the tangent plane of f at the
    // edge's midpoint (the clamp is flat where the free sheet leaves it).
    let hx = |h: Sym, x: Vector2| Vector2::new(h[0] * x.x + h[2] * x.y, h[2] * x.x + h[1] * x.y);
    let grad = |q: [Vector2; 3], h: Sym| {
        let f = q.map(|x| 0.5 * x.dot(hx(h, x)));
        let (d1, d2) = (q[1] - q[0], q[2] - q[0]);
        let (f1, f2) = (f[1] - f[0], f[2] - f[0]);
        let det = d1.perp_dot(d2);
        Vector2::new(f1 * d2.y - f2 * d1.y, d1.x * f2 - d2.x * f1) / det
    };
    let mut theta = [[0.0; 3]; 3];
    for j in 0..3 {
        let mut h = [0.0; 3];
        h[j] = 1.0;
        let own = grad(p, h);
        for a in 0..3 {
            let other = if held[a] {
                hx(h, 0.5 * (p[(a + 1) % 3] + p[(a + 2) % 3]))
            } else {
                grad(local(corners(across[a])), h)
            };
            theta[a][j] = n[a].dot(other - own);
        }
    }
    let (c, theta) = (from_rows(c), from_rows(theta));
    let p = c + (Matrix3::IDENTITY - c * theta) * pseudo_inverse(theta);
    let w = Matrix3::from_diagonal(Vector::new(1.0, 1.0, 2.0));
    ((bending * area) * p.transpose() * w * p)
        .transpose()
        .to_cols_array_2d()
}
