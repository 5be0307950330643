//! The command line: `vibrobed run SCENARIO.json [--rrd OUT.rrd] [--summary OUT.json]
//! [--profiles OUT.csv] [--trajectory OUT.xyz] [--set KEY=VALUE]...`, `vibrobed check SCENARIO.json` and
//! `vibrobed accuracy SCENARIO.json [--out DIR] [--set KEY=VALUE]... [--quick] [--effects]`.
//!
//! Exit codes: 0 success, 2 bad input or arguments (the message names the field), 1 runtime
//! failure, 130 interrupted by Ctrl-C (the summary so far is still written, marked
//! `"ending": "interrupted"`, and the recording is closed properly).

use crate::error::{Error, Result};
use crate::run::{run, RunOptions};
use crate::scenario::Scenario;
use crate::signals;
use crate::summary::Ending;
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
        /// Write the summary JSON here instead of stdout.
        #[arg(long)]
        summary: Option<PathBuf>,
        /// Write the height profiles as CSV here (gravity scenes).
        #[arg(long)]
        profiles: Option<PathBuf>,
        /// Write a trajectory in extended XYZ here (OVITO, ASE), a frame every
        /// output.trajectory_interval (default: the frame interval).
        #[arg(long)]
        trajectory: Option<PathBuf>,
        /// Override a scenario field by its dotted path, e.g. particles.count=10000.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
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
        /// No progress lines on stderr.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Parameter sweeps and seed ensembles: plan, run locally or on Slurm, collect.
    Sweep {
        /// What to do with the sweep.
        #[command(subcommand)]
        command: crate::sweep::command::SweepCommand,
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

/// Writes `text` to `path` atomically (a temporary file renamed into place).
fn write_file(path: &Path, text: &str) -> Result<()> {
    let tmp = path.with_extension("partial");
    std::fs::write(&tmp, text)
        .and_then(|_| std::fs::rename(&tmp, path))
        .map_err(|e| Error::Io(format!("cannot write {}: {e}", path.display())))
}

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

fn execute(cli: Cli) -> Result<i32> {
    match cli.command {
        Command::Sweep { command } => command.execute(),
        Command::Check { scenario, sets } => {
            let s = Scenario::load(&scenario, &sets)?;
            // Also resolve the scene (placement, grid, mask) without running it.
            crate::simulation::Scene::build(&s)?;
            print_advisories(&s);
            eprintln!("{}: ok ({} disks)", scenario.display(), s.disk_count());
            Ok(0)
        }
        Command::Accuracy {
            scenario,
            out,
            sets,
            quick,
            seeds,
            effects,
            quiet,
        } => {
            let s = Scenario::load(&scenario, &sets)?;
            if seeds == Some(0) {
                return Err(Error::input("--seeds", "must be at least 1"));
            }
            let report = crate::accuracy::report(
                &s,
                &crate::accuracy::Options {
                    out: out.clone(),
                    quick,
                    effects,
                    seeds,
                    verbose: !quiet,
                },
            )?;
            print!("{}", report.table());
            eprintln!(
                "wrote {}/accuracy.csv, accuracy.txt, accuracy.svg{}",
                out.display(),
                if effects { ", effects.csv" } else { "" }
            );
            Ok(0)
        }
        Command::Run {
            scenario,
            rrd,
            summary,
            profiles,
            trajectory,
            sets,
            quiet,
        } => {
            let s = Scenario::load(&scenario, &sets)?;
            print_advisories(&s);
            signals::install();
            let result = run(
                &s,
                RunOptions {
                    rrd,
                    trajectory,
                    sink: None,
                    interrupt: Some(signals::stop_flag()),
                    progress: !quiet,
                },
            )?;
            if let Some(path) = &profiles {
                match &result.profiles {
                    Some(p) => write_file(path, &p.to_csv())?,
                    None => {
                        return Err(Error::input(
                            "--profiles",
                            "this scene has no height profiles (they need gravity)",
                        ))
                    }
                }
            }
            let json = result.to_json();
            match &summary {
                Some(path) => write_file(path, &json)?,
                None => print!("{json}"),
            }
            Ok(match result.ending {
                Ending::Completed | Ending::EventLimit => 0,
                Ending::Interrupted => signals::exit_code(),
            })
        }
    }
}
