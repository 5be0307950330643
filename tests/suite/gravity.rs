//! Gravity, the floor and the open top: analytic single-disk motion, floor impacts against an
//! independent root search, the open-top hashing against the dense grid, the energy budget.

use crate::common;

use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::TAU;
use vibrobed::neighbours::grid::{WINDOW_CELLS_FLOOR, WINDOW_CELLS_PER_DISK};
use vibrobed::neighbours::{CellMap, DenseCells, GridGeometry, Mask, NeighbourLists, SparseCells};
use vibrobed::physics::drive::Drive;
use vibrobed::physics::floor::{Floor, FloorEvent};
use vibrobed::run::{run, RunOptions};

fn single_disk(y0: f64, vx: f64, vy: f64, floor: &str) -> String {
    format!(
        r#"{{"name": "one", "domain": {{"width": 1000, "x_boundary": "walls"}},
        "gravity": 2.0, "floor": {floor},
        "particles": {{"count": 1, "radius": 0.5,
            "placement": {{"positions": [[500, {y0}]], "velocities": [[{vx}, {vy}]]}}}},
        "run": {{"duration": 1}}}}"#
    )
}

#[test]
fn a_disk_in_flight_follows_the_parabola() {
    let mut sim = common::ballistic(&single_disk(1000.0, 0.75, 3.0, r#"{"restitution": 1}"#));
    for k in 1..=40 {
        let t = k as f64 * 0.5;
        sim.advance_to(t).unwrap();
        let s = sim.snapshot(t);
        let (x, y) = (500.0 + 0.75 * t, 1000.0 + 3.0 * t - t * t);
        assert!((s.x[0] - x).abs() < 1e-12, "x at {t}");
        assert!(
            (s.y[0] - y).abs() < 1e-10 * 1000.0,
            "y at {t}: {} vs {y}",
            s.y[0]
        );
        assert!((s.vy[0] - (3.0 - 2.0 * t)).abs() < 1e-12);
    }
    assert_eq!(sim.counts().floor, 0);
}

#[test]
fn elastic_bounces_on_a_static_floor_return_to_the_same_height() {
    // Dropped from rest at y = 10.5: falls 10 under g = 2, period 2·√10, apex back at 10.5.
    let period = 2.0 * 10f64.sqrt();
    let mut sim = common::ballistic(&single_disk(10.5, 0.0, 0.0, r#"{"restitution": 1}"#));
    let bounces = 1_000_000u64;
    let mut worst: f64 = 0.0;
    for k in 1..=100u64 {
        let t = (k * bounces / 100) as f64 * period;
        sim.advance_to(t).unwrap();
        let s = sim.snapshot(t);
        // At each multiple of the period the disk is back at its apex, at rest.
        worst = worst.max((s.y[0] - 10.5).abs());
        let energy = 0.5 * s.vy[0] * s.vy[0] + 2.0 * s.y[0];
        assert!(
            (energy - 21.0).abs() < 1e-9 * 21.0,
            "energy {energy} after {t}"
        );
    }
    assert_eq!(sim.counts().floor, bounces);
    assert!(worst < 1e-6, "apex drifted by {worst}");
    eprintln!("apex drift after 10^6 bounces: {worst:e}");
}

/// Independent reference: scan `f(t) = y(t) − a − h(t)` on a fine grid for the first sign
/// change, then bisect.
fn reference_impact(fl: &Floor, y: f64, vy: f64, a: f64, g: f64, horizon: f64) -> Option<f64> {
    let f = |t: f64| y + vy * t - 0.5 * g * t * t - a - fl.height(t);
    let step = (TAU / fl.drive().omega).min(1.0) * 2e-4;
    let n = (horizon / step).ceil() as usize;
    if f(0.0) <= 0.0 {
        return Some(0.0);
    }
    let mut prev = 0.0;
    for k in 1..=n {
        let t = k as f64 * step;
        if f(t) <= 0.0 {
            let (mut lo, mut hi) = (prev, t);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if f(mid) > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return Some(hi);
        }
        prev = t;
    }
    None
}

#[test]
fn sine_floor_impacts_agree_with_an_independent_root_search() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(2024);
    let g = 1.0;
    let (mut impacts, mut cases) = (0, 0);
    for case in 0..2000 {
        let amp = 10f64.powf(rng.random_range(-3.0..0.0));
        let freq = 10f64.powf(rng.random_range(-1.0..1.0));
        let phase = rng.random_range(0.0..TAU);
        let fl = Floor::new(0.9, Drive::new(amp, freq), phase);
        let a = 0.5;
        let h0 = fl.height(0.0);
        let hd0 = fl.velocity(0.0);
        // Random, then adversarial: grazing apex, floor rising into a slow disk, disk at rest.
        let (y, vy) = match case % 4 {
            0 => (
                h0 + a + rng.random_range(0.0..2.0),
                rng.random_range(-2.0..2.0),
            ),
            1 => {
                // Rising towards an apex exactly at the floor's top.
                let vy = rng.random_range(0.0..1.0) * (2.0 * g * (amp - h0)).sqrt();
                (amp + a - vy * vy / (2.0 * g) + 1e-12, vy)
            }
            2 => (h0 + a + 1e-9, hd0 - 1e-6),
            _ => (h0 + a, hd0),
        };
        let horizon = 2.0 / freq + 1.0;
        let engine = fl.next_event(y, vy, a, g, 0.0, horizon);
        if case % 4 == 3 {
            // Resting on the floor: an impact now if the floor presses the disk (h'' > −g),
            // else the disk is thrown off and f stays positive until its next impact.
            let f = |t: f64| y + vy * t - 0.5 * g * t * t - a - fl.height(t);
            if fl.acceleration(0.0) > -g {
                assert_eq!(engine, Some(FloorEvent::Impact(0.0)), "case {case}");
            } else if let Some(ev) = engine {
                let te = ev.time();
                assert!(te > 0.0, "case {case}");
                for k in 1..1000 {
                    assert!(
                        f(te * k as f64 / 1000.0) > -1e-12,
                        "case {case}: crossed before {te}"
                    );
                }
            }
            cases += 1;
            continue;
        }
        let reference = reference_impact(&fl, y, vy, a, g, horizon);
        cases += 1;
        match (engine, reference) {
            (Some(FloorEvent::Impact(te)), Some(tr)) => {
                impacts += 1;
                assert!(te >= 0.0, "case {case}: impact in the past");
                let f = |t: f64| y + vy * t - 0.5 * g * t * t - a - fl.height(t);
                assert!(
                    (te - tr).abs() < 1e-7 * (1.0 + tr) || f(te).abs() < 1e-11,
                    "case {case}: engine {te}, reference {tr}, f(te) = {:e}",
                    f(te)
                );
                assert!(
                    te <= tr + 1e-7 * (1.0 + tr),
                    "case {case}: engine passed the first root"
                );
            }
            (None, None) => {}
            (Some(FloorEvent::Recheck(t)), _) => assert!(t >= 0.0),
            (Some(FloorEvent::Impact(te)), None) => {
                // A graze the reference grid stepped over: the engine's root must be genuine.
                let f = |t: f64| y + vy * t - 0.5 * g * t * t - a - fl.height(t);
                assert!(f(te).abs() < 1e-10, "case {case}: spurious impact at {te}");
            }
            (None, Some(tr)) => panic!("case {case}: impact at {tr} missed (y {y}, vy {vy})"),
        }
    }
    assert!(impacts > cases / 2, "{impacts} impacts in {cases} cases");
}

fn lists_sorted(lists: &NeighbourLists, n: usize) -> Vec<Vec<u32>> {
    (0..n)
        .map(|i| {
            let mut l = lists.of(i).to_vec();
            l.sort_unstable();
            l
        })
        .collect()
}

#[test]
fn open_top_hashing_finds_what_the_dense_grid_finds() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(99);
    for trial in 0..20 {
        let a = 0.5;
        let width = 30.0;
        let top = 200.0;
        // Non-overlapping disks: jittered points of a coarse lattice, sparse above a dense bed.
        let mut cells_xy = Vec::new();
        for row in 0..(top / 1.2) as usize {
            for col in 0..(width / 1.2) as usize - 1 {
                let keep = if row < 20 { 0.9 } else { 0.05 };
                if rng.random::<f64>() < keep {
                    let x = 0.6 + col as f64 * 1.2 + rng.random_range(-0.09..0.09);
                    let y = 0.6 + row as f64 * 1.2 + rng.random_range(-0.09..0.09);
                    cells_xy.push((x, y));
                }
            }
        }
        let periodic = trial % 2 == 0;
        let dense_geo = GridGeometry::new(a, width, periodic, 0.0, Some(top), false);
        let open_geo = GridGeometry::new(a, width, periodic, 0.0, None, false);
        let mask = Mask::table(trial % 4);
        let cells: Vec<(u32, u32)> = cells_xy
            .iter()
            .map(|&(x, y)| dense_geo.cell_of(x, y))
            .collect();
        let open_cells: Vec<(u32, u32)> = cells_xy
            .iter()
            .map(|&(x, y)| open_geo.cell_of(x, y))
            .collect();
        assert_eq!(cells, open_cells);
        let mut dense = DenseCells::with_pad(mask.half_width as u32);
        dense.map(&dense_geo, cells.len(), |i| cells[i]).unwrap();
        let mut sparse = SparseCells::default();
        sparse.map(&open_geo, cells.len(), |i| cells[i]).unwrap();
        let (mut ld, mut ls) = (NeighbourLists::default(), NeighbourLists::default());
        ld.build(
            cells.len(),
            |i, out| dense.gather_half(&dense_geo, &mask, cells[i], |j| out.push(j)),
            |_, _| true,
        );
        ls.build(
            cells.len(),
            |i, out| sparse.gather_half(&open_geo, &mask, cells[i], |j| out.push(j)),
            |_, _| true,
        );
        let n = cells.len();
        assert_eq!(lists_sorted(&ld, n), lists_sorted(&ls, n), "trial {trial}");
        assert!(
            ld.entries() > n,
            "trial {trial}: the lists are not trivially empty"
        );
    }
}

#[test]
fn memory_does_not_grow_with_the_height_of_a_disk() {
    let bytes_with_top_disk_at = |height: f64| {
        let json = format!(
            r#"{{"name": "tall", "domain": {{"width": 20, "x_boundary": "periodic"}},
            "gravity": 1.0, "floor": {{"restitution": 0.9}},
            "particles": {{"count": 3, "radius": 0.5,
                "placement": {{"positions": [[2, 0.5], [5, 0.5], [10, {height}]]}}}},
            "run": {{"duration": 1}}}}"#
        );
        let mut sim = common::ballistic(&json);
        sim.advance_to(0.5).unwrap();
        assert!(sim.snapshot(0.5).y[2] > 0.9 * height);
        sim.bytes()
    };
    // Low, the disks fit a dense window over their rows (bounded: at most
    // WINDOW_CELLS_PER_DISK cells per disk plus WINDOW_CELLS_FLOOR); higher up, Isobe's arrays,
    // whose size does not depend on the height.
    let low = bytes_with_top_disk_at(10.0);
    let high = bytes_with_top_disk_at(1e4);
    let far = bytes_with_top_disk_at(1e7);
    assert_eq!(
        high, far,
        "a disk 10^7 diameters up must not allocate grid up to it"
    );
    let cap = 4 * (WINDOW_CELLS_PER_DISK as usize * 3 + WINDOW_CELLS_FLOOR as usize);
    assert!(low <= far + cap, "{low} bytes low, {far} far up");
}

