//! Renumbering the disks along a space-filling curve (`engine.renumber`) changes only where
//! they sit in the engine's memory: with Isobe's global re-mapping a renumbered run is the
//! run in the scenario's numbering, bit for bit (summary, final state in the scenario's
//! numbering); with the local one it re-maps at other times, so it is checked against the brute
//! force (tests/suite/brute_force.rs) and for resuming (tests/suite/checkpoint.rs) instead.

use crate::common;

use common::{crate_path, same_run};
use vibrobed::Scenario;

fn load(file: &str, sets: &[&str], renumber: &str) -> Scenario {
    let mut sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    sets.push(format!("engine.renumber={renumber}"));
    if !sets.iter().any(|s| s.starts_with("engine.remap")) {
        sets.push("engine.remap=global".into());
    }
    Scenario::load(&crate_path(&format!("scenarios/{file}")), &sets).expect("scenario loads")
}

fn same_either_way(file: &str, sets: &[&str]) {
    let (on, off) = (load(file, sets, "on"), load(file, sets, "off"));
    let (a, _) = same_run::summary(&on, &[]);
    let (b, _) = same_run::summary(&off, &[]);
    // Enough collisions for several renumberings.
    let several = 20 * on.disk_count() as u64;
    same_run::assert_same_runs(file, (&on, &a), (&off, &b), several);
}

#[test]
fn a_renumbered_gas_is_the_same_gas() {
    same_either_way(
        "gas_periodic_phi03.json",
        &["run.duration=20", "run.warmup=2"],
    );
    same_either_way("box_walls.json", &["run.duration=40", "run.warmup=1"]);
}

/// Beds in flight: the cures' memory and species follow the numbering.
#[test]
fn a_renumbered_bed_is_the_same_bed() {
    same_either_way("vibrated_bed.json", &["run.duration=10", "run.warmup=1"]);
    same_either_way("polydisperse.json", &["run.duration=12", "run.warmup=1"]);
}

/// A bed that comes to rest: the rules for disks at rest look at neighbours in list order (the
/// first support found, a cluster's members), so the two numberings part in round-off once
/// disks rest; both settle alike, and who rests on what follows the numbering (a wrong support
/// would drop or lift disks, and the floor would not carry the bed's weight).
#[test]
fn a_renumbered_bed_settles_as_the_bed() {
    let (on, off) = (
        load("hard/bed_at_rest_tc.json", &[], "on"),
        load("hard/bed_at_rest_tc.json", &[], "off"),
    );
    let (a, _) = same_run::summary(&on, &[]);
    let (b, _) = same_run::summary(&off, &[]);
    let at_rest = |v: &serde_json::Value| v["at_rest_since"].as_f64().expect("settles");
    assert!((at_rest(&a) - at_rest(&b)).abs() <= 2.0, "{a}\n{b}");
    let potential = |v: &serde_json::Value| v["energy"]["final"]["potential"].as_f64().unwrap();
    let (pa, pb) = (potential(&a), potential(&b));
    assert!(
        (pa - pb).abs() <= 1e-5 * pb,
        "final heights differ: {pa} vs {pb}"
    );
    for v in [&a, &b] {
        let (m, w) = (
            v["floor_pressure"]["measured"].as_f64().unwrap(),
            v["floor_pressure"]["weight"].as_f64().unwrap(),
        );
        assert!(
            (m - w).abs() <= 0.01 * w,
            "floor pressure {m} against weight {w}"
        );
        assert_eq!(v["energy"]["final"]["kinetic"].as_f64(), Some(0.0));
    }
}
