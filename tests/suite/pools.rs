//! Disks that leave through a floor orifice and enter through inlets: the pool keeps every id
//! once (none lost, none duplicated), the number of disks is conserved (in − out = live −
//! initial), a run is deterministic, the corner contact and the exit are exact against analytic
//! drops, entries happen at their exact times at free places, and bad orifices and inlets are
//! refused naming the field.

use crate::common::{ballistic, crate_path};
use std::collections::BTreeSet;
use vibrobed::engine::Progress;

/// A shipped scene with `edit` applied to its JSON.
fn shipped(name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> String {
    let text = std::fs::read_to_string(crate_path(&format!("scenarios/{name}"))).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    edit(&mut v);
    v.to_string()
}

/// The silo without its recycling inlet: it drains.
fn silo(_: &str) -> String {
    shipped("silo.json", |v| {
        v.as_object_mut().unwrap().remove("inlets");
    })
}

/// Every live disk has a distinct id below the initial count; ids that left never come back
/// (no inlet); the counts add up at every stop.
#[test]
fn ids_are_kept_none_lost_none_duplicated_and_the_count_is_conserved() {
    let mut sim = ballistic(&silo(""));
    let mut gone: BTreeSet<u32> = BTreeSet::new();
    let mut before: BTreeSet<u32> = (0..400).collect();
    let mut out_seen = 0;
    for k in 1..=60 {
        let t = k as f64;
        assert_eq!(sim.advance_to(t).unwrap(), Progress::Reached);
        let snap = sim.snapshot(t);
        let ids: BTreeSet<u32> = snap.ids.iter().copied().collect();
        assert_eq!(ids.len(), snap.ids.len(), "an id twice at t = {t}");
        assert_eq!(snap.x.len(), ids.len());
        assert!(ids.is_subset(&before), "an id came back at t = {t}");
        for id in before.difference(&ids) {
            gone.insert(*id);
        }
        let flow = sim.pool().unwrap().flow;
        assert_eq!(flow.initial + flow.entered, ids.len() as u64 + flow.left);
        assert_eq!(flow.left as usize, gone.len(), "out counts the ids gone");
        // The ones present are above the floor's underside; those gone left below it.
        for (i, &y) in snap.y.iter().enumerate() {
            assert!(y > -0.5 - 1e-9, "disk {} at y = {y}", snap.ids[i]);
        }
        out_seen = flow.left;
        before = ids;
    }
    assert!(out_seen > 100, "the silo drains: {out_seen} out");
}

/// The same scene twice gives the same exits at the same times, bit for bit.
#[test]
fn a_draining_silo_is_deterministic() {
    let run = || {
        let mut sim = ballistic(&silo(""));
        sim.advance_to(20.0).unwrap();
        let f = sim.pool().unwrap().flow;
        let s = sim.snapshot(20.0);
        (
            f.left,
            f.last_exit.to_bits(),
            f.sum_gap.to_bits(),
            s.ids,
            s.x,
        )
    };
    assert_eq!(run(), run());
}

/// A disk dropped straight onto a corner from rest bounces back up elastically at the time the
/// parabola puts its centre a radius above the corner, and no energy is lost.
#[test]
fn a_disk_dropped_on_a_corner_bounces_at_the_analytic_time() {
    let json = r#"{
        "name": "drop on a corner",
        "domain": { "width": 10.0, "x_boundary": "walls", "y_boundary": "open" },
        "gravity": 2.0,
        "floor": { "orifice": { "from": 4.0, "to": 6.0 } },
        "particles": { "count": 1, "radius": 0.5, "temperature": 0.0,
                       "placement": { "positions": [[4.0, 3.0]], "velocities": [[0.0, 0.0]] } },
        "run": { "duration": 10.0 }
    }"#;
    let mut sim = ballistic(json);
    sim.set_logging(true);
    let t_hit = (2.0f64 * (3.0 - 0.5) / 2.0).sqrt();
    sim.advance_to(t_hit * 1.5).unwrap();
    let log = sim.take_log();
    assert!(!log.is_empty(), "the disk hit something");
    let first = log[0].time;
    assert!(
        (first - t_hit).abs() < 1e-12 * t_hit,
        "hit at {first}, expected {t_hit}"
    );
    let s = sim.snapshot(t_hit * 1.5);
    // Straight back up: after the elastic bounce at speed g t_hit, it rises.
    let v = 2.0 * t_hit;
    let dt = 0.5 * t_hit;
    assert!((s.vy[0] - (v - 2.0 * dt)).abs() < 1e-12, "vy = {}", s.vy[0]);
    assert_eq!(sim.pool().unwrap().flow.corner, 1);
}

