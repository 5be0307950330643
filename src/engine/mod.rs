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
//! - [`event`](event.rs): every kind of event, and the code it is filed under;
//! - `predict`: each disk's earliest event, asked of each event source and filed in the queue;
//! - `fire`: the event that is due, handed to its source;
//! - the event sources, each with its prediction and its firing side by side: `pair`
//!   (pair collisions), [`walls`](walls.rs) (side walls and lid), [`floor`](floor.rs) (impacts,
//!   ride ends, lost supports), and the shells of the local re-mapping ([`remap::shells`]);
//! - [`remap`]: re-mapping when the DUTC deadline comes ([`remap::dutc`]), the local
//!   re-mapping ([`remap::shells`]: each disk rebuilds its own list when it leaves its shell)
//!   and the renumbering of disks along a space-filling curve ([`remap::numbering`]);
//! - `motion`: where a disk is at a time (lazy flight, riding the floor);
//! - `images`: the periodic images, and which candidate neighbours lie within reach of a disk
//!   across them (shared by the pair search's kernel and the shells);
//! - [`rest`]: disks at rest on the floor or on disks at rest, and the rules that end bursts
//!   of events at one instant;
//! - `clock`, `counts`, `log`, `observe`: the clock, what is counted, the collision log, and
//!   what callers can see.

mod clock;
mod counts;
mod event;
mod fire;
mod floor;
mod images;
mod log;
mod motion;
mod observe;
mod outlet;
mod pair;
mod parts;
pub mod placement;
pub mod pool;
mod predict;
pub mod published_clock;
pub mod remap;
pub mod rest;
mod rough;
pub mod scene;
mod setup;
mod stall;
mod state;
mod walls;

pub use counts::{EnergyFlow, EventCounts, JamCounts};
pub use event::Event;
pub use log::{Collision, Partner};
pub use observe::Snapshot;
pub use scene::Scene;
pub use state::EngineState;

use crate::error::{Error, Result};
use crate::physics::disks::Disks;
use crate::physics::flight::Flight;
use crate::physics::restitution::CollisionLaw;
use crate::platform::prefetch::prefetch;
use clock::Epoch;
use parts::{Bounds, Control, Events, Mapping, Rest, Tally};
use std::sync::atomic::Ordering;

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
    /// Simulated time stopped advancing (see [`stall`](stall.rs)): the report is in
    /// [`Simulation::stall_report`].
    Stalled,
}

/// The exact event-driven engine, generic over free flight (straight or under gravity). Its
/// state is in parts named for what they hold ([`parts`](parts.rs)): a method's borrows show
/// what it touches.
#[derive(Debug)]
pub struct Simulation<F: Flight> {
    flight: F,
    disks: Disks,
    /// The local clock: absolute time is `base + now`.
    base: Epoch,
    now: f64,
    events: Events,
    map: Mapping,
    bounds: Bounds,
    /// The restitution law, with the cures' memory of each disk.
    restitution: CollisionLaw,
    /// The tangential laws of rough disks (`None`: smooth disks, no spins).
    friction: Option<crate::physics::rough::Roughness>,
    rest: Rest,
    tally: Tally,
    control: Control,
    /// Live and dead disks, in scenes whose disks leave (`None`: every disk stays).
    pool: Option<Box<pool::Pool>>,
}

impl<F: Flight> Simulation<F> {
    /// Runs events until absolute time `target` (events at exactly `target` are left for later).
    pub fn advance_to(&mut self, target: f64) -> Result<Progress> {
        let progress = if self.pool.is_some() {
            self.event_loop::<true>(target)
        } else {
            self.event_loop::<false>(target)
        };
        self.refresh_pool();
        progress
    }

    /// Processes the next `k` turns of the event loop (events, re-mappings, entries through
    /// inlets), whatever their times: for benchmarks, which measure throughput rather than
    /// reach a time.
    pub fn step_events(&mut self, k: u64) -> Result<()> {
        let stepped = if self.pool.is_some() {
            self.steps::<true>(k)
        } else {
            self.steps::<false>(k)
        };
        self.refresh_pool();
        stepped
    }

    /// The live disks' view, after disks entered or left (a scene with a pool).
    fn refresh_pool(&mut self) {
        if let Some(pool) = self.pool.as_mut() {
            pool.refresh();
        }
    }

    /// The event loop of [`advance_to`](Self::advance_to), with its guards: the event budget,
    /// the interrupt and the stall (see [`stall`](stall.rs)).
    fn event_loop<const POOL: bool>(&mut self, target: f64) -> Result<Progress> {
        // Loop turns (events and re-mappings alike): the interrupt is looked at every 1024 and
        // at the start, so that a run stops within a bounded wall time whatever it is doing;
        // the clock is published as often (see `published_clock`).
        let mut turns = 0u32;
        loop {
            let local_target = self.base.local(target);
            if self.tally.counts.guarded() >= self.control.event_limit {
                return Ok(Progress::EventLimit);
            }
            if turns & 0x3ff == 0 {
                if self.interrupted() {
                    return Ok(Progress::Interrupted);
                }
                if let Some(report) = self.stalled()? {
                    self.control.stall_report = Some(report);
                    return Ok(Progress::Stalled);
                }
                let (t0, done) = self.control.published_origin;
                let collisions = done + self.tally.counts.collisions();
                published_clock::publish_installed(|| t0 + self.time(), collisions);
            }
            turns = turns.wrapping_add(1);
            if !self.turn::<POOL>(local_target)? {
                self.now = self.now.max(local_target);
                return Ok(Progress::Reached);
            }
        }
    }

