//! The sweep file and its expansion into runs.
//!
//! A sweep file names a base scenario, fixed `--set` overrides, axes of overrides (explicit
//! values, or linear/log ranges with a count), how the axes combine (`cross`: every combination,
//! the last axis fastest; `zip`: the k-th value of every axis together) and the seeds run at
//! every point. Run `i` is point `i / seeds` with the `(i % seeds)`-th seed; its output goes to
//! `DIR/<i>/`.

use crate::error::{Error, Result};
use crate::scenario::{overrides, Scenario};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The sweep file (JSON; unknown fields are rejected).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepFile {
    /// Name of the sweep (Slurm job name); default: the file name without extension.
    #[serde(default)]
    pub name: Option<String>,
    /// The base scenario, relative to the sweep file's folder.
    pub scenario: PathBuf,
    /// `KEY=VALUE` overrides applied to every run, before the axes.
    #[serde(default)]
    pub set: Vec<String>,
    /// The axes of the sweep; none: a single point.
    #[serde(default)]
    pub axes: Vec<Axis>,
    /// How the axes combine.
    #[serde(default)]
    pub combine: Combine,
    /// Seeds run at every point; absent: the scenario's own seed.
    #[serde(default)]
    pub seeds: Option<Seeds>,
    /// Record every run to `DIR/<index>/recording.rrd`.
    #[serde(default)]
    pub record: bool,
}

/// One axis: a scenario field (dotted path, as for `--set`) and the values it takes.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axis {
    /// Dotted path of the field, e.g. `floor.gamma`.
    pub key: String,
    /// Explicit values (any JSON: numbers, strings, objects).
    #[serde(default)]
    pub values: Option<Vec<Value>>,
    /// A range of numbers instead of explicit values.
    #[serde(default)]
    pub range: Option<Range>,
}

/// Evenly spaced numbers from `from` to `to` (both included).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Range {
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// How many values (at least 1; 1 gives `from` alone).
    pub count: usize,
    /// `linear` (equal differences) or `log` (equal ratios; both bounds positive).
    #[serde(default)]
    pub scale: Scale,
    /// Round the values to integers (for counts such as `particles.count`).
    #[serde(default)]
    pub integer: bool,
}

/// Spacing of a range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Scale {
    /// Equal differences.
    #[default]
    Linear,
    /// Equal ratios.
    Log,
}

/// How the axes combine into points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Combine {
    /// Every combination of the axes' values (the last axis varies fastest).
    #[default]
    Cross,
    /// The k-th values of all axes together (all axes the same length).
    Zip,
}

/// The seeds of every point: a count n (seeds 0 … n−1) or a list.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum Seeds {
    /// Seeds 0, 1, …, n−1.
    Count(u64),
    /// These seeds.
    List(Vec<u64>),
}

/// One run of the sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSpec {
    /// Run number (also its output folder's name).
    pub index: usize,
    /// Point number (runs of the same point differ only by seed).
    pub point: usize,
    /// Seed of this run, when the sweep sets seeds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// The axes' values at this point, in the order of [`Plan::axes`].
    pub values: Vec<Value>,
    /// Every `KEY=VALUE` override of this run, in the order applied (fixed, axes, seed).
    pub sets: Vec<String>,
    /// The floor's drive at this point (scenes with a vibrating floor and gravity).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drive: Option<PointDrive>,
}

/// The floor's drive at a point, whichever fields the scenario sets: amplitude A, frequency f,
/// Γ = Aω²/g, peak velocity Aω (ω = 2πf).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointDrive {
    /// Vibration amplitude A.
    pub amplitude: f64,
    /// Frequency f (cycles per unit time).
    pub frequency: f64,
    /// Γ = Aω²/g.
    pub gamma: f64,
    /// Peak floor velocity Aω.
    pub peak_velocity: f64,
}

impl PointDrive {
    /// The drive of a scenario with gravity and a vibrating floor.
    pub fn of(s: &Scenario) -> Option<PointDrive> {
        let (drive, g) = (s.floor_drive()?, s.gravity?);
        let frequency = s.floor.as_ref()?.frequency?;
        if drive.amplitude <= 0.0 {
            return None;
        }
        Some(PointDrive {
            amplitude: drive.amplitude,
            frequency,
            gamma: drive.gamma(g),
            peak_velocity: drive.peak_velocity(),
        })
    }
}

