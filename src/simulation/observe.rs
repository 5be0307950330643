//! Observing the engine without changing it: accessors, snapshots of every disk at one time,
//! and the overlap checks.

use super::clock::into_period;
use super::{EnergyFlow, EventCounts, Simulation, OVERLAP_TOLERANCE};
use crate::disks::Disks;
use crate::dynamics::Flight;
use crate::error::{Error, Result};
use crate::globals::{Cells, GridGeometry, Mask};
use crate::locals::floor::Floor;
use crate::locals::{SideBounds, Top};

/// The state of every disk at one time (for measurements and frames).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Snapshot {
    /// Absolute time.
    pub time: f64,
    /// Positions x (wrapped into [0, width) where periodic).
    pub x: Vec<f64>,
    /// Positions y.
    pub y: Vec<f64>,
    /// Velocities x.
    pub vx: Vec<f64>,
    /// Velocities y.
    pub vy: Vec<f64>,
    /// Floor height at `time`, if there is a floor.
    pub floor_height: Option<f64>,
}

impl<F: Flight> Simulation<F> {
    /// The scene's floor (its phase refers to the engine's current local clock).
    pub fn floor(&self) -> Option<&Floor> {
        self.floor.as_ref()
    }

    /// The disks in the scenario's numbering, for their radii, masses and species (which go
    /// with [`snapshot`](Self::snapshot)'s entries). Their motions are not the present state
    /// (nor in the scenario's numbering once the engine has renumbered its disks): take a
    /// snapshot for that.
    pub fn disks(&self) -> &Disks {
        self.numbering.original().unwrap_or(&self.disks)
    }

    /// Current absolute time.
    pub fn time(&self) -> f64 {
        self.base.absolute(self.now)
    }

    /// Event counts so far.
    pub fn counts(&self) -> EventCounts {
        self.counts
    }

    /// Energy injected by the floor and dissipated in collisions so far.
    pub fn energy_flow(&self) -> EnergyFlow {
        self.flow
    }

    /// Σ over pair collisions of (contact distance × momentum exchanged): the collision virial.
    pub fn virial(&self) -> f64 {
        self.virial
    }

    /// Largest overlap seen at a contact (contact distance − centre distance), ≥ 0.
    pub fn max_overlap(&self) -> f64 {
        self.max_overlap
    }

    /// The neighbour mask in use.
    pub fn mask(&self) -> &Mask {
        &self.mask
    }

    /// `dense`, `hashed` or `linked` (several disks per cell, the local re-mapping's closed
    /// domains): how the grid is stored.
    pub fn grid_kind(&self) -> &'static str {
        match self.cells {
            Cells::Dense(_) => "dense",
            Cells::Sparse(_) => "hashed",
            Cells::Linked(_) => "linked",
        }
    }

    /// `calendar` or `tree`: the event queue in use.
    pub fn queue_kind(&self) -> &'static str {
        self.queue.kind()
    }

    /// `global` (Isobe's DUTC re-mapping) or `local` (per-disk shells).
    pub fn remap_kind(&self) -> &'static str {
        if self.shells.is_some() {
            "local"
        } else {
            "global"
        }
    }

    /// The grid geometry in use.
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }

    /// The flight law.
    pub fn flight(&self) -> F {
        self.flight
    }

    /// Gravity of the flight law.
    pub fn gravity(&self) -> f64 {
        self.flight.g()
    }

    /// Bytes held by the engine's arrays (disks, events, queue, grid, neighbour lists, shells).
    pub fn bytes(&self) -> usize {
        self.disks.bytes()
            + self.shells.as_ref().map_or(0, |s| s.bytes())
            + 8 * self.ev_time.capacity()
            + 4 * (self.ev_partner.capacity() + self.ev_counter.capacity())
            + self.queue.bytes()
            + self.cells.bytes()
            + self.lists.bytes()
            + self.restitution.bytes()
            + self.riders.bytes()
            + self.numbering.bytes()
    }

    /// Energy flows up to absolute time `t`, including the work the floor has done on riding
    /// disks since they were last brought forward (and the momentum it gave them).
    pub fn energy_flow_at(&self, t: f64) -> EnergyFlow {
        let mut flow = self.flow;
        let local = self.base.local(t);
        let g = self.flight.g();
        for i in self.riders.iter() {
            let (_, y, _, vy) = self.state_at(i, local);
            let m = &self.disks.motion[i];
            flow.injected += self.disks.mass[i] * (g * (y - m.y) + 0.5 * (vy * vy - m.vy * m.vy));
            flow.floor_impulse += self.disks.mass[i] * (g * (local - m.t) + (vy - m.vy));
        }
        flow
    }

    /// Number of disks at rest now: riding the floor, or resting on disks that rest.
    pub fn riders(&self) -> usize {
        self.riders.count()
    }

    /// Number of disks resting on other disks now (part of [`riders`](Self::riders)).
    pub fn stacked(&self) -> usize {
        self.riders.stacked()
    }

    /// Every disk's state at absolute time `t ≥` [`time`](Self::time), without touching the
    /// engine (so observing never changes the dynamics).
    pub fn snapshot_into(&self, t: f64, out: &mut Snapshot) {
        let n = self.disks.len();
        let local = self.base.local(t);
        out.time = t;
        out.x.resize(n, 0.0);
        out.y.resize(n, 0.0);
        out.vx.resize(n, 0.0);
        out.vy.resize(n, 0.0);
        for k in 0..n {
            let (x, y, vx, vy) = self.state_at(k, local);
            let i = self.numbering.id(k);
            out.x[i] = x;
            out.y[i] = y;
            out.vx[i] = vx;
            out.vy[i] = vy;
        }
        if let SideBounds::Periodic { width } = self.sides {
            for x in &mut out.x {
                *x = into_period(*x, width);
            }
        }
        if let Top::Periodic { height } = self.top {
            for y in &mut out.y {
                *y = into_period(*y, height);
            }
        }
        out.floor_height = self.floor.as_ref().map(|f| f.height(local));
    }

    /// Every disk's state at absolute time `t`.
    pub fn snapshot(&self, t: f64) -> Snapshot {
        let mut s = Snapshot::default();
        self.snapshot_into(t, &mut s);
        s
    }

    /// Largest overlap between any two listed neighbours in `snap` (0 if none): an O(N) check
    /// run at samples when the invariant checks are on.
    pub fn overlap_in(&self, snap: &Snapshot) -> (f64, usize, usize) {
        let mut worst = (0.0, 0, 0);
        let id = |k: usize| self.numbering.id(k);
        for k in 0..self.disks.len() {
            for &l in self.lists.of(k) {
                let l = l as usize;
                let (i, j) = (id(k), id(l));
                let (dx, dy) = self.wrap(snap.x[i] - snap.x[j], snap.y[i] - snap.y[j]);
                let s = self.disks.radius[k] + self.disks.radius[l];
                let o = s - (dx * dx + dy * dy).sqrt();
                if o > worst.0 {
                    worst = (o, i, j);
                }
            }
        }
        worst
    }

    /// Checks that no two disks overlap beyond tolerance, by brute force over all pairs within
    /// reach (O(N·neighbours), used at start and by tests).
    pub fn check_no_overlap(&self, snap: &Snapshot) -> Result<()> {
        let (o, i, j) = self.overlap_in(snap);
        let s = self.disks().radius[i] + self.disks().radius[j];
        if o > OVERLAP_TOLERANCE * s {
            return Err(Error::Runtime(format!(
                "disks {i} and {j} overlap by {o:e} at time {}",
                snap.time
            )));
        }
        Ok(())
    }
}