/// A disk dropped just inside the gap, farther than a radius from both corners, falls through
/// and leaves when its centre is a radius below the floor.
#[test]
fn a_disk_through_the_gap_leaves_at_the_analytic_time() {
    let json = r#"{
        "name": "drop through",
        "domain": { "width": 10.0, "x_boundary": "walls", "y_boundary": "open" },
        "gravity": 1.0,
        "floor": { "orifice": { "from": 4.0, "to": 6.0 } },
        "particles": { "count": 2, "radius": 0.5, "temperature": 0.0,
                       "placement": { "positions": [[5.0, 2.0], [1.0, 0.5]],
                                      "velocities": [[0.0, 0.0], [0.0, 0.0]] } },
        "run": { "duration": 10.0 }
    }"#;
    let mut sim = ballistic(json);
    let t_out = (2.0f64 * 2.5).sqrt();
    sim.advance_to(t_out * (1.0 - 1e-9)).unwrap();
    assert_eq!(sim.pool().unwrap().flow.left, 0);
    sim.advance_to(t_out * (1.0 + 1e-9)).unwrap();
    let f = sim.pool().unwrap().flow;
    assert_eq!(f.left, 1);
    assert!((f.last_exit - t_out).abs() < 1e-12, "{}", f.last_exit);
    let s = sim.snapshot(t_out * 2.0);
    assert_eq!(
        s.ids,
        vec![1],
        "the disk at rest on the floor stays, by its id"
    );
    // Energy carried out: m g y at y = −a plus ½ m v², v = g t.
    assert!((f.energy_out - (-0.5 + 0.5 * t_out * t_out)).abs() < 1e-12);
}

/// Bad orifices are refused naming the field.
#[test]
fn bad_orifices_are_refused_naming_the_field() {
    let base = std::fs::read_to_string(crate_path("scenarios/silo.json")).unwrap();
    let cases = [
        ("\"to\": 17.15", "\"to\": 40.0", "floor.orifice.to"),
        ("\"from\": 13.15", "\"from\": -1.0", "floor.orifice.from"),
        ("\"to\": 17.15", "\"to\": 13.9", "floor.orifice.to"),
        (
            "\"restitution\": 0.5,",
            "\"restitution\": 0.5, \"amplitude\": 0.1, \"frequency\": 1.0,",
            "floor.orifice",
        ),
        (
            "\"run\": {",
            "\"engine\": { \"scheme\": \"time-step\" }, \"run\": {",
            "floor.orifice",
        ),
    ];
    for (from, to, field) in cases {
        let json = base.replacen(from, to, 1);
        let e = vibrobed::Scenario::from_json(&json).expect_err(to);
        assert!(e.to_string().contains(field), "{to}: {e}");
    }
}

/// The pour: new disks take fresh ids in order, every id at most once, none lost; the count
/// is conserved at every stop; the invariant checks (no overlap, energy with what came in)
/// hold at every sample of the whole run.
#[test]
fn a_pour_brings_every_disk_once_and_conserves_the_count() {
    let json = shipped("pour.json", |v| {
        v["run"]["duration"] = 30.0.into();
        v["run"]["warmup"] = 0.0.into();
    });
    let mut sim = ballistic(&json);
    sim.set_checks(true);
    let mut seen = 20;
    for k in 1..=30 {
        let t = k as f64;
        assert_eq!(sim.advance_to(t).unwrap(), Progress::Reached);
        sim.check_no_overlap(t).unwrap();
        let snap = sim.snapshot(t);
        let f = sim.pool().unwrap().flow;
        assert_eq!(f.initial + f.entered - f.left, snap.ids.len() as u64);
        let ids: BTreeSet<u32> = snap.ids.iter().copied().collect();
        assert_eq!(ids.len(), snap.ids.len(), "an id twice");
        // No orifice: the ids are exactly 0 … live − 1, the newest the latest to enter.
        assert_eq!(ids, (0..snap.ids.len() as u32).collect::<BTreeSet<_>>());
        assert!(snap.ids.len() >= seen);
        seen = snap.ids.len();
    }
    assert_eq!(seen, 520, "all 500 poured by t = 25");
}

