//! `[simulation] rest`: when a run counts as at rest and ends early.

use serde::Deserialize;

/// `rest = { speed, window }`: the run ends at rest once every seam is welded
/// and no vertex has moved faster than `speed` at any frame end of the last
/// `window` seconds; `duration` stays the longest the run may take.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Rest {
    /// The largest vertex speed at rest, m/s (> 0).
    pub speed: f64,
    /// How long the speed must stay under `speed`, s (> 0).
    pub window: f64,
}
