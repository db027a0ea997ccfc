//! Recording module: `.rrd` output decoded back, `RERUN=off`, error paths, OBJ export.

use std::path::PathBuf;

use drape::math::{Vector, Vector2};
use drape::record::{FrameView, RecordError, Recorder, obj::write_frame_obj};
use rerun::external::re_log_encoding::DecoderApp;
use rerun::log::{Chunk, LogMsg};

/// A fresh path in the temp dir, unique per process, test and call.
fn temp_path(name: &str) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!("drape-test-{}-{n}-{name}", std::process::id()))
}

/// Two triangles forming a unit square in the z = 0 plane, the second one refined (level 1).
struct Square {
    positions: Vec<Vector>,
    normals: Vec<Vector>,
    triangles: Vec<[u32; 3]>,
    levels: Vec<u8>,
    pinned: Vec<u32>,
}

fn square() -> Square {
    Square {
        positions: vec![
            Vector::new(0.0, 0.0, 0.0),
            Vector::new(1.0, 0.0, 0.0),
            Vector::new(1.0, 1.0, 0.0),
            Vector::new(0.0, 1.0, 0.0),
        ],
        normals: vec![Vector::Z; 4],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        levels: vec![0, 1],
        pinned: vec![2, 3],
    }
}

/// Records `frames` frames of the square falling under gravity, then finishes.
fn record_square(path: &std::path::Path, frames: u64) -> Result<u64, RecordError> {
    record_mesh(path, &square(), frames, std::time::Duration::ZERO).map(|(size, _)| size)
}

/// Records `frames` frames of `mesh` falling under gravity, pausing `pause` between frames;
/// returns the file size and the mean time spent in `record_frame`.
fn record_mesh(
    path: &std::path::Path,
    mesh: &Square,
    frames: u64,
    pause: std::time::Duration,
) -> Result<(u64, std::time::Duration), RecordError> {
    let mut rec = Recorder::create(path, "two-triangles")?;
    let mut positions = mesh.positions.clone();
    let mut spent = std::time::Duration::ZERO;
    for f in 0..frames {
        let t = f as f64 / 60.0;
        for (p, p0) in positions.iter_mut().zip(&mesh.positions) {
            *p = *p0 - Vector::Z * (0.5 * 9.81 * t * t);
        }
        let scalars = [
            ("energy/kinetic", 0.5 * (9.81 * t) * (9.81 * t)),
            ("mesh/vertices", positions.len() as f64),
            ("timing/sim_ms", 0.1),
        ];
        let start = std::time::Instant::now();
        rec.record_frame(&FrameView {
            frame: f,
            sim_time: t,
            positions: &positions,
            vertex_normals: &mesh.normals,
            triangles: &mesh.triangles,
            triangle_levels: &mesh.levels,
            edges: &[],
            edge_angles: &[],
            pinned: &mesh.pinned,
            scalars: &scalars,
            events: &[],
            garment: None,
        })?;
        spent += start.elapsed();
        std::thread::sleep(pause);
    }
    let size = rec.finish()?;
    Ok((
        size,
        spent / u32::try_from(frames.max(1)).unwrap_or(u32::MAX),
    ))
}

/// An `n` x `n` grid of quads (2 n^2 triangles), levels cycling 0..4, two corners pinned.
fn grid(n: u32) -> Square {
    let mut sq = Square {
        positions: Vec::new(),
        normals: Vec::new(),
        triangles: Vec::new(),
        levels: Vec::new(),
        pinned: vec![0, n],
    };
    for j in 0..=n {
        for i in 0..=n {
            sq.positions.push(Vector::new(
                f64::from(i) / f64::from(n),
                f64::from(j) / f64::from(n),
                1.0,
            ));
            sq.normals.push(Vector::Z);
        }
    }
    let v = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            sq.triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            sq.triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
            sq.levels.extend([(i % 4) as u8, (j % 4) as u8]);
        }
    }
    sq
}

/// What the decoded recording store holds.
#[derive(Debug, Default)]
pub(crate) struct Decoded {
    /// Rows per entity path in the recording store.
    pub(crate) rows: std::collections::BTreeMap<String, usize>,
    /// Chunks (arrow messages) of the recording store.
    pub(crate) chunks: usize,
    /// Timeline names seen on `cloth/mesh`.
    mesh_timelines: std::collections::BTreeSet<String>,
    recording_ids: std::collections::BTreeSet<String>,
    blueprint_msgs: usize,
    /// The entity paths the blueprint's 3D eyes track (the arrow text of each
    /// `EyeControls3D:tracking_entity` column).
    pub(crate) tracked: Vec<String>,
    /// The blueprint's fixed 3D eye positions (the arrow text of each
    /// `EyeControls3D:position` column).
    pub(crate) eye_positions: Vec<String>,
    /// The blueprint entities holding a `Mesh3D:vertex_colors` override, with the arrow
    /// text of the colours.
    pub(crate) colour_overrides: Vec<(String, String)>,
}

