//! The continuum membrane (`material.membrane = "triangles"`): constant-strain
//! triangles in material coordinates with a linear orthotropic St. Venant-Kirchhoff
//! law, warp along u, weft along v.
//!
//! # The element
//! Triangle `t` with rest corners `p_i = (u_i, v_i)` and rest area `A`. The linear
//! shape functions `N_i` have constant gradients `(du_i, dv_i) = grad N_i`, so the
//! deformation gradient's two columns are
//! `a = dx/du = sum_i du_i x_i` and `b = dx/dv = sum_i dv_i x_i`,
//! and the Green strain `E = (F^T F - I) / 2` has
//! `E_uu = (a.a - 1) / 2`, `E_vv = (b.b - 1) / 2`, `g = 2 E_uv = a.b`.
//! The energy per rest area, N/m (J/m^2), with Poisson ratio 0 like the bending
//! plate (`shape.rs`):
//! `W = (warp E_uu^2 + weft E_vv^2 + shear g^2) / 2`.
//! `warp` and `weft` are the tensile stiffnesses of a strip pulled along u and
//! along v (force per width per unit strain, N/m: what a textile tensile test
//! gives), `shear` the in-plane shear stiffness (force per width per unit shear
//! angle, N/m). The element's energy is `A W`, its forces `-grad (A W)`.
//!
//! # Why St. Venant-Kirchhoff, not Baraff and Witkin's conditions
//! Baraff and Witkin's stretch condition `C = A (|a| - 1, |b| - 1)` and shear
//! condition `A a.b` are the same three measures with `|a| - 1` in place of
//! `E_uu` (they agree to first order). Both are exact for any homogeneous
//! strain on any triangulation (the patch test), both are orthotropic in the
//! same axes. St. Venant-Kirchhoff is chosen because its energy is a
//! polynomial of the positions: its gradient and Hessian have no `1/|a|`
//! (which blows up for a triangle crushed to a line, where the implicit solver
//! needs a bounded matrix), and its stress is the second Piola-Kirchhoff
//! tensor of a named material law with moduli a lab can measure. The price is
//! the known softening of St. Venant-Kirchhoff under strong compression (a
//! triangle can invert at a finite force); cloth buckles out of plane long
//! before, and the bending elements hold it there.
//!
//! # Stress, forces and the Hessian
//! With the stress `tau = (warp E_uu, weft E_vv, shear g)`,
//! `dW/da = tau_uu a + tau_uv b`, `dW/db = tau_vv b + tau_uv a`, and vertex `i`
//! gets `f_i = -A (du_i dW/da + dv_i dW/db)`.
//! The Hessian in `(a, b)` is the Gauss-Newton part `J^T C J` (`C` the
//! diagonal of the three moduli, `J` the gradients of `(E_uu, E_vv, g)`):
//! `H_aa = warp a a^T + shear b b^T`, `H_bb = weft b b^T + shear a a^T`,
//! `H_ab = shear b a^T`, plus the geometric part `S (x) I_3` with
//! `S = [[tau_uu, tau_uv], [tau_uv, tau_vv]]` (the second Piola-Kirchhoff
//! stress). Under compression `S` has a negative eigenvalue and the Hessian
//! is indefinite; the implicit solver gets `J^T C J + S+ (x) I_3`, `S+` the
//! positive part of the 2 x 2 `S` (its negative eigenvalues set to zero). It
//! is the exact Hessian wherever the triangle is in tension, and the analogue
//! of the springs' transverse term clamped at zero under compression.
//!
//! # Damping
//! Stiffness proportional like the springs': the viscous stress is
//! `damping * C * dr/dt` for the strain rates `dr/dt = J v`, so the damping
//! force is `-damping * A J^T C J v` (the Gauss-Newton stiffness times the
//! velocities) and a rigid motion, whose strain rate is zero, is not damped.
//!
//! # The isotropic shorthand
//! `stretch` alone gives `warp = weft = stretch` and
//! `shear = stretch * ISOTROPIC_SHEAR_RATIO`: the shear modulus of an isotropic
//! sheet with Poisson ratio 0 (`G = Y / (2 (1 + nu))`), the same ratio the
//! bending plate uses.

use crate::math::{Matrix3, Scalar, Vector, Vector2};

/// `shear / stretch` when only `stretch` is given: the isotropic sheet with
/// Poisson ratio 0 (`G = Y / 2`).
pub const ISOTROPIC_SHEAR_RATIO: Scalar = 0.5;

/// Vertex slots of a membrane triangle (its three corners).
pub const MEMBRANE_SLOTS: usize = 3;

/// The orthotropic moduli of the continuum membrane, N/m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orthotropic {
    /// Tensile stiffness along material u (warp), N/m.
    pub warp: Scalar,
    /// Tensile stiffness along material v (weft), N/m.
    pub weft: Scalar,
    /// In-plane shear stiffness, N/m.
    pub shear: Scalar,
}

