//! The engine's disks as the measurements read them: at one time on the fly, from a snapshot
//! taken at a stop, or copied to be measured while the engine runs on.

use super::averages::Averages;
use crate::engine::Snapshot;
use crate::measure::phase::FloorTally;
use crate::measure::States;
use crate::physics::disks::Disks;
use crate::schemes::Integrator;

/// The floor's impacts and the momentum it has given so far, at time `t`.
pub(super) fn floor_tally<E: Integrator>(sim: &E, t: f64) -> FloorTally {
    FloorTally {
        time: t,
        impacts: sim.counts().floor,
        impulse: sim.energy_flow_at(t).floor_impulse,
    }
}

/// Every disk's state at `now` into `snap`, once per stop (a frame and a trajectory frame at
/// the same stop share it).
pub(super) fn fill_snapshot<E: Integrator>(sim: &E, now: f64, snap: &mut Snapshot) {
    if !holds(snap, now) {
        sim.snapshot_into(now, snap);
    }
}

/// `true` when `snap` already holds the disks' states at `now`.
pub(super) fn holds(snap: &Snapshot, now: f64) -> bool {
    snap.time == now && !snap.x.is_empty()
}

/// The states of an engine's disks in a snapshot taken at one time, the spins read from the
/// engine: one pass over the engine's disks serves every measurement of a sample.
pub(super) struct Snapped<'a, E>(pub(super) &'a Snapshot, pub(super) &'a E);

impl<E: Integrator> States for Snapped<'_, E> {
    fn each(&self, f: impl FnMut(usize, [f64; 4])) {
        self.0.each(f)
    }
    fn rotational_energy(&self) -> Option<f64> {
        self.1.rotational_energy(self.0.time)
    }
    fn spins(&self) -> Option<(f64, Vec<(f64, f64)>)> {
        Some((self.1.inertia_factor()?, self.1.spins_at(self.0.time)?))
    }
}

/// A sample's states, copied at its stop with the spins read there, to be measured later.
pub(super) struct Taken {
    pub(super) snap: Snapshot,
    rotational: Option<f64>,
    spins: Option<(f64, Vec<(f64, f64)>)>,
}

impl Taken {
    /// The states in `snap` with the spins of `sim` at their time, copied into `spare`.
    pub(super) fn of<E: Integrator>(sim: &E, snap: &Snapshot, mut spare: Snapshot) -> Taken {
        spare.clone_from(snap);
        let states = Snapped(snap, sim);
        Taken {
            snap: spare,
            rotational: states.rotational_energy(),
            spins: states.spins(),
        }
    }

    /// Measures the sample into `averages` (`disks`: the radii and masses).
    pub(super) fn add_to(&self, averages: &mut Averages, disks: &Disks, g: f64) {
        averages.add(self, disks, g);
    }
}

impl States for Taken {
    fn each(&self, f: impl FnMut(usize, [f64; 4])) {
        self.snap.each(f)
    }
    fn rotational_energy(&self) -> Option<f64> {
        self.rotational
    }
    fn spins(&self) -> Option<(f64, Vec<(f64, f64)>)> {
        self.spins.clone()
    }
}

/// The states of an engine's disks at one time, read on the fly (no copy of every state).
pub(super) struct StatesAt<'e, E>(pub(super) &'e E, pub(super) f64);

impl<E: Integrator> States for StatesAt<'_, E> {
    fn each(&self, f: impl FnMut(usize, [f64; 4])) {
        self.0.visit_states(self.1, f)
    }
    fn rotational_energy(&self) -> Option<f64> {
        self.0.rotational_energy(self.1)
    }
    fn spins(&self) -> Option<(f64, Vec<(f64, f64)>)> {
        Some((self.0.inertia_factor()?, self.0.spins_at(self.1)?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::{Scene, Simulation};
    use crate::physics::flight::Ballistic;
    use crate::Scenario;

    /// A sample measured from a copy of the states and one measured from the engine itself
    /// (as from `ON_THE_FLY_FROM` disks on) give the same averages bit for bit: the shipped
    /// bed with every measurement a sample can take (profiles, the bed's state fields, the 2D
    /// fields, the velocities by band), its disks renumbered by the engine as a large scene's
    /// are (the visit then reads them out of the engine's order).
    #[test]
    fn a_copy_and_the_engine_measure_the_same() {
        let json = include_str!("../../scenarios/vibrated_bed.json")
            .replacen(
                "\"output\": {",
                "\"output\": {\"velocity_distribution\": true, ",
                1,
            )
            .replacen(
                "\"run\":",
                "\"engine\": {\"renumber\": \"on\"}, \"run\":",
                1,
            );
        let s = Scenario::from_json(&json).expect("the shipped bed is valid");
        let (scene, disks) = Scene::build(&s).expect("scene builds");
        let g = scene.gravity.expect("the bed has gravity");
        let mut sim = Simulation::new(Ballistic { g }, &scene, disks).expect("engine starts");
        let start = StatesAt(&sim, 0.0);
        let mut copied = Averages::new(&s, &scene, &start, sim.disks(), true);
        let mut on_the_fly = copied.clone();
        let mut snap = Snapshot::default();
        for t in [1.0, 2.5, 4.0] {
            sim.advance_to(t).expect("runs");
            fill_snapshot(&sim, t, &mut snap);
            copied.add(&Snapped(&snap, &sim), sim.disks(), g);
            on_the_fly.add(&StatesAt(&sim, t), sim.disks(), g);
        }
        assert!(copied.velocities.is_some() && copied.fields.is_some());
        assert!(sim.renumbered(), "the engine renumbered its disks");
        let json = |a: &Averages| serde_json::to_string(a).expect("averages serialize");
        assert!(
            json(&copied) == json(&on_the_fly),
            "a copy of the states and the engine's own give different averages"
        );
    }
}
