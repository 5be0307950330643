//! Collecting a sweep's results into one table: `runs.csv` (one row per run: index, point, seed,
//! ending, the axes' values, the floor's drive, and the summary's scalar fields flattened with
//! dotted names such as `temperature.mean`) and `points.csv` (one row per point: the axes'
//! values, the drive, and for each numeric summary field its mean, standard error and count over
//! the point's completed runs).

use crate::error::{Error, Result};
use crate::studies::sweep::local::{run_dir, write_atomic};
use crate::studies::sweep::plan::{Plan, RunSpec};
use crate::studies::sweep::state_map::StatePoint;
use serde_json::Value;
use std::path::Path;

/// The drive's columns (present when the scene has a vibrating floor and gravity).
pub const DRIVE_COLUMNS: [&str; 4] = [
    "drive.amplitude",
    "drive.frequency",
    "drive.gamma",
    "drive.peak_velocity",
];

/// One run's row.
#[derive(Debug, Clone)]
pub struct RunRow {
    /// Run index.
    pub index: usize,
    /// Point number.
    pub point: usize,
    /// Seed (from the summary, else the plan).
    pub seed: Option<u64>,
    /// `completed`, `interrupted`, `event-limit`, `failed` (error.txt) or `missing`.
    pub ending: String,
    /// The summary's scalars by dotted name, sorted by name.
    pub fields: Vec<(String, Value)>,
}

/// Mean, standard error of the mean (sample standard deviation / √n; absent for n = 1) and
/// count of one field over a point's completed runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stat {
    /// Mean.
    pub mean: f64,
    /// Standard error of the mean.
    pub se: Option<f64>,
    /// Number of runs averaged.
    pub n: usize,
}

