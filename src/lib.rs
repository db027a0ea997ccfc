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

// The layers (`docs/architecture.md`, "What each layer may import"; test
// `layers` holds them): each imports only its own layer and those above it
// in this list.

// Vocabulary: numbers and the engine's specifications.
pub mod math;
pub mod spec;

// Engine: the cloth, its physics, moving bodies, collisions and remeshing.
pub mod adapt;
pub mod collide;
pub mod garment;
pub mod kinematics;
pub mod mesh;
pub mod physics;
pub mod pins;
pub mod sim;
pub mod world;

// Application: scene files, runs, recordings, reports and the tools.
pub mod bench;
pub mod cantilever;
pub mod check;
pub mod garmentcode;
pub mod record;
pub mod run;
pub mod scene;
pub mod stability;
pub mod summary;
