//! The two event queues (`engine.queue = "tree"`, Isobe's complete binary tree, and
//! `"calendar"`, Paul's calendar queue) pop the same events in the same order: shipped scenarios
//! run with either give the same summary (but for the process measurements) and the same final
//! state, bit for bit.

use crate::common;

use common::{crate_path, same_run};
use serde_json::Value;
use vibrobed::Scenario;

fn load(file: &str, sets: &[&str], queue: &str) -> Scenario {
    let mut sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    sets.push(format!("engine.queue={queue}"));
    Scenario::load(&crate_path(&format!("scenarios/{file}")), &sets).expect("scenario loads")
}

/// The summary without the process measurements, after checking that it names the queue
/// that was asked for.
fn summary(s: &Scenario) -> Value {
    let (v, queue) = same_run::summary(s, &["queue"]);
    let asked = serde_json::to_value(s.engine.queue).expect("queue choice serializes");
    assert_eq!(queue[0], asked, "the summary names the queue that ran");
    v
}

fn same_with_either_queue(file: &str, sets: &[&str]) {
    let (tree, calendar) = (load(file, sets, "tree"), load(file, sets, "calendar"));
    let (a, b) = (summary(&tree), summary(&calendar));
    same_run::assert_same_runs(file, (&tree, &a), (&calendar, &b), 1000);
}

#[test]
fn a_gas_is_the_same_with_either_queue() {
    same_with_either_queue(
        "gas_periodic_phi03.json",
        &["run.duration=20", "run.warmup=2"],
    );
    same_with_either_queue(
        "gas_periodic_phi07.json",
        &["run.duration=3", "run.warmup=1"],
    );
}

#[test]
fn a_vibrated_bed_is_the_same_with_either_queue() {
    same_with_either_queue("vibrated_bed.json", &["run.duration=3", "run.warmup=1"]);
    same_with_either_queue("deep_bed.json", &["run.duration=0.5", "run.warmup=0.1"]);
}

#[test]
fn walls_species_and_rest_are_the_same_with_either_queue() {
    same_with_either_queue("box_walls.json", &["run.duration=3", "run.warmup=1"]);
    same_with_either_queue("polydisperse.json", &["run.duration=3", "run.warmup=1"]);
    same_with_either_queue("brazil_nut.json", &["run.duration=3", "run.warmup=1"]);
    same_with_either_queue("hard/bed_at_rest_speed_cutoff.json", &[]);
}

/// With the local re-mapping the queue is rebuilt rarely, so the calendar wraps and re-tunes
/// itself between rebuilds.
#[test]
fn the_local_re_mapping_is_the_same_with_either_queue() {
    same_with_either_queue(
        "gas_periodic_phi07.json",
        &["run.duration=3", "run.warmup=1", "engine.remap=local"],
    );
    same_with_either_queue(
        "vibrated_bed.json",
        &["run.duration=3", "run.warmup=1", "engine.remap=local"],
    );
}
