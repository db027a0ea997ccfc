//! Recordings of whole runs (SPEC 7): the schema decoded back with rerun's decoder,
//! event counts against the engine's counters, completeness after an error and after Ctrl-C,
//! reproducibility, `--record-every` and the edge options.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use drape::record::EdgeDisplay;
use drape::record::decode::cloth_mesh_at;
use drape::record::edges::REVIEW_BAND;
use drape::record::inspect::{Inspection, inspect};
use drape::run::{RunError, RunOptions, run, run_observed};
use drape::scene::{Scene, default_scene, load_scene_file};
use drape::summary::Summary;

/// A fresh path in the temp dir, unique per process and call.
fn temp_path(name: &str) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!("drape-rr-{}-{n}-{name}", std::process::id()))
}

fn scene_file(name: &str, sets: &[&str]) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    load_scene_file(&path, &sets).expect("scene")
}

/// Runs `scene` recording to `out` with `opts` (its `record` is set here).
fn record(scene: &Scene, out: &Path, opts: RunOptions) -> Result<Summary, RunError> {
    let opts = RunOptions {
        record: Some(out.to_path_buf()),
        ..opts
    };
    run(scene, &opts, &AtomicBool::new(false), &mut |_| {})
}

/// The short adaptive run with an obstacle that exercises every entity of the schema: the
/// tablecloth at resolution 8 for 0.5 s (it lands on the table at about 0.2 s and folds).
fn tablecloth_short() -> Scene {
    scene_file(
        "tablecloth.toml",
        &["cloth.resolution=8", "simulation.duration=0.5"],
    )
}

/// The band of angles the default edge choice keeps: within a factor `REVIEW_BAND` of the
/// scene's refine threshold.
fn review_band(scene: &Scene) -> (f64, f64) {
    let refine = scene
        .adapt
        .as_ref()
        .expect("an adaptive scene")
        .refine_angle;
    (refine / REVIEW_BAND, refine * REVIEW_BAND)
}

/// Every frame has one mesh row, one `triangle_level` per triangle, the triangle count of the
/// `mesh/triangles` plot, and the edges: with `all_edges` (a disk-like sheet) `V + T - 1` of
/// them with the largest angle equal to the `angle/max_deg` plot; else (the default choice)
/// at most that many, every one in the band near the refine threshold, none when the largest
/// angle is below the band, and the largest one whenever it is in the band (the angles are
/// recorded as `f32`).
fn check_frames(ins: &Inspection, all_edges: bool, (low, high): (f64, f64)) {
    let topology = ins.frames.values().filter(|f| f.topology).count();
    assert!(
        ins.frames.values().next().is_some_and(|f| f.topology),
        "topology logged on {topology} of {} frames, not the first",
        ins.frames.len()
    );
    for (n, f) in &ins.frames {
        assert_eq!(f.mesh_rows, 1, "frame {n}: one mesh row");
        let tris = f.triangles.expect("mesh topology");
        assert_eq!(f.levels.len(), tris, "frame {n}: one level per triangle");
        assert_eq!(f.scalars.get("mesh/triangles"), Some(&(tris as f64)));
        let verts = f.vertices().expect("vertex plot") as usize;
        let edges = f.edges.expect("edges row");
        let plotted = f.scalars["angle/max_deg"];
        // The f32 angle of an edge at exactly a bound may round to either side of it.
        let slack = 1e-6;
        if all_edges {
            assert_eq!(edges, verts + tris - 1, "frame {n}: Euler's formula");
        } else {
            assert!(edges < verts + tris, "frame {n}: at most V + T - 1");
            if let (Some(min), Some(max)) = (f.min_edge_angle, f.max_edge_angle) {
                assert!(
                    min >= low - slack && max <= high + slack,
                    "frame {n}: kept edges from {min} to {max} deg"
                );
            }
            if plotted < low {
                assert_eq!(edges, 0, "frame {n}: nothing near the threshold");
                continue;
            }
            if plotted > high {
                continue;
            }
        }
        let max = f.max_edge_angle.expect("angles");
        assert!(
            (max - plotted).abs() <= 1e-6 * plotted.max(1.0),
            "{max} vs {plotted}"
        );
    }
}

/// `events/log` counts by kind against the summary's counters.
fn check_event_counts(ins: &Inspection, summary: &Summary) {
    let counts = ins.event_counts();
    let n = |k: &str| counts.get(k).copied().unwrap_or(0) as u64;
    let a = summary.adaptivity.adapt.expect("adaptive run");
    assert_eq!(
        n("split") + n("closure_split") + n("bounce"),
        a.splits,
        "events in the file {counts:?}; engine {a:?}"
    );
    assert_eq!(n("bounce"), a.bounces);
    assert_eq!(n("merge") + n("collapse"), a.merges);
    assert_eq!(n("rollback"), a.rollbacks);
    assert_eq!(n("flip"), a.flips);
}

