//! drape: adaptive mass-spring cloth simulation recorded to Rerun `.rrd` files.
//!
//! Data flows one way (`docs/architecture.md`, "Data flow"):
//! scene file -> [`scene::Scene`] -> [`sim::build`] -> [`sim::SimParts`]: the
//! [`sim::Setup`] (the [`physics::Model`], the obstacles and the
//! [`sim::Settings`], fixed for the run), a [`sim::SimState`] and the
//! [`sim::Pipeline`] that advances it (`pipeline.step(&setup, &mut state, h)`) ->
//! per frame ([`run::FrameLoop`]): the step's phases (forces + integrate, collide,
//! account, health check, rollback, adapt; see [`sim`]) until the frame's time,
//! then observe and record. The state is one cloneable value (the implicit
//! solver's warm start included); the pipeline holds only scratch, as in rapier's
//! parameters, sets and pipeline.

pub mod adapt;
pub mod bench;
pub mod cantilever;
pub mod check;
pub mod collide;
pub mod garment;
pub mod kinematics;
pub mod math;
pub mod mesh;
pub mod physics;
pub mod pins;
pub mod record;
pub mod run;
pub mod scene;
pub mod sim;
pub mod spec;
pub mod stability;
pub mod summary;
pub mod world;
