//! The event-driven engine (grid, masks, neighbour lists, DUTC, lazy updates, event tree)
//! against the all-pairs reference engine: the same collisions, pair for pair, with times equal
//! to round-off. Hard-disk dynamics is chaotic, so round-off differences between two correct
//! engines grow exponentially; the comparison therefore re-starts the reference from the
//! engine's state every window of a few collisions per disk, over thousands of events.

use crate::common;

use crate::common::reference;
use vibrobed::physics::flight::Flight;

use reference::Reference;
use vibrobed::engine::Collision;
use vibrobed::engine::{Scene, Simulation};
use vibrobed::scenario::RemapChoice;

/// The all-pairs reference started from the engine's disks in `snap` (the engine's time).
fn reference_from<F: Flight>(
    sim: &Simulation<F>,
    scene: &Scene,
    snap: &vibrobed::engine::Snapshot,
) -> Reference<F> {
    Reference::new(
        sim.flight(),
        snap,
        &sim.disks().radius.to_vec(),
        &sim.disks().mass.to_vec(),
        scene.sides,
        scene.top,
        scene.floor.clone(),
        scene.restitution.e,
    )
}

fn compare<F: Flight>(mut sim: Simulation<F>, scene: &Scene, total_events: usize) {
    sim.set_logging(true);
    let n = sim.disks().len();
    let target_per_window = (2 * n).max(20);
    let mut dt = 0.05;
    let mut compared = 0;
    let mut windows = 0;
    while compared < total_events {
        let t0 = sim.time();
        let snap = sim.snapshot(t0);
        let mut reference = reference_from(&sim, scene, &snap);
        if let (Some(laws), Some(spins)) = (scene.rough, sim.spins_at(t0)) {
            reference = reference.with_spins(laws, spins.iter().map(|s| s.1).collect());
        }
        sim.advance_to(t0 + dt).unwrap();
        let engine_log = sim.take_log();
        let reference_log = reference.run_until(t0 + dt);
        assert_same(&engine_log, &reference_log, windows);
        if let Some(spins) = sim.spins_at(t0 + dt) {
            for (k, (e, r)) in spins.iter().zip(reference.spins().unwrap()).enumerate() {
                assert!(
                    (e.1 - r).abs() <= 1e-8 * (1.0 + r.abs()),
                    "window {windows}: disk {k} spins at {} in the engine, {r} in the reference",
                    e.1
                );
            }
        }
        compared += engine_log.len();
        windows += 1;
        // Aim at a few collisions per disk per window.
        let got = engine_log.len().max(1) as f64;
        dt = (dt * target_per_window as f64 / got).clamp(1e-4, 10.0);
        assert!(windows < 10_000, "the comparison makes no progress");
    }
    let c = sim.counts();
    if scene.remap == RemapChoice::Local {
        // The local re-mapping was exercised: many disks left their shells.
        assert!(c.shell > n as u64, "only {} shell exits", c.shell);
    } else {
        assert_eq!(c.shell, 0);
    }
}

