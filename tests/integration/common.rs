//! Helpers shared by the test modules.

use drape::scene::{Pin, PinMotion};

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
