//! `vibrobed accuracy SCENARIO`: what accuracy costs in time.
//!
//! The exact event-driven engine runs the scene on a few seeds as the reference; then every
//! variant runs on the same scene and seeds — the approximate schemes with a sweep of their step
//! (time-step dt, space-time D), the cheaper floor models, the cures of inelastic collapse (TC,
//! speed cutoff) and frame recording. Each variant is reported with its cost (wall-clock seconds
//! per unit of simulated time, and that relative to the reference) and its error against the
//! reference in what users look at: the density and temperature profiles, the centre-of-mass
//! height, the granular temperature, the energy input rate and the pair collision rate; plus
//! overlaps and missed collisions for the approximate schemes.
//!
//! Cost is what a user pays on the machine the report runs on, with K cores (`--cores`, default
//! all): the approximate schemes run on K threads; the exact engine runs on one core, alone and
//! K seeds at once (the ensemble's throughput). Each row gives wall seconds and core seconds
//! (wall × cores) per unit of simulated time, and the report answers, per observable and error
//! level, which is the cheapest way there ([`cheapest`]).
//!
//! Errors compare seed-averaged observables (the same seeds for every variant). The reference's
//! own seed-to-seed spread is reported as the error one would expect between two independent
//! ensembles of the same size (`√(2/K)·σ` of K seeds): errors below it are noise. The exact engine
//! re-run on the same seeds gives zero error (it is deterministic).
//!
//! `--effects` adds a table of what each effect of a scene costs (gravity, floor kind, walls vs
//! periodic, dissipation model, polydispersity, friction, recording): the slowdown of a scene with
//! the effect against the same scene without it, on the exact engine, measured per collision and
//! per unit of simulated time; for friction, added to the scene itself, also what it changes in
//! the observables.
//!
//! The parts: `ensemble` (seed-averaged observables and their errors), `variants` (what is run
//! against the reference), [`cheapest`] (the answers), `effects` (`--effects`), `table` (the
//! text table and the CSV files) and [`plot`] (`accuracy.svg`).

pub mod cheapest;
mod effects;
mod ensemble;
pub mod plot;
mod table;
mod variants;

use crate::engine::Scene;
use crate::error::{Error, Result};
use crate::output::summary::{Ending, Summary};
use crate::platform::memory::{threads_fit, threads_refused, RUN_THREAD_STACK};
use crate::run::{run, RunOptions};
use crate::scenario::{overrides, Scenario, Scheme};
use crate::schemes::SchemeStats;
use ensemble::{Ensemble, Measured};
use serde::Serialize;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::Instant;
use variants::Variant;

/// How to run the report.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Where the CSV files, the plot and the table go.
    pub out: PathBuf,
    /// Shorter runs, fewer seeds and sweep points (for CI).
    pub quick: bool,
    /// Also measure what each effect costs.
    pub effects: bool,
    /// Number of seeds (default 3, or 2 with `quick`).
    pub seeds: Option<usize>,
    /// Print one line per run on stderr.
    pub verbose: bool,
    /// Cores K the report may use (default: every core this process may use).
    pub cores: Option<usize>,
}

/// Relative errors of the observables against the reference (absent where the scene has no such
/// observable, or the reference value is zero).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Errors {
    /// L2 distance of the density profile, relative to the reference profile's norm.
    pub density_profile: Option<f64>,
    /// L2 distance of the temperature profile weighted by the reference density,
    /// `√(Σ ρ (T − T_ref)²) / √(Σ ρ T_ref²)` (bins with few disks weigh little).
    pub temperature_profile: Option<f64>,
    /// Centre-of-mass height.
    pub com_height: Option<f64>,
    /// Granular temperature (mean of the two axes, averaged after warm-up).
    pub temperature: Option<f64>,
    /// Energy injected by the floor per unit time.
    pub energy_input: Option<f64>,
    /// Pair collisions per unit time.
    pub collision_rate: Option<f64>,
}

