//! How far the vertices a box or disk pin holds are from the region the
//! scene names.
//!
//! A pin holds vertices, so a box region holds exactly the cloth inside it
//! only where mesh edges run along the box's edges. A generated rectangle
//! puts grid lines there (`crate::mesh::fitted_lines`); a disk's rings and an
//! OBJ mesh in general do not, and the cloth held is then a staircase of
//! triangles inside the box. This module measures the difference two ways:
//! the bounding box of the held vertices against the bounding box of the
//! cloth inside the region (each side's gap), and the length of the region's
//! edges inside the cloth along which no mesh edge between held vertices
//! runs. A disk region is compared on the held cloth's edge instead
//! ([`disk`]).

mod disk;

use serde::Serialize;

use super::Region;
use crate::math::{Scalar, Vector2};
use crate::mesh::Mesh;
use crate::spec::Pin;

/// A box or disk pin region whose held vertices are not the cloth the region names.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PinMismatch {
    /// Index of the `[[pin]]` section.
    pub pin: usize,
    /// The region: `box` or `disk`.
    pub region: &'static str,
    /// Bounding box of the cloth inside the region (a disk: of the disk,
    /// within the cloth's bounds), `[u_min, v_min, u_max, v_max]` in material
    /// coordinates, m.
    pub region_box: [Scalar; 4],
    /// Bounding box of the vertices inside the region (those it holds), same
    /// layout, m.
    pub held_box: [Scalar; 4],
    /// A box: the largest distance between a side of `held_box` and the same
    /// side of `region_box`; a disk: how far inside its circle the deepest
    /// held vertex next to free cloth lies, m.
    pub largest_gap: Scalar,
    /// A box: length of its edges that lie inside the cloth; a disk: length
    /// of the mesh edges between held vertices that bound the held cloth, m.
    pub edge_length: Scalar,
    /// A box: of `edge_length`, the length along which no mesh edge between
    /// two held vertices runs; a disk: of `edge_length`, the length of the
    /// edges with an end off the circle, m.
    pub uncovered_length: Scalar,
}

impl PinMismatch {
    /// One line for `drape check` and the run's summary paragraph, in mm.
    pub fn describe(&self) -> String {
        let mm = |b: &[Scalar; 4]| {
            format!(
                "u {:.2} to {:.2} mm, v {:.2} to {:.2} mm",
                b[0] * 1e3,
                b[2] * 1e3,
                b[1] * 1e3,
                b[3] * 1e3
            )
        };
        if self.region == "disk" {
            return format!(
                "pin {}: the disk holds vertices over {} where it spans {}; held vertices next to \
                 free cloth lie up to {:.2} mm inside its edge, and {:.2} of the {:.2} mm of mesh \
                 edges that bound the held cloth have an end off that edge",
                self.pin,
                mm(&self.held_box),
                mm(&self.region_box),
                self.largest_gap * 1e3,
                self.uncovered_length * 1e3,
                self.edge_length * 1e3
            );
        }
        format!(
            "pin {}: the box holds vertices over {} where the cloth inside it spans {} \
             (largest gap {:.2} mm); {:.2} of its {:.2} mm of edges inside the cloth lie on no mesh edge",
            self.pin,
            mm(&self.held_box),
            mm(&self.region_box),
            self.largest_gap * 1e3,
            self.uncovered_length * 1e3,
            self.edge_length * 1e3
        )
    }
}

/// The box and disk pins of `pins` (the scene's `[[pin]]` sections) whose
/// vertices on `mesh` are not the cloth inside their region, measured at a
/// tolerance of 1e-9 of the cloth's size. Other regions, and pins that cannot
/// be parsed, are skipped: a corner, a side and `all` are held exactly by
/// construction.
pub fn mismatches(pins: &[Pin], mesh: &Mesh) -> Vec<PinMismatch> {
    let (lo, hi) = mesh.material_bounds();
    let tol = 1e-9 * (hi - lo).max_element().max(Scalar::MIN_POSITIVE);
    pins.iter()
        .enumerate()
        .filter_map(|(p, pin)| match Region::parse(p, pin) {
            Ok(Region::Box(a, b)) => measure(p, a, b, mesh, tol),
            Ok(Region::Disk(c, r)) => disk::measure(p, c, r, mesh, tol),
            _ => None,
        })
        .filter(|m| m.largest_gap > m_tol(tol) || m.uncovered_length > m_tol(tol))
        .collect()
}

/// The tolerance above which a gap or an uncovered length is reported: well
/// above the rounding of the sums that make them.
fn m_tol(tol: Scalar) -> Scalar {
    10.0 * tol
}

