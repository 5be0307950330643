//! The two event queues (`engine.queue = "tree"`, Isobe's complete binary tree, and
//! `"calendar"`, Paul's calendar queue) pop the same events in the same order: shipped scenarios
//! run with either give the same summary (but for the process measurements) and the same final
//! state, bit for bit.

mod common;

use common::crate_path;
use serde_json::Value;
use vibrobed::dynamics::{Ballistic, Straight};
use vibrobed::run::{run, RunOptions};
use vibrobed::simulation::{Progress, Scene, Simulation, Snapshot};
use vibrobed::Scenario;

fn load(file: &str, sets: &[&str], queue: &str) -> Scenario {
    let mut sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    sets.push(format!("engine.queue={queue}"));
    Scenario::load(&crate_path(&format!("scenarios/{file}")), &sets).expect("scenario loads")
}

/// The summary without what measures the process (wall time, rate, bytes held) and the name of
/// the queue it ran with (checked here to be the one asked for).
fn summary(s: &Scenario) -> Value {
    let summary = run(s, RunOptions::default()).expect("run");
    let mut v = serde_json::to_value(&summary).expect("summary serializes");
    let o = v.as_object_mut().expect("an object");
    o.remove("wall_seconds");
    o.remove("collisions_per_second");
    let engine = o["engine"].as_object_mut().expect("engine");
    engine.remove("bytes_per_disk");
    let queue = engine.remove("queue").expect("the summary names the queue");
    let asked = serde_json::to_value(s.engine.queue).expect("queue choice serializes");
    assert_eq!(queue, asked, "the summary names the queue that ran");
    v
}

/// Runs the engine itself to the end of the scenario: final state, event counts, virial.
fn final_state(s: &Scenario) -> (Snapshot, String, u64) {
    let (scene, disks) = Scene::build(s).expect("scene");
    let end = s.run.duration;
    macro_rules! go {
        ($sim:expr) => {{
            let mut sim = $sim;
            assert_eq!(sim.advance_to(end).expect("runs"), Progress::Reached);
            (
                sim.snapshot(end),
                format!("{:?}", sim.counts()),
                sim.virial().to_bits(),
            )
        }};
    }
    match scene.gravity {
        Some(g) => go!(Simulation::new(Ballistic { g }, &scene, disks).expect("engine")),
        None => go!(Simulation::new(Straight, &scene, disks).expect("engine")),
    }
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn same_with_either_queue(file: &str, sets: &[&str]) {
    let (tree, calendar) = (load(file, sets, "tree"), load(file, sets, "calendar"));
    let (a, b) = (summary(&tree), summary(&calendar));
    assert!(
        a["events"]["pair"].as_u64().unwrap() > 1000,
        "{file}: too few collisions to compare"
    );
    assert_eq!(a, b, "{file}: summaries differ");
    let ((sa, ca, va), (sb, cb, vb)) = (final_state(&tree), final_state(&calendar));
    assert_eq!(ca, cb, "{file}: event counts differ");
    assert_eq!(va, vb, "{file}: virial differs");
    assert_eq!(sa.time.to_bits(), sb.time.to_bits());
    for (what, x, y) in [
        ("x", &sa.x, &sb.x),
        ("y", &sa.y, &sb.y),
        ("vx", &sa.vx, &sb.vx),
        ("vy", &sa.vy, &sb.vy),
    ] {
        assert!(bits(x) == bits(y), "{file}: final {what} differs");
    }
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
