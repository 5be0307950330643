//! The engine's complete mutable state, for checkpoints: everything an event boundary holds that
//! the scene does not fix (disks, pending predictions, the event queue, the grid and neighbour
//! lists, the clock, the floor's phase, the cures' memory, who rests on what, the counts).
//!
//! What the scene fixes (flight law, grid geometry, mask, boundaries, list margin, switches) is
//! rebuilt from the scenario; [`Simulation::restore`] then overwrites the rest, so the resumed
//! engine pops the same events in the same order as the one that was saved, bit for bit.

use super::clock::Epoch;
use super::counts::{EnergyFlow, EventCounts};
use super::remap::dutc::Dutc;
use super::remap::numbering::Numbering;
use super::remap::shells::Shells;
use super::rest::riders::Riders;
use super::Simulation;
use crate::error::{Error, Result};
use crate::neighbours::{Cells, NeighbourLists};
use crate::physics::disks::Disks;
use crate::physics::flight::Flight;
use crate::physics::restitution::CollisionLaw;
use crate::scheduler::EventQueue;
use serde::{Deserialize, Serialize};

/// The event-driven engine's mutable state at an event boundary.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EngineState {
    disks: Disks,
    ev_time: Vec<f64>,
    ev_partner: Vec<u32>,
    ev_counter: Vec<u32>,
    queue: EventQueue,
    cells: Cells,
    lists: NeighbourLists,
    restitution: CollisionLaw,
    floor_phase: Option<f64>,
    base: Epoch,
    now: f64,
    dutc: Dutc,
    #[serde(default)]
    shells: Option<Shells>,
    counts: EventCounts,
    flow: EnergyFlow,
    virial: f64,
    max_overlap: f64,
    riders: Riders,
    same_instant: Vec<(f64, u32)>,
    numbering: Numbering,
    /// Live and dead disks (scenes whose disks leave).
    pool: Option<Box<super::pool::Pool>>,
}

impl EngineState {
    /// Number of disks.
    pub fn len(&self) -> usize {
        self.disks.len()
    }

    /// `true` without disks.
    pub fn is_empty(&self) -> bool {
        self.disks.len() == 0
    }
}

impl<F: Flight> Simulation<F> {
    /// The engine's state now (between events), for a checkpoint.
    pub fn state(&self) -> EngineState {
        EngineState {
            disks: self.disks.clone(),
            ev_time: self.events.time.clone(),
            ev_partner: self.events.code.clone(),
            ev_counter: self.events.counter.clone(),
            queue: self.events.queue.clone(),
            cells: self.map.cells.clone(),
            lists: self.map.lists.clone(),
            restitution: self.restitution.clone(),
            floor_phase: self.bounds.floor.as_ref().map(|f| f.phase_origin()),
            base: self.base,
            now: self.now,
            dutc: self.map.dutc,
            shells: self.map.shells.clone(),
            counts: self.tally.counts,
            flow: self.tally.flow,
            virial: self.tally.virial,
            max_overlap: self.tally.max_overlap,
            riders: self.rest.riders.clone(),
            same_instant: self.rest.same_instant.clone(),
            numbering: self.map.numbering.clone(),
            pool: self.pool.clone(),
        }
    }

    /// Puts a saved state into an engine built for the same scene. Refuses a state whose shape
    /// does not fit the scene (another number of disks, a floor where there is none, a grid of
    /// another kind), so that a mismatched checkpoint is an error, not a panic later.
    pub fn restore(&mut self, state: EngineState) -> Result<()> {
        // Where disks leave, the saved engine holds the disks live then.
        let n = match (&self.pool, &state.pool) {
            (Some(_), Some(saved))
                if saved.fits(state.disks.len(), state.numbering.ids().unwrap_or(&[])) =>
            {
                state.disks.len()
            }
            (None, None) => self.disks.len(),
            _ => usize::MAX,
        };
        let mismatch = |what: &str| {
            Error::input(
                "checkpoint",
                format!("the saved engine does not fit this scene ({what})"),
            )
        };
        let d = &state.disks;
        if d.len() != n
            || d.radius.len() != n
            || d.mass.len() != n
            || d.species.len() != n
            || d.counter.len() != n
        {
            return Err(mismatch("number of disks"));
        }
        if d.spins.as_ref().map(|s| s.omega.len()) != self.disks.spins.as_ref().map(|_| n) {
            return Err(mismatch("rough disks"));
        }
        if state.ev_time.len() != n + 1
            || state.ev_partner.len() != n
            || state.ev_counter.len() != n
            || !state.queue.fits(&state.ev_time)
        {
            return Err(mismatch("event tables"));
        }
        if state.queue.kind() != self.events.queue.kind() {
            return Err(mismatch("event queue"));
        }
        if state.floor_phase.is_some() != self.bounds.floor.is_some() {
            return Err(mismatch("floor"));
        }
        if std::mem::discriminant(&state.cells) != std::mem::discriminant(&self.map.cells) {
            return Err(mismatch("grid kind"));
        }
        if state.shells.as_ref().map(|s| s.len()) != self.map.shells.as_ref().map(|_| n) {
            return Err(mismatch("re-mapping"));
        }
        let per_disk = |v: usize| if v == 0 { 0 } else { n };
        if state.riders.len() != per_disk(self.rest.riders.len()) {
            return Err(mismatch("riders"));
        }
        if state.same_instant.len() != per_disk(self.rest.same_instant.len()) {
            return Err(mismatch("riders"));
        }
        if state.numbering.on != self.map.numbering.on {
            return Err(mismatch("engine.renumber"));
        }
        self.disks = state.disks;
        self.events.time = state.ev_time;
        self.events.code = state.ev_partner;
        self.events.counter = state.ev_counter;
        self.events.queue = state.queue;
        self.map.cells = state.cells;
        self.map.lists = state.lists;
        self.restitution = state.restitution;
        if let (Some(floor), Some(phase)) = (self.bounds.floor.as_mut(), state.floor_phase) {
            floor.set_phase_origin(phase);
        }
        self.base = state.base;
        self.now = state.now;
        self.map.dutc = state.dutc;
        self.map.shells = state.shells;
        self.tally.counts = state.counts;
        self.tally.flow = state.flow;
        self.tally.virial = state.virial;
        self.tally.max_overlap = state.max_overlap;
        self.rest.riders = state.riders;
        self.rest.riders.recount();
        self.rest.same_instant = state.same_instant;
        self.map.numbering = state.numbering;
        self.pool = state.pool;
        if let Some(pool) = self.pool.as_mut() {
            pool.restored();
        }
        self.schedule_entry();
        Ok(())
    }
}