impl Stat {
    /// Statistics of `values` (None when empty).
    pub fn of(values: &[f64]) -> Option<Stat> {
        let n = values.len();
        if n == 0 {
            return None;
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        let se = (n > 1).then(|| {
            let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
            (var / n as f64).sqrt()
        });
        Some(Stat { mean, se, n })
    }
}

/// One point's row.
#[derive(Debug, Clone)]
pub struct PointRow {
    /// Point number.
    pub point: usize,
    /// Completed runs at this point.
    pub completed: usize,
    /// Statistics per numeric field (same order as [`Collected::numeric`]).
    pub stats: Vec<Option<Stat>>,
    /// The bed state most of the completed runs ended in (`state.name`), and how many did.
    pub state: Option<(String, usize)>,
}

/// Everything `collect` reads: the plan and every run's summary.
#[derive(Debug, Clone)]
pub struct Collected {
    /// The plan (`DIR/plan.json`).
    pub plan: Plan,
    /// One row per run, by index.
    pub runs: Vec<RunRow>,
    /// Summary field names (the union over runs), sorted by name.
    pub fields: Vec<String>,
    /// The numeric ones among them (the per-point statistics).
    pub numeric: Vec<String>,
    /// One row per point.
    pub points: Vec<PointRow>,
}

/// Appends the scalar leaves of `v` under `prefix` (objects flattened with dots; lists, such as
/// the height profiles, left out).
fn flatten(prefix: &str, v: &Value, out: &mut Vec<(String, Value)>) {
    match v {
        Value::Object(map) => {
            for (k, v) in map {
                let name = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                flatten(&name, v, out);
            }
        }
        Value::Array(_) | Value::Null => {}
        scalar => out.push((prefix.to_string(), scalar.clone())),
    }
}

/// Reads the plan and the summaries under `dir`: a row per run, the fields they hold, and
/// the statistics of each numeric field over each point's completed runs.
pub fn collect(dir: &Path) -> Result<Collected> {
    let plan = Plan::read(dir)?;
    let mut runs = Vec::with_capacity(plan.runs.len());
    let mut fields: Vec<String> = Vec::new();
    for spec in &plan.runs {
        let row = read_run(dir, spec)?;
        for (k, _) in &row.fields {
            if !fields.contains(k) {
                fields.push(k.clone());
            }
        }
        runs.push(row);
    }
    fields.sort();
    let numeric: Vec<String> = fields
        .iter()
        .filter(|f| {
            runs.iter()
                .any(|r| r.fields.iter().any(|(k, v)| k == *f && v.is_number()))
        })
        .cloned()
        .collect();
    let points = (0..plan.points)
        .map(|p| point_row(p, &runs, &numeric))
        .collect();
    Ok(Collected {
        plan,
        runs,
        fields,
        numeric,
        points,
    })
}

/// The row of one run: how it ended (`failed` when it left error.txt, `missing` when it left
/// nothing), its seed, and its summary's scalar fields.
fn read_run(dir: &Path, spec: &RunSpec) -> Result<RunRow> {
    let run = run_dir(dir, spec.index);
    let summary_path = run.join("summary.json");
    let (ending, flat) = match std::fs::read_to_string(&summary_path) {
        Ok(text) => {
            let summary: Value = serde_json::from_str(&text).map_err(|e| {
                Error::Io(format!("{}: not a summary: {e}", summary_path.display()))
            })?;
            let mut flat = Vec::new();
            flatten("", &summary, &mut flat);
            let ending = summary
                .get("ending")
                .and_then(Value::as_str)
                .unwrap_or("unknown")
                .to_string();
            (ending, flat)
        }
        Err(_) if run.join("error.txt").exists() => ("failed".into(), Vec::new()),
        Err(_) => ("missing".into(), Vec::new()),
    };
    let seed = flat
        .iter()
        .find(|(k, _)| k == "seed")
        .and_then(|(_, v)| v.as_u64())
        .or(spec.seed);
    let flat: Vec<(String, Value)> = flat
        .into_iter()
        .filter(|(k, _)| k != "seed" && k != "ending")
        .collect();
    Ok(RunRow {
        index: spec.index,
        point: spec.point,
        seed,
        ending,
        fields: flat,
    })
}

/// Point `p`'s row: each numeric field's statistics over the point's completed runs.
fn point_row(p: usize, runs: &[RunRow], numeric: &[String]) -> PointRow {
    let done: Vec<&RunRow> = runs
        .iter()
        .filter(|r| r.point == p && r.ending == "completed")
        .collect();
    let stats = numeric
        .iter()
        .map(|f| {
            let values: Vec<f64> = done
                .iter()
                .filter_map(|r| r.fields.iter().find(|(k, _)| k == f))
                .filter_map(|(_, v)| v.as_f64())
                .collect();
            Stat::of(&values)
        })
        .collect();
    PointRow {
        point: p,
        completed: done.len(),
        stats,
        state: most_frequent_state(&done),
    }
}

/// The `state.name` most of `runs` ended in (the first to reach the most, in run order), and
/// how many did; `None` if none has a state.
fn most_frequent_state(runs: &[&RunRow]) -> Option<(String, usize)> {
    let names: Vec<&str> = runs
        .iter()
        .filter_map(|r| r.fields.iter().find(|(k, _)| k == "state.name"))
        .filter_map(|(_, v)| v.as_str())
        .collect();
    let count = |n: &str| names.iter().filter(|m| **m == n).count();
    let best = names.iter().copied().max_by_key(|n| {
        // Ties go to the earliest run: a larger key for an earlier first appearance.
        let first = names.iter().position(|m| m == n).unwrap_or(0);
        (count(n), usize::MAX - first)
    })?;
    Some((best.to_string(), count(best)))
}

/// One CSV cell: quoted when it holds a comma, a quote or a line break.
fn cell(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A JSON value as a cell: strings without their quotes, other values as JSON.
fn value_cell(v: &Value) -> String {
    match v {
        Value::String(s) => cell(s),
        other => cell(&other.to_string()),
    }
}

/// A number as a cell, in the shortest form that reads back exactly (exponent for tiny and
/// huge values); empty when absent or not finite.
fn float_cell(x: Option<f64>) -> String {
    x.filter(|v| v.is_finite())
        .map_or(String::new(), |v| Value::from(v).to_string())
}

fn line(cells: Vec<String>) -> String {
    cells.join(",") + "\n"
}

impl Collected {
    /// Whether any run has a floor drive (adds the `drive.*` columns).
    fn has_drive(&self) -> bool {
        self.plan.runs.iter().any(|r| r.drive.is_some())
    }

    /// The drive's values at `point`, in the order of [`DRIVE_COLUMNS`].
    fn drive_cells(&self, point: usize) -> Vec<String> {
        let drive = self
            .plan
            .runs
            .iter()
            .find(|r| r.point == point)
            .and_then(|r| r.drive);
        match drive {
            Some(d) => [d.amplitude, d.frequency, d.gamma, d.peak_velocity]
                .iter()
                .map(|v| float_cell(Some(*v)))
                .collect(),
            None => vec![String::new(); DRIVE_COLUMNS.len()],
        }
    }

    /// The value of a point-level column (an axis key or a `drive.*` column) at `point`.
    pub fn point_value(&self, column: &str, point: usize) -> Option<f64> {
        let run = self.plan.runs.iter().find(|r| r.point == point)?;
        if let Some(k) = self.plan.axes.iter().position(|a| a == column) {
            return run.values.get(k)?.as_f64();
        }
        let d = run.drive?;
        match column {
            "drive.amplitude" => Some(d.amplitude),
            "drive.frequency" => Some(d.frequency),
            "drive.gamma" => Some(d.gamma),
            "drive.peak_velocity" => Some(d.peak_velocity),
            _ => None,
        }
    }

    /// The value of a point-level column at `point` as text (numbers as JSON writes them,
    /// strings bare; empty when absent), to group and label points by.
    pub fn point_cell(&self, column: &str, point: usize) -> String {
        let run = self.plan.runs.iter().find(|r| r.point == point);
        match self.plan.axes.iter().position(|a| a == column) {
            Some(k) => run
                .and_then(|r| r.values.get(k))
                .map_or(String::new(), value_cell),
            None => float_cell(self.point_value(column, point)),
        }
    }

    /// The values of numeric field `field` in `point`'s completed runs, in run order.
    pub fn run_values(&self, point: usize, field: &str) -> Vec<f64> {
        self.runs
            .iter()
            .filter(|r| r.point == point && r.ending == "completed")
            .filter_map(|r| r.fields.iter().find(|(k, _)| k == field))
            .filter_map(|(_, v)| v.as_f64())
            .collect()
    }

    /// Whether `column` is an axis key or (with a drive) a drive column.
    pub fn is_point_column(&self, column: &str) -> bool {
        self.plan.axes.iter().any(|a| a == column)
            || (self.has_drive() && DRIVE_COLUMNS.contains(&column))
    }

    /// Refuses `key`, given to `option`, unless it is a point-level column (an axis, or a drive
    /// column for a vibrating floor).
    pub fn require_axis(&self, option: &str, key: &str) -> Result<()> {
        if self.is_point_column(key) {
            return Ok(());
        }
        Err(Error::input(
            option,
            format!(
                "`{key}` is not an axis of this sweep (choose from: {})",
                self.point_columns().join(", ")
            ),
        ))
    }

    /// The point-level columns, for messages.
    pub fn point_columns(&self) -> Vec<String> {
        let mut cols = self.plan.axes.clone();
        if self.has_drive() {
            cols.extend(DRIVE_COLUMNS.iter().map(|c| c.to_string()));
        }
        cols
    }

    /// `runs.csv`.
    pub fn runs_csv(&self) -> String {
        let mut header: Vec<String> = ["index", "point", "seed", "ending"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        header.extend(self.plan.axes.iter().map(|a| cell(a)));
        if self.has_drive() {
            header.extend(DRIVE_COLUMNS.iter().map(|c| c.to_string()));
        }
        header.extend(self.fields.iter().map(|f| cell(f)));
        let mut out = line(header);
        for (r, spec) in self.runs.iter().zip(&self.plan.runs) {
            let mut row = vec![
                r.index.to_string(),
                r.point.to_string(),
                r.seed.map_or(String::new(), |s| s.to_string()),
                r.ending.clone(),
            ];
            row.extend(spec.values.iter().map(value_cell));
            if self.has_drive() {
                row.extend(self.drive_cells(r.point));
            }
            row.extend(self.fields.iter().map(|f| {
                r.fields
                    .iter()
                    .find(|(k, _)| k == f)
                    .map_or(String::new(), |(_, v)| value_cell(v))
            }));
            out.push_str(&line(row));
        }
        out
    }

    /// `points.csv`.
    pub fn points_csv(&self) -> String {
        let mut header = vec!["point".to_string()];
        header.extend(self.plan.axes.iter().map(|a| cell(a)));
        if self.has_drive() {
            header.extend(DRIVE_COLUMNS.iter().map(|c| c.to_string()));
        }
        header.push("completed".into());
        let states = self.points.iter().any(|p| p.state.is_some());
        if states {
            header.extend(["state".into(), "state:n".into()]);
        }
        for f in &self.numeric {
            for stat in ["mean", "se", "n"] {
                header.push(cell(&format!("{f}:{stat}")));
            }
        }
        let mut out = line(header);
        for p in &self.points {
            let mut row = vec![p.point.to_string()];
            if let Some(spec) = self.plan.runs.iter().find(|r| r.point == p.point) {
                row.extend(spec.values.iter().map(value_cell));
            }
            if self.has_drive() {
                row.extend(self.drive_cells(p.point));
            }
            row.push(p.completed.to_string());
            if states {
                let (name, n) = p.state.clone().unwrap_or_default();
                row.extend([cell(&name), n.to_string()]);
            }
            for s in &p.stats {
                row.push(float_cell(s.map(|s| s.mean)));
                row.push(float_cell(s.and_then(|s| s.se)));
                row.push(s.map_or("0".into(), |s| s.n.to_string()));
            }
            out.push_str(&line(row));
        }
        out
    }

    /// The statistics of numeric field `field` at each point, with the x value from `x`
    /// (points without completed runs or without an x value are left out).
    pub fn series(&self, x: &str, field: &str) -> Result<Vec<(f64, Stat)>> {
        let all: Vec<usize> = self.points.iter().map(|p| p.point).collect();
        self.series_of(x, field, &all)
    }

    /// [`series`](Self::series) over the points `points` only (a group).
    pub fn series_of(&self, x: &str, field: &str, points: &[usize]) -> Result<Vec<(f64, Stat)>> {
        self.require_axis("--x", x)?;
        let k = self
            .numeric
            .iter()
            .position(|f| f == field)
            .ok_or_else(|| {
                Error::input(
                    "--y",
                    format!(
                        "`{field}` is not a numeric summary field of these runs (e.g. {})",
                        self.numeric
                            .iter()
                            .filter(|f| !f.starts_with("events.") && !f.starts_with("energy."))
                            .take(8)
                            .cloned()
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            })?;
        let mut out: Vec<(f64, Stat)> = self
            .points
            .iter()
            .filter(|p| points.contains(&p.point))
            .filter_map(|p| Some((self.point_value(x, p.point)?, p.stats[k]?)))
            .collect();
        out.sort_by(|a, b| a.0.total_cmp(&b.0));
        Ok(out)
    }

    /// Each point's state over the axes `x` and `y` (the map `sweep collect --states` draws);
    /// points with no state or no value on an axis are left out.
    pub fn state_points(&self, x: &str, y: &str) -> Result<Vec<StatePoint>> {
        self.require_axis("--states", x)?;
        self.require_axis("--states", y)?;
        Ok(self
            .points
            .iter()
            .filter_map(|p| {
                let (state, n) = p.state.clone()?;
                Some(StatePoint {
                    at: (self.point_value(x, p.point)?, self.point_value(y, p.point)?),
                    state,
                    agree: (n, p.completed),
                })
            })
            .collect())
    }

    /// Writes `runs.csv` and `points.csv` into `dir`.
    pub fn write_tables(&self, dir: &Path) -> Result<()> {
        write_atomic(&dir.join("runs.csv"), &self.runs_csv())?;
        write_atomic(&dir.join("points.csv"), &self.points_csv())
    }

    /// The label of `point`: its axes' values, e.g. `floor.gamma=0.8, particles.count=60`.
    pub fn point_label(&self, point: usize) -> String {
        let values = self
            .plan
            .runs
            .iter()
            .find(|r| r.point == point)
            .map_or(&[][..], |r| &r.values[..]);
        crate::studies::sweep::plan::point_label(&self.plan.axes, values)
    }

    /// The points some of whose runs did not complete, each with a line that names it and says
    /// how its runs ended, e.g. `point 3 (floor.gamma=0.8): 0 of 2 runs completed (2
    /// event-limit)`; their statistics cover only their completed runs.
    pub fn incomplete(&self) -> Vec<(usize, String)> {
        self.points
            .iter()
            .filter_map(|p| {
                let runs: Vec<&RunRow> = self.runs.iter().filter(|r| r.point == p.point).collect();
                if p.completed == runs.len() {
                    return None;
                }
                let mut endings: Vec<(&str, usize)> = Vec::new();
                for r in runs.iter().filter(|r| r.ending != "completed") {
                    match endings.iter_mut().find(|(e, _)| *e == r.ending) {
                        Some((_, n)) => *n += 1,
                        None => endings.push((&r.ending, 1)),
                    }
                }
                let endings: Vec<String> =
                    endings.iter().map(|(e, n)| format!("{n} {e}")).collect();
                Some((
                    p.point,
                    format!(
                        "point {} ({}): {} of {} runs completed ({})",
                        p.point,
                        self.point_label(p.point),
                        p.completed,
                        runs.len(),
                        endings.join(", ")
                    ),
                ))
            })
            .collect()
    }

    /// The points where no completed run measured numeric field `field` (none completed, or
    /// the field is absent from their summaries): a fit of it leaves them out.
    pub fn left_out(&self, field: &str) -> Vec<usize> {
        let k = self.numeric.iter().position(|f| f == field);
        self.points
            .iter()
            .filter(|p| k.is_none_or(|k| p.stats[k].is_none()))
            .map(|p| p.point)
            .collect()
    }

    /// How many runs ended each way, e.g. `18 completed` or `16 completed, 2 missing`.
    pub fn endings(&self) -> String {
        let mut counts: Vec<(String, usize)> = Vec::new();
        for r in &self.runs {
            match counts.iter_mut().find(|(e, _)| *e == r.ending) {
                Some((_, n)) => *n += 1,
                None => counts.push((r.ending.clone(), 1)),
            }
        }
        counts
            .iter()
            .map(|(e, n)| format!("{n} {e}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn flattens_scalars_with_dotted_names_and_leaves_lists_out() {
        let mut out = Vec::new();
        flatten(
            "",
            &json!({"a": 1, "t": {"x": 0.5, "mean": 0.7}, "p": {"h": [1, 2], "top": 3}, "s": "x"}),
            &mut out,
        );
        let names: Vec<&str> = out.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(names, ["a", "p.top", "s", "t.mean", "t.x"]);
    }

    #[test]
    fn mean_and_standard_error() {
        let s = Stat::of(&[1.0, 2.0, 3.0]).unwrap();
        assert_eq!(s.mean, 2.0);
        assert!((s.se.unwrap() - (1.0f64 / 3.0).sqrt()).abs() < 1e-15);
        assert_eq!(s.n, 3);
        assert_eq!(Stat::of(&[4.0]).unwrap().se, None);
        assert!(Stat::of(&[]).is_none());
    }

    #[test]
    fn cells_are_quoted_when_needed() {
        assert_eq!(cell("a"), "a");
        assert_eq!(cell("a,b"), "\"a,b\"");
        assert_eq!(
            value_cell(&json!({"max": 2, "min": 1})),
            "\"{\"\"max\"\":2,\"\"min\"\":1}\""
        );
        assert_eq!(value_cell(&json!("walls")), "walls");
    }
}