/// A lone inlet over an empty floor: a disk every 1/4 from t = 0.1, falling at speed 5 from
/// y = 50.
const DRIP: &str = r#"{
    "name": "drip",
    "domain": { "width": 10.0, "x_boundary": "walls", "y_boundary": "open" },
    "gravity": 1.0,
    "floor": { "restitution": 0.5 },
    "particles": { "count": 1, "radius": 0.5, "temperature": 0.0,
                   "placement": { "positions": [[1.0, 0.5]], "velocities": [[0.0, 0.0]] } },
    "inlets": [ { "x": { "from": 5.0, "to": 5.0 }, "y": { "from": 50.0, "to": 50.0 },
                  "rate": 4.0, "start": 0.1, "speed": 5.0 } ],
    "run": { "duration": 2.0 }
}"#;

/// The drip: its disks enter at the exact scheduled times (one every 1/rate), falling at the
/// inlet's speed (fast enough to clear the one place between entries).
#[test]
fn disks_enter_at_their_scheduled_times() {
    let mut sim = ballistic(DRIP);
    // Entries at 0.1, 0.35, 0.6, …: just before and after each.
    for j in 0..4 {
        let t = 0.1 + j as f64 * 0.25;
        sim.advance_to(t - 1e-9).unwrap();
        assert_eq!(sim.pool().unwrap().flow.entered, j);
        sim.advance_to(t + 1e-9).unwrap();
        assert_eq!(sim.pool().unwrap().flow.entered, j + 1);
        let s = sim.snapshot(t + 1e-9);
        let row = s.ids.iter().position(|&id| id == 1 + j as u32).unwrap();
        assert!((s.vy[row] + 5.0 + 1e-9).abs() < 1e-12, "vy = {}", s.vy[row]);
        assert!((s.y[row] - 50.0).abs() < 1e-8 && (s.x[row] - 5.0).abs() < 1e-12);
    }
}

/// The benchmarks' loop (`step_events`) is the event loop: it wakes for the entries through an
/// inlet, as `advance_to` does.
#[test]
fn stepping_events_enters_disks_as_advancing_does() {
    let mut stepped = ballistic(DRIP);
    for _ in 0..100_000 {
        if stepped.time() >= 0.95 {
            break;
        }
        stepped.step_events(1).unwrap();
    }
    let t = stepped.time();
    assert!((0.95..1.1).contains(&t), "stepped to t = {t}");
    let mut advanced = ballistic(DRIP);
    advanced.advance_to(t).unwrap();
    // Entries at 0.1, 0.35, 0.6 and 0.85 before t; the next at 1.1.
    assert_eq!(stepped.pool().unwrap().flow.entered, 4);
    assert_eq!(advanced.pool().unwrap().flow.entered, 4);
}

/// An inlet whose one place is taken waits: the next disk enters once the one below has
/// fallen clear, and the wait is counted.
#[test]
fn an_entry_with_no_free_place_waits() {
    let json = r#"{
        "name": "blocked",
        "domain": { "width": 10.0, "x_boundary": "walls", "y_boundary": "open" },
        "gravity": 1.0,
        "floor": { "restitution": 0.5 },
        "particles": { "count": 1, "radius": 0.5, "temperature": 0.0,
                       "placement": { "positions": [[1.0, 0.5]], "velocities": [[0.0, 0.0]] } },
        "inlets": [ { "x": { "from": 5.0, "to": 5.0 }, "y": { "from": 50.0, "to": 50.0 },
                      "count": 2, "start": 0.0, "end": 0.01 } ],
        "run": { "duration": 5.0 }
    }"#;
    let mut sim = ballistic(json);
    sim.advance_to(0.02).unwrap();
    let f = sim.pool().unwrap().flow;
    assert_eq!((f.entered, f.waits), (1, 1), "the second waits");
    sim.advance_to(5.0).unwrap();
    let f = sim.pool().unwrap().flow;
    assert_eq!(f.entered, 2, "and enters later");
    sim.check_no_overlap(5.0).unwrap();
}

