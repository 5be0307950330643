//! `vibrobed sweep plan|run|slurm|task|collect`: the sweep subcommands of the command line.

use crate::error::{Error, Result};
use crate::output::summary::Ending;
use crate::scenario::Scheme;
use crate::studies::sweep::collect::collect;
use crate::studies::sweep::fit::{power_law, PowerFit};
use crate::studies::sweep::local::{
    check_plan, ending_word, is_done, run_one, run_pool, write_atomic, write_plan, PoolReport,
};
use crate::studies::sweep::plan::{expand, point_label, Expanded, Plan};
use crate::studies::sweep::plot::{draw, Panel};
use crate::studies::sweep::slurm::{script, submit, SlurmOptions};
use crate::studies::sweep::state_map::draw_states;
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
        /// The sweep's output directory.
        dir: PathBuf,
        /// Axis of the plot: a key of the sweep's axes, or drive.amplitude, drive.frequency,
        /// drive.gamma, drive.peak_velocity (Aω) for a vibrating floor.
        #[arg(long)]
        x: Option<String>,
        /// Summary field to plot (repeatable: one panel each), e.g. temperature.mean.
        #[arg(long)]
        y: Vec<String>,
        /// Fit each plotted field against x: `power` fits y = c·x^δ (log–log least squares).
        #[arg(long, value_enum)]
        fit: Option<Fit>,
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
            SweepCommand::Plan { sweep, out } => plan(&sweep, out.as_deref()),
            SweepCommand::Run {
                sweep,
                out,
                jobs,
                quiet,
            } => run(&sweep, &out, jobs, quiet),
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
                dir,
                x,
                y,
                fit,
                log,
                plot,
                states,
            } => {
                // --log with --states alone is the map's (logarithmic x), not a plot's.
                let plot_log = log && (x.is_some() || states.is_none());
                let drawn = collect_command(&dir, x, y, fit, plot_log, plot)?;
                match states {
                    Some(axes) => states_command(&dir, &axes[0], &axes[1], log),
                    None => Ok(drawn),
                }
            }
        }
    }
}

/// `sweep plan`: expands the sweep, builds every run's scene as `check` does, and lists the runs.
fn plan(sweep: &Path, out: Option<&Path>) -> Result<i32> {
    let exp = expand(sweep)?;
    exp.check_scenes()?;
    print!("{}", exp.plan.listing(out));
    eprintln!(
        "{}: ok ({} runs checked)",
        sweep.display(),
        exp.plan.runs.len()
    );
    Ok(0)
}

/// `sweep run`: every run not yet completed, on a pool of worker threads. A signal stops the
/// pool (exit 128 + its number); a failed run fails the sweep once the others are done.
fn run(sweep: &Path, out: &Path, jobs: Option<usize>, quiet: bool) -> Result<i32> {
    if jobs == Some(0) {
        return Err(Error::input("--jobs", "must be at least 1"));
    }
    let exp = expand(sweep)?;
    exp.check_scenes()?;
    let jobs = jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    writable_out(out)?;
    crate::platform::signals::install();
    let report = run_pool(&exp, out, jobs, !quiet)?;
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
    Ok(0)
}

/// Refuses (exit 2) an output directory that cannot be created or written in, before any run.
pub fn writable_out(out: &Path) -> Result<()> {
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
    format!(
        "sweep {}: {} runs: {} ran now, {} done before{}{}{} ({})",
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
    let exp = expand(sweep)?;
    let n = exp.plan.runs.len();
    if index >= n {
        return Err(Error::input(
            "--index",
            format!("the sweep has {n} runs (0 to {})", n.saturating_sub(1)),
        ));
    }
    write_plan(&exp.plan, out)?;
    if is_done(out, index) {
        eprintln!("run {index}: already completed");
        return Ok(0);
    }
    crate::platform::signals::install();
    let spec = &exp.plan.runs[index];
    let ending = run_one(&exp.plan, spec, &exp.scenarios[index], out)?;
    eprintln!(
        "run {index} (point {}: {}, seed {}): {}",
        spec.point,
        point_label(&exp.plan.axes, &spec.values),
        spec.seed
            .map_or("of the scenario".into(), |s| s.to_string()),
        ending_word(ending)
    );
    Ok(if ending == Ending::Interrupted {
        130
    } else {
        0
    })
}

/// `sweep slurm`: writes `DIR/sweep.sbatch`, a job array over the runs not completed yet (all
/// of them the first time), and with `--submit` submits it and prints the job id.
fn slurm(sweep: &Path, out: &Path, opts: &SlurmOptions, submit_it: bool) -> Result<i32> {
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
                Some(t) if s.engine.scheme != Scheme::EventDriven => t as usize,
                _ => 1,
            }
        })
        .max()
        .unwrap_or(1)
}

