//! Structure-aware fuzzing of the scenario on the real binary: every shipped scene, each of its
//! fields (and the optional fields it leaves out) set in turn to values near its own, to the
//! ends of double precision and to the checks' limits and one past them; then pairs of such
//! changes. `check` and a short `run` must end with an exit code of the contract (0; 2 naming
//! the field, nothing written; for `run`, 6 for a run that stalled, 4 and 5 for one stopped by
//! its event or wall-clock limit, its summary saying so) in bounded memory (the guard's
//! address-space cap) — never a panic, an abort or a signal — or, still running after
//! [`INTERRUPT_AFTER`], stop on SIGINT.
//!
//! The cases come in a fixed order (every field of every scene before any field's second
//! value; pairs drawn from a seeded generator) and run until a time budget is spent
//! ([`DEFAULT_SECONDS`] per command; see [`crate::fuzz_budget`]); `VIBROBED_FUZZ_SEED` draws
//! other pairs. A failing case is reported with the command line that reproduces it. Every case, and
//! many more pairs, also go through the checks in this process (no engine built), which takes
//! seconds: the checks' whole reach is covered on every run of the suite.

use crate::fuzz_budget::Budget;
use crate::guarded;

use guarded::{entries, error_field, error_line, Limits, Outcome};
use serde_json::Value;
use std::ffi::OsString;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use vibrobed::error::Error;
use vibrobed::scenario::checks::{
    MAX_CHECKPOINTS, MAX_DISKS, MAX_FIELD_BINS, MAX_FIELD_CELLS, MAX_LENGTH_RATIO, MAX_MAGNITUDE,
    MAX_OUTPUT_TIMES, MAX_PHASE_BINS, MAX_PROFILE_BINS, MAX_STEPS, MAX_STRIPS, MAX_THREADS,
    MAX_TRAVEL, MAX_WALL_SECONDS, MIN_INERTIA_FACTOR, MIN_MAGNITUDE,
};
use vibrobed::scenario::work::Work;
use vibrobed::scenario::Scenario;

/// Seconds of cases per command when `VIBROBED_FUZZ_SECONDS` is not set (as in CI): some 1500
/// `check` and 1500 `run` cases of 8366, every field of every scene changed at least once; the
/// checks see every case in process anyway.
const DEFAULT_SECONDS: u64 = 45;

/// A case still running after this long is sent SIGINT (then SIGKILL 5 s later). A refusal or a
/// short run takes well under a second; a legal scene that takes longer must stop on SIGINT.
const INTERRUPT_AFTER: Duration = Duration::from_secs(8);