#[test]
fn energy_budget_closes_on_a_vibrated_bed() {
    let text = std::fs::read_to_string(common::crate_path("scenarios/vibrated_bed.json")).unwrap();
    let sets = [
        "run.duration=30".to_string(),
        "run.warmup=5".to_string(),
        "engine.check_invariants=true".to_string(),
    ];
    let scenario = vibrobed::Scenario::from_json_with_overrides(&text, &sets).unwrap();
    let s = run(&scenario, RunOptions::default()).unwrap();
    assert!(s.events.floor > 1000 && s.events.pair > 10_000);
    assert!(s.energy.injected > 0.0 && s.energy.dissipated > 0.0);
    assert!(
        s.energy.balance_error < 1e-9,
        "energy budget off by {:e}",
        s.energy.balance_error
    );
}

/// The floor's momentum balance: the vertical momentum the floor gave the disks between t1 and
/// t2 (impacts, and the force m (g + h'') carrying disks at rest) equals the change of the disks'
/// vertical momentum plus their weight times t2 − t1. Booked independently at each event.
fn floor_momentum_balance(file: &str, sets: &[&str], t1: f64, t2: f64) {
    let text = std::fs::read_to_string(common::crate_path(file)).unwrap();
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let json =
        serde_json::to_string(&vibrobed::Scenario::from_json_with_overrides(&text, &sets).unwrap())
            .unwrap();
    let mut sim = common::ballistic(&json);
    let g = 1.0;
    let mass: f64 = sim.disks().mass.iter().sum();
    let state = |sim: &vibrobed::engine::Simulation<vibrobed::physics::flight::Ballistic>,
                 t: f64| {
        let snap = sim.snapshot(t);
        let p: f64 = (0..snap.vy.len())
            .map(|i| sim.disks().mass[i] * snap.vy[i])
            .sum();
        (p, sim.energy_flow_at(t).floor_impulse)
    };
    sim.advance_to(t1).unwrap();
    let (p1, f1) = state(&sim, t1);
    sim.advance_to(t2).unwrap();
    let (p2, f2) = state(&sim, t2);
    let weight = mass * g * (t2 - t1);
    let error = ((f2 - f1) - (p2 - p1 + weight)).abs() / weight;
    assert!(
        error < 1e-9,
        "{file}: floor gave {}, momentum change + weight {} (relative error {error:e}); \
         {} disks at rest",
        f2 - f1,
        p2 - p1 + weight,
        sim.riders()
    );
}