/// `sweep collect`: gathers the runs into `DIR/runs.csv` and `DIR/points.csv`; with `--x` and
/// `--y`, plots each field's point means against x (and with `--fit`, fits and reports them).
/// The plot's fields are checked before anything is written.
fn collect_command(
    dir: &Path,
    x: Option<String>,
    ys: Vec<String>,
    fit: Option<Fit>,
    log: bool,
    plot: Option<PathBuf>,
) -> Result<i32> {
    let c = collect(dir)?;
    let x = match (x, ys.is_empty()) {
        (Some(x), false) => Some(x),
        (None, true) if fit.is_none() && plot.is_none() && !log => None,
        (None, _) => return Err(Error::input("--x", "needed to plot or fit (with --y)")),
        (Some(_), true) => return Err(Error::input("--y", "needed with --x")),
    };
    let series = match &x {
        Some(x) => ys
            .iter()
            .map(|y| c.series(x, y))
            .collect::<Result<Vec<_>>>()?,
        None => Vec::new(),
    };
    c.write_tables(dir)?;
    eprintln!(
        "{}: {} runs ({}); wrote runs.csv, points.csv",
        dir.display(),
        c.runs.len(),
        c.endings()
    );
    let Some(x) = x else { return Ok(0) };
    let fits: Vec<Option<PowerFit>> = series
        .iter()
        .map(|s| match fit {
            Some(Fit::Power) => {
                power_law(&s.iter().map(|(x, st)| (*x, st.mean)).collect::<Vec<_>>())
            }
            None => None,
        })
        .collect();
    if fit.is_some() {
        report_fits(dir, &x, &ys, &fits)?;
    }
    let panels: Vec<Panel> = ys
        .iter()
        .zip(&series)
        .zip(&fits)
        .map(|((y, s), f)| Panel {
            field: y,
            series: s,
            fit: *f,
        })
        .collect();
    let path = plot.unwrap_or_else(|| dir.join("plot.svg"));
    let title = format!(
        "sweep {}: against {x} ({} seeds per point)",
        c.plan.name,
        c.plan.seeds_per_point()
    );
    draw(&path, &title, &x, &panels, log, log)?;
    eprintln!("wrote {}", path.display());
    Ok(0)
}

/// `sweep collect --states X Y`: the map of the points' bed states over X and Y into
/// `DIR/states.svg` (logarithmic x with `--log`).
fn states_command(dir: &Path, x: &str, y: &str, log: bool) -> Result<i32> {
    let c = collect(dir)?;
    let points = c.state_points(x, y)?;
    if points.is_empty() {
        return Err(Error::input(
            "--states",
            "no completed run of this sweep has a bed state (a floor under gravity)",
        ));
    }
    let path = dir.join("states.svg");
    let title = format!(
        "sweep {}: bed states ({} seeds per point)",
        c.plan.name,
        c.plan.seeds_per_point()
    );
    draw_states(&path, &title, (x, y), &points, log)?;
    eprintln!("wrote {}", path.display());
    Ok(0)
}

/// Prints each field's power-law fit y = c·x^δ (or why it has none) and writes them all to
/// `DIR/fit.json`.
fn report_fits(dir: &Path, x: &str, ys: &[String], fits: &[Option<PowerFit>]) -> Result<()> {
    let mut json = serde_json::Map::new();
    for (y, f) in ys.iter().zip(fits) {
        match f {
            Some(f) => {
                println!(
                    "{y} = c·({x})^δ: δ = {:.4}{}, c = {:.4} ({} points, log–log least squares)",
                    f.exponent,
                    f.exponent_se
                        .map_or(" (no error with two points)".into(), |se| format!(
                            " ± {se:.4}"
                        )),
                    f.prefactor,
                    f.points
                );
                json.insert(y.clone(), serde_json::to_value(f).expect("fit serialises"));
            }
            None => println!("{y}: no fit (it needs two points with positive x and y)"),
        }
    }
    let text = serde_json::to_string_pretty(&serde_json::json!({ "x": x, "power_law": json }))
        .expect("fit serialises")
        + "\n";
    write_atomic(&dir.join("fit.json"), &text)
}
