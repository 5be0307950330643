//! Rough disks (rotation, tangential restitution, Coulomb friction): known physics on the exact
//! engine — equipartition of an elastic rough gas, the homogeneous cooling state's ratio of
//! rotational to translational temperature against kinetic theory, and a spinning disk's
//! bounce on the floor worked out by hand.

use crate::common;
use vibrobed::engine::Simulation;
use vibrobed::physics::flight::Flight;
use vibrobed::physics::theory::rough_cooling_ratio;

/// Translational temperature per degree of freedom `Σ m v² / 2N` (zero total momentum) and
/// rotational temperature `Σ I ω² / N` now.
fn temperatures<F: Flight>(sim: &Simulation<F>) -> (f64, f64) {
    let t = sim.time();
    let snap = sim.snapshot(t);
    let d = sim.disks();
    let n = d.len() as f64;
    let kinetic: f64 = (0..d.len())
        .map(|k| d.mass[k] * (snap.vx[k] * snap.vx[k] + snap.vy[k] * snap.vy[k]))
        .sum();
    let rotational = 2.0 * sim.rotational_energy(sim.time()).expect("rough disks") / n;
    (kinetic / (2.0 * n), rotational)
}

/// A periodic gas of `n` rough disks at packing 0.1 with restitution `e` and tangential
/// restitution `beta`, starting with `t_rot`.
fn gas(
    n: usize,
    e: f64,
    beta: f64,
    t_rot: f64,
    seed: u64,
) -> Simulation<vibrobed::physics::flight::Straight> {
    common::straight(&format!(
        r#"{{"name": "rough gas", "seed": {seed},
        "domain": {{"width": {w}, "x_boundary": "periodic", "y_boundary": "periodic"}},
        "particles": {{"count": {n}, "radius": 0.5, "packing_fraction": 0.1,
                      "rotational_temperature": {t_rot}}},
        "collisions": {{"restitution": {e}, "tangential_restitution": {beta}}},
        "run": {{"duration": 1}}}}"#,
        w = (n as f64 * std::f64::consts::PI * 0.25 / 0.1).sqrt(),
    ))
}

/// An elastic, perfectly rough gas (e = 1, β = 1) keeps its energy (rotation included) to
/// round-off and shares it equally between the two translational degrees of freedom and the
/// rotational one: from T_rot = 0 it reaches T_rot = T_tr = 2/3 of the initial T.
#[test]
fn an_elastic_rough_gas_reaches_equipartition() {
    let n = 400;
    let mut sim = gas(n, 1.0, 1.0, 0.0, 3);
    let energy = |sim: &Simulation<_>| {
        let (t, r) = temperatures(sim);
        n as f64 * (t + 0.5 * r)
    };
    let e0 = energy(&sim);
    // Relax (20 collisions per disk), then average over 100 more.
    sim.step_events(10 * n as u64).unwrap();
    let (mut tr, mut rot) = (0.0, 0.0);
    for _ in 0..100 {
        sim.step_events(n as u64).unwrap();
        let (t, r) = temperatures(&sim);
        tr += t;
        rot += r;
    }
    let ratio = rot / tr;
    assert!((ratio - 1.0).abs() < 0.03, "T_rot/T_tr = {ratio}");
    assert!(
        (tr / 100.0 - 2.0 / 3.0).abs() < 0.02,
        "T_tr = {}",
        tr / 100.0
    );
    let drift = (energy(&sim) - e0).abs() / e0;
    assert!(drift < 1e-12, "energy drifted by {drift:e}");
}