/// Compares the engine with each re-mapping (Isobe's global one, and the local one) against
/// the reference, on the scene `json` (which has no `engine` section); and the global one with
/// the disks renumbered in the engine (the log is in the scenario's numbering).
fn both_remaps(json: &str, events: usize, gravity: bool) {
    let with = |engine: &str| {
        format!(
            "{}, \"engine\": {engine}}}",
            json.trim_end().strip_suffix('}').expect("a JSON object")
        )
    };
    let global = with(r#"{"remap": "global"}"#);
    let local = with(r#"{"remap": "local"}"#);
    let renumbered = with(r#"{"remap": "global", "renumber": "on"}"#);
    for json in [global.as_str(), local.as_str(), renumbered.as_str()] {
        let (scene, _) = common::scene(json);
        if gravity {
            compare(common::ballistic(json), &scene, events);
        } else {
            compare(common::straight(json), &scene, events);
        }
    }
}

fn assert_same(engine: &[Collision], reference: &[Collision], window: usize) {
    assert_eq!(
        engine.len(),
        reference.len(),
        "window {window}: the engine saw {} collisions, the reference {}\nengine: {:?}\nreference: {:?}",
        engine.len(),
        reference.len(),
        engine.iter().take(5).collect::<Vec<_>>(),
        reference.iter().take(5).collect::<Vec<_>>()
    );
    for (k, (a, b)) in engine.iter().zip(reference).enumerate() {
        let same_event = a.disk == b.disk && a.partner == b.partner;
        let close = (a.time - b.time).abs() <= 1e-9 * (1.0 + a.time.abs());
        if same_event && close {
            continue;
        }
        // Near-simultaneous events may come in either order.
        let swapped = reference.iter().any(|c| {
            c.disk == a.disk
                && c.partner == a.partner
                && (c.time - a.time).abs() <= 1e-9 * (1.0 + a.time.abs())
        });
        assert!(
            swapped,
            "window {window}, collision {k}: engine {a:?} vs reference {b:?}"
        );
    }
}

#[test]
fn periodic_gas_at_low_density() {
    let json = r#"{"name": "bf", "seed": 11,
        "domain": {"width": 12, "x_boundary": "periodic", "y_boundary": "periodic", "height": 12},
        "particles": {"count": 40, "radius": 0.5},
        "run": {"duration": 1}}"#;
    both_remaps(json, 3000, false);
}

/// A dilute gas between side walls (periodic in height): the local re-mapping anchors a disk
/// that leaves its shell ahead of it, but not beyond a wall.
#[test]
fn dilute_gas_between_side_walls() {
    let json = r#"{"name": "bf", "seed": 15,
        "domain": {"width": 14, "x_boundary": "walls", "y_boundary": "periodic", "height": 12},
        "particles": {"count": 30, "radius": 0.5},
        "run": {"duration": 1}}"#;
    both_remaps(json, 3000, false);
}

#[test]
fn periodic_gas_at_high_density() {
    let json = r#"{"name": "bf", "seed": 12,
        "domain": {"width": 8, "x_boundary": "periodic", "y_boundary": "periodic"},
        "particles": {"count": 56, "radius": 0.5, "packing_fraction": 0.7},
        "run": {"duration": 1}}"#;
    both_remaps(json, 5000, false);
}

#[test]
fn box_with_walls_and_lid() {
    let json = r#"{"name": "bf", "seed": 13,
        "domain": {"width": 10, "height": 9, "x_boundary": "walls", "y_boundary": "lid"},
        "floor": {"restitution": 1.0},
        "particles": {"count": 30, "radius": 0.5},
        "run": {"duration": 1}}"#;
    both_remaps(json, 3000, false);
}

#[test]
fn inelastic_polydisperse_mixture() {
    let json = r#"{"name": "bf", "seed": 14,
        "domain": {"width": 14, "height": 14, "x_boundary": "periodic", "y_boundary": "periodic"},
        "particles": {"radius": {"species": [{"count": 20, "radius": 0.5}, {"count": 10, "radius": 0.8, "mass": 3.0}, {"count": 4, "radius": 1.2}]}},
        "collisions": {"restitution": 0.95},
        "run": {"duration": 1}}"#;
    both_remaps(json, 3000, false);
}

#[test]
fn bed_under_gravity_on_a_static_floor() {
    let json = r#"{"name": "bf", "seed": 15,
        "domain": {"width": 8, "x_boundary": "walls", "y_boundary": "open"},
        "gravity": 1.0,
        "floor": {"restitution": 1.0},
        "particles": {"count": 30, "radius": 0.5, "temperature": 2.0},
        "run": {"duration": 1}}"#;
    both_remaps(json, 3000, true);
}