/// The silo with recycling: disks that leave come back with their ids, so the live set keeps
/// its ids 0 … 399, and out = in at the end (each one re-enters at once: there is room).
#[test]
fn recycled_disks_come_back_with_their_ids() {
    let mut sim = ballistic(&shipped("silo.json", |_| {}));
    sim.set_checks(true);
    for k in 1..=20 {
        let t = k as f64;
        sim.advance_to(t).unwrap();
        let s = sim.snapshot(t);
        assert_eq!(s.ids, (0..400).collect::<Vec<u32>>(), "at t = {t}");
    }
    let f = sim.pool().unwrap().flow;
    assert!(f.left > 50, "{} out", f.left);
    assert_eq!(f.left, f.entered);
}

/// Bad inlets are refused naming the field.
#[test]
fn bad_inlets_are_refused_naming_the_field() {
    type Edit = fn(&mut serde_json::Value);
    let cases: [(&str, Edit); 6] = [
        ("inlets.0.y.from", |v| {
            v["inlets"][0]["y"]["from"] = 0.2.into()
        }),
        ("inlets.0.x", |v| v["inlets"][0]["x"]["to"] = 45.0.into()),
        ("inlets.0.count", |v| v["inlets"][0]["count"] = 5.into()),
        ("inlets.0.end", |v| v["inlets"][0]["end"] = (-1.0).into()),
        ("inlets.0.speed", |v| {
            v["inlets"][0]["speed"] = (-1.0).into()
        }),
        ("inlets.0.recycle", |v| {
            v["inlets"][0]["recycle"] = true.into()
        }),
    ];
    for (field, edit) in cases {
        let json = shipped("pour.json", edit);
        let e = vibrobed::Scenario::from_json(&json).expect_err(field);
        assert!(e.to_string().contains(field), "{field}: {e}");
    }
}

/// Isobe's tree and the calendar pop the same events in a scene whose disks enter, leave and
/// come back: the pool's re-mappings and entries change nothing in the order.
#[test]
fn the_tree_and_the_calendar_agree_on_a_recycling_silo() {
    let run = |queue: &str| {
        let json = shipped("silo.json", |v| {
            v["engine"] = serde_json::json!({ "queue": queue });
        });
        let mut sim = ballistic(&json);
        sim.advance_to(15.0).unwrap();
        let f = sim.pool().unwrap().flow;
        let s = sim.snapshot(15.0);
        (
            sim.counts(),
            f.left,
            f.entered,
            f.last_exit.to_bits(),
            s.x,
            s.vy,
        )
    };
    assert_eq!(run("tree"), run("calendar"));
}

/// A vibrated bed whose most energetic disks leave at an exit height of 10, recycled or not.
const FOUNTAIN: &str = r#"{
    "name": "vibrated bed losing disks at the top",
    "seed": 4,
    "domain": { "width": 20.0, "x_boundary": "periodic", "y_boundary": "open",
                "exit_height": 10.0 },
    "gravity": 1.0,
    "floor": { "gamma": 4.0, "frequency": 0.5, "restitution": 0.95 },
    "particles": { "count": 60, "radius": 0.5, "temperature": 0.5 },
    "collisions": { "restitution": 0.95 },
    "run": { "duration": 40.0, "warmup": 5.0 }
}"#;

type Engine = vibrobed::engine::Simulation<vibrobed::physics::flight::Ballistic>;

/// The energy of a scene at `t`: Σ m (½ v² + g y) of the live disks (their masses by id),
/// with Σ ½ I ω² of rough disks.
fn energy(sim: &Engine, t: f64) -> f64 {
    let s = sim.snapshot(t);
    let (mass, g) = (&sim.disks().mass, sim.gravity());
    let translational: f64 = (0..s.x.len())
        .map(|k| mass[k] * (0.5 * (s.vx[k] * s.vx[k] + s.vy[k] * s.vy[k]) + g * s.y[k]))
        .sum();
    translational + sim.rotational_energy(t).unwrap_or(0.0)
}

/// The energy budget at `t` against the energy `e0` at the start, relative to its largest
/// term: now − start − work of the floor + dissipated + carried out − brought in.
fn budget_error(sim: &Engine, t: f64, e0: f64) -> f64 {
    let flow = sim.energy_flow_at(t);
    let f = sim.pool().unwrap().flow;
    let balance =
        energy(sim, t) - e0 - flow.injected + flow.dissipated + f.energy_out - f.energy_in;
    let scale = [
        e0,
        flow.injected,
        flow.dissipated,
        f.energy_out,
        f.energy_in,
    ]
    .iter()
    .fold(0.0f64, |m, v| m.max(v.abs()));
    balance.abs() / scale
}

