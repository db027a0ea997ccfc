//! GarmentCode patterns: GarmentCode's four example specifications load and
//! build into garments; a panel lands where GarmentCode places it and faces
//! the way its outline winds; `drape garment` writes a scene that `drape run`
//! reads; and bad input is one line naming the file and the panel, edge,
//! stitch or body file.

use std::path::{Path, PathBuf};

use serde_json::Value;

use drape::garment;
use drape::garmentcode::{self, Pattern};
use drape::math::{Vector, Vector2, rotation_from_euler_deg};
use drape::spec::Garment;

use crate::bad_input::{drape, refused, temp_dir};

const EXAMPLES: [&str; 4] = ["dress_pencil", "hoody_mean", "js_mean_all", "shirt_mean"];

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/garmentcode")
        .join(format!("{name}_specification.json"))
}

fn json(name: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(example(name)).expect("read")).expect("json")
}

fn built(pattern: &Pattern) -> garment::BuiltGarment {
    garment::build(&Garment {
        panels: pattern.panels.clone(),
        seams: pattern.seams.clone(),
        holds: Vec::new(),
        max_edge: 0.03,
    })
    .expect("the garment builds")
}

#[test]
fn the_four_garmentcode_examples_load_and_build_with_every_stitch_a_seam() {
    for name in EXAMPLES {
        let pattern = garmentcode::load(&example(name)).expect("loads");
        let spec = json(name);
        let stitches = spec["pattern"]["stitches"]
            .as_array()
            .expect("stitches")
            .len();
        let panels = spec["pattern"]["panels"].as_object().expect("panels").len();
        assert_eq!(pattern.panels.len(), panels, "{name}");
        assert_eq!(pattern.seams.len(), stitches, "{name}");
        let g = built(&pattern);
        let seams = g.mesh.panels().expect("panels").seams.len();
        println!(
            "{name}: {panels} panels, {stitches} stitches, {} gathered, {} vertices",
            pattern
                .seams
                .iter()
                .filter(|s| s.gather == drape::spec::Gather::Any)
                .count(),
            g.mesh.vertex_count()
        );
        assert_eq!(seams, stitches, "{name}");
    }
}

/// Where GarmentCode puts corner `c` of panel `name`: R p + t, in metres.
fn garmentcode_corner(spec: &Value, name: &str, c: usize) -> Vector {
    let p = &spec["pattern"]["panels"][name];
    let f = |v: &Value| v.as_f64().expect("number");
    let corner = &p["vertices"][c];
    let local = Vector::new(f(&corner[0]), f(&corner[1]), 0.0);
    let t = &p["translation"];
    let r = &p["rotation"];
    let rotation = rotation_from_euler_deg([f(&r[0]), f(&r[1]), f(&r[2])]);
    (rotation * local + Vector::new(f(&t[0]), f(&t[1]), f(&t[2]))) / 100.0
}

#[test]
fn every_panel_corner_starts_where_garmentcode_places_it_and_faces_as_its_outline_winds() {
    let spec = json("shirt_mean");
    let pattern = garmentcode::load(&example("shirt_mean")).expect("loads");
    let g = built(&pattern);
    let panels = g.mesh.panels().expect("panels");
    for (p, panel) in pattern.panels.iter().enumerate() {
        let count = panel.outline.len();
        for c in 0..count {
            let want = garmentcode_corner(&spec, &panel.name, c);
            let corner = Vector2::from_array(panel.outline[c]);
            let v = (0..g.mesh.vertex_count())
                .find(|&v| {
                    panels.of_vertex[v] as usize == p && g.mesh.material[v].distance(corner) < 1e-12
                })
                .expect("a vertex at the corner");
            let got = g.positions[v];
            assert!(
                got.distance(want) < 1e-9,
                "{} corner {c}: {got} != {want}",
                panel.name
            );
        }
        // The panel's triangles face the way GarmentCode's outline winds:
        // along +z for the front panels (counter-clockwise), -z for the back.
        let t = panels
            .of_triangle
            .iter()
            .position(|&q| q as usize == p)
            .expect("a triangle");
        let [a, b, c] = g.mesh.triangles[t].map(|v| g.positions[v as usize]);
        let normal = (b - a).cross(c - a);
        let json_corners: Vec<[f64; 2]> = (0..count)
            .map(|k| {
                let q = &spec["pattern"]["panels"][&panel.name]["vertices"][k];
                [q[0].as_f64().expect("x"), q[1].as_f64().expect("y")]
            })
            .collect();
        let winding: f64 = (0..count)
            .map(|k| {
                let (u, w) = (json_corners[k], json_corners[(k + 1) % count]);
                u[0] * w[1] - w[0] * u[1]
            })
            .sum();
        let r = &spec["pattern"]["panels"][&panel.name]["rotation"];
        let f = |v: &Value| v.as_f64().expect("number");
        let facing = rotation_from_euler_deg([f(&r[0]), f(&r[1]), f(&r[2])]) * Vector::Z;
        assert!(
            normal.dot(facing) * winding > 0.0,
            "{} faces against its outline's winding",
            panel.name
        );
    }
}

