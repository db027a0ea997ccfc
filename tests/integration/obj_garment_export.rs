//! The per-frame OBJ export of a garment (`write_mesh_obj`) reads back with
//! `load_obj` as the same panels, corners and open seams, before and after a
//! seam is welded, also where a seam's two sides lie on each other and where
//! two seams meet end to end (GarmentCode's garments as they start).

use std::collections::HashMap;

use drape::garment;
use drape::garmentcode;
use drape::math::Vector;
use drape::mesh::{self, ObjCloth};
use drape::record::obj::write_mesh_obj;
use drape::spec::Garment;

use crate::obj_garments::{TWO_PANELS, line_of, load, panels, temp_dir};

/// Front and back panels sewn by `l` on one side and welded on the other (the
/// back's right edge shares its positions with a third panel, `side`, with
/// other `vt`), one face wound clockwise.
const SEWN_AND_WELDED: &str = "\
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
o side
v 2.1 1 0
v 2.1 1 0.5
v 2.1 1 1
f 8/1 13/2 14/4
f 8/1 14/4 10/3
f 10/3 12/5 14/4
f 12/5 15/6 14/4
l 2 7
l 4 9
l 6 11
";

/// Vertex `v` of `a` as a vertex of `b`, found by position (`b`'s are distinct).
fn vertex_map(a: &[Vector], b: &[Vector]) -> Vec<u32> {
    let key = |p: &Vector| p.to_array().map(f64::to_bits);
    let index: HashMap<[u64; 3], u32> = b
        .iter()
        .enumerate()
        .map(|(i, p)| (key(p), i as u32))
        .collect();
    assert_eq!(index.len(), b.len(), "distinct positions");
    a.iter().map(|p| index[&key(p)]).collect()
}

/// Checks that `b` is garment `a` (positions `xa`), its vertices perhaps renumbered.
fn assert_same_garment(a: &mesh::Mesh, xa: &[Vector], b: &ObjCloth) {
    assert_eq!(b.positions.len(), xa.len());
    let map = vertex_map(xa, &b.positions);
    let (pa, pb) = (a.panels().expect("garment"), panels(b));
    assert_eq!(pa.names, pb.names);
    assert_eq!(pa.of_triangle, pb.of_triangle);
    assert_eq!(a.triangles.len(), b.mesh.triangles.len());
    let mut worst: f64 = 0.0;
    for (t, tri) in a.triangles.iter().enumerate() {
        assert_eq!(
            b.mesh.triangles[t],
            tri.map(|v| map[v as usize]),
            "triangle {t}"
        );
        for k in 0..3 {
            worst = worst.max((pa.corners[t][k] - pb.corners[t][k]).length());
        }
    }
    assert!(worst <= 1e-12, "corners differ by {worst:e} m");
    for (v, &w) in map.iter().enumerate() {
        let w = w as usize;
        assert_eq!(pa.of_vertex[v], pb.of_vertex[w], "home panel of {v}");
        assert!((a.material[v] - b.mesh.material[w]).length() <= 1e-12);
    }
    let open: Vec<_> = pa.seams.iter().filter(|s| s.is_open()).collect();
    assert_eq!(open.len(), pb.seams.len());
    for (sa, sb) in open.iter().zip(&pb.seams) {
        let mapped: Vec<[u32; 2]> = sa
            .pairs
            .iter()
            .map(|p| p.map(|v| map[v as usize]))
            .collect();
        assert_eq!(mapped, sb.pairs, "{}", sa.name);
        assert!(sb.is_open(), "{}", sb.name);
    }
}

#[test]
fn exported_garment_frame_reads_back_as_the_same_panels_corners_and_seams() {
    let cloth = load("sewn_welded", SEWN_AND_WELDED).expect("the garment loads");
    let p = panels(&cloth);
    assert_eq!(p.names, ["front", "back", "side"]);
    assert_eq!(p.seams.len(), 1);
    assert_eq!(
        cloth.positions.len(),
        15,
        "the back and side share three vertices"
    );
    // A later frame: the cloth has moved (positions stay distinct).
    let x: Vec<Vector> = cloth
        .positions
        .iter()
        .enumerate()
        .map(|(i, p)| *p + Vector::new(0.01, -0.02, 0.003 * i as f64))
        .collect();
    let dir = temp_dir("export");
    let path = write_mesh_obj(&dir, 4, &x, &cloth.mesh).expect("export");
    let text = std::fs::read_to_string(&path).expect("read export");
    let back = mesh::load_obj(&path, 1.0).expect("the export loads");
    assert_same_garment(&cloth.mesh, &x, &back);
    assert_eq!(text.lines().filter(|l| l.starts_with("l ")).count(), 3);
    assert_eq!(
        back.mesh.panels().expect("garment").seams[0].name,
        format!("l{}", line_of(&text, "l "))
    );

    // Welded: the seam's pairs merge; the export reads back as the three panels,
    // welded there too, with no open seam.
    let weld = cloth.mesh.weld(0).expect("weld");
    let mut xw = vec![Vector::ZERO; weld.mesh.vertex_count()];
    for (v, &w) in weld.new_index.iter().enumerate() {
        xw[w as usize] = x[v];
    }
    let path = write_mesh_obj(&dir, 5, &xw, &weld.mesh).expect("export welded");
    let back = mesh::load_obj(&path, 1.0).expect("the welded export loads");
    assert_same_garment(&weld.mesh, &xw, &back);
    assert_eq!(back.positions.len(), 12);
    assert!(panels(&back).seams.is_empty());
    std::fs::remove_dir_all(&dir).ok();
}

