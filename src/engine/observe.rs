//! Observing the engine without changing it: accessors, snapshots of every disk at one time,
//! and the overlap checks.

use super::{EnergyFlow, EventCounts, JamCounts, Simulation, OVERLAP_TOLERANCE};
use crate::error::{Error, Result};
use crate::neighbours::{Cells, GridGeometry, Mask};
use crate::physics::disks::Disks;
use crate::physics::flight::Flight;
use crate::physics::floor::Floor;
use crate::physics::walls::into_period;
use crate::physics::walls::{SideBounds, Top};

/// Blocks of scenario numbers a visit of a renumbered engine's disks goes through.
const VISIT_BLOCKS: usize = 8;

/// How many disks ahead a visit of a renumbered engine's disks asks for a state.
const VISIT_AHEAD: usize = 16;

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
    /// The id (scenario number) of each entry, where disks leave (empty: entry i is disk i).
    pub ids: Vec<u32>,
}

impl Snapshot {
    /// Makes room for the states of `n` disks at time `t`, to be set one by one with
    /// [`set`](Self::set) (from a visit of their states: see [`Simulation::visit_states`]).
    pub fn start(&mut self, n: usize, t: f64, floor_height: Option<f64>) {
        self.time = t;
        self.x.resize(n, 0.0);
        self.y.resize(n, 0.0);
        self.vx.resize(n, 0.0);
        self.vy.resize(n, 0.0);
        self.floor_height = floor_height;
    }

    /// Entry `i`'s state `[x, y, vx, vy]`. Called once per disk by a visit, inlined into it.
    #[inline(always)]
    pub fn set(&mut self, i: usize, [x, y, vx, vy]: [f64; 4]) {
        self.x[i] = x;
        self.y[i] = y;
        self.vx[i] = vx;
        self.vy[i] = vy;
    }
}

impl<F: Flight> Simulation<F> {
    /// The scene's floor (its phase refers to the engine's current local clock).
    pub fn floor(&self) -> Option<&Floor> {
        self.bounds.floor.as_ref()
    }

    /// The disks in the scenario's numbering, for their radii, masses and species (which go
    /// with [`snapshot`](Self::snapshot)'s entries). Their motions are not the present state
    /// (nor in the scenario's numbering once the engine has renumbered its disks): take a
    /// snapshot for that.
    pub fn disks(&self) -> &Disks {
        if let Some(pool) = &self.pool {
            return pool.view();
        }
        self.map.numbering.original().unwrap_or(&self.disks)
    }

    /// The radius of the disk whose id is `id`.
    fn radius_of_id(&self, id: usize) -> f64 {
        match &self.pool {
            Some(pool) => pool.radius_of(id),
            None => self.disks().radius[id],
        }
    }

    /// `Σ ½ I ω²` of rough disks at absolute time `t ≥ time()` (spins are constant between
    /// events, but for disks sliding on a rough floor); `None` for smooth disks.
    pub fn rotational_energy(&self, t: f64) -> Option<f64> {
        let spins = self.disks.spins.as_ref()?;
        let mut e = self.disks.rotational_energy();
        if self.rest.riders.any_sliding() {
            let local = self.base.local(t);
            for k in self.rest.riders.iter() {
                if self.rest.riders.slide(k).is_some() {
                    let w0 = spins.omega[k];
                    let (_, w) = self.spin_at(k, local);
                    let a = self.disks.radius[k];
                    e += 0.5 * spins.q * self.disks.mass[k] * a * a * (w * w - w0 * w0);
                }
            }
        }
        Some(e)
    }

