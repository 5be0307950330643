//! The contact-dynamics scheme (`engine.scheme = contact`) against what holds exactly or is known
//! in closed form: the floor's impulse balances weight and momentum to round-off, a dropped disk
//! rebounds to e² of its height as the step shrinks (Newton's law), a disk sliding on a rough
//! floor slows at μg and rolls on at v₀/(1 + q) (Coulomb), a bed on a static floor rests on it
//! without sinking, a separation undone leaves the run as it was, and a run repeats bit for bit.

use crate::common::{momentum_y, same_run};
use vibrobed::engine::Scene;
use vibrobed::physics::flight::Ballistic;
use vibrobed::schemes::contact::Contact;
use vibrobed::schemes::Integrator;
use vibrobed::Scenario;

/// A small vibrated bed: 150 inelastic disks, about five layers.
const BED: &str = r#"{
  "name": "small vibrated bed",
  "seed": 3,
  "domain": { "width": 30.0, "x_boundary": "periodic", "y_boundary": "open" },
  "gravity": 1.0,
  "floor": { "gamma": 1.5, "frequency": 0.5, "restitution": 0.9 },
  "particles": { "count": 150, "radius": 0.5, "temperature": 0.5 },
  "collisions": { "restitution": 0.9 },
  "engine": { "scheme": "contact" },
  "run": { "duration": 30.0, "warmup": 10.0 }
}"#;

fn scenario(json: &str, sets: &[&str]) -> Scenario {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Scenario::from_json_with_overrides(json, &sets).expect("valid scenario")
}

fn engine(s: &Scenario) -> Contact<Ballistic> {
    let (scene, disks) = Scene::build(s).expect("scene");
    Contact::new(Ballistic { g: 1.0 }, &scene, disks, &s.engine).expect("engine")
}

/// Pair impulses are internal: whatever the bed does, the floor's impulse is the change of
/// momentum plus the weight's, `F = ΔP_y + N m g t`, to round-off — on a bouncing bed (Γ = 1.5)
/// and on one that rides the floor (Γ = 0.8).
#[test]
fn the_floor_impulse_balances_weight_and_momentum() {
    for gamma in ["1.5", "0.8"] {
        let s = scenario(BED, &[&format!("floor.gamma={gamma}")]);
        let mut sim = engine(&s);
        let p0 = momentum_y(&sim);
        sim.advance_to(25.0).unwrap();
        let t = sim.time();
        let weight = 150.0 * t;
        let floor = sim.energy_flow_at(t).floor_impulse;
        let off = floor - (momentum_y(&sim) - p0 + weight);
        assert!(
            off.abs() < 1e-10 * weight,
            "Γ = {gamma}: floor impulse {floor}, ΔP + N m g t = {}",
            floor - off
        );
        assert!(sim.counts().pair > 0 && sim.counts().floor > 0);
    }
}

/// The apex after the first bounce of a disk dropped onto a static floor with restitution `e`,
/// over its drop height: e² at every step, to 0.1 % (the disk turns within the step it would
/// meet the floor, up to a step's flight early, on the speed it had at the step's start).
#[test]
fn a_dropped_disk_rebounds_to_e_squared_of_its_height_at_any_step() {
    let (e, h0) = (0.8f64, 2.1234f64);
    let mut errors = Vec::new();
    for dt in [0.02, 0.01, 0.005] {
        let s = scenario(
            &format!(
                r#"{{"name": "drop", "gravity": 1.0, "domain": {{"width": 20}},
                "floor": {{"restitution": {e}}},
                "particles": {{"count": 1, "radius": 0.5,
                    "placement": {{"positions": [[10, {}]], "velocities": [[0, 0]]}}}},
                "engine": {{"scheme": "contact", "dt": {dt}}},
                "run": {{"duration": 8}}}}"#,
                h0 + 0.5
            ),
            &[],
        );
        let mut sim = engine(&s);
        let (mut apex, mut bounced) = (0.0f64, false);
        let mut k = 1;
        while sim.time() < 6.0 {
            sim.advance_to(k as f64 * dt).unwrap();
            k += 1;
            let mut state = [0.0; 4];
            sim.visit_states(sim.time(), |_, s| state = s);
            bounced |= state[3] > 0.0;
            if bounced {
                apex = apex.max(state[1] - 0.5);
            }
        }
        errors.push((apex / h0 - e * e).abs() / (e * e));
    }
    eprintln!("apex errors {errors:?}");
    assert!(errors.iter().all(|&e| e < 1e-3), "{errors:?}");
}