/// Decodes a `.rrd` file (panics if it does not decode); also used by the CLI tests.
pub(crate) fn decode(path: &std::path::Path) -> Decoded {
    let file = std::fs::File::open(path).expect("open rrd");
    let decoder = DecoderApp::decode_eager(std::io::BufReader::new(file)).expect("rrd header");
    let mut out = Decoded::default();
    for msg in decoder {
        let msg = msg.expect("decodable message");
        let store = msg.store_id().clone();
        if store.kind() != rerun::StoreKind::Recording {
            out.blueprint_msgs += 1;
            if let LogMsg::ArrowMsg(_, arrow) = &msg {
                let chunk = Chunk::from_arrow_msg(arrow).expect("blueprint chunk");
                let id = "EyeControls3D:tracking_entity".into();
                if let Some(array) = chunk.raw_component_array(id) {
                    out.tracked.push(format!("{array:?}"));
                }
                let id = "EyeControls3D:position".into();
                if let Some(array) = chunk.raw_component_array(id) {
                    out.eye_positions.push(format!("{array:?}"));
                }
                let id = "Mesh3D:vertex_colors".into();
                if let Some(array) = chunk.raw_component_array(id) {
                    let entity = chunk.entity_path().to_string();
                    out.colour_overrides.push((entity, format!("{array:?}")));
                }
            }
            continue;
        }
        out.recording_ids.insert(store.recording_id().to_string());
        if let LogMsg::ArrowMsg(_, arrow) = &msg {
            let chunk = Chunk::from_arrow_msg(arrow).expect("chunk");
            out.chunks += 1;
            let entity = chunk.entity_path().to_string();
            *out.rows.entry(entity.clone()).or_default() += chunk.num_rows();
            if entity == "/cloth/mesh" {
                out.mesh_timelines
                    .extend(chunk.timelines().keys().map(|t| t.to_string()));
            }
        }
    }
    out
}

#[test]
fn three_frames_decode_to_three_mesh_rows() {
    let path = temp_path("three.rrd");
    let size = record_square(&path, 3).expect("recording");
    let bytes = std::fs::read(&path).expect("read rrd");
    assert_eq!(size, bytes.len() as u64);
    assert!(bytes.starts_with(b"RRF2"), "rrd magic");
    // Stream footer: "RRF2" "FOOT" + u32 footer count, written on close.
    assert_eq!(&bytes[bytes.len() - 12..bytes.len() - 4], b"RRF2FOOT");

    let d = decode(&path);
    assert_eq!(d.rows.get("/cloth/mesh"), Some(&3), "rows {:?}", d.rows);
    assert_eq!(d.rows.get("/cloth/pins"), Some(&3), "rows {:?}", d.rows);
    assert_eq!(
        d.rows.get("/plots/energy/kinetic"),
        Some(&3),
        "rows {:?}",
        d.rows
    );
    assert_eq!(
        d.rows.get("/plots/mesh/vertices"),
        Some(&3),
        "rows {:?}",
        d.rows
    );
    assert!(d.mesh_timelines.contains("frame"), "{:?}", d.mesh_timelines);
    assert!(
        d.mesh_timelines.contains("sim_time"),
        "{:?}",
        d.mesh_timelines
    );
    assert!(d.rows.contains_key("/cloth"), "annotation context");
    let id = drape::record::recording_id("two-triangles");
    assert_eq!(d.recording_ids.iter().collect::<Vec<_>>(), vec![&id]);
    // The blueprint is sent even under `RERUN=off` (see the test below), and both 3D
    // views' eyes follow the cloth.
    assert!(d.blueprint_msgs > 0, "default blueprint sent");
    let mut tracked = d.tracked.clone();
    tracked.sort();
    assert_eq!(tracked.len(), 2, "tracked {tracked:?}");
    assert!(
        tracked.iter().all(|t| t.contains("\"/cloth/mesh\"")),
        "{tracked:?}"
    );
    assert!(d.eye_positions.is_empty(), "{:?}", d.eye_positions);
    std::fs::remove_file(&path).ok();
}