/// The expanded sweep: every run with its overrides. Written to `DIR/plan.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// Name of the sweep.
    pub name: String,
    /// The sweep file (absolute path).
    pub sweep: PathBuf,
    /// The base scenario (absolute path).
    pub scenario: PathBuf,
    /// Axis keys, in order.
    pub axes: Vec<String>,
    /// How the axes were combined.
    pub combine: Combine,
    /// Number of points.
    pub points: usize,
    /// Whether runs are recorded.
    pub record: bool,
    /// The runs, by index.
    pub runs: Vec<RunSpec>,
}

/// A plan with the typed scenario of each run (same order as `plan.runs`).
#[derive(Debug, Clone)]
pub struct Expanded {
    /// The plan.
    pub plan: Plan,
    /// The scenario of each run, overrides applied and validated.
    pub scenarios: Vec<Scenario>,
}

/// Reads and types a sweep file; errors name the dotted path of the culprit.
pub fn read_sweep(path: &Path) -> Result<SweepFile> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::input("SWEEP", format!("cannot read {}: {e}", path.display())))?;
    parse_sweep(&text, path)
}

/// Types the text of a sweep file read from (or to be written to) `path`.
fn parse_sweep(text: &str, path: &Path) -> Result<SweepFile> {
    let value: Value = serde_json::from_str(text).map_err(|e| {
        Error::input(
            "",
            format!(
                "{}: malformed JSON at line {} column {}: {e}",
                path.display(),
                e.line(),
                e.column()
            ),
        )
    })?;
    serde_path_to_error::deserialize(value).map_err(|e| {
        let field = e.path().to_string();
        let inner = e.into_inner().to_string();
        let hint = if field == "seeds" {
            " (expected a count or a list of non-negative integers)"
        } else {
            ""
        };
        let field = if field == "." {
            path.display().to_string()
        } else {
            field
        };
        Error::input(field, format!("{inner}{hint}"))
    })
}

/// The values an axis takes; errors name `axes[k]…`.
fn axis_values(k: usize, axis: &Axis) -> Result<Vec<Value>> {
    let here = format!("axes[{k}]");
    if axis.key.trim().is_empty() || axis.key.split('.').any(str::is_empty) {
        return Err(Error::input(
            format!("{here}.key"),
            format!(
                "`{}` is not a dotted field path (e.g. floor.gamma)",
                axis.key
            ),
        ));
    }
    match (&axis.values, &axis.range) {
        (Some(_), Some(_)) => Err(Error::input(
            here,
            "give either `values` or `range`, not both",
        )),
        (None, None) => Err(Error::input(here, "needs `values` or `range`")),
        (Some(values), None) if values.is_empty() => Err(Error::input(
            format!("{here}.values"),
            "must hold at least one value",
        )),
        (Some(values), None) => Ok(values.clone()),
        (None, Some(r)) => range_values(&format!("{here}.range"), r),
    }
}

/// Rounds to 12 significant digits, so that range values read well in tables and file names
/// (0.30000000000000004 → 0.3) and are the same on every machine.
fn tidy(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    format!("{x:.11e}").parse().unwrap_or(x)
}

/// Most runs one sweep may hold (points × seeds).
pub const MAX_RUNS: usize = 100_000;

fn range_values(here: &str, r: &Range) -> Result<Vec<Value>> {
    if !(1..=MAX_RUNS).contains(&r.count) {
        return Err(Error::input(
            format!("{here}.count"),
            format!("must lie in [1, {MAX_RUNS}] (got {})", r.count),
        ));
    }
    for (name, v) in [("from", r.from), ("to", r.to)] {
        if !v.is_finite() {
            return Err(Error::input(
                format!("{here}.{name}"),
                "must be a finite number",
            ));
        }
        if r.scale == Scale::Log && v <= 0.0 {
            return Err(Error::input(
                format!("{here}.{name}"),
                format!("a log range needs positive bounds (got {v})"),
            ));
        }
    }
    let n = r.count;
    let at = |k: usize| -> f64 {
        if k + 1 == n && n > 1 {
            return r.to;
        }
        let u = if n > 1 {
            k as f64 / (n - 1) as f64
        } else {
            0.0
        };
        match r.scale {
            Scale::Linear => r.from + (r.to - r.from) * u,
            Scale::Log => (r.from.ln() + (r.to.ln() - r.from.ln()) * u).exp(),
        }
    };
    Ok((0..n)
        .map(|k| {
            let x = at(k);
            if r.integer {
                Value::from(x.round() as i64)
            } else {
                Value::from(tidy(x))
            }
        })
        .collect())
}

