//! `sweep plan --estimate`: what a sweep will cost, from a short trial of each point.
//!
//! Each point's first run (its first seed) runs from its start for at most a few seconds of wall
//! time (`run.max_wall_seconds`, nothing written). A trial that reaches the run's end (its
//! duration or its event limit) measured the run's whole cost; otherwise the cost per unit of
//! simulated time so far, times the duration, estimates it. The CPU time is the wall time times
//! the threads the run used. A point costs its runs' estimate times its runs (seeds); the sweep,
//! the sum; on `cores` workers, at least the sum over the workers or the dearest run.
//!
//! The trial sees a run's start only: a bed that freezes into a collapse later costs more (the
//! run's note on a growing cost says so), one that settles into a steady state after a costly
//! start less.

use crate::error::Result;
use crate::output::progress::clock_time;
use crate::output::summary::{Ending, Summary};
use crate::run::{run, RunOptions};
use crate::studies::sweep::plan::{point_label, Expanded};
use std::sync::atomic::Ordering;

/// How a point's trial went.
#[derive(Debug, Clone, PartialEq)]
pub enum Trial {
    /// The trial reached the run's end (completed, or stopped by the run's event limit): the
    /// run's whole cost was measured.
    Whole {
        /// How the run ended.
        ending: Ending,
        /// CPU seconds of the run.
        cpu: f64,
    },
    /// The trial ran out of its wall time at simulated time `reached`: the run's cost is
    /// extrapolated over its duration.
    Extrapolated {
        /// Simulated time reached.
        reached: f64,
        /// CPU seconds per unit of simulated time over the trial.
        per_time: f64,
        /// CPU seconds of the whole run (capped by the run's own wall-clock limit).
        cpu: f64,
    },
    /// The trial did not tell (it failed, stalled, was interrupted, or simulated no time).
    Unknown(String),
}

impl Trial {
    /// The estimated CPU seconds of one run, when known.
    pub fn cpu(&self) -> Option<f64> {
        match self {
            Trial::Whole { cpu, .. } | Trial::Extrapolated { cpu, .. } => Some(*cpu),
            Trial::Unknown(_) => None,
        }
    }

    /// What the trial found, from its summary (`duration`: the run's; `limit`: its own
    /// `run.max_wall_seconds`).
    pub fn of(s: &Summary, duration: f64, limit: Option<f64>) -> Trial {
        let threads = s.engine.threads.unwrap_or(1).max(1) as f64;
        Trial::measured(
            s.ending,
            s.sim_time,
            s.wall_seconds,
            threads,
            duration,
            limit,
        )
    }

    /// What a trial found that ended so at simulated time `reached` after `wall` seconds on
    /// `threads` threads.
    fn measured(
        ending: Ending,
        reached: f64,
        wall: f64,
        threads: f64,
        duration: f64,
        limit: Option<f64>,
    ) -> Trial {
        let cpu = wall * threads;
        match ending {
            Ending::Completed | Ending::EventLimit => Trial::Whole { ending, cpu },
            Ending::WallLimit if reached > 0.0 => {
                let per_time = cpu / reached;
                let whole = per_time * duration;
                Trial::Extrapolated {
                    reached,
                    per_time,
                    cpu: limit.map_or(whole, |l| whole.min(l * threads)),
                }
            }
            Ending::WallLimit => Trial::Unknown("no simulated time in the trial".into()),
            Ending::Stalled => Trial::Unknown("simulated time stalled in the trial".into()),
            Ending::Interrupted => Trial::Unknown("interrupted".into()),
        }
    }
}

/// One point's estimate.
#[derive(Debug, Clone)]
pub struct PointEstimate {
    /// Point number.
    pub point: usize,
    /// The point's settings.
    pub label: String,
    /// Runs of the point.
    pub runs: usize,
    /// Its first run's trial.
    pub trial: Trial,
}

/// Runs each point's trial (`seconds` of wall time at most), one after the other; stops at
/// Ctrl-C.
pub fn estimate(exp: &Expanded, seconds: f64) -> Result<Vec<PointEstimate>> {
    crate::platform::signals::install();
    let mut out: Vec<PointEstimate> = Vec::new();
    for (spec, scenario) in exp.plan.runs.iter().zip(&exp.scenarios) {
        if let Some(p) = out.iter_mut().find(|p| p.point == spec.point) {
            p.runs += 1;
            continue;
        }
        let label = point_label(&exp.plan.axes, &spec.values);
        let trial = if crate::platform::signals::stop_flag().load(Ordering::Relaxed) {
            Trial::Unknown("interrupted".into())
        } else {
            let mut s = scenario.clone();
            let limit = s.run.max_wall_seconds;
            s.run.max_wall_seconds = Some(limit.map_or(seconds, |l| l.min(seconds)));
            let options = RunOptions {
                interrupt: Some(crate::platform::signals::stop_flag()),
                ..Default::default()
            };
            match run(&s, options) {
                Ok(summary) => Trial::of(&summary, s.run.duration, limit),
                Err(e) => Trial::Unknown(format!("failed: {e}")),
            }
        };
        eprintln!(
            "trial of point {} ({label}): {}",
            spec.point,
            trial_words(&trial)
        );
        out.push(PointEstimate {
            point: spec.point,
            label,
            runs: 1,
            trial,
        });
    }
    Ok(out)
}

/// A trial in words, for the line printed as it ends.
fn trial_words(t: &Trial) -> String {
    match t {
        Trial::Whole { ending, cpu } => format!("the whole run, {}, in {cpu:.2} s", ending.words()),
        Trial::Extrapolated {
            reached, per_time, ..
        } => format!("reached t = {reached:.4} at {per_time:.3} CPU s per unit time"),
        Trial::Unknown(why) => why.clone(),
    }
}

