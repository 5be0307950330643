//! Fuzzing the scenario input on the real binary: the shipped scenarios, mutated (wrong types,
//! extreme numbers, "NaN" and infinities, missing and unknown fields, odd and malformed `--set`
//! overrides), are given to `vibrobed check` and to a short `vibrobed run`. Whatever the input,
//! the binary must end by itself, or stop on SIGINT, with an exit code of its contract:
//! 0, or 2 with an error naming the field and nothing written; for `run`, 4 and 5 for one
//! stopped by its event or wall-clock limit (its summary saying so) and 6 for one whose clock
//! stalled; never a panic, an abort or a signal.
//!
//! Seeded and short by default; `VIBROBED_FUZZ_CASES=N` runs N cases per command and
//! `VIBROBED_FUZZ_SEED=S` draws another set of cases. Every case runs in a fresh temporary
//! directory, kept (and named in the failure message) when the case fails.

use crate::guarded;

use guarded::{entries, error_field, error_line, Limits, Outcome};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use serde_json::Value;
use std::ffi::OsString;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Cases per command when `VIBROBED_FUZZ_CASES` is not set.
const DEFAULT_CASES: u32 = 64;

/// Seed when `VIBROBED_FUZZ_SEED` is not set.
const DEFAULT_SEED: u64 = 0x5eed_b0de;

/// A case that has not ended after this long is sent SIGINT (then SIGKILL 5 s later).
const INTERRUPT_AFTER: Duration = Duration::from_secs(20);

/// Every field of a scenario (src/scenario/mod.rs), the optional ones included, with list items
/// (`every_scenario_field_is_fuzzed` checks it against the scenario's schema).
const FIELDS: &[&str] = &[
    "name",
    "seed",
    "gravity",
    "domain",
    "domain.width",
    "domain.height",
    "domain.x_boundary",
    "domain.y_boundary",
    "domain.wall_restitution",
    "domain.wall_friction",
    "domain.wall_tangential_restitution",
    "domain.exit_height",
    "floor",
    "floor.restitution",
    "floor.amplitude",
    "floor.gamma",
    "floor.frequency",
    "floor.phase",
    "floor.waveform",
    "floor.model",
    "floor.friction",
    "floor.tangential_restitution",
    "floor.orifice",
    "floor.orifice.from",
    "floor.orifice.to",
    "particles",
    "particles.count",
    "particles.radius",
    "particles.radius.min",
    "particles.radius.max",
    "particles.radius.species",
    "particles.radius.species.0",
    "particles.radius.species.0.count",
    "particles.radius.species.0.radius",
    "particles.radius.species.0.mass",
    "particles.radius.species.1.count",
    "particles.mass",
    "particles.density",
    "particles.packing_fraction",
    "particles.placement",
    "particles.placement.positions",
    "particles.placement.positions.0",
    "particles.placement.positions.0.1",
    "particles.placement.velocities",
    "particles.placement.velocities.0.0",
    "particles.temperature",
    "particles.inertia_factor",
    "particles.rotational_temperature",
    "collisions",
    "collisions.restitution",
    "collisions.tc",
    "collisions.speed_cutoff",
    "collisions.resting_contacts",
    "collisions.friction",
    "collisions.tangential_restitution",
    "run",
    "run.duration",
    "run.warmup",
    "run.max_events",
    "run.max_wall_seconds",
    "output",
    "output.frame_interval",
    "output.sample_interval",
    "output.profile_bins",
    "output.profile_height",
    "output.rrd",
    "output.color_by",
    "output.speed_scale",
    "output.spin_scale",
    "output.trajectory",
    "output.trajectory_interval",
    "output.field_bins",
    "output.field_height",
    "output.phase_bins",
    "output.record_fields",
    "output.velocity_distribution",
    "engine",
    "engine.scheme",
    "engine.mask",
    "engine.skin",
    "engine.grid",
    "engine.check_invariants",
    "engine.dt",
    "engine.verlet_skin",
    "engine.sync_distance",
    "engine.cell_size",
    "engine.queue",
    "engine.remap",
    "engine.renumber",
    "engine.strips",
    "engine.threads",
    "inlets",
    "inlets.0.count",
    "inlets.0.density",
    "inlets.0.end",
    "inlets.0.mass",
    "inlets.0.radius",
    "inlets.0.radius.max",
    "inlets.0.radius.min",
    "inlets.0.radius.species",
    "inlets.0.radius.species.0.count",
    "inlets.0.radius.species.0.mass",
    "inlets.0.radius.species.0.radius",
    "inlets.0.rate",
    "inlets.0.recycle",
    "inlets.0.speed",
    "inlets.0.start",
    "inlets.0.temperature",
    "inlets.0.x",
    "inlets.0.x.from",
    "inlets.0.x.to",
    "inlets.0.y",
    "inlets.0.y.from",
    "inlets.0.y.to",
];

