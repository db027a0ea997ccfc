//! Polygon checks for an outline: its area, and whether two of its sides
//! cross or touch.

use super::OutlineError;
use crate::math::{Scalar, Vector2};

/// The outline's signed area by the shoelace formula (positive when
/// counter-clockwise), m^2.
pub(super) fn polygon_area(outline: &[Vector2]) -> Scalar {
    let n = outline.len();
    0.5 * (0..n)
        .map(|i| outline[i].perp_dot(outline[(i + 1) % n]))
        .sum::<Scalar>()
}

/// Refuses an outline where two sides cross or touch, naming the first such pair.
/// Sides are swept in order of their smallest x, so that only sides whose
/// x ranges overlap are compared.
pub(super) fn check_simple(outline: &[Vector2]) -> Result<(), OutlineError> {
    let n = outline.len();
    let side = |i: usize| (outline[i], outline[(i + 1) % n]);
    let x_range = |i: usize| {
        let (a, b) = side(i);
        (a.x.min(b.x), a.x.max(b.x))
    };
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| x_range(i).0.total_cmp(&x_range(j).0).then(i.cmp(&j)));
    let mut first: Option<(usize, usize)> = None;
    for (k, &i) in order.iter().enumerate() {
        let reach = x_range(i).1;
        for &j in order[k + 1..].iter() {
            if x_range(j).0 > reach {
                break;
            }
            let pair = (i.min(j), i.max(j));
            if first.is_some_and(|f| f <= pair) {
                continue;
            }
            let adjacent = pair.1 == pair.0 + 1 || (pair.0 == 0 && pair.1 == n - 1);
            let (a, b) = (side(pair.0), side(pair.1));
            let meet = if adjacent {
                adjacent_overlap(a, b, pair.0 == 0 && pair.1 == n - 1)
            } else {
                segments_meet(a, b)
            };
            if meet {
                first = Some(pair);
            }
        }
    }
    match first {
        Some((a, b)) => Err(OutlineError::SelfIntersecting { a, b }),
        None => Ok(()),
    }
}

/// Sign of the turn from `a` to `b` to `c`: positive when counter-clockwise.
pub(super) fn orient(a: Vector2, b: Vector2, c: Vector2) -> Scalar {
    (b - a).perp_dot(c - a)
}

/// True when closed segments `s` and `t` share a point.
fn segments_meet(s: (Vector2, Vector2), t: (Vector2, Vector2)) -> bool {
    let (p, q) = s;
    let (r, u) = t;
    let (d1, d2) = (orient(p, q, r), orient(p, q, u));
    let (d3, d4) = (orient(r, u, p), orient(r, u, q));
    let opposite = |x: Scalar, y: Scalar| (x > 0.0 && y < 0.0) || (x < 0.0 && y > 0.0);
    if opposite(d1, d2) && opposite(d3, d4) {
        return true;
    }
    // Collinear touches: an endpoint of one segment on the other.
    let within = |a: Vector2, b: Vector2, c: Vector2| {
        c.x >= a.x.min(b.x) && c.x <= a.x.max(b.x) && c.y >= a.y.min(b.y) && c.y <= a.y.max(b.y)
    };
    (d1 == 0.0 && within(p, q, r))
        || (d2 == 0.0 && within(p, q, u))
        || (d3 == 0.0 && within(r, u, p))
        || (d4 == 0.0 && within(r, u, q))
}

/// True when adjacent sides `s` and `t` overlap beyond their shared corner: they
/// are collinear and double back. `wrapped`: `t` comes before `s` around the
/// outline (the last side and side 0), so the shared corner is `s`'s start.
fn adjacent_overlap(s: (Vector2, Vector2), t: (Vector2, Vector2), wrapped: bool) -> bool {
    let (before, corner, after) = if wrapped {
        (t.0, s.0, s.1)
    } else {
        (s.0, s.1, t.1)
    };
    orient(before, corner, after) == 0.0 && (before - corner).dot(after - corner) > 0.0
}