/// A disk launched along a rough floor (μ = 0.3) without spin slides, slowing at μ g while its
/// spin grows, until it rolls at v₀/(1 + q) (q = ½): Coulomb's cone and the sticking contact.
#[test]
fn a_disk_sliding_on_a_rough_floor_rolls_on_at_v0_over_1_plus_q() {
    let (v0, mu, a) = (1.0, 0.3, 0.5);
    let s = scenario(
        &format!(
            r#"{{"name": "slide", "gravity": 1.0, "domain": {{"width": 20}},
            "floor": {{"restitution": 0.5, "friction": {mu}}},
            "particles": {{"count": 1, "radius": {a}, "rotational_temperature": 0,
                "placement": {{"positions": [[5, {a}]], "velocities": [[{v0}, 0]]}}}},
            "engine": {{"scheme": "contact", "dt": 0.01}},
            "run": {{"duration": 4}}}}"#
        ),
        &[],
    );
    let mut sim = engine(&s);
    let vx = |sim: &Contact<Ballistic>| {
        let mut v = 0.0;
        sim.visit_states(sim.time(), |_, s| v = s[2]);
        v
    };
    sim.advance_to(0.5).unwrap();
    let sliding = vx(&sim);
    // (Its first step presses it on the floor with half its weight: it starts on the floor
    // with no velocity, and a step's impulse carries the weight of half a step before it.)
    assert!(
        (sliding - (v0 - mu * 0.5)).abs() <= 0.5 * mu * 0.01 + 1e-12,
        "sliding: {sliding}, μ g t says {}",
        v0 - mu * 0.5
    );
    sim.advance_to(3.0).unwrap();
    let (v, w) = (vx(&sim), sim.spins_at(sim.time()).unwrap()[0].1);
    assert!(
        (v - v0 / 1.5).abs() < 1e-9,
        "rolling at {v}, v0/(1+q) = {}",
        v0 / 1.5
    );
    assert!((v + a * w).abs() < 1e-9, "rolls: v = {v}, ω a = {}", w * a);
    let mut y = 0.0;
    sim.visit_states(sim.time(), |_, s| y = s[1]);
    assert!((y - a).abs() < 1e-9, "stays on the floor: y = {y}");
}

/// A bed dropped onto a static floor comes to rest on it: no disk below the floor, no pair
/// overlapping by more than 1 % of a diameter, and the floor carries the weight.
#[test]
fn a_bed_on_a_static_floor_rests_without_sinking() {
    let fixed = BED.replace(
        r#""floor": { "gamma": 1.5, "frequency": 0.5, "restitution": 0.9 }"#,
        r#""floor": { "restitution": 0.9 }"#,
    );
    let s = scenario(&fixed, &["run.duration=40"]);
    let mut sim = engine(&s);
    sim.advance_to(30.0).unwrap();
    let f0 = sim.energy_flow_at(sim.time()).floor_impulse;
    let t0 = sim.time();
    sim.advance_to(40.0).unwrap();
    let rate = (sim.energy_flow_at(sim.time()).floor_impulse - f0) / (sim.time() - t0);
    assert!(
        (rate - 150.0).abs() < 0.01 * 150.0,
        "floor carries {rate} of 150"
    );
    assert!(sim.max_overlap() < 0.01, "overlap {}", sim.max_overlap());
    let mut lowest = f64::INFINITY;
    sim.visit_states(sim.time(), |_, s| lowest = lowest.min(s[1]));
    assert!(lowest > 0.5 * (1.0 - 1e-3), "lowest centre {lowest}");
    let mut kinetic = 0.0;
    sim.visit_states(sim.time(), |_, s| {
        kinetic += 0.5 * (s[2] * s[2] + s[3] * s[3])
    });
    assert!(
        kinetic / 150.0 < 1e-4,
        "kinetic energy per disk {}",
        kinetic / 150.0
    );
}

/// An overlap is opened by moving the disks, not by giving them speed: two disks resting on a
/// static floor side by side, overlapping by a fifth of a radius, are pushed apart while their
/// horizontal speeds stay exactly 0 (opening the overlap through their velocities, a tenth a
/// step, would have left them flying apart at 0.01/dt): no energy is made. Once quiet for 50
/// steps the pair falls asleep on the floor, its overlap opened to within twice the slop; a
/// disk still pushed apart is moving, so nothing moves after the pair's time of rest.
#[test]
fn an_overlap_is_opened_by_position_without_making_energy() {
    let s = scenario(
        r#"{"name": "overlap", "gravity": 1.0, "domain": {"width": 20},
            "floor": {"restitution": 0.5},
            "particles": {"count": 2, "radius": 0.5,
                "placement": {"positions": [[9, 0.5], [11, 0.5]], "velocities": [[0, 0], [0, 0]]}},
            "collisions": {"restitution": 0.5},
            "engine": {"scheme": "contact", "dt": 0.01},
            "run": {"duration": 2}}"#,
        &[],
    );
    let (scene, mut disks) = Scene::build(&s).expect("scene");
    disks.motion[0].x = 9.95;
    disks.motion[1].x = 10.85;
    let mut sim = Contact::new(Ballistic { g: 1.0 }, &scene, disks, &s.engine).expect("engine");
    let states = |sim: &Contact<Ballistic>| {
        let mut states = Vec::new();
        sim.visit_states(sim.time(), |_, s| states.push(s));
        states
    };
    let gap = |s: &[[f64; 4]]| (s[1][0] - s[0][0]).abs() - 1.0;
    // Before 50 steps (t = 0.5) the pair cannot have fallen asleep, which would set its speeds.
    let mut last = -0.1;
    for t in [0.1, 0.2, 0.3] {
        sim.advance_to(t).unwrap();
        let now = states(&sim);
        assert!(gap(&now) > last, "t = {t}: gap {} after {last}", gap(&now));
        assert!(now.iter().all(|s| s[2] == 0.0), "t = {t}: {now:?}");
        last = gap(&now);
    }
    // Step by step to the end: from the pair's time of rest on, nothing moves (an overlap
    // still being opened is motion).
    let mut seen = Vec::new();
    for k in 31..=200 {
        sim.advance_to(k as f64 * 0.01).unwrap();
        seen.push((sim.time(), states(&sim)));
    }
    let end = states(&sim);
    let since = sim.at_rest_since().expect("the pair comes to rest");
    // Between steps a state is on its parabola, g dt²/2 below the step's end at most.
    for (t, s) in seen.iter().filter(|(t, _)| *t >= since) {
        let moved =
            (s.iter().zip(&end)).any(|(a, b)| (a[0] - b[0]).abs() + (a[1] - b[1]).abs() > 1e-4);
        assert!(
            !moved,
            "moved at t = {t} after rest from {since}: {s:?}, at the end {end:?}"
        );
    }
    assert!(gap(&end) > -2e-3 && gap(&end) < 1e-9, "gap {}", gap(&end));
    for s in &end {
        assert!(
            s[2] == 0.0 && s[3].abs() < 1e-12 && (s[1] - 0.5).abs() < 1e-4,
            "{s:?}"
        );
    }
}