/// Optional fields a scene may leave out, with a valid-looking value to switch them on.
const OPTIONAL: &[(&str, &str)] = &[
    ("gravity", "1"),
    ("domain.height", "40"),
    ("domain.exit_height", "30"),
    ("domain.wall_friction", "0.5"),
    ("domain.wall_tangential_restitution", "0.4"),
    ("floor.friction", "0.5"),
    ("floor.tangential_restitution", "0.4"),
    ("floor.orifice", r#"{"from": 4, "to": 8}"#),
    ("particles.mass", "1"),
    ("particles.density", "1"),
    ("particles.packing_fraction", "0.5"),
    ("particles.inertia_factor", "0.5"),
    ("particles.rotational_temperature", "0.5"),
    ("collisions.tc", "0.001"),
    ("collisions.speed_cutoff", "0.01"),
    ("collisions.friction", "0.5"),
    ("collisions.tangential_restitution", "0.4"),
    ("run.max_events", "1000"),
    ("run.max_wall_seconds", "100"),
    ("output.sample_interval", "0.01"),
    ("output.trajectory_interval", "0.01"),
    ("output.field_bins", "[10, 10]"),
    ("output.field_height", "10"),
    ("output.phase_bins", "20"),
    ("output.profile_bins", "40"),
    ("engine.threads", "1"),
    ("engine.strips", "2"),
    ("engine.dt", "0.001"),
    (
        "inlets",
        r#"[{"x": {"from": 1, "to": 9}, "y": {"from": 20, "to": 22}, "rate": 10}]"#,
    ),
];

/// The limits that follow the scene's duration `d` and smallest radius `a` (as the scene gives
/// them), at the limit and one part in 10¹⁵ either side.
fn scene_limits(d: f64, a: f64) -> Vec<(&'static str, Vec<String>)> {
    let just = |v: f64| {
        vec![
            format!("{v:e}"),
            format!("{:e}", v * (1.0 + 1e-15)),
            format!("{:e}", v * (1.0 - 1e-15)),
        ]
    };
    vec![
        ("output.frame_interval", just(d / MAX_OUTPUT_TIMES)),
        ("output.sample_interval", just(d / MAX_OUTPUT_TIMES)),
        ("output.trajectory_interval", just(d / MAX_OUTPUT_TIMES)),
        ("engine.dt", just(d / MAX_STEPS)),
        ("domain.width", just(MAX_LENGTH_RATIO * a)),
        ("domain.height", just(MAX_LENGTH_RATIO * a)),
        ("floor.amplitude", just(MAX_LENGTH_RATIO * a)),
        ("particles.temperature", just((MAX_TRAVEL * a / d).powi(2))),
        ("inlets.0.speed", just(MAX_TRAVEL * a / d)),
        ("--checkpoint-every", just(d / MAX_CHECKPOINTS)),
    ]
}

/// The duration of the most disk crossings a run may ask for (`checks::MAX_WORK`, as the
/// checks estimate them), and one part in 10¹⁵ either side; none for a scene that does not
/// load or where nothing moves.
fn work_limit(scene: &Value) -> Option<(&'static str, Vec<String>)> {
    let s = Scenario::from_json_with_overrides(&scene.to_string(), &[]).ok()?;
    let d = Work::of(&s).longest_duration();
    d.is_finite().then(|| {
        let values = [1.0, 1.0 + 1e-15, 1.0 - 1e-15].map(|f| format!("{:e}", d * f));
        ("run.duration", values.to_vec())
    })
}

/// The checks' limits, and one past them, for the fields they bound.
fn limits() -> Vec<(&'static str, Vec<String>)> {
    let around = |v: f64| vec![v.to_string(), (v + 1.0).to_string(), (v - 1.0).to_string()];
    let just = |v: f64| {
        vec![
            format!("{v:e}"),
            format!("{:e}", v * (1.0 + 1e-15)),
            format!("{:e}", v * (1.0 - 1e-15)),
        ]
    };
    vec![
        // Only past the limit: 2·10⁷ disks are a legal scene whose placement and build take
        // minutes and more memory than the guard allows (a run interrupted while it builds
        // ends at once: bad_input's `a_run_interrupted_while_its_scene_is_built…`).
        ("particles.count", vec![(MAX_DISKS + 1).to_string()]),
        ("output.profile_bins", around(MAX_PROFILE_BINS as f64)),
        ("output.phase_bins", around(MAX_PHASE_BINS as f64)),
        ("engine.threads", around(MAX_THREADS as f64)),
        ("engine.strips", around(MAX_STRIPS as f64)),
        (
            "output.field_bins",
            vec![
                format!("[{MAX_FIELD_BINS}, 1]"),
                format!("[{}, 1]", MAX_FIELD_BINS + 1),
                format!("[{}, {}]", MAX_FIELD_CELLS / 1000, 1000),
                format!("[{}, {}]", MAX_FIELD_CELLS / 1000 + 1, 1000),
            ],
        ),
        ("particles.inertia_factor", just(MIN_INERTIA_FACTOR)),
        ("particles.inertia_factor", just(1.0)),
        ("collisions.restitution", just(1.0)),
        ("domain.width", just(MAX_MAGNITUDE)),
        ("particles.radius", just(MIN_MAGNITUDE)),
        ("particles.temperature", just(MAX_MAGNITUDE)),
        ("inlets.0.count", around(MAX_DISKS as f64)),
        ("inlets.0.speed", just(MAX_MAGNITUDE)),
        ("output.frame_interval", just(1e-7)),
        ("--checkpoint-every", just(1.0 / MAX_CHECKPOINTS)),
        ("run.max_wall_seconds", just(MAX_WALL_SECONDS)),
    ]
}

/// Values tried in a numeric field that holds `x`.
fn near(x: f64) -> Vec<String> {
    let mut v: Vec<f64> = vec![
        0.0,
        -x,
        x * (1.0 + 1e-15),
        x * 1e6,
        x / 1e6,
        MIN_MAGNITUDE / 10.0,
        MAX_MAGNITUDE * 10.0,
        5e-324,
        1.7e308,
    ];
    v.dedup();
    let mut out: Vec<String> = v.into_iter().map(|y| format!("{y:e}")).collect();
    out.extend(["\"NaN\"".into(), "null".into()]);
    out
}

/// One change: a field (or `--checkpoint-every`) and the JSON text it is set to.
#[derive(Debug, Clone)]
struct Change {
    field: String,
    value: String,
}

/// The numeric leaves of `v` (dotted paths and values), lists looked into.
fn leaves(v: &Value, path: &str, out: &mut Vec<(String, f64)>) {
    let join = |k: &str| {
        if path.is_empty() {
            k.to_string()
        } else {
            format!("{path}.{k}")
        }
    };
    match v {
        Value::Number(n) => out.push((path.to_string(), n.as_f64().unwrap_or(0.0))),
        Value::Object(map) => map.iter().for_each(|(k, x)| leaves(x, &join(k), out)),
        Value::Array(items) => items
            .iter()
            .enumerate()
            .take(2)
            .for_each(|(i, x)| leaves(x, &join(&i.to_string()), out)),
        _ => {}
    }
}

/// Single changes of one scene, field by field: its numbers near and far, the optional fields
/// it leaves out switched on, the limits ±1. They come value by value across the fields (each
/// field's first value, then each field's second, …), so that a budget that ends early has
/// still changed every field.
fn singles(scene: &Value) -> Vec<Change> {
    let mut numbers = Vec::new();
    leaves(scene, "", &mut numbers);
    let change = |field: &str, value: String| Change {
        field: field.to_string(),
        value,
    };
    let mut per_field: Vec<Vec<Change>> = Vec::new();
    for (field, x) in numbers {
        per_field.push(near(x).into_iter().map(|v| change(&field, v)).collect());
    }
    for (field, value) in OPTIONAL {
        per_field.push(vec![change(field, value.to_string())]);
    }
    let duration = scene["run"]["duration"].as_f64().unwrap_or(1.0);
    let radius = scene["particles"]["radius"].as_f64().unwrap_or(0.5);
    let limits = limits()
        .into_iter()
        .chain(scene_limits(duration, radius))
        .chain(work_limit(scene));
    for (field, values) in limits {
        per_field.push(values.into_iter().map(|v| change(field, v)).collect());
    }
    interleave(&per_field)
}

/// The first item of each list, then the second of each, and so on.
fn interleave<T: Clone>(lists: &[Vec<T>]) -> Vec<T> {
    let longest = lists.iter().map(Vec::len).max().unwrap_or(0);
    (0..longest)
        .flat_map(|k| lists.iter().filter_map(move |l| l.get(k).cloned()))
        .collect()
}

/// The shipped top-level scenarios, sorted, with their JSON.
fn shipped() -> Vec<(PathBuf, Value)> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(guarded::crate_root().join("scenarios"))
        .expect("scenarios/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "json") && p.is_file())
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("a shipped scenario");
            (p, serde_json::from_str(&text).expect("JSON"))
        })
        .collect()
}

