//! `vibrobed sweep plan|run|slurm|task|collect`: the sweep subcommands of the command line.

use crate::error::{Error, Result};
use crate::output::progress::DEFAULT_EVERY;
use crate::output::summary::Ending;
use crate::scenario::Scheme;
use crate::studies::sweep::collect::collect;
use crate::studies::sweep::fit::{FitOptions, Offset};
use crate::studies::sweep::local::{
    check_plan, is_done, recorded_ending, run_one, run_pool, write_atomic, write_plan, PoolOptions,
    PoolReport,
};
use crate::studies::sweep::plan::{expand, point_label, Expanded, Plan};
use crate::studies::sweep::report::{collect_command, Asked};
use crate::studies::sweep::slurm::{script, submit, SlurmOptions};
use crate::studies::sweep::state_map::{draw_states, StatePoint};
use clap::{Subcommand, ValueEnum};
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

/// What to do with a sweep.
#[derive(Debug, Subcommand)]
pub enum SweepCommand {
    /// List the runs of a sweep file (index, point, seed, overrides, output folder) and check
    /// every derived scenario as `check` does, without running anything.
    Plan {
        /// The sweep file (JSON).
        sweep: PathBuf,
        /// Show the output folders under this directory.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Estimate the sweep's CPU time from a trial of each point's first run, at most
        /// SECONDS of wall time each (default 2): per run, per point and in total.
        #[arg(long, value_name = "SECONDS", num_args = 0..=1, default_missing_value = "2")]
        estimate: Option<f64>,
    },
    /// Run the sweep on this machine: each run writes `DIR/<index>/summary.json` (and profiles.csv
    /// for gravity scenes); a rerun skips completed runs.
    Run {
        /// The sweep file (JSON).
        sweep: PathBuf,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// Worker threads (default: all cores).
        #[arg(long, short)]
        jobs: Option<usize>,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
        /// Off a terminal, each run's progress line every SECONDS of wall time (default 60).
        #[arg(long, value_name = "SECONDS")]
        progress_every: Option<f64>,
        /// Stop each run after SECONDS of wall time (ending `wall-limit`; sets
        /// run.max_wall_seconds of every run); a later `sweep run` runs such runs again.
        #[arg(long, value_name = "SECONDS")]
        max_run_seconds: Option<f64>,
    },
    /// Write DIR/sweep.sbatch, a Slurm job array with one task per run, and submit it with
    /// --submit (prints the job id).
    Slurm {
        /// The sweep file (JSON).
        sweep: PathBuf,
        /// Output directory (the tasks write their runs here).
        #[arg(long)]
        out: PathBuf,
        /// Slurm partition.
        #[arg(long)]
        partition: Option<String>,
        /// Time limit of each task, e.g. 01:30:00.
        #[arg(long)]
        time: Option<String>,
        /// At most this many tasks at once.
        #[arg(long)]
        array_max: Option<usize>,
        /// A further sbatch option for the script, e.g. --sbatch=--mem=2G (repeatable).
        #[arg(long = "sbatch", value_name = "OPTION", allow_hyphen_values = true)]
        sbatch: Vec<String>,
        /// Submit the script with sbatch and print the job id.
        #[arg(long)]
        submit: bool,
    },
    /// Run one run of the sweep (what each Slurm array task does).
    Task {
        /// The sweep file (JSON).
        sweep: PathBuf,
        /// The run's index.
        #[arg(long)]
        index: usize,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
    },
    /// Gather the runs' summaries under DIR into DIR/runs.csv and DIR/points.csv; with --x and
    /// --y, plot the fields' means (± standard error) against an axis into an SVG file.
    Collect {
        /// The sweep's output directory; several: each gets its tables, and their series are
        /// overlaid in one plot (written into the first unless --plot).
        #[arg(required = true, num_args = 1..)]
        dirs: Vec<PathBuf>,
        /// Axis of the plot: a key of the sweep's axes, or drive.amplitude, drive.frequency,
        /// drive.gamma, drive.peak_velocity (Aω) for a vibrating floor.
        #[arg(long)]
        x: Option<String>,
        /// Summary field to plot (repeatable: one panel each), e.g. temperature.mean.
        #[arg(long)]
        y: Vec<String>,
        /// Group the points by this axis (repeatable): one series each, in its colour, fitted
        /// apart. Needed when another axis than --x varies.
        #[arg(long, value_name = "KEY")]
        by: Vec<String>,
        /// Fit each plotted field against x: `power` fits y = c·x^δ (log–log least squares).
        #[arg(long, value_enum)]
        fit: Option<Fit>,
        /// Fit only the points with x in [LO, HI].
        #[arg(long, num_args = 2, value_names = ["LO", "HI"], requires = "fit")]
        fit_range: Option<Vec<f64>>,
        /// Fit y − Y0 = c·x^δ: a value (e.g. the bed's height at rest), or `fit` to fit Y0 too.
        #[arg(long, value_name = "Y0", requires = "fit")]
        offset: Option<String>,
        /// Logarithmic x and y axes.
        #[arg(long)]
        log: bool,
        /// Where to write the plot (default DIR/plot.svg).
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Draw the phase diagram of the bed's states over two axes (each point's most frequent
        /// `state.name`) into DIR/states.svg, e.g. --states floor.gamma particles.count.
        #[arg(long, num_args = 2, value_names = ["X", "Y"])]
        states: Option<Vec<String>>,
    },
}

