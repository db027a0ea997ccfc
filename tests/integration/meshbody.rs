//! Deforming mesh obstacles (`src/collide/deform.rs`): a mesh sequence's
//! interpolation and per-vertex velocities against hand-computed values, its
//! loader's and the scene's errors, a cloth carried by a moving mesh, the
//! skinned body written as frames and read back, the cape on the mesh body,
//! and the body logged as a mesh per frame.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use drape::collide::obstacle::Body;
use drape::collide::{Drawn, Obstacles};
use drape::kinematics::skin::obj_text;
use drape::math::Vector;
use drape::scene::{Scene, load_scene_file};

/// A fresh directory for one test's files.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("drape-meshbody-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// Writes `text` to `dir/name`.
fn put(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).expect("write");
}

/// A scene in `dir` with one obstacle table `obstacle` (and a small cloth far
/// from it unless `cloth` says otherwise).
fn scene_in(dir: &Path, cloth: &str, obstacle: &str, sets: &[&str]) -> Result<Scene, String> {
    let text = format!(
        "name = \"seq\"\n[simulation]\nduration = 1.0\n[cloth]\nshape = \"rectangle\"\nwidth = 0.3\nheight = 0.3\nresolution = 8\n{cloth}\n[material]\ndensity = 0.15\nstretch = 200.0\nbending = 1.0e-5\ndamping = 0.001\n[[obstacle]]\n{obstacle}"
    );
    put(dir, "scene.toml", &text);
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    load_scene_file(&dir.join("scene.toml"), &sets).map_err(|e| e.to_string())
}

/// One triangle (0,0,0) (1,0,0) (0,1,0), moved by `d`.
fn triangle(d: [f64; 3]) -> String {
    let v = |x: f64, y: f64| format!("v {} {} {}\n", x + d[0], y + d[1], d[2]);
    format!("{}{}{}f 1 2 3\n", v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0))
}

