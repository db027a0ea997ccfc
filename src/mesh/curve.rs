//! Points along a panel side, straight or curved ([`Curve`]), equally spaced
//! by arc length, and the side's length.
//!
//! A Bézier curve's arc length is measured on a fine polyline of
//! [`CURVE_STEPS`] pieces, and a point at a given length is the curve's own
//! point at the parameter interpolated there. An arc is an SVG arc (endpoint
//! parametrisation, rotation 0) and is sampled at equal angles, which are
//! equal lengths.

use std::f64::consts::TAU;

use crate::math::{Scalar, Vector2};
use crate::spec::Curve;

/// Pieces of the polyline a Bézier side's length is measured on.
pub const CURVE_STEPS: usize = 512;

/// The length of the side from `a` to `b` along `curve` (straight without one), m.
pub fn side_length(curve: Option<&Curve>, a: Vector2, b: Vector2) -> Scalar {
    match curve {
        None => a.distance(b),
        Some(Curve::Arc {
            radius,
            large_arc,
            counter_clockwise,
        }) => {
            let arc = Arc::new(a, b, *radius, *large_arc, *counter_clockwise);
            arc.radius * arc.sweep.abs()
        }
        Some(c) => *cumulative(c, a, b).last().unwrap_or(&0.0),
    }
}

/// `segments + 1` points from `a` to `b` along `curve` (straight without one),
/// equally spaced by arc length; the first is `a` and the last `b`, exactly.
pub fn side_points(curve: Option<&Curve>, a: Vector2, b: Vector2, segments: usize) -> Vec<Vector2> {
    let n = segments.max(1);
    let fraction = |k: usize| k as Scalar / n as Scalar;
    let mut points: Vec<Vector2> = match curve {
        None => (0..=n).map(|k| a + (b - a) * fraction(k)).collect(),
        Some(Curve::Arc {
            radius,
            large_arc,
            counter_clockwise,
        }) => {
            let arc = Arc::new(a, b, *radius, *large_arc, *counter_clockwise);
            (0..=n).map(|k| arc.at(fraction(k))).collect()
        }
        Some(c) => {
            let lengths = cumulative(c, a, b);
            let total = lengths[CURVE_STEPS];
            (0..=n)
                .map(|k| bezier(c, a, b, parameter_at(&lengths, total * fraction(k))))
                .collect()
        }
    };
    points[0] = a;
    points[n] = b;
    points
}

/// The cumulative lengths of the [`CURVE_STEPS`]-piece polyline of a Bézier side.
fn cumulative(c: &Curve, a: Vector2, b: Vector2) -> Vec<Scalar> {
    let mut lengths = Vec::with_capacity(CURVE_STEPS + 1);
    let mut total = 0.0;
    let mut previous = a;
    lengths.push(0.0);
    for k in 1..=CURVE_STEPS {
        let p = bezier(c, a, b, k as Scalar / CURVE_STEPS as Scalar);
        total += p.distance(previous);
        lengths.push(total);
        previous = p;
    }
    lengths
}

/// The parameter at which the polyline of `lengths` reaches `length`.
fn parameter_at(lengths: &[Scalar], length: Scalar) -> Scalar {
    let k = lengths
        .partition_point(|&l| l < length)
        .clamp(1, CURVE_STEPS);
    let (l0, l1) = (lengths[k - 1], lengths[k]);
    let within = if l1 > l0 {
        (length - l0) / (l1 - l0)
    } else {
        0.0
    };
    ((k - 1) as Scalar + within.clamp(0.0, 1.0)) / CURVE_STEPS as Scalar
}

/// The point at parameter `t` of a Bézier side (an arc is not one).
fn bezier(c: &Curve, a: Vector2, b: Vector2, t: Scalar) -> Vector2 {
    let s = 1.0 - t;
    match c {
        Curve::Quadratic { control } => {
            let p = Vector2::from_array(*control);
            a * (s * s) + p * (2.0 * s * t) + b * (t * t)
        }
        Curve::Cubic { controls } => {
            let [p, q] = controls.map(Vector2::from_array);
            a * (s * s * s) + p * (3.0 * s * s * t) + q * (3.0 * s * t * t) + b * (t * t * t)
        }
        Curve::Arc { .. } => a + (b - a) * t,
    }
}

