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
//! `M_ab = (B / (4 A)) L_a L_b (t_a . t_b)^2` (constant, positive semi-definite),
//! here with each fold shared equally; "Splitting the folds" below frees the
//! share.
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
//! (Splitting by the heights over the shared edge, or by the centroids'
//! distances `h / 3` from it, is the same split: the edge is common, so the
//! heights are in proportion to the areas. Splitting by inradius was tried and
//! is worse: on the probe below, green triangles 1.325 and red ones 1.148 for
//! the cylinder about x, against 1.052 / 1.108 by area.)
//!
//! # Splitting the folds
//! Area shares fix the sizes, not the shapes: a triangle whose folds do not
//! cancel inside it (a green closure, any triangle of an irregular
//! triangulation: an OBJ cloth, a Delaunay mesh) keeps a residue for a
//! constant curvature, and by Jensen's inequality above the sheet is too
//! stiff, by a factor that does not fall with the cell size. Measured with
//! fixed shares on the cantilever with free vertices moved by up to 0.4 of a
//! cell: 1.6 to 2.7 deg stiff of the elastica at resolutions 16 to 32; on
//! transitions of two red-green levels single triangles carried up to 2.1
//! times the continuum's energy for a constant curvature.
//!
//! The fix is Morley's nonconforming plate element, whose degrees of freedom
//! are the vertex positions and one normal slope per edge midpoint: `S_t` is
//! the Hessian of the quadratic they define, `1/A sum_a L_a u_a n_a n_a^T`
//! with `u_a` the jump from the triangle's own slope to the edge's. With the
//! edge's slope between the two triangles' slopes, the two sides' `u` sum to
//! the fold, so each interior edge between two free triangles has one
//! unknown, its split `phi`: the triangle takes `share_a theta_a + phi` and
//! its neighbour `share_o theta_a - phi` (`split_sign` says which side adds).
//! `sum_t A_t S_t` is then still the distributional Hessian whatever the
//! splits, and the energy is
//! `E(x) = min_phi sum_t (1/2) u_t^T K_t u_t`, `K_ab = (B / A) L_a L_b (n_a . n_b)^2`.
//! It is quadratic in `phi` with a constant matrix, so the splits solve one
//! sparse symmetric positive definite system (module [`split`], factored once
//! per mesh) at every force evaluation, and by the envelope theorem the
//! forces are those at the optimal splits, per triangle:
//! `f = -sum_a share_a (K u)_a grad theta_a`. Morley's element converges on
//! general triangulations (it reproduces every quadratic exactly), where the
//! fixed shares do not.
//!
//! The implicit solvers keep the fixed-share Hessian `J^T M J`,
//! `M_ab = share_a share_b K_ab`: the energy at zero splits bounds the
//! minimised one from above, so it is a positive definite upper bound of the
//! exact Hessian (which couples every fold through the splits and has no
//! sparse form). The step's forces are exact; the Newton iterations converge
//! to the same state.
//! The direct solver's matrix, by default, keeps of `J^T M J` only the
//! blocks between the ends of mesh edges and lumps the others on the
//! diagonal, a positive semi-definite addition
//! (`kinds/shapes/blocks.rs`, "The first-ring matrix").
//!
//! Clamp edges keep no split (the free triangle takes the whole fold, as
//! above); free edges of the cloth have one of their own (below).
//!
//! The cost is the sparse solve between the angles and the forces at every
//! force evaluation (the angles and their gradients are computed once and
//! kept for the forces), which weighs most on explicit integrators (four
//! evaluations per RK4 step). It has not been timed on a quiet machine.
//!
//! Measured (`tests/integration/elastica_irregular.rs`, chord angle against
//! the elastica, free edges' parts free, below): free vertices moved by up
//! to 0.4 of a cell +0.12 / -0.07 / -0.13 deg at resolutions 16 / 32 / 64
//! (fixed shares: -1.56 / -2.73 at 16 / 32); a constrained Delaunay strip
//! -0.07 / +0.01 / +0.01 deg; adapted from either at resolution 8,
//! red-green +0.10 / +0.08 deg and the edge method -0.41 / -0.14 deg. Small
//! deflection on the irregular strips: tip drop within 0.5 % of the
//! elastica at 16 and 32. Red-green transitions two levels deep
//! store the unrefined sheet's energy to 0.0006 for constant curvatures
//! (test `second_level_transitions_bend_like_the_unrefined_sheet`).
//!
//! # Thin triangles
//! A triangle with a small corner has two nearly parallel edges whose
//! `n n^T` nearly coincide, so `K` is nearly singular in the difference of
//! their parts, and free splits on those edges let it soak up curvature at
//! almost no cost: measured, the tensor method's strip (cells of aspect 8:1)
//! settled 0.93 deg soft of the elastica, against 0.04 with fixed shares, and
//! a strip of 4:1 cells 0.21 deg soft. Morley's element converges only on
//! shape-regular meshes. So an edge takes a split only when both its
//! triangles (a free edge: its one) have every corner at least
//! [`SPLIT_MIN_ANGLE_DEG`] (15 deg):
//! the 4:1 cells' 14 deg corners keep fixed shares (exact there, for bends
//! along the cells), red-green's green closures (18.4 deg) take splits. The
//! limit was chosen between those two measured cases (20 deg left the greens
//! with fixed shares, 6 to 10 % stiff on transitions).
//!
//! # Free edges
//! A free edge of the cloth has no fold, and Morley's element leaves its
//! midpoint slope free: the edge has a split unknown of its own, the one
//! triangle's whole part (`share` zero), which the minimisation sets to the
//! plate's natural boundary condition. Held at zero instead, it forces the
//! triangle's curvature into the span of its other two edges' `n n^T`: a
//! triangle whose longest edge lies on a free side (the edge method's
//! bisections make them) cannot then bend along that side without bending
//! across it as much, and the strip is too stiff. Measured on the
//! cantilever adapted by the edge method from resolution 8: -2.31 deg from
//! a regular grid, -2.93 / -1.79 deg from the jittered / Delaunay strips
//! with the part held at zero; -0.65 / -0.41 / -0.14 deg with it free.