/// The objects of a scenario, where an unknown field can be added.
const OBJECTS: &[&str] = &[
    "",
    "domain",
    "floor",
    "particles",
    "particles.radius",
    "particles.radius.species.0",
    "particles.placement",
    "collisions",
    "run",
    "output",
    "engine",
];

/// Values, as JSON text (or not: `NaN`, `inf`), that a mutation puts in a field.
const VALUES: &[&str] = &[
    // Wrong types.
    "null",
    "true",
    "false",
    "\"\"",
    "\"abc\"",
    "[]",
    "[1, 2]",
    "[[1e300, 1]]",
    "{}",
    "{\"x\": 1}",
    // Not numbers, spelt as numbers.
    "\"NaN\"",
    "\"inf\"",
    "\"-inf\"",
    "NaN",
    "inf",
    "-inf",
    // Extremes.
    "0",
    "-0.0",
    "-1",
    "1e-300",
    "-1e-300",
    "5e-324",
    "1e300",
    "-1e300",
    "1.8e308",
    "-1.8e308",
    "9223372036854775807",
    "-9223372036854775808",
    "18446744073709551615",
    "18446744073709551616",
    "4294967296",
    "2147483648",
    "1000000000000",
    "1e12",
    "1e-7",
    "1e18",
    // Ordinary values, which may be valid where they land.
    "0.5",
    "1",
    "2",
    "3.5",
    "40",
    "1000",
    // The names the enums know, in the wrong places or the right ones.
    "\"periodic\"",
    "\"lid\"",
    "\"walls\"",
    "\"open\"",
    "\"time-step\"",
    "\"space-time\"",
    "\"hashed\"",
    "\"dense\"",
    "\"r10\"",
    "\"lattice\"",
    "\"sawtooth\"",
    "\"fixed-position\"",
    "\"species\"",
    // Structured values of the untagged fields.
    "{\"min\": 0.1, \"max\": 5}",
    "{\"min\": 1, \"max\": 0.5}",
    "{\"species\": [{\"count\": 3, \"radius\": 0.5}]}",
    "{\"species\": []}",
    "{\"species\": [{\"count\": 18446744073709551615, \"radius\": 0.5}, {\"count\": 2, \"radius\": 0.5}]}",
    "{\"positions\": [[1, 1]]}",
    "{\"positions\": [[1, 1], [1, 1]]}",
];

/// The numeric fields: most mutations put a number in one of them, so that many cases get past
/// the typing of the scenario and reach its checks, the scene and the engine.
const NUMERIC_FIELDS: &[&str] = &[
    "seed",
    "gravity",
    "domain.width",
    "domain.height",
    "domain.wall_restitution",
    "domain.wall_friction",
    "domain.wall_tangential_restitution",
    "domain.exit_height",
    "floor.restitution",
    "floor.amplitude",
    "floor.gamma",
    "floor.frequency",
    "floor.phase",
    "floor.friction",
    "floor.tangential_restitution",
    "floor.orifice.from",
    "floor.orifice.to",
    "particles.count",
    "particles.radius",
    "particles.radius.species.0.count",
    "particles.radius.species.0.radius",
    "particles.radius.species.0.mass",
    "particles.mass",
    "particles.density",
    "particles.packing_fraction",
    "particles.placement.positions.0.1",
    "particles.placement.velocities.0.0",
    "particles.temperature",
    "particles.inertia_factor",
    "particles.rotational_temperature",
    "collisions.restitution",
    "collisions.tc",
    "collisions.speed_cutoff",
    "collisions.friction",
    "collisions.tangential_restitution",
    "run.duration",
    "run.warmup",
    "run.max_events",
    "run.max_wall_seconds",
    "output.frame_interval",
    "output.sample_interval",
    "output.profile_bins",
    "output.profile_height",
    "output.speed_scale",
    "output.spin_scale",
    "output.trajectory_interval",
    "output.field_height",
    "output.phase_bins",
    "engine.skin",
    "engine.dt",
    "engine.verlet_skin",
    "engine.sync_distance",
    "engine.cell_size",
    "engine.strips",
    "engine.threads",
    "inlets.0.count",
    "inlets.0.rate",
    "inlets.0.speed",
    "inlets.0.temperature",
    "inlets.0.start",
    "inlets.0.end",
    "inlets.0.mass",
    "inlets.0.radius",
    "inlets.0.x.from",
    "inlets.0.y.to",
];

