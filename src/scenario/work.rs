//! The work a run is asked for, estimated before it starts: every disk the scene may hold
//! crossing its smallest radius, over and over, at the scene's own speed for the whole
//! `run.duration`. A disk in a bed collides a few times per crossing (2 to 15 in the shipped
//! beds), so the crossings are a lower estimate of the events; beyond [`MAX_WORK`] of them a
//! run takes weeks of computing and is refused, unless the scene bounds it itself with
//! `run.max_events` (at most [`MAX_EVENT_BUDGET`]) or `run.max_wall_seconds`. The disks the
//! scene may hold, which other costs multiply too (frames, samples, recordings), are counted
//! here.

use super::limits::{MAX_EVENT_BUDGET, MAX_WORK};
use super::speeds::natural_speed;
use super::{Inlet, Scenario, Scheme};
use crate::error::{Error, Result};

/// The estimate: disk crossings asked for, and what they are made of.
#[derive(Debug, Clone, PartialEq)]
pub struct Work {
    /// Every disk the scene may hold, initial and through every inlet.
    pub disks: f64,
    /// The run's duration.
    pub duration: f64,
    /// The scene's speed ([`natural_speed`]).
    pub speed: f64,
    /// The field that sets the speed (none for the speed of a fall under gravity).
    pub speed_field: Option<String>,
    /// Time of one crossing: the smallest radius over the scene's speed, or ten of the steps
    /// of a step scheme given an `engine.dt` that is shorter (its default step is a tenth of
    /// a crossing). Infinite when nothing moves.
    pub crossing_time: f64,
    /// Whether `engine.dt` sets the crossing time.
    pub by_step: bool,
}

impl Work {
    /// The work `s` asks for.
    pub fn of(s: &Scenario) -> Work {
        let (speed, speed_field) = natural_speed(s);
        let by_speed = if speed > 0.0 {
            s.all_radius_range().0 / speed
        } else {
            f64::INFINITY
        };
        let stepped = matches!(
            s.scheme(),
            Scheme::TimeStep | Scheme::Contact | Scheme::Hybrid
        );
        let by_steps = match s.engine.dt {
            Some(dt) if stepped => 10.0 * dt,
            _ => f64::INFINITY,
        };
        Work {
            disks: most_disks(s),
            duration: s.run.duration,
            speed,
            speed_field,
            crossing_time: by_speed.min(by_steps),
            by_step: by_steps < by_speed,
        }
    }

    /// Disk crossings asked for: disks × duration / crossing time.
    pub fn crossings(&self) -> f64 {
        self.disks * self.duration / self.crossing_time
    }

    /// The longest `run.duration` of [`MAX_WORK`] crossings for these disks (infinite when
    /// nothing moves).
    pub fn longest_duration(&self) -> f64 {
        MAX_WORK * self.crossing_time / self.disks.max(1.0)
    }

    /// The fields whose values make up the work besides the duration: what sets the pace
    /// (`engine.dt`, or the field of the scene's speed), then the disks' count.
    fn factors(&self) -> Vec<String> {
        let pace = if self.by_step {
            Some("engine.dt".to_string())
        } else {
            self.speed_field.clone()
        };
        pace.into_iter()
            .chain(["particles.count".to_string()])
            .collect()
    }

    /// "asks for … disk crossings (…)": the estimate and its factors.
    fn describe(&self) -> String {
        let pace = if self.by_step {
            "ten steps of engine.dt".to_string()
        } else {
            let from = self
                .speed_field
                .clone()
                .unwrap_or_else(|| "a fall of a radius under gravity".to_string());
            format!(
                "the time a disk takes to cross its smallest radius at the scene's speed {:.3e}, \
                 from {from}",
                self.speed
            )
        };
        format!(
            "asks for {:.3e} disk crossings ({:.0} disks × run.duration {:e} / {:.3e}, {pace})",
            self.crossings(),
            self.disks,
            self.duration,
            self.crossing_time
        )
    }
}

/// At most [`MAX_WORK`] disk crossings, or a run bounded by the scene itself: a
/// `run.max_events` of at most [`MAX_EVENT_BUDGET`], or a `run.max_wall_seconds`. The error
/// names `run.duration` (or `engine.dt`, when its steps set the pace), or `run.max_events`
/// when that is the budget given and it is past its bound.
pub fn validate_work(s: &Scenario) -> Result<()> {
    let work = Work::of(s);
    if work.crossings() <= MAX_WORK || s.run.max_wall_seconds.is_some() {
        return Ok(());
    }
    let asked = work.describe();
    match s.run.max_events {
        Some(n) if n as f64 <= MAX_EVENT_BUDGET => Ok(()),
        Some(n) => Err(Error::input(
            "run.max_events",
            format!(
                "{n} events is past the largest event budget, {MAX_EVENT_BUDGET:e}, for a run \
                 that {asked}"
            ),
        )),
        None => Err(Error::input(
            if work.by_step {
                "engine.dt"
            } else {
                "run.duration"
            },
            format!(
                "the run {asked}; at most {MAX_WORK:e} are run without a budget of the \
                 scene's own (weeks of computing; run.duration ≤ {:.3e} here): shorten the \
                 run, or bound it with run.max_events (at most {MAX_EVENT_BUDGET:e}) or \
                 run.max_wall_seconds",
                work.longest_duration()
            ),
        )),
    }
}

/// The work's refusal `e` of `s` blamed on a factor the user set (`set` tells) when the user
/// did not set the field it names: the field of the scene's speed, `engine.dt`, or the disks'
/// count. `None` when `e` is not the work's refusal or no factor was set.
pub fn blame_a_factor_set(e: &Error, s: &Scenario, set: &dyn Fn(&str) -> bool) -> Option<Error> {
    let Error::Input { field, message } = e else {
        return None;
    };
    if set(field) || validate_work(s).err().as_ref() != Some(e) {
        return None;
    }
    let factor = Work::of(s).factors().into_iter().find(|f| set(f))?;
    Some(Error::input(factor, message.clone()))
}

/// The most disks the scene may hold: its initial disks and every disk an inlet may bring.
pub fn most_disks(s: &Scenario) -> f64 {
    let d = s.run.duration;
    s.disk_count() as f64
        + s.inlets
            .iter()
            .map(|i| inlet_disks(i, i.end.unwrap_or(d)))
            .sum::<f64>()
}

/// New disks `inlet` brings over its window (`end`: its end): its count, or its rate times
/// the window's length; none for an inlet that only recycles.
pub fn inlet_disks(inlet: &Inlet, end: f64) -> f64 {
    match (inlet.rate, inlet.count) {
        (_, Some(n)) => n as f64,
        (Some(r), None) => r * (end - inlet.start),
        (None, None) => 0.0,
    }
}
