//! The command line: `vibrobed run SCENARIO.json [--rrd OUT.rrd] [--summary OUT.json]
//! [--profiles OUT.csv] [--trajectory OUT.xyz] [--set KEY=VALUE]...`, `vibrobed check SCENARIO.json` and
//! `vibrobed accuracy SCENARIO.json [--out DIR] [--set KEY=VALUE]... [--quick] [--effects] [--cores C]`.
//!
//! Exit codes: 0 success, 2 bad input or arguments (the message names the field), 1 runtime
//! failure (or a summary or profiles that could not be written), 3 an output (recording,
//! trajectory, checkpoint) that could not be written while the run went on, 4 stopped by
//! `run.max_events`, 5 stopped by `run.max_wall_seconds`, 6 a clock that stalled, 128 + n
//! stopped by signal n (130 Ctrl-C). A run that ends early still writes its summary (marked with its
//! `ending`) and closes its recording properly; one stopped before its first event, while its
//! scene is built, ends at once and writes nothing.

use crate::error::{Error, Result, EXIT_OUTPUT_FAILED};
use crate::output::canonical;
use crate::output::summary::{Ending, Summary};
use crate::platform::signals;
use crate::run::checkpoint::{check_resume_duration, check_resume_sets, Checkpoint};
use crate::run::{run, CheckpointPlan, RunOptions};
use crate::scenario::Scenario;
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};

/// Command-line arguments.
#[derive(Debug, Parser)]
#[command(
    name = "vibrobed",
    version,
    about = "Event-driven simulation of vibrated granular beds (hard disks in 2D)"
)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scenario and print (or write) its summary.
    Run {
        /// The scenario file (JSON).
        scenario: PathBuf,
        /// Record frames to this Rerun file (.rrd).
        #[arg(long)]
        rrd: Option<PathBuf>,
        /// Write the summary JSON here instead of stdout (`-`: stdout). No other output takes
        /// `-`.
        #[arg(long)]
        summary: Option<PathBuf>,
        /// Write the height profiles as CSV here (gravity scenes).
        #[arg(long)]
        profiles: Option<PathBuf>,
        /// Write the time-averaged 2D fields here (gravity scenes): CSV, or VTK image data
        /// for a file named *.vti; the grid is output.field_bins and output.field_height.
        #[arg(long)]
        fields: Option<PathBuf>,
        /// Write a trajectory in extended XYZ here (OVITO, ASE), a frame every
        /// output.trajectory_interval (default: the frame interval).
        #[arg(long)]
        trajectory: Option<PathBuf>,
        /// Override a scenario field by its dotted path, e.g. particles.count=10000.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Write the run's complete state to this file at the end, however the run ends
        /// (completed, event limit, SIGINT/SIGTERM/SIGHUP), for `vibrobed resume`.
        #[arg(long, value_name = "FILE")]
        checkpoint: Option<PathBuf>,
        /// Also write the checkpoint every T units of simulated time (needs --checkpoint).
        #[arg(long, value_name = "T", requires = "checkpoint")]
        checkpoint_every: Option<f64>,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
        /// Off a terminal, a progress line every SECONDS of wall time (default 60).
        #[arg(long, value_name = "SECONDS")]
        progress_every: Option<f64>,
    },
    /// Continue a run from its checkpoint: the same events, bit for bit, as if it had not
    /// stopped. The summary and profiles cover the whole run; a recording or trajectory holds
    /// the resumed part (a recording under the same recording id: open both files together).
    Resume {
        /// The checkpoint file (from `run --checkpoint`).
        checkpoint_file: PathBuf,
        /// Only run.duration and run.max_events can change, e.g. run.duration=400 to extend.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Record the resumed part to this Rerun file (.rrd); not a file an earlier part wrote.
        #[arg(long)]
        rrd: Option<PathBuf>,
        /// Write the summary JSON here instead of stdout (`-`: stdout). No other output takes
        /// `-`.
        #[arg(long)]
        summary: Option<PathBuf>,
        /// Write the height profiles as CSV here (gravity scenes).
        #[arg(long)]
        profiles: Option<PathBuf>,
        /// Write the 2D fields here (CSV, or VTK image data for *.vti); the checkpointed run
        /// must have measured them (run --fields).
        #[arg(long)]
        fields: Option<PathBuf>,
        /// Write the resumed part's trajectory in extended XYZ here.
        #[arg(long)]
        trajectory: Option<PathBuf>,
        /// Where to keep checkpointing (default: the checkpoint file itself).
        #[arg(long, value_name = "FILE")]
        checkpoint: Option<PathBuf>,
        /// Simulated time between checkpoints (default: the saved run's).
        #[arg(long, value_name = "T")]
        checkpoint_every: Option<f64>,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
        /// Off a terminal, a progress line every SECONDS of wall time (default 60).
        #[arg(long, value_name = "SECONDS")]
        progress_every: Option<f64>,
    },
    /// Show what accuracy costs in time: run the exact engine as reference and each variant
    /// (approximate schemes with a sweep of their step, floor models, dissipation cures,
    /// recording) on the same scene and seeds; print a table, write accuracy.csv, accuracy.txt
    /// and accuracy.svg (error vs cost, log–log) into --out.
    Accuracy {
        /// The scenario file (JSON).
        scenario: PathBuf,
        /// Directory for the CSV, the table and the plot.
        #[arg(long, default_value = "accuracy")]
        out: PathBuf,
        /// Override a scenario field by its dotted path.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Short runs, two seeds, three sweep points (for CI).
        #[arg(long)]
        quick: bool,
        /// Number of seeds of the ensembles (default 3; 2 with --quick).
        #[arg(long)]
        seeds: Option<usize>,
        /// Also measure what each effect costs (effects.csv): the slowdown of a scene with the
        /// effect against the same scene without it.
        #[arg(long)]
        effects: bool,
        /// Cores K to cost on: the approximate schemes run on K threads, the exact engine also K
        /// seeds at once (default: every core this process may use).
        #[arg(long)]
        cores: Option<usize>,
        /// No progress lines on stderr.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Parameter sweeps and seed ensembles: plan, run locally or on Slurm, collect.
    Sweep {
        /// What to do with the sweep.
        #[command(subcommand)]
        command: crate::studies::sweep::command::SweepCommand,
    },
    /// Validate a scenario without running it.
    Check {
        /// The scenario file (JSON).
        scenario: PathBuf,
        /// Override a scenario field by its dotted path.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
    },
}

