//! The hybrid scheme (`engine.scheme = hybrid`): a gas stays with the exact engine, event for
//! event; a dense bed goes to contact dynamics and, once it comes apart, back; momentum is
//! conserved across every hand-over; a run repeats bit for bit.

use crate::common::{momentum_y, same_run};
use serde_json::Value;
use vibrobed::engine::{Progress, Scene};
use vibrobed::physics::flight::Ballistic;
use vibrobed::schemes::handover::Handover;
use vibrobed::schemes::Integrator;
use vibrobed::Scenario;

/// A small vibrated bed: 150 inelastic disks, about five layers.
const BED: &str = r#"{
  "name": "small vibrated bed",
  "seed": 3,
  "domain": { "width": 30.0, "x_boundary": "periodic", "y_boundary": "open" },
  "gravity": 1.0,
  "floor": { "gamma": 3.0, "frequency": 0.5, "restitution": 0.9 },
  "particles": { "count": 150, "radius": 0.5, "temperature": 0.5 },
  "collisions": { "restitution": 0.9 },
  "engine": { "scheme": "hybrid" },
  "run": { "duration": 40.0, "warmup": 10.0 }
}"#;

fn scenario(sets: &[&str]) -> Scenario {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Scenario::from_json_with_overrides(BED, &sets).expect("valid scenario")
}

fn engine(s: &Scenario) -> Handover<Ballistic> {
    let (scene, disks) = Scene::build(s).expect("scene");
    Handover::new(Ballistic { g: 1.0 }, &scene, disks, &s.engine).expect("engine")
}

/// A fluidized bed (Γ = 3) never turns dense: the hybrid scheme is the exact engine with TC at
/// 10⁻⁴, its summary the same bit for bit but for the scheme's name.
#[test]
fn a_gas_stays_with_the_exact_engine_event_for_event() {
    let hybrid = scenario(&[]);
    let exact = scenario(&["engine.scheme=event-driven", "collisions.tc=0.0001"]);
    let (mut a, _) = same_run::summary(&hybrid, &[]);
    let (mut b, _) = same_run::summary(&exact, &[]);
    assert!(a.get("approximation").is_none(), "{}", a["approximation"]);
    for v in [&mut a, &mut b] {
        v["engine"]["scheme"] = Value::Null;
    }
    assert!(a["events"]["pair"].as_u64().unwrap() > 10_000);
    assert_eq!(a, b);
}

/// A bed that rides the floor (Γ = 0.5) turns dense: the run goes to contact dynamics and stays
/// there. Pair impulses are internal and the state is handed over whole, so the floor's impulse
/// is the change of momentum plus the weight's, `F = ΔP_y + N m g t`, to round-off across the
/// hand-over.
#[test]
fn a_riding_bed_goes_to_contact_dynamics_and_keeps_its_momentum() {
    let s = scenario(&["floor.gamma=0.5", "particles.temperature=0.01"]);
    let mut sim = engine(&s);
    let p0 = momentum_y(&sim);
    assert_eq!(sim.advance_to(40.0).unwrap(), Progress::Reached);
    let stats = sim.approximation().expect("contact dynamics ran");
    assert!(stats.handovers >= 1 && stats.dense_time > 20.0, "{stats:?}");
    let t = sim.time();
    let weight = 150.0 * t;
    let floor = sim.energy_flow_at(t).floor_impulse;
    let off = floor - (momentum_y(&sim) - p0 + weight);
    assert!(off.abs() < 1e-9 * weight, "floor {floor}, off by {off}");
}

/// A bed riding the floor below Γ = 1 falls asleep in contact dynamics: it is at rest from a
/// time on, every disk moving with the floor (between periodic sides on a smooth floor, with
/// the bed's mean horizontal velocity, here round-off), and the floor's impulse is still the
/// change of momentum plus the weight's.
#[test]
fn a_riding_bed_falls_asleep_and_rides_the_floor_as_one_body() {
    use vibrobed::run::{run, RunOptions};
    let s = scenario(&["floor.gamma=0.5", "particles.temperature=0.01"]);
    let sum = run(&s, RunOptions::default()).expect("run");
    let since = sum.at_rest_since.expect("the riding bed comes to rest");
    assert!(since < 0.75 * s.run.duration, "at rest only from {since}");
    let mut sim = engine(&s);
    let p0 = momentum_y(&sim);
    assert_eq!(sim.advance_to(40.0).unwrap(), Progress::Reached);
    assert_eq!(sim.disks_at_rest(), 150);
    let mut speeds = Vec::new();
    let floor_v = {
        let t = sim.time();
        let h = |t: f64| sim.floor_height_at(t).expect("a floor");
        (h(t + 1e-6) - h(t - 1e-6)) / 2e-6
    };
    sim.visit_states(sim.time(), |_, [_, _, vx, vy]| {
        speeds.push((vx, vy - floor_v))
    });
    for (vx, dv) in speeds {
        assert!(vx.abs() < 1e-12 && dv.abs() < 1e-6, "({vx}, {dv})");
    }
    let t = sim.time();
    let off = sim.energy_flow_at(t).floor_impulse - (momentum_y(&sim) - p0 + 150.0 * t);
    assert!(off.abs() < 1e-9 * 150.0 * t, "off by {off}");
}

