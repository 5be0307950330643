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
//! Errors compare seed-averaged observables (the same seeds for every variant). The reference's
//! own seed-to-seed spread is reported as the error one would expect between two independent
//! ensembles of the same size (`√(2/K)·σ` of K seeds): errors below it are noise. The exact engine
//! re-run on the same seeds gives zero error (it is deterministic).
//!
//! `--effects` adds a table of what each effect of a scene costs (gravity, floor kind, walls vs
//! periodic, dissipation model, polydispersity, recording): the slowdown of a scene with the effect
//! against the same scene without it, on the exact engine, measured per collision and per unit of
//! simulated time.

use crate::engine::Scene;
pub mod plot;

use crate::error::{Error, Result};
use crate::output::summary::Summary;
use crate::run::{run, RunOptions};
use crate::scenario::{overrides, Scenario, Scheme};
use crate::schemes::{time_step, SchemeStats};
use serde::Serialize;
use serde_json::Value;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

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
    /// Wall-clock seconds per unit of simulated time (mean over seeds).
    pub wall_per_time: f64,
    /// `wall_per_time` relative to the reference's.
    pub relative_cost: f64,
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
    /// The accuracy–cost rows (the first ones: the reference, its re-run and its seed spread).
    pub rows: Vec<Row>,
    /// The effects table (with `--effects`).
    pub effects: Vec<EffectRow>,
    /// Wall-clock seconds the whole report took.
    pub wall_seconds: f64,
}

/// What one run measured.
#[derive(Debug, Clone, Default)]
struct Measured {
    density: Option<Vec<f64>>,
    temperature_profile: Option<Vec<f64>>,
    com_height: Option<f64>,
    temperature: f64,
    energy_input: Option<f64>,
    collision_rate: f64,
    wall_per_time: f64,
    pair: f64,
    events: u64,
    max_overlap: f64,
    stats: Option<SchemeStats>,
}

impl Measured {
    fn of(s: &Summary, has_floor: bool) -> Measured {
        let t = s.sim_time.max(f64::MIN_POSITIVE);
        Measured {
            density: s.profiles.as_ref().map(|p| p.density.clone()),
            temperature_profile: s.profiles.as_ref().map(|p| {
                p.temperature_x
                    .iter()
                    .zip(&p.temperature_y)
                    .map(|(x, y)| 0.5 * (x + y))
                    .collect()
            }),
            com_height: s.com_height,
            temperature: s.temperature.mean,
            energy_input: has_floor.then(|| s.energy.injected / t),
            collision_rate: s.events.pair as f64 / t,
            wall_per_time: s.wall_seconds / t,
            pair: s.events.pair as f64,
            events: s.events.popped(),
            max_overlap: s.max_overlap,
            stats: s.approximation,
        }
    }
}

/// Seed-averaged observables of one variant.
#[derive(Debug, Clone, Default)]
struct Ensemble {
    runs: Vec<Measured>,
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

fn variance(v: &[f64]) -> f64 {
    if v.len() < 2 {
        return f64::NAN;
    }
    let m = mean(v);
    v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (v.len() - 1) as f64
}

impl Ensemble {
    fn scalars(&self, f: impl Fn(&Measured) -> Option<f64>) -> Option<Vec<f64>> {
        self.runs.iter().map(f).collect()
    }
    fn scalar(&self, f: impl Fn(&Measured) -> Option<f64>) -> Option<f64> {
        self.scalars(f).map(|v| mean(&v))
    }
    fn profiles(&self, f: impl Fn(&Measured) -> Option<&Vec<f64>>) -> Option<Vec<Vec<f64>>> {
        self.runs.iter().map(|m| f(m).cloned()).collect()
    }
    fn profile(&self, f: impl Fn(&Measured) -> Option<&Vec<f64>>) -> Option<Vec<f64>> {
        let all = self.profiles(f)?;
        let bins = all.first()?.len();
        Some(
            (0..bins)
                .map(|k| mean(&all.iter().map(|p| p[k]).collect::<Vec<_>>()))
                .collect(),
        )
    }
    fn density(&self) -> Option<Vec<f64>> {
        self.profile(|m| m.density.as_ref())
    }
    fn temperature_profile(&self) -> Option<Vec<f64>> {
        self.profile(|m| m.temperature_profile.as_ref())
    }
    fn wall_per_time(&self) -> f64 {
        mean(
            &self
                .runs
                .iter()
                .map(|m| m.wall_per_time)
                .collect::<Vec<_>>(),
        )
    }