/// The output files a command line (or the Python package) asks for.
#[derive(Default)]
pub struct OutputArgs<'a> {
    /// `--rrd`.
    pub rrd: Option<&'a Path>,
    /// `--summary`.
    pub summary: Option<&'a Path>,
    /// `--profiles`.
    pub profiles: Option<&'a Path>,
    /// `--fields`.
    pub fields: Option<&'a Path>,
    /// `--trajectory`.
    pub trajectory: Option<&'a Path>,
    /// `--checkpoint`.
    pub checkpoint: Option<&'a Path>,
    /// The files the command reads (`SCENARIO`, the `CHECKPOINT` resumed): no output may be
    /// written over them, but for the checkpoint a resume keeps checkpointing into.
    pub inputs: Vec<(&'static str, &'a Path)>,
}

/// Refuses, before anything runs, output files that cannot be written: a path that is not a
/// regular file (a directory, a device, a fifo) or lies in a directory that does not exist, one that names an input or another
/// output, profiles of a scene without gravity, a recording from a build without recording, a
/// recording or trajectory larger than [`MAX_RECORDED_DISKS`](crate::scenario::checks). A run
/// that starts can write all it was asked for.
pub fn output_paths(s: &Scenario, args: &OutputArgs) -> Result<()> {
    let scenario_rrd = s.output.rrd.as_deref().map(Path::new);
    let scenario_trajectory = s.output.trajectory.as_deref().map(Path::new);
    let files = [
        ("--rrd", args.rrd),
        ("output.rrd", scenario_rrd.filter(|_| args.rrd.is_none())),
        ("--summary", args.summary),
        ("--profiles", args.profiles),
        ("--fields", args.fields),
        ("--trajectory", args.trajectory),
        (
            "output.trajectory",
            scenario_trajectory.filter(|_| args.trajectory.is_none()),
        ),
        ("--checkpoint", args.checkpoint),
    ];
    for (field, path) in files {
        let Some(path) = path else { continue };
        crate::output::not_dash(field, path)?;
        not_special(field, path)?;
        crate::output::writable_directory(path)
            .map_err(|why| Error::input(field, format!("{}: {why}", path.display())))?;
    }
    distinct_files(&files, &args.inputs)?;
    let recording = (args.rrd.map(|_| "--rrd")).or(scenario_rrd.map(|_| "output.rrd"));
    if let Some(field) = recording {
        crate::scenario::checks::validate_recorded(s, field, None)?;
    }
    let trajectory = (args.trajectory.map(|_| "--trajectory"))
        .or(scenario_trajectory.map(|_| "output.trajectory"));
    if let Some(field) = trajectory {
        crate::scenario::checks::validate_recorded(s, field, s.output.trajectory_interval)?;
    }
    if args.profiles.is_some() && s.gravity.is_none() {
        return Err(Error::input(
            "--profiles",
            "this scene has no height profiles (they need gravity)",
        ));
    }
    if args.fields.is_some() && s.gravity.is_none() {
        return Err(Error::input(
            "--fields",
            "this scene has no 2D fields (they are over x and height: they need gravity)",
        ));
    }
    if !cfg!(feature = "record") && (args.rrd.is_some() || scenario_rrd.is_some()) {
        let field = if args.rrd.is_some() {
            "--rrd"
        } else {
            "output.rrd"
        };
        return Err(Error::input(
            field,
            "this build of vibrobed has no recording (build with the `record` feature)",
        ));
    }
    Ok(())
}

