//! Two runs of one scene that must agree bit for bit (another queue, another numbering): their
//! summaries without what measures the process, and the engine's final state.

use serde_json::Value;
use vibrobed::engine::{Progress, Scene, Simulation, Snapshot};
use vibrobed::physics::flight::{Ballistic, Straight};
use vibrobed::platform::cpu::Lanes;
use vibrobed::run::{run, RunOptions};
use vibrobed::Scenario;

/// The summary without what measures the process (wall time, rate, bytes held) and without the
/// engine fields named in `drop` (returned, to be checked by the caller).
pub fn summary(s: &Scenario, drop: &[&str]) -> (Value, Vec<Value>) {
    let summary = run(s, RunOptions::default()).expect("run");
    let mut v = serde_json::to_value(&summary).expect("summary serializes");
    let o = v.as_object_mut().expect("an object");
    o.remove("wall_seconds");
    o.remove("collisions_per_second");
    let engine = o["engine"].as_object_mut().expect("engine");
    engine.remove("bytes_per_disk");
    let dropped = drop
        .iter()
        .map(|k| engine.remove(*k).expect("the summary names it"))
        .collect();
    (v, dropped)
}

/// The end of a run as [`final_state`] gives it: state, event counts, virial.
pub type FinalState = (Snapshot, String, u64);

/// Runs the engine itself to the end of the scenario: final state, event counts, virial.
pub fn final_state(s: &Scenario) -> FinalState {
    final_state_on(s, Lanes::found())
}

/// [`final_state`] on the vector path `lanes`.
pub fn final_state_on(s: &Scenario, lanes: Lanes) -> FinalState {
    let (mut scene, disks) = Scene::build(s).expect("scene");
    scene.lanes = lanes;
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

/// Asserts that `a` and `b` (with summaries `sa` and `sb` from [`summary`]) are one run: the
/// first has more than `min_pairs` pair collisions to compare, the summaries are equal, and the
/// final states are the same bit for bit.
pub fn assert_same_runs(
    what: &str,
    (a, sa): (&Scenario, &Value),
    (b, sb): (&Scenario, &Value),
    min_pairs: u64,
) {
    assert!(
        sa["events"]["pair"].as_u64().unwrap() > min_pairs,
        "{what}: too few collisions to compare"
    );
    assert_eq!(sa, sb, "{what}: summaries differ");
    same_final_state(what, a, b);
}

/// Asserts that `a` and `b` end in the same state, bit for bit.
pub fn same_final_state(what: &str, a: &Scenario, b: &Scenario) {
    same_states(what, final_state(a), final_state(b));
}

/// Asserts that two ends of runs are the same, bit for bit.
pub fn same_states(what: &str, (sa, ca, va): FinalState, (sb, cb, vb): FinalState) {
    assert_eq!(ca, cb, "{what}: event counts differ");
    assert_eq!(va, vb, "{what}: virial differs");
    assert_eq!(sa.time.to_bits(), sb.time.to_bits());
    for (field, x, y) in [
        ("x", &sa.x, &sb.x),
        ("y", &sa.y, &sb.y),
        ("vx", &sa.vx, &sb.vx),
        ("vy", &sa.vy, &sb.vy),
    ] {
        assert!(bits(x) == bits(y), "{what}: final {field} differs");
    }
}
