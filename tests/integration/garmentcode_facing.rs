//! Which way GarmentCode's panels face in drape: a panel whose corners wind
//! one way and whose arcs wind it the other (a circle skirt's), and a collar
//! sewn `"right_wrong"` to its bodice, both weld untwisted.

use serde_json::{Value, json};

use drape::garmentcode;

/// A specification (centimetres) of `panels` and `stitches`.
fn spec(panels: Value, stitches: Value) -> String {
    let order: Vec<String> = panels
        .as_object()
        .expect("panels")
        .keys()
        .cloned()
        .collect();
    json!({
        "pattern": { "panels": panels, "stitches": stitches, "panel_order": order },
        "properties": { "units_in_meter": 100, "curvature_coords": "relative" }
    })
    .to_string()
}

/// A panel of straight edges through `vertices`, in order.
fn panel(vertices: Value, translation: [f64; 3]) -> Value {
    let n = vertices.as_array().expect("vertices").len();
    let edges: Vec<Value> = (0..n)
        .map(|k| json!({ "endpoints": [k, (k + 1) % n] }))
        .collect();
    json!({ "vertices": vertices, "edges": edges, "translation": translation, "rotation": [0, 0, 0] })
}

/// Builds the pattern as `drape garment` checks it (2 cm edges).
fn builds(text: &str) -> Result<(), String> {
    let pattern = garmentcode::parse(text).map_err(|e| e.to_string())?;
    garmentcode::check(&pattern, 0.02).map_err(|e| e.to_string())
}

/// GarmentCode's circle skirt front (a sampled `Skirt2` design): four corners
/// that wind clockwise, and a waist and a hem that are arcs of 243 degrees,
/// which wind the panel counter-clockwise; sewn to a waistband below it.
#[test]
fn a_panel_wound_by_its_arcs_against_its_corners_welds_to_its_waistband() {
    let mut skirt = panel(
        json!([[-0.47, 0.0], [-23.07, 13.88], [39.07, 13.88], [16.47, 0.0]]),
        [-8.47, 93.86, 17.5],
    );
    skirt["edges"][1]["curvature"] = json!({ "type": "circle", "params": [36.46, 1, 1] });
    skirt["edges"][3]["curvature"] = json!({ "type": "circle", "params": [9.94, 1, 0] });
    let band = panel(
        json!([[0.0, 0.0], [0.0, -4.7], [46.0, -4.7], [46.0, 0.0]]),
        [-22.6, 97.4, 20.0],
    );
    let text = spec(
        json!({ "wb_front": band, "skirt_front": skirt }),
        json!([[{ "panel": "wb_front", "edge": 1 }, { "panel": "skirt_front", "edge": 3 }]]),
    );
    builds(&text).expect("the skirt welds to its waistband");
}

/// A bodice panel and a collar panel in front of it, sewn `"right_wrong"`
/// along the neckline (start to start): the collar is turned over, and the
/// seam welds.
#[test]
fn a_collar_sewn_right_to_wrong_is_turned_over_and_welds() {
    let front = panel(
        json!([[0.0, 0.0], [30.0, 0.0], [30.0, 40.0], [0.0, 40.0]]),
        [-15.0, 100.0, 15.0],
    );
    let collar = panel(
        json!([[0.0, 0.0], [30.0, 0.0], [30.0, 6.0], [0.0, 6.0]]),
        [-15.0, 134.0, 16.0],
    );
    let stitch = |orientation: &str| {
        json!([[
            { "panel": "front", "edge": 2 },
            { "panel": "collar", "edge": 0 },
            orientation
        ]])
    };
    let text = spec(
        json!({ "front": front, "collar": collar }),
        stitch("right_wrong"),
    );
    builds(&text).expect("the collar welds");
    // The same stitch end to start (GarmentCode's default) welds too.
    let text = spec(
        json!({ "front": front, "collar": collar }),
        stitch("right_right"),
    );
    builds(&text).expect("the collar welds end to start");
}
