//! All integration tests in one binary: each test file is a module here, so the
//! heavy dependencies (rerun) are linked once.

mod adapt;
mod adapt_cost;
mod adapt_sizing;
mod adapt_tensor;
mod bad_cli;
mod bad_input;
mod bad_obj;
mod bench;
mod bench_convergence;
mod canonical;
mod cli;
mod collide;
mod common;
mod docs_commands;
mod elastica;
mod elements;
mod energy;
mod fuzz;
mod gradient;
mod inspect_cli;
mod mesh;
mod metric;
mod physics;
mod pins;
mod recording;
mod recording_run;
mod remesh_ops;
mod scene_errors;
mod sim;
mod solver;
mod stability;
mod statics;
mod transitions;
