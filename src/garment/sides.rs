//! A garment's panel sides before meshing: their lengths (along their curves),
//! how many segments each gets (both sides of a seam the same count), and each
//! panel's outline expanded so that a curved side is a run of straight sides,
//! one per segment, through points equally spaced along the curve.

use super::{GarmentError, seam_error};
use crate::math::{Scalar, Vector2};
use crate::mesh::{OutlineError, segments_for, side_length, side_points};
use crate::spec::{Curve, Garment, Gather, PanelSpec, SeamSpec};

/// The relative difference in length the two sides of a seam may have unless
/// it gathers: sewn point to point, longer differences would gather the cloth.
pub const SEAM_LENGTH_TOLERANCE: Scalar = 0.05;

/// A panel's outline as it is meshed: every curved side replaced by its
/// segments' straight pieces.
pub struct Expanded {
    /// The polygon's corners, m.
    pub outline: Vec<Vector2>,
    /// Segments per polygon side.
    pub segments: Vec<usize>,
    /// For each side of the panel, its first polygon side and how many there are.
    pub runs: Vec<(usize, usize)>,
}

impl Expanded {
    /// The panel's side (0-based) that polygon side `j` belongs to.
    pub fn side_of(&self, j: usize) -> usize {
        self.runs
            .iter()
            .position(|&(first, count)| j >= first && j < first + count)
            .unwrap_or(j)
    }

    /// An outline error of the polygon in the panel's side numbers.
    pub fn renumber(&self, why: OutlineError) -> OutlineError {
        match why {
            OutlineError::SelfIntersecting { a, b } => OutlineError::SelfIntersecting {
                a: self.side_of(a),
                b: self.side_of(b),
            },
            OutlineError::ZeroLengthSide { side, x, y, .. } => {
                let side = self.side_of(side);
                OutlineError::ZeroLengthSide {
                    side,
                    next: (side + 1) % self.runs.len(),
                    x,
                    y,
                }
            }
            OutlineError::NearlyTouching { side } => OutlineError::NearlyTouching {
                side: self.side_of(side),
            },
            other => other,
        }
    }

    /// The chain of vertices along the panel's side `k` (0-based), from the
    /// chains of its polygon sides (`sides`, as the mesher returns them).
    pub fn chain(&self, sides: &[Vec<u32>], k: usize) -> Vec<u32> {
        let (first, count) = self.runs[k];
        let mut chain: Vec<u32> = Vec::new();
        for piece in &sides[first..first + count] {
            let skip = usize::from(!chain.is_empty());
            chain.extend_from_slice(&piece[skip..]);
        }
        chain
    }
}

/// The curve of side `k` (0-based) of a panel, if it is curved.
pub fn curve_of(panel: &PanelSpec, k: usize) -> Option<&Curve> {
    panel
        .curves
        .iter()
        .find(|c| c.side == k + 1)
        .map(|c| &c.curve)
}

/// The ends of side `k` (0-based) of an outline.
fn ends(outline: &[[f64; 2]], k: usize) -> (Vector2, Vector2) {
    (
        Vector2::from_array(outline[k]),
        Vector2::from_array(outline[(k + 1) % outline.len()]),
    )
}

/// The length of side `k` (0-based) of a panel along its curve, m.
pub fn panel_side_length(panel: &PanelSpec, k: usize) -> Scalar {
    let (a, b) = ends(&panel.outline, k);
    side_length(curve_of(panel, k), a, b)
}

/// Every curve names an existing side, each side at most once.
pub fn check_curves(panel: &PanelSpec) -> Result<(), GarmentError> {
    let n = panel.outline.len();
    for (i, c) in panel.curves.iter().enumerate() {
        let reason = if c.side == 0 || c.side > n {
            format!(
                "curve {}: the panel has sides 1 to {n}, not {}",
                i + 1,
                c.side
            )
        } else if panel.curves[..i].iter().any(|e| e.side == c.side) {
            format!("curve {}: side {} has two curves", i + 1, c.side)
        } else if let Curve::Arc { radius, .. } = c.curve
            && !(radius.is_finite() && radius > 0.0)
        {
            format!("curve {}: an arc's radius must be > 0, got {radius}", i + 1)
        } else {
            continue;
        };
        return Err(GarmentError::Curve {
            panel: panel.name.clone(),
            reason,
        });
    }
    Ok(())
}

