//! The event-driven engine (Isobe 1999): per-disk local minima in an event queue (a complete
//! binary tree or a calendar, `engine.queue`),
//! neighbour lists from the EEPGM grid, re-mapping by DUTC, lazy per-disk time stamps.
//!
//! The engine runs on a local clock that restarts at 0 at every mapping (all disks are brought
//! to the mapping time then), so event times never lose precision however long the run; the
//! absolute time is `base + now`. The floor's phase is re-based at the same moment.
//!
//! This file is the event loop; each step has a file of its own:
//! - [`setup`](setup.rs): grid, mask, initial checks, the first mapping;
//! - `predict`: each disk's earliest event, filed in the queue;
//! - `fire`: carrying out the event that is due (collision rules, bookkeeping);
//! - `remap` and [`dutc`]: re-mapping the grid when the DUTC deadline comes;
//! - [`shells`]: the local re-mapping (each disk rebuilds its own list when it leaves its
//!   shell);
//! - `motion`: where a disk is at a time (lazy flight, riding the floor);
//! - [`numbering`]: disks renumbered along a space-filling curve at re-mappings;
//! - [`riders`] and `resting`: disks at rest on the floor or on disks at rest;
//! - `clock`, `counts`, `log`, `observe`: the clock, what is counted, the collision log, and
//!   what callers can see.

mod clock;
mod counts;
pub mod dutc;
mod fire;
mod jams;
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
mod lanes;
mod log;
mod motion;
pub mod numbering;
mod observe;
mod predict;
mod remap;
mod resting;
pub mod riders;
pub mod scene;
mod setup;
pub mod shells;
mod state;

pub use counts::{EnergyFlow, EventCounts};
pub use log::{Collision, Partner};
pub use observe::Snapshot;
pub use scene::Scene;
pub use state::EngineState;

use crate::disks::Disks;
use crate::dynamics::Flight;
use crate::error::{Error, Result};
use crate::globals::{Cells, GridGeometry, Mask, NeighbourLists};
use crate::locals::floor::Floor;
use crate::locals::{SideBounds, Top};
use crate::prefetch::prefetch;
use crate::restitution::CollisionLaw;
use crate::scheduler::EventQueue;
use clock::Epoch;
use dutc::Dutc;
use riders::Riders;
use std::sync::atomic::{AtomicBool, Ordering};

/// Relative overlap (of the contact distance) beyond which the invariant check fails.
pub const OVERLAP_TOLERANCE: f64 = 1e-9;

/// Why [`Simulation::advance_to`] returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress {
    /// The target time was reached.
    Reached,
    /// The event budget ran out first.
    EventLimit,
    /// An interrupt was requested.
    Interrupted,
}

/// The exact event-driven engine, generic over free flight (straight or under gravity).
#[derive(Debug)]
pub struct Simulation<F: Flight> {
    flight: F,
    disks: Disks,
    ev_time: Vec<f64>,
    ev_partner: Vec<u32>,
    ev_counter: Vec<u32>,
    queue: EventQueue,
    geometry: GridGeometry,
    mask: Mask,
    cells: Cells,
    lists: NeighbourLists,
    sides: SideBounds,
    top: Top,
    /// The periodic images of `sides` and `top`, for minimum-image separations.
    images: motion::Images,
    floor: Option<Floor>,
    restitution: CollisionLaw,
    margin: f64,
    base: Epoch,
    now: f64,
    dutc: Dutc,
    /// The local re-mapping's anchors (`engine.remap = "local"`); `None` for Isobe's global one.
    shells: Option<shells::Shells>,
    /// The engine's numbering of the disks against the scenario's (`engine.renumber`).
    numbering: numbering::Numbering,
    counts: EventCounts,
    flow: EnergyFlow,
    virial: f64,
    max_overlap: f64,
    check: bool,
    event_limit: u64,
    interrupt: Option<&'static AtomicBool>,
    log: Option<Vec<Collision>>,
    /// Disks at rest on (riding) the floor or on resting disks; empty without a floor.
    riders: Riders,
    /// Disks resting on disks that rest move with the floor (`collisions.resting_contacts`).
    resting_contacts: bool,
    /// Scratch of the release cascade: the stack, and the disks one support carried.
    releasing: Vec<u32>,
    carried: Vec<u32>,
    /// Scratch of the settling of clusters: the candidates, and who is one.
    cluster: Vec<u32>,
    in_cluster: Vec<bool>,
    /// Per disk: the first event of its latest burst at one instant and how many it has had
    /// since (scenes with a floor and resting contacts; see `stop_zeno`).
    same_instant: Vec<(f64, u32)>,
    /// Events of disk i within `√(zeno_instant2 · a_i)` of the first of a burst count as at one
    /// instant for `same_instant`: the square of `jams::INSTANT` time units per unit radius.
    zeno_instant2: f64,
    /// The event loop prefetches what it will read (from
    /// [`PREFETCH_FROM`](crate::prefetch::PREFETCH_FROM) disks on).
    prefetching: bool,
    /// The prefetching runs as a pipeline over the next three events, the calendar keeping
    /// them ahead (under the local re-mapping from
    /// [`PIPELINE_FROM`](crate::prefetch::PIPELINE_FROM) disks on; the calendar alone under the
    /// global one from [`KEEP_AHEAD_FROM`](crate::prefetch::KEEP_AHEAD_FROM)).
    pipelining: bool,
}