    /// Errors of this ensemble's means against `reference`'s.
    fn errors_against(&self, reference: &Ensemble) -> Errors {
        let rel = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(a), Some(b)) if b != 0.0 => Some((a - b).abs() / b.abs()),
            _ => None,
        };
        let density = match (self.density(), reference.density()) {
            (Some(a), Some(b)) => l2_rel(&a, &b, None),
            _ => None,
        };
        let temperature_profile = match (
            self.temperature_profile(),
            reference.temperature_profile(),
            reference.density(),
        ) {
            (Some(a), Some(b), Some(w)) => l2_rel(&a, &b, Some(&w)),
            _ => None,
        };
        Errors {
            density_profile: density,
            temperature_profile,
            com_height: rel(
                self.scalar(|m| m.com_height),
                reference.scalar(|m| m.com_height),
            ),
            temperature: rel(
                self.scalar(|m| Some(m.temperature)),
                reference.scalar(|m| Some(m.temperature)),
            ),
            energy_input: rel(
                self.scalar(|m| m.energy_input),
                reference.scalar(|m| m.energy_input),
            ),
            collision_rate: rel(
                self.scalar(|m| Some(m.collision_rate)),
                reference.scalar(|m| Some(m.collision_rate)),
            ),
        }
    }

    /// The error expected between two independent K-seed ensembles: `√(2/K)·σ/|mean|`.
    fn spread(&self) -> Errors {
        let k = self.runs.len() as f64;
        let factor = (2.0 / k).sqrt();
        let scalar = |f: &dyn Fn(&Measured) -> Option<f64>| {
            let v = self.scalars(f)?;
            let m = mean(&v);
            (m != 0.0 && v.len() > 1).then(|| factor * variance(&v).sqrt() / m.abs())
        };
        let profile = |all: Option<Vec<Vec<f64>>>, weights: Option<&[f64]>| {
            let all = all?;
            if all.len() < 2 {
                return None;
            }
            let bins = all[0].len();
            let (mut num, mut den) = (0.0, 0.0);
            for b in 0..bins {
                let col: Vec<f64> = all.iter().map(|p| p[b]).collect();
                let w = weights.map_or(1.0, |w| w[b]);
                num += w * variance(&col);
                den += w * mean(&col).powi(2);
            }
            (den > 0.0).then(|| factor * (num / den).sqrt())
        };
        let density = self.density();
        Errors {
            density_profile: profile(self.profiles(|m| m.density.as_ref()), None),
            temperature_profile: profile(
                self.profiles(|m| m.temperature_profile.as_ref()),
                density.as_deref(),
            ),
            com_height: scalar(&|m| m.com_height),
            temperature: scalar(&|m| Some(m.temperature)),
            energy_input: scalar(&|m| m.energy_input),
            collision_rate: scalar(&|m| Some(m.collision_rate)),
        }
    }
}

/// `‖a − b‖ / ‖b‖`, optionally weighted per bin.
fn l2_rel(a: &[f64], b: &[f64], w: Option<&[f64]>) -> Option<f64> {
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0..a.len().min(b.len()) {
        let wk = w.map_or(1.0, |w| w[k]);
        num += wk * (a[k] - b[k]).powi(2);
        den += wk * b[k] * b[k];
    }
    (den > 0.0).then(|| (num / den).sqrt())
}

/// A variant: a family, a label and the overrides that make it.
#[derive(Debug, Clone)]
struct Variant {
    family: &'static str,
    label: String,
    sets: Vec<String>,
    record: bool,
}

