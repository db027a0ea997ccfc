//! The signed dihedral angle of a hinge and its exact gradient.
//!
//! Hinge vertices `[a, b, p, q]`: the edge runs a -> b counter-clockwise in the
//! first triangle `(a, b, p)`; the second triangle is `(b, a, q)`. With the
//! normals `n0 = (b - a) x (p - a)` and `n1 = (a - b) x (q - b)` and the unit
//! edge `e`, the angle is `theta = atan2((n0^ x n1^) . e, n0^ . n1^)`: zero when
//! flat, smooth through zero, and it wraps only when the hinge folds completely.
//!
//! Gradient (Bridson et al. 2003; Tamstorf and Grinspun 2013). Moving a wing tip
//! along its triangle's normal turns that triangle about the edge at the rate
//! `1 / h` (h the tip's height over the edge), and both tips lifted along their
//! normals decrease theta, so
//! `d theta / d p = -n0^ / h0`, `d theta / d q = -n1^ / h1`.
//! The edge vertices take the rest so that translations and rotations leave theta
//! unchanged: with `alpha`, `beta` the positions of p and q projected on the edge
//! (0 at a, 1 at b), `d theta / d a = -(1 - alpha) g_p - (1 - beta) g_q` and
//! `d theta / d b = -alpha g_p - beta g_q`. The unit test checks all twelve
//! components against finite differences.

use crate::math::{Scalar, Vector};

/// Signed dihedral angle (radians) and its gradient with respect to `[a, b, p, q]`.
/// A degenerate hinge (a wing of zero area) gives zero angle and gradient.
#[inline(always)]
pub fn dihedral_angle_and_gradient(x: [Vector; 4]) -> (Scalar, [Vector; 4]) {
    let [a, b, p, q] = x;
    let e = b - a;
    let e_len2 = e.length_squared();
    let n0 = e.cross(p - a);
    let n1 = (a - b).cross(q - b);
    let (n0_len2, n1_len2) = (n0.length_squared(), n1.length_squared());
    if e_len2 <= 0.0 || n0_len2 <= 1e-300 || n1_len2 <= 1e-300 {
        return (0.0, [Vector::ZERO; 4]);
    }
    let e_len = e_len2.sqrt();
    let (n0_len, n1_len) = (n0_len2.sqrt(), n1_len2.sqrt());
    let (u0, u1) = (n0 / n0_len, n1 / n1_len);
    let theta = u0.cross(u1).dot(e / e_len).atan2(u0.dot(u1));
    // Heights over the edge: h = |n| / |e|, so n^ / h = n |e| / |n|^2.
    let gp = -n0 * (e_len / n0_len2);
    let gq = -n1 * (e_len / n1_len2);
    let alpha = (p - a).dot(e) / e_len2;
    let beta = (q - a).dot(e) / e_len2;
    let ga = -(1.0 - alpha) * gp - (1.0 - beta) * gq;
    let gb = -alpha * gp - beta * gq;
    (theta, [ga, gb, gp, gq])
}

/// The signed dihedral angle alone (radians), equal to
/// [`dihedral_angle_and_gradient`]'s.
#[inline(always)]
pub fn dihedral_angle(x: [Vector; 4]) -> Scalar {
    let [a, b, p, q] = x;
    let e = b - a;
    let e_len2 = e.length_squared();
    let n0 = e.cross(p - a);
    let n1 = (a - b).cross(q - b);
    let (n0_len2, n1_len2) = (n0.length_squared(), n1.length_squared());
    if e_len2 <= 0.0 || n0_len2 <= 1e-300 || n1_len2 <= 1e-300 {
        return 0.0;
    }
    let (u0, u1) = (n0 / n0_len2.sqrt(), n1 / n1_len2.sqrt());
    u0.cross(u1).dot(e / e_len2.sqrt()).atan2(u0.dot(u1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradient_matches_finite_differences() {
        let x = [
            Vector::new(0.1, -0.05, 0.02),
            Vector::new(1.0, 0.1, -0.1),
            Vector::new(0.4, 0.9, 0.3),
            Vector::new(0.6, -0.8, 0.25),
        ];
        let (theta, grad) = dihedral_angle_and_gradient(x);
        assert!(theta.abs() > 0.1, "test hinge should be bent: {theta}");
        let h = 1e-6;
        for v in 0..4 {
            for d in 0..3 {
                let mut xp = x;
                let mut xm = x;
                xp[v][d] += h;
                xm[v][d] -= h;
                let fd = (dihedral_angle_and_gradient(xp).0 - dihedral_angle_and_gradient(xm).0)
                    / (2.0 * h);
                assert!(
                    (fd - grad[v][d]).abs() < 1e-6,
                    "vertex {v} dim {d}: fd {fd} vs {}",
                    grad[v][d]
                );
            }
        }
    }

    #[test]
    fn flat_hinge_has_zero_angle() {
        let x = [
            Vector::ZERO,
            Vector::X,
            Vector::new(0.5, 1.0, 0.0),
            Vector::new(0.5, -1.0, 0.0),
        ];
        assert_eq!(dihedral_angle_and_gradient(x).0, 0.0);
    }
}
