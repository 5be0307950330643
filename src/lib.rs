//! vibrobed: exact event-driven simulation of hard disks in 2D under gravity, on a vibrating
//! floor, with an open top — Isobe's (1999) algorithm extended to infinite height.
//!
//! The crate is a few layers, each using only those above it (the book's contributing page says
//! where a new rule, event source or output goes):
//! - [`physics`]: the disks' state, free flight, pair collisions, restitution and its cures, the
//!   side walls and the lid, the floor, known results for hard disks;
//! - [`neighbours`]: who can meet whom — Isobe's grid (dense or hashed for an open top), masks,
//!   neighbour lists;
//! - [`scheduler`]: the event queue (complete binary tree or calendar);
//! - [`engine`]: the exact event-driven engine — the scene and its initial state, the event
//!   loop, the event kinds and their sources, re-mapping, disks at rest;
//! - [`schemes`]: the approximate time-step and space-time schemes, for comparison;
//! - [`measure`]: what is measured (energies, temperature, profiles);
//! - [`output`]: what is written (summary, recording, trajectories, progress);
//! - [`scenario`]: the scene description (read strictly, overridden with `--set`) and its checks;
//! - [`run`]: one run from scenario to outputs (driver, stops, checkpoints);
//! - [`studies`]: what is made of many runs — accuracy against cost, parameter sweeps on local
//!   cores or Slurm — and the figures they draw;
//! - [`platform`]: allocator settings, prefetch hints, signals; [`cli`]: the command line.
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