/// Refuses a path that exists and is not a regular file (a directory, a device, a fifo, a
/// socket): an output is written under another name and renamed over its path, which would
/// replace the special file rather than write to it.
fn not_special(field: &str, path: &Path) -> Result<()> {
    let Ok(meta) = std::fs::metadata(path) else {
        return Ok(());
    };
    if meta.is_dir() {
        return Err(Error::input(
            field,
            format!("{} is a directory: name a file", path.display()),
        ));
    }
    if !meta.is_file() {
        return Err(Error::input(
            field,
            format!("{} is not a regular file: name a file", path.display()),
        ));
    }
    Ok(())
}

/// `--summary PATH`, where `-` is stdout (as without the option).
fn summary_path(path: Option<PathBuf>) -> Option<PathBuf> {
    path.filter(|p| p != Path::new("-"))
}

/// Refuses an output named twice, or over an input (`files`: each output's option and path;
/// `inputs`: the files read), or over the name another output is written under until it is
/// complete: a later write would destroy the earlier. Paths are compared canonically (links and
/// `..` resolved; a file not yet there by its directory's canonical path). A resumed checkpoint
/// may be checkpointed into again, by `--checkpoint` only.
fn distinct_files(files: &[(&str, Option<&Path>)], inputs: &[(&'static str, &Path)]) -> Result<()> {
    let outputs: Vec<(&str, PathBuf)> = files
        .iter()
        .filter_map(|(field, path)| Some((*field, canonical(path.as_ref()?))))
        .collect();
    let temporaries: Vec<(&str, PathBuf)> = outputs
        .iter()
        .filter_map(|(field, path)| Some((*field, canonical(&temporary_name(field, path)?))))
        .collect();
    for (k, (field, path)) in outputs.iter().enumerate() {
        if let Some((other, _)) = outputs[..k].iter().find(|(_, p)| p == path) {
            return Err(Error::input(
                *field,
                format!(
                    "{} is also given to {other}: one would overwrite the other (name two files)",
                    path.display()
                ),
            ));
        }
        if let Some((other, _)) = temporaries.iter().find(|(_, p)| p == path) {
            return Err(Error::input(
                *field,
                format!(
                    "{} is the name {other} is written under until it is complete: one would \
                     overwrite the other (name another file)",
                    path.display()
                ),
            ));
        }
        let temporary = temporaries.iter().find(|(f, _)| f == field);
        for (input, read) in inputs {
            let resumed_into = *input == "CHECKPOINT" && *field == "--checkpoint";
            let read = canonical(read);
            let over = (!resumed_into && read == *path).then_some(path);
            let over = over.or(temporary.map(|(_, t)| t).filter(|t| **t == read));
            if let Some(over) = over {
                return Err(Error::input(
                    *field,
                    format!(
                        "{} is the {} this command reads: writing it would destroy it (name another file)",
                        over.display(),
                        if *input == "CHECKPOINT" { "checkpoint" } else { "scenario" }
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The name `field`'s output is written under until it is complete, where that name is fixed: a
/// recording's or trajectory's `FILE.partial`, a checkpoint's `FILE.tmp` (the summary, profiles
/// and fields go through a hidden name of the process's own).
fn temporary_name(field: &str, path: &Path) -> Option<PathBuf> {
    match field {
        "--checkpoint" => Some(crate::run::checkpoint::temporary_name(path)),
        "--rrd" | "output.rrd" | "--trajectory" | "output.trajectory" => {
            Some(crate::output::partial::partial_name(path))
        }
        _ => None,
    }
}

/// Most cores an accuracy report may cost on (`engine.threads`' own bound).
const MAX_CORES: usize = crate::scenario::checks::MAX_THREADS as usize;

/// Most seeds an accuracy ensemble may ask for (each seed is a full run of every variant).
pub const MAX_SEEDS: usize = 1000;

/// Prints the scenario's advisories (likely unintended settings) on stderr.
fn print_advisories(s: &Scenario) {
    for note in s.advisories() {
        eprintln!("vibrobed: note: {note}");
    }
}

/// Runs the command line; returns the process exit code.
pub fn main_with(cli: Cli) -> i32 {
    match execute(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("vibrobed: {e}");
            e.exit_code()
        }
    }
}

/// Dispatches to the subcommand; errors carry their exit code.
fn execute(cli: Cli) -> Result<i32> {
    // A path the processor cannot run, or a misspelt one, stops every command before it starts.
    use crate::platform::cpu::{Lanes, OVERRIDE};
    Lanes::from_environment().map_err(|message| Error::input(OVERRIDE, message))?;
    match cli.command {
        Command::Sweep { command } => command.execute(),
        Command::Check { scenario, sets } => check(&scenario, &sets),
        Command::Accuracy {
            scenario,
            out,
            sets,
            quick,
            seeds,
            effects,
            cores,
            quiet,
        } => {
            let options = crate::studies::accuracy::Options {
                out,
                quick,
                effects,
                seeds,
                verbose: !quiet,
                cores,
            };
            accuracy(&scenario, &sets, options)
        }
        Command::Run {
            scenario,
            rrd,
            summary,
            profiles,
            fields,
            trajectory,
            sets,
            checkpoint,
            checkpoint_every,
            quiet,
            progress_every,
        } => {
            let files = RunFiles {
                rrd,
                summary: summary_path(summary),
                profiles,
                fields,
                trajectory,
                checkpoint,
            };
            let shown = Shown::new(quiet, progress_every)?;
            run_scenario(&scenario, &sets, files, checkpoint_every, shown)
        }
        Command::Resume {
            checkpoint_file,
            sets,
            rrd,
            summary,
            profiles,
            fields,
            trajectory,
            checkpoint,
            checkpoint_every,
            quiet,
            progress_every,
        } => {
            let files = RunFiles {
                rrd,
                summary: summary_path(summary),
                profiles,
                fields,
                trajectory,
                checkpoint,
            };
            let shown = Shown::new(quiet, progress_every)?;
            resume(&checkpoint_file, &sets, files, checkpoint_every, shown)
        }
    }
}

/// `vibrobed check`: loads the scenario and also builds its scene and engine (placement, grid,
/// mask, neighbour lists, first predictions) without running it, so that whatever would stop
/// a run at its start stops the check too.
fn check(scenario: &Path, sets: &[String]) -> Result<i32> {
    let s = Scenario::load(scenario, sets)?;
    crate::run::check(&s)?;
    let args = OutputArgs {
        inputs: vec![("SCENARIO", scenario)],
        ..OutputArgs::default()
    };
    output_paths(&s, &args)?;
    print_advisories(&s);
    eprintln!("{}: ok ({} disks)", scenario.display(), s.disk_count());
    Ok(0)
}

/// `vibrobed accuracy`: checks `--out` and `--seeds` before the (long) ensembles start, then
/// prints the table and names the files written.
fn accuracy(
    scenario: &Path,
    sets: &[String],
    options: crate::studies::accuracy::Options,
) -> Result<i32> {
    let s = Scenario::load(scenario, sets)?;
    let out = &options.out;
    crate::output::not_dash("--out", out)?;
    if out.exists() && !out.is_dir() {
        return Err(Error::input(
            "--out",
            format!("{} is a file: name a directory", out.display()),
        ));
    }
    if let Some(k) = options.seeds.filter(|k| !(1..=MAX_SEEDS).contains(k)) {
        return Err(Error::input(
            "--seeds",
            format!("must lie in [1, {MAX_SEEDS}] (got {k})"),
        ));
    }
    if let Some(k) = options.cores.filter(|&k| !(1..=MAX_CORES).contains(&k)) {
        return Err(Error::input(
            "--cores",
            format!("must lie in [1, {MAX_CORES}] (got {k})"),
        ));
    }
    // SIGINT, SIGTERM and SIGHUP stop the run in hand; the report, unfinished, is not written.
    signals::install();
    let report = match crate::studies::accuracy::report(&s, &options) {
        Err(_) if signals::stop_flag().load(std::sync::atomic::Ordering::Relaxed) => {
            eprintln!("vibrobed: accuracy: interrupted; no report written");
            return Ok(signals::exit_code());
        }
        made => made?,
    };
    print!("{}", report.table());
    eprintln!(
        "wrote {}/accuracy.csv, answers.csv, accuracy.txt, accuracy.svg{}",
        out.display(),
        if options.effects { ", effects.csv" } else { "" }
    );
    Ok(0)
}

/// What a `run` or `resume` shows while it runs: nothing (`--quiet`), or its progress with a line
/// every `--progress-every` seconds off a terminal.
struct Shown {
    quiet: bool,
    every: Option<f64>,
}

impl Shown {
    /// Refuses a `--progress-every` out of its bounds.
    fn new(quiet: bool, every: Option<f64>) -> Result<Shown> {
        crate::scenario::intervals::progress_every(every)?;
        Ok(Shown { quiet, every })
    }
}

/// The files a `run` or `resume` command line asks for.
struct RunFiles {
    rrd: Option<PathBuf>,
    summary: Option<PathBuf>,
    profiles: Option<PathBuf>,
    fields: Option<PathBuf>,
    trajectory: Option<PathBuf>,
    checkpoint: Option<PathBuf>,
}

impl RunFiles {
    /// The paths, borrowed for [`output_paths`], with the files the command reads.
    fn as_output_args<'a>(&'a self, inputs: Vec<(&'static str, &'a Path)>) -> OutputArgs<'a> {
        OutputArgs {
            inputs,
            rrd: self.rrd.as_deref(),
            summary: self.summary.as_deref(),
            profiles: self.profiles.as_deref(),
            fields: self.fields.as_deref(),
            trajectory: self.trajectory.as_deref(),
            checkpoint: self.checkpoint.as_deref(),
        }
    }
}

/// `vibrobed run`: loads the scenario, refuses outputs it could not write, and runs it. With
/// `--checkpoint` the scenario's text goes into the checkpoint, so that `resume` needs nothing
/// but that file.
fn run_scenario(
    scenario: &Path,
    sets: &[String],
    mut files: RunFiles,
    checkpoint_every: Option<f64>,
    shown: Shown,
) -> Result<i32> {
    let s = Scenario::load(scenario, sets)?;
    output_paths(&s, &files.as_output_args(vec![("SCENARIO", scenario)]))?;
    print_advisories(&s);
    let checkpoint = match files.checkpoint.take() {
        Some(path) => Some(CheckpointPlan {
            path,
            every: checkpoint_every,
            scenario: Scenario::read_text(scenario)?,
            source: scenario.to_path_buf(),
            sets: sets.to_vec(),
        }),
        None => None,
    };
    simulate(&s, files, checkpoint, None, shown)
}

/// `vibrobed resume`: rebuilds the scene from the checkpoint (its scenario text and overrides,
/// then this command line's `--set`) and continues it, checkpointing on (by default into the
/// same file, at the saved run's interval).
fn resume(
    checkpoint_file: &Path,
    sets: &[String],
    files: RunFiles,
    checkpoint_every: Option<f64>,
    shown: Shown,
) -> Result<i32> {
    let (s, plan, ck) = resumed(
        checkpoint_file,
        sets,
        files.rrd.as_deref(),
        files.trajectory.as_deref(),
        files.checkpoint.clone(),
        checkpoint_every,
    )?;
    let mut args = files.as_output_args(vec![("CHECKPOINT", checkpoint_file)]);
    args.checkpoint = Some(&plan.path);
    output_paths(&s, &args)?;
    if !shown.quiet {
        eprintln!(
            "resuming {} (scenario {}) at t = {}",
            checkpoint_file.display(),
            ck.source.display(),
            ck.driver.time()
        );
    }
    simulate(&s, files, Some(plan), Some(ck), shown)
}

/// What a resume continues: the checkpoint read from `checkpoint_file`, its scene with the
/// resume's overrides (`run.duration` and `run.max_events` only) after the run's own, and where
/// and how often to go on checkpointing (by default into the same file at the saved interval).
/// Refuses a recording `rrd` that holds an earlier part of the run, and a new `run.duration`
/// where a default of the scene follows the duration (frames count when the resume records,
/// to `rrd` or the scene's own, or writes a trajectory, to `trajectory` or the scene's own,
/// without `output.trajectory_interval`).
pub fn resumed(
    checkpoint_file: &Path,
    sets: &[String],
    rrd: Option<&Path>,
    trajectory: Option<&Path>,
    checkpoint: Option<PathBuf>,
    checkpoint_every: Option<f64>,
) -> Result<(Scenario, CheckpointPlan, Box<Checkpoint>)> {
    check_resume_sets(sets)?;
    let ck = Checkpoint::read(checkpoint_file)?;
    if let Some(path) = rrd {
        refuse_earlier_recording(&ck, path)?;
    }
    let all_sets: Vec<String> = ck.sets.iter().chain(sets).cloned().collect();
    let s = Scenario::from_json_with_overrides(&ck.scenario, &all_sets)?;
    let saved = Scenario::from_json_with_overrides(&ck.scenario, &ck.sets)?;
    let trajectory = trajectory.is_some() || s.output.trajectory.is_some();
    let frames = rrd.is_some()
        || s.output.rrd.is_some()
        || (trajectory && s.output.trajectory_interval.is_none());
    check_resume_duration(&saved, &s, frames)?;
    let plan = CheckpointPlan {
        path: checkpoint.unwrap_or_else(|| checkpoint_file.to_path_buf()),
        every: checkpoint_every.or(ck.every),
        scenario: ck.scenario.clone(),
        source: ck.source.clone(),
        sets: all_sets,
    };
    Ok((s, plan, Box::new(ck)))
}

/// Refuses to record the resumed part into a file that holds an earlier part of the run:
/// it would overwrite what the earlier part recorded.
fn refuse_earlier_recording(ck: &Checkpoint, path: &Path) -> Result<()> {
    if ck.recordings.iter().any(|r| same_file(r, path)) {
        return Err(Error::input(
            "--rrd",
            format!(
                "{} holds an earlier part of this run: record the resumed part to a \
                 new file (the viewer shows both as one recording)",
                path.display()
            ),
        ));
    }
    Ok(())
}

/// Runs (or resumes) the scene, stopping cleanly on SIGINT/SIGTERM/SIGHUP, and writes what
/// the run produced; returns the exit code of its ending.
fn simulate(
    s: &Scenario,
    files: RunFiles,
    checkpoint: Option<CheckpointPlan>,
    resume: Option<Box<Checkpoint>>,
    shown: Shown,
) -> Result<i32> {
    signals::install();
    signals::building();
    let written_after = [("profiles", &files.profiles), ("summary", &files.summary)]
        .into_iter()
        .filter_map(|(output, path)| Some((output, path.clone()?)))
        .collect();
    let result = run(
        s,
        RunOptions {
            rrd: files.rrd,
            trajectory: files.trajectory,
            sink: None,
            interrupt: Some(signals::stop_flag()),
            progress: !shown.quiet,
            progress_every: shown.every,
            progress_label: None,
            checkpoint,
            resume,
            written_after,
            fields: false,
            fields_file: files.fields,
        },
    );
    signals::built();
    let result = result?;
    let written = Written {
        profiles: files.profiles.as_deref(),
        summary: files.summary.as_deref(),
    };
    write_results(&result, written)
}

/// The files written once a run has ended.
struct Written<'a> {
    profiles: Option<&'a Path>,
    summary: Option<&'a Path>,
}

/// `true` when `a` and `b` name the same file (compared canonically when both exist).
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

/// Writes a run's profiles and summary (the fields are an output of the run), each whatever
/// becomes of the other; a summary that
/// cannot be written goes to stdout instead (a batch job's log keeps it). Returns the exit code:
/// 1 when one of them could not be written, else that of the run's ending ([`ending_code`]).
fn write_results(result: &Summary, files: Written) -> Result<i32> {
    let Written { profiles, summary } = files;
    let mut lost = false;
    if let Some(path) = profiles {
        match &result.profiles {
            Some(p) => {
                if let Err(e) = crate::output::write_output("profiles", path, &p.to_csv()) {
                    eprintln!("vibrobed: {e}");
                    lost = true;
                }
            }
            None => not_measured("profiles", path, result),
        }
    }
    let json = result.to_json();
    match summary.map(|path| crate::output::write_output("summary", path, &json)) {
        None => print!("{json}"),
        Some(Ok(())) => {}
        Some(Err(e)) => {
            eprintln!("vibrobed: {e}; the summary follows on stdout");
            print!("{json}");
            lost = true;
        }
    }
    Ok(if lost { 1 } else { ending_code(result) })
}

/// The exit code of a run's ending ([`Ending::exit_code`]: its own for each ending but
/// completed), or [`EXIT_OUTPUT_FAILED`] when an output failed during a run that completed: a
/// run that did not complete never exits 0.
fn ending_code(result: &Summary) -> i32 {
    match result.ending {
        Ending::Completed if !result.output_failures.is_empty() => EXIT_OUTPUT_FAILED,
        ending => ending.exit_code(),
    }
}

/// Says that `output` (the profiles), asked for at `path`, was not written: the run ended
/// before it measured any (no sample after the warm-up), and zeros would read as a measurement.
fn not_measured(output: &str, path: &Path, result: &Summary) {
    eprintln!(
        "vibrobed: warning: no {output} measured (the run ended, {}, at t = {} before any \
         sample after its warm-up): {output} {} not written",
        result.ending.words(),
        result.sim_time,
        path.display()
    );
}