/// The points: for each, one value per axis.
fn points(sweep: &SweepFile) -> Result<Vec<Vec<Value>>> {
    let values: Vec<Vec<Value>> = sweep
        .axes
        .iter()
        .enumerate()
        .map(|(k, a)| axis_values(k, a))
        .collect::<Result<_>>()?;
    for (k, a) in sweep.axes.iter().enumerate() {
        if let Some(j) = sweep.axes[..k].iter().position(|b| b.key == a.key) {
            return Err(Error::input(
                format!("axes[{k}].key"),
                format!("`{}` is already the key of axes[{j}]", a.key),
            ));
        }
    }
    if values.is_empty() {
        return Ok(vec![Vec::new()]);
    }
    if sweep.combine == Combine::Cross {
        let total = values
            .iter()
            .try_fold(1usize, |n, v| n.checked_mul(v.len()))
            .filter(|&n| n <= MAX_RUNS);
        if total.is_none() {
            return Err(Error::input(
                "axes",
                format!("every combination of the axes makes more than {MAX_RUNS} points"),
            ));
        }
    }
    match sweep.combine {
        Combine::Zip => {
            let n = values[0].len();
            if let Some(k) = values.iter().position(|v| v.len() != n) {
                return Err(Error::input(
                    "combine",
                    format!(
                        "`zip` needs axes of one length: axes[0] has {n} values, axes[{k}] has {}",
                        values[k].len()
                    ),
                ));
            }
            Ok((0..n)
                .map(|i| values.iter().map(|v| v[i].clone()).collect())
                .collect())
        }
        Combine::Cross => {
            let mut out: Vec<Vec<Value>> = vec![Vec::new()];
            for axis in &values {
                out = out
                    .into_iter()
                    .flat_map(|p| {
                        axis.iter().map(move |v| {
                            let mut q = p.clone();
                            q.push(v.clone());
                            q
                        })
                    })
                    .collect();
            }
            Ok(out)
        }
    }
}

/// `KEY=VALUE` with the value written as JSON (read back as the same JSON by `--set`).
fn set_string(key: &str, value: &Value) -> String {
    format!("{key}={value}")
}

/// Expands the sweep file at `path` into runs and types (and validates) every run's scenario,
/// as `check` does before building the scene. A bad point is reported as
/// `point P (KEY=VALUE, …): FIELD: what is wrong`.
pub fn expand(path: &Path) -> Result<Expanded> {
    let sweep = read_sweep(path)?;
    let sweep_path = std::fs::canonicalize(path)
        .map_err(|e| Error::Io(format!("cannot resolve {}: {e}", path.display())))?;
    expand_sweep(&sweep, sweep_path)
}

/// Expands the text of a sweep file as [`expand`] expands the file, as if it were at `path`
/// (which need not exist yet): a sweep handed over as text (the Python package's dict) is
/// written only once it is known good.
pub fn expand_text(text: &str, path: &Path) -> Result<Expanded> {
    let sweep = parse_sweep(text, path)?;
    let sweep_path = std::path::absolute(path)
        .map_err(|e| Error::Io(format!("cannot resolve {}: {e}", path.display())))?;
    expand_sweep(&sweep, sweep_path)
}

