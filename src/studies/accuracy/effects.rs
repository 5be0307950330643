//! `--effects`: what each effect of a scene costs (walls, polydispersity, dissipation, a floor,
//! gravity, floor kinds, friction, recording). Each effect is a pair of scenes, without and with
//! it, built around the scenario's disks and run on the exact engine; the row gives the slowdown
//! per collision and per unit of simulated time. Friction is added to the scenario itself (the
//! vibrated bed with friction on and off), and its row also gives what it changes in the
//! observables.

use super::ensemble::{Ensemble, Measured};
use super::{say, with_sets, EffectRow, Options};
use crate::error::{Error, Result};
use crate::output::summary::Ending;
use crate::physics::drive::Drive;
use crate::run::{run, RunOptions};
use crate::scenario::{Scenario, XBoundary, YBoundary};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// What each effect costs: the minimum over repetitions of the wall time per collision and per
/// unit time (the minimum is the least disturbed by a noisy machine). `scenario` is the
/// reference (the exact engine, without recording).
pub(super) fn table(scenario: &Scenario, opts: &Options) -> Result<Vec<EffectRow>> {
    let scenes = Scenes::around(scenario, opts.quick);
    let reps = if opts.quick { 1 } else { 3 };
    let mut rows = Vec::new();
    for effect in scenes.effects() {
        let timed = effect.time(reps, &opts.out)?;
        say(
            opts,
            format!(
                "  effect {:<30} ×{:.2} per collision",
                effect.name,
                timed.best[1][0] / timed.best[0][0]
            ),
        );
        rows.push(effect.row(timed));
    }
    Ok(rows)
}

/// The two scenes the effects are added to, with the scales the effects are set in.
struct Scenes {
    /// An elastic gas in a periodic box, at packing fraction 0.3.
    gas: Value,
    /// The same disks in a box with a static floor and a lid, without gravity.
    floor_box: Value,
    /// The scenario's smallest radius.
    a: f64,
    /// Gravity: a gravitational height kT/(mg) of two diameters.
    g: f64,
    /// The scenario itself.
    scenario: Value,
    /// Its overrides without and with friction, and the friction in words (see [`friction`]).
    friction: (Vec<String>, Vec<String>, String),
}

impl Scenes {
    /// The scenes with the scenario's disk count, smallest radius and seed; long enough for each
    /// disk to travel some 100 diameters at unit temperature (10 with `quick`).
    fn around(scenario: &Scenario, quick: bool) -> Scenes {
        let n = scenario.disk_count().max(2);
        let (a, _) = scenario.radius_range();
        let phi = 0.3;
        let area = n as f64 * std::f64::consts::PI * a * a / phi;
        let width = area.sqrt().max(8.0 * a);
        // Long enough for each disk to travel some 100 diameters at unit temperature.
        let duration = if quick { 10.0 } else { 100.0 } * 2.0 * a;
        let gas = serde_json::json!({
            "name": "effects: elastic gas, periodic box",
            "seed": scenario.seed,
            "domain": {"width": width, "x_boundary": "periodic", "y_boundary": "periodic"},
            "particles": {"count": n, "radius": a, "packing_fraction": phi, "temperature": 1.0},
            "run": {"duration": duration},
        });
        let height = area / width;
        let floor_box = serde_json::json!({
            "name": "effects: box with a lid and a static floor",
            "seed": scenario.seed,
            "domain": {"width": width, "height": height, "x_boundary": "periodic", "y_boundary": "lid"},
            "floor": {"restitution": 1.0},
            "particles": {"count": n, "radius": a, "temperature": 1.0},
            "run": {"duration": duration},
        });
        let g = 1.0 / (4.0 * a); // gravitational height kT/(mg) of two diameters
        Scenes {
            gas,
            floor_box,
            a,
            g,
            scenario: serde_json::to_value(scenario).expect("a scenario serialises"),
            friction: friction(scenario),
        }
    }

