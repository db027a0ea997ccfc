//! Curved panel sides: a side of a garment panel's outline that runs along a
//! circle arc or a Bézier curve instead of straight from corner to corner.

use serde::Deserialize;

/// A curved side of a panel outline: which side, and the curve it follows.
/// In a scene, one entry of `[[panel]] curves`: `{ side, kind, controls }`
/// for a Bézier curve, `{ side, kind = "arc", radius, large_arc,
/// counter_clockwise }` for an arc.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(try_from = "CurveEntry")]
pub struct SideCurve {
    /// The side, 1-based: side k runs from outline corner k to corner k + 1.
    pub side: usize,
    /// The curve from the side's first corner to its second.
    pub curve: Curve,
}

/// Which kind of curve an entry of `curves` is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
enum CurveKind {
    Quadratic,
    Cubic,
    Arc,
}

/// One entry of `[[panel]] curves` as written, before its keys are checked
/// against its kind.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct CurveEntry {
    side: usize,
    kind: CurveKind,
    controls: Option<Vec<[f64; 2]>>,
    radius: Option<f64>,
    large_arc: Option<bool>,
    counter_clockwise: Option<bool>,
}

impl TryFrom<CurveEntry> for SideCurve {
    type Error = String;

    fn try_from(e: CurveEntry) -> Result<SideCurve, String> {
        let arc_keys = e.radius.is_some() || e.large_arc.is_some() || e.counter_clockwise.is_some();
        let curve = match (e.kind, e.controls) {
            (CurveKind::Arc, None) => Curve::Arc {
                radius: e.radius.ok_or("an arc needs `radius`")?,
                large_arc: e.large_arc.ok_or("an arc needs `large_arc`")?,
                counter_clockwise: e
                    .counter_clockwise
                    .ok_or("an arc needs `counter_clockwise`")?,
            },
            (CurveKind::Arc, Some(_)) => return Err("an arc has no `controls`".into()),
            (_, _) if arc_keys => {
                return Err(
                    "`radius`, `large_arc` and `counter_clockwise` belong to an arc".into(),
                );
            }
            (CurveKind::Quadratic, Some(c)) if c.len() == 1 => Curve::Quadratic { control: c[0] },
            (CurveKind::Cubic, Some(c)) if c.len() == 2 => Curve::Cubic {
                controls: [c[0], c[1]],
            },
            (kind, _) => {
                let n = if kind == CurveKind::Quadratic { 1 } else { 2 };
                return Err(
                    format!("a {kind:?} curve needs `controls` with {n} [u, v] point(s)")
                        .to_lowercase(),
                );
            }
        };
        Ok(SideCurve {
            side: e.side,
            curve,
        })
    }
}

/// The curve of a side, in the panel's pattern coordinates (m). The side's two
/// corners are its ends; the curve gives what lies between them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Curve {
    /// A quadratic Bézier curve through one control point.
    Quadratic {
        /// The control point `[u, v]`, m.
        control: [f64; 2],
    },
    /// A cubic Bézier curve through two control points.
    Cubic {
        /// The control points `[[u, v], [u, v]]`, m, the first nearer the start.
        controls: [[f64; 2]; 2],
    },
    /// A circle arc, as an SVG arc: its radius and which of the four arcs of
    /// that radius through the two ends it is.
    Arc {
        /// The radius, m; a radius shorter than half the chord is taken as
        /// half the chord (a half circle), as SVG does.
        radius: f64,
        /// The arc spans more than 180 degrees.
        large_arc: bool,
        /// The arc turns counter-clockwise (in the pattern's u-v plane) from
        /// the first corner to the second.
        counter_clockwise: bool,
    },
}