impl Variant {
    fn new(family: &'static str, label: impl Into<String>, sets: &[String]) -> Variant {
        Variant {
            family,
            label: label.into(),
            sets: sets.to_vec(),
            record: false,
        }
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

/// Sweep factors of a scheme's step.
fn sweep(quick: bool) -> Vec<(f64, &'static str)> {
    if quick {
        vec![(2.0, "×2"), (1.0, "×1"), (0.5, "×½")]
    } else {
        vec![
            (4.0, "×4"),
            (2.0, "×2"),
            (1.0, "×1"),
            (0.5, "×½"),
            (0.25, "×¼"),
        ]
    }
}

/// Runs the accuracy report for `scenario` and writes its files into `opts.out`.
pub fn report(scenario: &Scenario, opts: &Options) -> Result<Report> {
    let clock = Instant::now();
    // The reference: the scene on the exact engine, without recording.
    let mut reference = scenario.clone();
    reference.engine = crate::scenario::Engine {
        scheme: Scheme::EventDriven,
        check_invariants: false,
        dt: None,
        verlet_skin: None,
        sync_distance: None,
        cell_size: None,
        ..scenario.engine.clone()
    };
    reference.output.rrd = None;
    if opts.quick {
        reference.run.duration *= 0.25;
        reference.run.warmup *= 0.25;
    }
    let base = serde_json::to_value(&reference).expect("scenario serialises");
    let k = opts.seeds.unwrap_or(if opts.quick { 2 } else { 3 }).max(1);
    let seeds: Vec<u64> = (0..k as u64)
        .map(|i| scenario.seed.wrapping_add(i))
        .collect();
    let has_floor = reference.floor.is_some();
    let (scene0, disks0) = Scene::build(&reference)?;
    // Every variant's engine accepts the scene before anything is written.
    crate::run::check(scenario)?;
    std::fs::create_dir_all(&opts.out)
        .map_err(|e| Error::Io(format!("cannot create {}: {e}", opts.out.display())))?;
    let (a_min, _) = disks0.radius_range();
    let diameter = 2.0 * a_min;

    let log = |line: String| {
        if opts.verbose {
            eprintln!("{line}");
        }
    };
    // A variant may get stuck where the reference does not (e.g. a floor model that never lets
    // a disk come to rest): it is stopped after five times the reference's events.
    let event_cap = std::cell::Cell::new(None::<u64>);
    let run_variant = |v: &Variant| -> Result<Ensemble> {
        let mut ens = Ensemble::default();
        for &seed in &seeds {
            let mut sets = v.sets.clone();
            sets.push(format!("seed={seed}"));
            if let (Some(cap), None) = (event_cap.get(), reference.run.max_events) {
                sets.push(format!("run.max_events={cap}"));
            }
            let s = with_sets(&base, &sets)?;
            let rrd = v.record.then(|| opts.out.join("accuracy-recording.rrd"));
            let summary = run(
                &s,
                RunOptions {
                    rrd: rrd.clone(),
                    ..Default::default()
                },
            )?;
            if let Some(path) = rrd {
                let _ = std::fs::remove_file(path);
            }
            if summary.ending != crate::output::summary::Ending::Completed {
                return Err(Error::Runtime(format!(
                    "seed {seed} stopped at t = {:.4} ({:?}, after {} events{})",
                    summary.sim_time,
                    summary.ending,
                    summary.events.popped(),
                    if event_cap.get().is_some() {
                        ": the cap is 5× the reference's"
                    } else {
                        ""
                    }
                )));
            }
            log(format!(
                "  {:<12} {:<36} seed {seed}: {:.3} s",
                v.family, v.label, summary.wall_seconds
            ));
            ens.runs.push(Measured::of(&summary, has_floor));
        }
        Ok(ens)
    };

    log(format!(
        "accuracy: {} ({} disks, duration {}, seeds {:?})",
        reference.name,
        reference.disk_count(),
        reference.run.duration,
        seeds
    ));
    let exact = run_variant(&Variant::new("reference", "exact event-driven", &[]))?;
    let most = exact.runs.iter().map(|m| m.events).max().unwrap_or(0);
    event_cap.set(Some(5 * most.max(1000)));
    let mut rows = Vec::new();
    let ref_cost = exact.wall_per_time();
    let make_row = |v: &Variant, ens: &Ensemble, errors: Errors, note: String| {
        let pair: f64 = ens.runs.iter().map(|m| m.pair).sum::<f64>().max(1.0);
        let stat = |f: &dyn Fn(&SchemeStats) -> f64| {
            let all: Option<Vec<f64>> = ens.runs.iter().map(|m| m.stats.as_ref().map(f)).collect();
            all.map(|v| v.iter().sum::<f64>() / pair)
        };
        Row {
            family: v.family.into(),
            variant: v.label.clone(),
            settings: v.sets.join(" "),
            seeds: ens.runs.len(),
            wall_per_time: ens.wall_per_time(),
            relative_cost: ens.wall_per_time() / ref_cost,
            errors,
            max_overlap: ens.runs.iter().map(|m| m.max_overlap).fold(0.0, f64::max) / diameter,
            overlapped_fraction: stat(&|s| s.overlapped_collisions as f64),
            deep_fraction: stat(&|s| s.deep_overlaps as f64),
            missed_fraction: stat(&|s| s.missed as f64),
            note,
        }
    };
    let ref_variant = Variant::new("reference", "exact event-driven", &[]);
    rows.push(make_row(
        &ref_variant,
        &exact,
        exact.errors_against(&exact),
        "the reference".into(),
    ));
    rows.push(make_row(
        &Variant::new("reference", format!("seed spread (√(2/{k})·σ)"), &[]),
        &exact,
        exact.spread(),
        "errors below these are noise".into(),
    ));

    // The variants.
    let mut variants = Vec::new();
    variants.push(Variant::new("reference", "exact, re-run same seeds", &[]));
    let dt0 = time_step::default_dt(&scene0, &disks0);
    for (f, name) in sweep(opts.quick) {
        if let Some(dt0) = dt0 {
            let dt = dt0 * f;
            variants.push(Variant::new(
                "time-step",
                format!("dt = {} ({name})", fmt_g(dt)),
                &[
                    "engine.scheme=time-step".into(),
                    format!("engine.dt={dt:e}"),
                ],
            ));
        }
    }
    for (f, name) in sweep(opts.quick) {
        let d = crate::schemes::space_time::DEFAULT_SYNC_DISTANCE * f;
        variants.push(Variant::new(
            "space-time",
            format!("D = {} d ({name})", fmt_g(d * a_min / diameter)),
            &[
                "engine.scheme=space-time".into(),
                format!("engine.sync_distance={d:e}"),
            ],
        ));
    }
    if let Some(floor) = scene0.floor.as_ref().filter(|f| !f.is_static()) {
        use crate::scenario::{FloorModel, Waveform};
        let models = [
            (Waveform::Sine, FloorModel::Exact, "exact sine"),
            (
                Waveform::Sine,
                FloorModel::FixedPosition,
                "fixed-position sine",
            ),
            (Waveform::Triangle, FloorModel::Exact, "triangle wave"),
        ];
        for (w, m, name) in models {
            if (w, m) == (floor.waveform, floor.model) {
                continue;
            }
            let w_name = match w {
                Waveform::Sine => "sine",
                Waveform::Triangle => "triangle",
                Waveform::Sawtooth => "sawtooth",
            };
            let m_name = match m {
                FloorModel::Exact => "exact",
                FloorModel::FixedPosition => "fixed-position",
            };
            variants.push(Variant::new(
                "floor",
                format!("floor: {name}"),
                &[
                    format!("floor.waveform={w_name}"),
                    format!("floor.model={m_name}"),
                ],
            ));
        }
    }
    if reference.collisions.restitution < 1.0 {
        // Scales: the mean time between a disk's collisions, and the thermal speed.
        let pair_rate = exact.scalar(|m| Some(m.collision_rate)).unwrap_or(0.0);
        let n = reference.disk_count() as f64;
        let tau = if pair_rate > 0.0 {
            n / (2.0 * pair_rate)
        } else {
            1.0
        };
        let v_th = exact
            .scalar(|m| Some(m.temperature))
            .unwrap_or(1.0)
            .max(0.0)
            .sqrt();
        let factors: &[f64] = if opts.quick {
            &[1e-2]
        } else {
            &[1e-3, 1e-2, 1e-1]
        };
        for &f in factors {
            let tc = f * tau;
            variants.push(Variant::new(
                "dissipation",
                format!("TC t_c = {} (τ_coll×{f})", fmt_g(tc)),
                &[format!("collisions.tc={tc:e}")],
            ));
        }
        // A bed at rest has no thermal speed to scale a cutoff with.
        for &f in factors.iter().filter(|_| v_th > 0.0) {
            let v = f * v_th;
            variants.push(Variant::new(
                "dissipation",
                format!("speed cutoff {} (v_T×{f})", fmt_g(v)),
                &[format!("collisions.speed_cutoff={v:e}")],
            ));
        }
    }
    if scene0.floor.is_some() && reference.collisions.resting_contacts {
        // What resting contacts buy where a bed comes to rest: the same scene without them.
        variants.push(Variant::new(
            "resting",
            "resting contacts off",
            &["collisions.resting_contacts=false".into()],
        ));
    }
    let mut rec = Variant::new("recording", "recording frames on", &[]);
    rec.record = true;
    let record_available = cfg!(feature = "record");
    variants.push(rec);

    for v in &variants {
        if v.record && !record_available {
            rows.push(Row {
                family: v.family.into(),
                variant: v.label.clone(),
                settings: String::new(),
                seeds: 0,
                wall_per_time: f64::NAN,
                relative_cost: f64::NAN,
                errors: Errors::default(),
                max_overlap: f64::NAN,
                overlapped_fraction: None,
                deep_fraction: None,
                missed_fraction: None,
                note: "skipped: this build has no `record` feature".into(),
            });
            continue;
        }
        match run_variant(v) {
            Ok(ens) => {
                let errors = ens.errors_against(&exact);
                rows.push(make_row(v, &ens, errors, String::new()));
            }
            Err(e) => rows.push(Row {
                family: v.family.into(),
                variant: v.label.clone(),
                settings: v.sets.join(" "),
                seeds: 0,
                wall_per_time: f64::NAN,
                relative_cost: f64::NAN,
                errors: Errors::default(),
                max_overlap: f64::NAN,
                overlapped_fraction: None,
                deep_fraction: None,
                missed_fraction: None,
                note: format!("failed: {e}"),
            }),
        }
    }

    let effects = if opts.effects {
        effects_table(scenario, opts, &log)?
    } else {
        Vec::new()
    };
    let report = Report {
        scenario: reference.name.clone(),
        particles: reference.disk_count(),
        duration: reference.run.duration,
        seeds,
        rows,
        effects,
        wall_seconds: clock.elapsed().as_secs_f64(),
    };
    write_file(&opts.out.join("accuracy.csv"), &report.csv())?;
    write_file(&opts.out.join("accuracy.txt"), &report.table())?;
    if !report.effects.is_empty() {
        write_file(&opts.out.join("effects.csv"), &report.effects_csv())?;
    }
    plot::draw(&report, &opts.out.join("accuracy.svg"))?;
    Ok(report)
}

fn write_file(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text)
        .map_err(|e| Error::Io(format!("cannot write {}: {e}", path.display())))
}

fn cell(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{v:.2e}"),
        _ => "-".into(),
    }
}