/// A temp dir with a small y-up box body (`body.obj`, 0.4 x 1.7 x 0.3 m) and
/// the shirt's specification edited by `edit`.
fn case(name: &str, edit: impl Fn(&mut Value)) -> PathBuf {
    let dir = temp_dir(name);
    let mut spec = json("shirt_mean");
    edit(&mut spec);
    std::fs::write(dir.join("shirt.json"), spec.to_string()).expect("write");
    // A closed 0.5 m cube (y up) 2 m below the garment.
    let body = box_obj([0.0, -3.0, 0.0], [0.5, -2.5, 0.5]);
    std::fs::write(dir.join("body.obj"), body).expect("write body");
    dir
}

#[test]
fn bad_patterns_are_one_line_naming_the_file_and_the_panel_edge_or_stitch() {
    type Edit = Box<dyn Fn(&mut Value)>;
    let cases: Vec<(&str, Edit, Vec<&str>)> = vec![
        (
            "curvature",
            Box::new(|s| {
                s["pattern"]["panels"]["left_btorso"]["edges"][1]["curvature"]["type"] =
                    "spline".into()
            }),
            vec![
                "panel `left_btorso`, edge 1",
                "unknown curvature type \"spline\"",
            ],
        ),
        (
            "stitch-panel",
            Box::new(|s| s["pattern"]["stitches"][3][0]["panel"] = "collar".into()),
            vec!["stitch 3", "there is no panel `collar`"],
        ),
        (
            "stitch-edge",
            Box::new(|s| s["pattern"]["stitches"][4][1]["edge"] = 9.into()),
            vec!["stitch 4", "edges 0 to 6, not 9"],
        ),
        (
            "zero-length",
            Box::new(|s| {
                let v = s["pattern"]["panels"]["left_ftorso"]["vertices"][1].clone();
                s["pattern"]["panels"]["left_ftorso"]["vertices"][2] = v;
            }),
            vec!["panel `left_ftorso`, edge 1", "zero length"],
        ),
        (
            "crossing",
            Box::new(|s| {
                let v = &mut s["pattern"]["panels"]["left_ftorso"]["vertices"];
                v.as_array_mut().expect("corners").swap(1, 4);
            }),
            vec!["panel `left_ftorso`", "crosses itself", "edges 0 and 4"],
        ),
    ];
    for (name, edit, needles) in cases {
        let dir = case(name, edit);
        let out = drape(
            &dir,
            &["garment", "shirt.json", "--body", "body.obj", "--no-record"],
        );
        let mut all = vec!["shirt.json"];
        all.extend(needles);
        refused(&out, 1, &all);
        std::fs::remove_dir_all(&dir).ok();
    }
}