/// Rough disks (pairs with a capped tangential restitution, walls and lid with their own; the
/// normal parts elastic and β = 1, so that the gas cools only where the friction caps the
/// tangential impulse): the engine and the reference see the same collisions, and the disks end
/// each window with the same spins.
#[test]
fn rough_disks_in_a_box_with_walls_and_lid() {
    let json = r#"{"name": "bf", "seed": 16,
        "domain": {"width": 10, "height": 9, "x_boundary": "walls", "y_boundary": "lid",
                   "wall_friction": 0.4, "wall_tangential_restitution": 1.0},
        "floor": {"restitution": 1.0, "friction": 0.3},
        "particles": {"count": 30, "radius": 0.5, "rotational_temperature": 1.0},
        "collisions": {"friction": 0.25, "tangential_restitution": 1.0},
        "run": {"duration": 1}}"#;
    both_remaps(json, 3000, false);
}

/// A rough polydisperse bed under gravity on a vibrating floor with friction.
#[test]
fn rough_polydisperse_bed_on_a_vibrating_floor() {
    let json = r#"{"name": "bf", "seed": 17,
        "domain": {"width": 8, "x_boundary": "periodic", "y_boundary": "open"},
        "gravity": 1.0,
        "floor": {"restitution": 0.95, "amplitude": 0.2, "frequency": 1.0, "friction": 0.5,
                  "tangential_restitution": 0.2},
        "particles": {"radius": {"species": [{"count": 20, "radius": 0.5}, {"count": 8, "radius": 0.7}]},
                      "temperature": 2.0, "inertia_factor": 0.4, "rotational_temperature": 0.5},
        "collisions": {"restitution": 0.98, "tangential_restitution": 0.5},
        "run": {"duration": 1}}"#;
    both_remaps(json, 3000, true);
}

/// A small pour: disks entering through an inlet, each entry an exact event after which the
/// engine rebuilds its grid, lists and queue over one more disk. Between entries the engine and
/// the reference (restarted from the engine's state just after each entry, the new disk
/// included) see the same collisions; elastic, so that nothing comes to rest (the reference has
/// no rules for rest).
#[test]
fn a_small_pour_between_entries() {
    let json = r#"{"name": "bf", "seed": 16,
        "domain": {"width": 8, "x_boundary": "walls", "y_boundary": "open"},
        "gravity": 1.0,
        "floor": {"restitution": 1.0},
        "particles": {"count": 10, "radius": 0.5, "temperature": 2.0},
        "inlets": [{"x": {"from": 1.0, "to": 7.0}, "y": {"from": 10.0, "to": 12.0},
                    "rate": 2.0, "start": 0.25, "end": 10.25, "speed": 1.0, "temperature": 0.5}],
        "run": {"duration": 11}}"#;
    for remap in ["global", "local"] {
        let json = format!(
            "{}, \"engine\": {{\"remap\": \"{remap}\"}}}}",
            json.trim_end().strip_suffix('}').unwrap()
        );
        let (scene, _) = common::scene(&json);
        let mut sim = common::ballistic(&json);
        sim.set_logging(true);
        let mut compared = 0;
        let mut t0 = 0.0;
        for k in 0..=20 {
            let entry = 0.25 + 0.5 * k as f64;
            // Windows of 0.05 up to the entry, then the entry itself in a step of 10⁻¹².
            while t0 < entry {
                let t1 = (t0 + 0.05f64).min(entry);
                let snap = sim.snapshot(t0);
                assert_eq!(snap.ids, (0..snap.x.len() as u32).collect::<Vec<_>>());
                let mut reference = reference_from(&sim, &scene, &snap);
                sim.advance_to(t1).unwrap();
                let engine_log = sim.take_log();
                assert_same(&engine_log, &reference.run_until(t1), k);
                compared += engine_log.len();
                t0 = t1;
            }
            if k < 20 {
                t0 = entry + 1e-12;
                sim.advance_to(t0).unwrap();
                sim.take_log();
                assert_eq!(sim.pool().unwrap().flow.entered, k as u64 + 1, "{remap}");
            }
        }
        assert_eq!(sim.disks().len(), 30);
        assert!(
            compared > 300,
            "{remap}: only {compared} collisions compared"
        );
    }
}
