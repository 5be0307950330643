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