/// The homogeneous cooling state of rough disks with constant e and β: T_rot/T_tr settles at
/// the root of kinetic theory's quadratic (see the book's physics page), within the theory's
/// accuracy (molecular chaos with Gaussian velocities and spins: measured 1 to 3 % below it at e ≥ 0.9, 11 %
/// at e = 0.8). From T_rot = T_tr, the ratio is averaged from 10 to 25 collisions per disk,
/// after it has relaxed (β ≥ 0 couples spin and translation strongly enough; at β = −0.5 it is
/// still relaxing then) and before the shear modes of a cooling gas carry a share of the
/// kinetic energy that is not temperature. Four seeds of 500 disks at packing 0.1.
#[test]
fn the_homogeneous_cooling_state_has_kinetic_theorys_ratio_of_temperatures() {
    let n = 500;
    for (e, beta, tolerance) in [
        (0.95, 0.0, 0.05),
        (0.9, 0.0, 0.05),
        (0.9, 0.5, 0.05),
        (0.95, 0.8, 0.05),
        (0.8, 0.5, 0.15),
    ] {
        let theory = rough_cooling_ratio(e, beta, 0.5);
        let (mut ratio, mut samples) = (0.0, 0);
        for seed in 1..=4 {
            let mut sim = gas(n, e, beta, 1.0, seed);
            let per_disk = |sim: &Simulation<_>| 2.0 * sim.counts().pair as f64 / n as f64;
            while per_disk(&sim) < 10.0 {
                sim.step_events(n as u64).unwrap();
            }
            while per_disk(&sim) < 25.0 {
                sim.step_events(n as u64 / 4).unwrap();
                let (t, r) = temperatures(&sim);
                ratio += r / t;
                samples += 1;
            }
        }
        let ratio = ratio / samples as f64;
        eprintln!("e = {e}, β = {beta}: T_rot/T_tr = {ratio:.4}, theory {theory:.4}");
        assert!(
            (ratio / theory - 1.0).abs() < tolerance,
            "e = {e}, β = {beta}: T_rot/T_tr = {ratio}, theory {theory}"
        );
    }
}

/// A disk thrown spinning onto a static floor (e_f = 0.8, μ = 0.2, β = 0: `floor.friction`
/// alone) rebounds as the rule says, worked out by hand: the normal impulse is
/// p_n = m (1 + e_f)|v_y|, the slip of the contact point g_t = −v_x − a ω (tangent (−1, 0)),
/// the sticking impulse −(1 + β) m_t g_t with m_t = m q/(1 + q) = m/3, capped at μ p_n.
#[test]
fn a_spinning_disk_rebounds_from_the_floor_as_the_rule_says() {
    // (vx, spin temperature): fast spin slides (the cap acts), slow spin sticks.
    for (vx, t_rot, slides) in [(0.3, 4.0, true), (0.3, 0.01, false)] {
        let mut sim = common::ballistic(&format!(
            r#"{{"name": "spinning drop", "gravity": 1.0,
            "domain": {{"width": 20}},
            "floor": {{"restitution": 0.8, "friction": 0.2}},
            "particles": {{"count": 1, "radius": 0.5, "rotational_temperature": {t_rot},
                "placement": {{"positions": [[10, 2.5]], "velocities": [[{vx}, 0]]}}}},
            "run": {{"duration": 3}}}}"#
        ));
        let (m, a, q) = (1.0, 0.5, 0.5);
        let w0 = sim.spins_at(0.0).unwrap()[0].1;
        assert!((q * m * a * a * w0 * w0 - t_rot).abs() < 1e-12 * t_rot);
        // Falls 2 from rest: impact at t = 2, v_y = −2.
        let vy = -2.0f64;
        let p_n = m * (1.0 + 0.8) * -vy;
        let g_t = -vx - a * w0;
        let m_t = m * q / (1.0 + q);
        let stick = -m_t * g_t;
        let j = if stick.abs() <= 0.2 * p_n {
            stick
        } else {
            -(0.2 * p_n).copysign(g_t)
        };
        assert_eq!(stick.abs() > 0.2 * p_n, slides);
        // Along the tangent (−1, 0): v_x changes by −j/m, ω by −a j / I.
        let (vx_after, w_after) = (vx - j / m, w0 - a * j / (q * m * a * a));
        sim.advance_to(2.5).unwrap();
        assert_eq!(sim.counts().floor, 1);
        let snap = sim.snapshot(2.5);
        let w = sim.spins_at(2.5).unwrap()[0].1;
        assert!(
            (snap.vx[0] - vx_after).abs() < 1e-12,
            "{} {vx_after}",
            snap.vx[0]
        );
        assert!((snap.vy[0] - (1.6 - 0.5)).abs() < 1e-9, "{}", snap.vy[0]);
        assert!((w - w_after).abs() < 1e-12, "{w} {w_after}");
        if !slides {
            // A sticking contact with β = 0 leaves rolling: the contact point at rest.
            assert!((vx_after + a * w_after).abs() < 1e-12);
        }
    }
}