/// A disk thrown up from the floor leaves when its centre reaches the exit height, at the
/// smaller root of y0 + v t − ½ g t² = h, carrying out its energy; a disk thrown lower turns
/// back and stays, by its id.
#[test]
fn a_disk_thrown_up_leaves_at_the_exit_height_at_the_analytic_time() {
    let (g, h, y0, v, vx): (f64, f64, f64, f64, f64) = (2.0, 10.0, 0.5, 7.0, 0.3);
    let json = format!(
        r#"{{
        "name": "throw",
        "domain": {{ "width": 10.0, "x_boundary": "walls", "y_boundary": "open",
                     "exit_height": {h} }},
        "gravity": {g},
        "floor": {{}},
        "particles": {{ "count": 2, "radius": 0.5, "temperature": 0.0,
                       "placement": {{ "positions": [[5.0, {y0}], [2.0, {y0}]],
                                      "velocities": [[{vx}, {v}], [0.0, 5.0]] }} }},
        "run": {{ "duration": 10.0 }}
    }}"#
    );
    let mut sim = ballistic(&json);
    let t_out = (v - (v * v - 2.0 * g * (h - y0)).sqrt()) / g;
    sim.advance_to(t_out * (1.0 - 1e-9)).unwrap();
    assert_eq!(sim.pool().unwrap().flow.left, 0, "still in just before");
    sim.advance_to(t_out * (1.0 + 1e-9)).unwrap();
    let f = sim.pool().unwrap().flow;
    assert_eq!((f.left, f.top), (1, 1));
    assert!(
        (f.last_exit - t_out).abs() < 1e-12 * t_out,
        "left at {}, expected {t_out}",
        f.last_exit
    );
    // What it carried out is what it had: ½ m v² + m g y0, m = 1.
    let e0 = 0.5 * (vx * vx + v * v) + g * y0;
    assert!(
        (f.energy_out - e0).abs() < 1e-12 * e0,
        "{} vs {e0}",
        f.energy_out
    );
    // The other rises to 0.5 + 25/4 < 10, falls back and bounces on: it never leaves.
    sim.advance_to(10.0).unwrap();
    assert_eq!(sim.snapshot(10.0).ids, vec![1]);
    assert_eq!(sim.pool().unwrap().flow.left, 1);
}

/// Disks thrown out of a vibrated bed at the top: at every stop no overlap, the energy budget
/// closes with what was carried out, in − out = live − initial, every exit is a top exit and
/// the live disks are those never seen to leave.
#[test]
fn exits_at_the_top_conserve_number_and_energy() {
    let mut sim = ballistic(FOUNTAIN);
    sim.set_checks(true);
    let e0 = energy(&sim, 0.0);
    let mut before: BTreeSet<u32> = (0..60).collect();
    for k in 1..=40 {
        let t = k as f64;
        assert_eq!(sim.advance_to(t).unwrap(), Progress::Reached);
        sim.check_no_overlap(t).unwrap();
        let snap = sim.snapshot(t);
        let ids: BTreeSet<u32> = snap.ids.iter().copied().collect();
        assert!(ids.is_subset(&before), "an id came back at t = {t}");
        let f = sim.pool().unwrap().flow;
        assert_eq!(f.top, f.left);
        assert_eq!(60 - f.left, ids.len() as u64, "at t = {t}");
        // Those present are below the exit height.
        assert!(snap.y.iter().all(|&y| y < 10.0), "a disk above 10 at {t}");
        let error = budget_error(&sim, t, e0);
        assert!(error < 1e-12, "energy budget off by {error:e} at {t}");
        before = ids;
    }
    assert!(
        before.len() < 40,
        "the bed loses disks: {} left",
        before.len()
    );
}