/// The panel's outline expanded with `segments` per side.
pub fn expand(panel: &PanelSpec, segments: &[usize]) -> Expanded {
    let mut outline = Vec::new();
    let mut per_side = Vec::new();
    let mut runs = Vec::new();
    for (k, &count) in segments.iter().enumerate() {
        let (a, b) = ends(&panel.outline, k);
        match curve_of(panel, k) {
            None => {
                runs.push((per_side.len(), 1));
                outline.push(a);
                per_side.push(count);
            }
            Some(c) => {
                runs.push((per_side.len(), count));
                let points = side_points(Some(c), a, b, count);
                outline.extend_from_slice(&points[..count]);
                per_side.extend(std::iter::repeat_n(1, count));
            }
        }
    }
    Expanded {
        outline,
        segments: per_side,
        runs,
    }
}

/// Segments per side of every panel: each side gets `max_edge`'s share of its
/// length; both sides of a seam get the larger of their two counts.
pub fn side_segments(garment: &Garment) -> Result<Vec<Vec<usize>>, GarmentError> {
    let mut segments: Vec<Vec<usize>> = garment
        .panels
        .iter()
        .map(|p| {
            (0..p.outline.len())
                .map(|k| segments_for(panel_side_length(p, k), garment.max_edge))
                .collect()
        })
        .collect();
    // Each side sewn so far, with its seam.
    let mut used_sides: Vec<((usize, usize), usize)> = Vec::new();
    for (i, s) in garment.seams.iter().enumerate() {
        let (a, b) = (
            super::edge_sides(garment, s, true)?,
            super::edge_sides(garment, s, false)?,
        );
        for &side in a.iter().chain(&b) {
            if let Some(&(_, j)) = used_sides.iter().find(|u| u.0 == side) {
                let panel = &garment.panels[side.0].name;
                return Err(seam_error(
                    s,
                    match j == i {
                        true => format!(
                            "side {} of panel `{panel}` is on the seam twice; a panel side is \
                             sewn once",
                            side.1 + 1
                        ),
                        false => format!(
                            "side {} of panel `{panel}` is already sewn by seam `{}`",
                            side.1 + 1,
                            garment.seams[j].name
                        ),
                    },
                ));
            }
            used_sides.push((side, i));
        }
        let len = |(p, k): (usize, usize)| panel_side_length(&garment.panels[p], k);
        let lengths = |e: &[(usize, usize)]| e.iter().map(|&x| len(x)).collect::<Vec<_>>();
        let (la, lb) = (lengths(&a), lengths(&b));
        check_lengths(s, la.iter().sum(), lb.iter().sum())?;
        let count = |e: &[(usize, usize)]| e.iter().map(|&(p, k)| segments[p][k]).sum::<usize>();
        let total = count(&a).max(count(&b)).max(a.len()).max(b.len());
        for (edge, lengths) in [(&a, &la), (&b, &lb)] {
            for (&(p, k), n) in edge.iter().zip(shares(total, lengths)) {
                segments[p][k] = n;
            }
        }
    }
    Ok(segments)
}

/// `total` segments shared among sides of `lengths`, in proportion to their
/// lengths and at least one each (largest remainders first); `total` is at
/// least the number of sides.
fn shares(total: usize, lengths: &[Scalar]) -> Vec<usize> {
    let sum: Scalar = lengths.iter().sum();
    let exact: Vec<Scalar> = lengths
        .iter()
        .map(|l| total as Scalar * l / sum.max(Scalar::MIN_POSITIVE))
        .collect();
    let mut n: Vec<usize> = exact.iter().map(|e| (e.floor() as usize).max(1)).collect();
    while n.iter().sum::<usize>() < total {
        let k = (0..n.len())
            .max_by(|&i, &j| (exact[i] - n[i] as Scalar).total_cmp(&(exact[j] - n[j] as Scalar)))
            .unwrap_or(0);
        n[k] += 1;
    }
    while n.iter().sum::<usize>() > total {
        let Some(k) = (0..n.len())
            .filter(|&i| n[i] > 1)
            .min_by(|&i, &j| (exact[i] - n[i] as Scalar).total_cmp(&(exact[j] - n[j] as Scalar)))
        else {
            break;
        };
        n[k] -= 1;
    }
    n
}

/// A seam that does not gather has sides within [`SEAM_LENGTH_TOLERANCE`].
fn check_lengths(s: &SeamSpec, la: Scalar, lb: Scalar) -> Result<(), GarmentError> {
    if s.gather == Gather::Any || (la - lb).abs() <= SEAM_LENGTH_TOLERANCE * la.max(lb) {
        return Ok(());
    }
    Err(seam_error(
        s,
        format!(
            "its sides are {la:.4} m and {lb:.4} m long, {:.1} % apart; allowed: at most \
             {:.0} % (the sides are sewn point to point), or any lengths with `gather = true`",
            100.0 * (la - lb).abs() / la.max(lb),
            100.0 * SEAM_LENGTH_TOLERANCE
        ),
    ))
}