/// Numbers, extreme and ordinary, as JSON text.
const NUMBERS: &[&str] = &[
    "0",
    "-1",
    "1e-300",
    "5e-324",
    "1e300",
    "1.8e308",
    "18446744073709551615",
    "9223372036854775807",
    "1e12",
    "1e18",
    "2147483648",
    "1e-7",
    "1e-3",
    "0.05",
    "0.5",
    "0.9",
    "1",
    "2",
    "7",
    "100",
    "5000",
];

/// Malformed or odd `--set` arguments.
const ODD_SETS: &[&str] = &[
    "=1",
    "=",
    "a..b=1",
    ".a=1",
    "a.=1",
    "particles.count",
    "particles.count=",
    "particles.count.x=1",
    "name.first=1",
    "gravity.value=1",
    "particles.radius.species.0.count=3",
    "particles.radius.species.9.count=3",
    "particles.radius.species.x.count=3",
    "particles.placement.positions.0.0=1e300",
    "particles.placement.positions.5=[1,1]",
    "run=5",
    "output=[]",
    "domain=null",
    "a=b=c",
    " = ",
    "particles.count=1=2",
    "bogus.deep.path=1",
];

/// One change to a scenario.
#[derive(Debug, Clone)]
enum Mutation {
    /// `--set PATH=VALUE`.
    Set(&'static str, &'static str),
    /// An odd `--set` argument, as it stands.
    OddSet(&'static str),
    /// The field set to VALUE in the file itself.
    File(&'static str, &'static str),
    /// The field removed from the file.
    Remove(&'static str),
    /// An unknown field added to an object of the file.
    Unknown(&'static str),
}

/// A scenario and its changes, and which outputs a run writes.
#[derive(Debug, Clone)]
struct Case {
    scenario: usize,
    mutations: Vec<Mutation>,
    profiles: bool,
    trajectory: bool,
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let field = proptest::sample::select(FIELDS);
    let value = proptest::sample::select(VALUES);
    let numeric = proptest::sample::select(NUMERIC_FIELDS);
    let number = proptest::sample::select(NUMBERS);
    prop_oneof![
        6 => (numeric.clone(), number.clone()).prop_map(|(f, v)| Mutation::Set(f, v)),
        2 => (numeric, number).prop_map(|(f, v)| Mutation::File(f, v)),
        3 => (field.clone(), value.clone()).prop_map(|(f, v)| Mutation::Set(f, v)),
        2 => (field.clone(), value).prop_map(|(f, v)| Mutation::File(f, v)),
        1 => field.prop_map(Mutation::Remove),
        1 => proptest::sample::select(OBJECTS).prop_map(Mutation::Unknown),
        1 => proptest::sample::select(ODD_SETS).prop_map(Mutation::OddSet),
    ]
}

fn case(scenarios: usize) -> impl Strategy<Value = Case> {
    (
        0..scenarios,
        proptest::collection::vec(mutation(), 1..=2),
        any::<bool>(),
        prop::bool::weighted(0.25),
    )
        .prop_map(|(scenario, mutations, profiles, trajectory)| Case {
            scenario,
            mutations,
            profiles,
            trajectory,
        })
}

/// The shipped top-level scenarios, sorted.
fn shipped() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(guarded::crate_root().join("scenarios"))
        .expect("scenarios/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "json") && p.is_file())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no scenarios/*.json");
    files
}

/// A text that stands for a raw value in the file until the file is written.
fn placeholder(i: usize) -> String {
    format!("@@raw-value-{i}@@")
}

/// The node at a dotted path, created (as objects) where missing; None when an index is out of
/// range. A value in the way is replaced by an object.
fn node_at<'a>(root: &'a mut Value, path: &[&str]) -> Option<&'a mut Value> {
    let mut node = root;
    for segment in path {
        if !node.is_object() && !node.is_array() {
            *node = Value::Object(Default::default());
        }
        node = match node {
            Value::Array(items) => items.get_mut(segment.parse::<usize>().ok()?)?,
            Value::Object(map) => map
                .entry(segment.to_string())
                .or_insert_with(|| Value::Object(Default::default())),
            _ => unreachable!("made an object above"),
        };
    }
    Some(node)
}