impl Orthotropic {
    /// The isotropic sheet of stiffness `stretch` (module docs: the shorthand).
    pub fn isotropic(stretch: Scalar) -> Orthotropic {
        Orthotropic {
            warp: stretch,
            weft: stretch,
            shear: stretch * ISOTROPIC_SHEAR_RATIO,
        }
    }

    /// The energy per rest area of the homogeneous deformation gradient with
    /// columns `a = dx/du` and `b = dx/dv`, J/m^2.
    pub fn energy_density(&self, a: Vector, b: Vector) -> Scalar {
        let [euu, evv, g] = green_strain(a, b);
        0.5 * (self.warp * euu * euu + self.weft * evv * evv + self.shear * g * g)
    }

    /// The first Piola-Kirchhoff stress `[dW/da, dW/db]` of the homogeneous
    /// deformation gradient with columns `a` and `b`, N/m.
    pub fn first_piola(&self, a: Vector, b: Vector) -> [Vector; 2] {
        let [euu, evv, g] = green_strain(a, b);
        let tau = [self.warp * euu, self.weft * evv, self.shear * g];
        [a * tau[0] + b * tau[2], b * tau[1] + a * tau[2]]
    }
}

/// The in-plane force model of the cloth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Membrane {
    /// One spring per edge from `stretch` (the papers' model, see `elements.rs`).
    Springs,
    /// Constant-strain triangles with these moduli (module docs).
    Triangles(Orthotropic),
}

/// `(E_uu, E_vv, 2 E_uv)` of the deformation gradient with columns `a`, `b`.
#[inline(always)]
pub fn green_strain(a: Vector, b: Vector) -> [Scalar; 3] {
    [0.5 * (a.dot(a) - 1.0), 0.5 * (b.dot(b) - 1.0), a.dot(b)]
}

/// A symmetric 6 x 6 matrix over the deformation gradient's columns `(a, b)`, as
/// its three distinct 3 x 3 blocks (`ba` is `ab` transposed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColumnBlocks {
    /// `d^2 / da da`.
    pub aa: Matrix3,
    /// `d^2 / da db` (rows: a, columns: b).
    pub ab: Matrix3,
    /// `d^2 / db db`.
    pub bb: Matrix3,
}

impl ColumnBlocks {
    /// All zero.
    pub const ZERO: ColumnBlocks = ColumnBlocks {
        aa: Matrix3::ZERO,
        ab: Matrix3::ZERO,
        bb: Matrix3::ZERO,
    };

    /// `self * s + other * t`.
    #[inline(always)]
    pub fn combine(&self, s: Scalar, other: &ColumnBlocks, t: Scalar) -> ColumnBlocks {
        ColumnBlocks {
            aa: self.aa * s + other.aa * t,
            ab: self.ab * s + other.ab * t,
            bb: self.bb * s + other.bb * t,
        }
    }
}

/// One constant-strain membrane triangle (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MembraneTriangle {
    /// The triangle's vertices (counter-clockwise in material space).
    pub v: [u32; 3],
    /// `dN_i/du` of the three shape functions, 1/m.
    pub du: [Scalar; 3],
    /// `dN_i/dv` of the three shape functions, 1/m.
    pub dv: [Scalar; 3],
    /// Rest area times warp, weft and shear stiffness, N m.
    pub k: [Scalar; 3],
    /// Stiffness-proportional damping, s.
    pub damping: Scalar,
}

impl MembraneTriangle {
    /// The element of the rest triangle with corners `p` (counter-clockwise,
    /// positive area `area`).
    pub fn new(
        v: [u32; 3],
        p: [Vector2; 3],
        area: Scalar,
        moduli: &Orthotropic,
        damping: Scalar,
    ) -> MembraneTriangle {
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let det = e1.perp_dot(e2);
        // Rows of the inverse of [e1 e2]: d(barycentric 1, 2)/d(u, v).
        let (g1, g2) = (
            Vector2::new(e2.y, -e2.x) / det,
            Vector2::new(-e1.y, e1.x) / det,
        );
        MembraneTriangle {
            v,
            du: [-g1.x - g2.x, g1.x, g2.x],
            dv: [-g1.y - g2.y, g1.y, g2.y],
            k: [moduli.warp, moduli.weft, moduli.shear].map(|m| m * area),
            damping,
        }
    }

    /// The deformation gradient's columns `(a, b)` for the vectors `x` (positions,
    /// or velocities for their rates).
    #[inline(always)]
    pub fn columns(&self, x: &[Vector]) -> (Vector, Vector) {
        let p = self.v.map(|i| x[i as usize]);
        (
            p[0] * self.du[0] + p[1] * self.du[1] + p[2] * self.du[2],
            p[0] * self.dv[0] + p[1] * self.dv[1] + p[2] * self.dv[2],
        )
    }

    /// Elastic energy at positions `x`, J.
    pub fn energy(&self, x: &[Vector]) -> Scalar {
        let (a, b) = self.columns(x);
        let [euu, evv, g] = green_strain(a, b);
        0.5 * (self.k[0] * euu * euu + self.k[1] * evv * evv + self.k[2] * g * g)
    }