    /// Rough disk `k`'s `(orientation, ω)` at local time `t` (no event of its between): its
    /// free turn, or for a disk sliding on a rough floor its turn under the friction's torque.
    fn spin_at(&self, k: usize, t: f64) -> (f64, f64) {
        let spins = self.disks.spins.as_ref().expect("rough disks");
        let (angle, w) = (spins.angle(k, t), spins.omega[k]);
        if self.rest.riders.slide(k).is_none() {
            return (angle, w);
        }
        let m = &self.disks.motion[k];
        let (x, _, vx, _) = self.state_at(k, t);
        let qa = spins.q * self.disks.radius[k];
        let dx = x - m.x - m.vx * (t - m.t);
        (
            (angle + dx / qa).rem_euclid(std::f64::consts::TAU),
            w + (vx - m.vx) / qa,
        )
    }

    /// `q` in `I = q m a²` of rough disks; `None` for smooth disks.
    pub fn inertia_factor(&self) -> Option<f64> {
        self.disks.spins.as_ref().map(|s| s.q)
    }

    /// Each rough disk's orientation and spin at absolute time `t ≥ time()` (no event between),
    /// in the scenario's numbering: `(angle in [0, 2π), ω)`; `None` for smooth disks.
    pub fn spins_at(&self, t: f64) -> Option<Vec<(f64, f64)>> {
        let spins = self.disks.spins.as_ref()?;
        let local = self.base.local(t);
        let spin = |k: usize| {
            if self.rest.riders.any_sliding() {
                self.spin_at(k, local)
            } else {
                (spins.angle(k, local), spins.omega[k])
            }
        };
        if let Some(pool) = &self.pool {
            // Live disks only, in the order of their ids (the rows of the snapshots).
            return Some(pool.engine_rows().map(spin).collect());
        }
        let mut out = vec![(0.0, 0.0); self.disks.len()];
        for k in 0..self.disks.len() {
            out[self.map.numbering.id(k)] = spin(k);
        }
        Some(out)
    }

    /// Current absolute time.
    pub fn time(&self) -> f64 {
        self.base.absolute(self.now)
    }

    /// Event counts so far.
    pub fn counts(&self) -> EventCounts {
        self.tally.counts
    }

    /// Why simulated time stopped advancing, once [`advance_to`](Self::advance_to) has
    /// returned [`Progress::Stalled`](super::Progress::Stalled): the disks and rules involved.
    pub fn stall_report(&self) -> Option<&str> {
        self.control.stall_report.as_deref()
    }

    /// How often each jam rule engaged since the engine started (not kept across a resume).
    pub fn jam_counts(&self) -> JamCounts {
        self.tally.jams
    }

    /// Energy injected by the floor and dissipated in collisions so far.
    pub fn energy_flow(&self) -> EnergyFlow {
        self.tally.flow
    }

    /// Σ over pair collisions of (contact distance × momentum exchanged): the collision virial.
    pub fn virial(&self) -> f64 {
        self.tally.virial
    }

    /// Largest overlap seen at a contact (contact distance − centre distance), ≥ 0.
    pub fn max_overlap(&self) -> f64 {
        self.tally.max_overlap
    }

    /// The neighbour mask in use.
    pub fn mask(&self) -> &Mask {
        &self.map.mask
    }