/// Seeded pairs of changes the commands are given after the single changes.
const PAIRS: usize = 4096;

/// Seeded pairs of changes checked in process (a few seconds).
const PAIRS_IN_PROCESS: usize = 100_000;

/// The cases in order: every scene's single changes taken round-robin (so that each scene's
/// first changes come before any scene's last), then `pairs` pairs from a seeded generator.
fn cases(scenes: &[(PathBuf, Value)], seed: u64, pairs: usize) -> Vec<(usize, Vec<Change>)> {
    let per_scene: Vec<Vec<(usize, Vec<Change>)>> = scenes
        .iter()
        .enumerate()
        .map(|(s, (_, v))| singles(v).into_iter().map(|c| (s, vec![c])).collect())
        .collect();
    let mut out = interleave(&per_scene);
    let per_scene: Vec<Vec<Change>> = scenes.iter().map(|(_, v)| singles(v)).collect();
    let mut state = seed | 1;
    let mut next = |n: usize| {
        // xorshift64*: a fixed, dependency-free sequence.
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 33) as usize % n.max(1)
    };
    for _ in 0..pairs {
        let s = next(scenes.len());
        let list = &per_scene[s];
        let (a, b) = (
            list[next(list.len())].clone(),
            list[next(list.len())].clone(),
        );
        out.push((s, vec![a, b]));
    }
    out
}

