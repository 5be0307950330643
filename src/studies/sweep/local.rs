//! Running a sweep's runs: one run into its folder (shared by `sweep run` and a Slurm task), and
//! a pool of worker threads over the runs not yet done.
//!
//! A run writes `DIR/<index>/recording.rrd` when the sweep records, then `profiles.csv`
//! (gravity scenes), then `summary.json` (each to a temporary name renamed into place). The
//! summary comes last, so a summary that says `"ending": "completed"` (and lists no
//! `output_failures`) means the run is complete: a rerun skips it. Runs that were interrupted, failed or never started are run again from the start.
//! The engine is deterministic given the scenario and its seed, so run i gives the same result
//! whichever worker runs it and in whatever order.

use crate::error::{Error, Result};
use crate::output::summary::Ending;
pub use crate::output::write_atomic;
use crate::platform::memory::{threads_fit, threads_refused, RUN_THREAD_STACK};
use crate::run::{run, RunOptions};
use crate::scenario::Scenario;
use crate::schemes::cores::share;
use crate::studies::sweep::plan::{Expanded, Plan, RunSpec};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Output folder of run `index`.
pub fn run_dir(out: &Path, index: usize) -> PathBuf {
    out.join(index.to_string())
}

/// Whether run `index` has a complete summary (`"ending": "completed"`, or `"event-limit"`,
/// which a rerun would only repeat) and wrote all its outputs (no `output_failures`).
pub fn is_done(out: &Path, index: usize) -> bool {
    recorded_ending(out, index).is_some_and(|ending| DONE.contains(&ending.as_str()))
}

/// The endings of the runs a rerun skips.
const DONE: [&str; 2] = ["completed", "event-limit"];

/// The ending run `index`'s summary records (`completed`, `event-limit`, …), if it has a
/// summary that lists no `output_failures` (a run that lost an output is to be run again).
pub fn recorded_ending(out: &Path, index: usize) -> Option<String> {
    let path = run_dir(out, index).join("summary.json");
    let text = std::fs::read_to_string(path).ok()?;
    let summary = serde_json::from_str::<serde_json::Value>(&text).ok()?;
    if summary.get("output_failures").is_some() {
        return None;
    }
    summary.get("ending")?.as_str().map(str::to_owned)
}

/// Writes `DIR/plan.json`, or checks that the one already there is the same sweep (the same
/// runs with the same overrides), so that a folder never mixes two sweeps.
pub fn write_plan(plan: &Plan, out: &Path) -> Result<()> {
    if check_plan(plan, out)? {
        return Ok(());
    }
    std::fs::create_dir_all(out)
        .map_err(|e| Error::Io(format!("cannot create {}: {e}", out.display())))?;
    write_atomic(&out.join("plan.json"), &plan.to_json())
}

/// Checks that `DIR/plan.json`, if there is one, is the same sweep as `plan` (the same runs
/// with the same overrides); returns whether it is there and identical.
pub fn check_plan(plan: &Plan, out: &Path) -> Result<bool> {
    let path = out.join("plan.json");
    if path.exists() {
        let old = Plan::read(out)?;
        let same = old.runs.len() == plan.runs.len()
            && old
                .runs
                .iter()
                .zip(&plan.runs)
                .all(|(a, b)| a.sets == b.sets);
        if !same {
            return Err(Error::input(
                "--out",
                format!(
                    "{} holds the results of a different sweep (its plan.json differs); \
                     choose another folder",
                    out.display()
                ),
            ));
        }
        return Ok(old == *plan);
    }
    Ok(false)
}

