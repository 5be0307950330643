//! The scenario regression suite.
//!
//! Every `scenarios/*.json` (top level only) is run briefly through [`vibrobed::run::run`] and its
//! summary compared with the golden one in `scenarios/golden/<stem>.json`:
//!
//! ```json
//! { "overrides": ["run.duration=5", "run.warmup=1.25", "run.max_events=300000"],
//!   "summary": { … } }
//! ```
//!
//! The overrides (`--set` syntax) make the run short. The comparison skips what depends on the
//! machine (`wall_seconds`, `collisions_per_second`, `engine.bytes_per_disk`); integers must be
//! equal, floats equal to 1e-9 relative (1e-12 absolute), strings equal, lists of equal length,
//! objects with the same keys. Every difference is reported with its dotted path.
//!
//! Re-bless after an intended change of results with
//! `VIBROBED_BLESS=1 cargo test --release --test suite scenarios::`: golden files are rewritten, keeping their
//! overrides. A scenario without a golden file fails unless blessing; blessing creates one with
//! default overrides sized by measurement so that the run takes about [`TARGET_WALL_SECONDS`]
//! (see [`default_overrides`]).

use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Instant;
use vibrobed::run::{run, RunOptions};
use vibrobed::Scenario;

/// Summary fields that depend on the machine or the allocator, not on the physics.
const SKIPPED: &[&str] = &[
    "wall_seconds",
    "collisions_per_second",
    "engine.bytes_per_disk",
];

/// Relative tolerance on floats.
const REL_TOL: f64 = 1e-9;
/// Absolute tolerance on floats near zero.
const ABS_TOL: f64 = 1e-12;

/// Wall-clock time a new golden run is sized for (test build).
const TARGET_WALL_SECONDS: f64 = 0.3;
/// Event safety net added to new golden files.
const MAX_EVENTS: u64 = 300_000;
/// Fewest measurement samples after the warm-up a new golden run is given.
const MIN_SAMPLES: f64 = 20.0;

fn crate_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn blessing() -> bool {
    std::env::var("VIBROBED_BLESS").is_ok_and(|v| !v.is_empty() && v != "0")
}

/// The top-level scenario files, sorted.
fn scenario_files() -> Vec<PathBuf> {
    let dir = crate_dir().join("scenarios");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    files
}

fn stem(path: &Path) -> String {
    path.file_stem().unwrap().to_string_lossy().into_owned()
}

fn golden_path(stem: &str) -> PathBuf {
    crate_dir()
        .join("scenarios/golden")
        .join(format!("{stem}.json"))
}

/// A golden file: the overrides that make the run short, and the expected summary.
struct Golden {
    overrides: Vec<String>,
    summary: Value,
}

fn read_golden(path: &Path) -> Result<Option<Golden>, String> {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("cannot read {}: {e}", path.display())),
    };
    let v: Value =
        serde_json::from_str(&text).map_err(|e| format!("{} is not JSON: {e}", path.display()))?;
    let overrides = v["overrides"]
        .as_array()
        .and_then(|a| a.iter().map(|s| s.as_str().map(String::from)).collect())
        .ok_or_else(|| format!("{}: `overrides` must be a list of strings", path.display()))?;
    let summary = v
        .get("summary")
        .cloned()
        .ok_or_else(|| format!("{}: no `summary`", path.display()))?;
    Ok(Some(Golden { overrides, summary }))
}