/// The energy budget closes with the energy carried out at the top and brought back in by a
/// recycling inlet, and the recycled disks keep their ids: the live set is always the 60 ids
/// the scene began with.
#[test]
fn disks_leaving_at_the_top_are_recycled_with_their_ids() {
    let mut v: serde_json::Value = serde_json::from_str(FOUNTAIN).unwrap();
    v["inlets"] = serde_json::json!([{
        "x": { "from": 1.0, "to": 19.0 }, "y": { "from": 6.0, "to": 8.0 }, "recycle": true
    }]);
    let mut sim = ballistic(&v.to_string());
    sim.set_checks(true);
    let e0 = energy(&sim, 0.0);
    for k in 1..=40 {
        let t = k as f64;
        sim.advance_to(t).unwrap();
        assert_eq!(
            sim.snapshot(t).ids,
            (0..60).collect::<Vec<u32>>(),
            "at t = {t}"
        );
        let error = budget_error(&sim, t, e0);
        assert!(error < 1e-12, "energy budget off by {error:e} at {t}");
    }
    let f = sim.pool().unwrap().flow;
    assert!(f.top > 20, "{} out at the top", f.top);
    assert_eq!(f.left, f.entered);
    assert!(f.energy_in > 0.0 && f.energy_out > f.energy_in);
}

/// Two runs of the fountain agree bit for bit: exits, their times, the live disks' states.
#[test]
fn exits_at_the_top_are_deterministic() {
    let run = || {
        let mut sim = ballistic(FOUNTAIN);
        sim.advance_to(30.0).unwrap();
        let f = sim.pool().unwrap().flow;
        let s = sim.snapshot(30.0);
        (
            f.top,
            f.last_exit.to_bits(),
            f.energy_out.to_bits(),
            s.ids,
            s.x,
            s.vy,
        )
    };
    let (one, two) = (run(), run());
    assert!(one.0 > 10, "{} out", one.0);
    assert_eq!(one, two);
}

/// Without `domain.exit_height` nothing leaves at the top, though disks rise above 10, and a
/// scene with neither inlets nor an orifice has no pool: the exit is no event of it at all.
#[test]
fn without_an_exit_height_nothing_leaves_at_the_top() {
    let mut v: serde_json::Value = serde_json::from_str(FOUNTAIN).unwrap();
    v["domain"].as_object_mut().unwrap().remove("exit_height");
    let mut sim = ballistic(&v.to_string());
    assert!(sim.pool().is_none());
    let mut highest = f64::NEG_INFINITY;
    for k in 1..=200 {
        let t = 0.1 * k as f64;
        sim.advance_to(t).unwrap();
        let s = sim.snapshot(t);
        assert_eq!(s.x.len(), 60);
        highest = s.y.iter().copied().fold(highest, f64::max);
    }
    assert!(highest > 10.0, "the highest centre seen: {highest}");
}

/// The pour with its inlet bringing radii drawn uniformly in [0.3, 0.6] (equal areal density:
/// mass (a / 0.5)², the bed's disks of 0.5 weighing 1), for `duration`.
fn polydisperse_pour(duration: f64) -> String {
    shipped("pour.json", |v| {
        v["run"]["duration"] = duration.into();
        v["run"]["warmup"] = 0.0.into();
        v["inlets"][0]["radius"] = serde_json::json!({ "min": 0.3, "max": 0.6 });
    })
}

/// A polydisperse pour: every disk that entered has its radius in the inlet's range, the radii
/// are spread over it (not one value), masses follow equal areal density, the count is
/// conserved, no pair overlaps, and the energy budget closes with what came in.
#[test]
fn an_inlet_brings_sizes_from_its_distribution_and_the_budget_closes() {
    let mut sim = ballistic(&polydisperse_pour(30.0));
    sim.set_checks(true);
    let e0 = energy(&sim, 0.0);
    for k in 1..=30 {
        let t = k as f64;
        assert_eq!(sim.advance_to(t).unwrap(), Progress::Reached);
        sim.check_no_overlap(t).unwrap();
        let f = sim.pool().unwrap().flow;
        assert_eq!(
            f.initial + f.entered - f.left,
            sim.snapshot(t).ids.len() as u64
        );
        let error = budget_error(&sim, t, e0);
        assert!(error < 1e-12, "energy budget off by {error:e} at {t}");
    }
    let pool = sim.pool().unwrap();
    assert_eq!(pool.flow.entered, 500);
    let view = pool.view();
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for (row, &id) in pool.ids().iter().enumerate() {
        let (a, m) = (view.radius[row], view.mass[row]);
        if id < 20 {
            assert_eq!((a, m), (0.5, 1.0), "the bed's disk {id}");
            continue;
        }
        assert!((0.3..=0.6).contains(&a), "disk {id} of radius {a}");
        assert!(
            (m - (a / 0.5).powi(2)).abs() < 1e-15,
            "disk {id}: mass {m} for radius {a}"
        );
        lo = lo.min(a);
        hi = hi.max(a);
    }
    assert!(lo < 0.33 && hi > 0.57, "500 radii spread over [{lo}, {hi}]");
}