#[test]
fn bad_bodies_are_one_line_naming_the_body_file() {
    let dir = case("bodies", |_| {});
    std::fs::write(dir.join("empty.obj"), "").expect("write");
    std::fs::write(dir.join("points.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\n").expect("write");
    for (body, scale, needle) in [
        ("missing.obj", "1", "body missing.obj: cannot read it"),
        ("empty.obj", "1", "body empty.obj: the file has no faces"),
        ("points.obj", "1", "body points.obj: the file has no faces"),
        ("body.obj", "0.01", "its largest extent is 0.005 m"),
        ("body.obj", "100", "its largest extent is 50.000 m"),
    ] {
        let args = [
            "garment",
            "shirt.json",
            "--body",
            body,
            "--body-scale",
            scale,
            "--no-record",
        ];
        refused(&drape(&dir, &args), 1, &[needle]);
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `drape garment` of the case's shirt on its body for 0.02 s, writing
/// `shirt.toml`, with `extra` arguments.
fn write_scene(dir: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "garment",
        "shirt.json",
        "--body",
        "body.obj",
        "--write-scene",
        "shirt.toml",
        "--no-record",
        "-q",
        "--set",
        "simulation.duration=0.02",
    ];
    args.extend_from_slice(extra);
    drape(dir, &args)
}

#[test]
fn the_written_scene_loads_as_a_scene_with_every_panel_curve_and_seam() {
    let dir = case("write-scene", |_| {});
    let out = write_scene(&dir, &[]);
    assert_eq!(out.status.code(), Some(0));
    let scene = drape::scene::load_scene_file(&dir.join("shirt.toml"), &[]).expect("scene");
    let pattern = garmentcode::load(&dir.join("shirt.json")).expect("pattern");
    assert_eq!(scene.panel.len(), pattern.panels.len());
    assert_eq!(scene.seam.len(), pattern.seams.len());
    for (table, panel) in scene.panel.iter().zip(&pattern.panels) {
        assert_eq!(table.curves, panel.curves, "{}", panel.name);
        assert_eq!(table.outline, panel.outline, "{}", panel.name);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_shipped_garmentcode_scenes_load_and_build() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/garmentcode");
    let mut built_scenes = 0;
    for entry in std::fs::read_dir(&dir).expect("scenes/garmentcode") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        let scene = drape::scene::load_scene_file(&path, &[])
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let spec = scene.resolve().expect("resolved");
        drape::sim::build(&spec).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        built_scenes += 1;
    }
    assert_eq!(built_scenes, 4, "shirt, hoody, dress and jumpsuit");
}

/// A closed axis-aligned box as an OBJ file, corners `lo` and `hi`.
fn box_obj(lo: [f64; 3], hi: [f64; 3]) -> String {
    let mut obj = String::new();
    for k in 0..8 {
        let pick = |axis: usize| {
            if (k >> axis) & 1 == 1 {
                hi[axis]
            } else {
                lo[axis]
            }
        };
        obj.push_str(&format!("v {} {} {}\n", pick(0), pick(1), pick(2)));
    }
    for f in [
        [1, 3, 4, 2],
        [5, 6, 8, 7],
        [1, 2, 6, 5],
        [3, 7, 8, 4],
        [1, 5, 7, 3],
        [2, 4, 8, 6],
    ] {
        obj.push_str(&format!("f {} {} {} {}\n", f[0], f[1], f[2], f[3]));
    }
    obj
}

#[test]
fn a_panel_placed_inside_the_body_is_moved_out_along_its_normal_or_refused_beyond_150_mm() {
    let dir = case("inside", |_| {});
    // The shirt's left front panel lies in the plane z = 0.25 m (y up); this
    // box's front face is 20 mm in front of it, over part of the panel.
    let body = box_obj([0.05, 1.1, 0.0], [0.15, 1.2, 0.27]);
    std::fs::write(dir.join("body.obj"), body).expect("write body");
    let out = write_scene(&dir, &[]);
    assert_eq!(out.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let moved: Vec<&str> = stderr.lines().filter(|l| l.contains("moved")).collect();
    assert_eq!(
        moved,
        [
            "shirt.json: panel `left_ftorso` starts 20.0 mm inside the body: moved 25.0 mm out \
          along its normal"
        ]
    );
    // The written scene starts outside the body; the pattern as GarmentCode
    // places it does not.
    let scene = drape::scene::load_scene_file(&dir.join("shirt.toml"), &[]).expect("scene");
    let spec = scene.resolve().expect("resolved");
    assert_eq!(drape::sim::panels_inside(&spec).expect("built"), []);
    let mut unmoved = spec.clone();
    let pattern = garmentcode::load(&dir.join("shirt.json")).expect("pattern");
    let drape::spec::ClothMesh::Panels(garment) = &mut unmoved.cloth.mesh else {
        panic!("a garment");
    };
    garment.panels = pattern.panels.clone();
    let inside = drape::sim::panels_inside(&unmoved).expect("built");
    let names: Vec<&str> = inside.iter().map(|p| p.panel.as_str()).collect();
    assert_eq!(names, ["left_ftorso"]);
    println!("as placed: {:.2} mm inside", 1e3 * inside[0].inside.depth);
    assert!((inside[0].inside.depth - 0.02).abs() < 1e-9);
    // Deep in a box whose nearest faces meet the panel edge-on (the panel's
    // middle is 43 mm from the box's sides and 200 mm behind its front), the
    // panel would move further than 150 mm: refused.
    let deep = box_obj([0.05, 1.1, 0.0], [0.15, 1.2, 0.45]);
    std::fs::write(dir.join("body.obj"), deep).expect("write body");
    let out = drape(
        &dir,
        &["garment", "shirt.json", "--body", "body.obj", "--no-record"],
    );
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let line = stderr.trim_end();
    assert!(
        line.starts_with("error: shirt.json: panel `left_ftorso` is ")
            && line.ends_with(
                " mm inside the body, and moving it out along its normal would take it more \
                 than 150 mm from where the pattern places it; place it around the body"
            ),
        "{line}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// GarmentCode's measurements of `mean_all` that place the planes, cm.
const MEASUREMENTS: &str = "body:\n  armscye_depth: 12.8679\n  head_l: 26.3262\n  height: 171.99\n  \
                            neck_w: 18.9328\n  waist_line: 36.8913\n";

#[test]
fn labelled_edges_become_attachments_at_the_planes_the_body_measurements_give() {
    let dir = case("labels", |s| {
        let edges = &mut s["pattern"]["panels"]["left_ftorso"]["edges"];
        edges[0]["label"] = "lower_interface".into();
        edges[1]["label"] = "hem".into();
    });
    let write = |extra: &[&str]| {
        let out = write_scene(&dir, extra);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let scene = drape::scene::load_scene_file(&dir.join("shirt.toml"), &[]).expect("scene");
        (scene, String::from_utf8_lossy(&out.stderr).into_owned())
    };
    // No measurements beside the body: nothing held, and a note says so.
    let (scene, stderr) = write(&[]);
    assert!(scene.attachment.is_empty());
    assert!(stderr.contains("labelled edges are not held"), "{stderr}");
    // body.yaml beside body.obj: one attachment, its plane at the waist, lowered
    // by as much as the body (a cube from y = -3 m) reaches below the floor.
    std::fs::write(dir.join("body.yaml"), MEASUREMENTS).expect("write");
    let (scene, _) = write(&[]);
    assert_eq!(scene.attachment.len(), 1, "only lower_interface is held");
    let a = &scene.attachment[0];
    assert_eq!(a.name, "lower_interface");
    assert_eq!(a.sides.len(), 1);
    assert_eq!(
        (a.sides[0].panel.as_str(), a.sides[0].side),
        ("left_ftorso", 1)
    );
    let waist = (171.99 - 26.3262 - 36.8913) / 100.0;
    assert!((a.point[2] - (waist - 3.0)).abs() < 1e-9, "{:?}", a.point);
    assert_eq!(a.normal, [0.0, 0.0, 1.0]);
    assert_eq!(a.stiffness, 1000.0);
    assert!((a.release.expect("a release time") - 400.0 / 60.0).abs() < 1e-12);
    // --no-hold: nothing held, whatever the measurements.
    let (scene, _) = write(&["--no-hold"]);
    assert!(scene.attachment.is_empty());
    // A measurements file without a height is refused, naming it.
    std::fs::write(dir.join("bad.yaml"), "body:\n  head_l: 26\n").expect("write");
    let args = [
        "garment",
        "shirt.json",
        "--body",
        "body.obj",
        "--body-measurements",
        "bad.yaml",
        "--no-record",
    ];
    refused(
        &drape(&dir, &args),
        1,
        &["body measurements bad.yaml", "`height`"],
    );
    std::fs::remove_dir_all(&dir).ok();
}
