//! The elastic hard-disk gas reproduces the equation of state: the compressibility factor from
//! the collision virial matches Henderson's `Z = (1 + φ²/8)/(1 − φ)²` within 1% at φ = 0.1–0.4
//! (N = 2500, periodic box). Henderson's formula itself is accurate to a few 0.1% there.

use crate::common;

use vibrobed::physics::theory::henderson_z;
use vibrobed::run::{run, RunOptions};

fn measured_z(phi: f64, duration: f64, seed: u64) -> f64 {
    let json = format!(
        r#"{{"name": "eos", "seed": {seed},
        "domain": {{"width": 50, "x_boundary": "periodic", "y_boundary": "periodic"}},
        "particles": {{"count": 2500, "radius": 0.5, "packing_fraction": {phi}}},
        "run": {{"duration": {duration}, "warmup": 2}},
        "output": {{"sample_interval": 1}}}}"#
    );
    let summary = run(&common::scenario(&json), RunOptions::default()).unwrap();
    eprintln!("φ = {phi}: {} pair collisions", summary.events.pair);
    assert!(summary.events.pair > 200_000, "too few collisions for 1%");
    summary
        .compressibility_factor
        .expect("closed elastic box reports Z")
}

#[test]
fn compressibility_matches_henderson() {
    for (phi, duration) in [(0.1, 320.0), (0.2, 150.0), (0.3, 80.0), (0.4, 50.0)] {
        let z = measured_z(phi, duration, 7);
        let h = henderson_z(phi);
        let rel = (z - h).abs() / h;
        eprintln!(
            "φ = {phi}: Z = {z:.4}, Henderson {h:.4}, off by {:.3}%",
            100.0 * rel
        );
        assert!(rel < 0.01, "φ = {phi}: Z = {z}, Henderson {h}");
    }
}
