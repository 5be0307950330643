//! vibrobed: exact event-driven simulation of hard disks in 2D under gravity, on a vibrating
//! floor, with an open top — Isobe's (1999) algorithm extended to infinite height.
//!
//! The code is organised after the physics (see DESIGN.md §6):
//! - [`dynamics`]: how disks fly between collisions;
//! - [`interactions`]: when two disks touch and what their collision does;
//! - [`restitution`]: the restitution law of every collision and the cures of inelastic collapse;
//! - [`locals`]: what a single disk hits (walls, lid, floor);
//! - [`globals`]: the grid, masks and neighbour lists;
//! - [`scheduler`]: the event sorter (complete binary tree or calendar queue);
//! - [`simulation`]: the event loop, re-mapping (DUTC) and the scene set-up;
//! - [`measure`], [`summary`], [`output`]: what is measured and written; [`figure`]: what the
//!   SVG figures share (axes, markers, legends);
//! - [`schemes`]: the approximate time-step and space-time schemes, for comparison, and
//!   [`accuracy`]: what accuracy costs in time (error against the exact engine vs cost);
//! - [`scenario`], [`placement`]: the scene description and the initial state;
//! - [`sweep`]: parameter sweeps and seed ensembles, locally and on Slurm, and their table;
//! - [`theory`]: known results for hard disks (equation of state, mean free path).
//!
//! The brute-force reference engine the tests compare against lives with the tests
//! (`tests/common/reference.rs`).

pub mod accuracy;
pub mod cli;
pub mod disks;
pub mod dynamics;
pub mod error;
pub mod figure;
pub mod globals;
pub mod interactions;
pub mod locals;
pub mod measure;
pub mod memory;
pub mod output;
pub mod placement;
pub mod prefetch;
pub mod restitution;
pub mod run;
pub mod scenario;
pub mod scheduler;
pub mod schemes;
pub mod signals;
pub mod simulation;
pub mod summary;
pub mod sweep;
pub mod theory;

pub use error::{Error, Result};
pub use scenario::Scenario;

/// Large blocks on huge pages in large scenes (see [`memory::huge`]).
#[cfg(target_os = "linux")]
#[global_allocator]
static ALLOCATOR: memory::huge::Allocator = memory::huge::Allocator;
