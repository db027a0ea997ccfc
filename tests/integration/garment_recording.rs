//! Garments in the recording: the seams at `cloth/seams` (open pairs, then the welded
//! seams' edges), the `weld` events, and `--colour-by panel` (class id = panel index),
//! decoded back from short runs of the skirt scene.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::AtomicBool;

use drape::record::ColourBy;
use drape::record::decode::cloth_mesh_at;
use drape::record::garment::{SEAM_CLASS_OPEN, SEAM_CLASS_WELDED};
use drape::record::inspect::inspect;
use drape::run::{RunOptions, run};
use drape::scene::{Scene, default_scene, load_scene_file};

/// A fresh path in the temp dir, unique per process and call.
fn temp_path(name: &str) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    std::env::temp_dir().join(format!("drape-gr-{}-{n}-{name}", std::process::id()))
}

/// The skirt for `duration` seconds (its side seams weld at about 0.033 s).
fn skirt(duration: f64) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/skirt.toml");
    load_scene_file(&path, &[format!("simulation.duration={duration}")]).expect("skirt scene")
}

/// Runs `scene` recorded to `out` with the triangles coloured by `colour_by`.
fn record(scene: &Scene, out: &Path, colour_by: ColourBy) {
    let opts = RunOptions {
        record: Some(out.to_path_buf()),
        colour_by,
        ..RunOptions::default()
    };
    run(scene, &opts, &AtomicBool::new(false), &mut |_| {}).expect("run");
}

/// The panel of each triangle of the scene's cloth as built (welding keeps the triangle
/// order and panels).
fn built_panels(scene: &Scene) -> (Vec<u16>, usize) {
    let sim = drape::sim::build(&scene.resolve().expect("resolve")).expect("simulation");
    let mesh = &sim.state.world.mesh;
    let panels = mesh.panels().expect("a garment");
    let pairs = panels.seams.iter().map(|s| s.pairs.len()).sum();
    (panels.of_triangle.clone(), pairs)
}

#[test]
fn skirt_seams_show_open_pairs_then_welded_edges() {
    let scene = skirt(0.2);
    let out = temp_path("seams.rrd");
    record(&scene, &out, ColourBy::Level);
    let (_, pairs) = built_panels(&scene);
    let ins = inspect(&out).expect("decodes");
    let rows = ins
        .entities
        .get("/cloth/seams")
        .expect("a cloth/seams entity");
    assert_eq!(rows.static_rows, 1, "annotation context and width, once");
    assert_eq!(rows.temporal, ins.frames.len(), "a row every frame");
    let first = ins.frames[&0].seams.as_ref().expect("seams at frame 0");
    assert_eq!((first.open, first.welded), (pairs, 0), "every pair open");
    assert!(first.classes.iter().all(|&c| c == SEAM_CLASS_OPEN));
    for side in ["left", "right"] {
        assert!(first.names.iter().any(|n| n == side), "{side} named");
    }
    let last = ins.frames.values().next_back().expect("frames");
    let last = last.seams.as_ref().expect("seams at the last frame");
    assert_eq!(last.open, 0, "both seams welded by 0.2 s");
    assert!(last.classes.iter().all(|&c| c == SEAM_CLASS_WELDED));
    // A welded side seam is a chain of edges: one fewer than its pairs.
    assert_eq!(last.welded, pairs - 2, "the welded seams' edges");
    for side in ["left", "right"] {
        assert_eq!(
            last.names.iter().filter(|n| *n == side).count(),
            pairs / 2 - 1
        );
    }
    std::fs::remove_file(&out).ok();
}

