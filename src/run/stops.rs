//! The stop schedule of a run: samples, frames, trajectory frames, the end of the warm-up,
//! checkpoints and the end, each at an exact simulated time.

use crate::measure::phase::PhaseClock;
use crate::scenario::Scenario;
use serde::{Deserialize, Serialize};

/// Simulated time of frame `k`: `k·dt`, or the duration when `k·dt` passes it by round-off only,
/// so that a duration that is a multiple of the frame interval ends with a frame (29 × 0.1 =
/// 2.9000000000000004 > 2.9: without this the last frame of a 2.9-long run would be lost).
pub(super) fn frame_time(k: u64, dt: f64, duration: f64) -> f64 {
    let t = k as f64 * dt;
    if t > duration && t - duration <= 1e-6 * dt {
        duration
    } else {
        t
    }
}

/// When the run next stops, and for what: samples, frames, the end of the warm-up, the end.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub(super) struct Stops {
    pub(super) sample_dt: f64,
    pub(super) frame_dt: f64,
    pub(super) trajectory_dt: f64,
    pub(super) duration: f64,
    pub(super) warmup: f64,
    /// Samples taken so far.
    pub(super) k_sample: u64,
    /// Frames recorded so far.
    pub(super) k_frame: u64,
    /// Trajectory frames written so far.
    pub(super) k_trajectory: u64,
    /// Simulated time between checkpoints (∞: none on a schedule).
    pub(super) checkpoint_dt: f64,
    /// The next scheduled checkpoint is the `k_checkpoint`-th (from 1: none at the start).
    pub(super) k_checkpoint: u64,
    /// The bin edges of the floor's phase (a vibrating floor): stops after the warm-up.
    #[serde(default)]
    pub(super) phase: Option<PhaseClock>,
    /// The next phase stop is at the `k_phase`-th bin edge.
    #[serde(default)]
    pub(super) k_phase: u64,
}

/// The next stop: its time and what is due then.
#[derive(Debug, Clone, Copy)]
pub(super) struct Stop {
    pub(super) time: f64,
    pub(super) sample: bool,
    pub(super) frame: bool,
    pub(super) trajectory: bool,
    pub(super) window: bool,
    pub(super) checkpoint: bool,
    /// A bin edge of the floor's phase (after the warm-up).
    pub(super) phase: bool,
}

impl Stops {
    pub(super) fn new(
        s: &Scenario,
        checkpoint_every: Option<f64>,
        phase: Option<PhaseClock>,
    ) -> Stops {
        Stops {
            sample_dt: s.sample_interval(),
            frame_dt: s.frame_interval(),
            trajectory_dt: s.trajectory_interval(),
            duration: s.run.duration,
            warmup: s.run.warmup,
            k_sample: 0,
            k_frame: 0,
            k_trajectory: 0,
            checkpoint_dt: checkpoint_every.unwrap_or(f64::INFINITY),
            k_checkpoint: 1,
            phase,
            k_phase: 0,
        }
    }

    /// After a resume at engine time `t`: frames and trajectory frames the saved run did not
    /// write (it had no recording or trajectory) start at `t`, not at 0; checkpoints follow the
    /// new interval from `t` on.
    pub(super) fn resume_at(&mut self, t: f64, checkpoint_every: Option<f64>) {
        while frame_time(self.k_frame, self.frame_dt, f64::INFINITY) < t {
            self.k_frame += 1;
        }
        while frame_time(self.k_trajectory, self.trajectory_dt, f64::INFINITY) < t {
            self.k_trajectory += 1;
        }
        self.checkpoint_dt = checkpoint_every.unwrap_or(f64::INFINITY);
        self.k_checkpoint = if self.checkpoint_dt.is_finite() {
            (t / self.checkpoint_dt).floor() as u64 + 1
        } else {
            1
        };
    }

    /// The next stop, given whether frames are recorded, whether a trajectory is written and
    /// whether the window is open.
    pub(super) fn next(&self, recording: bool, trajectory: bool, window_open: bool) -> Stop {
        let t_sample = frame_time(self.k_sample, self.sample_dt, self.duration);
        let t_frame = if recording {
            frame_time(self.k_frame, self.frame_dt, self.duration)
        } else {
            f64::INFINITY
        };
        let t_trajectory = if trajectory {
            frame_time(self.k_trajectory, self.trajectory_dt, self.duration)
        } else {
            f64::INFINITY
        };
        let t_window = if window_open {
            f64::INFINITY
        } else {
            self.warmup
        };
        let t_checkpoint = self.k_checkpoint as f64 * self.checkpoint_dt;
        let t_phase = match self.phase {
            Some(c) if window_open => c.edge_time(self.k_phase),
            _ => f64::INFINITY,
        };
        let time = t_sample
            .min(t_frame)
            .min(t_trajectory)
            .min(t_window)
            .min(t_checkpoint)
            .min(t_phase)
            .min(self.duration);
        Stop {
            time,
            sample: time == t_sample,
            frame: time == t_frame,
            trajectory: time == t_trajectory,
            checkpoint: time == t_checkpoint,
            window: time == t_window,
            phase: time == t_phase,
        }
    }
}