impl Report {
    /// The table printed on stdout.
    pub fn table(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            "accuracy vs cost: {} ({} disks, {} time units, seeds {:?})",
            self.scenario, self.particles, self.duration, self.seeds
        );
        let _ = writeln!(
            out,
            "errors are relative to the exact engine's seed mean; cost = wall s per unit time\n"
        );
        let _ = writeln!(
            out,
            "{:<11} {:<34} {:>9} {:>6} | {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} | {:>8} {:>8} {:>8} note",
            "family",
            "variant",
            "s/t",
            "×ref",
            "ρ(z)",
            "T(z)",
            "z_cm",
            "T",
            "E_in/t",
            "coll/t",
            "ovl/d",
            "deep",
            "missed",
        );
        for r in &self.rows {
            let e = r.errors;
            let _ = writeln!(
                out,
                "{:<11} {:<34} {:>9} {:>6} | {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} | {:>8} {:>8} {:>8} {}",
                r.family,
                r.variant,
                if r.wall_per_time.is_finite() {
                    format!("{:.4}", r.wall_per_time)
                } else {
                    "-".into()
                },
                if r.relative_cost.is_finite() {
                    format!("{:.2}", r.relative_cost)
                } else {
                    "-".into()
                },
                cell(e.density_profile),
                cell(e.temperature_profile),
                cell(e.com_height),
                cell(e.temperature),
                cell(e.energy_input),
                cell(e.collision_rate),
                cell(Some(r.max_overlap)),
                cell(r.deep_fraction),
                cell(r.missed_fraction),
                r.note
            );
        }
        let _ = writeln!(
            out,
            "\nρ(z), T(z): L2 profile errors; ovl/d: largest pair overlap / smallest diameter; deep: overlaps > 10 % of contact per pair collision; missed: missed collisions per pair collision"
        );
        if !self.effects.is_empty() {
            let _ = writeln!(
                out,
                "\nwhat each effect costs (exact engine; slowdown = with / without)\n"
            );
            let _ = writeln!(
                out,
                "{:<28} {:<34} {:>12} {:>12} {:>9} {:>9} note",
                "effect",
                "added to the scene without it",
                "µs/coll w/o",
                "µs/coll with",
                "×/coll",
                "×/time",
            );
            for e in &self.effects {
                let _ = writeln!(
                    out,
                    "{:<28} {:<34} {:>12.3} {:>12.3} {:>9.2} {:>9.2} {}",
                    e.effect,
                    e.with,
                    1e6 * e.per_collision[0],
                    1e6 * e.per_collision[1],
                    e.slowdown_per_collision,
                    e.slowdown_per_time,
                    e.note
                );
            }
        }
        let _ = writeln!(out, "\nreport took {:.1} s", self.wall_seconds);
        out
    }

    /// The rows as CSV.
    pub fn csv(&self) -> String {
        let mut out = String::from(
            "family,variant,settings,seeds,wall_per_time,relative_cost,err_density_profile,err_temperature_profile,err_com_height,err_temperature,err_energy_input,err_collision_rate,max_overlap_per_diameter,overlapped_fraction,deep_fraction,missed_fraction,note\n",
        );
        let f = |v: Option<f64>| {
            v.filter(|v| v.is_finite())
                .map_or(String::new(), |v| format!("{v:e}"))
        };
        for r in &self.rows {
            let e = r.errors;
            let _ = writeln!(
                out,
                "{},\"{}\",\"{}\",{},{},{},{},{},{},{},{},{},{},{},{},{},\"{}\"",
                r.family,
                r.variant,
                r.settings,
                r.seeds,
                f(Some(r.wall_per_time)),
                f(Some(r.relative_cost)),
                f(e.density_profile),
                f(e.temperature_profile),
                f(e.com_height),
                f(e.temperature),
                f(e.energy_input),
                f(e.collision_rate),
                f(Some(r.max_overlap)),
                f(r.overlapped_fraction),
                f(r.deep_fraction),
                f(r.missed_fraction),
                r.note.replace('"', "'")
            );
        }
        out
    }

    /// The effects table as CSV.
    pub fn effects_csv(&self) -> String {
        let mut out = String::from(
            "effect,without,with,seconds_per_collision_without,seconds_per_collision_with,seconds_per_time_without,seconds_per_time_with,slowdown_per_collision,slowdown_per_time,note\n",
        );
        for e in &self.effects {
            let _ = writeln!(
                out,
                "\"{}\",\"{}\",\"{}\",{:e},{:e},{:e},{:e},{},{},\"{}\"",
                e.effect,
                e.without,
                e.with,
                e.per_collision[0],
                e.per_collision[1],
                e.per_time[0],
                e.per_time[1],
                e.slowdown_per_collision,
                e.slowdown_per_time,
                e.note
            );
        }
        out
    }
}