/// Which command a case runs.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Command {
    Check,
    Run,
}

/// The command line of one case.
fn command_line(cmd: Command, scene: &Path, changes: &[Change]) -> Vec<String> {
    let mut args: Vec<String> = match cmd {
        Command::Check => vec!["check".into(), scene.display().to_string()],
        Command::Run => [
            "run",
            &scene.display().to_string(),
            "--quiet",
            "--summary",
            "summary.json",
            "--set",
            "run.duration=0.05",
            "--set",
            "run.warmup=0",
            "--set",
            "run.max_events=100000",
        ]
        .map(String::from)
        .to_vec(),
    };
    for c in changes {
        if c.field == "--checkpoint-every" {
            if cmd == Command::Run {
                args.extend(["--checkpoint".into(), "c.ckpt".into()]);
                args.extend([c.field.clone(), c.value.clone()]);
            }
            continue;
        }
        args.extend(["--set".into(), format!("{}={}", c.field, c.value)]);
    }
    args
}

/// What is wrong with one finished case (None: within the contract).
fn judge(cmd: Command, out: &Outcome, dir: &Path) -> Option<String> {
    let written = entries(dir);
    let mut problems: Vec<String> = Vec::new();
    if out.panicked() {
        problems.push("panicked or aborted".into());
    }
    if out.killed {
        problems.push("did not stop within 5 s of SIGINT".into());
    } else if let Some(sig) = out.signal() {
        // `check` keeps SIGINT's default: Ctrl-C ends it at once, which is all it need do.
        let stopped = cmd == Command::Check && sig == 2 && out.interrupted_at.is_some();
        if !stopped {
            problems.push(format!("ended by signal {sig}"));
        } else if !written.is_empty() {
            problems.push(format!(
                "stopped by SIGINT but files were written: {written:?}"
            ));
        }
    }
    let early = (cmd == Command::Run)
        .then(|| out.ended_early(dir))
        .flatten();
    match out.code() {
        Some(0) if cmd == Command::Run => {
            let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap_or_default();
            if serde_json::from_str::<Value>(&summary).is_err() {
                problems.push("exit 0 without a summary".into());
            }
        }
        Some(0) => {}
        // Stopped by `run.max_events` (each case sets it) or `run.max_wall_seconds`, or by a
        // stalled clock.
        Some(_) if early.is_some() => problems.extend(early.and_then(Result::err)),
        Some(2) => {
            let located = error_line(&out.stderr)
                .is_some_and(|l| l.contains("field `") || l.contains(" at line "));
            if error_field(&out.stderr).is_none() && !located {
                problems.push(format!(
                    "exit 2 naming no field: {:?}",
                    error_line(&out.stderr)
                ));
            }
            if !written.is_empty() {
                problems.push(format!("exit 2 but files were written: {written:?}"));
            }
        }
        Some(130) if cmd == Command::Run && out.interrupted_at.is_some() => {}
        Some(code) => problems.push(format!("exit code {code} is not in the contract")),
        None => {}
    }
    (!problems.is_empty()).then(|| problems.join("; "))
}

fn env_number(name: &str) -> Option<u64> {
    let text = std::env::var(name).ok()?;
    Some(
        text.trim()
            .parse()
            .unwrap_or_else(|_| panic!("{name}={text} is not a number")),
    )
}

