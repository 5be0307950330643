//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod reference;
pub mod same_run;
pub mod svg;

use vibrobed::engine::{Scene, Simulation};
use vibrobed::physics::disks::Disks;
use vibrobed::physics::flight::{Ballistic, Straight};
use vibrobed::Scenario;

/// A validated scenario from JSON text.
pub fn scenario(json: &str) -> Scenario {
    Scenario::from_json(json).unwrap_or_else(|e| panic!("test scenario is invalid: {e}"))
}

/// The resolved scene and initial disks of a scenario.
pub fn scene(json: &str) -> (Scene, Disks) {
    Scene::build(&scenario(json)).expect("scene builds")
}

/// An engine without gravity.
pub fn straight(json: &str) -> Simulation<Straight> {
    let (scene, disks) = scene(json);
    assert!(scene.gravity.is_none());
    Simulation::new(Straight, &scene, disks).expect("engine starts")
}

/// An engine with gravity.
pub fn ballistic(json: &str) -> Simulation<Ballistic> {
    let (scene, disks) = scene(json);
    let g = scene.gravity.expect("scene has gravity");
    Simulation::new(Ballistic { g }, &scene, disks).expect("engine starts")
}

/// Path of a file in the crate.
pub fn crate_path(rel: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// Σ m v_y of the disks at the engine's time.
pub fn momentum_y<E: vibrobed::schemes::Integrator>(sim: &E) -> f64 {
    let mut p = 0.0;
    let t = sim.time();
    sim.visit_states(t, |i, s| p += sim.disks().mass[i] * s[3]);
    p
}
