//! A run saved and resumed: the checkpoint the driver writes at its stops and at the end (the
//! engine between events, the driver's state, the scene's text), and a resumed driver taking
//! back the state one holds.

use super::checkpoint::Checkpoint;
use super::driver::Driver;
use super::state::DriverState;
use super::stops::Stops;
use crate::error::{Error, Result};
use crate::schemes::Integrator;

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
        self.last_frame_collisions = d.last_frame_collisions;
        self.at_rest_since = d.at_rest_since;
        self.wall_before = d.wall_seconds;
        self.recordings = ck.recordings;
        Ok(())
    }

    /// Writes a checkpoint, if asked: the engine between events, this driver, the scene's text.
    pub(super) fn save_checkpoint(&self) -> Result<()> {
        let Some(plan) = &self.checkpoint else {
            return Ok(());
        };
        let engine = self.sim.saved_state().ok_or_else(|| {
            Error::input(
                "engine.scheme",
                "only the event-driven and hybrid schemes can be checkpointed",
            )
        })?;
        Checkpoint {
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
                last_frame_collisions: self.last_frame_collisions,
                at_rest_since: self.at_rest_since,
                wall_seconds: self.wall_before + self.clock.elapsed().as_secs_f64(),
                time: self.sim.time(),
            },
            engine,
        }
        .write(&plan.path)
    }

    /// Writes a checkpoint if asked; a failure to write it is an output failure (the run goes
    /// on), any other error ends the run.
    pub(super) fn checkpoint(&mut self) -> Result<()> {
        self.settle(); // the averages saved hold every sample taken
        let path = self.checkpoint.as_ref().map(|c| c.path.clone());
        let time = self.sim.time();
        match (self.save_checkpoint(), path) {
            (Ok(()), Some(path)) => self.failures.checkpoint_written(&path, time),
            (Err(e @ Error::Io(_)), Some(path)) => {
                self.failures.record("checkpoint", &path, e, time, false)
            }
            (result, _) => result?,
        }
        Ok(())
    }
}
