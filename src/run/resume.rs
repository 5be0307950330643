//! A run saved and resumed: the checkpoint the driver gives its outputs at its stops and at the
//! end (the engine between events, the driver's state, the scene's text), the output that writes
//! it to its file, and a resumed driver taking back the state one holds.

use super::checkpoint::Checkpoint;
use super::driver::Driver;
use super::state::DriverState;
use super::stops::Stops;
use super::streams::{Given, Output, Takes};
use crate::error::{Error, Result};
use crate::output::watch::Target;
use crate::schemes::Integrator;
use std::path::PathBuf;

impl<E: Integrator> Driver<'_, E> {
    /// Continues the run a checkpoint holds: the engine's state, the stop schedule (to the new
    /// duration), the averages so far. The duration may be extended, not cut below the
    /// checkpoint's time.
    pub(super) fn resume(&mut self, ck: Checkpoint) -> Result<()> {
        let at = ck.driver.time;
        if self.stops.duration < at {
            return Err(Error::input(
                "run.duration",
                format!(
                    "the checkpoint is at t = {at}; a resumed run must end at or after it (got {})",
                    self.stops.duration
                ),
            ));
        }
        if ck.driver.averages.profiles.is_some() != self.averages.profiles.is_some() {
            return Err(Error::input(
                "CHECKPOINT",
                "its profiles do not fit this scene",
            ));
        }
        let mut d = ck.driver;
        match (&self.averages.fields, &d.averages.fields) {
            (Some(_), None) if d.averages.window.is_some() => {
                return Err(Error::input(
                    "--fields",
                    "the checkpointed run did not measure 2D fields after its warm-up: run it \
                     with --fields to resume with them",
                ))
            }
            (Some(_), None) => d.averages.fields = self.averages.fields.take(),
            _ => {}
        }
        self.sim.restore_state(ck.engine)?;
        let duration = self.stops.duration;
        self.stops = Stops {
            duration,
            ..d.stops
        };
        self.stops.resume_at(
            self.sim.time(),
            self.checkpoint.as_ref().and_then(|c| c.every),
        );
        self.averages = d.averages;
        self.initial = d.initial;
        self.frames.last_collisions = d.last_frame_collisions;
        self.at_rest_since = d.at_rest_since;
        self.wall_before = d.wall_seconds;
        self.recordings = ck.recordings;
        Ok(())
    }

    /// The checkpoint to the outputs that take it, if any: the engine between events, this
    /// driver, the scene's text. A checkpoint that cannot be written is an output failure (the
    /// run goes on); an engine that cannot be saved ends the run.
    pub(super) fn checkpoint(&mut self) -> Result<()> {
        self.settle(); // the averages saved hold every sample taken
        let Some(plan) = self
            .checkpoint
            .as_ref()
            .filter(|_| self.streams.take(Takes::Checkpoints))
        else {
            return Ok(());
        };
        let engine = self.sim.saved_state().ok_or_else(|| {
            Error::input(
                "engine.scheme",
                "only the event-driven and hybrid schemes can be checkpointed",
            )
        })?;
        let ck = Checkpoint {
            scenario: plan.scenario.clone(),
            source: plan.source.clone(),
            sets: plan.sets.clone(),
            every: plan.every,
            recording_id: self.recording_id.clone(),
            recordings: self.recordings.clone(),
            driver: DriverState {
                stops: self.stops,
                averages: self.averages.clone(),
                initial: self.initial,
                last_frame_collisions: self.frames.last_collisions,
                at_rest_since: self.at_rest_since,
                wall_seconds: self.wall_before + self.clock.elapsed().as_secs_f64(),
                time: self.sim.time(),
            },
            engine,
        };
        let time = self.sim.time();
        let given = Given::Checkpoint(&ck);
        (self.streams).give(Takes::Checkpoints, &given, time, &mut self.failures);
        Ok(())
    }
}

/// The checkpoint file as an output at stops: each checkpoint written whole over the last.
pub(super) struct CheckpointFile(pub(super) PathBuf);

impl Output for CheckpointFile {
    fn take(&mut self, given: &Given) -> Result<()> {
        match given {
            Given::Checkpoint(ck) => ck.write(&self.0),
            Given::Frame(_) | Given::End(..) => Ok(()),
        }
    }
    fn watched(&self, name: &'static str) -> Option<Target> {
        Some(Target::later(name, &self.0))
    }
}