/// The comparison for the box `a`..`b` of pin `p`; `None` when the box holds
/// no vertex or contains no cloth.
fn measure(p: usize, a: Vector2, b: Vector2, mesh: &Mesh, tol: Scalar) -> Option<PinMismatch> {
    let (held, held_box) = held_by(mesh, |m| m.cmpge(a - tol).all() && m.cmple(b + tol).all());
    let held_box = held_box?;
    let region_box = bounding_box(
        mesh.triangles
            .iter()
            .flat_map(|t| clip_to_box(t.map(|i| mesh.material[i as usize]), a, b)),
    )?;
    let largest_gap = (0..4)
        .map(|k| (held_box[k] - region_box[k]).abs())
        .fold(0.0, Scalar::max);
    let corners = [a, Vector2::new(b.x, a.y), b, Vector2::new(a.x, b.y)];
    let (mut edge_length, mut covered) = (0.0, 0.0);
    for k in 0..4 {
        let (s, e) = (corners[k], corners[(k + 1) % 4]);
        let len = s.distance(e);
        let inside: Vec<(Scalar, Scalar)> = mesh
            .triangles
            .iter()
            .filter_map(|t| segment_in_triangle(s, e, t.map(|i| mesh.material[i as usize]), tol))
            .collect();
        let along: Vec<(Scalar, Scalar)> = mesh
            .edges
            .iter()
            .map(|ed| ed.vertices.map(|v| v as usize))
            .filter(|[i, j]| held[*i] && held[*j])
            .filter_map(|[i, j]| on_segment(s, e, mesh.material[i], mesh.material[j], tol))
            .collect();
        edge_length += len * union_length(inside);
        covered += len * union_length(along);
    }
    Some(PinMismatch {
        pin: p,
        region: "box",
        region_box,
        held_box,
        largest_gap,
        edge_length,
        uncovered_length: (edge_length - covered).max(0.0),
    })
}

/// Per vertex of `mesh`, whether its material point is `inside` the region,
/// and the bounding box of those that are (`None`: none is).
fn held_by(mesh: &Mesh, inside: impl Fn(Vector2) -> bool) -> (Vec<bool>, Option<[Scalar; 4]>) {
    let held: Vec<bool> = mesh.material.iter().map(|m| inside(*m)).collect();
    let held_box = bounding_box(
        mesh.material
            .iter()
            .zip(&held)
            .filter(|(_, h)| **h)
            .map(|(m, _)| *m),
    );
    (held, held_box)
}

/// `[u_min, v_min, u_max, v_max]` of the points, `None` for none.
fn bounding_box(points: impl Iterator<Item = Vector2>) -> Option<[Scalar; 4]> {
    points.fold(None, |acc, p| {
        Some(match acc {
            None => [p.x, p.y, p.x, p.y],
            Some([a, b, c, d]) => [a.min(p.x), b.min(p.y), c.max(p.x), d.max(p.y)],
        })
    })
}

/// The corners of triangle `t` clipped to the box `a`..`b` (Sutherland and
/// Hodgman against its four sides); empty when they do not overlap.
fn clip_to_box(t: [Vector2; 3], a: Vector2, b: Vector2) -> Vec<Vector2> {
    let mut poly = t.to_vec();
    // Each side as (axis, bound, keep below): u >= a.x, u <= b.x, v >= a.y, v <= b.y.
    for (axis, bound, below) in [
        (0, a.x, false),
        (0, b.x, true),
        (1, a.y, false),
        (1, b.y, true),
    ] {
        let inside = |p: &Vector2| {
            if below {
                p[axis] <= bound
            } else {
                p[axis] >= bound
            }
        };
        let mut out = Vec::with_capacity(poly.len() + 1);
        for k in 0..poly.len() {
            let (p, q) = (poly[k], poly[(k + 1) % poly.len()]);
            if inside(&p) {
                out.push(p);
            }
            if inside(&p) != inside(&q) {
                let s = (bound - p[axis]) / (q[axis] - p[axis]);
                let mut x = p + (q - p) * s;
                x[axis] = bound;
                out.push(x);
            }
        }
        poly = out;
        if poly.is_empty() {
            break;
        }
    }
    poly
}

/// The parameter interval of the segment `s`..`e` inside triangle `t`
/// (either orientation; a segment along a side, within `tol`, counts as
/// inside), `None` when they do not meet along a length.
fn segment_in_triangle(
    s: Vector2,
    e: Vector2,
    t: [Vector2; 3],
    tol: Scalar,
) -> Option<(Scalar, Scalar)> {
    let d = e - s;
    let orient = (t[1] - t[0]).perp_dot(t[2] - t[0]).signum();
    let (mut t0, mut t1): (Scalar, Scalar) = (0.0, 1.0);
    for k in 0..3 {
        let (p, q) = (t[k], t[(k + 1) % 3]);
        let side = q - p;
        let len = side.length();
        if len <= 0.0 {
            return None;
        }
        // Signed distance of a point to the side, positive inside: f(t) = f0 + t df.
        let f0 = orient * side.perp_dot(s - p) / len;
        let df = orient * side.perp_dot(d) / len;
        if df.abs() <= tol {
            // Along the side: inside when on it or on its inner side.
            if f0.max(f0 + df) < -tol {
                return None;
            }
        } else if df > 0.0 {
            t0 = t0.max(-f0 / df);
        } else {
            t1 = t1.min(-f0 / df);
        }
    }
    (t1 > t0).then_some((t0, t1))
}