/// Fits offered by `sweep collect --fit`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Fit {
    /// y = c·x^δ by least squares on log–log axes; δ with its standard error.
    Power,
}

/// An absolute path for `path` (the Slurm script's tasks run elsewhere).
fn absolute(path: &Path) -> Result<PathBuf> {
    std::path::absolute(path)
        .map_err(|e| Error::Io(format!("cannot resolve {}: {e}", path.display())))
}

/// Maps an I/O error to one that says what could not be done to which path.
fn io<'a>(path: &'a Path, what: &'a str) -> impl Fn(std::io::Error) -> Error + 'a {
    move |e| Error::Io(format!("cannot {what} {}: {e}", path.display()))
}

impl SweepCommand {
    /// Runs the subcommand; returns the exit code (errors carry theirs).
    pub fn execute(self) -> Result<i32> {
        match self {
            SweepCommand::Plan {
                sweep,
                out,
                estimate,
            } => plan(&sweep, out.as_deref(), estimate),
            SweepCommand::Run {
                sweep,
                out,
                jobs,
                quiet,
                progress_every,
                max_run_seconds,
            } => {
                crate::scenario::intervals::progress_every(progress_every)?;
                check_max_run_seconds(max_run_seconds)?;
                let options = PoolOptions {
                    jobs: jobs.unwrap_or(0),
                    progress: !quiet,
                    progress_every: progress_every.unwrap_or(DEFAULT_EVERY),
                    max_run_seconds,
                };
                run(&sweep, &out, jobs, options)
            }
            SweepCommand::Task { sweep, index, out } => task(&sweep, index, &out),
            SweepCommand::Slurm {
                sweep,
                out,
                partition,
                time,
                array_max,
                sbatch,
                submit,
            } => {
                let opts = SlurmOptions {
                    partition,
                    time,
                    array_max,
                    extra: sbatch,
                };
                slurm(&sweep, &out, &opts, submit)
            }
            SweepCommand::Collect {
                dirs,
                x,
                y,
                by,
                fit,
                fit_range,
                offset,
                log,
                plot,
                states,
            } => {
                // --log with --states alone is the map's (logarithmic x), not a plot's.
                let plot_log = log && (x.is_some() || states.is_none());
                let asked = Asked {
                    x,
                    ys: y,
                    by,
                    fit: fit.map(|_| fit_options(fit_range, offset)).transpose()?,
                    log: plot_log,
                    plot,
                };
                // The map's axes and states are checked before the tables are written: a
                // command that fails writes nothing.
                let map = states
                    .map(|axes| state_map(&dirs[0], &axes[0], &axes[1]))
                    .transpose()?;
                let drawn = collect_command(&dirs, asked)?;
                match map {
                    Some(map) => draw_state_map(&map, log),
                    None => Ok(drawn),
                }
            }
        }
    }
}

