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

#[test]
fn a_pile_is_at_rest_from_its_last_disk_coming_to_rest_over_seeds() {
    let file = "scenarios/hard/bed_at_rest_tc.json";
    for seed in [1, 2, 3] {
        let run_to = |duration: f64| {
            summary(
                file,
                &[format!("seed={seed}"), format!("run.duration={duration}")],
            )
        };
        let long = run_to(30.0);
        let t = long
            .at_rest_since
            .unwrap_or_else(|| panic!("seed {seed}: not at rest by t = 30"));
        // The same run stopped a hair before the last disk came to rest is not at rest; a hair
        // after, at rest from the same instant; and to t = 30 nothing woke in between.
        assert_eq!(run_to(t - 1e-9).at_rest_since, None, "seed {seed}");
        assert_eq!(run_to(t + 1e-9).at_rest_since, Some(t), "seed {seed}");
        assert_eq!(long.rest_wakes, None, "seed {seed}: disks woke after rest");
    }
}

/// A bed that rides a floor below Γ = 1 on contact dynamics (the hybrid scheme hands it over)
/// comes to rest over seeds, from the end of its last motion (a step's end, not a sample time):
/// stopped a hair before, it is not at rest; a hair after, at rest from the same instant. Until
/// stop 77 seed 3 never rested: a disk resting on the floor was measured against the floor's
/// velocity at the step's end, `(g + h'') dt/2` off its own, and the bed's noise crossed the
/// rest speed once a period.
#[test]
fn a_bed_riding_the_floor_rests_on_contact_dynamics_over_seeds() {
    for seed in 1..=6 {
        let run_to = |duration: f64| {
            summary(
                "scenarios/vibrated_bed.json",
                &[
                    format!("seed={seed}"),
                    "particles.count=200".into(),
                    "domain.width=40.3".into(),
                    "floor.gamma=0.5".into(),
                    "collisions.restitution=0.5".into(),
                    "run.warmup=10".into(),
                    format!("run.duration={duration}"),
                ],
            )
        };
        let long = run_to(60.0);
        let t = long
            .at_rest_since
            .unwrap_or_else(|| panic!("seed {seed}: not at rest by t = 60"));
        assert_eq!(run_to(t - 1e-9).at_rest_since, None, "seed {seed}");
        assert_eq!(run_to(t + 1e-9).at_rest_since, Some(t), "seed {seed}");
    }
}