/// A circle arc in centre form.
struct Arc {
    center: Vector2,
    radius: Scalar,
    start: Scalar,
    sweep: Scalar,
}

impl Arc {
    /// The SVG endpoint parametrisation turned into centre form (SVG 1.1,
    /// appendix F.6.5, with equal radii and no rotation): a radius too short
    /// for the chord grows to half the chord.
    fn new(a: Vector2, b: Vector2, radius: Scalar, large_arc: bool, ccw: bool) -> Arc {
        let half = (a - b) * 0.5;
        let d2 = half.length_squared();
        let radius = radius.abs().max(d2.sqrt());
        let sign = if large_arc == ccw { -1.0 } else { 1.0 };
        let coef = if d2 > 0.0 {
            sign * ((radius * radius - d2) / d2).max(0.0).sqrt()
        } else {
            0.0
        };
        let centre_local = Vector2::new(coef * half.y, -coef * half.x);
        let center = centre_local + (a + b) * 0.5;
        let angle = |v: Vector2| v.y.atan2(v.x);
        let start = angle(half - centre_local);
        let mut sweep = angle(-half - centre_local) - start;
        if ccw && sweep < 0.0 {
            sweep += TAU;
        } else if !ccw && sweep > 0.0 {
            sweep -= TAU;
        }
        Arc {
            center,
            radius,
            start,
            sweep,
        }
    }

    /// The point a `fraction` of the way along the arc.
    fn at(&self, fraction: Scalar) -> Vector2 {
        let phi = self.start + self.sweep * fraction;
        self.center + Vector2::new(phi.cos(), phi.sin()) * self.radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_counter_clockwise_half_circle_bulges_to_the_right_of_its_chord() {
        let (a, b) = (Vector2::new(0.0, 0.0), Vector2::new(2.0, 0.0));
        let arc = Curve::Arc {
            radius: 1.0,
            large_arc: false,
            counter_clockwise: true,
        };
        let p = side_points(Some(&arc), a, b, 2);
        assert!(p[1].distance(Vector2::new(1.0, -1.0)) < 1e-12, "{:?}", p[1]);
        assert!((side_length(Some(&arc), a, b) - std::f64::consts::PI).abs() < 1e-12);
    }

    #[test]
    fn a_large_arc_goes_the_long_way_round() {
        let (a, b) = (Vector2::new(0.0, 0.0), Vector2::new(1.0, 0.0));
        let arc = Curve::Arc {
            radius: 1.0,
            large_arc: true,
            counter_clockwise: true,
        };
        let circle = TAU * 1.0;
        let chord_angle = 2.0 * (0.5_f64).asin();
        let long = circle - chord_angle;
        assert!((side_length(Some(&arc), a, b) - long).abs() < 1e-12);
    }

    #[test]
    fn bezier_points_are_equally_spaced_by_arc_length() {
        let (a, b) = (Vector2::new(0.0, 0.0), Vector2::new(1.0, 0.0));
        let c = Curve::Cubic {
            controls: [[0.1, 0.8], [0.9, 0.1]],
        };
        let p = side_points(Some(&c), a, b, 8);
        let total = side_length(Some(&c), a, b);
        let fine = side_points(Some(&c), a, b, 800);
        // The fine polyline between consecutive coarse points has an eighth of the length.
        for k in 0..8 {
            let piece: Scalar = fine[100 * k..=100 * (k + 1)]
                .windows(2)
                .map(|w| w[0].distance(w[1]))
                .sum();
            assert!(
                (piece - total / 8.0).abs() < 1e-4 * total,
                "piece {k}: {piece}"
            );
        }
        assert_eq!(p[0], a);
        assert_eq!(p[8], b);
    }

    #[test]
    fn a_quadratic_side_is_longer_than_its_chord_and_passes_near_its_control() {
        let (a, b) = (Vector2::new(0.0, 0.0), Vector2::new(1.0, 0.0));
        let c = Curve::Quadratic {
            control: [0.5, 0.5],
        };
        let mid = side_points(Some(&c), a, b, 2)[1];
        assert!((mid - Vector2::new(0.5, 0.25)).length() < 1e-9, "{mid:?}");
        assert!(side_length(Some(&c), a, b) > 1.1);
    }
}
