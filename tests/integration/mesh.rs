//! Mesh module: OBJ loading (texture coordinates, planar rest shapes), every refused
//! input with its specific error (through `Mesh::new`, OBJ files and `drape check`),
//! and the rectangle and disk generators.
//!
//! OBJ fixtures live in `tests/data/`; each starts with a comment saying what it is.

use std::path::{Path, PathBuf};
use std::process::Command;

use drape::math::{Vector, Vector2};
use drape::mesh::{self, Mesh, MeshError, ObjError};
use drape::scene::DiagonalPattern;

/// A fixture in `tests/data/`.
fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// A fresh empty directory in the temp dir, unique per process, test and call.
fn temp_dir(name: &str) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir =
        std::env::temp_dir().join(format!("drape-mesh-test-{}-{n}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// Loads a fixture that must be refused; returns the error.
fn refused(name: &str) -> ObjError {
    let err = mesh::load_obj(&data(name), 1.0).expect_err(name);
    assert!(
        err.to_string().contains(name),
        "the message names the file: {err}"
    );
    err
}

/// The mesh error inside an `ObjError::Mesh`.
fn mesh_error(err: ObjError) -> MeshError {
    match err {
        ObjError::Mesh { source, .. } => source,
        other => panic!("expected a mesh error, got {other:?}"),
    }
}

fn v2(points: &[[f64; 2]]) -> Vec<Vector2> {
    points.iter().map(|&[u, v]| Vector2::new(u, v)).collect()
}

/// Area of a triangle in 3D.
fn area3(p: &[Vector], tri: &[u32; 3]) -> f64 {
    let [a, b, c] = tri.map(|v| p[v as usize]);
    0.5 * (b - a).cross(c - a).length()
}

// ---------------------------------------------------------------- OBJ loading

#[test]
fn obj_texcoords_times_uv_scale_become_material_and_positions_are_kept() {
    let cloth = mesh::load_obj(&data("quad_2x2_uv.obj"), 4.0).expect("load");
    let m = &cloth.mesh;
    assert_eq!(m.vertex_count(), 9);
    assert_eq!(m.triangles.len(), 8, "four quads, triangulated");
    // vt = (x, y) / 4, so with uv_scale = 4 every material point is the position's (x, y).
    for (p, u) in cloth.positions.iter().zip(&m.material) {
        assert_eq!(*u, p.truncate(), "material = vt * uv_scale");
    }
    // Positions come from the file untouched, the bulge included.
    let mut z: Vec<f64> = cloth.positions.iter().map(|p| p.z).collect();
    z.sort_by(f64::total_cmp);
    assert_eq!(z, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.3]);
    assert!(cloth.positions.contains(&Vector::new(1.0, 1.0, 0.3)));
    // Rest area from the texture coordinates (2 x 2 m), not from the bulging 3D shape.
    assert!((m.total_rest_area() - 4.0).abs() < 1e-12);
    let area_3d: f64 = m.triangles.iter().map(|t| area3(&cloth.positions, t)).sum();
    assert!(area_3d > 4.0 + 1e-3, "3D area {area_3d}");

    // uv_scale scales areas by its square.
    let half = mesh::load_obj(&data("quad_2x2_uv.obj"), 2.0).expect("load");
    assert!((half.mesh.total_rest_area() - 1.0).abs() < 1e-12);
}

#[test]
fn flat_obj_without_texcoords_rests_in_its_own_plane() {
    let cloth = mesh::load_obj(&data("quad_2x2_tilted.obj"), 1.0).expect("load");
    let m = &cloth.mesh;
    assert_eq!((m.vertex_count(), m.triangles.len()), (9, 8));
    let area_3d: f64 = m.triangles.iter().map(|t| area3(&cloth.positions, t)).sum();
    let expected = 4.0 * 1.25_f64.sqrt();
    assert!((area_3d - expected).abs() < 1e-12, "3D area {area_3d}");
    assert!(
        (m.total_rest_area() - expected).abs() < 1e-12,
        "rest area {} vs 3D area {expected}",
        m.total_rest_area()
    );
    // Every rest edge length equals its 3D length: an isometric flattening.
    for (e, edge) in m.edges.iter().enumerate() {
        let [a, b] = edge.vertices.map(|v| cloth.positions[v as usize]);
        assert!((m.rest_length(e) - a.distance(b)).abs() < 1e-12);
    }
    // Triangles are counter-clockwise in material space.
    assert!((0..m.triangles.len()).all(|t| m.rest_area(t) > 0.0));
}

#[test]
fn non_planar_obj_without_texcoords_is_not_planar() {
    let err = refused("bent_no_uv.obj");
    let ObjError::NotPlanar { distance, .. } = err else {
        panic!("expected NotPlanar, got {err:?}");
    };
    assert!(distance > 0.1, "off-plane distance {distance}");
}

/// A position with two texture coordinates is one vertex welded across two
/// panels (formerly refused as a UV seam).
#[test]
fn one_position_with_two_texcoords_is_welded_across_two_panels() {
    let cloth = mesh::load_obj(&data("seam.obj"), 1.0).expect("seam.obj loads");
    let m = &cloth.mesh;
    let panels = m.panels().expect("a garment");
    assert_eq!(panels.names, ["piece1", "piece2"]);
    assert_eq!(m.vertex_count(), 4);
    assert_eq!(m.corner_at(0, 0), Vector2::new(0.0, 0.0));
    assert_eq!(m.corner_at(1, 0), Vector2::new(0.5, 0.5));
    assert_eq!(
        m.material[0],
        Vector2::new(0.0, 0.0),
        "home: the first face's"
    );
    assert!((m.total_rest_area() - 0.75).abs() < 1e-15);
}

#[test]
fn texcoords_on_some_faces_only_is_partial() {
    let err = refused("partial_uv.obj");
    assert!(
        matches!(err, ObjError::PartialTexcoords { .. }),
        "expected PartialTexcoords, got {err:?}"
    );
}

/// Regression: tobj fills a corner without `vt` with another corner's `vt`, so this
/// file used to be refused as a UV seam; the loader now reads the face corners itself.
#[test]
fn partial_texcoords_in_one_object_are_reported_as_partial_not_as_a_seam() {
    let err = refused("partial_uv_one_object.obj");
    assert!(
        matches!(err, ObjError::PartialTexcoords { .. }),
        "got {err:?}"
    );
}

/// Regression: the fold check used to depend on face winding, refusing a valid kite
/// whose two faces are wound the same way.
#[test]
fn fold_check_ignores_winding_and_accepts_a_kite_wound_inconsistently() {
    let pts = v2(&[[0.0, 0.0], [1.0, 0.0], [0.5, 1.0], [0.5, -1.0]]);
    let m = Mesh::new(pts, vec![[0, 1, 2], [0, 1, 3]]).expect("a kite is a valid rest shape");
    assert!((m.total_rest_area() - 1.0).abs() < 1e-12);
}

/// Regression: a real fold wound "consistently" by accident used to be accepted
/// with its overlap counted twice.
#[test]
fn fold_check_refuses_a_real_fold_whatever_the_winding() {
    let pts = v2(&[[0.0, 0.0], [1.0, 0.0], [0.5, 1.0], [0.5, 0.3]]);
    let err = Mesh::new(pts, vec![[0, 1, 2], [0, 1, 3]]);
    assert_eq!(err, Err(MeshError::Folded { a: 0, b: 1 }));
}

/// Regression: the plane of a flat OBJ without `vt` was fitted from summed face
/// normals, which cancel when faces are wound inconsistently.
#[test]
fn flat_obj_with_a_reversed_face_still_gets_its_planar_rest_shape() {
    let dir = std::env::temp_dir().join(format!("drape-mesh-reversed-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("square.obj");
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 4 3\n",
    )
    .unwrap();
    let cloth = drape::mesh::load_obj(&path, 1.0).expect("a flat square loads");
    assert!((cloth.mesh.total_rest_area() - 1.0).abs() < 1e-12);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn missing_garbage_and_empty_obj_files_are_read_errors_naming_the_file() {
    let missing = mesh::load_obj(&data("no_such_file.obj"), 1.0).expect_err("missing");
    assert!(matches!(missing, ObjError::Read { .. }), "{missing:?}");
    assert!(
        missing.to_string().contains("no_such_file.obj"),
        "{missing}"
    );
    let garbage = refused("garbage.obj");
    assert!(matches!(garbage, ObjError::Read { .. }), "{garbage:?}");
    let dir = temp_dir("empty");
    let empty = dir.join("empty.obj");
    std::fs::write(&empty, "# nothing here\n").unwrap();
    let err = mesh::load_obj(&empty, 1.0).expect_err("an empty OBJ has no cloth");
    assert!(err.to_string().contains("empty.obj"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn obj_with_three_triangles_on_an_edge_is_non_manifold() {
    let err = mesh_error(refused("nonmanifold_edge.obj"));
    assert!(
        matches!(err, MeshError::NonManifoldEdge { count: 3, .. }),
        "{err:?}"
    );
}

#[test]
fn obj_bow_tie_is_a_non_manifold_vertex() {
    let err = mesh_error(refused("bowtie.obj"));
    assert!(
        matches!(err, MeshError::NonManifoldVertex { fans: 2, .. }),
        "{err:?}"
    );
}

/// Two separate pieces are two panels (formerly refused as disconnected).
#[test]
fn obj_in_two_pieces_is_two_panels() {
    let cloth = mesh::load_obj(&data("two_pieces.obj"), 1.0).expect("loads");
    let panels = cloth.mesh.panels().expect("a garment");
    assert_eq!(panels.names, ["piece1", "piece2"]);
    assert_eq!(panels.of_triangle, [0, 1]);
    assert!(panels.seams.is_empty());
}

#[test]
fn obj_with_a_zero_area_triangle_is_degenerate() {
    let err = mesh_error(refused("degenerate.obj"));
    assert!(
        matches!(err, MeshError::Degenerate { triangle: 1, .. }),
        "{err:?}"
    );
}

#[test]
fn mesh_new_refuses_empty_and_out_of_range_input() {
    assert_eq!(Mesh::new(Vec::new(), Vec::new()), Err(MeshError::Empty));
    let pts = v2(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    assert_eq!(
        Mesh::new(pts, vec![[0, 5, 2]]),
        Err(MeshError::BadIndex {
            triangle: 0,
            vertex: 5,
            count: 3
        })
    );
}

#[test]
fn mesh_new_refuses_collinear_and_repeated_corners() {
    let pts = v2(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]);
    assert!(matches!(
        Mesh::new(pts, vec![[0, 1, 2]]),
        Err(MeshError::Degenerate { triangle: 0, .. })
    ));
    let pts = v2(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    assert!(matches!(
        Mesh::new(pts, vec![[0, 1, 1]]),
        Err(MeshError::Degenerate { triangle: 0, .. })
    ));
}

#[test]
fn mesh_new_refuses_non_manifold_and_disconnected_meshes() {
    // Three triangles on the edge 0-1.
    let pts = v2(&[[0.0, 0.0], [1.0, 0.0], [0.5, 1.0], [0.5, -1.0], [0.5, 2.0]]);
    let err = Mesh::new(pts, vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
    assert!(
        matches!(
            err,
            Err(MeshError::NonManifoldEdge {
                a: 0,
                b: 1,
                count: 3
            })
        ),
        "{err:?}"
    );
    // A bow tie at vertex 0.
    let pts = v2(&[
        [0.0, 0.0],
        [1.0, 0.5],
        [1.0, -0.5],
        [-1.0, 0.5],
        [-1.0, -0.5],
    ]);
    let err = Mesh::new(pts, vec![[0, 2, 1], [0, 3, 4]]);
    assert_eq!(
        err,
        Err(MeshError::NonManifoldVertex { vertex: 0, fans: 2 })
    );
    // Two separate triangles.
    let pts = v2(&[
        [0.0, 0.0],
        [1.0, 0.0],
        [0.0, 1.0],
        [5.0, 0.0],
        [6.0, 0.0],
        [5.0, 1.0],
    ]);
    let err = Mesh::new(pts, vec![[0, 1, 2], [3, 4, 5]]);
    assert_eq!(err, Err(MeshError::Disconnected { components: 2 }));
}

#[test]
fn mesh_new_refuses_an_unused_vertex() {
    let pts = v2(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [5.0, 5.0]]);
    let err = Mesh::new(pts, vec![[0, 1, 2]]);
    assert_eq!(err, Err(MeshError::UnusedVertex { vertex: 3 }));
}

#[test]
fn mesh_new_refuses_a_rest_shape_folded_over_an_edge() {
    // Consistently wound (the edge 0-1 is traversed both ways), but vertex 3 lies on
    // the same side of the edge as vertex 2: the second triangle folds back over the first.
    let pts = v2(&[[0.0, 0.0], [1.0, 0.0], [0.5, 1.0], [0.5, 0.3]]);
    let err = Mesh::new(pts, vec![[0, 1, 2], [1, 0, 3]]);
    assert_eq!(err, Err(MeshError::Folded { a: 0, b: 1 }));
}

#[test]
fn mesh_new_flips_a_mirrored_material_map_counter_clockwise() {
    let pts = v2(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    let m = Mesh::new(pts, vec![[0, 2, 1], [0, 3, 2]]).expect("clockwise square");
    assert!((0..2).all(|t| m.rest_area(t) > 0.0));
    assert!((m.total_rest_area() - 1.0).abs() < 1e-15);
}

// ---------------------------------------------------------------- drape check on OBJ scenes

/// Writes a scene with `shape = "obj"` and `path = "cloth.obj"` (a copy of the fixture
/// next to it) into a fresh directory and runs `drape check` on it.
fn check_obj_scene(fixture: &str) -> (Option<i32>, String, String) {
    let dir = temp_dir("check");
    std::fs::copy(data(fixture), dir.join("cloth.obj")).expect("copy fixture");
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        "name = \"obj_cloth\"\n\n[simulation]\nduration = 0.1\n\n[cloth]\nshape = \"obj\"\n\
         path = \"cloth.obj\"\n\n[material]\ndensity = 0.15\nstretch = 200.0\n",
    )
    .expect("write scene");
    // Run from elsewhere: the OBJ path must resolve relative to the scene file.
    let out = Command::new(env!("CARGO_BIN_EXE_drape"))
        .arg("check")
        .arg(&scene)
        .current_dir(std::env::temp_dir())
        .output()
        .expect("run drape check");
    std::fs::remove_dir_all(&dir).ok();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    (out.status.code(), stdout, stderr)
}

#[test]
fn drape_check_accepts_a_flat_obj_cloth_next_to_the_scene() {
    let (code, stdout, stderr) = check_obj_scene("quad_2x2_tilted.obj");
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("9 vertices, 8 triangles"), "{stdout}");
}

#[test]
fn drape_check_reports_bad_obj_meshes_with_exit_1() {
    for (fixture, says) in [
        (
            "nonmanifold_edge.obj",
            "the edge between vertices 0 and 1 has 3 triangles",
        ),
        (
            "bowtie.obj",
            "the triangles around vertex 0 form 2 separate fans",
        ),
        ("degenerate.obj", "triangle 1 is degenerate"),
        ("bent_no_uv.obj", "is not flat"),
    ] {
        let (code, stdout, stderr) = check_obj_scene(fixture);
        assert_eq!(code, Some(1), "{fixture}: {stderr}");
        assert!(stdout.is_empty(), "{fixture}: nothing on stdout: {stdout}");
        let line = stderr.trim_end();
        assert!(line.starts_with("error: "), "{fixture}: {stderr}");
        assert_eq!(line.lines().count(), 1, "{fixture}: one line: {stderr}");
        assert!(
            line.contains("cloth.obj"),
            "{fixture}: names the file: {stderr}"
        );
        assert!(line.contains(says), "{fixture}: says {says:?}: {stderr}");
        assert_eq!(
            line.matches(says).count(),
            1,
            "{fixture}: the reason is given once: {stderr}"
        );
    }
}

// ---------------------------------------------------------------- generators

#[test]
fn rectangle_has_resolution_segments_along_the_longer_side() {
    for pattern in [DiagonalPattern::Alternating, DiagonalPattern::Regular] {
        let m = mesh::rectangle(2.0, 1.0, 8, pattern).expect("rectangle");
        assert_eq!(m.vertex_count(), 9 * 5, "{pattern:?}");
        let (lo, hi) = m.material_bounds();
        assert_eq!((lo, hi), (Vector2::new(-1.0, -0.5), Vector2::new(1.0, 0.5)));
        // Tall instead of wide: the segments follow the longer side.
        let tall = mesh::rectangle(1.0, 2.0, 8, pattern).expect("rectangle");
        let (lo, hi) = tall.material_bounds();
        assert_eq!((lo, hi), (Vector2::new(-0.5, -1.0), Vector2::new(0.5, 1.0)));
        assert_eq!(tall.vertex_count(), 5 * 9);
        // A very thin strip keeps one segment across.
        let strip = mesh::rectangle(10.0, 0.1, 8, pattern).expect("strip");
        assert_eq!(strip.vertex_count(), 9 * 2);
    }
}

#[test]
fn short_side_segments_set_the_cells_across_the_shorter_side() {
    for pattern in [DiagonalPattern::Alternating, DiagonalPattern::Regular] {
        // A 5 x 2 strip, 40 segments along: 16 across by default (square cells).
        let square = mesh::rectangle_cells(5.0, 2.0, 40, None, pattern).expect("strip");
        assert_eq!(square.vertex_count(), 41 * 17, "{pattern:?}");
        assert_eq!(
            square.material,
            mesh::rectangle(5.0, 2.0, 40, pattern)
                .expect("strip")
                .material
        );
        let thin = mesh::rectangle_cells(5.0, 2.0, 40, Some(2), pattern).expect("strip");
        assert_eq!(thin.vertex_count(), 41 * 3, "{pattern:?}");
        assert_eq!(thin.triangles.len(), 2 * 40 * 2);
        assert!((thin.total_rest_area() - 10.0).abs() < 1e-12);
        // The cells are 0.125 along and 1.0 across: every edge is one of those,
        // or a diagonal, and the longest is the diagonal.
        let longest = (0..thin.triangles.len())
            .flat_map(|t| {
                let [a, b, c] = thin.triangles[t].map(|i| thin.material[i as usize]);
                [a.distance(b), b.distance(c), c.distance(a)]
            })
            .fold(0.0, f64::max);
        assert!((longest - (1.0f64 + 0.125 * 0.125).sqrt()).abs() < 1e-12);
        // Tall: the shorter side is u.
        let tall = mesh::rectangle_cells(2.0, 5.0, 40, Some(1), pattern).expect("tall");
        assert_eq!(tall.vertex_count(), 2 * 41, "{pattern:?}");
        let (lo, hi) = tall.material_bounds();
        assert_eq!((lo, hi), (Vector2::new(-1.0, -2.5), Vector2::new(1.0, 2.5)));
    }
}

#[test]
fn rectangle_is_a_manifold_disk_with_both_diagonal_patterns() {
    for pattern in [DiagonalPattern::Alternating, DiagonalPattern::Regular] {
        let (nx, ny) = (8usize, 4usize);
        let m = mesh::rectangle(2.0, 1.0, 8, pattern).expect("rectangle");
        assert_eq!(m.triangles.len(), 2 * nx * ny);
        assert!((m.total_rest_area() - 2.0).abs() < 1e-12);
        assert!((0..m.triangles.len()).all(|t| m.rest_area(t) > 0.0));
        let boundary = m.edges.iter().filter(|e| !e.is_interior()).count();
        assert_eq!(
            boundary,
            2 * (nx + ny),
            "{pattern:?}: boundary is the rectangle"
        );
        // Euler characteristic of a disk: V - E + F = 1.
        let euler = m.vertex_count() as i64 - m.edges.len() as i64 + m.triangles.len() as i64;
        assert_eq!(euler, 1, "{pattern:?}");
        // Each interior edge's two triangles lie on opposite sides of it.
        for e in m.edges.iter().filter(|e| e.is_interior()) {
            let [a, b] = e.vertices.map(|v| m.material[v as usize]);
            let side = |t: u32| (b - a).perp_dot(m.material[m.opposite_vertex(t, e) as usize] - a);
            assert!(side(e.triangles[0]) * side(e.triangles[1]) < 0.0, "{e:?}");
        }
    }
}

/// Smallest interior angle of the triangle, degrees.
fn min_angle_deg(m: &Mesh, t: usize) -> f64 {
    let [a, b, c] = m.triangles[t].map(|v| m.material[v as usize]);
    let angle = |p: Vector2, q: Vector2, r: Vector2| (q - p).angle_to(r - p).abs().to_degrees();
    angle(a, b, c).min(angle(b, c, a)).min(angle(c, a, b))
}

/// The smallest angle is exactly 30 degrees (not above it) for every resolution >= 3:
/// where an inner-ring vertex lies radially below an outer-ring one, the zip makes a
/// 30-30-120 triangle with the next inner vertex (e.g. inner 0 deg, outer 60 deg,
/// inner 60 deg between rings 1 and 2). Pinned here with rounding slack only.
#[test]
fn disk_triangles_have_no_angle_below_30_degrees() {
    let mut worst = (f64::INFINITY, 0);
    for res in 4..=32 {
        let m = mesh::disk(0.5, res).expect("disk");
        let smallest = (0..m.triangles.len())
            .map(|t| min_angle_deg(&m, t))
            .fold(f64::INFINITY, f64::min);
        if smallest < worst.0 {
            worst = (smallest, res);
        }
    }
    assert!(
        worst.0 > 30.0 - 1e-9,
        "smallest angle {} deg at res {}",
        worst.0,
        worst.1
    );
    assert!(
        worst.0 < 30.0 + 1e-9,
        "the 30-30-120 triangles are gone: update the doc"
    );
}