impl Errors {
    /// The observables' names and values, in table order.
    pub fn entries(&self) -> [(&'static str, Option<f64>); 6] {
        [
            ("density profile", self.density_profile),
            ("temperature profile", self.temperature_profile),
            ("com height", self.com_height),
            ("temperature", self.temperature),
            ("energy input rate", self.energy_input),
            ("collision rate", self.collision_rate),
        ]
    }

    /// The largest error.
    pub fn worst(&self) -> Option<f64> {
        self.entries()
            .iter()
            .filter_map(|e| e.1)
            .fold(None, |m, v| Some(m.map_or(v, |m: f64| m.max(v))))
    }
}

/// One line of the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    /// `reference`, `time-step`, `space-time`, `floor`, `dissipation`, `recording`.
    pub family: String,
    /// What was changed, in words.
    pub variant: String,
    /// The `--set` overrides applied to the scenario.
    pub settings: String,
    /// Seeds run.
    pub seeds: usize,
    /// Wall-clock seconds per unit of simulated time (mean over seeds; for runs all at once,
    /// of the ensemble).
    pub wall_per_time: f64,
    /// `wall_per_time` relative to the reference's.
    pub relative_cost: f64,
    /// Cores the variant held: its threads, or the runs it ran at once.
    pub cores: usize,
    /// Core seconds (wall × cores) per unit of simulated time.
    pub core_per_time: f64,
    /// Errors against the reference.
    pub errors: Errors,
    /// Largest pair overlap seen, in units of the smallest diameter.
    pub max_overlap: f64,
    /// Approximate schemes: collisions resolved with an overlap, per pair collision.
    pub overlapped_fraction: Option<f64>,
    /// Approximate schemes: overlaps deeper than 10 % of the contact distance, per pair collision.
    pub deep_fraction: Option<f64>,
    /// Approximate schemes: missed collisions per pair collision.
    pub missed_fraction: Option<f64>,
    /// Remarks (skipped, failed, …).
    pub note: String,
}

/// One line of the effects table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EffectRow {
    /// The effect.
    pub effect: String,
    /// The scene without it.
    pub without: String,
    /// What was added.
    pub with: String,
    /// Wall seconds per collision without / with the effect.
    pub per_collision: [f64; 2],
    /// Wall seconds per unit simulated time without / with.
    pub per_time: [f64; 2],
    /// Slowdown per collision (with / without).
    pub slowdown_per_collision: f64,
    /// Slowdown per unit of simulated time (with / without).
    pub slowdown_per_time: f64,
    /// What the effect changes in the observables (the friction row): the profiles' relative
    /// L2 distances, the scalars' relative changes with their sign, with against without.
    pub changes: Option<Errors>,
    /// Remarks.
    pub note: String,
}

/// The whole report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    /// Scenario name.
    pub scenario: String,
    /// Disks.
    pub particles: usize,
    /// Simulated time of each run.
    pub duration: f64,
    /// Seeds of the ensemble.
    pub seeds: Vec<u64>,
    /// Cores K the report used: the approximate schemes' threads, the exact runs at once.
    pub cores: usize,
    /// The machine's processor (`model name` of /proc/cpuinfo, where there is one).
    pub machine: String,
    /// The cheapest way to each observable within each error level.
    pub answers: Vec<cheapest::Answer>,
    /// The accuracy–cost rows (the first ones: the reference, its re-run and its seed spread).
    pub rows: Vec<Row>,
    /// The effects table (with `--effects`).
    pub effects: Vec<EffectRow>,
    /// Wall-clock seconds the whole report took.
    pub wall_seconds: f64,
}

/// Runs the accuracy report for `scenario` and writes its files into `opts.out`. A report that
/// fails writes nothing: the folder it made is removed.
pub fn report(scenario: &Scenario, opts: &Options) -> Result<Report> {
    let created = !opts.out.exists();
    let made = measure_and_write(scenario, opts);
    if made.is_err() && created {
        let _ = std::fs::remove_dir_all(&opts.out);
    }
    made
}