#[test]
fn recording_id_is_deterministic() {
    let a = drape::record::recording_id("tablecloth");
    assert_eq!(a, drape::record::recording_id("tablecloth"));
    assert_ne!(a, drape::record::recording_id("flag"));
    assert_eq!(a.len(), 36);
    assert_eq!(&a[14..15], "8", "uuid version nibble");
}

/// Runs [`three_frames_decode_to_three_mesh_rows`] again in a child process of this test
/// binary with `RERUN=off`: setting the variable here would race with the other test threads.
#[test]
fn recording_is_forced_on_with_rerun_off() {
    let exe = std::env::current_exe().expect("test binary path");
    let out = std::process::Command::new(exe)
        .args([
            "--exact",
            "recording::three_frames_decode_to_three_mesh_rows",
            "--nocapture",
            "--test-threads=1",
        ])
        .env("RERUN", "off")
        .output()
        .expect("run child test");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "child with RERUN=off failed:\n{stdout}{stderr}"
    );
    assert!(
        stdout.contains("1 passed"),
        "child ran the test:\n{stdout}{stderr}"
    );
}

#[test]
fn frames_share_chunks_and_cost_at_most_16_bytes_per_triangle() {
    let one = temp_path("one.rrd");
    let many = temp_path("many.rrd");
    let s1 = record_square(&one, 1).expect("recording");
    let s101 = record_square(&many, 101).expect("recording");
    // Pauses longer than rerun's default 200 ms batching tick, which a recording without a
    // live viewer does without: the frames still share their chunks (one per entity, not one
    // per entity and frame).
    let pause = std::time::Duration::from_millis(250);
    let (s4, _) = record_mesh(&many, &square(), 4, pause).expect("recording");
    let chunks = decode(&many).chunks;
    assert!(
        chunks <= 16,
        "{chunks} chunks: frames 250 ms apart should share their entities' chunks"
    );
    let big = grid(100);
    let (b1, _) = record_mesh(&one, &big, 1, std::time::Duration::ZERO).expect("recording");
    let (b11, _) = record_mesh(&many, &big, 11, std::time::Duration::ZERO).expect("recording");
    let per_triangle = (b11 - b1) as f64 / 10.0 / big.triangles.len() as f64;
    // Every frame adds bytes (positions change), and batching frames into one chunk
    // costs less per frame than a chunk per frame.
    assert!(s101 > s1 && s4 > s1, "frames add bytes: {s1} {s101} {s4}");
    assert!(
        (s101 - s1) as f64 / 100.0 < (s4 - s1) as f64 / 3.0,
        "batched frames cost less per frame"
    );
    // Topology constant, no edges: positions only after the first frame (shared
    // vertices, triangles logged once). The budget: 16 B per triangle per frame
    // for a uniform scene without edges.
    assert!(
        per_triangle <= 16.0,
        "{per_triangle:.2} B per triangle per frame on a constant topology"
    );
    std::fs::remove_file(&one).ok();
    std::fs::remove_file(&many).ok();
}

#[test]
fn dropped_recorder_leaves_valid_file() {
    let path = temp_path("dropped.rrd");
    let sq = square();
    let result: Result<(), RecordError> = (|| {
        let mut rec = Recorder::create(&path, "dropped")?;
        rec.record_frame(&FrameView {
            frame: 0,
            sim_time: 0.0,
            positions: &sq.positions,
            vertex_normals: &sq.normals,
            triangles: &sq.triangles,
            triangle_levels: &sq.levels,
            edges: &[],
            edge_angles: &[],
            pinned: &sq.pinned,
            scalars: &[],
            events: &[],
            garment: None,
        })?;
        // A later frame is invalid: `?` returns early and drops the recorder.
        rec.record_frame(&FrameView {
            frame: 1,
            sim_time: 0.1,
            positions: &sq.positions,
            vertex_normals: &sq.normals,
            triangles: &[[0, 1, 7]],
            triangle_levels: &[0],
            edges: &[],
            edge_angles: &[],
            pinned: &[],
            scalars: &[],
            events: &[],
            garment: None,
        })?;
        Ok(())
    })();
    let err = result.expect_err("index 7 of 4 vertices is invalid");
    assert!(
        matches!(err, RecordError::InvalidFrame { frame: 1, .. }),
        "{err}"
    );
    let bytes = std::fs::read(&path).expect("read rrd");
    assert_eq!(&bytes[bytes.len() - 12..bytes.len() - 4], b"RRF2FOOT");
    assert_eq!(decode(&path).rows.get("/cloth/mesh"), Some(&1));
    std::fs::remove_file(&path).ok();
}