impl<F: Flight> Simulation<F> {
    /// Runs events until absolute time `target` (events at exactly `target` are left for later).
    pub fn advance_to(&mut self, target: f64) -> Result<Progress> {
        // Loop turns (events and re-mappings alike): the interrupt is looked at every 1024 and
        // at the start, so that a run stops within a bounded wall time whatever it is doing.
        let mut turns = 0u32;
        loop {
            let local_target = self.base.local(target);
            if self.counts.guarded() >= self.event_limit {
                return Ok(Progress::EventLimit);
            }
            if turns & 0x3ff == 0 && self.interrupted() {
                return Ok(Progress::Interrupted);
            }
            turns = turns.wrapping_add(1);
            let i = self.queue.min();
            self.prefetch_next();
            let te = self.ev_time[i];
            let deadline = self.dutc.deadline;
            if deadline <= te && deadline < local_target {
                self.now = deadline;
                self.remap()?;
                continue;
            }
            if te >= local_target {
                self.now = self.now.max(local_target);
                return Ok(Progress::Reached);
            }
            if self.check && te < self.now {
                return Err(Error::Runtime(format!(
                    "event of disk {} at {} is before the present {}",
                    self.numbering.id(i),
                    self.base.absolute(te),
                    self.base.absolute(self.now)
                )));
            }
            self.now = te;
            self.fire(i)?;
        }
    }

    /// Hints the memory system at the states and events of the disks likely to come next.
    #[inline(always)]
    fn prefetch_next(&self) {
        if !self.prefetching {
            return;
        }
        if self.pipelining {
            if let Some(shells) = &self.shells {
                return self.prefetch_pipeline(self.queue.next_likely(), shells);
            }
        }
        // The next two events' entries; under the local re-mapping, the next event's
        // neighbours, from its list in its row (whose row was asked for at the event before):
        // the states its prediction reads.
        let likely = self.queue.next_likely();
        let likely = [likely[0], likely[1]];
        let local = self.shells.is_some();
        if let Some(k) = likely[0].filter(|_| local) {
            for &j in self.lists.of(k) {
                prefetch(&self.disks.motion, j as usize);
            }
        }
        for k in likely.into_iter().flatten() {
            self.prefetch_entries(k);
        }
    }

    /// Hints at disk `k`'s state and event entries (and under the local re-mapping its anchor
    /// and list row).
    #[inline(always)]
    fn prefetch_entries(&self, k: usize) {
        prefetch(&self.disks.motion, k);
        prefetch(&self.ev_time, k);
        prefetch(&self.ev_partner, k);
        prefetch(&self.ev_counter, k);
        if let Some(shells) = &self.shells {
            shells.prefetch(k);
            self.lists.prefetch_list(k);
        }
    }

    /// [`prefetch_next`](Self::prefetch_next) where the arrays outgrow the last-level cache
    /// (from [`PIPELINE_FROM`](crate::prefetch::PIPELINE_FROM) disks, local re-mapping): a
    /// pipeline over the next three events, each stage reading only what the stage before asked
    /// for an event earlier — the third's own entries and list row; the second's neighbours
    /// (from its row) and its partner's state, counter, event time, queue entry, anchor and
    /// row; the next one's partner's neighbours and the neighbours of its queue entry (the next
    /// one's own neighbours were asked for as the second).
    #[inline(always)]
    fn prefetch_pipeline(&self, likely: [Option<usize>; 3], shells: &shells::Shells) {
        let n = self.disks.len();
        let partner = |k: usize| Some(self.ev_partner[k] as usize).filter(|&j| j < n);
        if let Some(j) = likely[0].and_then(partner) {
            for &m in self.lists.of(j) {
                prefetch(&self.disks.motion, m as usize);
            }
            self.queue.prefetch_links(j);
        }
        if let Some(k) = likely[1] {
            for &m in self.lists.of(k) {
                prefetch(&self.disks.motion, m as usize);
            }
            if let Some(j) = partner(k) {
                prefetch(&self.disks.motion, j);
                prefetch(&self.disks.counter, j);
                prefetch(&self.ev_time, j);
                self.queue.prefetch(j);
                shells.prefetch(j);
                self.lists.prefetch_list(j);
            } else if self.ev_partner[k] == predict::partner::SHELL {
                // A shell exit reads the cells around its anchor (the new one is in them or
                // next to them) and changes its neighbours' rows.
                let [x, y] = shells.anchor(k);
                let cell = self.geometry.cell_of(x, y);
                self.cells.prefetch_around(&self.geometry, &self.mask, cell);
                self.lists.prefetch_neighbours(k);
            }
        }
        if let Some(k) = likely[2] {
            self.prefetch_entries(k);
        }
    }

    /// `true` once the caller's interrupt flag is set.
    #[inline]
    fn interrupted(&self) -> bool {
        self.interrupt
            .is_some_and(|flag| flag.load(Ordering::Relaxed))
    }

    /// Processes the next `k` events (collisions, stale events, re-mappings), whatever their
    /// times: for benchmarks, which measure throughput rather than reach a time (with the
    /// same hints to the memory system as [`advance_to`](Self::advance_to)).
    pub fn step_events(&mut self, k: u64) -> Result<()> {
        for _ in 0..k {
            let i = self.queue.min();
            self.prefetch_next();
            let te = self.ev_time[i];
            if self.dutc.deadline <= te {
                self.now = self.dutc.deadline;
                self.remap()?;
                continue;
            }
            if te == f64::INFINITY {
                return Ok(());
            }
            self.now = te;
            self.fire(i)?;
        }
        Ok(())
    }
}