#[test]
fn a_sequence_interpolates_positions_and_per_vertex_velocities() {
    let dir = scratch("interp");
    // Three frames at 2 frames/s: the first vertex rises 0.4 m, then the
    // second moves 0.2 m along x; scale 2, placed at (1, 0, 0).
    put(&dir, "f0.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    put(&dir, "f1.obj", "v 0 0 0.4\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    put(&dir, "f2.obj", "v 0 0 0.4\nv 1.2 0 0\nv 0 1 0\nf 1 2 3\n");
    for (after, t, want_x0, want_v0, want_v1) in [
        // t = 0.25 s is halfway from frame 0 to 1: vertex 0 at z = 2 * 0.2,
        // moving at 2 * 0.4 m per frame * 2 frames/s = 1.6 m/s.
        ("hold", 0.25, [1.0, 0.0, 0.4], [0.0, 0.0, 1.6], [0.0; 3]),
        // t = 0.875 s: 3/4 of frame 1 to 2: vertex 1 at x = 1 + 2 (1 + 0.15).
        ("hold", 0.875, [1.0, 0.0, 0.8], [0.0; 3], [0.8, 0.0, 0.0]),
        // After the last frame: held, at rest.
        ("hold", 3.0, [1.0, 0.0, 0.8], [0.0; 3], [0.0; 3]),
        // Looping, period 1.5 s: t = 1.25 s is halfway from frame 2 back to
        // frame 0 (vertex 0 at z = 0.4, falling at 1.6 m/s).
        (
            "loop",
            1.25,
            [1.0, 0.0, 0.4],
            [0.0, 0.0, -1.6],
            [-0.8, 0.0, 0.0],
        ),
    ] {
        let obstacle = format!(
            "shape = \"mesh_sequence\"\nfiles = [\"f0.obj\", \"f1.obj\", \"f2.obj\"]\nframe_rate = 2.0\nscale = 2.0\nposition = [1.0, 0.0, 0.0]\nafter_last = \"{after}\"\n"
        );
        let scene = scene_in(&dir, "", &obstacle, &[]).expect("scene");
        let body =
            &Body::from_spec(0, &scene.obstacle[0].resolve().expect("resolved")).expect("body")[0];
        let (x, tris) = body.world_triangles(t, (Vector::ZERO, 1.0));
        assert_eq!(tris, vec![[0, 1, 2]]);
        let at = body.at(t);
        let s = at.surface.as_ref().expect("deforming");
        let (v0, v1) = (s.velocities()[0], s.velocities()[1]);
        println!(
            "{after} t = {t}: vertex 0 at {:?} moving {v0:?}, vertex 1 moving {v1:?}",
            x[0]
        );
        assert!(
            (x[0] - Vector::from_array(want_x0)).length() < 1e-12,
            "{:?}",
            x[0]
        );
        assert!(
            (v0 - Vector::from_array(want_v0)).length() < 1e-12,
            "{v0:?}"
        );
        assert!(
            (v1 - Vector::from_array(want_v1)).length() < 1e-12,
            "{v1:?}"
        );
        // The surface velocity at a point is the barycentric mix: at the
        // midpoint of edge 0-1 the mean of the two vertices' velocities.
        let mid = (x[0] + x[1]) * 0.5;
        let v = body.point_velocity(t, mid);
        assert!((v - (v0 + v1) * 0.5).length() < 1e-9, "{v:?}");
    }
}

#[test]
fn sequence_errors_name_the_file_and_what_is_wrong() {
    let dir = scratch("errors");
    put(&dir, "a.obj", &triangle([0.0; 3]));
    put(
        &dir,
        "more.obj",
        &format!("{}v 5 5 5\nf 1 2 4\n", triangle([0.0; 3])),
    );
    put(&dir, "turned.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 3 2\n");
    put(&dir, "nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
    let build = |files: &str| -> String {
        let obstacle = format!("shape = \"mesh_sequence\"\nfiles = {files}\nframe_rate = 24.0\n");
        let scene = scene_in(&dir, "", &obstacle, &[]).expect("scene");
        Obstacles::from_scene(&scene)
            .expect_err("refused")
            .to_string()
    };
    for (files, file, needle) in [
        (
            "[\"a.obj\", \"more.obj\"]",
            "more.obj",
            "the topology changed: it has 4 vertices",
        ),
        (
            "[\"a.obj\", \"turned.obj\"]",
            "turned.obj",
            "its triangle 1 has the vertices [1, 3, 2], in the first frame [1, 2, 3]",
        ),
        (
            "[\"a.obj\", \"nan.obj\"]",
            "nan.obj",
            "line 2: the vertex [1.0, NaN, 0.0] has a coordinate that is not a finite number",
        ),
    ] {
        let e = build(files);
        println!("{e}");
        assert!(e.contains(file) && e.contains(needle), "{e}");
    }
    // A missing file is a scene error at the line and key that name it.
    let obstacle =
        "shape = \"mesh_sequence\"\nfiles = [\"a.obj\", \"gone.obj\"]\nframe_rate = 24.0\n";
    let e = scene_in(&dir, "", obstacle, &[]).expect_err("missing");
    println!("{e}");
    assert!(
        e.contains("scene.toml:17: key `obstacle.0.files.1`: no such file: `"),
        "{e}"
    );
    assert!(e.contains("gone.obj"), "{e}");
    let obstacle = "shape = \"mesh_sequence\"\nfiles = \"f_{:03}.obj\"\nframe_rate = 24.0\n";
    let e = scene_in(&dir, "", obstacle, &[]).expect_err("missing");
    println!("{e}");
    assert!(
        e.contains(":17: key `obstacle.0.files`: no such file: `") && e.contains("f_000.obj"),
        "{e}"
    );
}

#[test]
fn mesh_scene_mistakes_name_file_line_and_key() {
    let dir = scratch("keys");
    put(&dir, "a.obj", &triangle([0.0; 3]));
    let seq = "shape = \"mesh_sequence\"\nfiles = [\"a.obj\"]\nframe_rate = 24.0\n";
    for (obstacle, needle) in [
        (
            "shape = \"mesh_sequence\"\nfiles = [\"a.obj\"]\n",
            "scene.toml:15: key `obstacle.0.frame_rate`: missing required key",
        ),
        (
            "shape = \"mesh_sequence\"\nfiles = [\"a.obj\"]\nframe_rate = -1.0\n",
            "key `obstacle.0.frame_rate`",
        ),
        (
            "shape = \"mesh_sequence\"\nfiles = \"a_{:x}.obj\"\nframe_rate = 24.0\n",
            "scene.toml:17: key `obstacle.0.files`: `{:x}` in `a_{:x}.obj` is not a frame-number placeholder",
        ),
        (
            &format!("{seq}keyframes = [{{ time = 0.0 }}, {{ time = 1.0 }}]\n"),
            "scene.toml:19: key `obstacle.0.keyframes`: `keyframes` does not apply to shape = \"mesh_sequence\"",
        ),
        (
            "shape = \"sphere\"\nradius = 0.1\nfiles = [\"a.obj\"]\n",
            "scene.toml:18: key `obstacle.0.files`: `files` does not apply to shape = \"sphere\"",
        ),
        (
            "shape = \"sphere\"\nradius = 0.1\nsurface = \"skinned_mesh\"\n",
            "scene.toml:18: key `obstacle.0.surface`: `surface` does not apply to shape = \"sphere\"",
        ),
    ] {
        let e = scene_in(&dir, "", obstacle, &[]).expect_err("refused");
        println!("{e}");
        assert!(e.contains(needle), "{e}");
    }
}

#[test]
fn a_cloth_on_a_moving_mesh_moves_with_it() {
    let dir = scratch("carry");
    // A 0.8 m square tray (two triangles, top at z = 0.5): still for 1 s
    // while the sheet settles, then it slides 0.1 m along x in 1 s.
    let tray = |dx: f64| {
        let v = |x: f64, y: f64| format!("v {} {} 0.5\n", x + dx, y);
        format!(
            "{}{}{}{}f 1 2 3\nf 1 3 4\n",
            v(-0.4, -0.4),
            v(0.4, -0.4),
            v(0.4, 0.4),
            v(-0.4, 0.4)
        )
    };
    put(&dir, "t0.obj", &tray(0.0));
    put(&dir, "t1.obj", &tray(0.0));
    put(&dir, "t2.obj", &tray(0.1));
    let obstacle = "shape = \"mesh_sequence\"\nfiles = \"t{}.obj\"\nframe_rate = 1.0\nfriction_static = 0.9\nfriction_kinetic = 0.7\n";
    let cloth = "position = [0.0, 0.0, 0.51]";
    let scene = scene_in(&dir, cloth, obstacle, &["simulation.duration=2.5"]).expect("scene");
    let (mut settled, mut last) = (None, None);
    let summary = drape::run::run_observed(
        &scene,
        &drape::run::RunOptions::default(),
        &AtomicBool::new(false),
        &mut |_| {},
        &mut |f| {
            let c = f.positions.iter().copied().sum::<Vector>() / f.positions.len() as f64;
            if f.sim_time <= 1.0 + 1e-9 {
                settled = Some(c);
            }
            last = Some(c);
        },
    )
    .expect("run");
    let (c0, c1) = (settled.expect("frames"), last.expect("frames"));
    let moved = c1 - c0;
    println!(
        "tray slid 0.1 m: cloth centre {c0:.4?} -> {c1:.4?}; max penetration {} m",
        summary.collision.max_penetration
    );
    assert!((moved.x - 0.1).abs() < 0.005, "moved {moved:?}");
    assert!(
        moved.y.abs() < 0.005 && moved.z.abs() < 0.005,
        "moved {moved:?}"
    );
    assert!(summary.collision.max_penetration < 1e-3);
}

/// `scenes/cape_mesh_body.toml` with `sets`.
fn cape_mesh_body(sets: &[&str]) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cape_mesh_body.toml");
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    load_scene_file(&path, &sets).expect("scene")
}

#[test]
fn the_skinned_body_written_as_frames_reads_back_as_a_sequence() {
    let dir = scratch("frames");
    let skinned = Obstacles::from_scene(&cape_mesh_body(&[])).expect("skinned");
    let rate = 30.0;
    let mesh_at = |o: &Obstacles, t: f64| {
        o.meshes(t, (Vector::ZERO, 1.0), true)
            .into_iter()
            .find(|m| m.drawn == Drawn::Deforming)
            .expect("a deforming mesh")
    };
    // The arms rise from 0.5 s: frames 15 to 30 (0.5 s to 1 s).
    for k in 15..=30 {
        let m = mesh_at(&skinned, k as f64 / rate);
        put(
            &dir,
            &format!("body_{k:04}.obj"),
            &obj_text(&m.positions, &m.triangles),
        );
    }
    let obstacle = "shape = \"mesh_sequence\"\nfiles = \"body_{:04}.obj\"\nfirst_frame = 15\nframe_rate = 30.0\n";
    let scene = scene_in(&dir, "", obstacle, &[]).expect("scene");
    let seq = Obstacles::from_scene(&scene).expect("sequence");
    // The sequence's time 0 is frame 15, the skinned body's 0.5 s.
    let mut worst = [0.0f64; 2];
    for (n, k) in [(0, 3.0), (1, 7.5)] {
        let (a, b) = (mesh_at(&seq, k / rate), mesh_at(&skinned, 0.5 + k / rate));
        // tobj numbers the vertices as the faces first use them: compare
        // the triangles' corners.
        assert_eq!(a.triangles.len(), b.triangles.len());
        let corner = |m: &drape::collide::ObstacleMesh, t: usize, c: usize| {
            m.positions[m.triangles[t][c] as usize]
        };
        let off = (0..a.triangles.len())
            .flat_map(|t| (0..3).map(move |c| (t, c)))
            .map(|(t, c)| (corner(&a, t, c) - corner(&b, t, c)).length())
            .fold(0.0, f64::max);
        worst[n] = off;
    }
    println!(
        "read back: {} triangles; largest distance to the skinned body at a frame {:.1e} m, between frames {:.1e} m",
        mesh_at(&seq, 0.0).triangles.len(),
        worst[0],
        worst[1]
    );
    assert!(worst[0] < 1e-12, "at a frame: {}", worst[0]);
    assert!(worst[1] < 2e-3, "between frames: {}", worst[1]);
}

#[test]
fn the_cape_turns_with_the_mesh_body() {
    let scene = cape_mesh_body(&["simulation.duration=2.75"]);
    let mut last = Vec::new();
    let summary = drape::run::run_observed(
        &scene,
        &drape::run::RunOptions::default(),
        &AtomicBool::new(false),
        &mut |_| {},
        &mut |f| last = f.positions.to_vec(),
    )
    .expect("run");
    // As the rigid mannequin's cape: 45 deg of the body's turn at 2.75 s.
    let c = last.iter().copied().sum::<Vector>() / last.len() as f64;
    let angle = (-c.x).atan2(c.y).to_degrees();
    let lowest = last.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
    println!(
        "cape on the mesh body at 2.75 s: centre {c:.3?}, turned {angle:.1} deg (body 45 deg), lowest {lowest:.2} m; \
         max penetration {} m, mean contacts {:.0}",
        summary.collision.max_penetration, summary.collision.contacts
    );
    assert!((25.0..60.0).contains(&angle), "turned {angle} deg");
    assert!(
        lowest < 1.0,
        "the cape hangs down the back: lowest {lowest} m"
    );
    assert!(summary.collision.max_penetration < 5e-3);
}

#[test]
fn the_mesh_body_is_logged_as_a_mesh_per_frame() {
    let out = std::env::temp_dir().join(format!("drape-meshbody-{}.rrd", std::process::id()));
    let scene = cape_mesh_body(&["simulation.duration=0.2"]);
    let opts = drape::run::RunOptions {
        record: Some(out.clone()),
        ..drape::run::RunOptions::default()
    };
    let summary =
        drape::run::run(&scene, &opts, &AtomicBool::new(false), &mut |_| {}).expect("run");
    let ins = drape::record::inspect::inspect(&out).expect("decodes");
    let rows = &ins.entities["/obstacles/obstacle_0__skinned_mesh_"];
    println!("body: {rows:?} over {} frames", summary.extent.frames);
    // The triangles once (static), the vertex positions at every recorded frame.
    assert_eq!(rows.static_rows, 1);
    assert_eq!(rows.temporal as u64, summary.extent.frames);
    std::fs::remove_file(&out).ok();
}