/// Refuses a `--max-run-seconds` that `run.max_wall_seconds` would refuse.
pub fn check_max_run_seconds(seconds: Option<f64>) -> Result<()> {
    seconds.map_or(Ok(()), |m| {
        crate::scenario::intervals::wall_seconds("--max-run-seconds", m)
    })
}

/// The fit's options from `--fit-range LO HI` and `--offset Y0|fit`, refused when they make no
/// sense (a range not from low to high, an offset that is neither a number nor `fit`).
fn fit_options(range: Option<Vec<f64>>, offset: Option<String>) -> Result<FitOptions> {
    let range = match range.as_deref() {
        None => None,
        Some(&[lo, hi]) if lo < hi => Some((lo, hi)),
        Some(r) => {
            return Err(Error::input(
                "--fit-range",
                format!("give LO < HI (got {r:?})"),
            ))
        }
    };
    let offset = match offset.as_deref() {
        None => None,
        Some("fit") => Some(Offset::Fitted),
        Some(text) => match text.parse::<f64>() {
            Ok(y0) if y0.is_finite() => Some(Offset::Given(y0)),
            _ => {
                return Err(Error::input(
                    "--offset",
                    format!("a number or `fit` (got `{text}`)"),
                ))
            }
        },
    };
    Ok(FitOptions { range, offset })
}

/// `sweep plan`: expands the sweep, builds every run's scene as `check` does, and lists the runs;
/// with `--estimate`, runs each point's trial and prints the estimated CPU time.
fn plan(sweep: &Path, out: Option<&Path>, estimate: Option<f64>) -> Result<i32> {
    crate::scenario::intervals::estimate_seconds(estimate)?;
    let exp = expand(sweep)?;
    exp.check_scenes()?;
    print!("{}", exp.plan.listing(out));
    eprintln!(
        "{}: ok ({} runs checked)",
        sweep.display(),
        exp.plan.runs.len()
    );
    if let Some(seconds) = estimate {
        let points = crate::studies::sweep::estimate::estimate(&exp, seconds)?;
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        print!(
            "{}",
            crate::studies::sweep::estimate::table(&points, seconds, cores)
        );
        if crate::platform::signals::stop_flag().load(Ordering::Relaxed) {
            return Ok(crate::platform::signals::exit_code());
        }
    }
    Ok(0)
}

/// `sweep run`: every run not yet completed, on a pool of worker threads. A signal stops the
/// pool (exit 128 + its number); a failed run fails the sweep once the others are done; a run
/// stopped by a limit, now or before, gives the sweep its exit code (4, 5), since the sweep's
/// results are then incomplete.
fn run(sweep: &Path, out: &Path, jobs: Option<usize>, options: PoolOptions) -> Result<i32> {
    if jobs == Some(0) {
        return Err(Error::input("--jobs", "must be at least 1"));
    }
    let exp = expand(sweep)?;
    exp.check_scenes()?;
    let jobs = jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    writable_out(out)?;
    crate::platform::signals::install();
    let report = run_pool(&exp, out, PoolOptions { jobs, ..options })?;
    eprintln!("{}", pool_tally(&exp.plan, &report, jobs, out));
    if crate::platform::signals::stop_flag().load(Ordering::Relaxed) {
        return Ok(crate::platform::signals::exit_code());
    }
    if let Some((i, first)) = report.failed.first() {
        return Err(Error::Runtime(format!(
            "{} of {} runs failed (their folders hold error.txt); run {i}: {first}",
            report.failed.len(),
            exp.plan.runs.len()
        )));
    }
    Ok(report
        .first_early()
        .map_or(0, |(_, ending)| ending.exit_code()))
}