/// A hand-back that the exact engine refuses puts contact dynamics back as it was before the
/// separation (the hybrid restores the state it saved): the run goes on bit for bit as if no
/// separation had been made, although the separation moved disks.
#[test]
fn a_separation_undone_leaves_the_run_as_it_was() {
    let s = scenario(
        BED,
        &["particles.count=600", "run.duration=8", "run.warmup=0"],
    );
    let states = |sim: &Contact<Ballistic>| {
        let mut states = Vec::new();
        sim.visit_states(sim.time(), |_, s| states.push(s));
        states
    };
    let (mut plain, mut undone) = (engine(&s), engine(&s));
    // Separated and undone every tenth of a time unit, until the separation moves a disk (a
    // contact overlaps).
    let mut t = 0.0;
    loop {
        t += 0.1;
        assert!(t < 4.0, "no overlap to separate");
        plain.advance_to(t).unwrap();
        undone.advance_to(t).unwrap();
        let saved = undone.state();
        undone.separate();
        let moved = states(&undone) != states(&plain);
        undone.restore(saved).unwrap();
        if moved {
            break;
        }
    }
    plain.advance_to(8.0).unwrap();
    undone.advance_to(8.0).unwrap();
    assert_eq!(states(&undone), states(&plain));
    assert_eq!(undone.energy_flow_at(8.0), plain.energy_flow_at(8.0));
    assert_eq!(undone.counts(), plain.counts());
}

/// The same scenario gives the same run, bit for bit.
#[test]
fn a_contact_run_repeats_bit_for_bit() {
    let s = scenario(BED, &["run.duration=10", "run.warmup=2"]);
    same_run::same_final_state("contact", &s, &s.clone());
}

/// Knobs of other schemes are refused with their field's name; the threads knob too (the
/// Gauss–Seidel sweep runs on one thread).
#[test]
fn knobs_of_other_schemes_are_refused_on_the_contact_scheme() {
    for (set, field) in [
        ("engine.sync_distance=6", "engine.sync_distance"),
        ("engine.strips=2", "engine.strips"),
        ("engine.threads=2", "engine.threads"),
    ] {
        let sets = vec![set.to_string()];
        let err = Scenario::from_json_with_overrides(BED, &sets).expect_err(set);
        assert!(err.to_string().contains(field), "{set}: {err}");
        assert_eq!(err.exit_code(), 2);
    }
}

/// The default step follows the fastest impact, between a fiftieth of the floor's period and a
/// 400th: a bed the floor throws lands on it each period and takes fine steps there; a bed that
/// rides the floor meets few fast impacts and takes mostly coarse ones; a step given
/// (`engine.dt`) is kept.
#[test]
fn the_default_step_follows_the_fastest_impact() {
    let (coarse, finest) = (2.0 / 50.0, 2.0 / 400.0);
    let mean_step = |sets: &[&str]| {
        let mut sim = engine(&scenario(BED, sets));
        sim.advance_to(10.0).unwrap();
        let settled = sim.approximation().unwrap();
        sim.advance_to(30.0).unwrap();
        let end = sim.approximation().unwrap();
        20.0 / (end.steps - settled.steps) as f64
    };
    let riding = mean_step(&["floor.gamma=0.5"]);
    let landing = mean_step(&["floor.gamma=1.5"]);
    assert!(
        riding > 0.5 * coarse && riding <= coarse * 1.001,
        "riding: {riding}"
    );
    assert!(
        landing >= 0.999 * finest && landing < 0.2 * coarse,
        "landing: {landing}"
    );
    let given = mean_step(&["floor.gamma=1.5", "engine.dt=0.01"]);
    assert!((given - 0.01).abs() < 1e-3 * 0.01, "given: {given}");
}
