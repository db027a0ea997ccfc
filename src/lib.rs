//! drape: adaptive mass-spring cloth simulation recorded to Rerun `.rrd` files.
//!
//! Data flows one way (SPEC section 2):
//! scene file -> [`scene::Scene`] -> [`world::World`] -> per step: forces ->
//! integrate -> record. Simulation state ([`world::World`]) is kept apart from the
//! stepper's scratch memory ([`physics::Stepper`]), as in rapier's sets and pipeline.

pub mod adapt;
pub mod bench;
pub mod cantilever;
pub mod check;
pub mod collide;
pub mod math;
pub mod mesh;
pub mod physics;
pub mod pins;
pub mod record;
pub mod run;
pub mod scene;
pub mod spec;
pub mod stability;
pub mod summary;
pub mod world;