/// Refuses (exit 2) an output directory that cannot be created or written in, before any run.
pub fn writable_out(out: &Path) -> Result<()> {
    crate::output::not_dash("--out", out)?;
    std::fs::create_dir_all(out)
        .map_err(|e| Error::input("--out", format!("cannot create {}: {e}", out.display())))?;
    crate::output::writable_directory(&out.join("plan.json"))
        .map_err(|why| Error::input("--out", format!("{}: {why}", out.display())))
}

/// The line `sweep run` ends with: how many runs ran now, were done before, failed, were
/// interrupted or never started, and on how many workers.
fn pool_tally(plan: &Plan, report: &PoolReport, jobs: usize, out: &Path) -> String {
    let n = plan.runs.len();
    let not_started = n - report.skipped - report.ran - report.failed.len() - report.interrupted;
    let early = if report.ended_early.is_empty() {
        String::new()
    } else {
        let runs: Vec<String> = report
            .ended_early
            .iter()
            .map(|(i, e)| format!("run {i} {}", e.words()))
            .collect();
        format!(" (of them ended early: {})", runs.join("; "))
    };
    let limited = match report.limited_before.as_slice() {
        [] => String::new(),
        runs => format!(
            " (of them stopped by the event limit: run {})",
            runs.iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    format!(
        "sweep {}: {} runs: {} ran now{early}, {} done before{limited}{}{}{} ({})",
        plan.name,
        n,
        report.ran,
        report.skipped,
        if report.failed.is_empty() {
            String::new()
        } else {
            format!(", {} failed", report.failed.len())
        },
        if report.interrupted + not_started > 0 {
            format!(
                ", {} interrupted, {} not started",
                report.interrupted, not_started
            )
        } else {
            String::new()
        },
        if jobs > 1 {
            format!(", {jobs} workers")
        } else {
            ", 1 worker".into()
        },
        out.display()
    )
}

/// `sweep task`: one run of the sweep, what each Slurm array task does; a run completed
/// already is not run again.
fn task(sweep: &Path, index: usize, out: &Path) -> Result<i32> {
    crate::output::not_dash("--out", out)?;
    let exp = expand(sweep)?;
    let n = exp.plan.runs.len();
    if index >= n {
        return Err(Error::input(
            "--index",
            format!("the sweep has {n} runs (0 to {})", n.saturating_sub(1)),
        ));
    }
    write_plan(&exp.plan, out)?;
    // A run done before exits as it did then (0, or 4 for its event limit, which a rerun
    // would only repeat).
    match recorded_ending(out, index).as_deref() {
        Some("completed") => {
            eprintln!("run {index}: already completed");
            return Ok(0);
        }
        Some("event-limit") => {
            eprintln!("run {index}: already ran, {}", Ending::EventLimit.words());
            return Ok(Ending::EventLimit.exit_code());
        }
        _ => {}
    }
    crate::platform::signals::install();
    let spec = &exp.plan.runs[index];
    let ending = match run_one(
        &exp.plan,
        spec,
        &exp.scenarios[index],
        out,
        Some(DEFAULT_EVERY),
    ) {
        Ok(ending) => ending,
        // A stalled run counts as failed (error.txt holds the stall's report) but keeps its
        // summary, and exits with the stall's own code, as `run` does.
        Err(e) if ended_stalled(out, index) => {
            eprintln!("vibrobed: run {index}: {e}");
            return Ok(Ending::Stalled.exit_code());
        }
        Err(e) => return Err(e),
    };
    eprintln!(
        "run {index} (point {}: {}, seed {}): {}",
        spec.point,
        point_label(&exp.plan.axes, &spec.values),
        spec.seed
            .map_or("of the scenario".into(), |s| s.to_string()),
        ending.words()
    );
    Ok(ending.exit_code())
}

/// Whether run `index`'s summary under `out` says `"ending": "stalled"`.
fn ended_stalled(out: &Path, index: usize) -> bool {
    std::fs::read_to_string(crate::studies::sweep::local::run_dir(out, index).join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .is_some_and(|s| s["ending"] == "stalled")
}

/// `sweep slurm`: writes `DIR/sweep.sbatch`, a job array over the runs not completed yet (all
/// of them the first time), and with `--submit` submits it and prints the job id.
fn slurm(sweep: &Path, out: &Path, opts: &SlurmOptions, submit_it: bool) -> Result<i32> {
    crate::output::not_dash("--out", out)?;
    let exp = expand(sweep)?;
    exp.check_scenes()?;
    let out = absolute(out)?;
    let exe = std::env::current_exe()
        .map_err(|e| Error::Io(format!("cannot find this program's path: {e}")))?;
    check_plan(&exp.plan, &out)?;
    let pending: Vec<usize> = (0..exp.plan.runs.len())
        .filter(|&i| !is_done(&out, i))
        .collect();
    let n = exp.plan.runs.len();
    if pending.is_empty() {
        eprintln!(
            "all {n} runs are completed in {}: nothing to submit",
            out.display()
        );
        return Ok(0);
    }
    let text = script(
        &exp.plan,
        &pending,
        task_cpus(&exp, &pending),
        &exe,
        &out,
        opts,
    )?;
    write_plan(&exp.plan, &out)?;
    let logs = out.join("slurm");
    std::fs::create_dir_all(&logs).map_err(io(&logs, "create"))?;
    let path = out.join("sweep.sbatch");
    write_atomic(&path, &text)?;
    eprintln!(
        "wrote {} ({} array tasks{})",
        path.display(),
        pending.len(),
        if pending.len() < n {
            format!("; {} of {n} runs are completed already", n - pending.len())
        } else {
            String::new()
        }
    );
    if submit_it {
        let id = submit(&path)?;
        println!("{id}");
    }
    Ok(0)
}

/// The cores an array task asks for: the most threads any of the runs `pending` uses
/// (`engine.threads` of an approximate scheme; one for the exact engine, and for an
/// approximate scheme that does not set it, which then runs on the one core it is given).
fn task_cpus(exp: &Expanded, pending: &[usize]) -> usize {
    pending
        .iter()
        .map(|&i| {
            let s = &exp.scenarios[i];
            match s.engine.threads {
                Some(t) if s.scheme() != Scheme::EventDriven => t as usize,
                _ => 1,
            }
        })
        .max()
        .unwrap_or(1)
}

/// The map `sweep collect --states X Y` draws: where it goes, its title, axes and points.
struct StateMap {
    path: PathBuf,
    title: String,
    axes: (String, String),
    points: Vec<StatePoint>,
}

/// The map of the points' bed states over X and Y into `DIR/states.svg`, refused (before
/// anything is written) for an axis the sweep does not have or a sweep with no bed state.
fn state_map(dir: &Path, x: &str, y: &str) -> Result<StateMap> {
    let c = collect(dir)?;
    let points = c.state_points(x, y)?;
    if points.is_empty() {
        return Err(Error::input(
            "--states",
            "no completed run of this sweep has a bed state: a state needs a floor under \
             gravity and a window after the warm-up that resolves the floor's periods (check \
             notes so when it does not)",
        ));
    }
    let title = format!(
        "sweep {}: bed states ({} seeds per point)",
        c.plan.name,
        c.plan.seeds_per_point()
    );
    Ok(StateMap {
        path: dir.join("states.svg"),
        title,
        axes: (x.to_string(), y.to_string()),
        points,
    })
}

/// `sweep collect --states X Y`: draws the map (logarithmic x with `--log`).
fn draw_state_map(map: &StateMap, log: bool) -> Result<i32> {
    let axes = (map.axes.0.as_str(), map.axes.1.as_str());
    draw_states(&map.path, &map.title, axes, &map.points, log)?;
    eprintln!("wrote {}", map.path.display());
    Ok(0)
}
