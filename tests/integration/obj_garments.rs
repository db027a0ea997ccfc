//! OBJ garments: panels from texture islands, panels welded where a position has
//! several `vt`, seams from `l` elements (sewing edges), the errors of a bad `l`
//! (each naming the file and line) and plain single-piece files unchanged (the
//! per-frame export of a garment is in `obj_garment_export.rs`).
//!
//! The fixtures are written as strings into temporary files.

use std::path::PathBuf;

use drape::math::Vector2;
use drape::mesh::{self, ObjCloth, ObjError, Panels, Pattern};

/// A fresh empty directory in the temp dir, unique per process, test and call.
pub(crate) fn temp_dir(name: &str) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!(
        "drape-obj-garments-{}-{n}-{name}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// Writes `text` to `NAME.obj` in a fresh directory and loads it.
pub(crate) fn load(name: &str, text: &str) -> Result<ObjCloth, ObjError> {
    let dir = temp_dir(name);
    let path = dir.join(format!("{name}.obj"));
    std::fs::write(&path, text).expect("write fixture");
    let loaded = mesh::load_obj(&path, 1.0);
    std::fs::remove_dir_all(&dir).ok();
    loaded
}

/// The panels of a garment (panics for a plain cloth).
pub(crate) fn panels(cloth: &ObjCloth) -> &Panels {
    match &cloth.mesh.pattern {
        Pattern::Panels(p) => p,
        Pattern::PerVertex => panic!("expected a garment, got a plain cloth"),
    }
}

/// The 1-based number of the first line of `text` that starts with `prefix`.
pub(crate) fn line_of(text: &str, prefix: &str) -> usize {
    text.lines()
        .position(|l| l.starts_with(prefix))
        .expect("line")
        + 1
}

/// Two panels 0.1 m apart, each 1 m square in two rows of two triangles, in
/// the plane y = 0; `l` elements sew the front's right edge (x = 1) to the
/// back's left edge (x = 1.1), the middle one written back side first.
pub(crate) const TWO_PANELS: &str = "\
# Two panels with sewing edges between them.
o front
v 0 0 0
v 1 0 0
v 0 0 0.5
v 1 0 0.5
v 0 0 1
v 1 0 1
vt 0 0
vt 1 0
vt 0 0.5
vt 1 0.5
vt 0 1
vt 1 1
f 1/1 2/2 4/4
f 1/1 4/4 3/3
f 3/3 4/4 6/6
f 3/3 6/6 5/5
o back
v 1.1 0 0
v 2.1 0 0
v 1.1 0 0.5
v 2.1 0 0.5
v 1.1 0 1
v 2.1 0 1
f 7/1 8/2 10/4
f 7/1 10/4 9/3
f 9/3 10/4 12/6
f 9/3 12/6 11/5
l 2 7
l 9 4
l 6 11
";

/// The pairs the two-panel fixtures sew, in cloth vertices: the faces use the
/// front's vertices 1, 2, 4, 3, 6, 5 first (cloth vertices 0 to 5), then the
/// back's 7, 8, 10, 9, 12, 11 (6 to 11).
const TWO_PANEL_PAIRS: [[u32; 2]; 3] = [[1, 6], [2, 9], [4, 11]];

/// Checks the two-panel garment: panels `front` and `back`, one seam of three
/// pairs from the front's right edge to the back's left edge.
fn check_two_panels(cloth: &ObjCloth, first_l: usize) {
    let p = panels(cloth);
    assert_eq!(p.names, ["front", "back"]);
    assert_eq!(p.of_triangle, [0, 0, 0, 0, 1, 1, 1, 1]);
    assert_eq!(p.of_vertex, [0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1]);
    assert_eq!(p.seams.len(), 1, "{:?}", p.seams);
    let seam = &p.seams[0];
    assert_eq!(seam.name, format!("l{first_l}"));
    assert!(seam.is_open());
    assert_eq!(seam.pairs, TWO_PANEL_PAIRS);
    for &[a, b] in &seam.pairs {
        let (pa, pb) = (cloth.positions[a as usize], cloth.positions[b as usize]);
        assert_eq!(
            (pa.x, pb.x),
            (1.0, 1.1),
            "front's right edge to back's left"
        );
        assert_eq!(pa.z, pb.z);
    }
    assert_eq!(cloth.mesh.total_rest_area(), 2.0);
}

#[test]
fn two_panels_with_l_sewing_edges_read_as_two_panels_and_one_seam() {
    let cloth = load("two_panels", TWO_PANELS).expect("a two-panel garment loads");
    check_two_panels(&cloth, line_of(TWO_PANELS, "l "));
}

/// The same garment with the `v` lines in another order than the faces use
/// them, an unused `v`, a position given twice (the `l` names the copy), one
/// given with a homogeneous `w`, and `l` elements with negative (relative)
/// indices and `v/vt` vertices: the `l` indices reach the same cloth vertices.
#[test]
fn l_indices_name_the_cloth_vertices_of_their_positions_whatever_the_v_order() {
    let text = "\
v 1.1 0 0
v 2.1 0 0
v 1.1 0 0.5
v 9 9 9
v 2.1 0 0.5
v 1.1 0 1
v 2.1 0 1
vt 0 0
vt 1 0
vt 0 0.5
vt 1 0.5
vt 0 1
vt 1 1
o front
v 0 0 0
v 1 0 0
v 0 0 0.5
v 1 0 0.5
v 0 0 1
v 2 0 2 2
v 1 0 0.5
f 8/1 9/2 11/4
f 8/1 11/4 10/3
f 10/3 11/4 13/6
f 10/3 13/6 12/5
o back
f 1/1 2/2 5/4
f 1/1 5/4 3/3
f 3/3 5/4 7/6
f 3/3 7/6 6/5
l 9/2 1/1
l -1 3
l 6 -2
";
    let cloth = load("mapping", text).expect("the garment loads");
    check_two_panels(&cloth, line_of(text, "l "));
    assert_eq!(
        cloth.positions.len(),
        12,
        "the unused and the repeated `v` add none"
    );
}

/// A cylinder (radius 0.1 m, 16 segments around, 3 rows) cut open along one
/// line in its pattern: the vertices on the cut have `vt` u = 0 in the first
/// column of faces and u = the pattern's width in the last.
fn cylinder_obj(segments: usize, rows: usize) -> (String, f64, f64) {
    let (radius, height) = (0.1_f64, 0.3_f64);
    let chord = 2.0 * radius * (std::f64::consts::PI / segments as f64).sin();
    let mut text = String::from("# A cylinder welded along its seam.\no sleeve\n");
    for i in 0..=rows {
        for j in 0..segments {
            let angle = std::f64::consts::TAU * j as f64 / segments as f64;
            let z = height * i as f64 / rows as f64;
            let (x, y) = (radius * angle.cos(), radius * angle.sin());
            text += &format!("v {x} {y} {z}\n");
        }
    }
    for i in 0..=rows {
        for j in 0..=segments {
            let z = height * i as f64 / rows as f64;
            text += &format!("vt {} {z}\n", chord * j as f64);
        }
    }
    let v = |i: usize, j: usize| i * segments + j % segments + 1;
    let t = |i: usize, j: usize| i * (segments + 1) + j + 1;
    for j in 0..segments {
        for i in 0..rows {
            let [a, b, c, d] = [(i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)];
            let corner = |(i, j): (usize, usize)| format!("{}/{}", v(i, j), t(i, j));
            let [a, b, c, d] = [a, b, c, d].map(corner);
            text += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    (text, chord * segments as f64, height)
}

#[test]
fn cylinder_welded_at_its_seam_reads_as_one_welded_panel_with_per_corner_coordinates() {
    let (segments, rows) = (16, 3);
    let (text, width, height) = cylinder_obj(segments, rows);
    let cloth = load("cylinder", &text).expect("the cylinder loads");
    let m = &cloth.mesh;
    let p = panels(&cloth);
    assert_eq!(p.names, ["sleeve"]);
    assert!(p.seams.is_empty(), "a welded seam has no sewing pairs");
    assert_eq!(
        m.vertex_count(),
        segments * (rows + 1),
        "welded: one vertex per position"
    );
    // Only the top and bottom rings are boundary: the cut is one surface.
    let boundary = m.edges.iter().filter(|e| !e.is_interior()).count();
    assert_eq!(boundary, 2 * segments);
    // Each rest length is the 3D length (the pattern is an isometric
    // unrolling), across the cut too, where the corners differ.
    let worst = (0..m.edges.len())
        .map(|e| {
            let [a, b] = m.edges[e].vertices.map(|v| cloth.positions[v as usize]);
            (m.rest_length(e) - a.distance(b)).abs()
        })
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-12,
        "rest length off the 3D length by {worst:e} m"
    );
    // A vertex on the cut: u = 0 in the first column of faces, u = width in
    // the last; its home coordinate is the first face's.
    let on_cut = m.triangles[0]
        .into_iter()
        .find(|&v| cloth.positions[v as usize].y == 0.0 && cloth.positions[v as usize].z == 0.0)
        .expect("vertex at angle 0, z = 0");
    let mut us: Vec<f64> = (0..m.triangles.len())
        .filter(|&t| m.triangles[t].contains(&on_cut))
        .map(|t| m.corner_at(t, on_cut).x)
        .collect();
    us.sort_by(f64::total_cmp);
    us.dedup_by(|a, b| (*a - *b).abs() < 1e-15);
    assert_eq!(us.len(), 2, "{us:?}");
    assert_eq!(us[0], 0.0);
    assert!((us[1] - width).abs() < 1e-15, "{us:?} vs {width}");
    assert_eq!(m.material[on_cut as usize], Vector2::new(0.0, 0.0));
    let area = m.total_rest_area();
    let pattern = width * height;
    println!(
        "cylinder: rest area {area} m^2, pattern {pattern} m^2, deviation {:e}",
        area - pattern
    );
    assert!((area - pattern).abs() < 1e-14, "{area} vs {pattern}");
}

/// A 3 x 3 vertex panel (vertex 5 in its middle) and a separate triangle
/// (10 to 12), an unused vertex 13, then one `l` line.
fn panel_with(l: &str) -> String {
    let mut text = String::from("# A panel and a triangle.\n");
    for y in 0..3 {
        for x in 0..3 {
            text += &format!("v {x} {y} 0\n");
        }
    }
    text += "v 5 0 0\nv 6 0 0\nv 5 1 0\nv 9 9 0\n";
    for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let v = |dx: usize, dy: usize| (y + dy) * 3 + x + dx + 1;
        text += &format!("f {} {} {}\n", v(0, 0), v(1, 0), v(1, 1));
        text += &format!("f {} {} {}\n", v(0, 0), v(1, 1), v(0, 1));
    }
    text += "f 10 11 12\n";
    text + l + "\n"
}

/// Loads `panel_with(l)`: it must be refused on the `l` line, naming the file,
/// with a reason containing `says`.
fn refused_l(l: &str, says: &str) {
    let text = panel_with(l);
    let err = load("bad_l", &text).expect_err(l);
    let line = line_of(&text, "l ");
    assert!(
        matches!(err, ObjError::BadLine { line: n, .. } if n == line),
        "{l}: expected a bad line {line}, got {err:?}"
    );
    let message = err.to_string();
    assert!(message.contains(&format!("bad_l.obj:{line}:")), "{message}");
    assert!(message.contains(says), "{l}: says {says:?}: {message}");
    println!("{l}: {message}");
}

#[test]
fn l_endpoint_inside_a_panel_is_refused_naming_file_and_line() {
    // Sanity: the same file sewing two boundary vertices loads.
    let ok = load("good_l", &panel_with("l 3 10")).expect("boundary to boundary");
    assert_eq!(panels(&ok).seams.len(), 1);
    refused_l("l 5 10", "`l` vertex 5 is not a boundary vertex");
}

#[test]
fn l_along_an_existing_edge_is_refused_naming_file_and_line() {
    refused_l("l 1 2", "already joined by an edge of the mesh");
    refused_l("l 2 1", "already joined by an edge of the mesh");
    refused_l("l 1 1", "the same vertex of the cloth");
}

#[test]
fn l_index_out_of_range_is_refused_naming_file_and_line() {
    refused_l(
        "l 1 99",
        "`l` vertex `99` is out of range: the file has 13 vertices",
    );
    refused_l("l 1 -14", "`l` vertex `-14` is out of range");
    refused_l("l 0 1", "index 0; OBJ indices start at 1");
    refused_l("l 1 x", "`l` vertex `x` is not a vertex index");
    refused_l("l 1", "at least two vertices");
    refused_l("l 1 13", "`l` vertex 13 is used by no face");
}

/// Old files: one connected piece, one `vt` per position, no `l` (here in two
/// objects that share positions, and a fixture of `tests/data`) stay plain
/// cloths with one material point per vertex.
#[test]
fn single_piece_files_without_l_stay_plain_cloths() {
    let text = "\
o left
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
f 1/1 2/2 3/3
o right
f 1/1 3/3 4/4
";
    let cloth = load("two_objects", text).expect("loads");
    assert_eq!(cloth.mesh.pattern, Pattern::PerVertex);
    assert_eq!(cloth.mesh.total_rest_area(), 1.0);
    let fixture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    for name in ["quad_2x2_uv.obj", "quad_2x2_tilted.obj"] {
        let cloth = mesh::load_obj(&fixture.join(name), 1.0).expect(name);
        assert_eq!(cloth.mesh.pattern, Pattern::PerVertex, "{name}");
        let rebuilt = mesh::Mesh::new(cloth.mesh.material.clone(), cloth.mesh.triangles.clone())
            .expect("valid");
        assert_eq!(rebuilt, cloth.mesh, "{name}");
    }
}

/// Pieces without `vt` are the connected pieces of a flat mesh.
#[test]
fn flat_pieces_without_texcoords_are_panels_named_by_number() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 3 0 0\nv 4 0 0\nv 3 1 0\nf 1 2 3\nf 4 5 6\n";
    let cloth = load("flat_pieces", text).expect("two flat pieces load");
    let p = panels(&cloth);
    assert_eq!(p.names, ["piece1", "piece2"]);
    assert_eq!(p.of_triangle, [0, 1]);
    assert!((cloth.mesh.total_rest_area() - 1.0).abs() < 1e-12);
}
