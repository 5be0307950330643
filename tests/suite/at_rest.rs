//! At rest means at rest: the summary's time to rest is the end of the last motion, exact to
//! the event (not a sample time), and no disk moves after it unless something acts on it.

use crate::common::crate_path;
use vibrobed::output::summary::Summary;
use vibrobed::run::{run, RunOptions};
use vibrobed::Scenario;

fn summary(file: &str, sets: &[String]) -> Summary {
    let text = std::fs::read_to_string(crate_path(file)).unwrap();
    let s =
        Scenario::from_json_with_overrides(&text, sets).unwrap_or_else(|e| panic!("{file}: {e}"));
    run(&s, RunOptions::default()).unwrap_or_else(|e| panic!("{file}: {e}"))
}

/// The run of `file` with `sets`, to `end`: asserts that it is at rest by then, and that its
/// time of rest `t` is exact (the same run stopped a hair before `t` is not at rest; a hair
/// after, at rest from the same instant). Returns the summary at `end`.
fn rests_exactly(file: &str, sets: &[String], end: f64) -> Summary {
    let run_to = |duration: f64| {
        let mut all = sets.to_vec();
        all.push(format!("run.duration={duration}"));
        summary(file, &all)
    };
    let long = run_to(end);
    let t = (long.at_rest_since).unwrap_or_else(|| panic!("{sets:?}: not at rest by t = {end}"));
    assert_eq!(run_to(t - 1e-9).at_rest_since, None, "{sets:?}");
    assert_eq!(run_to(t + 1e-9).at_rest_since, Some(t), "{sets:?}");
    long
}

#[test]
fn a_pile_is_at_rest_from_its_last_disk_coming_to_rest_over_seeds() {
    for seed in [1, 2, 3] {
        // At rest from the last disk coming to rest, and to t = 30 nothing woke in between.
        let sets = [format!("seed={seed}")];
        let long = rests_exactly("scenarios/hard/bed_at_rest_tc.json", &sets, 30.0);
        assert_eq!(long.rest_wakes, None, "seed {seed}: disks woke after rest");
    }
}

/// A bed that rides a floor below Γ = 1 on contact dynamics (the hybrid scheme hands it over)
/// comes to rest over seeds, from the end of its last motion (a step's end, not a sample time).
/// Until stop 77 seed 3 never rested: a disk resting on the floor was measured against the
/// floor's velocity at the step's end, `(g + h'') dt/2` off its own, and the bed's noise crossed
/// the rest speed once a period.
#[test]
fn a_bed_riding_the_floor_rests_on_contact_dynamics_over_seeds() {
    for seed in 1..=6 {
        let sets = [
            format!("seed={seed}"),
            "particles.count=200".into(),
            "domain.width=40.3".into(),
            "floor.gamma=0.5".into(),
            "collisions.restitution=0.5".into(),
            "run.warmup=10".into(),
        ];
        rests_exactly("scenarios/vibrated_bed.json", &sets, 60.0);
    }
}