/// Expands a typed sweep whose file is (or is to be) at `sweep_path`, an absolute path.
fn expand_sweep(sweep: &SweepFile, sweep_path: PathBuf) -> Result<Expanded> {
    let base_dir = sweep_path.parent().unwrap_or(Path::new("."));
    let scenario_path = base_dir.join(&sweep.scenario);
    let base = base_scenario(sweep, &scenario_path)?;
    let seeds = seed_list(sweep.seeds.as_ref())?;
    #[cfg(not(feature = "record"))]
    if sweep.record {
        return Err(Error::input(
            "record",
            "this build of vibrobed has no recording (build with the `record` feature)",
        ));
    }
    let points = points(sweep)?;
    if points.len().saturating_mul(seeds.len()) > MAX_RUNS {
        return Err(Error::input(
            "seeds",
            format!(
                "{} points × {} seeds make more than {MAX_RUNS} runs",
                points.len(),
                seeds.len()
            ),
        ));
    }
    let keys: Vec<String> = sweep.axes.iter().map(|a| a.key.clone()).collect();
    let (runs, scenarios) = expand_runs(&base, &sweep.set, &keys, &points, &seeds)?;
    let name = sweep.name.clone().unwrap_or_else(|| {
        sweep_path
            .file_stem()
            .map_or("sweep".into(), |s| s.to_string_lossy().into_owned())
    });
    Ok(Expanded {
        plan: Plan {
            name,
            sweep: sweep_path,
            scenario: std::fs::canonicalize(&scenario_path).unwrap_or(scenario_path),
            axes: keys,
            combine: sweep.combine,
            points: points.len(),
            record: sweep.record,
            runs,
        },
        scenarios,
    })
}

/// The base scenario as JSON, with the sweep's fixed overrides applied and without a
/// recording path (the runs write into folders of their own: a recording path in the scenario
/// would have every run write the same file; recording is the sweep's `record` instead).
fn base_scenario(sweep: &SweepFile, scenario_path: &Path) -> Result<Value> {
    let text = std::fs::read_to_string(scenario_path).map_err(|e| {
        Error::input(
            "scenario",
            format!("cannot read {}: {e}", scenario_path.display()),
        )
    })?;
    let mut base: Value = serde_json::from_str(&text).map_err(|e| {
        Error::input(
            "scenario",
            format!(
                "{}: malformed JSON at line {} column {}: {e}",
                scenario_path.display(),
                e.line(),
                e.column()
            ),
        )
    })?;
    if let Some(output) = base.get_mut("output").and_then(Value::as_object_mut) {
        output.remove("rrd");
    }
    for (k, set) in sweep.set.iter().enumerate() {
        overrides::apply(&mut base, set).map_err(|e| rename_field(e, &format!("set[{k}]")))?;
    }
    Ok(base)
}

/// The seeds run at every point: `None` alone (the scenario's own seed) when the sweep sets
/// none; a count or a list must give between 1 and [`MAX_RUNS`] distinct seeds.
fn seed_list(seeds: Option<&Seeds>) -> Result<Vec<Option<u64>>> {
    match seeds {
        None => Ok(vec![None]),
        Some(Seeds::Count(n)) if !(1..=MAX_RUNS as u64).contains(n) => Err(Error::input(
            "seeds",
            format!("must lie in [1, {MAX_RUNS}] (got {n})"),
        )),
        Some(Seeds::Count(n)) => Ok((0..*n).map(Some).collect()),
        Some(Seeds::List(list)) if list.is_empty() => {
            Err(Error::input("seeds", "must list at least one seed"))
        }
        Some(Seeds::List(list)) => {
            for (k, s) in list.iter().enumerate() {
                if list[..k].contains(s) {
                    return Err(Error::input(
                        format!("seeds[{k}]"),
                        format!("seed {s} is listed twice"),
                    ));
                }
            }
            Ok(list.iter().copied().map(Some).collect())
        }
    }
}

