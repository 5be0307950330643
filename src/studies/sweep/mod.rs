//! Parameter sweeps and seed ensembles: many runs of one scenario with `--set`-style overrides,
//! on the cores of this machine or as a Slurm job array, collected into one table.
//!
//! - [`plan`]: the sweep file and its expansion into runs (checked before anything runs);
//! - [`estimate`]: the cost of a sweep from a short trial of each point (`sweep plan
//!   --estimate`);
//! - [`local`]: one run into its folder, and the pool of worker threads (`sweep run`);
//! - [`slurm`]: the job-array script and its submission (`sweep slurm`, `sweep task`);
//! - [`collect`]: `runs.csv` and `points.csv` (`sweep collect`), with [`groups`] (a series per
//!   value of `--by`), [`fit`] (power law) and [`plot`] (SVG with error bars) and [`state_map`]
//!   (the phase diagram of the bed's states), their axes described by [`quantities`] (each
//!   field's meaning and unit);
//! - [`report`]: what `sweep collect` prints, fits and draws, per group and folder;
//! - [`command`]: the `vibrobed sweep …` subcommands.

pub mod collect;
pub mod command;
pub mod estimate;
pub mod fit;
pub mod groups;
pub mod local;
pub mod plan;
pub mod plot;
pub mod quantities;
pub mod report;
pub mod slurm;
pub mod state_map;