/// [`report`]'s work: the ensembles, the rows, the files.
fn measure_and_write(scenario: &Scenario, opts: &Options) -> Result<Report> {
    let clock = Instant::now();
    let reference = reference_scenario(scenario, opts.quick);
    let mut runner = Runner::new(&reference, opts);
    let (scene, disks) = Scene::build(&reference)?;
    // Every variant's engine accepts the scene before anything is written.
    crate::run::check(scenario)?;
    std::fs::create_dir_all(&opts.out)
        .map_err(|e| Error::Io(format!("cannot create {}: {e}", opts.out.display())))?;
    say(
        opts,
        format!(
            "accuracy: {} ({} disks, duration {}, seeds {:?})",
            reference.name,
            reference.disk_count(),
            reference.run.duration,
            runner.seeds
        ),
    );
    let cores = opts
        .cores
        .unwrap_or_else(crate::schemes::cores::available)
        .max(1);
    // Before any run: the seeds side by side (a thread each) and the schemes' threads.
    for (stack, what) in [
        (RUN_THREAD_STACK, "runs at once, a thread each"),
        (
            crate::schemes::cores::POOL_STACK,
            "threads for the approximate schemes",
        ),
    ] {
        threads_fit(cores, stack)
            .map_err(|limit| Error::input("--cores", threads_refused(cores, what, limit)))?;
    }
    let exact = runner.ensemble(&Variant::new("reference", "exact event-driven", &[]))?;
    runner.cap_events(&exact);
    let (a_min, _) = disks.radius_range();
    let scale = Scale {
        ref_cost: exact.wall_per_time(),
        diameter: 2.0 * a_min,
    };
    let mut rows = scale.reference_rows(&exact);
    if cores > 1 {
        let v = Variant::new("reference", format!("exact, {cores} runs at once"), &[]);
        let at_once = runner.at_once(&v, cores)?;
        let note = "the throughput of seeds run side by side".to_string();
        let cost = at_once.wall_per_time_at_once();
        rows.push(scale.row_costing(
            &v,
            &at_once,
            (cost, cores),
            exact.errors_against(&exact),
            note,
        ));
    }
    let basis = variants::Basis {
        reference: &reference,
        scene: &scene,
        disks: &disks,
        exact: &exact,
        quick: opts.quick,
        cores,
        strips: scenario.engine.strips,
    };
    for v in &variants::all(&basis) {
        rows.push(variant_row(&runner, &scale, &exact, v));
    }
    let effects = if opts.effects {
        effects::table(&reference, opts)?
    } else {
        Vec::new()
    };
    let answers = cheapest::answers(&rows);
    let report = Report {
        scenario: reference.name.clone(),
        particles: reference.disk_count(),
        duration: reference.run.duration,
        seeds: runner.seeds,
        cores,
        machine: machine(),
        answers,
        rows,
        effects,
        wall_seconds: clock.elapsed().as_secs_f64(),
    };
    // A signal stopped the run in hand and every run after it: the rows are not measurements.
    if crate::platform::signals::stop_flag().load(std::sync::atomic::Ordering::Relaxed) {
        return Err(Error::Runtime("interrupted: no report written".into()));
    }
    write_outputs(&report, &opts.out)?;
    Ok(report)
}

/// The reference: the scene on the exact engine, without recording (a quarter of the run and
/// warm-up with `quick`).
fn reference_scenario(scenario: &Scenario, quick: bool) -> Scenario {
    let mut reference = scenario.clone();
    reference.engine = crate::scenario::Engine {
        scheme: Scheme::EventDriven,
        check_invariants: false,
        dt: None,
        verlet_skin: None,
        sync_distance: None,
        cell_size: None,
        strips: None,
        threads: None,
        ..scenario.engine.clone()
    };
    reference.output.rrd = None;
    if quick {
        reference.run.duration *= 0.25;
        reference.run.warmup *= 0.25;
    }
    reference
}

/// Runs a variant of the reference scene on every seed of the ensemble.
struct Runner<'a> {
    /// The reference scenario as JSON, to which each variant's overrides are applied.
    base: Value,
    /// The seeds of the ensemble: the scenario's seed and the next ones.
    seeds: Vec<u64>,
    /// Whether the scene has a floor (and so an energy input).
    has_floor: bool,
    /// The reference's own limit on events, if any.
    max_events: Option<u64>,
    /// The limit on events set after the reference has run (see [`Runner::cap_events`]).
    event_cap: Option<u64>,
    opts: &'a Options,
}

