//! Upper limits that keep a valid scene within memory and exact counting.
//!
//! Without them a scene with `resolution = 100000` aborted on a failed allocation,
//! and `duration = 1e300` or `dt = 1e-300` asked for a number of frames or steps
//! that no counter can hold. Each limit is documented in `docs/scenes.md` and
//! `docs/errors.md`.

use super::error::{Issue, keys, num};
use super::validate::out_of_range;
use super::{Simulation, TimeStep};

/// Largest `cloth.resolution`. A 2048 x 2048 grid has 4.2 million vertices; drape
/// needs about 1.6 kB per vertex (430 MB measured at resolution 512), so this is
/// already about 7 GB of memory. (The vertex indices are 32-bit; resolution 65536
/// would overflow them.)
pub const MAX_RESOLUTION: u32 = 2048;

/// Largest number of frames (`duration * frame_rate`) or of fixed steps
/// (`duration / dt`): 2^53, the largest count a `f64` holds exactly.
pub const MAX_COUNT: f64 = 9_007_199_254_740_992.0;

/// `cloth.resolution` at most [`MAX_RESOLUTION`].
pub(super) fn resolution(resolution: Option<u32>) -> Result<(), Issue> {
    match resolution {
        Some(r) if r > MAX_RESOLUTION => Err(out_of_range(
            keys(&["cloth", "resolution"]),
            format!(
                "{r} is out of range: must be <= {MAX_RESOLUTION} (a {r} x {r} grid would need \
                 about {:.0} GB of memory)",
                (r as f64 + 1.0).powi(2) * 1.6e3 / 1e9
            ),
        )),
        _ => Ok(()),
    }
}

/// `cloth.short_side_segments` from 1 to [`MAX_RESOLUTION`].
pub(super) fn short_side_segments(segments: Option<u32>) -> Result<(), Issue> {
    match segments {
        Some(0) => Err(out_of_range(
            keys(&["cloth", "short_side_segments"]),
            "0 is out of range: must be >= 1",
        )),
        Some(s) if s > MAX_RESOLUTION => Err(out_of_range(
            keys(&["cloth", "short_side_segments"]),
            format!("{s} is out of range: must be <= {MAX_RESOLUTION}"),
        )),
        _ => Ok(()),
    }
}

/// The number of frames and of fixed steps at most [`MAX_COUNT`]. Call after the
/// values themselves are known to be finite and positive.
pub(super) fn counts(s: &Simulation) -> Result<(), Issue> {
    let frames = s.duration * s.frame_rate;
    if frames > MAX_COUNT {
        return Err(out_of_range(
            keys(&["simulation", "duration"]),
            format!(
                "{} s at {} frames per second is {} frames, more than any run can \
                 count (at most 2^53 = {MAX_COUNT:e})",
                num(s.duration),
                num(s.frame_rate),
                num(frames)
            ),
        )
        .because(keys(&["simulation", "frame_rate"])));
    }
    if let TimeStep::Fixed(dt) = s.dt {
        let steps = s.duration / dt;
        if steps > MAX_COUNT {
            return Err(out_of_range(
                keys(&["simulation", "dt"]),
                format!(
                    "{} s steps over {} s are {} steps, more than any run can count \
                     (at most 2^53 = {MAX_COUNT:e})",
                    num(dt),
                    num(s.duration),
                    num(steps)
                ),
            )
            .because(keys(&["simulation", "duration"])));
        }
    }
    Ok(())
}