/// The table `sweep plan --estimate` prints: a row per point (its trial, a run's and the point's
/// CPU time), then the sweep's total and its wall time on `cores` workers.
pub fn table(points: &[PointEstimate], seconds: f64, cores: usize) -> String {
    let mut out = format!(
        "estimated cost (a trial of each point's first run, at most {seconds} s of wall time, \
         from its start):\n"
    );
    out.push_str(&format!(
        "{:<6}  {:<30}  {:<13}  {:<5}  {:<13}  {}\n",
        "point", "trial", "per run", "runs", "per point", "settings"
    ));
    let (mut total, mut dearest, mut unknown) = (0.0f64, 0.0f64, Vec::new());
    for p in points {
        let (trial, per_run) = match &p.trial {
            Trial::Whole { ending, cpu } => (
                match ending {
                    Ending::EventLimit => "whole run (event limit)".to_string(),
                    _ => "whole run".to_string(),
                },
                Some(*cpu),
            ),
            Trial::Extrapolated { reached, cpu, .. } => {
                (format!("to t = {reached:.4}, extrapolated"), Some(*cpu))
            }
            Trial::Unknown(why) => (why.clone(), None),
        };
        let (run, point) = match per_run {
            Some(c) => {
                total += c * p.runs as f64;
                dearest = dearest.max(c);
                (cpu_time(c), cpu_time(c * p.runs as f64))
            }
            None => {
                unknown.push(p.point.to_string());
                ("?".into(), "?".into())
            }
        };
        out.push_str(&format!(
            "{:<6}  {:<30}  {:<13}  {:<5}  {:<13}  {}\n",
            p.point, trial, run, p.runs, point, p.label
        ));
    }
    let runs: usize = points.iter().map(|p| p.runs).sum();
    let cores = cores.max(1);
    out.push_str(&format!(
        "total: {runs} runs, {} of CPU time{}; `sweep run` on {cores} worker{} about {} \
         (more when the runs' costs grow as they go: the trial sees their start only)\n",
        cpu_time(total),
        if unknown.is_empty() {
            String::new()
        } else {
            format!(" without point {} (no estimate)", unknown.join(", "))
        },
        if cores == 1 { "" } else { "s" },
        cpu_time((total / cores as f64).max(dearest)),
    ));
    out
}

/// CPU seconds as `0.42 s` below ten seconds, else as the progress lines say times.
fn cpu_time(seconds: f64) -> String {
    if seconds < 10.0 {
        format!("{seconds:.2} s")
    } else {
        clock_time(seconds)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(point: usize, runs: usize, trial: Trial) -> PointEstimate {
        PointEstimate {
            point,
            label: format!("x={point}"),
            runs,
            trial,
        }
    }

    /// Per point: a run's CPU time times its runs; the total sums the points it knows and names
    /// the ones it does not; on two workers half the total, or the dearest run when that is more.
    #[test]
    fn the_total_adds_the_points_and_divides_over_the_workers() {
        let points = [
            point(
                0,
                3,
                Trial::Whole {
                    ending: Ending::Completed,
                    cpu: 2.0,
                },
            ),
            point(
                1,
                3,
                Trial::Extrapolated {
                    reached: 1.5,
                    per_time: 4.0,
                    cpu: 400.0,
                },
            ),
            point(2, 3, Trial::Unknown("failed: x".into())),
        ];
        let t = table(&points, 2.0, 2);
        let rows: Vec<&str> = t.lines().collect();
        assert!(rows[2].starts_with("0       whole run"), "{t}");
        assert!(
            rows[2].contains("2.00 s") && rows[2].contains("6.00 s"),
            "{t}"
        );
        assert!(
            rows[3].contains("6 min 40 s") && rows[3].contains("20 min 00 s"),
            "{t}"
        );
        assert!(
            rows[4].contains("failed: x") && rows[4].contains('?'),
            "{t}"
        );
        // 6 + 1200 = 1206 s in all; 603 s on two workers.
        assert!(
            rows[5].starts_with("total: 9 runs, 20 min 06 s of CPU time without point 2"),
            "{t}"
        );
        assert!(rows[5].contains("on 2 workers about 10 min 03 s"), "{t}");
        // One dear run bounds the wall time whatever the workers.
        let t = table(&points[1..2], 2.0, 64);
        assert!(t.contains("on 64 workers about 6 min 40 s"), "{t}");
    }

    /// A trial cut by its wall time extrapolates over the duration, no further than the run's
    /// own wall-clock limit allows.
    #[test]
    fn a_run_cut_short_extrapolates_up_to_its_own_limit() {
        let per_time = |t: &Trial| match t {
            Trial::Extrapolated { per_time, cpu, .. } => (*per_time, *cpu),
            other => panic!("{other:?}"),
        };
        let cut = |limit| Trial::measured(Ending::WallLimit, 4.0, 2.0, 1.0, 100.0, limit);
        assert_eq!(per_time(&cut(None)), (0.5, 50.0));
        assert_eq!(per_time(&cut(Some(30.0))), (0.5, 30.0));
        // On 4 threads, 4 CPU seconds per wall second.
        let four = Trial::measured(Ending::WallLimit, 4.0, 2.0, 4.0, 100.0, Some(30.0));
        assert_eq!(per_time(&four), (2.0, 120.0));
        let whole = Trial::measured(Ending::EventLimit, 4.0, 2.0, 1.0, 100.0, None);
        assert_eq!(whole.cpu(), Some(2.0));
        let stalled = Trial::measured(Ending::Stalled, 4.0, 2.0, 1.0, 100.0, None);
        assert_eq!(stalled.cpu(), None);
    }
}