/// With the hand-over to contact dynamics made cheap (one event per disk in 25 steps), a
/// fluidized bed (Γ = 3) goes to contact dynamics, is seen there as a gas, and comes back to
/// the exact engine, which accepts the state handed back (no overlap): back and forth.
#[test]
fn a_gas_handed_to_contact_dynamics_comes_back_to_the_exact_engine() {
    let s = scenario(&[]);
    let mut sim = engine(&s).with_thresholds(0.04, vibrobed::schemes::handover::CONTACTS_OUT);
    assert_eq!(sim.advance_to(40.0).unwrap(), Progress::Reached);
    let stats = sim.approximation().expect("contact dynamics ran");
    // A second hand-over is a hand-back accepted by the exact engine.
    assert!(stats.handovers >= 2, "{stats:?}");
    assert!(stats.dense_time < 40.0 - 2.0, "{stats:?}");
}

/// A run asked for many targets that are no round numbers reaches each of them after the run
/// has come back to the exact engine (the Brazil-nut bed: a window of contact dynamics, then
/// exact): a target that the part's clock, whose zero is the hand-back's time `t0`, cannot
/// write to the last bit (`t0 + (target - t0) < target`) ends the call too. It looped forever
/// on such a target; the watchdog turns a hang into a failure.
#[test]
fn every_target_is_reached_whatever_the_hand_overs_clock() {
    let (done, seen) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let path = format!("{}/scenarios/brazil_nut.json", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(path).expect("the Brazil-nut bed");
        let s = Scenario::from_json(&text).expect("valid scenario");
        let mut sim = engine(&s);
        let mut short = 0.0f64;
        for k in 1..=2500 {
            let target = k as f64 * std::f64::consts::PI / 400.0;
            assert_eq!(
                sim.advance_to(target).unwrap(),
                Progress::Reached,
                "{target}"
            );
            short = short.max((target - sim.time()).abs());
        }
        let _ = done.send((short, sim.approximation().map_or(0, |a| a.handovers)));
    });
    let (short, handovers) = seen
        .recv_timeout(std::time::Duration::from_secs(300))
        .expect("a target was never reached (or the run failed)");
    assert_eq!(handovers, 2, "exact, contact dynamics, exact");
    // Contact dynamics stops at its last whole step before a target (at most 0.04 here).
    assert!(short < 0.04, "{short}");
}

