//! The refinement decisions in a recording: each triangle's criterion ratio, term and state
//! on `cloth/mesh` every frame, decoded with Rerun's own reader and with `drape inspect`;
//! every event's reason; `drape inspect --at` following the triangle under a point; and the
//! simulation left as it is by recording them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use drape::adapt::{Adapter, TriangleState};
use drape::math::Vector;
use drape::record::DecisionData;
use drape::record::decisions::{RATIO_COMPONENT, STATE_COMPONENT, STATE_NAMES, TERM_COMPONENT};
use drape::record::history::history_at;
use drape::run::{RunOptions, run};
use drape::scene::{AdaptMethod, DiagonalPattern};
use drape::world::World;
use rerun::external::arrow::array::{Array, AsArray, types::Float32Type, types::UInt8Type};
use rerun::external::re_log_encoding::DecoderApp;
use rerun::log::{Chunk, LogMsg};

fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("drape-decisions-{}-{name}", std::process::id()))
}

/// The default scene for 0.7 s (it splits, forces splits across levels, merges, refuses
/// and bounces merges in that time), recorded to `path` with `decisions`.
fn record_default(path: &Path, decisions: DecisionData) -> drape::summary::Summary {
    let scene = drape::scene::default_scene(&["simulation.duration=0.7".to_owned()])
        .expect("the default scene");
    let opts = RunOptions {
        record: Some(path.to_path_buf()),
        decisions,
        ..RunOptions::default()
    };
    run(&scene, &opts, &AtomicBool::new(false), &mut |_| {}).expect("the run")
}

/// Per frame, from Rerun's own decoder: the `cloth/mesh` row's ratio, term and state
/// lengths, and the triangle count of the topology logged at or before it.
fn decision_lengths(path: &Path) -> BTreeMap<i64, [usize; 3]> {
    let file = std::fs::File::open(path).expect("open rrd");
    let decoder = DecoderApp::decode_eager(std::io::BufReader::new(file)).expect("rrd header");
    let mut out: BTreeMap<i64, [usize; 3]> = BTreeMap::new();
    for msg in decoder {
        let LogMsg::ArrowMsg(store, arrow) = msg.expect("decodable message") else {
            continue;
        };
        if store.kind() != rerun::StoreKind::Recording {
            continue;
        }
        let chunk = Chunk::from_arrow_msg(&arrow).expect("chunk");
        if chunk.entity_path().to_string() != "/cloth/mesh" || chunk.is_static() {
            continue;
        }
        let frames = chunk.timelines()[&"frame".into()].times_raw().to_vec();
        let column = |name: &str| {
            chunk.component_descriptors().find_map(|d| {
                (d.component.as_str() == name)
                    .then(|| chunk.components().get_array(d.component))
                    .flatten()
            })
        };
        let (ratio, term, state) = (
            column(RATIO_COMPONENT).expect("decision_ratio"),
            column(TERM_COMPONENT).expect("decision_term"),
            column(STATE_COMPONENT).expect("decision_state"),
        );
        for (row, &f) in frames.iter().enumerate() {
            let r = ratio.value(row);
            let r = r.as_primitive::<Float32Type>();
            assert!(r.values().iter().all(|v| v.is_finite() && *v >= 0.0));
            let s = state.value(row);
            let s = s.as_primitive::<UInt8Type>();
            assert!(
                s.values()
                    .iter()
                    .all(|&v| usize::from(v) < STATE_NAMES.len())
            );
            out.insert(f, [r.len(), term.value(row).len(), s.len()]);
        }
    }
    out
}

#[test]
fn every_frame_holds_each_triangles_ratio_term_and_state() {
    let path = temp("every-frame.rrd");
    let summary = record_default(&path, DecisionData::Recorded);
    let lengths = decision_lengths(&path);
    assert_eq!(
        lengths.len() as u64,
        summary.extent.frames,
        "one decision row per frame"
    );
    for (&f, lens) in &lengths {
        let mesh = drape::record::decode::cloth_mesh_at(&path, f).expect("the frame's mesh");
        assert_eq!(*lens, [mesh.triangles.len(); 3], "frame {f}");
    }
    // `drape inspect --at` reads the same components back.
    let history = history_at(&path, [0.0, 0.5, 0.8], None).expect("history");
    assert!(
        history
            .frames
            .values()
            .all(|(_, m)| !m.decisions.is_empty())
    );
    std::fs::remove_file(&path).ok();
}

/// The first event line of `kind` whose reason contains `reason`, with its frame and the
/// centroid of its triangle (its position).
fn find_event(path: &Path, kind: &str, reason: &str) -> (i64, [f64; 3], String) {
    let inspection = drape::record::inspect::inspect(path).expect("inspect");
    for (&f, info) in &inspection.frames {
        for line in &info.events {
            if line.starts_with(&format!("{kind} ")) && line.contains(reason) {
                let at = line.split(" at (").nth(1).expect("a position");
                let xyz: Vec<f64> = at
                    .split(')')
                    .next()
                    .expect("a closing parenthesis")
                    .split(',')
                    .map(|v| v.trim().parse().expect("a number"))
                    .collect();
                return (f, [xyz[0], xyz[1], xyz[2]], line.clone());
            }
        }
    }
    panic!("no {kind} event with {reason:?}");
}