impl<'a> Runner<'a> {
    /// A runner of `opts.seeds` seeds (3 by default, 2 with `quick`).
    fn new(reference: &Scenario, opts: &'a Options) -> Runner<'a> {
        let k = opts.seeds.unwrap_or(if opts.quick { 2 } else { 3 }).max(1);
        Runner {
            base: serde_json::to_value(reference).expect("scenario serialises"),
            seeds: (0..k as u64)
                .map(|i| reference.seed.wrapping_add(i))
                .collect(),
            has_floor: reference.floor.is_some(),
            max_events: reference.run.max_events,
            event_cap: None,
            opts,
        }
    }

    /// A variant may get stuck where the reference does not (e.g. a floor model that never lets
    /// a disk come to rest): it is stopped after five times the reference's events (at least
    /// 5000), unless the scenario sets its own limit.
    fn cap_events(&mut self, exact: &Ensemble) {
        let most = exact.runs.iter().map(|m| m.events).max().unwrap_or(0);
        self.event_cap = Some(5 * most.max(1000));
    }

    /// The variant's runs, one per seed; the first that fails or stops early is an error.
    fn ensemble(&self, v: &Variant) -> Result<Ensemble> {
        let mut ens = Ensemble::default();
        for &seed in &self.seeds {
            ens.runs.push(self.measure(v, seed)?);
        }
        Ok(ens)
    }

    /// The variant on `k` seeds (the scenario's and the next ones) run all at once, each on a
    /// thread of its own.
    fn at_once(&self, v: &Variant, k: usize) -> Result<Ensemble> {
        let runs: Result<Vec<Result<Measured>>> = std::thread::scope(|scope| {
            let mut handles = Vec::with_capacity(k);
            for i in 0..k as u64 {
                let seed = self.seeds[0].wrapping_add(i);
                let started = std::thread::Builder::new()
                    .stack_size(RUN_THREAD_STACK)
                    .spawn_scoped(scope, move || self.measure(v, seed));
                handles.push(started.map_err(|e| {
                    Error::input(
                        "--cores",
                        format!("cannot start {k} runs at once, a thread each: {e} (give fewer)"),
                    )
                })?);
            }
            Ok(handles
                .into_iter()
                .map(|h| h.join().expect("a run does not panic"))
                .collect())
        });
        Ok(Ensemble {
            runs: runs?.into_iter().collect::<Result<_>>()?,
        })
    }

    /// One run of the variant: its overrides, the seed and the event cap applied to the base;
    /// a recording goes to a scratch file in the output folder, removed afterwards.
    fn measure(&self, v: &Variant, seed: u64) -> Result<Measured> {
        let mut sets = v.sets.clone();
        sets.push(format!("seed={seed}"));
        if let (Some(cap), None) = (self.event_cap, self.max_events) {
            sets.push(format!("run.max_events={cap}"));
        }
        let s = with_sets(&self.base, &sets)?;
        let rrd = v
            .record
            .then(|| self.opts.out.join("accuracy-recording.rrd"));
        let summary = run(
            &s,
            RunOptions {
                rrd: rrd.clone(),
                interrupt: Some(crate::platform::signals::stop_flag()),
                ..Default::default()
            },
        )?;
        if let Some(path) = rrd {
            let _ = std::fs::remove_file(path);
        }
        if summary.ending != Ending::Completed {
            return Err(self.stopped(seed, &summary));
        }
        say(
            self.opts,
            format!(
                "  {:<12} {:<36} seed {seed}: {:.3} s",
                v.family, v.label, summary.wall_seconds
            ),
        );
        Ok(Measured::of(&summary, self.has_floor))
    }

    /// The error of a run that did not complete: where and why it stopped.
    fn stopped(&self, seed: u64, summary: &Summary) -> Error {
        Error::Runtime(format!(
            "seed {seed} stopped at t = {:.4} ({:?}, after {} events{})",
            summary.sim_time,
            summary.ending,
            summary.events.popped(),
            if self.event_cap.is_some() {
                ": the cap is 5× the reference's"
            } else {
                ""
            }
        ))
    }
}

/// What the rows are measured in: cost relative to the reference's, overlaps relative to the
/// smallest diameter.
struct Scale {
    /// The reference's wall seconds per unit of simulated time.
    ref_cost: f64,
    diameter: f64,
}

impl Scale {
    /// The first rows: the reference against itself (zero error) and its seed spread (the
    /// error expected between two independent ensembles: errors below it are noise).
    fn reference_rows(&self, exact: &Ensemble) -> Vec<Row> {
        let k = exact.runs.len();
        vec![
            self.row(
                &Variant::new("reference", "exact event-driven", &[]),
                exact,
                exact.errors_against(exact),
                "the reference".into(),
            ),
            self.row(
                &Variant::new("reference", format!("seed spread (√(2/{k})·σ)"), &[]),
                exact,
                exact.spread(),
                "errors below these are noise".into(),
            ),
        ]
    }

    /// The row of a variant's ensemble with the given errors, run one seed after the other.
    fn row(&self, v: &Variant, ens: &Ensemble, errors: Errors, note: String) -> Row {
        let cost = (ens.wall_per_time(), ens.cores());
        self.row_costing(v, ens, cost, errors, note)
    }

