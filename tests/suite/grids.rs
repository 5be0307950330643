//! The grid's storage changes nothing but speed and memory: a closed box mapped on the dense
//! grid or on Isobe's compressed array (`engine.grid = "hashed"`, with the dense window it uses
//! where it can) gives the same summary and final state, bit for bit — periodic in y (where the
//! mask wraps round the top and bottom edges) and with walls and a lid.

use crate::common;

use common::{crate_path, same_run};
use serde_json::Value;
use vibrobed::Scenario;

fn load(file: &str, sets: &[&str], grid: &str) -> Scenario {
    let mut sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    sets.push(format!("engine.grid={grid}"));
    sets.push("engine.remap=global".to_string());
    sets.push("engine.check_invariants=true".to_string());
    Scenario::load(&crate_path(&format!("scenarios/{file}")), &sets).expect("scenario loads")
}

fn summary(s: &Scenario, grid: &str) -> Value {
    let (v, named) = same_run::summary(s, &["grid"]);
    assert_eq!(named[0], grid, "the summary names the grid that ran");
    v
}

fn same_on_either_grid(file: &str, sets: &[&str]) {
    let (dense, hashed) = (load(file, sets, "dense"), load(file, sets, "hashed"));
    let (a, b) = (summary(&dense, "dense"), summary(&hashed, "hashed"));
    assert!(
        a["events"]["rebuild"].as_u64().unwrap() > 3,
        "{file}: too few re-mappings to compare"
    );
    same_run::assert_same_runs(file, (&dense, &a), (&hashed, &b), 1000);
}

#[test]
fn a_gas_periodic_in_y_is_the_same_on_either_grid() {
    same_on_either_grid(
        "gas_periodic_phi03.json",
        &["run.duration=8", "run.warmup=1"],
    );
}

#[test]
fn a_box_with_walls_is_the_same_on_either_grid() {
    same_on_either_grid("box_walls.json", &["run.duration=3", "run.warmup=1"]);
}