/// A disk thrown sideways onto a rough floor, without spin, bounces (each impact's friction
/// impulse acts at the contact point, so `I ω − m a v_x` is kept) and comes to rest riding
/// the floor; Coulomb friction then slows its slip until it rolls. Whatever the impacts and the
/// slide did, it rolls on at `v₀/(1 + q)` — two thirds of its speed for a uniform disk — with
/// `ω = −v_x/a`, and the energy it lost is booked.
#[test]
fn a_disk_sliding_onto_a_rough_floor_rolls_on_at_two_thirds_of_its_speed() {
    for (friction, beta) in [(0.2, None), (0.5, Some(0.3)), (f64::INFINITY, Some(0.0))] {
        let law = match beta {
            Some(b) if friction == f64::INFINITY => format!(r#""tangential_restitution": {b}"#),
            Some(b) => format!(r#""friction": {friction}, "tangential_restitution": {b}"#),
            None => format!(r#""friction": {friction}"#),
        };
        let mut sim = common::ballistic(&format!(
            r#"{{"name": "sliding drop", "gravity": 1.0,
            "domain": {{"width": 20, "x_boundary": "periodic"}},
            "floor": {{"restitution": 0.5, {law}}},
            "particles": {{"count": 1, "radius": 0.5,
                "placement": {{"positions": [[10, 2.5]], "velocities": [[1.0, 0]]}}}},
            "run": {{"duration": 30}}}}"#
        ));
        sim.advance_to(30.0).unwrap();
        assert_eq!(sim.riders(), 1, "{law}: rides the floor");
        let (v, w) = (sim.snapshot(30.0).vx[0], sim.spins_at(30.0).unwrap()[0].1);
        assert!((v - 2.0 / 3.0).abs() < 1e-12, "{law}: v = {v}");
        assert!((w + v / 0.5).abs() < 1e-12, "{law}: ω = {w}");
        // Mass 1, radius 0.5, q = ½; it started at height 2.5 with speed 1 and no spin.
        let flow = sim.energy_flow();
        let now = 0.5 * v * v + 0.5 * 0.5 * 0.25 * w * w + 0.5;
        let budget = now - (0.5 + 2.5) - flow.injected + flow.dissipated;
        assert!(budget.abs() < 1e-12, "{law}: energy budget off by {budget}");
    }
}

/// Total energy of the disks at absolute time `t` (kinetic, potential under g = 1, rotational)
/// minus what the floor put in plus what was lost: constant for an exact engine.
fn budget(sim: &Simulation<vibrobed::physics::flight::Ballistic>, t: f64) -> f64 {
    let snap = sim.snapshot(t);
    let disks = sim.disks();
    let mut e = sim.rotational_energy(t).unwrap();
    for k in 0..snap.x.len() {
        let m = disks.mass[k];
        e += 0.5 * m * (snap.vx[k].powi(2) + snap.vy[k].powi(2)) + m * snap.y[k];
    }
    let flow = sim.energy_flow_at(t);
    e - flow.injected + flow.dissipated
}

/// A disk set down sliding on a still rough floor (v₀ = 1, no spin, μ = 0.2, q = ½) slows
/// uniformly under Coulomb friction, `v_x = v₀ − μ g t`, while the friction's torque spins it
/// up, `ω = −μ g t/(q a)`, until its slip `v_x + a ω` vanishes at `t = v₀/(μ g (1 + 1/q))`;
/// then it rolls on at two thirds of its speed. Followed in time, with no step: positions,
/// velocities, spins and orientations agree with the closed form to round-off at any time, and
/// the energy budget closes in the middle of the slide.
#[test]
fn a_disk_sliding_on_a_still_rough_floor_slows_exactly_until_it_rolls() {
    let mut sim = common::ballistic(
        r#"{"name": "slide", "gravity": 1.0,
        "domain": {"width": 20, "x_boundary": "periodic"},
        "floor": {"restitution": 0.5, "friction": 0.2},
        "particles": {"count": 1, "radius": 0.5,
            "placement": {"positions": [[10, 0.5]], "velocities": [[1.0, 0]]}},
        "run": {"duration": 3}}"#,
    );
    let (mu, qa) = (0.2, 0.25);
    let end = 1.0 / (mu * 3.0);
    let e0 = budget(&sim, 0.0);
    for k in 1..=12 {
        let t = 0.25 * k as f64;
        sim.advance_to(t).unwrap();
        let ts = t.min(end);
        let (x, v) = (10.0 + ts - 0.5 * mu * ts * ts, 1.0 - mu * ts);
        let (x, w) = (x + v * (t - ts), -mu * ts / qa);
        let angle = -0.5 * mu * ts * ts / qa + w * (t - ts);
        let snap = sim.snapshot(t);
        let (a, w_sim) = sim.spins_at(t).unwrap()[0];
        assert!(
            (snap.x[0] - x).abs() < 1e-13,
            "t = {t}: x = {} vs {x}",
            snap.x[0]
        );
        assert!(
            (snap.vx[0] - v).abs() < 1e-14,
            "t = {t}: v = {} vs {v}",
            snap.vx[0]
        );
        assert!((w_sim - w).abs() < 1e-13, "t = {t}: ω = {w_sim} vs {w}");
        let da = (a - angle.rem_euclid(std::f64::consts::TAU)).abs();
        assert!(
            da.min(std::f64::consts::TAU - da) < 1e-12,
            "t = {t}: angle {a} vs {angle}"
        );
        let off = budget(&sim, t) - e0;
        assert!(off.abs() < 1e-14, "t = {t}: energy budget off by {off}");
        assert_eq!(sim.counts().slide_end, u64::from(t >= end), "t = {t}");
    }
}

