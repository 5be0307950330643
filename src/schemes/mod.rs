//! Integration schemes behind `engine.scheme`. The exact event-driven engine
//! ([`Simulation`]) is the product's core; the two approximate schemes here are what a user would
//! otherwise reach for, run on the same scene so that vibrobed can show what accuracy costs:
//!
//! - [`time_step::TimeStep`]: one global step dt; overlaps found after each step with a cell list
//!   feeding a Verlet list (neighbour-list tutorial; ReMoDy's standard scheme), resolved when found;
//! - [`space_time::SpaceTime`]: per-disk times, each disk moved straight to its next predicted
//!   collision, candidates from linked cells, never past a global synchronisation time (ReMoDy's
//!   space-time scheme).
//!
//! All three share the scene (boundaries, floor, collision law), the flight law, the pair
//! formulas, and — through [`Integrator`] — the driver that samples, measures, records and
//! summarises (`run::drive`).

pub mod cells;
pub mod contact;
pub mod cores;
pub mod handover;
mod rough;
pub mod space_time;
pub mod time_step;

use crate::engine::{EnergyFlow, EngineState, EventCounts, Progress, Simulation, Snapshot};
use crate::error::{Error, Result};
use crate::physics::disks::Disks;
use crate::physics::flight::Flight;
use crate::physics::walls::{into_period, nearest_image, SideBounds, Top};
use serde::{Deserialize, Serialize};
use std::sync::atomic::AtomicBool;

/// A checkpoint's engine: the exact engine's state, or the hybrid scheme's.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub enum SavedState {
    /// `event-driven`.
    Exact(Box<EngineState>),
    /// `hybrid`.
    Hybrid(Box<handover::HandoverState>),
}

impl SavedState {
    /// A checkpoint of scheme `saved` resumed on a scene of another.
    fn other_scheme(saved: &str) -> Error {
        Error::input(
            "engine.scheme",
            format!(
                "the checkpoint was written by the {saved} scheme, and this scene runs another"
            ),
        )
    }
}

/// How the engine was set up, for the summary (`engine` there, less the sample count).
#[derive(Debug, Clone, PartialEq)]
pub struct Setup {
    /// `event-driven`, `time-step` or `space-time`.
    pub scheme: &'static str,
    /// Neighbour search: Isobe's mask name, or the approximate scheme's lists.
    pub mask: String,
    /// Cell side.
    pub cell: f64,
    /// Cell storage.
    pub grid: String,
    /// The exact engine's event queue (`calendar` or `tree`); `None` for the approximate schemes.
    pub queue: Option<&'static str>,
    /// The exact engine's re-mapping (`global` or `local`); `None` for the approximate schemes.
    pub remap: Option<&'static str>,
    /// Bytes held by the engine.
    pub bytes: usize,
    /// Threads an approximate scheme runs on (`None`: the exact engine, on one core).
    pub threads: Option<usize>,
}

/// What an approximate scheme did wrong, and how it stepped (the summary's `approximation`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct SchemeStats {
    /// `time-step`: the step dt; `space-time`: the mean synchronisation step; `contact` and
    /// `hybrid`: contact dynamics' mean step.
    pub step: f64,
    /// Global steps (time-step) or synchronisations (space-time) taken.
    pub steps: u64,
    /// Pair collisions resolved while the disks overlapped (by more than 10⁻⁹ of the contact
    /// distance): in the time-step scheme every collision; in the space-time scheme the late ones.
    pub overlapped_collisions: u64,
    /// Overlaps deeper than 10 % of the contact distance (a tenth of a diameter for equal disks)
    /// seen at a detection.
    pub deep_overlaps: u64,
    /// Collisions the scheme never processed. Time-step: pairs whose paths touched during a step
    /// but which no longer overlap at its end (passed through or grazed). Space-time: pairs found
    /// overlapping at a synchronisation that were not overlapping at the previous one (they met
    /// while not candidates of each other; pairs that fully passed through each other between
    /// two synchronisations go unseen, so this is a lower bound).
    pub missed: u64,
    /// Deepest penetration of a disk into a wall, the lid or the floor.
    pub max_boundary_penetration: f64,
    /// `contact`: Gauss–Seidel sweeps over the contacts, all steps together.
    #[serde(skip_serializing_if = "is_zero")]
    pub sweeps: u64,
    /// `contact`: contacts that rebounded by Newton's law (impacts faster than the rest speed),
    /// all steps together.
    #[serde(skip_serializing_if = "is_zero", default)]
    pub rebounds: u64,
    /// `hybrid`: hand-overs between the exact engine and contact dynamics.
    #[serde(skip_serializing_if = "is_zero")]
    pub handovers: u64,
    /// `hybrid`: simulated time spent in contact dynamics.
    #[serde(skip_serializing_if = "is_nought")]
    pub dense_time: f64,
}

