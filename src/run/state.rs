//! The driver's part of a checkpoint.

use super::averages::Averages;
use super::stops::Stops;
use crate::measure::Observables;
use serde::{Deserialize, Serialize};

/// The driver's state in a checkpoint: the stop schedule, the averages, the initial energy.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DriverState {
    pub(super) stops: Stops,
    pub(super) averages: Averages,
    pub(super) initial: Observables,
    pub(super) last_frame_collisions: u64,
    /// The sample time since which every disk has been at rest, if it still is.
    #[serde(default)]
    pub(super) at_rest_since: Option<f64>,
    /// Wall seconds spent by the run so far (all its parts).
    pub(super) wall_seconds: f64,
    /// The engine's time at the checkpoint.
    pub(super) time: f64,
}

impl DriverState {
    /// Simulated time at which the checkpoint was taken.
    pub fn time(&self) -> f64 {
        self.time
    }
}