/// Applies the file mutations of `case` to the scenario's text; the text to write, and whether
/// anything changed.
fn mutated_file(text: &str, case: &Case) -> (String, bool) {
    let mut root: Value = serde_json::from_str(text).expect("a shipped scenario is JSON");
    let mut raws: Vec<&str> = Vec::new();
    let mut changed = false;
    for m in &case.mutations {
        match m {
            Mutation::File(field, raw) => {
                let segments: Vec<&str> = field.split('.').collect();
                if let Some(node) = node_at(&mut root, &segments) {
                    *node = Value::String(placeholder(raws.len()));
                    raws.push(raw);
                    changed = true;
                }
            }
            Mutation::Remove(field) => {
                let segments: Vec<&str> = field.split('.').collect();
                let (last, parent) = segments.split_last().expect("a field");
                if let Some(node) = node_at(&mut root, parent) {
                    match node {
                        Value::Object(map) => changed |= map.remove(*last).is_some(),
                        Value::Array(items) => {
                            if let Ok(i) = last.parse::<usize>() {
                                if i < items.len() {
                                    items.remove(i);
                                    changed = true;
                                }
                            }
                        }
                        _ => {}
                    }
                }
            }
            Mutation::Unknown(object) => {
                let segments: Vec<&str> = object.split('.').filter(|s| !s.is_empty()).collect();
                if let Some(Value::Object(map)) = node_at(&mut root, &segments) {
                    map.insert("unexpected_field".into(), Value::from(1));
                    changed = true;
                }
            }
            Mutation::Set(..) | Mutation::OddSet(..) => {}
        }
    }
    let mut text = serde_json::to_string_pretty(&root).expect("JSON text");
    for (i, raw) in raws.iter().enumerate() {
        text = text.replace(&format!("\"{}\"", placeholder(i)), raw);
    }
    (text, changed)
}