#[test]
fn the_floor_gives_exactly_the_momentum_the_disks_take() {
    // A fluidized bed (impacts), a bed at rest on a static floor (disks riding it and resting
    // on each other), and a stack on a sine floor at Γ = 1.2 (take-offs and landings).
    floor_momentum_balance("scenarios/vibrated_bed.json", &[], 5.0, 25.0);
    floor_momentum_balance("scenarios/hard/bed_at_rest_tc.json", &[], 10.0, 20.0);
    floor_momentum_balance("scenarios/hard/stack_gamma_1.2.json", &[], 5.0, 15.0);
}

#[test]
fn the_pressure_on_the_floor_is_the_weight_of_the_bed() {
    let text = std::fs::read_to_string(common::crate_path("scenarios/vibrated_bed.json")).unwrap();
    let sets = ["run.duration=100".to_string(), "run.warmup=20".to_string()];
    let scenario = vibrobed::Scenario::from_json_with_overrides(&text, &sets).unwrap();
    let s = run(&scenario, RunOptions::default()).unwrap();
    let p = s
        .floor_pressure
        .expect("a floor scene reports its pressure");
    assert_eq!(p.weight, 1000.0 * 1.0 / scenario.domain.width);
    assert!(
        (p.measured / p.weight - 1.0).abs() < 0.01,
        "pressure {} against a weight of {} per unit width",
        p.measured,
        p.weight
    );
}

