//! The shift part of a run's error at rest, with its direction: runs a scene
//! (with `--set`-style overrides) sampled the way `drape bench` samples it and
//! prints, against a cached bench reference, the last frame's error and the
//! mean displacement of the samples from the reference's (x, y, z in mm).
//! `drape bench` reports the length of that mean as the final offset; this
//! shows its sign (`docs/speed-vs-error-history.md`, "Strain thresholds").
//!
//! ```sh
//! cargo run --release --example rest_offset -- scenes/hanging_sheet_rest.toml \
//!     bench-out/s6/hs-strain/cache/hanging_sheet_rest-f5d2b38cfd7626f4.json \
//!     cloth.resolution=64 adapt.method=none
//! ```

use std::path::Path;
use std::sync::atomic::AtomicBool;

use anyhow::{Context, bail};
use drape::bench::Reference;
use drape::bench::metric::{mean_displacement, relative_rms};
use drape::bench::sampling::{matched, sampled_run};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [scene, reference, overrides @ ..] = args.as_slice() else {
        bail!("usage: rest_offset SCENE.toml REFERENCE.json [KEY=VALUE ...]");
    };
    let scene = drape::scene::load_scene_file(Path::new(scene), overrides)?;
    let text =
        std::fs::read_to_string(reference).with_context(|| format!("reading {reference}"))?;
    let reference: Reference =
        serde_json::from_str(&text).with_context(|| format!("parsing {reference}"))?;
    let run = sampled_run(
        &scene,
        &drape::run::RunOptions::default(),
        &reference.sample_points(),
        &AtomicBool::new(false),
    )?;
    let (Some(last), Some(r)) = (run.frames.last(), reference.frames.last()) else {
        bail!("no frames");
    };
    if last.frame != r.frame {
        bail!(
            "the run ends at frame {}, the reference at {}",
            last.frame,
            r.frame
        );
    }
    let (a, b) = matched(last, r).context("no common samples")?;
    let error = relative_rms(&a, &b, reference.diagonal);
    let mean = mean_displacement(&a, &b);
    println!(
        "error {:.4e} of the diagonal, mean displacement ({:.3}, {:.3}, {:.3}) mm, {:.0} mean vertices: {}",
        error,
        1e3 * mean.x,
        1e3 * mean.y,
        1e3 * mean.z,
        run.summary.vertices.mean,
        overrides.join(" ")
    );
    Ok(())
}