    /// The row of a variant's ensemble that cost `wall_per_time` on `cores` cores.
    fn row_costing(
        &self,
        v: &Variant,
        ens: &Ensemble,
        (wall_per_time, cores): (f64, usize),
        errors: Errors,
        note: String,
    ) -> Row {
        Row {
            family: v.family.into(),
            variant: v.label.clone(),
            settings: v.sets.join(" "),
            seeds: ens.runs.len(),
            wall_per_time,
            relative_cost: wall_per_time / self.ref_cost,
            cores,
            core_per_time: wall_per_time * cores as f64,
            errors,
            max_overlap: ens.runs.iter().map(|m| m.max_overlap).fold(0.0, f64::max) / self.diameter,
            overlapped_fraction: per_pair(ens, |s| s.overlapped_collisions as f64),
            deep_fraction: per_pair(ens, |s| s.deep_overlaps as f64),
            missed_fraction: per_pair(ens, |s| s.missed as f64),
            note,
        }
    }
}

/// An approximate scheme's count per pair collision, over all seeds (absent for exact engines).
fn per_pair(ens: &Ensemble, f: impl Fn(&SchemeStats) -> f64) -> Option<f64> {
    let pair: f64 = ens.runs.iter().map(|m| m.pair).sum::<f64>().max(1.0);
    let all: Option<Vec<f64>> = ens.runs.iter().map(|m| m.stats.as_ref().map(&f)).collect();
    all.map(|v| v.iter().sum::<f64>() / pair)
}

/// A variant's row: its errors against the exact engine's, or why it has none (skipped in a
/// build without recording, or failed).
fn variant_row(runner: &Runner, scale: &Scale, exact: &Ensemble, v: &Variant) -> Row {
    if v.record && !cfg!(feature = "record") {
        let note = "skipped: this build has no `record` feature";
        return Row::unmeasured(v, String::new(), note.into());
    }
    match runner.ensemble(v) {
        Ok(ens) => {
            let errors = ens.errors_against(exact);
            scale.row(v, &ens, errors, String::new())
        }
        Err(e) => Row::unmeasured(v, v.sets.join(" "), format!("failed: {e}")),
    }
}

impl Row {
    /// The row of a variant that was not measured: no cost, no errors, a note saying why.
    fn unmeasured(v: &Variant, settings: String, note: String) -> Row {
        Row {
            family: v.family.into(),
            variant: v.label.clone(),
            settings,
            seeds: 0,
            wall_per_time: f64::NAN,
            relative_cost: f64::NAN,
            cores: 0,
            core_per_time: f64::NAN,
            errors: Errors::default(),
            max_overlap: f64::NAN,
            overlapped_fraction: None,
            deep_fraction: None,
            missed_fraction: None,
            note,
        }
    }
}

/// The processor's name (`model name` in /proc/cpuinfo), or `unknown processor`.
fn machine() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, name)| name.trim().to_string())
        })
        .unwrap_or_else(|| "unknown processor".into())
}

/// Writes `accuracy.csv`, `answers.csv`, `accuracy.txt`, `effects.csv` (with effects) and
/// `accuracy.svg`.
fn write_outputs(report: &Report, out: &Path) -> Result<()> {
    write_file(&out.join("accuracy.csv"), &report.csv())?;
    write_file(&out.join("answers.csv"), &report.answers_csv())?;
    write_file(&out.join("accuracy.txt"), &report.table())?;
    if !report.effects.is_empty() {
        write_file(&out.join("effects.csv"), &report.effects_csv())?;
    }
    plot::draw(report, &out.join("accuracy.svg"))
}

/// Prints a progress line on stderr, unless quiet.
fn say(opts: &Options, line: String) {
    if opts.verbose {
        eprintln!("{line}");
    }
}

/// Applies `--set` overrides to a scenario.
fn with_sets(base: &Value, sets: &[String]) -> Result<Scenario> {
    let mut v = base.clone();
    for s in sets {
        overrides::apply(&mut v, s)?;
    }
    let s = Scenario::from_value(v)?;
    s.validate()?;
    Ok(s)
}

/// A number in a label: up to four decimals without trailing zeros, or three significant
/// digits in exponent form when very small or large.
fn fmt_g(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if (1e-3..1e4).contains(&v.abs()) {
        format!("{:.4}", v)
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{v:.3e}")
    }
}

/// Writes a file, saying which one on error.
fn write_file(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text)
        .map_err(|e| Error::Io(format!("cannot write {}: {e}", path.display())))
}