/// Runs the cases of `cmd` until the budget is spent; panics listing the failures.
fn fuzz(cmd: Command) {
    let budget = Budget::from_env(DEFAULT_SECONDS);
    let seed = env_number("VIBROBED_FUZZ_SEED").unwrap_or(0x62);
    let scenes = shipped();
    let all = cases(&scenes, seed, PAIRS);
    let name = format!("{cmd:?}").to_lowercase();
    let root = guarded::fresh_dir(&format!("fuzz-fields-{name}"));
    let mut failures = String::new();
    let mut tally: std::collections::BTreeMap<String, usize> = Default::default();
    let mut ran = 0;
    for (i, (s, changes)) in all.iter().enumerate() {
        if budget.spent() {
            break;
        }
        let dir = root.join(format!("case-{i:05}"));
        std::fs::create_dir_all(&dir).expect("case directory");
        let args = command_line(cmd, &scenes[*s].0, changes);
        let os_args: Vec<OsString> = args.iter().map(OsString::from).collect();
        let logs = dir.with_extension("logs");
        let out = guarded::run(
            &os_args,
            &dir,
            &logs,
            Limits {
                interrupt_after: INTERRUPT_AFTER,
                kill_after: Duration::from_secs(5),
            },
        );
        ran += 1;
        *tally
            .entry(out.code().map_or("signal".into(), |c| format!("exit {c}")))
            .or_default() += 1;
        if let Some(why) = judge(cmd, &out, &dir) {
            let _ = writeln!(
                failures,
                "\n=== case #{i}: {why}\nvibrobed {}\n{}",
                args.join(" "),
                out.describe()
            );
        } else {
            let _ = std::fs::remove_dir_all(&dir);
        }
        let _ = std::fs::remove_dir_all(&logs);
    }
    budget.report(
        &format!("fuzz fields {name} (seed {seed:#x})"),
        ran,
        all.len(),
        &format!("{tally:?}"),
    );
    assert!(failures.is_empty(), "fuzz fields {name}:{failures}");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn every_field_changed_and_paired_is_checked_within_the_contract() {
    fuzz(Command::Check);
}

#[test]
fn every_field_changed_and_paired_runs_within_the_contract() {
    fuzz(Command::Run);
}

/// Every single change of every scene and [`PAIRS_IN_PROCESS`] seeded pairs, each scene read
/// and checked in this process, without building the engine: the checks' whole reach in a few
/// seconds (the commands above run as many of the same cases as their budget allows, on the
/// binary). A case must be accepted, or refused naming a field (or, for malformed JSON, where);
/// never a panic.
#[test]
fn every_field_changed_and_paired_is_refused_by_name_or_accepted_by_the_checks() {
    let seed = env_number("VIBROBED_FUZZ_SEED").unwrap_or(0x62);
    let scenes = shipped();
    let texts: Vec<String> = scenes
        .iter()
        .map(|(p, _)| std::fs::read_to_string(p).expect("a shipped scenario"))
        .collect();
    let start = Instant::now();
    let all = cases(&scenes, seed, PAIRS_IN_PROCESS);
    let (mut accepted, mut refused) = (0, 0);
    let mut failures = String::new();
    for (i, (s, changes)) in all.iter().enumerate() {
        let sets: Vec<String> = changes
            .iter()
            .filter(|c| c.field != "--checkpoint-every")
            .map(|c| format!("{}={}", c.field, c.value))
            .collect();
        let got =
            std::panic::catch_unwind(|| Scenario::from_json_with_overrides(&texts[*s], &sets));
        let why = match got {
            Err(_) => Some("panicked".to_string()),
            Ok(Ok(_)) => {
                accepted += 1;
                None
            }
            Ok(Err(Error::Input { field, message }))
                if !field.is_empty() || message.contains(" at line ") =>
            {
                refused += 1;
                None
            }
            Ok(Err(e)) => Some(format!("refused naming no field: {e}")),
        };
        if let Some(why) = why {
            let _ = writeln!(
                failures,
                "\n=== case #{i}: {why}\nvibrobed check {} --set {}",
                scenes[*s].0.display(),
                sets.join(" --set ")
            );
        }
    }
    eprintln!(
        "fuzz fields in process: {} cases in {:.1} s: {accepted} accepted, {refused} refused",
        all.len(),
        start.elapsed().as_secs_f64()
    );
    assert!(failures.is_empty(), "fuzz fields in process:{failures}");
}