fn is_nought(x: &f64) -> bool {
    *x == 0.0
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

/// What the driver needs from an engine: advance to exact times, observe without disturbing,
/// and report counts, energy flows and set-up. Implemented by the exact engine and by both
/// approximate schemes, so that measurement, recording and the summary are shared.
pub trait Integrator {
    /// Stop [`advance_to`](Self::advance_to) at the next opportunity once `flag` is set.
    fn set_interrupt(&mut self, flag: &'static AtomicBool);
    /// The disks (radii, masses, species; states at the engine's own time stamps).
    fn disks(&self) -> &Disks;
    /// Current absolute time.
    fn time(&self) -> f64;
    /// Runs until absolute time `target`.
    fn advance_to(&mut self, target: f64) -> Result<Progress>;
    /// Whether the engine runs on threads of its own ([`advance_beside`](Self::advance_beside)
    /// then does other work on them).
    fn has_threads(&self) -> bool {
        false
    }
    /// Runs until `target` as [`advance_to`](Self::advance_to) does, with `beside` done on the
    /// engine's threads meanwhile (by default first, on this thread).
    fn advance_beside(&mut self, target: f64, beside: impl FnOnce() + Send) -> Result<Progress> {
        beside();
        self.advance_to(target)
    }
    /// Calls `visit(i, [x, y, vx, vy])` with every disk's state at absolute time `t ≥ time()`
    /// (`i` in the scenario's numbering, in any order; positions wrapped into a periodic box).
    fn visit_states(&self, t: f64, visit: impl FnMut(usize, [f64; 4]));
    /// The floor's height at absolute time `t` (`None` without a floor).
    fn floor_height_at(&self, t: f64) -> Option<f64>;
    /// Every disk's state at absolute time `t ≥ time()`, in the scenario's numbering.
    fn snapshot_into(&self, t: f64, out: &mut Snapshot) {
        out.start(self.disks().len(), t, self.floor_height_at(t));
        self.visit_states(t, |i, state| out.set(i, state));
    }
    /// `Σ ½ I ω²` of rough disks at absolute time `t ≥ time()` (by default the spins now: the
    /// approximate schemes' spins are constant between steps); `None` for smooth disks.
    fn rotational_energy(&self, _t: f64) -> Option<f64> {
        self.disks().spins.as_ref()?;
        Some(self.disks().rotational_energy())
    }
    /// Each rough disk's `(angle, ω)` at absolute time `t ≥ time()`, in the scenario's
    /// numbering; `None` for smooth disks. (By default the spins' own clock and numbering, the
    /// approximate schemes'; the exact engine, which re-bases its clock and renumbers its disks,
    /// says its own.)
    fn spins_at(&self, t: f64) -> Option<Vec<(f64, f64)>> {
        self.disks().spins.as_ref().map(|s| s.at(t))
    }
    /// `q` in `I = q m a²` of rough disks; `None` for smooth disks.
    fn inertia_factor(&self) -> Option<f64> {
        self.disks().spins.as_ref().map(|s| s.q)
    }
    /// Event counts so far.
    fn counts(&self) -> EventCounts;
    /// Disks in and out, in scenes whose disks leave (`None`: every disk stays).
    fn flow(&self) -> Option<crate::engine::pool::Flow> {
        None
    }
    /// Energy injected and dissipated up to absolute time `t`.
    fn energy_flow_at(&self, t: f64) -> EnergyFlow;
    /// Collision virial so far.
    fn virial(&self) -> f64;
    /// Largest pair overlap seen.
    fn max_overlap(&self) -> f64;
    /// The invariant check at absolute time `t ≥ time()` (no overlap beyond tolerance for the
    /// exact engine; the approximate schemes overlap by design and report it instead).
    fn check_state(&self, t: f64) -> Result<()>;
    /// Why simulated time stopped advancing, after [`Progress::Stalled`].
    fn stall_report(&self) -> Option<&str> {
        None
    }
    /// How the engine is set up.
    fn setup(&self) -> Setup;
    /// Errors and steps of an approximate scheme (`None` for the exact engine).
    fn approximation(&self) -> Option<SchemeStats>;
    /// Number of disks at rest now (riding the floor or resting on disks at rest, resting
    /// contacts); the approximate schemes have no rest and report 0.
    fn disks_at_rest(&self) -> usize {
        0
    }
    /// The time the last disk came to rest while every disk is at rest, exact to the event
    /// (`None`: a disk moves, or the scheme has no rest).
    fn at_rest_since(&self) -> Option<f64> {
        None
    }
    /// Disks released from a bed all at rest by the rest rules or a collision.
    fn rest_wakes(&self) -> u64 {
        0
    }
    /// The engine's complete state between events, for a checkpoint (`None`: this scheme has
    /// none; the exact engine and the hybrid scheme can be checkpointed).
    fn saved_state(&self) -> Option<SavedState> {
        None
    }
    /// Puts a checkpoint's state back into an engine built for the same scene.
    fn restore_state(&mut self, _state: SavedState) -> Result<()> {
        Err(Error::input(
            "engine.scheme",
            "only the event-driven and hybrid schemes can be checkpointed and resumed",
        ))
    }
}

impl<F: Flight> Integrator for Simulation<F> {
    fn set_interrupt(&mut self, flag: &'static AtomicBool) {
        Simulation::set_interrupt(self, flag)
    }
    fn disks(&self) -> &Disks {
        Simulation::disks(self)
    }
    fn time(&self) -> f64 {
        Simulation::time(self)
    }
    fn advance_to(&mut self, target: f64) -> Result<Progress> {
        Simulation::advance_to(self, target)
    }
    fn stall_report(&self) -> Option<&str> {
        Simulation::stall_report(self)
    }
    fn visit_states(&self, t: f64, visit: impl FnMut(usize, [f64; 4])) {
        Simulation::visit_states(self, t, visit)
    }
    fn snapshot_into(&self, t: f64, out: &mut Snapshot) {
        Simulation::snapshot_into(self, t, out)
    }
    fn floor_height_at(&self, t: f64) -> Option<f64> {
        Simulation::floor_height_at(self, t)
    }
    fn counts(&self) -> EventCounts {
        Simulation::counts(self)
    }
    fn flow(&self) -> Option<crate::engine::pool::Flow> {
        self.pool().map(|p| p.flow)
    }
    fn rotational_energy(&self, t: f64) -> Option<f64> {
        Simulation::rotational_energy(self, t)
    }
    fn spins_at(&self, t: f64) -> Option<Vec<(f64, f64)>> {
        Simulation::spins_at(self, t)
    }
    fn inertia_factor(&self) -> Option<f64> {
        Simulation::inertia_factor(self)
    }
    fn energy_flow_at(&self, t: f64) -> EnergyFlow {
        Simulation::energy_flow_at(self, t)
    }
    fn virial(&self) -> f64 {
        Simulation::virial(self)
    }
    fn max_overlap(&self) -> f64 {
        Simulation::max_overlap(self)
    }
    fn disks_at_rest(&self) -> usize {
        self.riders()
    }
    fn at_rest_since(&self) -> Option<f64> {
        Simulation::at_rest_since(self)
    }
    fn rest_wakes(&self) -> u64 {
        Simulation::rest_wakes(self)
    }
    fn check_state(&self, t: f64) -> Result<()> {
        self.check_no_overlap(t)
    }
    fn setup(&self) -> Setup {
        let geometry = self.geometry();
        Setup {
            scheme: "event-driven",
            mask: self.mask().name.into(),
            cell: geometry.cell(),
            grid: self.grid_kind().into(),
            queue: Some(self.queue_kind()),
            remap: Some(self.remap_kind()),
            bytes: self.bytes(),
            threads: None,
        }
    }
    fn approximation(&self) -> Option<SchemeStats> {
        None
    }
    fn saved_state(&self) -> Option<SavedState> {
        Some(SavedState::Exact(Box::new(self.state())))
    }
    fn restore_state(&mut self, state: SavedState) -> Result<()> {
        match state {
            SavedState::Exact(state) => self.restore(*state),
            SavedState::Hybrid(_) => Err(SavedState::other_scheme("hybrid")),
        }
    }
}

/// Minimum-image separation for any separation (positions may have drifted by more than half a
/// period since they were last wrapped).
#[inline(always)]
pub(crate) fn min_image(sides: SideBounds, top: Top, mut dx: f64, mut dy: f64) -> (f64, f64) {
    if let SideBounds::Periodic { width } = sides {
        dx = nearest_image(dx, width);
    }
    if let Top::Periodic { height } = top {
        dy = nearest_image(dy, height);
    }
    (dx, dy)
}

/// A position wrapped into the periodic box.
#[inline(always)]
pub(crate) fn wrap(sides: SideBounds, top: Top, mut x: f64, mut y: f64) -> (f64, f64) {
    if let SideBounds::Periodic { width } = sides {
        x = into_period(x, width);
    }
    if let Top::Periodic { height } = top {
        y = into_period(y, height);
    }
    (x, y)
}

/// Wraps positions into the periodic box.
pub(crate) fn wrap_positions(sides: SideBounds, top: Top, disks: &mut Disks) {
    for m in &mut disks.motion {
        (m.x, m.y) = wrap(sides, top, m.x, m.y);
    }
}

/// Visits disks all stored at engine time `now`, flown freely to absolute time `t` (positions
/// wrapped into a periodic box), in their own order.
pub(crate) fn free_flight_visit<F: Flight>(
    flight: F,
    disks: &Disks,
    sides: SideBounds,
    top: Top,
    t: f64,
    mut visit: impl FnMut(usize, [f64; 4]),
) {
    for (i, m) in disks.motion.iter().enumerate() {
        let (x, y, vx, vy) = flight.advance(m.x, m.y, m.vx, m.vy, t - m.t);
        let (x, y) = wrap(sides, top, x, y);
        visit(i, [x, y, vx, vy]);
    }
}