/// On a floor vibrating below Γ = 1 the floor's push `m (g + h'')` varies, and so does the
/// friction: a disk sliding on it follows `v_x' = −μ (g + h'')` exactly. Against a fine
/// numerical integration of that law, its velocity, spin and the moment it starts rolling.
#[test]
fn a_disk_sliding_on_a_vibrating_rough_floor_follows_the_floors_push() {
    // Γ = A ω²/g = 0.8, period 2π/4.
    let (amp, omega, mu) = (0.05, 4.0, 0.3);
    let mut sim = common::ballistic(&format!(
        r#"{{"name": "slide", "gravity": 1.0,
        "domain": {{"width": 40, "x_boundary": "periodic"}},
        "floor": {{"restitution": 0.5, "friction": {mu}, "amplitude": {amp}, "frequency": {f}}},
        "particles": {{"count": 1, "radius": 0.5,
            "placement": {{"positions": [[10, 0.5]], "velocities": [[-1.2, 0]]}}}},
        "run": {{"duration": 3}}}}"#,
        f = omega / std::f64::consts::TAU
    ));
    // It bounces on the rising floor a little, then rides it.
    let mut t0 = 0.0;
    while sim.riders() == 0 && t0 < 2.0 {
        t0 += 1e-3;
        sim.advance_to(t0).unwrap();
    }
    assert_eq!(sim.riders(), 1, "rides the floor by t = {t0}");
    let (v0, w0) = (sim.snapshot(t0).vx[0], sim.spins_at(t0).unwrap()[0].1);
    let slip0 = v0 + 0.5 * w0;
    assert!(slip0.abs() > 0.5, "slides: slip {slip0}");
    // Integrate v' = −κ (1 + h''), ω' = v'/(q a) from t0 until the slip vanishes.
    let h2 = |t: f64| -amp * omega * omega * (omega * t).sin();
    let kappa = slip0.signum() * mu;
    let (mut t, mut v, mut w, dt) = (t0, v0, w0, 1e-6);
    let mut samples = Vec::new();
    while (v + 0.5 * w) * slip0 > 0.0 {
        let acc = -kappa * (1.0 + h2(t + 0.5 * dt));
        v += acc * dt;
        w += acc * dt / 0.25;
        t += dt;
        if samples.len() < 8 && t >= t0 + 0.2 * (samples.len() + 1) as f64 {
            samples.push((t, v, w));
        }
    }
    for (ts, v, w) in samples {
        sim.advance_to(ts).unwrap();
        let (vs, ws) = (sim.snapshot(ts).vx[0], sim.spins_at(ts).unwrap()[0].1);
        assert!(
            (vs - v).abs() < 1e-6 && (ws - w).abs() < 4e-6,
            "t = {ts}: {vs} {ws} vs {v} {w}"
        );
    }
    sim.advance_to(t - 1e-4).unwrap();
    assert_eq!(sim.counts().slide_end, 0, "still sliding just before {t}");
    sim.advance_to(t + 1e-4).unwrap();
    assert_eq!(sim.counts().slide_end, 1, "rolling just after {t}");
}

