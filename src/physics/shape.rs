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
//!   as `C` does) is not exact for it. For example, a first-level green next
//!   to a flipped corner square (the
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
//!   alternating diagonals alike; (0, -0.25) had none. On the four meshes of
//!   the test `second_level_transitions_bend_within_ten_percent_of_the_continuum`
//!   (among them `(b1, b2)` = (0, -0.3)), every triangle more than 5 % off is
//!   a second-level (level 3) green
//!   beside a level-4 triangle where the second level's rim runs along y,
//!   each at 0.905 / 1.000 / 0.953 / 0.953 for the four shapes, and its
//!   `Theta` is singular the same way (singular values 0.0563 m, 0.0469 m, 0;
//!   null direction 0.555 xx - 0.832 xy); rims along x and round ones have
//!   none. Of those meshes' 1,320 transition operators (four meshes, both
//!   diagonal settings) 116 had a
//!   singular `Theta`: 96 blind to twist only, these 20 to part of a bend.
//!   Reading a fourth fold (a neighbour's) where `Theta` is singular might fix
//!   it; not done (it needs a seventh and eighth slot in the element).
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
//! * Irregular triangulations (an OBJ cloth, bisection in a metric) are not
//!   exact: a triangle whose folds do not cancel inside it carries a residue
//!   for a constant curvature, so by Jensen the sheet is too stiff, by a
//!   factor that does not fall with the cell size. Measured on the
//!   cantilever with free vertices moved up to a quarter cell: 1.1 to 1.2 deg
//!   stiff of the elastica, 1.7 to 1.8 deg at 0.3 cell and 64 cells along;
//!   `P` on every interior triangle overshoots to 0.3 to 0.9 deg soft (3.5
//!   to 5.1 deg on thin cells). The test
//!   `elastica::an_irregular_strip_bends_stiffer_than_the_elastica` pins it.
//!
//! Boundary edges have no angle, so an imposed curvature across a free edge loses
//! the outer half row of triangles' share (the `1 - 1/n` of the cylinder test).
//! At a free edge the plate's natural boundary condition is zero moment, so a
//! settled sheet has no curvature across it there, and no energy is lost.

mod build;

pub(crate) use build::{ShapeMatrix, ShapeScratch, build_shape_triangles_into};

use super::bending::dihedral_angle_and_gradient;
use crate::math::{Scalar, Vector};

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