#[test]
fn skirt_welds_are_events_naming_their_seam_and_gap() {
    let scene = skirt(0.2);
    let out = temp_path("welds.rrd");
    record(&scene, &out, ColourBy::Level);
    let ins = inspect(&out).expect("decodes");
    assert_eq!(ins.event_counts().get("weld"), Some(&2), "two side seams");
    let welds: Vec<(i64, &String)> = ins
        .frames
        .iter()
        .flat_map(|(&n, f)| f.events.iter().map(move |e| (n, e)))
        .filter(|(_, e)| e.starts_with("weld "))
        .collect();
    for side in ["left", "right"] {
        let (frame, line) = welds
            .iter()
            .find(|(_, e)| e.contains(&format!("seam {side}, gap ")))
            .unwrap_or_else(|| panic!("a weld of {side} in {welds:?}"));
        let gap_mm: f64 = line
            .split("gap ")
            .nth(1)
            .and_then(|g| g.split(" mm").next())
            .and_then(|g| g.parse().ok())
            .unwrap_or_else(|| panic!("a gap in {line}"));
        assert!(
            (0.0..5.0).contains(&gap_mm),
            "within the 5 mm weld gap: {line}"
        );
        // The frame of the weld is the first that shows the seam welded.
        let seams = ins.frames[frame].seams.as_ref().expect("seams");
        let open_before = ins.frames[&(frame - 1)].seams.as_ref().expect("seams");
        assert!(
            seams
                .names
                .iter()
                .zip(&seams.classes)
                .any(|(n, &c)| n == side && c == SEAM_CLASS_WELDED)
        );
        assert!(
            open_before
                .names
                .iter()
                .zip(&open_before.classes)
                .all(|(n, &c)| n != side || c == SEAM_CLASS_OPEN)
        );
    }
    std::fs::remove_file(&out).ok();
}

#[test]
fn colour_by_panel_gives_each_triangle_its_panel_index() {
    let scene = skirt(0.1);
    let out = temp_path("panels.rrd");
    record(&scene, &out, ColourBy::Panel);
    let (of_triangle, _) = built_panels(&scene);
    assert!(
        of_triangle.contains(&0) && of_triangle.contains(&1),
        "front and back"
    );
    let ins = inspect(&out).expect("decodes");
    let last = *ins.frames.keys().next_back().expect("frames");
    for frame in [0, last] {
        let f = cloth_mesh_at(&out, frame).expect("frame decodes");
        assert_eq!(f.classes, of_triangle, "frame {frame}: class id = panel");
        assert!(f.levels.iter().all(|&l| l == 0), "levels still recorded");
    }
    // By default the classes are the levels.
    let by_level = temp_path("levels.rrd");
    record(&scene, &by_level, ColourBy::Level);
    let f = cloth_mesh_at(&by_level, 0).expect("frame decodes");
    assert_eq!(f.classes, vec![0; of_triangle.len()]);
    std::fs::remove_file(&out).ok();
    std::fs::remove_file(&by_level).ok();
}

#[test]
fn cloth_without_panels_has_no_seams_and_colours_as_one_panel() {
    let scene = default_scene(&["simulation.duration=0.1".to_owned()]).expect("scene");
    let out = temp_path("plain.rrd");
    record(&scene, &out, ColourBy::Panel);
    let ins = inspect(&out).expect("decodes");
    assert!(
        !ins.entities.contains_key("/cloth/seams"),
        "no seams entity"
    );
    assert!(ins.frames.values().all(|f| f.seams.is_none()));
    let f = cloth_mesh_at(&out, 0).expect("frame decodes");
    assert!(!f.classes.is_empty() && f.classes.iter().all(|&c| c == 0));
    std::fs::remove_file(&out).ok();
}

#[test]
fn colour_by_flag_is_in_help_and_inspect_lists_the_seams() {
    let exe = env!("CARGO_BIN_EXE_drape");
    let help = Command::new(exe)
        .args(["run", "--help"])
        .output()
        .expect("help");
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(help.contains("--colour-by"), "{help}");
    let out = temp_path("cli.rrd");
    let skirt = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/skirt.toml");
    let status = Command::new(exe)
        .arg("run")
        .arg(&skirt)
        .args([
            "--set",
            "simulation.duration=0.1",
            "--colour-by",
            "panel",
            "-q",
            "-o",
        ])
        .arg(&out)
        .output()
        .expect("run");
    assert!(status.status.success(), "{status:?}");
    let report = Command::new(exe)
        .arg("inspect")
        .arg(&out)
        .output()
        .expect("inspect");
    let report = String::from_utf8_lossy(&report.stdout);
    assert!(
        report.contains("seams per frame: open segments 0 to "),
        "{report}"
    );
    assert!(report.contains("/cloth/seams"), "{report}");
    assert!(report.contains("weld 2"), "{report}");
    let bad = Command::new(exe)
        .arg("run")
        .arg(&skirt)
        .args(["--colour-by", "seam", "--no-record"])
        .output()
        .expect("run");
    assert_eq!(bad.status.code(), Some(2), "a usage error");
    std::fs::remove_file(&out).ok();
}
