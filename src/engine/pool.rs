//! Pools of live and dead disks, for scenes whose disks leave (a floor orifice).
//!
//! The live disks are the engine's disks `0..n`; a disk that leaves swaps places with the last
//! live one and the arrays shrink by one (their memory is kept: capacity is fixed at the start,
//! so leaving allocates nothing). Every loop over the engine's disks therefore visits only the
//! live ones, and the grid, the neighbour lists, the shells and the event queue are rebuilt
//! over them by a whole re-mapping at the moment a disk leaves. Each disk keeps its scenario
//! number (its id) for the whole run; measurements and outputs see the live disks in the order
//! of their ids ([`Pool::view`]), and trajectories and recordings name them by id.

use super::Simulation;
use crate::physics::disks::Disks;
use crate::physics::flight::Flight;
use serde::{Deserialize, Serialize};

/// The engine number of an id that is not in the scene.
const DEAD: u32 = u32::MAX;

/// The counts and sums of disks going out (and in) since the start.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Flow {
    /// Disks at the start.
    pub initial: u64,
    /// Disks that entered.
    pub entered: u64,
    /// Disks that left.
    pub left: u64,
    /// Their mass.
    pub mass_out: f64,
    /// The energy they carried out (kinetic and potential, m g y, as they left).
    pub energy_out: f64,
    /// Impacts on the orifice's corners (also counted as floor impacts).
    pub corner: u64,
    /// Disks at rest on the floor that slid over an edge of the orifice and fell.
    pub edge: u64,
    /// Absolute time from which exits count for the rate (the end of the warm-up).
    pub from: f64,
    /// Exits from `from` on, their mass, the first and last exit times, and the sums of the
    /// intervals between consecutive exits and of their squares (for the rate's error).
    pub exits: u64,
    pub exit_mass: f64,
    pub first_exit: f64,
    pub last_exit: f64,
    pub sum_gap: f64,
    pub sum_gap2: f64,
}

impl Flow {
    /// Books an exit of mass `m` at absolute time `t`.
    fn exit(&mut self, t: f64, m: f64) {
        self.left += 1;
        self.mass_out += m;
        if t < self.from {
            return;
        }
        if self.exits == 0 {
            self.first_exit = t;
        } else {
            let gap = t - self.last_exit;
            self.sum_gap += gap;
            self.sum_gap2 += gap * gap;
        }
        self.exits += 1;
        self.exit_mass += m;
        self.last_exit = t;
    }

    /// Disks per unit time out after the warm-up, `(rate, standard error)`, from the intervals
    /// between exits (taken as independent): the rate is one over the mean interval, its error
    /// the mean's by the delta method. `None` before two exits.
    pub fn rate(&self) -> Option<(f64, f64)> {
        let gaps = self.exits.checked_sub(1).filter(|&g| g >= 1)? as f64;
        let mean = self.sum_gap / gaps;
        if mean <= 0.0 {
            return None;
        }
        let var = if gaps > 1.0 {
            ((self.sum_gap2 - gaps * mean * mean) / (gaps - 1.0)).max(0.0)
        } else {
            0.0
        };
        let rate = 1.0 / mean;
        Some((rate, rate * rate * (var / gaps).sqrt()))
    }
}

/// Live and dead disks: each id's engine number, the properties of every id, and the view of
/// the live ones that callers read.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Pool {
    /// Engine number of each id (`DEAD` when not in the scene).
    engine_of: Vec<u32>,
    /// Radii, masses and species of every id (no motions).
    all: Disks,
    /// The live disks' radii, masses and species in the order of their ids (rebuilt when the
    /// event loop returns, not within it).
    #[serde(skip)]
    view: Disks,
    /// The ids of the live disks in order (the rows of the view).
    #[serde(skip)]
    ids: Vec<u32>,
    /// The live set changed since the view was built.
    #[serde(skip)]
    stale: bool,
    /// What went out and in.
    pub flow: Flow,
}

impl Pool {
    /// A pool holding `disks` (every id live), with room for `capacity` ids; exits count for
    /// the rate from absolute time `from`.
    pub fn new(disks: &Disks, capacity: usize, from: f64) -> Pool {
        let n = disks.len();
        let mut all = disks.clone();
        all.motion = Vec::new();
        all.counter = Vec::new();
        all.spins = None;
        let mut engine_of = Vec::with_capacity(capacity);
        engine_of.extend(0..n as u32);
        let mut pool = Pool {
            engine_of,
            view: all.clone(),
            all,
            ids: Vec::with_capacity(capacity),
            stale: true,
            flow: Flow {
                initial: n as u64,
                from,
                ..Flow::default()
            },
        };
        pool.refresh();
        pool
    }

