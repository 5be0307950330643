//! A sweep from Python, as `vibrobed sweep run` runs it on this machine's cores, and its tables
//! as `vibrobed sweep collect` makes them. The Slurm path stays the command line's.

use crate::detached;
use crate::errors::IntoPy;
use pyo3::prelude::*;
use std::path::Path;
use std::sync::atomic::Ordering;
use vibrobed::output::progress::DEFAULT_EVERY;
use vibrobed::output::summary::Ending;
use vibrobed::output::write_atomic;
use vibrobed::platform::signals::stop_flag;
use vibrobed::studies::sweep::command::{check_max_run_seconds, writable_out};
use vibrobed::studies::sweep::local::{check_plan, run_pool, PoolOptions};
use vibrobed::studies::sweep::plan::{expand, expand_text};
use vibrobed::{Error, Result};

/// How a sweep went: runs completed now, done before, interrupted, the failed ones (index and
/// message), and those stopped by a limit, now or before (index and how, in words).
pub type Report = (
    usize,
    usize,
    usize,
    Vec<(usize, String)>,
    Vec<(usize, &'static str)>,
);

/// `sweep run --progress-every` and `--max-run-seconds` (None: the command line's defaults).
pub struct Limits {
    /// Wall seconds between a run's progress lines off a terminal.
    pub progress_every: Option<f64>,
    /// Wall-clock limit of each run.
    pub max_run_seconds: Option<f64>,
}

/// Runs every run of the sweep file `sweep` not yet done into `out` on `jobs` workers (default:
/// every core), off the GIL; Ctrl-C stops the pool as SIGINT stops `sweep run`. With `text`
/// (a sweep given as a dict), `sweep` is where that text is written, once every check has
/// passed: a refused sweep writes nothing.
pub fn run(
    py: Python<'_>,
    sweep: &Path,
    text: Option<&str>,
    out: &Path,
    jobs: Option<usize>,
    progress: bool,
    limits: Limits,
) -> PyResult<Report> {
    if jobs == Some(0) {
        return Err(Error::input("--jobs", "must be at least 1")).py();
    }
    check_max_run_seconds(limits.max_run_seconds).py()?;
    let mut exp = match text {
        Some(text) => expand_text(text, sweep),
        None => expand(sweep),
    }
    .py()?;
    exp.check_scenes().py()?;
    // A folder of another sweep is refused before the sweep file is written into it.
    check_plan(&exp.plan, out).py()?;
    let jobs = jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    writable_out(out).py()?;
    if let Some(text) = text {
        write_atomic(sweep, text).py()?;
        exp.plan.sweep = std::fs::canonicalize(sweep)?;
    }
    // The pool and its runs watch the process's stop flag (the signal handlers' on the command
    // line): raised by Ctrl-C here, lowered again once the pool has stopped.
    let flag = stop_flag();
    let options = PoolOptions {
        jobs,
        progress,
        progress_every: limits.progress_every.unwrap_or(DEFAULT_EVERY),
        max_run_seconds: limits.max_run_seconds,
    };
    let report = detached::run(py, flag, || run_pool(&exp, out, options));
    flag.store(false, Ordering::Relaxed);
    let report = report?.py()?;
    let mut early: Vec<(usize, &'static str)> = report
        .ended_early
        .iter()
        .map(|&(i, ending)| (i, ending.words()))
        .chain(
            report
                .limited_before
                .iter()
                .map(|&i| (i, Ending::EventLimit.words())),
        )
        .collect();
    early.sort_unstable();
    Ok((
        report.ran,
        report.skipped,
        report.interrupted,
        report.failed,
        early,
    ))
}

/// `runs.csv` and `points.csv` of the sweep in `out`, as text (also written into `out`).
pub fn collect(out: &Path) -> Result<(String, String)> {
    let collected = vibrobed::studies::sweep::collect::collect(out)?;
    collected.write_tables(out)?;
    Ok((collected.runs_csv(), collected.points_csv()))
}