/// Runs one run into `DIR/<index>/` and returns how it ended. A runtime failure leaves
/// `error.txt` (and no summary) in the run's folder; an output the run could not write (its
/// recording), or a clock that stopped (the stall's report), leaves `error.txt` beside the
/// summary, and the run counts as failed: a rerun runs it again.
///
/// `progress_every`: off a terminal, a progress line named `run <index>` every so many wall
/// seconds, and on one only the note on a growing cost (the pool's bar shows the progress);
/// `None`: silent.
pub fn run_one(
    plan: &Plan,
    spec: &RunSpec,
    scenario: &Scenario,
    out: &Path,
    progress_every: Option<f64>,
) -> Result<Ending> {
    let dir = run_dir(out, spec.index);
    std::fs::create_dir_all(&dir)
        .map_err(|e| Error::Io(format!("cannot create {}: {e}", dir.display())))?;
    let summary_path = dir.join("summary.json");
    let error_path = dir.join("error.txt");
    let _ = std::fs::remove_file(&error_path);
    let rrd = dir.join("recording.rrd");
    let result = run(
        scenario,
        RunOptions {
            rrd: plan.record.then(|| rrd.clone()),
            interrupt: Some(crate::platform::signals::stop_flag()),
            progress: progress_every.is_some(),
            progress_every,
            progress_label: Some(format!("run {}", spec.index)),
            written_after: vec![("summary", summary_path.clone())],
            ..Default::default()
        },
    );
    let failed = |e: Error| {
        let _ = std::fs::write(&error_path, format!("{e}\n"));
        Err(e)
    };
    let summary = match result {
        Ok(summary) => summary,
        Err(e) => {
            let _ = std::fs::remove_file(&summary_path);
            let _ = std::fs::remove_file(&rrd);
            return failed(e);
        }
    };
    let profiles_path = dir.join("profiles.csv");
    let written = match &summary.profiles {
        Some(p) => write_atomic(&profiles_path, &p.to_csv()),
        None => {
            // None measured (the run ended before its warm-up): an earlier attempt's are stale.
            let _ = std::fs::remove_file(&profiles_path);
            Ok(())
        }
    }
    .and_then(|()| write_atomic(&summary_path, &summary.to_json()));
    if let Err(e) = written {
        return failed(e);
    }
    if let Some(f) = summary.output_failures.first() {
        return failed(Error::Io(f.error.clone()));
    }
    match &summary.stall {
        Some(report) => failed(Error::Runtime(report.clone())),
        None => Ok(summary.ending),
    }
}

/// How a pool of runs went.
#[derive(Debug, Default)]
pub struct PoolReport {
    /// Runs completed now.
    pub ran: usize,
    /// Runs skipped because an earlier invocation completed them.
    pub skipped: usize,
    /// Runs that failed: index and message.
    pub failed: Vec<(usize, String)>,
    /// Runs stopped by Ctrl-C (their summaries say so).
    pub interrupted: usize,
    /// Runs that ended before their duration (an event or wall-clock limit): index and ending.
    pub ended_early: Vec<(usize, Ending)>,
    /// Runs skipped that an earlier invocation saw stopped by their event limit.
    pub limited_before: Vec<usize>,
}

impl PoolReport {
    /// The first run, by index, that ended early, now or in an earlier invocation, and how: a
    /// sweep whose runs all ran is complete only when there is none (its exit code is that
    /// run's, as `run` exits for it).
    pub fn first_early(&self) -> Option<(usize, Ending)> {
        let now = self.ended_early.first().copied();
        let before = self
            .limited_before
            .first()
            .map(|&i| (i, Ending::EventLimit));
        now.into_iter().chain(before).min_by_key(|&(i, _)| i)
    }
}

/// How a pool runs its runs.
#[derive(Debug, Clone, Copy)]
pub struct PoolOptions {
    /// Worker threads.
    pub jobs: usize,
    /// A bar over the runs on a terminal; off one, a line per run and progress lines.
    pub progress: bool,
    /// Wall seconds between a run's progress lines off a terminal.
    pub progress_every: f64,
    /// Wall-clock limit of each run (`--max-run-seconds`), in place of `run.max_wall_seconds`.
    pub max_run_seconds: Option<f64>,
}