/// The `--set` arguments of `case`.
fn sets(case: &Case) -> Vec<String> {
    case.mutations
        .iter()
        .filter_map(|m| match m {
            Mutation::Set(field, raw) => Some(format!("{field}={raw}")),
            Mutation::OddSet(arg) => Some(arg.to_string()),
            _ => None,
        })
        .collect()
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Subcommand {
    Check,
    Run,
}

/// What the fuzzer saw of one case.
struct Verdict {
    /// None: the case passed.
    failure: Option<String>,
    /// The case only ended because it was sent SIGINT.
    needed_interrupt: bool,
    code: Option<i32>,
}

/// Checks one finished case against the contract.
fn judge(cmd: Subcommand, out: &Outcome, outputs: &Path) -> Verdict {
    let written = entries(outputs);
    let mut problems: Vec<String> = Vec::new();
    if out.panicked() {
        problems.push("panicked or aborted".into());
    }
    if out.killed {
        problems.push("did not stop within 5 s of SIGINT (SIGKILL sent)".into());
    } else if let Some(sig) = out.signal() {
        problems.push(format!(
            "ended by signal {sig}{}",
            if out.interrupted_at.is_some() && sig == 2 {
                " (still loading or building the scene when interrupted: SIGINT is not handled yet)"
            } else {
                ""
            }
        ));
    }
    let early = (cmd == Subcommand::Run)
        .then(|| out.ended_early(outputs))
        .flatten();
    match (cmd, out.code()) {
        (_, Some(0)) => {
            if cmd == Subcommand::Run {
                match std::fs::read_to_string(outputs.join("summary.json")) {
                    Ok(text) => {
                        if serde_json::from_str::<Value>(&text).is_err() {
                            problems.push("exit 0 but summary.json is not JSON".into());
                        }
                    }
                    Err(e) => problems.push(format!("exit 0 but no summary.json: {e}")),
                }
            }
        }
        (_, Some(2)) => {
            let located = error_line(&out.stderr)
                .is_some_and(|l| l.contains("field `") || l.contains(" at line "));
            if error_field(&out.stderr).is_none() && !located {
                problems.push(format!(
                    "exit 2 but the error names no field: {:?}",
                    error_line(&out.stderr)
                ));
            }
            if !written.is_empty() {
                problems.push(format!("exit 2 but files were written: {written:?}"));
            }
        }
        (Subcommand::Run, Some(130)) if out.interrupted_at.is_some() => {
            match std::fs::read_to_string(outputs.join("summary.json"))
                .ok()
                .and_then(|t| serde_json::from_str::<Value>(&t).ok())
            {
                Some(s) if s["ending"] == "interrupted" => {}
                other => problems.push(format!(
                    "exit 130 but no summary marked interrupted: {other:?}"
                )),
            }
        }
        // Stopped by `run.max_events` (each case sets it) or `run.max_wall_seconds`, or by a
        // stalled clock.
        (_, Some(_)) if early.is_some() => problems.extend(early.and_then(Result::err)),
        (_, Some(code)) => problems.push(format!("exit code {code} is not in the contract")),
        (_, None) => {}
    }
    if cmd == Subcommand::Check && !written.is_empty() {
        problems.push(format!("check wrote files: {written:?}"));
    }
    Verdict {
        failure: (!problems.is_empty()).then(|| problems.join("; ")),
        needed_interrupt: out.interrupted_at.is_some(),
        code: out.code(),
    }
}

/// Shell-quotes an argument for the reproduction line.
fn quote(arg: &str) -> String {
    if !arg.is_empty()
        && arg
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+".contains(c))
    {
        arg.to_string()
    } else {
        format!("'{}'", arg.replace('\'', "'\\''"))
    }
}

fn env_number(name: &str) -> Option<u64> {
    let text = std::env::var(name).ok()?;
    let text = text.trim();
    match text.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16).ok(),
        None => text.parse().ok(),
    }
    .or_else(|| panic!("{name}={text} is not a number"))
}

