//! A GarmentCode pattern turned into drape's garment: metres, absolute
//! control points, outlines that wind counter-clockwise, and stitches as
//! seams.
//!
//! GarmentCode's panel faces the way its outline winds along its sides,
//! curves included (counter-clockwise seen from the front of the fabric), while drape meshes every outline
//! counter-clockwise and faces it along the placement's +z. A clockwise panel
//! is therefore mirrored (u -> -u, which keeps every length and area) and
//! placed with an extra half turn about its v axis, which puts each point
//! where GarmentCode puts it and faces the panel the way GarmentCode does.

use serde_json::Value;

use super::json::{EdgeJson, PanelJson, SpecFile};
use super::{Labelled, Why};
use crate::garment::SEAM_LENGTH_TOLERANCE;
use crate::math::{Matrix3, Scalar, Vector2, rotation_from_euler_deg};
use crate::mesh::{side_length, side_points};
use crate::spec::{
    Curve, Gather, PanelSpec, Placement, SeamDirection, SeamSide, SeamSpec, SideCurve,
};

/// One panel converted, with its labelled sides.
pub struct Converted {
    /// The panel, as its outline winds in GarmentCode (not yet turned over).
    pub panel: PanelSpec,
    /// Its labelled sides.
    pub labels: Vec<Labelled>,
    /// Whether its outline winds clockwise (along its sides, curves included):
    /// GarmentCode faces it along its placement's -z.
    pub clockwise: bool,
}

/// Converts panel `name` of `file`.
pub fn panel(file: &SpecFile, name: &str, p: &PanelJson) -> Result<Converted, Why> {
    let scale = 1.0 / file.properties.units_in_meter;
    let absolute = file.properties.curvature_coords == "absolute";
    let corners = loop_corners(name, p)?;
    let outline: Vec<[f64; 2]> = corners
        .iter()
        .map(|&c| scaled(p.vertices[c], scale))
        .collect();
    let n = outline.len();
    let mut curves = Vec::new();
    let mut labels = Vec::new();
    for (k, e) in p.edges.iter().enumerate() {
        let (a, b) = (
            Vector2::from_array(outline[k]),
            Vector2::from_array(outline[(k + 1) % n]),
        );
        if a.distance(b) <= 1e-9 {
            return Err(Why::ZeroLength {
                panel: name.into(),
                edge: k,
            });
        }
        if let Some(value) = &e.curvature {
            let curve = curve(name, k, value, a, b, absolute, scale)?;
            curves.push(SideCurve { side: k + 1, curve });
        }
        if let Some(label) = &e.label {
            labels.push(Labelled {
                panel: name.into(),
                side: k + 1,
                label: label.clone(),
            });
        }
    }
    let clockwise = outline_signed_area(&outline, &curves) < 0.0;
    let panel = PanelSpec {
        name: name.into(),
        outline,
        curves,
        placement: Placement::Flat {
            position: p.translation.map(|t| t * scale),
            rotation: p.rotation,
        },
    };
    Ok(Converted {
        panel,
        labels,
        clockwise,
    })
}

/// Turns `panel` over: its outline mirrored (u -> -u, which keeps every
/// length and area and reverses the way it winds) and its placement given a
/// half turn about its v axis, which keeps each point where it was and faces
/// the panel the other way (drape faces a panel along its placement's +z
/// whichever way its outline winds).
pub fn turn_over(panel: &mut PanelSpec) {
    for c in &mut panel.outline {
        c[0] = -c[0];
    }
    for c in &mut panel.curves {
        c.curve = mirrored(c.curve);
    }
    if let Placement::Flat { rotation, .. } = &mut panel.placement {
        let turned =
            rotation_from_euler_deg(*rotation) * Matrix3::from_rotation_y(std::f64::consts::PI);
        *rotation = euler_deg(&turned);
    }
}

