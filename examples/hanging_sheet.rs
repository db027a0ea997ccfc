//! drape as a library: load a scene, run it without recording while
//! observing every frame, and print the run's summary.
//!
//! The embedded default scene (a sheet pinned at two corners that falls and
//! swings, its mesh adapting) is loaded with one override, and the lowest
//! point of the cloth is measured at every recorded frame.
//!
//! ```sh
//! cargo run --release --example hanging_sheet
//! ```

use std::sync::atomic::AtomicBool;

use drape::run::{FrameState, RunOptions, run_observed};
use drape::scene::default_scene;

fn main() -> anyhow::Result<()> {
    // Any scene file works the same way: drape::scene::load_scene_file(path, &overrides).
    let scene = default_scene(&["simulation.duration=2.0".to_owned()])?;
    let options = RunOptions::default(); // no recording, one thread per core
    let mut lowest = Vec::new();
    let mut observe = |frame: &FrameState| {
        let z = frame
            .positions
            .iter()
            .map(|p| p.z)
            .fold(f64::INFINITY, f64::min);
        lowest.push((frame.sim_time, z, frame.triangles.len()));
    };
    let stop = AtomicBool::new(false);
    let summary = run_observed(&scene, &options, &stop, &mut |_| {}, &mut observe)?;
    for (t, z, triangles) in lowest.iter().step_by(10) {
        println!("t = {t:.2} s: lowest point z = {z:.3} m, {triangles} triangles");
    }
    println!("{}", summary.paragraph());
    Ok(())
}
