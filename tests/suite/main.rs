//! The integration tests, in one binary (one link of the crate and its dependencies instead of
//! one per file). Each module is one concern; `cargo test --release --test suite NAME::` runs one.

mod common;
mod guarded;

mod accuracy;
mod at_rest;
mod bad_input;
mod bed_state;
mod book;
mod brute_force;
mod checkpoint;
mod cli;
mod contact;
mod cpu_paths;
mod endings;
mod equation_of_state;
mod faults;
mod fields;
mod figures;
mod fuzz_budget;
mod fuzz_commands;
mod fuzz_fields;
mod fuzz_inputs;
mod gravity;
mod grids;
mod hard_cases;
mod hybrid;
mod invariants;
mod layers;
mod pools;
mod queues;
mod record_e2e;
mod recording;
mod renumbering;
mod rough;
mod scenarios;
mod schemes;
mod solver_properties;
mod sweep;
mod trajectory;
