//! vibrobed: exact event-driven simulation of hard disks in 2D under gravity, on a vibrating
//! floor, with an open top — Isobe's (1999) algorithm extended to infinite height.
//!
//! The crate is a few layers, listed from the bottom up; each uses only the layers below it
//! (`tests/suite/layers.rs` fails when a module imports one above it). The book's contributing
//! page lists the same layers and says where a new rule, event source or output goes.
//! - [`platform`]: the vector path of the hot loops, allocator settings, prefetch hints, signals;
//! - [`error`]: bad input (exit 2, naming the field) and failures while running (exit 1);
//! - [`physics`]: the disks' state, free flight, pair collisions, restitution and its cures,
//!   rough disks, the side walls and the lid, the floor and its drive, known results;
//! - [`scheduler`]: the event queue (complete binary tree or calendar);
//! - [`scenario`]: the scene description (read strictly, overridden with `--set`) and its
//!   checks;
//! - [`neighbours`]: who can meet whom — Isobe's grid (dense or hashed for an open top), masks,
//!   neighbour lists;
//! - [`engine`]: the exact event-driven engine — the scene and its initial state, the event
//!   loop, the event kinds and their sources, re-mapping, disks at rest;
//! - [`schemes`]: the approximate time-step and space-time schemes, for comparison;
//! - [`measure`]: what is measured (energies, temperature, profiles, the phase-resolved motion);
//! - [`output`]: what is written (summary, recording, trajectories, progress);
//! - [`run`]: one run from scenario to outputs (the driver from stop to stop, the outputs
//!   streamed at stops, the summary, checkpoints);
//! - [`studies`]: what is made of many runs — accuracy against cost, parameter sweeps on local
//!   cores or Slurm — and the figures they draw;
//! - [`cli`]: the command line.
//!
//! The brute-force reference engine the tests compare against lives with the tests
//! (`tests/suite/common/reference.rs`).

pub mod cli;
pub mod engine;
pub mod error;
pub mod measure;
pub mod neighbours;
pub mod output;
pub mod physics;
pub mod platform;
pub mod run;
pub mod scenario;
pub mod scheduler;
pub mod schemes;
pub mod studies;

pub use error::{Error, Result};
pub use scenario::Scenario;

/// Large blocks on huge pages in large scenes (see [`platform::memory::huge`]).
#[cfg(target_os = "linux")]
#[global_allocator]
static ALLOCATOR: platform::memory::huge::Allocator = platform::memory::huge::Allocator;