#[test]
fn adaptive_run_holds_the_whole_schema() {
    let out = temp_path("schema.rrd");
    let scene = tablecloth_short();
    let summary = record(&scene, &out, RunOptions::default()).expect("run");
    let ins = inspect(&out).expect("decodes");
    assert!(ins.footer);
    let mut expected: BTreeSet<String> = [
        "/",
        "/cloth",
        "/cloth/mesh",
        "/cloth/edges",
        "/cloth/pins",
        "/events/points",
        "/events/log",
        "/legend",
    ]
    .into_iter()
    .map(String::from)
    .collect();
    for plot in [
        "mesh/vertices",
        "mesh/triangles",
        "energy/kinetic",
        "energy/gravitational",
        "energy/elastic",
        "energy/total",
        "time/dt_ms",
        "timing/sim_ms",
        "timing/record_ms",
        "angle/max_deg",
        "adapt/splits",
        "adapt/merges",
        "adapt/flips",
        "adapt/rollbacks",
        "collision/contacts",
        "penetration/max_mm",
    ] {
        expected.insert(format!("/plots/{plot}"));
    }
    let present: BTreeSet<String> = ins.entities.keys().cloned().collect();
    let missing: Vec<_> = expected.difference(&present).collect();
    assert!(missing.is_empty(), "missing entities {missing:?}");
    let obstacles: Vec<_> = present
        .iter()
        .filter(|p| p.starts_with("/obstacles/"))
        .collect();
    assert!(!obstacles.is_empty(), "an obstacle entity");
    assert!(obstacles.iter().all(|p| ins.entities[*p].static_rows == 1));
    assert_eq!(ins.frames.len() as u64, summary.extent.frames);
    assert_eq!(
        ins.entities["/cloth/mesh"].temporal as u64,
        summary.extent.frames
    );
    let rec = summary.recording.as_ref().expect("recording");
    assert_eq!(rec.frames, summary.extent.frames);
    assert_eq!(rec.bytes, ins.bytes);
    assert!(summary.adaptivity.splits > 0, "the short run refines");
    check_frames(&ins, false, review_band(&scene));
    check_event_counts(&ins, &summary);
    std::fs::remove_file(&out).ok();
}

/// The engine's positions (as `f32`) and triangles of one recorded frame.
type SeenFrame = (Vec<[f32; 3]>, Vec<[u32; 3]>);

/// Every recorded frame decodes back to the engine's mesh of that frame: the same triangles
/// in the same order, one level per triangle, and the positions to `f32`; between topology
/// changes the frame shows the topology logged last.
#[test]
fn every_frame_decodes_to_the_engine_mesh() {
    let out = temp_path("decode.rrd");
    let opts = RunOptions {
        record: Some(out.clone()),
        ..RunOptions::default()
    };
    let mut seen: Vec<SeenFrame> = Vec::new();
    let summary = run_observed(
        &tablecloth_short(),
        &opts,
        &AtomicBool::new(false),
        &mut |_| {},
        &mut |s| {
            let f32s = s.positions.iter().map(|p| p.to_array().map(|c| c as f32));
            seen.push((f32s.collect(), s.triangles.to_vec()));
        },
    )
    .expect("run");
    assert_eq!(seen.len() as u64, summary.extent.frames);
    let ins = inspect(&out).expect("decodes");
    for (n, (positions, triangles)) in seen.iter().enumerate() {
        let f = cloth_mesh_at(&out, n as i64).expect("frame decodes");
        assert_eq!(&f.positions, positions, "frame {n}: positions");
        assert_eq!(&f.triangles, triangles, "frame {n}: triangles");
        assert_eq!(f.levels, ins.frames[&(n as i64)].levels, "frame {n}");
        assert_eq!(f.levels.len(), triangles.len());
        assert_eq!(f.normals.len(), positions.len());
    }
    std::fs::remove_file(&out).ok();
}

#[test]
fn record_every_thins_frames_and_keeps_every_event() {
    let out = temp_path("every.rrd");
    let scene = scene_file(
        "hanging_sheet.toml",
        &["cloth.resolution=8", "simulation.duration=0.5"],
    );
    let every = 4;
    let opts = RunOptions {
        record_every: every,
        ..RunOptions::default()
    };
    let summary = record(&scene, &out, opts).expect("run");
    let ins = inspect(&out).expect("decodes");
    let last = summary.extent.frames - 1;
    let expected: Vec<i64> = (0..=last)
        .filter(|f| f % every == 0 || *f == last)
        .map(|f| f as i64)
        .collect();
    let got: Vec<i64> = ins.frames.keys().copied().collect();
    assert_eq!(got, expected);
    assert!(
        got.len() < summary.extent.frames as usize,
        "{} frames simulated, recorded {got:?}",
        summary.extent.frames
    );
    assert_eq!(
        summary.recording.as_ref().map(|r| r.frames),
        Some(got.len() as u64)
    );
    check_frames(&ins, false, review_band(&scene));
    check_event_counts(&ins, &summary);
    std::fs::remove_file(&out).ok();
}