/// A polydisperse pour twice: the same radii for the same ids and the same states, bit for bit.
#[test]
fn a_polydisperse_pour_is_deterministic() {
    let run = || {
        let mut sim = ballistic(&polydisperse_pour(12.0));
        sim.advance_to(12.0).unwrap();
        let s = sim.snapshot(12.0);
        let radii: Vec<u64> = sim
            .pool()
            .unwrap()
            .view()
            .radius
            .iter()
            .map(f64::to_bits)
            .collect();
        (s.ids, radii, s.x, s.vy)
    };
    let one = run();
    assert!(one.0.len() > 200, "{} in", one.0.len());
    assert_eq!(one, run());
}

/// An inlet of two species with their own masses: each entering disk is one of them with its
/// mass and species number, both species come, and the seed decides which (another seed, other
/// draws).
#[test]
fn an_inlet_of_species_brings_each_with_its_mass() {
    let species = |seed: u64| {
        let json = shipped("pour.json", |v| {
            v["seed"] = seed.into();
            v["run"]["duration"] = 10.0.into();
            v["run"]["warmup"] = 0.0.into();
            v["inlets"][0]["radius"] = serde_json::json!({ "species": [
                { "count": 3, "radius": 0.4, "mass": 2.0 },
                { "count": 1, "radius": 0.7 } ] });
            v["inlets"][0]["density"] = 1.0.into();
        });
        let mut sim = ballistic(&json);
        sim.advance_to(10.0).unwrap();
        let pool = sim.pool().unwrap();
        let view = pool.view();
        let mut kinds = Vec::new();
        for (row, &id) in pool.ids().iter().enumerate().filter(|(_, &id)| id >= 20) {
            let (a, m, sp) = (view.radius[row], view.mass[row], view.species[row]);
            let expected = if sp == 0 {
                (0.4, 2.0)
            } else {
                (0.7, std::f64::consts::PI * 0.49)
            };
            assert_eq!((a, m), expected, "disk {id} of species {sp}");
            kinds.push(sp);
        }
        kinds
    };
    let (one, other) = (species(5), species(6));
    let small = one.iter().filter(|&&k| k == 0).count();
    assert!(one.len() > 150, "{} in", one.len());
    // Odds 3 : 1 (binomial spread over ~190 draws is about 6).
    let share = small as f64 / one.len() as f64;
    assert!((share - 0.75).abs() < 0.1, "small share {share}");
    assert_ne!(one, other, "another seed draws other species");
}

/// Rough disks through an inlet: they enter spinning with the particles' rotational
/// temperature (a normal ω of variance T_rot / I), or not at all without one; the energy budget
/// closes with their spins' energy brought in.
#[test]
fn rough_disks_enter_spinning_at_the_rotational_temperature() {
    let first_spins = |t_rot: Option<f64>| {
        let json = shipped("pour.json", |v| {
            v["run"]["duration"] = 20.0.into();
            v["run"]["warmup"] = 0.0.into();
            v["collisions"]["friction"] = 0.5.into();
            if let Some(t) = t_rot {
                v["particles"]["rotational_temperature"] = t.into();
            }
        });
        let mut sim = ballistic(&json);
        let e0 = energy(&sim, 0.0);
        // Entries at 0, 0.05, 0.1, …: the first ten fall from 25 untouched till 0.5.
        sim.advance_to(0.48).unwrap();
        let spins = sim.spins_at(0.48).unwrap();
        let ids = sim.snapshot(0.48).ids;
        let new: Vec<f64> = ids
            .iter()
            .zip(&spins)
            .filter(|(&id, _)| id >= 20)
            .map(|(_, s)| s.1)
            .collect();
        assert_eq!(new.len(), 10);
        for k in 1..=20 {
            let t = k as f64;
            sim.advance_to(t).unwrap();
            let error = budget_error(&sim, t, e0);
            assert!(error < 1e-12, "energy budget off by {error:e} at {t}");
        }
        new
    };
    assert!(
        first_spins(None).iter().all(|&w| w == 0.0),
        "no rotational temperature, no spin"
    );
    // I = ½ m a² = 1/8: ω has a standard deviation of √(0.2 · 8) ≈ 1.26.
    let spins = first_spins(Some(0.2));
    let mean_square = spins.iter().map(|w| w * w).sum::<f64>() / spins.len() as f64;
    assert!(spins.iter().all(|&w| w != 0.0));
    assert!(
        (0.3..5.0).contains(&mean_square),
        "⟨ω²⟩ = {mean_square}, expected 1.6"
    );
}

