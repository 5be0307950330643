//! The intervals and wall-clock limits a command is given beside its scene, in one place:
//! `--progress-every`, `--checkpoint-every`, `run.max_wall_seconds` and `sweep run
//! --max-run-seconds`, `sweep plan --estimate`. Each is a positive finite number within bounds
//! the run can keep; anything else is refused naming the option and the bound, before anything
//! is built or written.

use super::limits::{
    at_most, positive, MAX_CHECKPOINTS, MAX_WALL_SECONDS, MIN_PROGRESS_SECONDS, MIN_WALL_SECONDS,
};
use crate::error::{Error, Result};

/// Wall seconds in [`shortest`, [`MAX_WALL_SECONDS`]] for the option `field`.
fn wall(field: &str, seconds: f64, shortest: f64) -> Result<()> {
    if !(seconds.is_finite() && seconds > 0.0) {
        return Err(Error::input(
            field,
            format!("must be a positive number of seconds (got {seconds})"),
        ));
    }
    if seconds < shortest {
        return Err(Error::input(
            field,
            format!("{seconds:e} s is shorter than the shortest accepted, {shortest} s"),
        ));
    }
    if seconds > MAX_WALL_SECONDS {
        return Err(Error::input(
            field,
            format!("{seconds:e} s is past the longest limit, {MAX_WALL_SECONDS:e} s (32 years)"),
        ));
    }
    Ok(())
}

/// A wall-clock limit of a run (`run.max_wall_seconds`, `sweep run --max-run-seconds`):
/// at least [`MIN_WALL_SECONDS`], at most [`MAX_WALL_SECONDS`].
pub fn wall_seconds(field: &str, seconds: f64) -> Result<()> {
    wall(field, seconds, MIN_WALL_SECONDS)
}

/// `--progress-every` (wall seconds between progress lines), if given: at least
/// [`MIN_PROGRESS_SECONDS`], at most [`MAX_WALL_SECONDS`].
pub fn progress_every(every: Option<f64>) -> Result<()> {
    every.map_or(Ok(()), |e| {
        wall("--progress-every", e, MIN_PROGRESS_SECONDS)
    })
}

/// `sweep plan --estimate` (wall seconds of each trial run), if given: a wall-clock limit.
pub fn estimate_seconds(seconds: Option<f64>) -> Result<()> {
    seconds.map_or(Ok(()), |s| wall_seconds("--estimate", s))
}

/// `--checkpoint-every` (simulated time between checkpoints) of a run of `duration`: a time of
/// the scene (within the magnitudes double precision computes with) that asks for at most
/// [`MAX_CHECKPOINTS`] checkpoints.
pub fn checkpoint_every(every: f64, duration: f64) -> Result<()> {
    positive("--checkpoint-every", every)?;
    at_most(
        "--checkpoint-every",
        "checkpoints",
        duration / every,
        MAX_CHECKPOINTS,
    )
}