/// Runs the fuzzer on one subcommand.
fn fuzz(cmd: Subcommand) {
    let cases = env_number("VIBROBED_FUZZ_CASES").map_or(DEFAULT_CASES, |n| n as u32);
    let seed = env_number("VIBROBED_FUZZ_SEED").unwrap_or(DEFAULT_SEED);
    let salt: u64 = match cmd {
        Subcommand::Check => 1,
        Subcommand::Run => 2,
    };
    let mut seed_bytes = [0u8; 32];
    seed_bytes[..8].copy_from_slice(&seed.to_le_bytes());
    seed_bytes[8..16].copy_from_slice(&salt.to_le_bytes());
    let config = Config {
        cases,
        failure_persistence: None,
        max_shrink_iters: 0,
        ..Config::default()
    };
    let mut runner = TestRunner::new_with_rng(
        config,
        TestRng::from_seed(RngAlgorithm::ChaCha, &seed_bytes),
    );

    let files = shipped();
    let strategy = case(files.len());
    let name = match cmd {
        Subcommand::Check => "check",
        Subcommand::Run => "run",
    };
    let root = guarded::fresh_dir(&format!("fuzz-{name}"));
    let mut failures = String::new();
    let mut interrupted = String::new();
    let mut tally: std::collections::BTreeMap<String, usize> = Default::default();
    for i in 0..cases {
        let case = strategy
            .new_tree(&mut runner)
            .expect("a case is drawn")
            .current();
        let dir = root.join(format!("case-{i:04}"));
        let outputs = dir.join("out");
        std::fs::create_dir_all(&outputs).expect("case directory");
        let original = &files[case.scenario];
        let text = std::fs::read_to_string(original).expect("a shipped scenario");
        let (mutated, changed) = mutated_file(&text, &case);
        let scenario = if changed {
            let path = dir.join("scenario.json");
            std::fs::write(&path, &mutated).expect("write the mutated scenario");
            path
        } else {
            original.clone()
        };

        let mut args: Vec<String> = vec![name.into(), scenario.display().to_string()];
        if cmd == Subcommand::Run {
            args.extend(
                [
                    "--quiet",
                    "--summary",
                    "summary.json",
                    "--set",
                    "run.duration=0.05",
                    "--set",
                    "run.warmup=0",
                    "--set",
                    "run.max_events=200000",
                ]
                .map(String::from),
            );
            if case.profiles {
                args.extend(["--profiles".into(), "profiles.csv".into()]);
            }
            if case.trajectory {
                args.extend(["--trajectory".into(), "trajectory.xyz".into()]);
            }
        }
        for set in sets(&case) {
            args.push("--set".into());
            args.push(set);
        }
        let os_args: Vec<OsString> = args.iter().map(OsString::from).collect();
        // The binary runs in the (empty) output directory: relative paths a scenario names
        // (output.rrd, output.trajectory) land there too.
        let out = guarded::run(
            &os_args,
            &outputs,
            &dir,
            Limits {
                interrupt_after: INTERRUPT_AFTER,
                kill_after: Duration::from_secs(5),
            },
        );
        let verdict = judge(cmd, &out, &outputs);
        let command_line = std::iter::once("vibrobed".to_string())
            .chain(args.iter().map(|a| quote(a)))
            .collect::<Vec<_>>()
            .join(" ");
        *tally
            .entry(match verdict.code {
                Some(c) => format!("exit {c}"),
                None => "signal".into(),
            })
            .or_default() += 1;
        eprintln!(
            "fuzz {name} #{i}: exit {:?} in {:.2} s{}: {command_line}{}",
            out.code(),
            out.elapsed.as_secs_f64(),
            if verdict.needed_interrupt {
                " (needed SIGINT)"
            } else {
                ""
            },
            match error_line(&out.stderr) {
                Some(line) => format!("\n    -> {line}"),
                None => String::new(),
            },
        );
        if verdict.needed_interrupt {
            let _ = writeln!(interrupted, "  #{i}: {command_line}");
        }
        match verdict.failure {
            Some(why) => {
                let _ = writeln!(
                    failures,
                    "\n=== case #{i}: {why}\n(in {}, run from its out/)\n{command_line}\n{}{}",
                    dir.display(),
                    if changed {
                        format!("--- scenario.json ---\n{mutated}\n")
                    } else {
                        String::new()
                    },
                    out.describe()
                );
            }
            None => {
                let _ = std::fs::remove_dir_all(&dir);
            }
        }
    }
    eprintln!("fuzz {name}: {cases} cases (seed {seed:#x}): {tally:?}");
    if !interrupted.is_empty() {
        eprintln!("fuzz {name}: cases that only ended on SIGINT:\n{interrupted}");
    }
    if failures.is_empty() {
        let _ = std::fs::remove_dir_all(&root);
    } else {
        panic!(
            "fuzz {name} (seed {seed:#x}): cases outside the contract:{failures}\n\
             cases that only ended on SIGINT:\n{interrupted}"
        );
    }
}

#[test]
fn mutated_scenarios_are_checked_within_the_contract() {
    fuzz(Subcommand::Check);
}

#[test]
fn mutated_scenarios_run_within_the_contract() {
    fuzz(Subcommand::Run);
}

/// A new scenario field is fuzzed as soon as it is there: `FIELDS` names every field the
/// scenario's schema has, a list's fields by its first item (`inlets[].rate` as
/// `inlets.0.rate`).
#[test]
fn every_scenario_field_is_fuzzed() {
    let schema = crate::book::scenario_field_paths();
    assert!(schema.len() > 50, "the schema walk found too few fields");
    let missing: Vec<&String> = schema
        .iter()
        .filter(|f| !FIELDS.contains(&f.replace("[]", ".0").as_str()))
        .collect();
    assert!(
        missing.is_empty(),
        "scenario fields the fuzzer never changes (add them to FIELDS, and a number to \
         NUMERIC_FIELDS): {missing:?}"
    );
    for field in NUMERIC_FIELDS {
        assert!(
            FIELDS.contains(field),
            "{field} is numeric but not in FIELDS"
        );
    }
}