/// Every run, point by point and seed by seed within a point, with its overrides (fixed, axes,
/// seed) and its typed, validated scenario; the first bad point is the error.
fn expand_runs(
    base: &Value,
    fixed: &[String],
    keys: &[String],
    points: &[Vec<Value>],
    seeds: &[Option<u64>],
) -> Result<(Vec<RunSpec>, Vec<Scenario>)> {
    let mut runs = Vec::with_capacity(points.len() * seeds.len());
    let mut scenarios = Vec::with_capacity(runs.capacity());
    for (p, values) in points.iter().enumerate() {
        let mut sets = fixed.to_vec();
        sets.extend(keys.iter().zip(values).map(|(k, v)| set_string(k, v)));
        let mut at_point = base.clone();
        for (k, v) in keys.iter().zip(values) {
            overrides::apply(&mut at_point, &set_string(k, v))
                .map_err(|e| at(p, values, keys, e))?;
        }
        for seed in seeds {
            let mut value = at_point.clone();
            let mut run_sets = sets.clone();
            if let Some(seed) = seed {
                value["seed"] = Value::from(*seed);
                run_sets.push(format!("seed={seed}"));
            }
            let scenario = Scenario::from_value(value)
                .and_then(|s| s.validate().map(|_| s))
                .map_err(|e| at(p, values, keys, e))?;
            runs.push(RunSpec {
                index: runs.len(),
                point: p,
                seed: *seed,
                values: values.clone(),
                sets: run_sets,
                drive: PointDrive::of(&scenario),
            });
            scenarios.push(scenario);
        }
    }
    Ok((runs, scenarios))
}

/// An error of a fixed override, renamed to name the sweep file's field.
fn rename_field(e: Error, field: &str) -> Error {
    match e {
        Error::Input { field: f, message } => Error::input(format!("{field} ({f})"), message),
        other => other,
    }
}

/// An error at point `p`, naming the point, its values and the field.
fn at(p: usize, values: &[Value], keys: &[String], e: Error) -> Error {
    let label = point_label(keys, values);
    match e {
        Error::Input { field, message } => {
            let field = field.trim_start_matches("--set ").to_string();
            let sep = if field.is_empty() { "" } else { ": " };
            Error::input(format!("point {p} ({label}){sep}{field}"), message)
        }
        other => other,
    }
}

/// `1 point`, `3 points`.
pub fn plural(n: usize, word: &str) -> String {
    if n == 1 {
        format!("1 {word}")
    } else {
        format!("{n} {word}s")
    }
}