    /// `out[i] = du_i ga + dv_i gb`: a vector over `(a, b)` taken back to the
    /// three corners (the transpose of [`MembraneTriangle::columns`]).
    #[inline(always)]
    pub fn spread(&self, ga: Vector, gb: Vector, out: &mut [Vector]) {
        for (i, o) in out.iter_mut().enumerate().take(MEMBRANE_SLOTS) {
            *o = ga * self.du[i] + gb * self.dv[i];
        }
    }

    /// Elastic and damping forces by corner at positions `x` and velocities `vel`,
    /// into `out[..3]`.
    #[inline(always)]
    pub fn forces(&self, x: &[Vector], vel: &[Vector], out: &mut [Vector]) {
        let (a, b) = self.columns(x);
        let [euu, evv, g] = green_strain(a, b);
        let mut r = [euu, evv, g];
        if self.damping > 0.0 {
            let (da, db) = self.columns(vel);
            let rate = [a.dot(da), b.dot(db), a.dot(db) + b.dot(da)];
            for (r, rate) in r.iter_mut().zip(rate) {
                *r += self.damping * rate;
            }
        }
        let tau = [0, 1, 2].map(|c| self.k[c] * r[c]);
        self.spread(-(a * tau[0] + b * tau[2]), -(b * tau[1] + a * tau[2]), out);
    }

    /// The stiffness at positions `x` over `(a, b)`, with the rest area: the
    /// Gauss-Newton part `A J^T C J` and the geometric part `A S+ (x) I`
    /// (module docs), both positive semi-definite.
    #[inline(always)]
    pub fn stiffness(&self, x: &[Vector]) -> (ColumnBlocks, ColumnBlocks) {
        let (a, b) = self.columns(x);
        let [euu, evv, g] = green_strain(a, b);
        let [kw, kf, ks] = self.k;
        let (aat, bbt) = (outer(a, a), outer(b, b));
        let gauss_newton = ColumnBlocks {
            aa: aat * kw + bbt * ks,
            ab: outer(b, a) * ks,
            bb: bbt * kf + aat * ks,
        };
        let [s00, s01, s11] = positive_part([kw * euu, ks * g, kf * evv]);
        let geometric = ColumnBlocks {
            aa: Matrix3::from_diagonal(Vector::splat(s00)),
            ab: Matrix3::from_diagonal(Vector::splat(s01)),
            bb: Matrix3::from_diagonal(Vector::splat(s11)),
        };
        (gauss_newton, geometric)
    }

    /// The corner block `(i, j)` of the matrix whose column form is `m`:
    /// `du_i du_j aa + du_i dv_j ab + dv_i du_j ab^T + dv_i dv_j bb`.
    #[inline(always)]
    pub fn block(&self, m: &ColumnBlocks, i: usize, j: usize) -> Matrix3 {
        let (ui, vi, uj, vj) = (self.du[i], self.dv[i], self.du[j], self.dv[j]);
        m.aa * (ui * uj) + m.ab * (ui * vj) + m.ab.transpose() * (vi * uj) + m.bb * (vi * vj)
    }

    /// `out[i] = sum_j block(i, j) p_j`, computed through the columns.
    #[inline(always)]
    pub fn apply(&self, m: &ColumnBlocks, p: &[Vector], out: &mut [Vector]) {
        let (pa, pb) = self.columns(p);
        let ga = m.aa * pa + m.ab * pb;
        let gb = m.ab.transpose() * pa + m.bb * pb;
        self.spread(ga, gb, out);
    }
}

/// The positive semi-definite part of the symmetric 2 x 2 matrix
/// `[[s00, s01], [s01, s11]]` (negative eigenvalues set to zero), as
/// `[s00, s01, s11]`.
#[inline(always)]
pub fn positive_part([s00, s01, s11]: [Scalar; 3]) -> [Scalar; 3] {
    let mean = 0.5 * (s00 + s11);
    let half = 0.5 * (s00 - s11);
    let radius = (half * half + s01 * s01).sqrt();
    let (hi, lo) = (mean + radius, mean - radius);
    if lo >= 0.0 {
        return [s00, s01, s11];
    }
    if hi <= 0.0 {
        return [0.0; 3];
    }
    // hi e e^T with e the unit eigenvector of hi: (s01, hi - s00) or
    // (hi - s11, s01), whichever is longer.
    let (p, q) = (Vector2::new(s01, hi - s00), Vector2::new(hi - s11, s01));
    let e = if p.length_squared() >= q.length_squared() {
        p
    } else {
        q
    };
    let e = e / e.length();
    [hi * e.x * e.x, hi * e.x * e.y, hi * e.y * e.y]
}

/// The outer product `a b^T`.
#[inline(always)]
fn outer(a: Vector, b: Vector) -> Matrix3 {
    Matrix3::from_cols(a * b.x, a * b.y, a * b.z)
}