fn write_golden(path: &Path, golden: &Golden) -> Result<(), String> {
    let mut summary = golden.summary.clone();
    for skipped in SKIPPED {
        remove_path(&mut summary, skipped);
    }
    let v = json!({ "overrides": golden.overrides, "summary": summary });
    let text = serde_json::to_string_pretty(&v).unwrap() + "\n";
    std::fs::create_dir_all(path.parent().unwrap())
        .and_then(|_| std::fs::write(path, text))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

fn remove_path(v: &mut Value, dotted: &str) {
    let (parents, last) = match dotted.rsplit_once('.') {
        Some((parents, last)) => (Some(parents), last),
        None => (None, dotted),
    };
    let mut node = v;
    for key in parents.into_iter().flat_map(|p| p.split('.')) {
        match node.get_mut(key) {
            Some(next) => node = next,
            None => return,
        }
    }
    if let Some(map) = node.as_object_mut() {
        map.remove(last);
    }
}

/// Runs a scenario file with overrides; returns the summary as JSON and the wall time.
fn run_scenario(text: &str, overrides: &[String]) -> Result<(Value, f64), String> {
    let scenario = Scenario::from_json_with_overrides(text, overrides)
        .map_err(|e| format!("scenario rejected with overrides {overrides:?}: {e}"))?;
    let clock = Instant::now();
    let summary = run(&scenario, RunOptions::default()).map_err(|e| format!("run failed: {e}"))?;
    let wall = clock.elapsed().as_secs_f64();
    let value = serde_json::to_value(&summary).map_err(|e| format!("summary: {e}"))?;
    Ok((value, wall))
}

/// `x` rounded down to 1, 2 or 5 times a power of ten.
fn round_down_nicely(x: f64) -> f64 {
    let p = 10f64.powf(x.log10().floor());
    let m = x / p;
    let nice = if m >= 5.0 {
        5.0
    } else if m >= 2.0 {
        2.0
    } else {
        1.0
    };
    // Printed through `{}` this gives e.g. `0.05`, not `0.05000000000000001`.
    format!("{:.1e}", nice * p).parse().unwrap()
}

/// `x` to three significant digits (so that overrides read `0.133`, not `0.13333333333333333`).
fn three_digits(x: f64) -> f64 {
    format!("{x:.2e}").parse().unwrap()
}

/// Events of every kind counted in a summary.
fn total_events(summary: &Value) -> u64 {
    summary["events"]
        .as_object()
        .map_or(0, |m| m.values().filter_map(Value::as_u64).sum())
}

/// Default overrides for a new golden file, found by measuring: a duration that runs in about
/// [`TARGET_WALL_SECONDS`] and well inside the event limit, the warm-up scaled alike, a sample
/// interval giving at least [`MIN_SAMPLES`] samples after the warm-up, and an event limit as a
/// safety net.
fn default_overrides(text: &str) -> Result<Vec<String>, String> {
    let full = Scenario::from_json(text).map_err(|e| format!("scenario rejected: {e}"))?;
    let (duration, warmup) = (full.run.duration, full.run.warmup);
    let sample_dt = full
        .output
        .sample_interval
        .or(full.output.frame_interval)
        .unwrap_or(duration / 200.0);
    let with = |d: f64| {
        let mut o = Vec::new();
        let w = three_digits(warmup * d / duration);
        if d < duration {
            o.push(format!("run.duration={d}"));
            o.push(format!("run.warmup={w}"));
        }
        // The default sample interval (duration/200) shrinks with the duration by itself.
        let explicit = full.output.sample_interval.or(full.output.frame_interval);
        if explicit.is_some() && (d - w) / sample_dt < MIN_SAMPLES {
            let dt = round_down_nicely((d - w) / MIN_SAMPLES);
            o.push(format!("output.sample_interval={dt}"));
        }
        o.push(format!("run.max_events={MAX_EVENTS}"));
        o
    };
    // Probe a hundredth of the run for its speed in simulated time per wall second and events
    // per simulated time.
    let (probe, wall) = run_scenario(text, &with(duration / 100.0))?;
    let reached = probe["sim_time"]
        .as_f64()
        .unwrap_or(0.0)
        .max(f64::MIN_POSITIVE);
    let by_wall = TARGET_WALL_SECONDS * reached / wall.max(1e-4);
    let by_events = 0.5 * MAX_EVENTS as f64 * reached / total_events(&probe).max(1) as f64;
    let mut d = round_down_nicely(by_wall.min(by_events).min(duration));
    // Event rates may grow as the bed settles: shorten until the run completes.
    for _ in 0..5 {
        let (summary, _) = run_scenario(text, &with(d))?;
        if summary["ending"] == "completed" {
            return Ok(with(d));
        }
        let reached = summary["sim_time"].as_f64().unwrap_or(0.0);
        d = round_down_nicely((0.5 * reached).clamp(0.01 * d, 0.5 * d));
    }
    Err(format!(
        "no short run completes within {MAX_EVENTS} events; write the overrides by hand"
    ))
}

/// Compares `actual` with `expected`, appending one line per difference.
fn compare(path: &str, expected: &Value, actual: &Value, diffs: &mut Vec<String>) {
    if SKIPPED.contains(&path) {
        return;
    }
    let show = |p: &str| {
        if p.is_empty() {
            "(root)".to_string()
        } else {
            p.to_string()
        }
    };
    let child = |key: &str| {
        if path.is_empty() {
            key.to_string()
        } else {
            format!("{path}.{key}")
        }
    };
    match (expected, actual) {
        (Value::Object(e), Value::Object(a)) => {
            for (key, ev) in e {
                match a.get(key) {
                    Some(av) => compare(&child(key), ev, av, diffs),
                    None if SKIPPED.contains(&child(key).as_str()) => {}
                    None => diffs.push(format!("{}: missing (expected {ev})", child(key))),
                }
            }
            for (key, av) in a {
                if !e.contains_key(key) && !SKIPPED.contains(&child(key).as_str()) {
                    diffs.push(format!("{}: unexpected field (got {av})", child(key)));
                }
            }
        }
        (Value::Array(e), Value::Array(a)) => {
            if e.len() != a.len() {
                diffs.push(format!(
                    "{}: list of {} entries, expected {}",
                    show(path),
                    a.len(),
                    e.len()
                ));
            } else {
                for (k, (ev, av)) in e.iter().zip(a).enumerate() {
                    compare(&child(&k.to_string()), ev, av, diffs);
                }
            }
        }
        (Value::Number(e), Value::Number(a)) => {
            let integer = |n: &serde_json::Number| n.is_u64() || n.is_i64();
            match (integer(e), integer(a)) {
                (true, true) => {
                    if e != a {
                        diffs.push(format!("{}: {a}, expected {e} (exactly)", show(path)));
                    }
                }
                (false, false) => {
                    let (ef, af) = (e.as_f64().unwrap(), a.as_f64().unwrap());
                    let tol = (REL_TOL * ef.abs().max(af.abs())).max(ABS_TOL);
                    if (ef - af).abs() > tol {
                        let rel = (ef - af).abs() / ef.abs().max(af.abs());
                        diffs.push(format!(
                            "{}: {af:e}, expected {ef:e} (relative difference {rel:.1e})",
                            show(path)
                        ));
                    }
                }
                _ => diffs.push(format!(
                    "{}: {a}, expected {e} (integer and float differ in kind)",
                    show(path)
                )),
            }
        }
        _ if expected == actual => {}
        _ => diffs.push(format!("{}: {actual}, expected {expected}", show(path))),
    }
}

/// Checks (or, when blessing, records) one scenario; returns its failures and wall time.
fn check_scenario(file: &Path, bless: bool) -> (Vec<String>, f64) {
    let stem = stem(file);
    let text = match std::fs::read_to_string(file) {
        Ok(text) => text,
        Err(e) => return (vec![format!("cannot read {}: {e}", file.display())], 0.0),
    };
    let golden_file = golden_path(&stem);
    let golden = match read_golden(&golden_file) {
        Ok(golden) => golden,
        Err(e) => return (vec![e], 0.0),
    };
    let overrides = match (&golden, bless) {
        (Some(g), _) => g.overrides.clone(),
        (None, true) => match default_overrides(&text) {
            Ok(o) => o,
            Err(e) => return (vec![e], 0.0),
        },
        (None, false) => {
            return (
                vec![format!(
                    "no golden summary {}; create it with `VIBROBED_BLESS=1 cargo test --release --test suite scenarios::`",
                    golden_file.display()
                )],
                0.0,
            )
        }
    };
    let (summary, wall) = match run_scenario(&text, &overrides) {
        Ok(r) => r,
        Err(e) => return (vec![e], 0.0),
    };
    if bless {
        let result = write_golden(&golden_file, &Golden { overrides, summary });
        return (result.err().into_iter().collect(), wall);
    }
    let mut diffs = Vec::new();
    compare("", &golden.unwrap().summary, &summary, &mut diffs);
    (diffs, wall)
}

#[test]
fn scenarios_match_their_golden_summaries() {
    let bless = blessing();
    let files = scenario_files();
    assert!(!files.is_empty(), "no scenarios/*.json found");
    let mut failures = Vec::new();
    for file in &files {
        let stem = stem(file);
        let (diffs, wall) = check_scenario(file, bless);
        eprintln!(
            "{stem}: {} in {wall:.2} s wall{}",
            if bless { "blessed" } else { "ran" },
            if diffs.is_empty() {
                String::new()
            } else {
                format!(", {} difference(s)", diffs.len())
            }
        );
        failures.extend(diffs.into_iter().map(|d| format!("{stem}: {d}")));
    }
    // Golden files whose scenario is gone.
    let stems: Vec<String> = files.iter().map(|f| stem(f)).collect();
    if let Ok(entries) = std::fs::read_dir(crate_dir().join("scenarios/golden")) {
        for entry in entries.flatten() {
            let p = entry.path();
            if p.extension().is_some_and(|e| e == "json") && !stems.contains(&stem(&p)) {
                failures.push(format!(
                    "{}: golden file without a scenario (delete it)",
                    p.display()
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} scenario difference(s) from the golden summaries \
         (re-bless intended changes with `VIBROBED_BLESS=1 cargo test --release --test suite scenarios::`):\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The comparison itself: what it tolerates and what it reports.
#[test]
fn comparison_reports_dotted_paths_and_honours_tolerances() {
    let expected = json!({
        "particles": 10,
        "wall_seconds": 1.0,
        "events": { "pair": 100, "floor": 3 },
        "energy": { "final": { "kinetic": 1.0, "potential": 0.0 } },
        "engine": { "bytes_per_disk": 100.0, "mask": "r3" },
        "profiles": { "density": [1.0, 2.0] },
        "ending": "completed"
    });
    let mut same = expected.clone();
    same["wall_seconds"] = json!(7.5);
    same["engine"]["bytes_per_disk"] = json!(99.0);
    same["energy"]["final"]["kinetic"] = json!(1.0 + 1e-12);
    same["energy"]["final"]["potential"] = json!(1e-13);
    let mut diffs = Vec::new();
    compare("", &expected, &same, &mut diffs);
    assert!(diffs.is_empty(), "{diffs:?}");

    let mut other: Value = expected.clone();
    other["events"]["pair"] = json!(101);
    other["energy"]["final"]["kinetic"] = json!(1.0 + 1e-6);
    other["profiles"]["density"] = json!([1.0]);
    other["ending"] = json!("event-limit");
    other["particles"] = json!(10.0);
    other
        .as_object_mut()
        .unwrap()
        .insert("extra".into(), json!(1));
    other["engine"].as_object_mut().unwrap().remove("mask");
    let mut diffs = Vec::new();
    compare("", &expected, &other, &mut diffs);
    let text = diffs.join("\n");
    for path in [
        "events.pair:",
        "energy.final.kinetic:",
        "profiles.density:",
        "ending:",
        "particles:",
        "extra:",
        "engine.mask:",
    ] {
        assert!(text.contains(path), "no report for {path}:\n{text}");
    }
    assert_eq!(diffs.len(), 7, "{text}");
}

#[test]
fn nice_rounding() {
    assert_eq!(round_down_nicely(0.37), 0.2);
    assert_eq!(round_down_nicely(7.9), 5.0);
    assert_eq!(round_down_nicely(1.0), 1.0);
    assert_eq!(round_down_nicely(23.0), 20.0);
    assert_eq!(format!("{}", round_down_nicely(0.06)), "0.05");
}