    /// Every effect, in table order.
    fn effects(&self) -> Vec<Effect<'_>> {
        let mut effects = self.gas_effects();
        effects.extend(self.floor_effects());
        let (without, with, added) = &self.friction;
        let mut friction = Effect::on(
            "friction",
            &self.scenario,
            without.clone(),
            with.clone(),
            added,
        );
        friction.observe = true;
        effects.push(friction);
        if cfg!(feature = "record") {
            let mut recording = Effect::on(
                "recording",
                &self.gas,
                vec![],
                vec![],
                "frames recorded (200 frames)",
            );
            recording.record = true;
            effects.push(recording);
        }
        effects
    }

    /// The effects added to the elastic gas: walls, polydispersity, dissipation, a floor and lid.
    fn gas_effects(&self) -> Vec<Effect<'_>> {
        let (gas, a) = (&self.gas, self.a);
        let tc = format!("collisions.tc={:e}", 1e-3 * 2.0 * a);
        let poly = format!(
            "particles.radius={{\"min\":{},\"max\":{}}}",
            0.7 * a,
            1.3 * a
        );
        vec![
            Effect::on(
                "walls vs periodic",
                gas,
                vec![],
                sets(&["domain.x_boundary=walls"]),
                "hard side walls",
            ),
            Effect::on(
                "polydispersity",
                gas,
                vec![],
                vec![poly],
                "radii uniform in [0.7a, 1.3a]",
            ),
            Effect::on(
                "dissipation: e = 0.9 + TC",
                gas,
                vec![],
                vec!["collisions.restitution=0.9".into(), tc],
                "e = 0.9 with TC",
            ),
            Effect::on(
                "dissipation: e = 0.9 + cutoff",
                gas,
                vec![],
                sets(&["collisions.restitution=0.9", "collisions.speed_cutoff=0.05"]),
                "e = 0.9 with speed cutoff",
            ),
            // The one effect that compares two different base scenes.
            Effect::between(
                "floor and lid vs periodic y",
                (gas, vec![]),
                (&self.floor_box, vec![]),
                "static floor and lid",
            ),
        ]
    }

    /// The effects added to the box with a floor: gravity, a vibrating floor, its other kinds.
    fn floor_effects(&self) -> Vec<Effect<'_>> {
        let (floor_box, a, g) = (&self.floor_box, self.a, self.g);
        let freq = (g / a).sqrt() / 10.0;
        let gamma_amp = |gamma: f64| Drive::of_gamma(gamma, freq, g).amplitude;
        let gravity = vec![format!("gravity={g:e}")];
        let vib = vec![
            format!("gravity={g:e}"),
            format!("floor.amplitude={:e}", gamma_amp(3.0)),
            format!("floor.frequency={freq:e}"),
        ];
        let vib_and = |more: &str| [vib.clone(), sets(&[more])].concat();
        vec![
            Effect::on(
                "gravity",
                floor_box,
                vec![],
                gravity.clone(),
                &format!("g = {}", super::fmt_g(g)),
            ),
            Effect::on(
                "floor kind: vibrating sine",
                floor_box,
                gravity,
                vib.clone(),
                "sine floor, Γ = 3",
            ),
            Effect::on(
                "floor kind: triangle vs sine",
                floor_box,
                vib.clone(),
                vib_and("floor.waveform=triangle"),
                "triangle wave",
            ),
            Effect::on(
                "floor kind: fixed-position",
                floor_box,
                vib.clone(),
                vib_and("floor.model=fixed-position"),
                "fixed-position model",
            ),
        ]
    }
}