/// Front and back panels whose sewn edges lie on each other: [`TWO_PANELS`]
/// with the back moved onto the front's right edge, so that the back's left
/// edge has the front's right edge's positions, in `v` lines of its own, and
/// each `l` pairs two `v` lines at one position.
fn sides_on_each_other() -> String {
    TWO_PANELS
        .replace("v 1.1 ", "v 1 ")
        .replace("v 2.1 ", "v 2 ")
}

/// Checks that `cloth` has two panels and one open seam of three pairs, each
/// pair two vertices at one position.
fn assert_sides_distinct(cloth: &ObjCloth) {
    let p = panels(cloth);
    assert_eq!(cloth.positions.len(), 12, "each side keeps its vertices");
    assert_eq!(cloth.mesh.triangles.len(), 8);
    assert_eq!(p.seams.len(), 1);
    assert_eq!(p.seams[0].pairs.len(), 3);
    for &[a, b] in &p.seams[0].pairs {
        assert_ne!(a, b);
        assert_ne!(p.of_vertex[a as usize], p.of_vertex[b as usize]);
        assert_eq!(cloth.positions[a as usize], cloth.positions[b as usize]);
    }
}

#[test]
fn open_seam_whose_sides_lie_on_each_other_reads_back_with_every_pair_distinct() {
    let cloth = load("on_each_other", &sides_on_each_other()).expect("the garment loads");
    assert_sides_distinct(&cloth);
    let dir = temp_dir("on_each_other_export");
    let path = write_mesh_obj(&dir, 0, &cloth.positions, &cloth.mesh).expect("export");
    let back = mesh::load_obj(&path, 1.0).expect("the export loads");
    assert_sides_distinct(&back);
    assert_eq!(back.mesh.triangles, cloth.mesh.triangles);
    assert_eq!(back.positions, cloth.positions);
    let (pa, pb) = (panels(&cloth), panels(&back));
    assert_eq!(pa.seams[0].pairs, pb.seams[0].pairs);
    assert_eq!(pa.of_vertex, pb.of_vertex);
    std::fs::remove_dir_all(&dir).ok();
}

/// The vertex of `b` at each vertex of `a`, read off their triangles (the
/// same triangles in the same order, the vertices perhaps renumbered);
/// checks that it is one to one.
fn vertex_map_by_triangles(a: &[[u32; 3]], b: &[[u32; 3]], count: usize) -> Vec<u32> {
    assert_eq!(a.len(), b.len(), "triangles");
    let mut map = vec![u32::MAX; count];
    for (ta, tb) in a.iter().zip(b) {
        for k in 0..3 {
            let old = std::mem::replace(&mut map[ta[k] as usize], tb[k]);
            assert!(old == u32::MAX || old == tb[k], "vertex {} split", ta[k]);
        }
    }
    let mut seen = map.clone();
    seen.sort_unstable();
    seen.dedup();
    assert_eq!(seen.len(), count, "two vertices merged");
    map
}

/// Each of GarmentCode's examples as `drape garment` builds it (2 cm edges),
/// exported as it starts and read back: the same vertices, triangles and
/// open seams, each seam's pairs the same and two distinct vertices, though
/// some pairs' two vertices lie at one position and some seams meet another
/// end to end (the shirt's stitches 4 and 5).
#[test]
fn garmentcode_garments_read_back_from_their_first_frame_with_every_seam_and_pair() {
    let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/garmentcode");
    let mut coincident = 0;
    for name in ["shirt_mean", "hoody_mean", "dress_pencil"] {
        let spec = examples.join(format!("{name}_specification.json"));
        let pattern = garmentcode::load(&spec).expect("the pattern loads");
        let built = garment::build(&Garment {
            panels: pattern.panels,
            seams: pattern.seams,
            holds: Vec::new(),
            max_edge: 0.02,
        })
        .expect("the garment builds");
        let dir = temp_dir(name);
        let path = write_mesh_obj(&dir, 0, &built.positions, &built.mesh).expect("export");
        let back = mesh::load_obj(&path, 1.0).expect("the export loads");
        std::fs::remove_dir_all(&dir).ok();
        let count = built.mesh.vertex_count();
        assert_eq!(back.mesh.vertex_count(), count, "{name}: vertices");
        let map = vertex_map_by_triangles(&built.mesh.triangles, &back.mesh.triangles, count);
        let (a, b) = (built.mesh.panels().expect("garment"), panels(&back));
        assert_eq!(b.seams.len(), a.seams.len(), "{name}: seams");
        for (sa, sb) in a.seams.iter().zip(&b.seams) {
            let mapped: Vec<[u32; 2]> = sa
                .pairs
                .iter()
                .map(|p| p.map(|v| map[v as usize]))
                .collect();
            // The loader puts a seam's side in the lower-numbered panel first.
            let turned: Vec<[u32; 2]> = mapped.iter().map(|&[u, w]| [w, u]).collect();
            assert!(
                sb.pairs == mapped || sb.pairs == turned,
                "{name}: seam {}",
                sa.name
            );
            for &[u, w] in &sb.pairs {
                assert_ne!(u, w, "{name}: seam {}", sa.name);
                coincident += usize::from(back.positions[u as usize] == back.positions[w as usize]);
            }
        }
    }
    assert!(
        coincident > 0,
        "no pair lies at one position: the test tests less"
    );
}
