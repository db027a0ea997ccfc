//! Helpers shared by the test modules.

use drape::adapt::AdaptConfig;
use drape::scene::{AdaptCriterion, AdaptMethod, Pin, PinMotion};

/// A fixed pin on `region` with every other key at its default.
pub fn pin(region: &str) -> Pin {
    Pin {
        region: region.into(),
        box_min: None,
        box_max: None,
        motion: PinMotion::Fixed,
        velocity: [0.0; 3],
        acceleration: [0.0; 3],
        center: [0.0; 3],
        axis: [0.0, 0.0, 1.0],
        angular_velocity: 0.0,
        release_time: None,
    }
}

/// Adaptivity with the papers' angle criterion as most tests use it: 15 / 1.5
/// deg, levels up to 4, a pass whenever the test calls one, no rollback. Tests
/// change what they need with `AdaptConfig { .., ..angle_config(method) }`.
pub fn angle_config(method: AdaptMethod) -> AdaptConfig {
    AdaptConfig {
        method,
        refine_angle: 15.0,
        coarsen_angle: 1.5,
        max_level: 4,
        min_edge_length: 0.0,
        every: 1,
        rollback: false,
        max_rollbacks: 0,
        criterion: AdaptCriterion::Angle,
        hysteresis: 2.0,
    }
}