#[test]
fn edge_options_filter_or_drop_cloth_edges() {
    let scene = scene_file(
        "hanging_sheet.toml",
        &["cloth.resolution=8", "simulation.duration=0.3"],
    );
    let (all, above, none, review) = (
        temp_path("all.rrd"),
        temp_path("above.rrd"),
        temp_path("none.rrd"),
        temp_path("review.rrd"),
    );
    let threshold = 2.0;
    for (path, edges) in [
        (&all, EdgeDisplay::All),
        (&above, EdgeDisplay::Above(threshold)),
        (&none, EdgeDisplay::Off),
        (&review, EdgeDisplay::Review),
    ] {
        let opts = RunOptions {
            edges,
            ..RunOptions::default()
        };
        record(&scene, path, opts).expect("run");
    }
    let (all_i, above_i, none_i, review_i) = (
        inspect(&all).expect("all"),
        inspect(&above).expect("above"),
        inspect(&none).expect("none"),
        inspect(&review).expect("review"),
    );
    assert!(!none_i.entities.contains_key("/cloth/edges"));
    check_frames(&all_i, true, review_band(&scene));
    check_frames(&review_i, false, review_band(&scene));
    let kept = |i: &Inspection| i.frames.values().filter_map(|f| f.edges).sum::<usize>();
    assert!(
        kept(&review_i) < kept(&all_i),
        "the default leaves flat edges out"
    );
    assert!(
        kept(&review_i) <= kept(&above_i),
        "the band (12.5 to 18 deg) is within the edges above 2 deg"
    );
    let mut kept_some = false;
    for (n, f) in &all_i.frames {
        let g = &above_i.frames[n];
        let kept = g.edges.expect("edges row");
        assert!(kept <= f.edges.expect("edges row"));
        if let Some(min) = g.min_edge_angle {
            assert!(min > threshold, "frame {n}: kept an edge at {min} deg");
            kept_some = true;
        }
        // The largest angle is the same whenever an edge is above the threshold.
        if f.max_edge_angle.is_some_and(|m| m > threshold) {
            assert_eq!(g.max_edge_angle, f.max_edge_angle);
        } else {
            assert_eq!(kept, 0, "frame {n}");
        }
    }
    assert!(kept_some, "the run bends past {threshold} deg somewhere");
    for p in [all, above, none, review] {
        std::fs::remove_file(p).ok();
    }
}

#[test]
fn numerical_failure_leaves_a_complete_recording() {
    // An explicit integrator at a step so far past its stability limit that even the
    // smallest retry (1/16 of it) is slightly unstable: each frame is saved by a retry
    // while the unstable mode grows, until even the smallest step lets the energy
    // explode (frame 4 here) and the run stops.
    let scene = default_scene(&[
        "simulation.integrator=symplectic_euler".into(),
        "simulation.dt=0.03".into(),
        "cloth.resolution=8".into(),
    ])
    .expect("scene");
    let out = temp_path("numerical.rrd");
    let err = record(&scene, &out, RunOptions::default()).expect_err("numerical failure");
    let RunError::Numerical { frame, summary, .. } = err else {
        panic!("not a numerical failure: {err}");
    };
    assert!(frame > 1, "failed mid-way, at frame {frame}");
    let ins = inspect(&out).expect("decodes completely");
    assert!(ins.footer, "footer written");
    assert_eq!(ins.frames.len() as u64, summary.extent.frames);
    assert_eq!(
        *ins.frames.keys().next_back().expect("frames"),
        frame as i64 - 1
    );

    // With --record-every 4 the last good frame is not a multiple of 4: it is recorded too.
    assert_ne!(
        (frame - 1) % 4,
        0,
        "the check below needs an unaligned last frame"
    );
    let opts = RunOptions {
        record_every: 4,
        ..RunOptions::default()
    };
    let err = record(&scene, &out, opts).expect_err("numerical failure");
    let RunError::Numerical { frame: again, .. } = err else {
        panic!("not a numerical failure: {err}");
    };
    assert_eq!(again, frame, "same failure");
    let ins = inspect(&out).expect("decodes completely");
    let got: Vec<i64> = ins.frames.keys().copied().collect();
    let expected: Vec<i64> = (0..frame as i64)
        .filter(|f| f % 4 == 0 || *f == frame as i64 - 1)
        .collect();
    assert_eq!(got, expected);
    std::fs::remove_file(&out).ok();
}

