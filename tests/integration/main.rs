//! All integration tests in one binary: each test file is a module here, so the
//! heavy dependencies (rerun) are linked once.

mod adapt;
mod bench;
mod cli;
mod collide;
mod common;
mod mesh;
mod metric;
mod physics;
mod recording;
mod scene_errors;
