//! The error metric converges: at rest, uniform meshes approach a fine
//! reference at the rate linear triangles allow.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use crate::bench::temp_dir;
use drape::bench::{BenchOptions, Compare, Ladder, Rung, bench};

/// A double cantilever: a strip 6.4 cm x 0.8 cm clamped over its middle 8 mm
/// (the clamp's edges at +-4 mm are mesh lines at 16, 32, 64 and 128 segments,
/// so every mesh holds the same clamp), two 2.8 cm arms bending under their
/// weight, with the cantilever scene's material and heavy air drag, so that it
/// is at rest after 2.5 s.
fn strip_scene(dir: &Path) -> PathBuf {
    let path = dir.join("strip.toml");
    std::fs::write(
        &path,
        r#"name = "strip"
[simulation]
duration = 2.5
frame_rate = 10
integrator = "implicit"
dt = 0.02
[cloth]
shape = "rectangle"
width = 0.064
height = 0.008
resolution = 16
position = [0.0, 0.0, 0.5]
[material]
density = 0.15
stretch = 1.0e4
bending_length = 0.02
damping = 0.0005
[air]
drag = 4.0
[[pin]]
region = "box"
box_min = [-0.004, -0.01]
box_max = [0.004, 0.01]
"#,
    )
    .expect("write scene");
    path
}

#[test]
fn uniform_error_at_rest_falls_with_resolution() {
    let dir = temp_dir("convergence");
    let rungs = [16, 32, 64].map(|n| {
        Rung::new(
            format!("uniform {n}"),
            vec![format!("cloth.resolution={n}")],
        )
    });
    let opts = BenchOptions {
        scene: strip_scene(&dir),
        overrides: vec![],
        ladder: Some(Ladder {
            reference: Some(vec!["cloth.resolution=128".into()]),
            compare: Some(Compare::Rest),
            step: None,
            rung: rungs.to_vec(),
        }),
        time_ladder: false,
        rungs: vec![],
        compare: None,
        step: None,
        reps: 1,
        duration: None,
        threads: None,
        cache: false,
        reference_resolution: None,
        grid: 24,
        floor: false,
    };
    let (res, _) = bench(
        &opts,
        &dir.join("out"),
        &AtomicBool::new(false),
        &mut |_| {},
    )
    .expect("bench");
    let e: Vec<f64> = res.rows.iter().map(|r| r.error).collect();
    let motion = res.reference_last_motion.expect("frames");
    assert!(res.rows.iter().all(|r| r.status == "ok"), "{:?}", res.rows);
    // The reference has settled: its last frame moves it far less than the
    // smallest error measured.
    assert!(
        motion < 0.1 * e[2],
        "the reference moved {motion:e}, errors {e:?}"
    );
    assert!(e[0] > e[1] && e[1] > e[2] && e[2] > 0.0, "{e:?}");
    // Linear triangles approximate a smooth bent shape to O(h^2); first order
    // or worse would mean the model does not converge as it should.
    let order = (e[0] / e[2]).log2() / 2.0;
    assert!(order > 1.5, "observed order {order}, errors {e:?}");
    std::fs::remove_dir_all(&dir).ok();
}