/// One effect: its name, the base scene, the overrides without and with it, what is added.
type EffectPair<'a> = (&'static str, &'a Value, Vec<String>, Vec<String>, String);

/// What each effect costs: pairs of scenes (without, with) built around the scenario's disks,
/// run on the exact engine; the minimum over repetitions of the wall time per collision and per
/// unit time (the minimum is the least disturbed by a noisy machine).
fn effects_table(
    scenario: &Scenario,
    opts: &Options,
    log: &dyn Fn(String),
) -> Result<Vec<EffectRow>> {
    let n = scenario.disk_count().max(2);
    let (a, _) = scenario.radius_range();
    let phi = 0.3;
    let area = n as f64 * std::f64::consts::PI * a * a / phi;
    let width = area.sqrt().max(8.0 * a);
    // Long enough for each disk to travel some 100 diameters at unit temperature.
    let duration = if opts.quick { 10.0 } else { 100.0 } * 2.0 * a;
    let gas = serde_json::json!({
        "name": "effects: elastic gas, periodic box",
        "seed": scenario.seed,
        "domain": {"width": width, "x_boundary": "periodic", "y_boundary": "periodic"},
        "particles": {"count": n, "radius": a, "packing_fraction": phi, "temperature": 1.0},
        "run": {"duration": duration},
    });
    let height = area / width;
    let g = 1.0 / (4.0 * a); // gravitational height kT/(mg) of two diameters
    let floor_box = serde_json::json!({
        "name": "effects: box with a lid and a static floor",
        "seed": scenario.seed,
        "domain": {"width": width, "height": height, "x_boundary": "periodic", "y_boundary": "lid"},
        "floor": {"restitution": 1.0},
        "particles": {"count": n, "radius": a, "temperature": 1.0},
        "run": {"duration": duration},
    });
    let s = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<String>>();
    let freq = (g / a).sqrt() / 10.0;
    let gamma_amp = |gamma: f64| gamma * g / (std::f64::consts::TAU * freq).powi(2);
    let vib = vec![
        format!("gravity={g:e}"),
        format!("floor.amplitude={:e}", gamma_amp(3.0)),
        format!("floor.frequency={freq:e}"),
    ];
    let cat = |a: &[String], b: &[String]| [a, b].concat();
    let gravity = vec![format!("gravity={g:e}")];
    let tc = format!("collisions.tc={:e}", 1e-3 * 2.0 * a);
    // (effect, base scene, without, with, label of what is added)
    let mut pairs: Vec<EffectPair> = vec![
        (
            "walls vs periodic",
            &gas,
            vec![],
            s(&["domain.x_boundary=walls"]),
            "hard side walls".into(),
        ),
        (
            "polydispersity",
            &gas,
            vec![],
            vec![format!(
                "particles.radius={{\"min\":{},\"max\":{}}}",
                0.7 * a,
                1.3 * a
            )],
            "radii uniform in [0.7a, 1.3a]".into(),
        ),
        (
            "dissipation: e = 0.9 + TC",
            &gas,
            vec![],
            vec!["collisions.restitution=0.9".into(), tc.clone()],
            "e = 0.9 with TC".into(),
        ),
        (
            "dissipation: e = 0.9 + cutoff",
            &gas,
            vec![],
            s(&["collisions.restitution=0.9", "collisions.speed_cutoff=0.05"]),
            "e = 0.9 with speed cutoff".into(),
        ),
        (
            "floor and lid vs periodic y",
            &gas,
            vec![],
            vec![],
            "static floor and lid".into(),
        ),
        (
            "gravity",
            &floor_box,
            vec![],
            gravity.clone(),
            format!("g = {}", fmt_g(g)),
        ),
        (
            "floor kind: vibrating sine",
            &floor_box,
            gravity.clone(),
            vib.clone(),
            "sine floor, Γ = 3".into(),
        ),
        (
            "floor kind: triangle vs sine",
            &floor_box,
            vib.clone(),
            cat(&vib, &s(&["floor.waveform=triangle"])),
            "triangle wave".into(),
        ),
        (
            "floor kind: fixed-position",
            &floor_box,
            vib.clone(),
            cat(&vib, &s(&["floor.model=fixed-position"])),
            "fixed-position model".into(),
        ),
    ];
    if cfg!(feature = "record") {
        pairs.push((
            "recording",
            &gas,
            vec![],
            vec![],
            "frames recorded (200 frames)".into(),
        ));
    }
    let reps = if opts.quick { 1 } else { 3 };
    let mut rows = Vec::new();
    for (effect, base, without, with, label) in pairs {
        let record = effect == "recording";
        // The floor-and-lid row compares two different base scenes.
        let (base_with, with) = if effect == "floor and lid vs periodic y" {
            (&floor_box, with)
        } else {
            (base, with)
        };
        let mut best = [[f64::INFINITY; 2]; 2];
        let mut note = String::new();
        for _ in 0..reps {
            for (k, (b, sets)) in [(base, &without), (base_with, &with)]
                .into_iter()
                .enumerate()
            {
                let sc = with_sets(b, sets)?;
                let rrd = (record && k == 1).then(|| opts.out.join("effects-recording.rrd"));
                match run(
                    &sc,
                    RunOptions {
                        rrd: rrd.clone(),
                        ..Default::default()
                    },
                ) {
                    Ok(sum) => {
                        let coll = sum.events.collisions().max(1) as f64;
                        best[k][0] = best[k][0].min(sum.wall_seconds / coll);
                        best[k][1] = best[k][1].min(sum.wall_seconds / sum.sim_time);
                    }
                    Err(e) => note = format!("failed: {e}"),
                }
                if let Some(p) = rrd {
                    let _ = std::fs::remove_file(p);
                }
            }
        }
        log(format!(
            "  effect {effect:<30} ×{:.2} per collision",
            best[1][0] / best[0][0]
        ));
        rows.push(EffectRow {
            effect: effect.into(),
            without: format!(
                "{} {}",
                base["name"].as_str().unwrap_or(""),
                without.join(" ")
            )
            .trim()
            .to_string(),
            with: label,
            per_collision: [best[0][0], best[1][0]],
            per_time: [best[0][1], best[1][1]],
            slowdown_per_collision: best[1][0] / best[0][0],
            slowdown_per_time: best[1][1] / best[0][1],
            note,
        });
    }
    Ok(rows)
}