/// The corner each edge starts at, checking that the edges form one loop.
fn loop_corners(name: &str, p: &PanelJson) -> Result<Vec<usize>, Why> {
    let n = p.edges.len();
    if n < 3 {
        return Err(Why::Panel {
            panel: name.into(),
            reason: format!("it has {n} edges; a panel needs at least 3"),
        });
    }
    for (k, e) in p.edges.iter().enumerate() {
        if let Some(&v) = e.endpoints.iter().find(|&&v| v >= p.vertices.len()) {
            return Err(Why::Edge {
                panel: name.into(),
                edge: k,
                reason: format!(
                    "corner {v} does not exist (the panel has {})",
                    p.vertices.len()
                ),
            });
        }
        let next: &EdgeJson = &p.edges[(k + 1) % n];
        if e.endpoints[1] != next.endpoints[0] {
            return Err(Why::Edge {
                panel: name.into(),
                edge: k,
                reason: format!(
                    "it ends at corner {} but edge {} starts at corner {}: the edges must form \
                     one loop, in order",
                    e.endpoints[1],
                    (k + 1) % n,
                    next.endpoints[0]
                ),
            });
        }
    }
    Ok(p.edges.iter().map(|e| e.endpoints[0]).collect())
}

fn scaled(p: [f64; 2], scale: Scalar) -> [f64; 2] {
    [p[0] * scale, p[1] * scale]
}

/// The curve of edge `k` from `a` to `b` (m) from its JSON `curvature`.
fn curve(
    panel: &str,
    edge: usize,
    value: &Value,
    a: Vector2,
    b: Vector2,
    absolute: bool,
    scale: Scalar,
) -> Result<Curve, Why> {
    let bad = |reason: String| Why::Edge {
        panel: panel.into(),
        edge,
        reason,
    };
    let point = |v: &Value| -> Result<[f64; 2], Why> {
        let xy: Vec<f64> = v
            .as_array()
            .map(|a| a.iter().filter_map(Value::as_f64).collect())
            .unwrap_or_default();
        match xy.as_slice() {
            [x, y] if x.is_finite() && y.is_finite() => Ok(if absolute {
                [x * scale, y * scale]
            } else {
                let d = b - a;
                (a + d * *x + Vector2::new(-d.y, d.x) * *y).to_array()
            }),
            _ => Err(bad(format!("a control point must be [x, y], got {v}"))),
        }
    };
    if value.is_array() {
        return Ok(Curve::Quadratic {
            control: point(value)?,
        });
    }
    let kind = value.get("type").and_then(Value::as_str).unwrap_or("");
    let params: Vec<Value> = value
        .get("params")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    match (kind, params.as_slice()) {
        ("quadratic", [c]) => Ok(Curve::Quadratic { control: point(c)? }),
        ("cubic", [c, d]) => Ok(Curve::Cubic {
            controls: [point(c)?, point(d)?],
        }),
        ("circle", [r, large, right]) => {
            let radius = r.as_f64().filter(|r| r.is_finite() && *r > 0.0);
            let flag = |v: &Value| v.as_bool().or(v.as_i64().map(|i| i != 0));
            match (radius, flag(large), flag(right)) {
                (Some(r), Some(large_arc), Some(right)) => Ok(Curve::Arc {
                    radius: r * scale,
                    large_arc,
                    counter_clockwise: right,
                }),
                _ => Err(bad(format!(
                    "a circle's params must be [radius > 0, large_arc, right], got {}",
                    value["params"]
                ))),
            }
        }
        ("quadratic" | "cubic" | "circle", _) => Err(bad(format!(
            "a {kind} curvature has the wrong number of params: {}",
            value.get("params").unwrap_or(&Value::Null)
        ))),
        _ => Err(Why::UnknownCurvature {
            panel: panel.into(),
            edge,
            kind: value
                .get("type")
                .map_or_else(|| value.to_string(), Value::to_string),
        }),
    }
}

/// A curve mirrored with its panel (u -> -u).
fn mirrored(c: Curve) -> Curve {
    let m = |p: [f64; 2]| [-p[0], p[1]];
    match c {
        Curve::Quadratic { control } => Curve::Quadratic {
            control: m(control),
        },
        Curve::Cubic { controls } => Curve::Cubic {
            controls: controls.map(m),
        },
        Curve::Arc {
            radius,
            large_arc,
            counter_clockwise,
        } => Curve::Arc {
            radius,
            large_arc,
            counter_clockwise: !counter_clockwise,
        },
    }
}

/// Segments a curved side is sampled with to tell which way an outline winds.
const WINDING_SEGMENTS: usize = 64;

