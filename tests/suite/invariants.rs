//! Conservation and no-overlap invariants, with the engine's checks switched on.

use crate::common;

use vibrobed::run::{run, RunOptions};

#[test]
fn elastic_periodic_gas_conserves_energy_and_momentum() {
    let json = r#"{"name": "inv", "seed": 3,
        "domain": {"width": 30, "x_boundary": "periodic", "y_boundary": "periodic"},
        "particles": {"count": 600, "radius": 0.5, "packing_fraction": 0.5},
        "run": {"duration": 10}}"#;
    let mut sim = common::straight(json);
    sim.set_checks(true);
    let p = |s: &vibrobed::engine::Snapshot, m: &[f64]| {
        let px: f64 = s.vx.iter().zip(m).map(|(v, m)| v * m).sum();
        let py: f64 = s.vy.iter().zip(m).map(|(v, m)| v * m).sum();
        let ke: f64 = (0..m.len())
            .map(|i| 0.5 * m[i] * (s.vx[i] * s.vx[i] + s.vy[i] * s.vy[i]))
            .sum();
        (px, py, ke)
    };
    let m = sim.disks().mass.to_vec();
    let (px0, py0, ke0) = p(&sim.snapshot(0.0), &m);
    for k in 1..=10 {
        let t = k as f64;
        sim.advance_to(t).unwrap();
        let snap = sim.snapshot(t);
        sim.check_no_overlap(t).unwrap();
        let (px, py, ke) = p(&snap, &m);
        assert!(
            (px - px0).abs() < 1e-10 && (py - py0).abs() < 1e-10,
            "momentum drifts"
        );
        assert!(
            (ke - ke0).abs() < 1e-11 * ke0,
            "energy drifts: {ke} vs {ke0}"
        );
    }
    assert!(sim.counts().pair > 10_000);
    assert!(sim.max_overlap() < 1e-9);
}

#[test]
fn invariant_checks_run_through_a_whole_scenario() {
    let json = r#"{"name": "inv", "seed": 4,
        "domain": {"width": 20, "height": 20, "x_boundary": "walls", "y_boundary": "lid", "wall_restitution": 0.9},
        "floor": {"restitution": 0.8},
        "particles": {"radius": {"min": 0.4, "max": 0.6}, "count": 300},
        "collisions": {"restitution": 0.9},
        "run": {"duration": 5},
        "output": {"sample_interval": 0.1},
        "engine": {"check_invariants": true}}"#;
    let s = run(&common::scenario(json), RunOptions::default()).unwrap();
    assert!(s.energy.balance_error < 1e-9, "{}", s.energy.balance_error);
    assert!(s.energy.dissipated > 0.0);
    assert!(s.events.pair > 1000 && s.events.wall > 0 && s.events.lid > 0 && s.events.floor > 0);
}

#[test]
fn same_seed_same_result_bit_for_bit() {
    let json = r#"{"name": "det", "seed": 9,
        "domain": {"width": 20, "x_boundary": "periodic", "y_boundary": "periodic"},
        "particles": {"count": 200, "radius": 0.5, "packing_fraction": 0.4},
        "run": {"duration": 3}}"#;
    let a = run(&common::scenario(json), RunOptions::default()).unwrap();
    let b = run(&common::scenario(json), RunOptions::default()).unwrap();
    assert_eq!(a.events, b.events);
    assert_eq!(
        a.energy.final_.kinetic.to_bits(),
        b.energy.final_.kinetic.to_bits()
    );
    assert_eq!(
        a.temperature.unwrap().x.to_bits(),
        b.temperature.unwrap().x.to_bits()
    );
    let c = run(
        &common::scenario(&json.replace("\"seed\": 9", "\"seed\": 10")),
        RunOptions::default(),
    )
    .unwrap();
    assert_ne!(a.events, c.events, "another seed gives another run");
}