/// Owned copies of `--set` overrides.
fn sets(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

/// The friction effect on `scenario`: the overrides of the scene without friction, those of
/// the scene with it, and the friction in words. A rough scenario is the scene with friction,
/// and without it every rough field is removed; a smooth one is the scene without, and gets
/// the friction of `scenarios/rough_vibrated_bed.json`: μ = 0.5 and β = 0.4 at pairs, μ = 0.5
/// at the floor and the walls (where the scene has them), spins started at the translational
/// temperature.
fn friction(scenario: &Scenario) -> (Vec<String>, Vec<String>, String) {
    // A floor with an orifice stays smooth: its corners are (rough disks fall through it).
    let floor = scenario.floor.as_ref().is_some_and(|f| f.orifice.is_none());
    let walls = scenario.domain.x_boundary == XBoundary::Walls
        || scenario.domain.y_boundary == YBoundary::Lid;
    if scenario.is_rough() {
        let mut fields = vec![
            "collisions.friction",
            "collisions.tangential_restitution",
            "domain.wall_friction",
            "domain.wall_tangential_restitution",
            "particles.inertia_factor",
            "particles.rotational_temperature",
        ];
        if floor {
            fields.extend(["floor.friction", "floor.tangential_restitution"]);
        }
        let smooth = fields.iter().map(|f| format!("{f}=null")).collect();
        return (smooth, vec![], "the scenario's friction".into());
    }
    let mut rough = sets(&[
        "collisions.friction=0.5",
        "collisions.tangential_restitution=0.4",
    ]);
    let mut added = String::from("μ = 0.5, β = 0.4");
    let at: Vec<&str> = [(floor, "floor"), (walls, "walls")]
        .into_iter()
        .filter_map(|(has, name)| has.then_some(name))
        .collect();
    if floor {
        rough.push("floor.friction=0.5".into());
    }
    if walls {
        rough.push("domain.wall_friction=0.5".into());
    }
    if !at.is_empty() {
        added += &format!("; {} μ = 0.5", at.join(", "));
    }
    rough.push(format!(
        "particles.rotational_temperature={}",
        scenario.particles.temperature
    ));
    (vec![], rough, added)
}

/// One effect: the scene without it and the scene with it (each a base scene and its
/// overrides), and what is added, in words.
struct Effect<'a> {
    name: &'static str,
    without: (&'a Value, Vec<String>),
    with: (&'a Value, Vec<String>),
    added: String,
    /// The scene with the effect records frames.
    record: bool,
    /// The row also gives what the effect changes in the observables.
    observe: bool,
}

impl<'a> Effect<'a> {
    /// An effect added to one base scene.
    fn on(
        name: &'static str,
        base: &'a Value,
        without: Vec<String>,
        with: Vec<String>,
        added: &str,
    ) -> Effect<'a> {
        Effect::between(name, (base, without), (base, with), added)
    }

    /// An effect that changes the base scene too.
    fn between(
        name: &'static str,
        without: (&'a Value, Vec<String>),
        with: (&'a Value, Vec<String>),
        added: &str,
    ) -> Effect<'a> {
        Effect {
            name,
            without,
            with,
            added: added.into(),
            record: false,
            observe: false,
        }
    }

    /// The least wall seconds per collision (`[k][0]`) and per unit time (`[k][1]`) over `reps`
    /// repetitions, without (`k = 0`) and with (`k = 1`) the effect, and what the runs measured
    /// (the same each time: a run is deterministic). A failed run leaves its entries at infinity
    /// and says why in the note; a scene that does not build is an error.
    fn time(&self, reps: usize, out: &Path) -> Result<Timed> {
        let mut t = Timed {
            best: [[f64::INFINITY; 2]; 2],
            note: String::new(),
            measured: [None, None],
        };
        for _ in 0..reps {
            for (k, (base, sets)) in [&self.without, &self.with].into_iter().enumerate() {
                let sc = with_sets(base, sets)?;
                let rrd = (self.record && k == 1).then(|| out.join("effects-recording.rrd"));
                match time_run(&sc, rrd) {
                    Ok((times, measured)) => {
                        t.best[k][0] = t.best[k][0].min(times[0]);
                        t.best[k][1] = t.best[k][1].min(times[1]);
                        t.measured[k] = Some(measured);
                    }
                    Err(e) => t.note = format!("failed: {e}"),
                }
            }
        }
        Ok(t)
    }

    /// The effect's row, from its best times (and, for an effect that observes, what it
    /// changed).
    fn row(self, timed: Timed) -> EffectRow {
        let Timed {
            best,
            note,
            measured,
        } = timed;
        let changes = match measured {
            [Some(without), Some(with)] if self.observe => {
                let one = |m: Measured| Ensemble { runs: vec![m] };
                Some(one(with).changes_from(&one(without)))
            }
            _ => None,
        };
        let (base, without) = self.without;
        EffectRow {
            effect: self.name.into(),
            without: format!(
                "{} {}",
                base["name"].as_str().unwrap_or(""),
                without.join(" ")
            )
            .trim()
            .to_string(),
            with: self.added,
            per_collision: [best[0][0], best[1][0]],
            per_time: [best[0][1], best[1][1]],
            slowdown_per_collision: best[1][0] / best[0][0],
            slowdown_per_time: best[1][1] / best[0][1],
            changes,
            note,
        }
    }
}

/// What the runs of an effect gave: the least times (see [`Effect::time`]), a note, and what
/// the runs without and with the effect measured.
struct Timed {
    best: [[f64; 2]; 2],
    note: String,
    measured: [Option<Measured>; 2],
}

/// Runs a scene (recording into `rrd`, removed afterwards) and gives its wall seconds per
/// collision and per unit of simulated time, and what it measured.
fn time_run(sc: &Scenario, rrd: Option<PathBuf>) -> Result<([f64; 2], Measured)> {
    let result = run(
        sc,
        RunOptions {
            rrd: rrd.clone(),
            interrupt: Some(crate::platform::signals::stop_flag()),
            ..Default::default()
        },
    );
    if let Some(p) = rrd {
        let _ = std::fs::remove_file(p);
    }
    let sum = result?;
    if sum.ending == Ending::Interrupted {
        return Err(Error::Runtime(format!(
            "interrupted at t = {:.4}",
            sum.sim_time
        )));
    }
    let coll = sum.events.collisions().max(1) as f64;
    let times = [sum.wall_seconds / coll, sum.wall_seconds / sum.sim_time];
    Ok((times, Measured::of(&sum, sc.floor.is_some())))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The silo's floor has an orifice, which needs a smooth floor: the friction effect makes
    /// its disks and walls rough and leaves the floor smooth (it once set floor.friction, and
    /// the report failed on a field the user never set).
    #[test]
    fn friction_leaves_a_floor_with_an_orifice_smooth() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/silo.json");
        let silo = Scenario::load(&path, &[]).expect("the silo is valid");
        let (_, rough, added) = friction(&silo);
        assert!(!rough.iter().any(|s| s.starts_with("floor.")), "{rough:?}");
        assert_eq!(added, "μ = 0.5, β = 0.4; walls μ = 0.5");
        let text = std::fs::read_to_string(&path).expect("the silo's text");
        Scenario::from_json_with_overrides(&text, &rough).expect("the rough silo is valid");
    }
}