/// Twice the signed area of an outline along its sides, curves included
/// (positive: counter-clockwise). The corners alone can wind the other way:
/// a circle skirt's panel has arcs of more than half a turn at its waist and
/// hem, and its four corners wind opposite to its shape.
fn outline_signed_area(outline: &[[f64; 2]], curves: &[SideCurve]) -> Scalar {
    let n = outline.len();
    let mut points = Vec::new();
    for k in 0..n {
        let (a, b) = (
            Vector2::from_array(outline[k]),
            Vector2::from_array(outline[(k + 1) % n]),
        );
        let curve = curves.iter().find(|c| c.side == k + 1).map(|c| &c.curve);
        let segments = if curve.is_some() { WINDING_SEGMENTS } else { 1 };
        points.extend_from_slice(&side_points(curve, a, b, segments)[..segments]);
    }
    let m = points.len();
    (0..m)
        .map(|i| points[i].perp_dot(points[(i + 1) % m]))
        .sum()
}

/// Euler angles (degrees, about x, then y, then z) of a rotation matrix.
fn euler_deg(r: &Matrix3) -> [f64; 3] {
    // r = Rz(c) Ry(b) Rx(a): r[0][2] (column 0, row 2) = -sin b.
    let (c0, c1, c2) = (r.x_axis, r.y_axis, r.z_axis);
    let sb = (-c0.z).clamp(-1.0, 1.0);
    let b = sb.asin();
    let (a, c) = if sb.abs() < 1.0 - 1e-12 {
        (c1.z.atan2(c2.z), c0.y.atan2(c0.x))
    } else {
        // Gimbal lock: only a - c (or a + c) is defined; put it all in a.
        ((-c2.y).atan2(c1.y), 0.0)
    };
    [a, b, c].map(Scalar::to_degrees)
}

/// Stitch `i` as a seam between two converted panels.
pub fn stitch(i: usize, entry: &[Value], panels: &[PanelSpec]) -> Result<SeamSpec, Why> {
    let bad = |reason: String| Why::Stitch { stitch: i, reason };
    if !(entry.len() == 2 || entry.len() == 3) {
        return Err(bad(format!(
            "it has {} entries; a stitch has two sides and an optional orientation",
            entry.len()
        )));
    }
    let mut sides = Vec::new();
    for side in &entry[..2] {
        let panel = side.get("panel").and_then(Value::as_str);
        let edge = side.get("edge").and_then(Value::as_u64);
        let (Some(panel), Some(edge)) = (panel, edge) else {
            return Err(bad(format!(
                "a side must be {{\"panel\": NAME, \"edge\": N}}, got {side}"
            )));
        };
        let Some(p) = panels.iter().find(|p| p.name == panel) else {
            return Err(bad(format!("there is no panel `{panel}`")));
        };
        let edge = edge as usize;
        if edge >= p.outline.len() {
            return Err(bad(format!(
                "panel `{panel}` has edges 0 to {}, not {edge}",
                p.outline.len() - 1
            )));
        }
        sides.push((p, edge));
    }
    let direction = match entry.get(2).map(|v| v.as_str()) {
        None | Some(Some("right_right")) => SeamDirection::Opposite,
        Some(Some("right_wrong")) => SeamDirection::Same,
        Some(other) => {
            return Err(bad(format!(
                "its orientation must be \"right_right\" or \"right_wrong\", got {}",
                other.map_or_else(|| entry[2].to_string(), |s| format!("\"{s}\""))
            )));
        }
    };
    let length = |(p, k): (&PanelSpec, usize)| {
        let n = p.outline.len();
        let curve = p.curves.iter().find(|c| c.side == k + 1).map(|c| &c.curve);
        side_length(
            curve,
            Vector2::from_array(p.outline[k]),
            Vector2::from_array(p.outline[(k + 1) % n]),
        )
    };
    let (la, lb) = (length(sides[0]), length(sides[1]));
    let gather = if (la - lb).abs() > SEAM_LENGTH_TOLERANCE * la.max(lb) {
        Gather::Any
    } else {
        Gather::None
    };
    let side = |(p, k): (&PanelSpec, usize)| SeamSide {
        panel: p.name.clone(),
        side: k + 1,
    };
    Ok(SeamSpec {
        name: format!("stitch{i}"),
        a: vec![side(sides[0])],
        b: vec![side(sides[1])],
        direction,
        gather,
    })
}