    /// The loop of [`step_events`](Self::step_events): `k` turns, or fewer if nothing is left
    /// to happen.
    fn steps<const POOL: bool>(&mut self, k: u64) -> Result<()> {
        for _ in 0..k {
            if !self.turn::<POOL>(f64::INFINITY)? {
                break;
            }
        }
        Ok(())
    }

    /// One turn of the event loop: the re-mapping, the entry through an inlet (if `POOL`: ∞
    /// without inlets) or the event that comes first, if before `local_target`. `false` if
    /// none is.
    #[inline(always)]
    fn turn<const POOL: bool>(&mut self, local_target: f64) -> Result<bool> {
        let i = self.events.queue.min();
        self.prefetch_next();
        let te = self.events.time[i];
        let deadline = self.map.dutc.deadline;
        let wake = if POOL {
            deadline.min(self.control.entry)
        } else {
            deadline
        };
        if wake <= te && wake < local_target {
            self.now = wake;
            if POOL && wake != deadline {
                self.enter_due()?;
            } else {
                self.remap()?;
            }
            return Ok(true);
        }
        if te >= local_target {
            return Ok(false);
        }
        if self.control.check && te < self.now {
            return Err(Error::Runtime(format!(
                "event of disk {} at {} is before the present {}",
                self.map.numbering.id(i),
                self.base.absolute(te),
                self.base.absolute(self.now)
            )));
        }
        self.now = te;
        self.fire(i)?;
        Ok(true)
    }

    /// Hints the memory system at the states and events of the disks likely to come next.
    #[inline(always)]
    fn prefetch_next(&self) {
        if !self.control.prefetching {
            return;
        }
        if self.control.pipelining {
            if let Some(shells) = &self.map.shells {
                return self.prefetch_pipeline(self.events.queue.next_likely(), shells);
            }
        }
        // The next two events' entries; under the local re-mapping, the next event's
        // neighbours, from its list in its row (whose row was asked for at the event before):
        // the states its prediction reads.
        let likely = self.events.queue.next_likely();
        let likely = [likely[0], likely[1]];
        let local = self.map.shells.is_some();
        if let Some(k) = likely[0].filter(|_| local) {
            for &j in self.map.lists.of(k) {
                prefetch(&self.disks.motion, j as usize);
            }
        }
        // Under the global re-mapping, the next event's list and its partner's: the rows a
        // collision's predictions read first.
        if let Some(k) = likely[0].filter(|_| !local) {
            self.map.lists.prefetch_list(k);
            if let Some(&j) = self
                .events
                .code
                .get(k)
                .filter(|&&j| (j as usize) < self.disks.len())
            {
                self.map.lists.prefetch_list(j as usize);
                self.restitution.prefetch(j as usize);
            }
        }
        for k in likely.into_iter().flatten() {
            self.prefetch_entries(k);
        }
    }

    /// Hints at disk `k`'s state and event entries, its record of same-instant events and of
    /// its last collision (where the scene keeps them), and under the local re-mapping its
    /// anchor and list row.
    #[inline(always)]
    fn prefetch_entries(&self, k: usize) {
        prefetch(&self.disks.motion, k);
        prefetch(&self.events.time, k);
        prefetch(&self.events.code, k);
        prefetch(&self.events.counter, k);
        prefetch(&self.rest.same_instant, k);
        self.restitution.prefetch(k);
        if let Some(shells) = &self.map.shells {
            shells.prefetch(k);
            self.map.lists.prefetch_list(k);
        }
    }

    /// [`prefetch_next`](Self::prefetch_next) where the arrays outgrow the last-level cache
    /// (from [`PIPELINE_FROM`](crate::platform::prefetch::PIPELINE_FROM) disks, local re-mapping): a
    /// pipeline over the next three events, each stage reading only what the stage before asked
    /// for an event earlier — the third's own entries and list row; the second's neighbours
    /// (from its row) and its partner's state, counter, event time, queue entry, anchor and
    /// row; the next one's partner's neighbours and the neighbours of its queue entry (the next
    /// one's own neighbours were asked for as the second).
    #[inline(always)]
    fn prefetch_pipeline(&self, likely: [Option<usize>; 3], shells: &remap::shells::Shells) {
        let n = self.disks.len();
        let partner = |k: usize| Some(self.events.code[k] as usize).filter(|&j| j < n);
        if let Some(j) = likely[0].and_then(partner) {
            for &m in self.map.lists.of(j) {
                prefetch(&self.disks.motion, m as usize);
            }
            self.events.queue.prefetch_links(j);
        }
        if let Some(k) = likely[1] {
            for &m in self.map.lists.of(k) {
                prefetch(&self.disks.motion, m as usize);
            }
            if let Some(j) = partner(k) {
                prefetch(&self.disks.motion, j);
                prefetch(&self.disks.counter, j);
                prefetch(&self.events.time, j);
                self.events.queue.prefetch(j);
                shells.prefetch(j);
                self.map.lists.prefetch_list(j);
            } else if self.events.code[k] == event::code::SHELL {
                // A shell exit reads the cells around its anchor (the new one is in them or
                // next to them) and changes its neighbours' rows.
                let [x, y] = shells.anchor(k);
                let cell = self.map.geometry.cell_of(x, y);
                self.map
                    .cells
                    .prefetch_around(&self.map.geometry, &self.map.mask, cell);
                self.map.lists.prefetch_neighbours(k);
            }
        }
        if let Some(k) = likely[2] {
            self.prefetch_entries(k);
        }
    }

    /// `true` once the caller's interrupt flag is set.
    #[inline]
    fn interrupted(&self) -> bool {
        self.control
            .interrupt
            .is_some_and(|flag| flag.load(Ordering::Relaxed))
    }
}