mod build;
mod folds;
mod split;

pub use build::SPLIT_MIN_ANGLE_DEG;
pub(crate) use build::{ShapeMatrix, ShapeScratch, build_shape_triangles_into};
pub use folds::{EdgeFold, FoldEdges};
pub use split::{FoldSplits, SplitError};

use super::bending::{dihedral_angle, dihedral_angle_and_gradient};
use crate::math::{Scalar, Vector};

/// Vertex slots of a shape triangle: its three vertices, then the tips across
/// edges 0, 1, 2.
pub const SHAPE_SLOTS: usize = 6;

/// Slots of the hinge of edge `a` in the order of [`dihedral_angle_and_gradient`]:
/// the edge (counter-clockwise in the triangle), the triangle's own opposite
/// vertex, the tip across.
const HINGE_SLOTS: [[usize; 4]; 3] = [[1, 2, 0, 3], [2, 0, 1, 4], [0, 1, 2, 5]];

/// Marks an edge of a shape triangle without a split unknown (module docs,
/// "Splitting the folds").
pub const NO_SPLIT: u32 = u32::MAX;

/// One triangle's bending element (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeTriangle {
    /// Vertices: the triangle's three (counter-clockwise in material space), then
    /// the tips across edges 0, 1, 2 (edge `a` is opposite vertex `a`); a boundary
    /// edge's tip slot repeats vertex `a` and is unused.
    pub v: [u32; SHAPE_SLOTS],
    /// Which edges are interior (have an angle).
    pub interior: [bool; 3],
    /// The constant matrix `M` of the fixed-share energy `theta^T M theta / 2`,
    /// N m: the approximate Hessian the implicit solvers use.
    pub m: [[Scalar; 3]; 3],
    /// The plate matrix `K` of `E = u^T K u / 2` in the triangle's parts `u` of
    /// its three folds, N m: `K_ab = (B / A) L_a L_b (n_a . n_b)^2`.
    pub k: [[Scalar; 3]; 3],
    /// The fixed part of each fold the triangle takes (one half on a uniform
    /// mesh, all of it next to a clamp, zero on a boundary edge).
    pub share: [Scalar; 3],
    /// Per edge, its split unknown ([`NO_SPLIT`]: none).
    pub split: [u32; 3],
    /// Per edge, the sign with which the split adds to this side's part (the
    /// other side subtracts it).
    pub split_sign: [Scalar; 3],
}

/// Angles of a shape triangle's edges and their gradients by slot.
pub type ShapeJacobian = [[Vector; SHAPE_SLOTS]; 3];

impl ShapeTriangle {
    /// The used slots with their vertices.
    pub fn slots(&self) -> impl Iterator<Item = (usize, u32)> + Clone + '_ {
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

    /// The three edge angles alone (zero on boundary edges).
    #[inline(always)]
    pub fn folds(&self, x: &[Vector]) -> [Scalar; 3] {
        [0, 1, 2].map(|a| {
            if self.interior[a] {
                dihedral_angle(HINGE_SLOTS[a].map(|k| x[self.v[k] as usize]))
            } else {
                0.0
            }
        })
    }

    /// The triangle's parts `u` of its folds `theta` given the split unknowns.
    #[inline(always)]
    pub fn parts(&self, theta: [Scalar; 3], splits: &[Scalar]) -> [Scalar; 3] {
        [0, 1, 2].map(|a| {
            let split = match self.split[a] {
                NO_SPLIT => 0.0,
                s => self.split_sign[a] * splits[s as usize],
            };
            self.share[a] * theta[a] + split
        })
    }

    /// `K u`.
    #[inline(always)]
    pub fn times_k(&self, u: [Scalar; 3]) -> [Scalar; 3] {
        [0, 1, 2].map(|a| (0..3).map(|b| self.k[a][b] * u[b]).sum())
    }

    /// `dE / d theta` at fixed splits: `share_a (K u)_a`, N m.
    #[inline(always)]
    pub fn moments(&self, theta: [Scalar; 3], splits: &[Scalar]) -> [Scalar; 3] {
        let ku = self.times_k(self.parts(theta, splits));
        [0, 1, 2].map(|a| self.share[a] * ku[a])
    }

    /// `M y`.
    #[inline(always)]
    pub fn times_m(&self, y: [Scalar; 3]) -> [Scalar; 3] {
        [0, 1, 2].map(|a| (0..3).map(|b| self.m[a][b] * y[b]).sum())
    }

    /// Elastic energy at positions `x` with the split unknowns `splits`, J.
    pub fn energy(&self, x: &[Vector], splits: &[Scalar]) -> Scalar {
        let u = self.parts(self.folds(x), splits);
        let ku = self.times_k(u);
        0.5 * (0..3).map(|a| u[a] * ku[a]).sum::<Scalar>()
    }

    /// Forces `-sum_a (dE / d theta_a) grad theta_a` by slot, into `out[..6]`,
    /// with the split unknowns `splits` (at their optimum these are the forces
    /// of the energy minimised over the splits).
    #[inline(always)]
    pub fn forces(&self, x: &[Vector], splits: &[Scalar], out: &mut [Vector]) {
        let (theta, jac) = self.angles(x);
        spread(&jac, self.moments(theta, splits).map(|c| -c), out);
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