/// A disk sliding on a rough floor toward a side wall, and another into a disk rolling on the
/// floor: the bent paths meet the wall and the disk exactly (no overlap under the invariant
/// checks), and the energy budget closes.
#[test]
fn sliding_disks_meet_walls_and_disks_on_their_bent_paths() {
    let mut sim = common::ballistic(
        r#"{"name": "slide", "gravity": 1.0,
        "domain": {"width": 6, "x_boundary": "walls", "wall_restitution": 0.9},
        "floor": {"restitution": 0.5, "friction": 0.1},
        "collisions": {"restitution": 0.9},
        "particles": {"count": 2, "radius": 0.5,
            "placement": {"positions": [[1.5, 0.5], [4.0, 0.5]], "velocities": [[-1.5, 0], [2.5, 0]]}},
        "engine": {"check_invariants": true},
        "run": {"duration": 20}}"#,
    );
    let e0 = budget(&sim, 0.0);
    sim.advance_to(20.0).unwrap();
    let counts = sim.counts();
    assert!(counts.wall >= 2 && counts.pair >= 1, "{counts:?}");
    assert!(counts.slide_end >= 2, "{counts:?}");
    let off = budget(&sim, 20.0) - e0;
    assert!(off.abs() < 1e-12, "energy budget off by {off}");
    assert!(sim.max_overlap() < 1e-10, "overlap {}", sim.max_overlap());
}

/// A disk dropped a little off the crown of a rough disk at rest on the floor, in a narrow box
/// with rough walls, rolls off and comes to rest: both at rest, still, no spin, no events.
/// (The two roll on the floor together, without rolling resistance, to the wall: at rest from
/// t ≈ 115.)
#[test]
fn a_disk_dropped_on_the_crown_of_a_rough_disk_at_rest_stops() {
    let mut sim = common::ballistic(
        r#"{"name": "crown drop", "gravity": 1.0,
        "domain": {"width": 4.3, "x_boundary": "walls", "y_boundary": "open",
                   "wall_friction": 0.5, "wall_restitution": 0.5},
        "floor": {"restitution": 0.5, "friction": 0.5},
        "particles": {"count": 2, "radius": 0.5,
            "placement": {"positions": [[2.15, 0.5], [2.25, 3.0]],
                          "velocities": [[0, 0], [0, 0]]}},
        "collisions": {"restitution": 0.5, "friction": 0.5, "tc": 0.001},
        "run": {"duration": 300}}"#,
    );
    sim.advance_to(150.0).unwrap();
    assert_eq!(sim.riders(), 2, "both at rest by t = 150");
    let events = sim.counts().popped();
    sim.advance_to(300.0).unwrap();
    assert_eq!(sim.counts().popped(), events, "events at rest");
    let snap = sim.snapshot(300.0);
    assert!(snap.vx.iter().chain(&snap.vy).all(|&v| v == 0.0));
    assert!(
        snap.y.iter().all(|&y| (y - 0.5).abs() < 1e-6),
        "both on the floor"
    );
    assert!(sim.spins_at(300.0).unwrap().iter().all(|&(_, w)| w == 0.0));
}

/// A rough bed on a vibrating floor with friction on pairs, floor and walls keeps its energy
/// budget, rotation and tangential losses included, to round-off, under the invariant checks.
#[test]
fn a_rough_vibrated_bed_closes_its_energy_budget_under_the_invariant_checks() {
    let text = std::fs::read_to_string(common::crate_path("scenarios/vibrated_bed.json")).unwrap();
    let sets: Vec<String> = [
        "run.duration=40",
        "run.warmup=10",
        "domain.x_boundary=walls",
        "output.profile_height=40",
        "domain.wall_friction=0.3",
        "collisions.friction=0.5",
        "collisions.tangential_restitution=0.4",
        "floor.friction=0.5",
        "particles.rotational_temperature=0.2",
        "engine.check_invariants=true",
    ]
    .map(String::from)
    .to_vec();
    let s = vibrobed::Scenario::from_json_with_overrides(&text, &sets).unwrap();
    let summary = vibrobed::run::run(&s, vibrobed::run::RunOptions::default()).unwrap();
    let summary = serde_json::to_value(&summary).unwrap();
    let error = summary["energy"]["balance_error"].as_f64().unwrap();
    assert!(error < 1e-12, "balance error {error:e}");
    assert!(summary["temperature"]["rotational"].as_f64().unwrap() > 0.0);
    assert!(summary["energy"]["final"]["rotational"].as_f64().unwrap() > 0.0);
    assert!(summary["events"]["wall"].as_u64().unwrap() > 0);
    // The profiles' rotational temperature adds up to the summary's: Σ_bins T_rot·density·area
    // is N ⟨T_rot⟩ when no disk flies above the profiles. A bin no disk entered has none (null).
    let p = &summary["profiles"];
    let column = |name: &str| -> Vec<Option<f64>> {
        p[name]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64())
            .collect()
    };
    let number = |c: Vec<Option<f64>>| -> Vec<f64> { c.into_iter().map(Option::unwrap).collect() };
    let (height, density, t_rot) = (
        number(column("height")),
        number(column("density")),
        column("temperature_rotational"),
    );
    assert_eq!(p["above_top"].as_f64().unwrap(), 0.0);
    for k in 0..height.len() {
        assert_eq!(
            t_rot[k].is_none(),
            density[k] == 0.0,
            "bin {k}: {:?}",
            t_rot[k]
        );
    }
    let bin_area = (height[1] - height[0]) * s.domain.width;
    let total: f64 = (0..height.len())
        .map(|k| t_rot[k].unwrap_or(0.0) * density[k] * bin_area)
        .sum();
    let expected = 1000.0 * summary["temperature"]["rotational"].as_f64().unwrap();
    assert!(
        (total / expected - 1.0).abs() < 1e-9,
        "{total} vs {expected}"
    );
}