    /// `dense`, `hashed` or `linked` (several disks per cell, the local re-mapping's closed
    /// domains): how the grid is stored.
    pub fn grid_kind(&self) -> &'static str {
        match self.map.cells {
            Cells::Dense(_) => "dense",
            Cells::Sparse(_) => "hashed",
            Cells::Linked(_) => "linked",
        }
    }

    /// `calendar` or `tree`: the event queue in use.
    pub fn queue_kind(&self) -> &'static str {
        self.events.queue.kind()
    }

    /// `global` (Isobe's DUTC re-mapping) or `local` (per-disk shells).
    pub fn remap_kind(&self) -> &'static str {
        if self.map.shells.is_some() {
            "local"
        } else {
            "global"
        }
    }

    /// The grid geometry in use.
    pub fn geometry(&self) -> &GridGeometry {
        &self.map.geometry
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
            + self.map.shells.as_ref().map_or(0, |s| s.bytes())
            + 8 * self.events.time.capacity()
            + 4 * (self.events.code.capacity() + self.events.counter.capacity())
            + self.events.queue.bytes()
            + self.map.cells.bytes()
            + self.map.lists.bytes()
            + self.restitution.bytes()
            + self.rest.riders.bytes()
            + self.map.numbering.bytes()
            + self.pool.as_ref().map_or(0, |p| p.bytes())
    }

    /// Energy flows up to absolute time `t`, including the work the floor has done on riding
    /// disks since they were last brought forward (and the momentum it gave them).
    pub fn energy_flow_at(&self, t: f64) -> EnergyFlow {
        let mut flow = self.tally.flow;
        let local = self.base.local(t);
        let g = self.flight.g();
        for i in self.rest.riders.iter() {
            let (_, y, _, vy) = self.state_at(i, local);
            let m = &self.disks.motion[i];
            flow.floor_carry(self.disks.mass[i], g, (m.y, m.vy, m.t), (y, vy, local));
            if self.rest.riders.slide(i).is_some() {
                flow.dissipated += self.slide_loss(i, local);
            }
        }
        flow
    }

    /// The kinetic energy (translation and spin) friction has taken from sliding disk `i`
    /// since its time stamp, by local time `t`.
    fn slide_loss(&self, i: usize, t: f64) -> f64 {
        let spins = self.disks.spins.as_ref().expect("rough disks");
        let m = &self.disks.motion[i];
        let (_, _, vx, _) = self.state_at(i, t);
        let (_, w) = self.spin_at(i, t);
        let (a, w0) = (self.disks.radius[i], spins.omega[i]);
        let mass = self.disks.mass[i];
        0.5 * mass * ((m.vx * m.vx - vx * vx) + spins.q * a * a * (w0 * w0 - w * w))
    }

    /// Number of disks at rest now: riding the floor, or resting on disks that rest.
    pub fn riders(&self) -> usize {
        self.rest.riders.count()
    }

    /// The time the last disk came to rest, while every disk is at rest (`None` while a disk
    /// moves): the end of the last motion, exact to the event.
    pub fn at_rest_since(&self) -> Option<f64> {
        self.rest.riders.at_rest_since()
    }

    /// Disks released from a bed all at rest by the rest rules or a collision (not by the
    /// floor, an outlet or an arriving disk) since the start.
    pub fn rest_wakes(&self) -> u64 {
        self.rest.riders.wakes()
    }

    /// Number of disks resting on other disks now (part of [`riders`](Self::riders)).
    pub fn stacked(&self) -> usize {
        self.rest.riders.stacked()
    }

    /// `true` once the engine numbers its disks otherwise than the scenario (tests of the
    /// visits' order).
    #[cfg(test)]
    pub(crate) fn renumbered(&self) -> bool {
        self.map.numbering.ids().is_some()
    }

    /// Calls `visit(i, [x, y, vx, vy])` with every disk's state at absolute time
    /// `t ≥` [`time`](Self::time), in the scenario's numbering and order (so that sums over the
    /// disks do not depend on renumbering), positions wrapped into a periodic box, without
    /// touching the engine (so observing never changes the dynamics) and without a copy of
    /// every state.
    pub fn visit_states(&self, t: f64, mut visit: impl FnMut(usize, [f64; 4])) {
        let local = self.base.local(t);
        let state = |k: usize| self.wrapped_state_at(k, local);
        if let Some(pool) = &self.pool {
            // Live disks only, in the order of their ids.
            for (row, k) in pool.engine_rows().enumerate() {
                visit(row, state(k));
            }
            return;
        }
        let Some(id) = self.map.numbering.ids() else {
            (0..self.disks.len()).for_each(|i| visit(i, state(i)));
            return;
        };
        // Renumbered: the engine number of each scenario number, found a block of scenario
        // numbers at a time (an eighth of the disks: half a byte per disk while a visit lasts,
        // where a whole inverse would add four to the run's peak memory).
        let n = id.len();
        let block = n.div_ceil(VISIT_BLOCKS).max(1);
        let mut k_of = vec![0u32; block];
        for lo in (0..n).step_by(block) {
            let hi = (lo + block).min(n);
            for (k, &i) in id.iter().enumerate() {
                if (lo..hi).contains(&(i as usize)) {
                    k_of[i as usize - lo] = k as u32;
                }
            }
            // The states are read at random: each is asked for a few disks ahead, so that the
            // reads overlap instead of waiting one after another.
            let ks = &k_of[..hi - lo];
            for (off, (i, &k)) in (lo..hi).zip(ks).enumerate() {
                if let Some(&ahead) = ks.get(off + VISIT_AHEAD) {
                    crate::platform::prefetch::prefetch(&self.disks.motion, ahead as usize);
                }
                visit(i, state(k as usize));
            }
        }
    }

    /// The floor's height at absolute time `t` (`None` without a floor).
    pub fn floor_height_at(&self, t: f64) -> Option<f64> {
        self.bounds
            .floor
            .as_ref()
            .map(|f| f.height(self.base.local(t)))
    }

    /// Every disk's state at absolute time `t ≥` [`time`](Self::time) into `out` (see
    /// [`visit_states`](Self::visit_states)).
    pub fn snapshot_into(&self, t: f64, out: &mut Snapshot) {
        out.start(self.disks.len(), t, self.floor_height_at(t));
        self.visit_states(t, |i, state| out.set(i, state));
        if let Some(pool) = &self.pool {
            out.ids.clear();
            out.ids.extend_from_slice(pool.ids());
        }
    }

    /// Every disk's state at absolute time `t`.
    pub fn snapshot(&self, t: f64) -> Snapshot {
        let mut s = Snapshot::default();
        self.snapshot_into(t, &mut s);
        s
    }

    /// Disk `k`'s state `[x, y, vx, vy]` at local time `local`, its position wrapped into a
    /// periodic box (what [`visit_states`](Self::visit_states) gives).
    #[inline(always)]
    fn wrapped_state_at(&self, k: usize, local: f64) -> [f64; 4] {
        let (mut x, mut y, vx, vy) = self.state_at(k, local);
        if let SideBounds::Periodic { width } = self.bounds.sides {
            x = into_period(x, width);
        }
        if let Top::Periodic { height } = self.bounds.top {
            y = into_period(y, height);
        }
        [x, y, vx, vy]
    }

    /// Largest overlap between any two listed neighbours at absolute time `t ≥`
    /// [`time`](Self::time) (0 if none), with the two disks (the scenario's numbering): an
    /// O(N·neighbours) check, at the start and at samples when the invariant checks are on,
    /// read from the engine without a copy of every state.
    pub fn overlap_at(&self, t: f64) -> (f64, usize, usize) {
        let local = self.base.local(t);
        let mut worst = (0.0, 0, 0);
        for k in 0..self.disks.len() {
            let [xk, yk, _, _] = self.wrapped_state_at(k, local);
            for &l in self.map.lists.of(k) {
                let l = l as usize;
                let [xl, yl, _, _] = self.wrapped_state_at(l, local);
                let (dx, dy) = self.wrap(xk - xl, yk - yl);
                let s = self.disks.radius[k] + self.disks.radius[l];
                let o = s - (dx * dx + dy * dy).sqrt();
                if o > worst.0 {
                    worst = (o, self.map.numbering.id(k), self.map.numbering.id(l));
                }
            }
        }
        worst
    }

    /// Checks that no two listed neighbours overlap beyond tolerance at absolute time `t`
    /// (see [`overlap_at`](Self::overlap_at)).
    pub fn check_no_overlap(&self, t: f64) -> Result<()> {
        let (o, i, j) = self.overlap_at(t);
        let s = self.radius_of_id(i) + self.radius_of_id(j);
        if o > OVERLAP_TOLERANCE * s {
            return Err(Error::Runtime(format!(
                "disks {i} and {j} overlap by {o:e} at time {t}"
            )));
        }
        Ok(())
    }
}