#[test]
fn an_inelastic_disk_comes_to_rest_on_a_static_floor() {
    let json = single_disk(5.5, 0.0, 0.0, r#"{"restitution": 0.5}"#);
    let mut sim = common::ballistic(&json);
    sim.advance_to(100.0).unwrap();
    let s = sim.snapshot(100.0);
    assert_eq!(sim.counts().rest, 1, "it rests once");
    assert!(
        sim.counts().floor < 100,
        "finitely many bounces: {}",
        sim.counts().floor
    );
    assert!((s.y[0] - 0.5).abs() < 1e-12 && s.vy[0] == 0.0);
}

#[test]
fn a_resting_disk_takes_off_where_the_floor_accelerates_down_faster_than_g() {
    // Γ = 2: take-off at sin(ωt + φ0) = 1/2.
    let (g, f, gamma) = (1.0, 1.0, 2.0);
    let w = TAU * f;
    let amp = gamma * g / (w * w);
    let json = format!(
        r#"{{"name": "ride", "domain": {{"width": 10}}, "gravity": {g},
        "floor": {{"amplitude": {amp}, "frequency": {f}, "phase": 3.3, "restitution": 0.0}},
        "particles": {{"count": 1, "radius": 0.5,
            "placement": {{"positions": [[5, {y}]], "velocities": [[0, 0]]}}}},
        "run": {{"duration": 1}}}}"#,
        y = 0.5 + amp * 3.3f64.sin() + 1e-3
    );
    let mut sim = common::ballistic(&json);
    sim.set_logging(true);
    let mut t = 0.0;
    while sim.counts().takeoff == 0 && t < 5.0 {
        t += 0.001;
        sim.advance_to(t).unwrap();
    }
    assert_eq!(sim.counts().takeoff, 1, "takes off within five periods");
    assert!(sim.counts().rest >= 1);
    // The take-off happened in the last step: find its phase.
    let fl = sim.floor().unwrap();
    let s = sim.snapshot(t);
    let phase_now = (3.3 + w * t).rem_euclid(TAU);
    assert!(
        phase_now.sin() > 0.49 && phase_now < std::f64::consts::PI,
        "phase {phase_now}"
    );
    assert!(s.y[0] > fl.height(t - sim.time()) + 0.5 - 1e-9);
}