/// The parameter interval of the segment `s`..`e` covered by the mesh edge
/// `p`..`q` when both its ends lie on the segment's line (within `tol`).
fn on_segment(
    s: Vector2,
    e: Vector2,
    p: Vector2,
    q: Vector2,
    tol: Scalar,
) -> Option<(Scalar, Scalar)> {
    let d = e - s;
    let len2 = d.length_squared();
    if len2 <= 0.0 {
        return None;
    }
    let off = |x: Vector2| d.perp_dot(x - s).abs() / len2.sqrt();
    if off(p) > tol || off(q) > tol {
        return None;
    }
    let (a, b) = ((p - s).dot(d) / len2, (q - s).dot(d) / len2);
    let (a, b) = (a.min(b).max(0.0), a.max(b).min(1.0));
    (b > a).then_some((a, b))
}

/// Length of the union of intervals (in the unit parameter).
fn union_length(mut intervals: Vec<(Scalar, Scalar)>) -> Scalar {
    intervals.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut total = 0.0;
    let mut current: Option<(Scalar, Scalar)> = None;
    for (a, b) in intervals {
        current = match current {
            Some((c, d)) if a <= d => Some((c, d.max(b))),
            Some((c, d)) => {
                total += d - c;
                Some((a, b))
            }
            None => Some((a, b)),
        };
    }
    total + current.map_or(0.0, |(c, d)| d - c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::DiagonalPattern;

    fn box_pin(a: [Scalar; 2], b: [Scalar; 2]) -> Pin {
        Pin {
            region: "box".into(),
            box_min: Some(a),
            box_max: Some(b),
            disk_center: None,
            disk_radius: None,
            motion: crate::spec::PinMotion::Fixed,
            velocity: [0.0; 3],
            acceleration: [0.0; 3],
            center: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            angular_velocity: 0.0,
            release_time: None,
            keyframes: Vec::new(),
            easing: Default::default(),
            after_last: Default::default(),
            attach: None,
        }
    }

    #[test]
    fn a_box_on_grid_lines_matches() {
        let m = crate::mesh::rectangle(1.0, 1.0, 4, DiagonalPattern::Alternating).unwrap();
        assert!(mismatches(&[box_pin([-1.0, -1.0], [0.0, 1.0])], &m).is_empty());
    }

    #[test]
    fn a_box_between_grid_lines_is_measured() {
        // Lines at -0.5, -0.25, 0, 0.25, 0.5; the box edge at u = 0.1.
        let m = crate::mesh::rectangle(1.0, 1.0, 4, DiagonalPattern::Alternating).unwrap();
        let found = mismatches(&[box_pin([-1.0, -1.0], [0.1, 1.0])], &m);
        assert_eq!(found.len(), 1);
        let f = &found[0];
        assert!((f.region_box[2] - 0.1).abs() < 1e-12, "{f:?}");
        assert!((f.held_box[2] - 0.0).abs() < 1e-12, "{f:?}");
        assert!((f.largest_gap - 0.1).abs() < 1e-12, "{f:?}");
        // Of the box's edges only the right one crosses the cloth (1 m), and
        // no mesh edge runs along it.
        assert!((f.edge_length - 1.0).abs() < 1e-9, "{f:?}");
        assert!((f.uncovered_length - 1.0).abs() < 1e-9, "{f:?}");
    }

    fn disk_pin(r: Scalar) -> Pin {
        Pin {
            region: "disk".into(),
            box_min: None,
            box_max: None,
            disk_radius: Some(r),
            ..box_pin([0.0; 2], [0.0; 2])
        }
    }

    #[test]
    fn a_disk_on_a_ring_matches() {
        // 25 rings 6 mm apart: ring 15 lies at 90 mm.
        let m = crate::mesh::disk(0.15, 50).unwrap();
        assert!(mismatches(&[disk_pin(0.09)], &m).is_empty());
    }

    #[test]
    fn a_disk_between_rings_is_measured() {
        let m = crate::mesh::disk(0.15, 50).unwrap();
        let found = mismatches(&[disk_pin(0.093)], &m);
        assert_eq!(found.len(), 1);
        let f = &found[0];
        assert_eq!(f.region, "disk");
        // Ring 15 at 90 mm is held, ring 16 at 96 mm free.
        assert!((f.largest_gap - 0.003).abs() < 1e-12, "{f:?}");
        assert!(
            f.uncovered_length > 0.0 && f.uncovered_length == f.edge_length,
            "{f:?}"
        );
        assert!(
            f.describe().contains("lie up to 3.00 mm inside its edge"),
            "{}",
            f.describe()
        );
    }

    #[test]
    fn union_merges_overlaps() {
        assert!((union_length(vec![(0.5, 0.7), (0.0, 0.2), (0.1, 0.3)]) - 0.5).abs() < 1e-15);
    }
}