    /// The live disks' properties in id order.
    pub fn view(&self) -> &Disks {
        &self.view
    }

    /// The ids of the live disks in order (the rows of [`view`](Self::view)).
    pub fn ids(&self) -> &[u32] {
        &self.ids
    }

    /// Rebuilds the view if the live set changed (no allocation once it has held every id).
    pub fn refresh(&mut self) {
        if !self.stale {
            return;
        }
        self.ids.clear();
        for (id, &k) in self.engine_of.iter().enumerate() {
            if k != DEAD {
                self.ids.push(id as u32);
            }
        }
        let rows = || self.ids.iter().map(|&i| i as usize);
        self.view.radius.gather(&self.all.radius, rows());
        self.view.mass.gather(&self.all.mass, rows());
        self.view.species.gather(&self.all.species, rows());
        self.stale = false;
    }

    /// The engine numbers of the live disks in the order of their ids.
    pub fn engine_rows(&self) -> impl Iterator<Item = usize> + '_ {
        self.ids
            .iter()
            .map(|&i| self.engine_of[i as usize] as usize)
    }

    /// The radius of the disk whose id is `id`.
    pub fn radius_of(&self, id: usize) -> f64 {
        self.all.radius[id]
    }

    /// Number of ids the pool has room for.
    pub fn capacity(&self) -> usize {
        self.engine_of.capacity()
    }

    /// Live disks.
    pub fn live(&self) -> usize {
        self.ids.len()
    }

    /// `true` when the saved pool fits `n` live disks and these properties.
    pub fn fits(&self, n: usize, ids: &[u32]) -> bool {
        let live = self.engine_of.iter().filter(|&&k| k != DEAD).count();
        live == n
            && ids.len() == n
            && ids
                .iter()
                .enumerate()
                .all(|(k, &id)| self.engine_of.get(id as usize) == Some(&(k as u32)))
    }

    /// After a restore: the view is built anew.
    pub fn restored(&mut self) {
        self.stale = true;
        self.refresh();
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        4 * (self.engine_of.capacity() + self.ids.capacity()) + self.all.bytes() + self.view.bytes()
    }
}

impl<F: Flight> Simulation<F> {
    /// Disk `i` (flying, wholly below the floor in the orifice) leaves the scene: its energy
    /// and mass are booked as carried out, the last engine disk takes its number, and the grid,
    /// lists and predictions are rebuilt over the disks that remain.
    pub(super) fn leave(&mut self, i: usize) -> crate::error::Result<()> {
        let now = self.now;
        self.bring(i, now);
        let m = &self.disks.motion[i];
        let mass = self.disks.mass[i];
        let g = self.flight.g();
        let energy = mass * (0.5 * (m.vx * m.vx + m.vy * m.vy) + g * m.y);
        let time = self.base.absolute(now);
        let last = self.disks.len() - 1;
        let pool = self.pool.as_mut().expect("leaving needs a pool");
        let id = self.map.numbering.id(i);
        let last_id = self.map.numbering.id(last);
        pool.engine_of[last_id] = i as u32;
        pool.engine_of[id] = DEAD;
        pool.stale = true;
        pool.flow.exit(time, mass);
        pool.flow.energy_out += energy;
        // Everything that holds a disk number between events follows the move of the last disk
        // to `i`; what the re-mapping rebuilds (grid, lists, anchors, queue) is only truncated.
        self.disks.swap_remove(i);
        self.map.numbering.swap_remove(i);
        self.restitution.swap_remove(i);
        self.rest.riders.swap_remove(i);
        if !self.rest.same_instant.is_empty() {
            self.rest.same_instant.swap_remove(i);
        }
        if !self.rest.in_cluster.is_empty() {
            self.rest.in_cluster.swap_remove(i);
        }
        if let Some(sh) = self.map.shells.as_mut() {
            sh.swap_remove(i);
        }
        let ev = &mut self.events;
        ev.time.truncate(last + 1);
        ev.time[last] = f64::INFINITY;
        ev.code.swap_remove(i);
        ev.counter.swap_remove(i);
        if self.disks.is_empty() {
            // Nobody left: no grid to build, no event to file.
            self.events.queue.rebuild(&self.events.time);
            return Ok(());
        }
        self.remap()
    }

    /// The pool of live and dead disks, in scenes whose disks may leave.
    pub fn pool(&self) -> Option<&Pool> {
        self.pool.as_ref()
    }
}