/// Trajectories carry each rough disk's orientation and spin as two more extended XYZ columns,
/// on every engine: a lone disk spinning in flight turns at its constant ω
/// (|ω| = √(T_rot / I) = √(2 / 0.125) = 4), across the exact engine's re-based clock and on the
/// schemes' absolute one.
#[test]
fn trajectories_carry_the_orientation_and_spin_of_rough_disks() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("rough-trajectory");
    let _ = std::fs::create_dir_all(&dir);
    for scheme in ["event-driven", "time-step", "space-time"] {
        let path = dir.join(format!("{scheme}.xyz"));
        let s = common::scenario(&format!(
            r#"{{"name": "spinning", "seed": 5,
            "domain": {{"width": 10, "height": 10, "x_boundary": "periodic",
                        "y_boundary": "periodic"}},
            "particles": {{"count": 1, "radius": 0.5, "rotational_temperature": 2.0,
                "placement": {{"positions": [[5, 5]], "velocities": [[0.3, 0.1]]}}}},
            "run": {{"duration": 40}},
            "engine": {{"scheme": "{scheme}"}},
            "output": {{"trajectory": "{}", "trajectory_interval": 2.5}}}}"#,
            path.display()
        ));
        vibrobed::run::run(&s, vibrobed::run::RunOptions::default()).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert!(
            lines[1]
                .contains("Properties=species:S:1:pos:R:3:radius:R:1:velo:R:3:angle:R:1:omega:R:1"),
            "{scheme}: {}",
            lines[1]
        );
        let mut frames = 0;
        for (k, frame) in lines.chunks(3).enumerate() {
            let cols: Vec<f64> = frame[2]
                .split_whitespace()
                .skip(1)
                .map(|c| c.parse().unwrap())
                .collect();
            let (angle, omega) = (cols[7], cols[8]);
            assert!((omega.abs() - 4.0).abs() < 1e-14, "{scheme}: {omega}");
            let expected = (omega * 2.5 * k as f64).rem_euclid(std::f64::consts::TAU);
            let diff = (angle - expected).abs();
            assert!(
                diff.min(std::f64::consts::TAU - diff) < 1e-9,
                "{scheme}, frame {k}: {angle} vs {expected}"
            );
            frames += 1;
        }
        assert_eq!(frames, 17, "{scheme}");
    }
}

/// The shipped rough bed on the fixed-position floor stalled at t = 20.87: a disk came to rest
/// on the floor while the floor moved down faster than gravity, where the fixed-position model's
/// ride ends at once with a launch of 0 — it landed again at the same instant, for ever. Such a
/// disk now rides on to the next take-off, and the run goes on.
#[test]
fn a_disk_at_rest_on_the_fixed_position_floor_while_it_falls_rides_on() {
    let text =
        std::fs::read_to_string(common::crate_path("scenarios/rough_vibrated_bed.json")).unwrap();
    let sets: Vec<String> = [
        "floor.model=fixed-position",
        "run.duration=22",
        "run.warmup=1",
    ]
    .map(String::from)
    .to_vec();
    let s = vibrobed::Scenario::from_json_with_overrides(&text, &sets).unwrap();
    let summary = vibrobed::run::run(&s, vibrobed::run::RunOptions::default()).unwrap();
    let summary = serde_json::to_value(&summary).unwrap();
    assert_eq!(summary["ending"], "completed", "{}", summary["ending"]);
    assert!(summary["energy"]["balance_error"].as_f64().unwrap() < 1e-10);
}