/// Runs every run of the plan that is not done yet on `jobs` worker threads, with a progress bar
/// over runs on stderr when `progress` (hidden when stderr is not a terminal, where each run
/// writes progress lines instead). The runs of an approximate scheme that leave
/// `engine.threads` unset share the cores: each gets cores / jobs threads (at least one), so that
/// the pool does not oversubscribe the machine.
pub fn run_pool(exp: &Expanded, out: &Path, options: PoolOptions) -> Result<PoolReport> {
    let PoolOptions { jobs, progress, .. } = options;
    write_plan(&exp.plan, out)?;
    let runs = &exp.plan.runs;
    let recorded: Vec<Option<String>> = (0..runs.len()).map(|i| recorded_ending(out, i)).collect();
    let ended = |i: &usize, endings: &[&str]| {
        recorded[*i]
            .as_deref()
            .is_some_and(|ending| endings.contains(&ending))
    };
    let pending: Vec<usize> = (0..runs.len()).filter(|i| !ended(i, &DONE)).collect();
    let mut report = PoolReport {
        skipped: runs.len() - pending.len(),
        limited_before: (0..runs.len())
            .filter(|i| ended(i, &["event-limit"]))
            .collect(),
        ..Default::default()
    };
    let bar = if progress {
        indicatif::ProgressBar::new(runs.len() as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} runs (eta {eta}) {msg}",
        )
        .expect("valid template"),
    );
    bar.set_position(report.skipped as u64);
    if report.skipped > 0 {
        bar.set_message(format!("{} done before", report.skipped));
    }
    let next = AtomicUsize::new(0);
    let outcomes: Mutex<Vec<(usize, Result<Ending>)>> = Mutex::new(Vec::new());
    let jobs = jobs.clamp(1, pending.len().max(1));
    threads_fit(jobs, RUN_THREAD_STACK)
        .map_err(|limit| Error::input("--jobs", threads_refused(jobs, "runs at once", limit)))?;
    let cores = crate::schemes::cores::available();
    std::thread::scope(|scope| {
        for _ in 0..jobs {
            let worker = || loop {
                if crate::platform::signals::stop_flag().load(Ordering::Relaxed) {
                    break;
                }
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(&i) = pending.get(k) else { break };
                let mut scenario = share(&exp.scenarios[i], jobs, cores);
                if let Some(seconds) = options.max_run_seconds {
                    scenario.run.max_wall_seconds = Some(seconds);
                }
                let lines = progress.then_some(options.progress_every);
                let outcome = run_one(&exp.plan, &runs[i], &scenario, out, lines);
                bar.inc(1);
                let line = match &outcome {
                    Err(e) => Some(format!("vibrobed: run {i} failed: {e}")),
                    // Without a terminal (a log file), one line per run instead of the bar.
                    Ok(ending) if progress && bar.is_hidden() => Some(format!(
                        "run {i}: {} ({}/{} runs)",
                        ending.words(),
                        bar.position(),
                        runs.len()
                    )),
                    Ok(_) => None,
                };
                match line {
                    Some(line) if bar.is_hidden() => eprintln!("{line}"),
                    Some(line) => bar.println(line),
                    None => {}
                }
                outcomes
                    .lock()
                    .expect("no worker panics")
                    .push((i, outcome));
            };
            std::thread::Builder::new()
                .stack_size(RUN_THREAD_STACK)
                .spawn_scoped(scope, worker)
                .expect("a worker thread starts");
        }
    });
    bar.finish_and_clear();
    let mut outcomes = outcomes.into_inner().expect("no worker panics");
    outcomes.sort_by_key(|(i, _)| *i);
    for (i, outcome) in outcomes {
        match outcome {
            Ok(Ending::Interrupted) => report.interrupted += 1,
            Ok(Ending::Completed) => report.ran += 1,
            Ok(early) => {
                report.ran += 1;
                report.ended_early.push((i, early));
            }
            Err(e) => report.failed.push((i, e.to_string())),
        }
    }
    Ok(report)
}