/// Compares the decoded contents of two recordings row by row (see `canonical.rs`).
#[test]
fn same_scene_twice_gives_identical_decoded_contents() {
    let scene = tablecloth_short();
    let (a, b) = (temp_path("a.rrd"), temp_path("b.rrd"));
    record(&scene, &a, RunOptions::default()).expect("run a");
    record(&scene, &b, RunOptions::default()).expect("run b");
    let (ra, rb) = (
        crate::canonical::rows(&a, crate::canonical::WALL_CLOCK),
        crate::canonical::rows(&b, crate::canonical::WALL_CLOCK),
    );
    assert!(ra.len() > 100, "{} rows", ra.len());
    crate::canonical::assert_same(&ra, &rb);
    for p in [a, b] {
        std::fs::remove_file(p).ok();
    }
}

#[test]
fn sigint_leaves_a_complete_recording() {
    let dir = temp_path("sigint");
    std::fs::create_dir_all(&dir).expect("dir");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/tablecloth.toml");
    let mut child = Command::new(env!("CARGO_BIN_EXE_drape"))
        .args(["run", scene.to_str().expect("utf-8 path"), "-q"])
        .args(["--out", "x.rrd", "--summary", "s.json"])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn drape");
    // Let it start recording, then interrupt. Without a live viewer rerun writes an entity's
    // rows only once they reach 2 MiB, so the file's size says little about the frames done:
    // wait for the file, then a little (the first, flat frames are quick).
    let started = Instant::now();
    let rrd = dir.join("x.rrd");
    while !rrd.exists() && started.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(100));
    }
    std::thread::sleep(Duration::from_secs(2));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill -INT");
    assert!(status.success());
    let deadline = Instant::now() + Duration::from_secs(60);
    let code = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s.code();
        }
        assert!(Instant::now() < deadline, "drape did not stop after SIGINT");
        std::thread::sleep(Duration::from_millis(50));
    };
    assert_eq!(code, Some(130), "interrupted after {:?}", started.elapsed());
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("s.json")).expect("summary"))
            .expect("json");
    assert_eq!(summary["interrupted"], true);
    let ins = inspect(&rrd).expect("decodes completely");
    assert!(ins.footer, "footer written");
    let frames = summary["frames"].as_u64().expect("frames");
    assert!(frames < 121, "stopped early");
    assert_eq!(ins.frames.len() as u64, frames);
    assert_eq!(ins.entities["/cloth/mesh"].temporal as u64, frames);
    std::fs::remove_dir_all(&dir).ok();
}

/// Regression: the step plot showed the automatic step's target (10 ms on
/// `hanging_sheet_rest`), not the step taken (8.333 ms: the target evened out
/// so that four steps end each 1/30 s frame). Now every frame plots the step
/// the run took, here the frame interval over the steps per frame.
#[test]
fn step_plot_shows_the_step_taken_not_the_target() {
    let scene = scene_file(
        "hanging_sheet_rest.toml",
        &[
            "adapt.method=\"none\"",
            "cloth.resolution=8",
            "simulation.duration=0.5",
        ],
    );
    let out = temp_path("dt.rrd");
    let summary = record(&scene, &out, RunOptions::default()).expect("run");
    let taken_ms = 1e3 * summary.extent.sim_time / summary.extent.steps as f64;
    let ins = inspect(&out).expect("decodes");
    let plotted: Vec<f64> = ins
        .frames
        .values()
        .filter_map(|f| f.scalars.get("time/dt_ms").copied())
        .collect();
    assert_eq!(
        plotted.len() as u64,
        summary.extent.frames,
        "plotted {plotted:?}"
    );
    for (n, ms) in plotted.iter().enumerate() {
        assert!(
            (ms - taken_ms).abs() <= 1e-9 * taken_ms,
            "frame {n}: plotted {ms} ms, taken {taken_ms} ms"
        );
    }
    std::fs::remove_file(&out).ok();
}

/// Bounces (`src/adapt/sizing.rs`, "Bounces") are recorded as `bounce` events,
/// one per bounce the summary counts, and counted among the splits: the case
/// of `adapt_sizing::a_sheet_at_rest_stops_remeshing` over 1 s, where they
/// happen.
#[test]
fn bounces_are_recorded_as_their_own_events() {
    let out = temp_path("bounces.rrd");
    let sets: Vec<&str> = std::iter::once("simulation.duration=1.0")
        .chain(crate::common::BOUNCING_SHEET)
        .collect();
    let scene = scene_file("hanging_sheet_rest.toml", &sets);
    let summary = record(&scene, &out, RunOptions::default()).expect("run");
    let ins = inspect(&out).expect("decodes");
    let bounces = ins.event_counts().get("bounce").copied().unwrap_or(0);
    assert!(bounces > 0, "the case bounces");
    check_event_counts(&ins, &summary);
    let _ = std::fs::remove_file(&out);
}
