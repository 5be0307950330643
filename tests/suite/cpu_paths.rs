//! The vector paths of the engine's hot loops (`src/platform/cpu.rs`): the same scenes run
//! four AVX2 lanes at a time (with AVX-512's registers too, where the processor has them) and
//! one by one end in the same state, bit for bit, with the same event counts and summaries;
//! `VIBROBED_CPU` chooses the path on the command line, and a value it does not take exits 2
//! naming it.

use crate::common::same_run::{final_state_on, same_states};
use serde_json::Value;
use std::process::{Command, Output};
use vibrobed::platform::cpu::Lanes;
use vibrobed::Scenario;

/// Shipped scenes, shortened, and their re-mappings: the pair search, the shells' filter and
/// the rows' slot search (local), Isobe's re-mapping (global), mixed radii, walls, a floor with
/// disks riding on it, rough disks.
const SCENES: &[(&str, &[&str])] = &[
    (
        "gas_periodic_phi03",
        &["run.duration=3", "run.warmup=1", "engine.remap=local"],
    ),
    (
        "gas_periodic_phi03",
        &["run.duration=3", "run.warmup=1", "engine.remap=global"],
    ),
    ("gas_periodic_phi07", &["run.duration=1", "run.warmup=0.5"]),
    (
        "polydisperse",
        &["run.duration=4", "run.warmup=1", "engine.remap=local"],
    ),
    ("box_walls", &["run.duration=6", "run.warmup=1"]),
    ("vibrated_bed", &["run.duration=30", "run.warmup=10"]),
    ("rough_vibrated_bed", &["run.duration=10", "run.warmup=2"]),
];

fn scenario(stem: &str, sets: &[&str]) -> Scenario {
    let path = crate::common::crate_path(&format!("scenarios/{stem}.json"));
    let json = std::fs::read_to_string(&path).expect("a shipped scenario");
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Scenario::from_json_with_overrides(&json, &sets).expect("valid overrides")
}

/// The pair collisions in an engine's event counts (as `Debug` prints them).
fn pairs(counts: &str) -> u64 {
    let at = counts
        .find("pair: ")
        .expect("the counts name pair collisions")
        + 6;
    let digits: String = counts[at..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    digits.parse().expect("a count")
}

#[test]
fn four_lanes_and_one_by_one_end_in_the_same_state() {
    let wider = &Lanes::all_here()[1..];
    if wider.is_empty() {
        eprintln!("no AVX2 on this processor: one path only, nothing to compare");
        return;
    }
    for &(stem, sets) in SCENES {
        let s = scenario(stem, sets);
        let one = final_state_on(&s, Lanes::ONE_BY_ONE);
        assert!(
            pairs(&one.1) > 1000,
            "{stem} {sets:?}: too few collisions to compare"
        );
        for &lanes in wider {
            let what = format!("{stem} {sets:?} on {}", lanes.name());
            same_states(&what, final_state_on(&s, lanes), one.clone());
        }
    }
}

fn vibrobed(path: Option<&str>, args: &[&str]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_vibrobed"));
    command.current_dir(env!("CARGO_MANIFEST_DIR")).args(args);
    match path {
        Some(p) => command.env("VIBROBED_CPU", p),
        None => command.env_remove("VIBROBED_CPU"),
    };
    command.output().expect("the vibrobed binary starts")
}

/// The summary of the shortened gas under `VIBROBED_CPU=path`, without what measures the
/// process.
fn summary(path: Option<&str>, out: &std::path::Path) -> Value {
    let gas = [
        "scenarios/gas_periodic_phi03.json",
        "--set",
        "run.duration=3",
    ];
    summary_of(path, &gas, out)
}

/// The summary of `vibrobed run SCENE...` under `VIBROBED_CPU=path`, as [`summary`].
fn summary_of(path: Option<&str>, scene: &[&str], out: &std::path::Path) -> Value {
    let _ = std::fs::remove_file(out);
    let mut args = vec!["run", "-q", "--set", "run.warmup=1"];
    args.extend(scene);
    args.extend(["--summary", out.to_str().expect("a path in UTF-8")]);
    let o = vibrobed(path, &args);
    assert!(o.status.success(), "{path:?}: {o:?}");
    let mut v: Value =
        serde_json::from_str(&std::fs::read_to_string(out).expect("summary")).expect("JSON");
    let o = v.as_object_mut().expect("an object");
    o.remove("wall_seconds");
    o.remove("collisions_per_second");
    o["engine"]
        .as_object_mut()
        .expect("engine")
        .remove("bytes_per_disk");
    v
}

#[test]
fn the_environment_chooses_the_path_and_the_summary_stays() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cpu-paths");
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let out = dir.join("summary.json");
    let found = summary(None, &out);
    assert!(found["events"]["pair"].as_u64().expect("pairs") > 1000);
    assert_eq!(summary(Some("scalar"), &out), found, "scalar");
    assert_eq!(summary(Some("auto"), &out), found, "auto");
    if Lanes::widest().avx2() {
        assert_eq!(summary(Some("avx2"), &out), found, "avx2");
    }
    if Lanes::widest().avx512() {
        assert_eq!(summary(Some("avx512"), &out), found, "avx512");
    }
    // Values it does not take, and paths the processor lacks: exit 2 naming the variable, and
    // nothing written.
    let mut bad = vec!["sse9", "SCALAR"];
    if !Lanes::widest().avx2() {
        bad.push("avx2");
    }
    if !Lanes::widest().avx512() {
        bad.push("avx512");
    }
    for value in bad {
        let _ = std::fs::remove_file(&out);
        let o = vibrobed(
            Some(value),
            &[
                "run",
                "scenarios/gas_periodic_phi03.json",
                "-q",
                "--summary",
                out.to_str().expect("a path in UTF-8"),
            ],
        );
        assert_eq!(o.status.code(), Some(2), "{value}: {o:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("VIBROBED_CPU"), "{value}: {err}");
        assert!(!out.exists(), "{value}: a summary was written");
    }
}

/// Contact dynamics' sweep and its pairs' separations (`src/schemes/contact/`) run four lanes
/// at a time where the processor has AVX2: a rough bed the floor throws, on contact dynamics
/// with the step following its impacts, gives the same summary on both paths.
#[test]
fn contact_dynamics_gives_the_same_summary_on_both_paths() {
    if !Lanes::widest().avx2() {
        eprintln!("no AVX2 on this processor: one path only, nothing to compare");
        return;
    }
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cpu-paths-contact");
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let out = dir.join("summary.json");
    let bed = [
        "scenarios/vibrated_bed.json",
        "--set",
        "floor.gamma=1.5",
        "--set",
        "collisions.friction=0.5",
        "--set",
        "floor.friction=0.5",
        "--set",
        "engine.scheme=contact",
        "--set",
        "run.duration=20",
    ];
    let found = summary_of(Some("avx2"), &bed, &out);
    assert!(found["approximation"]["sweeps"].as_u64().expect("sweeps") > 1000);
    assert!(found["events"]["pair"].as_u64().expect("pairs") > 1000);
    assert_eq!(summary_of(Some("scalar"), &bed, &out), found);
}