#[test]
fn inspect_at_lists_the_split_forced_split_and_bounce_of_the_triangle_under_a_point() {
    let path = temp("at.rrd");
    record_default(&path, DecisionData::Recorded);
    for (kind, reason) in [
        ("split", "criterion: "),
        ("closure_split", "forced by level rule: neighbour at level"),
        ("bounce", "bounced: the previous pass merged it"),
    ] {
        let (frame, at, line) = find_event(&path, kind, reason);
        // The event's triangle is gone after it: the point is on one of its children, whose
        // history lists the event at its frame.
        let report = history_at(&path, at, Some(frame))
            .expect("history")
            .report();
        assert!(
            report.lines().any(|l| l.trim() == line),
            "{kind} at frame {frame} missing from\n{report}"
        );
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_drape"))
            .args(["inspect", path.to_str().expect("utf-8 path")])
            .arg(format!("--at={},{},{}", at[0], at[1], at[2]))
            .args(["--frame", &frame.to_string()])
            .output()
            .expect("drape inspect");
        assert!(out.status.success());
        assert_eq!(String::from_utf8_lossy(&out.stdout), report);
    }
    std::fs::remove_file(&path).ok();
}

#[test]
fn recording_the_decisions_leaves_the_simulation_as_it_is() {
    let (with, without) = (temp("with.rrd"), temp("without.rrd"));
    let a = record_default(&with, DecisionData::Recorded);
    let b = record_default(&without, DecisionData::Off);
    let last = (a.extent.frames - 1) as i64;
    let (ma, mb) = (
        drape::record::decode::cloth_mesh_at(&with, last).expect("mesh"),
        drape::record::decode::cloth_mesh_at(&without, last).expect("mesh"),
    );
    assert_eq!(ma.positions, mb.positions);
    assert_eq!(ma.triangles, mb.triangles);
    assert_eq!(
        (
            a.adaptivity.splits,
            a.adaptivity.merges,
            a.conservation.energy.r#final
        ),
        (
            b.adaptivity.splits,
            b.adaptivity.merges,
            b.conservation.energy.r#final
        )
    );
    assert!(
        std::fs::metadata(&with).expect("file").len()
            > std::fs::metadata(&without).expect("file").len()
    );
    std::fs::remove_file(&with).ok();
    std::fs::remove_file(&without).ok();
}

/// A 1 m sheet of 4 x 4 squares folded 90 degrees about the grid line through its middle.
fn folded_sheet() -> World {
    let m = drape::mesh::rectangle(1.0, 1.0, 4, DiagonalPattern::Regular).expect("a grid");
    // Folded 90 degrees about the grid line through the middle of the sheet: the edges on
    // the crease bend far past 15 degrees.
    let mid = 0.5 * (m.material_bounds().0.x + m.material_bounds().1.x);
    let x = m
        .material
        .iter()
        .map(|p| match p.x > mid {
            true => Vector::new(mid, p.y, p.x - mid),
            false => p.extend(0.0),
        })
        .collect();
    World::new(m, x)
}

#[test]
fn a_fold_at_max_level_is_held_there() {
    let world = folded_sheet();
    for (max_level, want) in [(0, TriangleState::AtMaxLevel), (4, TriangleState::Free)] {
        let config = drape::adapt::AdaptConfig {
            max_level,
            ..crate::common::angle_config(AdaptMethod::RedGreen)
        };
        let ad = Adapter::new(&config, &world, 0.15).expect("the adapter");
        let decisions = ad.decisions(&config, &world, &[]);
        assert_eq!(decisions.len(), world.mesh.triangles.len());
        let creased: Vec<_> = decisions.iter().filter(|d| d.reading.ratio > 1.0).collect();
        assert!(!creased.is_empty(), "the crease is past the threshold");
        assert!(
            creased.iter().all(|d| d.state == want),
            "max_level {max_level}"
        );
        // 90 degrees over 15.
        assert!(creased.iter().all(|d| (d.reading.ratio - 6.0).abs() < 1e-9));
    }
}

#[test]
fn an_edge_method_fold_whose_split_would_be_too_short_is_at_the_smallest_edge() {
    let world = folded_sheet();
    // The squares' diagonals are 0.354 m: bisected, 0.177 m.
    for (min_edge, want) in [(0.2, TriangleState::AtMinEdge), (0.1, TriangleState::Free)] {
        let config = drape::adapt::AdaptConfig {
            max_level: 4,
            min_edge_length: min_edge,
            ..crate::common::angle_config(AdaptMethod::Edge)
        };
        let ad = Adapter::new(&config, &world, 0.15).expect("the adapter");
        let decisions = ad.decisions(&config, &world, &[]);
        let creased: Vec<_> = decisions.iter().filter(|d| d.reading.ratio > 1.0).collect();
        assert!(!creased.is_empty(), "the crease is past the threshold");
        assert!(
            creased.iter().all(|d| d.state == want),
            "min_edge_length {min_edge}: {:?}",
            creased.iter().map(|d| d.state).collect::<Vec<_>>()
        );
    }
}