/// Rough disks leaving at the top: the spins of those that stay are read by id (ids beyond the
/// live count included) and the budget closes with the rotational energy carried out.
#[test]
fn rough_disks_leave_at_the_top_with_their_spins_energy() {
    let mut v: serde_json::Value = serde_json::from_str(FOUNTAIN).unwrap();
    v["collisions"]["friction"] = 0.3.into();
    v["particles"]["rotational_temperature"] = 0.5.into();
    let mut sim = ballistic(&v.to_string());
    let e0 = energy(&sim, 0.0);
    for k in 1..=40 {
        let t = k as f64;
        sim.advance_to(t).unwrap();
        let live = sim.snapshot(t).ids.len();
        assert_eq!(sim.spins_at(t).unwrap().len(), live);
        let error = budget_error(&sim, t, e0);
        assert!(error < 1e-12, "energy budget off by {error:e} at {t}");
    }
    let f = sim.pool().unwrap().flow;
    assert!(f.top > 5, "{} out", f.top);
}

/// A spinning rough disk dropped on a corner of the orifice (the floor and so the corners
/// smooth): it bounces at the analytic time, straight back up, its spin as it was, no energy
/// lost.
#[test]
fn a_spinning_rough_disk_bounces_off_a_smooth_corner_keeping_its_spin() {
    let json = r#"{
        "name": "rough drop on a corner",
        "domain": { "width": 10.0, "x_boundary": "walls", "y_boundary": "open" },
        "gravity": 2.0,
        "floor": { "orifice": { "from": 4.0, "to": 6.0 } },
        "particles": { "count": 1, "radius": 0.5, "temperature": 0.0,
                       "rotational_temperature": 0.5,
                       "placement": { "positions": [[4.0, 3.0]], "velocities": [[0.0, 0.0]] } },
        "collisions": { "friction": 0.5 },
        "run": { "duration": 10.0 }
    }"#;
    let mut sim = ballistic(json);
    let w0 = sim.spins_at(0.0).unwrap()[0].1;
    assert!(w0 != 0.0, "the disk spins");
    let e0 = energy(&sim, 0.0);
    let t_hit = (2.0f64 * (3.0 - 0.5) / 2.0).sqrt();
    let t = t_hit * 1.5;
    sim.advance_to(t).unwrap();
    assert_eq!(sim.pool().unwrap().flow.corner, 1);
    let s = sim.snapshot(t);
    assert!(
        (s.vy[0] - (2.0 * t_hit - 2.0 * (t - t_hit))).abs() < 1e-12,
        "vy = {}",
        s.vy[0]
    );
    assert_eq!(s.vx[0], 0.0);
    assert_eq!(sim.spins_at(t).unwrap()[0].1, w0, "the spin is kept");
    let error = budget_error(&sim, t, e0);
    assert!(error < 1e-14, "energy off by {error:e}");
}

/// A silo of rough disks drains through the orifice, recycled: the ids stay the 400 of the
/// start, out = in, the discharge goes on, and the energy budget closes at every stop with the
/// rotational energy carried out and brought back in.
#[test]
fn rough_disks_drain_through_the_orifice_and_the_budget_closes() {
    let json = shipped("silo.json", |v| {
        v["run"]["duration"] = 15.0.into();
        v["run"]["warmup"] = 2.0.into();
        v["collisions"]["friction"] = 0.5.into();
        v["particles"]["rotational_temperature"] = 0.05.into();
    });
    let mut sim = ballistic(&json);
    let e0 = energy(&sim, 0.0);
    for k in 1..=15 {
        let t = k as f64;
        assert_eq!(sim.advance_to(t).unwrap(), Progress::Reached);
        assert_eq!(
            sim.snapshot(t).ids,
            (0..400).collect::<Vec<u32>>(),
            "at t = {t}"
        );
        let error = budget_error(&sim, t, e0);
        assert!(error < 1e-11, "energy budget off by {error:e} at {t}");
    }
    let f = sim.pool().unwrap().flow;
    assert!(f.left > 20, "{} out", f.left);
    assert_eq!(f.left, f.entered);
}