/// `key=value, key=value` for messages and listings.
pub fn point_label(keys: &[String], values: &[Value]) -> String {
    if keys.is_empty() {
        return "base scenario".into();
    }
    keys.iter()
        .zip(values)
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

impl Expanded {
    /// Builds every run's initial state and engine (placement, grid, mask, neighbour lists,
    /// first predictions) as `check` does, without running; the first failure names its point.
    pub fn check_scenes(&self) -> Result<()> {
        for (run, s) in self.plan.runs.iter().zip(&self.scenarios) {
            crate::run::check(s).map_err(|e| at(run.point, &run.values, &self.plan.axes, e))?;
        }
        Ok(())
    }
}

impl Plan {
    /// Pretty JSON of the plan.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("plan serialises") + "\n"
    }

    /// Reads `DIR/plan.json`.
    pub fn read(dir: &Path) -> Result<Plan> {
        let path = dir.join("plan.json");
        let text = std::fs::read_to_string(&path).map_err(|e| {
            Error::input(
                "DIR",
                format!(
                    "cannot read {} (is this a sweep's output folder?): {e}",
                    path.display()
                ),
            )
        })?;
        serde_json::from_str(&text)
            .map_err(|e| Error::input("DIR", format!("{}: {e}", path.display())))
    }

    /// Number of seeds per point.
    pub fn seeds_per_point(&self) -> usize {
        self.runs.len() / self.points.max(1)
    }

    /// A table of the runs: index, point, seed, overrides, output folder.
    pub fn listing(&self, out: Option<&Path>) -> String {
        let mut text = format!(
            "sweep {}: {} runs ({} × {}), axes: {}\n",
            self.name,
            self.runs.len(),
            plural(self.points, "point"),
            plural(self.seeds_per_point(), "seed"),
            if self.axes.is_empty() {
                "none".into()
            } else {
                format!("{} ({:?})", self.axes.join(", "), self.combine).to_lowercase()
            }
        );
        text.push_str("index\tpoint\tseed\toverrides\toutput\n");
        for r in &self.runs {
            let dir = match out {
                Some(out) => out.join(r.index.to_string()).display().to_string(),
                None => format!("<out>/{}", r.index),
            };
            text.push_str(&format!(
                "{}\t{}\t{}\t{}\t{}\n",
                r.index,
                r.point,
                r.seed.map_or("-".into(), |s| s.to_string()),
                point_label(&self.axes, &r.values),
                dir
            ));
        }
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn sweep(v: Value) -> SweepFile {
        serde_json::from_value(v).unwrap()
    }

    #[test]
    fn ranges_hit_both_ends_and_round_to_twelve_digits() {
        let r = |scale, from, to, count| Range {
            from,
            to,
            count,
            scale,
            integer: false,
        };
        let v = range_values("r", &r(Scale::Linear, 0.1, 0.6, 6)).unwrap();
        assert_eq!(
            v,
            vec![
                json!(0.1),
                json!(0.2),
                json!(0.3),
                json!(0.4),
                json!(0.5),
                json!(0.6)
            ]
        );
        let v = range_values("r", &r(Scale::Log, 1.0, 1000.0, 4)).unwrap();
        assert_eq!(
            v,
            vec![json!(1.0), json!(10.0), json!(100.0), json!(1000.0)]
        );
        let v = range_values("r", &r(Scale::Log, 2.0, 5.0, 1)).unwrap();
        assert_eq!(v, vec![json!(2.0)]);
        let mut counts = r(Scale::Log, 100.0, 10000.0, 5);
        counts.integer = true;
        let v = range_values("r", &counts).unwrap();
        assert_eq!(
            v,
            vec![
                json!(100),
                json!(316),
                json!(1000),
                json!(3162),
                json!(10000)
            ]
        );
    }

    #[test]
    fn bad_ranges_name_the_field() {
        let e = range_values(
            "axes[1].range",
            &Range {
                from: 1.0,
                to: 2.0,
                count: 0,
                scale: Scale::Linear,
                integer: false,
            },
        )
        .unwrap_err();
        assert!(e.to_string().starts_with("axes[1].range.count:"), "{e}");
        let e = range_values(
            "axes[0].range",
            &Range {
                from: 0.0,
                to: 2.0,
                count: 3,
                scale: Scale::Log,
                integer: false,
            },
        )
        .unwrap_err();
        assert!(
            e.to_string().starts_with("axes[0].range.from: a log range"),
            "{e}"
        );
    }

    #[test]
    fn cross_varies_the_last_axis_fastest_and_zip_pairs() {
        let s = sweep(json!({"scenario": "x.json", "axes": [
            {"key": "a", "values": [1, 2]}, {"key": "b", "values": ["x", "y", "z"]}]}));
        let p = points(&s).unwrap();
        assert_eq!(p.len(), 6);
        assert_eq!(p[1], vec![json!(1), json!("y")]);
        assert_eq!(p[3], vec![json!(2), json!("x")]);
        let z = sweep(json!({"scenario": "x.json", "combine": "zip", "axes": [
            {"key": "a", "values": [1, 2]}, {"key": "b", "range": {"from": 5, "to": 6, "count": 2}}]}));
        assert_eq!(
            points(&z).unwrap(),
            vec![vec![json!(1), json!(5.0)], vec![json!(2), json!(6.0)]]
        );
        let bad = sweep(json!({"scenario": "x.json", "combine": "zip", "axes": [
            {"key": "a", "values": [1, 2]}, {"key": "b", "values": [1]}]}));
        let e = points(&bad).unwrap_err();
        assert!(e.to_string().starts_with("combine:"), "{e}");
    }

    #[test]
    fn axis_needs_exactly_one_source_and_a_path() {
        let s = sweep(json!({"scenario": "x.json", "axes": [{"key": "a"}]}));
        assert!(points(&s).unwrap_err().to_string().starts_with("axes[0]:"));
        let s = sweep(json!({"scenario": "x.json", "axes": [{"key": "a..b", "values": [1]}]}));
        assert!(points(&s)
            .unwrap_err()
            .to_string()
            .starts_with("axes[0].key:"));
        let s = sweep(json!({"scenario": "x.json", "axes": [
            {"key": "a", "values": [1]}, {"key": "a", "values": [2]}]}));
        assert!(points(&s)
            .unwrap_err()
            .to_string()
            .starts_with("axes[1].key:"));
    }
}