#[test]
fn unwritable_path_is_an_error() {
    let err = Recorder::create(std::path::Path::new("/nonexistent-dir/x.rrd"), "unwritable")
        .expect_err("missing directory");
    assert!(matches!(err, RecordError::Create { .. }), "{err}");
    assert!(err.to_string().contains("/nonexistent-dir/x.rrd"), "{err}");
}

#[test]
fn obj_export_writes_v_vt_f_lines() {
    let dir = temp_path("obj");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let sq = square();
    let material: Vec<Vector2> = sq.positions.iter().map(|p| p.truncate() * 2.0).collect();
    let path = write_frame_obj(&dir, 7, &sq.positions, &material, &sq.triangles).expect("obj");
    assert_eq!(path, dir.join("frame_00007.obj"));
    let text = std::fs::read_to_string(&path).expect("read obj");
    let lines: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(
        lines,
        [
            "v 0 0 0",
            "v 1 0 0",
            "v 1 1 0",
            "v 0 1 0",
            "vt 0 0",
            "vt 2 0",
            "vt 2 2",
            "vt 0 2",
            "f 1/1 2/2 3/3",
            "f 1/1 3/3 4/4",
        ]
    );
    // The written file reads back with tobj.
    let (models, _) = tobj::load_obj(&path, &tobj::GPU_LOAD_OPTIONS).expect("tobj");
    assert_eq!(models[0].mesh.indices.len(), 6);

    let err = write_frame_obj(
        &dir.join("missing"),
        0,
        &sq.positions,
        &material,
        &sq.triangles,
    )
    .expect_err("missing directory");
    assert!(matches!(err, RecordError::Obj { .. }), "{err}");
    let err = write_frame_obj(&dir, 0, &sq.positions, &material[..2], &sq.triangles)
        .expect_err("material length");
    assert!(matches!(err, RecordError::InvalidFrame { .. }), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// One frame of the new recording decodes back to the full triangle list with levels: four
/// frames of a grid whose topology changes at frame 2 (a triangle removed, levels shifted),
/// each decoded at its frame and compared with what was recorded, positions to `f32`.
#[test]
fn decoded_frame_rebuilds_the_triangle_list_with_levels() {
    use drape::record::decode::cloth_mesh_at;
    let path = temp_path("decode.rrd");
    let g = grid(6);
    let mut changed = grid(6);
    changed.triangles.pop();
    changed.levels.pop();
    for l in &mut changed.levels {
        *l = (*l + 1) % 5;
    }
    let meshes = [&g, &g, &changed, &changed];
    let mut recorded = Vec::new();
    {
        let mut rec = Recorder::create(&path, "decode").expect("open");
        for (f, m) in meshes.iter().enumerate() {
            let shift = Vector::new(0.0, 0.0, -0.01 * f as f64);
            let positions: Vec<Vector> = m.positions.iter().map(|&p| p + shift).collect();
            rec.record_frame(&FrameView {
                frame: f as u64,
                sim_time: f as f64 / 30.0,
                positions: &positions,
                vertex_normals: &m.normals,
                triangles: &m.triangles,
                triangle_levels: &m.levels,
                edges: &[],
                edge_angles: &[],
                pinned: &m.pinned,
                scalars: &[],
                events: &[],
                garment: None,
            })
            .expect("frame");
            recorded.push(positions);
        }
        rec.finish().expect("finish");
    }
    for (f, (m, positions)) in meshes.iter().zip(&recorded).enumerate() {
        let d = cloth_mesh_at(&path, f as i64).expect("decodes");
        assert_eq!(d.triangles, m.triangles, "frame {f}");
        assert_eq!(d.levels, m.levels, "frame {f}");
        let f32s: Vec<[f32; 3]> = positions
            .iter()
            .map(|p| p.to_array().map(|c| c as f32))
            .collect();
        assert_eq!(d.positions, f32s, "frame {f}");
        assert_eq!(d.topology_frame, [0, 0, 2, 2][f]);
        assert!(
            d.recorded_vertices > d.positions.len(),
            "levels meet: copies"
        );
    }
    cloth_mesh_at(&path, 9).map(|_| ()).expect_err("no frame 9");
    let ins = drape::record::inspect::inspect(&path).expect("inspect");
    let flags: Vec<bool> = ins.frames.values().map(|f| f.topology).collect();
    assert_eq!(flags, [true, false, true, false]);
    assert_eq!(ins.frames[&3].levels, changed.levels, "carried to frame 3");
    std::fs::remove_file(&path).ok();
}