/// The clock the progress report reads is the run's, not the present part's: once the
/// Brazil-nut bed is back on the exact engine, what that engine publishes as it runs counts
/// time from the run's start (not from the hand-back) and the collisions of every part.
#[test]
fn the_published_clock_is_the_runs_across_hand_overs() {
    use vibrobed::engine::published_clock::PublishedClock;
    let path = format!("{}/scenarios/brazil_nut.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).expect("the Brazil-nut bed");
    let s = Scenario::from_json(&text).expect("valid scenario");
    let mut sim = engine(&s);
    let clock = std::sync::Arc::new(PublishedClock::new(0.0, 0));
    let _installed = PublishedClock::install(std::sync::Arc::clone(&clock));
    assert_eq!(sim.advance_to(12.0).unwrap(), Progress::Reached);
    assert_eq!(sim.approximation().map(|a| a.handovers), Some(2));
    let seen = clock.read();
    let collisions = sim.counts().collisions();
    assert!((11.5..=12.0).contains(&seen.time), "{}", seen.time);
    assert!(seen.collisions <= collisions && seen.collisions * 100 > 99 * collisions);
}

/// The same scene twice: the same run, hand-overs included.
#[test]
fn a_hybrid_run_repeats_bit_for_bit() {
    let s = scenario(&["floor.gamma=0.8"]);
    let (a, _) = same_run::summary(&s, &[]);
    let (b, _) = same_run::summary(&s, &[]);
    assert!(a.get("approximation").is_some());
    assert_eq!(a, b);
}

/// `run.max_events` bounds the whole run, whichever engine holds it: a hybrid run asked for a
/// tenth or half of the events of its whole stops with the event limit before its end.
#[test]
fn the_event_limit_holds_across_hand_overs() {
    let s = scenario(&["floor.gamma=0.5"]);
    let mut whole = engine(&s);
    assert_eq!(whole.advance_to(40.0).unwrap(), Progress::Reached);
    let total = whole.counts().guarded();
    for limit in [total / 10, total / 2] {
        let s = scenario(&["floor.gamma=0.5", &format!("run.max_events={limit}")]);
        let mut sim = engine(&s);
        assert_eq!(
            sim.advance_to(40.0).unwrap(),
            Progress::EventLimit,
            "{limit}"
        );
        assert!(sim.time() < 40.0 && sim.counts().guarded() >= limit);
    }
}

/// The exact engine's hard cases on a vibrating floor with inelastic disks (they set
/// `engine.scheme = "event-driven"`; `auto` would run them on the hybrid scheme) run on the
/// hybrid scheme too: each to its end, its energy budget closed across the hand-overs, every
/// disk kept; those that turn dense go to contact dynamics.
#[test]
fn the_vibrated_hard_cases_run_to_their_end_on_the_hybrid_scheme() {
    let mut dense = 0;
    for case in VIBRATED_HARD_CASES {
        let path = format!("{}/scenarios/hard/{case}.json", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).expect("hard case");
        let sets = ["engine.scheme=hybrid".to_string()];
        let s = Scenario::from_json_with_overrides(&text, &sets).expect("valid scenario");
        let (v, _) = same_run::summary(&s, &[]);
        assert_eq!(v["ending"], "completed", "{case}");
        assert_eq!(v["sim_time"].as_f64(), Some(s.run.duration), "{case}");
        assert_eq!(
            v["particles"].as_u64(),
            Some(s.disk_count() as u64),
            "{case}"
        );
        let balance = v["energy"]["balance_error"]
            .as_f64()
            .expect("energy balance");
        assert!(balance < 1e-9, "{case}: energy balance off by {balance:e}");
        dense += usize::from(v["approximation"]["handovers"].as_u64() >= Some(1));
    }
    assert!(
        dense >= 5,
        "only {dense} hard cases went to contact dynamics"
    );
}

/// The hard cases the test above runs.
const VIBRATED_HARD_CASES: [&str; 16] = [
    "bed_1000_gamma_0.8_tc",
    "bed_gamma_0.001",
    "bed_gamma_50",
    "bed_riding_gamma_0.5",
    "bed_sawtooth",
    "bed_triangle",
    "bouncing_bed_gamma_1.5",
    "cell_borders",
    "dense_bed",
    "far_above_bed",
    "restitution_0",
    "stack_gamma_0.5",
    "stack_gamma_1.2",
    "two_disks",
    "vibrated_inelastic_speed_cutoff",
    "vibrated_inelastic_tc",
];

/// No scene hangs: the shipped bed, with no setting but Γ (and friction, for the rough bed),
/// runs to its end on `auto` at every point of the sweep, on the hybrid scheme, and reads solid
/// below Γ = 1. The event limit is far above what a completed run needs: reaching it would be
/// the exact engine's collapse back.
#[test]
fn the_shipped_bed_runs_to_its_end_at_every_gamma() {
    let path = format!("{}/scenarios/vibrated_bed.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).expect("the shipped bed");
    let smooth = [0.5, 0.8, 1.0, 1.2, 1.5, 2.0, 3.0, 5.0].map(|g| (g, false));
    let rough = [0.5, 0.8, 1.2, 1.5].map(|g| (g, true));
    for (gamma, is_rough) in smooth.into_iter().chain(rough) {
        let mut sets = vec![
            format!("floor.gamma={gamma}"),
            "run.duration=60".into(),
            "run.warmup=20".into(),
            "run.max_events=50000000".into(),
        ];
        if is_rough {
            sets.extend([
                "collisions.friction=0.5".into(),
                "floor.friction=0.5".into(),
            ]);
        }
        let s = Scenario::from_json_with_overrides(&text, &sets).expect("valid scenario");
        assert_eq!(s.scheme(), vibrobed::scenario::Scheme::Hybrid);
        let (v, _) = same_run::summary(&s, &[]);
        let point = format!("Γ = {gamma}, rough: {is_rough}");
        assert_eq!(v["ending"], "completed", "{point}");
        if gamma < 1.0 {
            assert_eq!(v["state"]["name"], "solid", "{point}: {}", v["state"]);
        }
    }
}

/// A dense gas goes back to the exact engine: the Brazil-nut bed (25 layers at Γ = 3) turns
/// dense as it settles and goes to contact dynamics, where more than
/// [`IMPACTS_OUT`](vibrobed::schemes::handover::IMPACTS_OUT) of the pushing contacts are impacts;
/// it comes back within a few windows (the floor's period) and stays exact.
#[test]
fn a_dense_gas_goes_back_to_the_exact_engine_and_stays() {
    let path = format!("{}/scenarios/brazil_nut.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).expect("the Brazil-nut bed");
    let sets = ["run.duration=20".to_string(), "run.warmup=2".into()];
    let s = Scenario::from_json_with_overrides(&text, &sets).expect("valid scenario");
    assert_eq!(s.scheme(), vibrobed::scenario::Scheme::Hybrid);
    let (v, _) = same_run::summary(&s, &[]);
    let a = &v["approximation"];
    assert_eq!(a["handovers"], 2, "{a}");
    let dense = a["dense_time"].as_f64().unwrap();
    assert!(
        dense > 0.0 && dense <= 10.0 + 1e-9,
        "at most five windows: {a}"
    );
}

/// A bed settling on a static floor with no cure set runs on the hybrid under `auto` and reaches
/// its end in contact dynamics, at rest, its energy budget closed (the exact engine alone meets
/// inelastic collapse there); with TC set it stays on the exact engine and its rest rules.
#[test]
fn an_uncured_bed_on_a_static_floor_runs_to_its_end_on_auto() {
    use vibrobed::run::{run, RunOptions};
    use vibrobed::scenario::Scheme;
    let static_floor = r#"floor={"restitution": 0.9}"#;
    let s = scenario(&[
        "engine.scheme=auto",
        static_floor,
        "particles.temperature=0.1",
    ]);
    assert_eq!(s.scheme(), Scheme::Hybrid);
    let sum = run(&s, RunOptions::default()).expect("run");
    let v = serde_json::to_value(&sum).expect("summary serializes");
    assert_eq!(v["ending"], "completed", "{v}");
    assert_eq!(v["engine"]["scheme"], "hybrid");
    let dense = v["approximation"]["dense_time"]
        .as_f64()
        .expect("dense time");
    assert!(dense > 0.5 * s.run.duration, "{dense}");
    assert!(
        sum.energy.balance_error < 1e-9,
        "{}",
        sum.energy.balance_error
    );
    assert!(sum.max_overlap < 0.05, "{}", sum.max_overlap);
    assert!(sum.at_rest_since.is_some(), "the bed did not come to rest");
    let cured = scenario(&["engine.scheme=auto", static_floor, "collisions.tc=0.001"]);
    assert_eq!(cured.scheme(), Scheme::EventDriven);
}

/// A hand-back refused in a tall bed leaves no deep overlap: the deep bed's 100 layers, 30 wide,
/// thrown at Γ = 4, go to contact dynamics as they settle; the separation before a hand-back
/// lifts the upper disks layer on layer, past neighbours the Verlet list did not hold when it
/// moved them more than half a skin (overlaps of half a diameter where the list was kept), and
/// contact dynamics carries on from there when the exact engine refuses.
#[test]
fn a_refused_hand_back_in_a_tall_bed_leaves_no_deep_overlap() {
    let path = format!("{}/scenarios/deep_bed.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).expect("the deep bed");
    let sets = [
        "engine.scheme=auto",
        "domain.width=30",
        "particles.count=3000",
        "run.duration=16",
        "run.warmup=5",
    ]
    .map(String::from);
    let s = Scenario::from_json_with_overrides(&text, &sets).expect("valid scenario");
    let (v, _) = same_run::summary(&s, &[]);
    let a = &v["approximation"];
    assert!(a["dense_time"].as_f64().unwrap() > 1.0, "{a}");
    assert_eq!(a["deep_overlaps"], 0, "{a}");
    let overlap = v["max_overlap"].as_f64().unwrap();
    assert!(overlap < 0.05, "{overlap}");
}
