//! The event-driven engine (Isobe 1999): per-disk local minima in a complete binary tree,
//! neighbour lists from the EEPGM grid, re-mapping by DUTC, lazy per-disk time stamps.
//!
//! The engine runs on a local clock that restarts at 0 at every mapping (all disks are brought
//! to the mapping time then), so event times never lose precision however long the run; the
//! absolute time is `base + now`. The floor's phase is re-based at the same moment.

pub mod dutc;
mod resting;
pub mod riders;
pub mod scene;

pub use scene::Scene;

use crate::disks::Disks;
use crate::dynamics::Flight;
use crate::error::{Error, Result};
use crate::globals::{Cells, GridGeometry, Mask, NeighbourLists};
use crate::interactions::{
    collide_rebounding, contact_time, rider_contact, CollisionLaw, Restitution, RiderContact,
};
use crate::locals::floor::{Floor, FloorEvent, RideEnd};
use crate::locals::{Side, SideBounds, Top};
use crate::reference::{Collision, Partner};
use crate::scenario::GridChoice;
use crate::scheduler::CompleteBinaryTree;
use dutc::Dutc;
use riders::Riders;
use serde::Serialize;
use std::sync::atomic::{AtomicBool, Ordering};

/// Event partner codes beyond the disk numbers.
mod partner {
    pub const NONE: u32 = u32::MAX;
    pub const LEFT: u32 = u32::MAX - 1;
    pub const RIGHT: u32 = u32::MAX - 2;
    pub const LID: u32 = u32::MAX - 3;
    pub const FLOOR: u32 = u32::MAX - 4;
    pub const RIDE_END: u32 = u32::MAX - 5;
    /// A disk resting on disks loses a support (they slide apart).
    pub const UNMOUNT: u32 = u32::MAX - 6;
    /// Lowest code of an event that involves no partner disk.
    pub const RECHECK: u32 = u32::MAX - 7;
}

/// Relative overlap (of the contact distance) beyond which the invariant check fails.
pub const OVERLAP_TOLERANCE: f64 = 1e-9;

/// The absolute time of the engine's local clock zero, summed with compensation (Neumaier) so
/// that millions of re-basings add no drift: absolute = `hi + (lo + local)`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Epoch {
    hi: f64,
    lo: f64,
}

impl Epoch {
    /// Moves the epoch forward by `dt`.
    fn advance(&mut self, dt: f64) {
        let sum = self.hi + dt;
        let err = if self.hi.abs() >= dt.abs() {
            (self.hi - sum) + dt
        } else {
            (dt - sum) + self.hi
        };
        self.hi = sum;
        self.lo += err;
    }

    /// Absolute time of local time `local`.
    #[inline]
    fn absolute(&self, local: f64) -> f64 {
        self.hi + (self.lo + local)
    }

    /// Local time of absolute time `t`.
    #[inline]
    fn local(&self, t: f64) -> f64 {
        (t - self.hi) - self.lo
    }
}

/// `x` reduced into `[0, period)` (`rem_euclid` can round up to `period` itself).
#[inline]
fn into_period(x: f64, period: f64) -> f64 {
    let r = x.rem_euclid(period);
    if r >= period {
        0.0
    } else {
        r
    }
}

/// Minimum-image separation where periodic. Positions are wrapped at every mapping and drift
/// by less than the DUTC margin before the next, so one correction suffices.
#[inline(always)]
fn wrap(sides: SideBounds, top: Top, mut dx: f64, mut dy: f64) -> (f64, f64) {
    if let SideBounds::Periodic { width } = sides {
        if dx > 0.5 * width {
            dx -= width;
        } else if dx < -0.5 * width {
            dx += width;
        }
    }
    if let Top::Periodic { height } = top {
        if dy > 0.5 * height {
            dy -= height;
        } else if dy < -0.5 * height {
            dy += height;
        }
    }
    (dx, dy)
}

/// Counts of events by kind.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct EventCounts {
    /// Disk–disk collisions.
    pub pair: u64,
    /// Disk–side-wall collisions.
    pub wall: u64,
    /// Disk–lid collisions.
    pub lid: u64,
    /// Disk–floor impacts.
    pub floor: u64,
    /// Contact searches (floor or riding disk) that needed a second look (no velocity change).
    pub recheck: u64,
    /// Disks that came to rest: on the floor (riding it), or on disks at rest.
    pub rest: u64,
    /// Riding disks thrown off by the floor.
    pub takeoff: u64,
    /// Predicted pair events found stale (the partner moved on); the disk was re-predicted.
    pub stale: u64,
    /// Disks resting on disks that slid off a support (the supports moved apart).
    pub unmount: u64,
    /// Grid re-mappings (DUTC).
    pub rebuild: u64,
}

impl EventCounts {
    /// Collisions of any kind: pair + wall + lid + floor.
    pub fn collisions(&self) -> u64 {
        self.pair + self.wall + self.lid + self.floor
    }

    /// Every event popped from the queue (collisions, stale events, rechecks).
    pub fn popped(&self) -> u64 {
        self.collisions() + self.recheck + self.stale + self.takeoff + self.unmount
    }
}

/// Energy exchanged with the outside and lost in collisions since the start.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct EnergyFlow {
    /// Work done by the floor on the disks (can be negative for a lossy static floor).
    pub injected: f64,
    /// Kinetic energy lost in pair, wall and lid collisions.
    pub dissipated: f64,
}

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

/// The exact event-driven engine, generic over free flight (straight or under gravity).
#[derive(Debug)]
pub struct Simulation<F: Flight> {
    flight: F,
    disks: Disks,
    ev_time: Vec<f64>,
    ev_partner: Vec<u32>,
    ev_counter: Vec<u32>,
    tree: CompleteBinaryTree,
    geometry: GridGeometry,
    mask: Mask,
    cells: Cells,
    lists: NeighbourLists,
    sides: SideBounds,
    top: Top,
    floor: Option<Floor>,
    restitution: CollisionLaw,
    margin: f64,
    base: Epoch,
    now: f64,
    dutc: Dutc,
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
    /// Scratch stack of the release cascade.
    releasing: Vec<u32>,
}

impl<F: Flight> Simulation<F> {
    /// Sets up the engine for `scene` with the disks in their initial state (all at time 0).
    pub fn new(flight: F, scene: &Scene, disks: Disks) -> Result<Simulation<F>> {
        let n = disks.len();
        let (a_min, a_max) = disks.radius_range();
        let floor = scene.floor.clone();
        let bottom = floor.as_ref().map_or(0.0, |f| f.lowest());
        let (top_y, y_periodic) = match scene.top {
            Top::Open => (None, false),
            Top::Lid { height, .. } => (Some(height), false),
            Top::Periodic { height } => (Some(height), true),
        };
        let geometry = GridGeometry::new(
            a_min,
            scene.sides.width(),
            matches!(scene.sides, SideBounds::Periodic { .. }),
            bottom,
            top_y,
            y_periodic,
        );
        let mask = Mask::choose(scene.mask, geometry.cell(), a_min, a_max, scene.packing).ok_or_else(|| {
            Error::input(
                "engine.mask",
                format!(
                    "the mask does not reach beyond contact of the largest disks (radius {a_max}, cells of {:.4})",
                    geometry.cell()
                ),
            )
        })?;
        geometry.check_mask_fits(mask.half_width)?;
        let mask_margin = mask.reach() * geometry.cell() - 2.0 * a_max;
        let mask_margin = match scene.skin {
            Some(skin) => (skin * a_min).min(mask_margin),
            None => mask_margin,
        };
        let mut sim = Simulation {
            flight,
            disks,
            ev_time: vec![f64::INFINITY; n + 1],
            ev_partner: vec![partner::NONE; n],
            ev_counter: vec![0; n],
            tree: CompleteBinaryTree::default(),
            cells: Cells::for_geometry(&geometry, &mask, scene.grid == GridChoice::Hashed),
            geometry,
            mask,
            lists: NeighbourLists::default(),
            sides: scene.sides,
            top: scene.top,
            floor,
            restitution: CollisionLaw::new(
                Restitution {
                    e: scene.restitution,
                    tc: scene.tc,
                    speed_cutoff: scene.speed_cutoff,
                },
                n,
            ),
            margin: mask_margin,
            base: Epoch::default(),
            now: 0.0,
            dutc: Dutc::new(0.0, 0.0, 0.0),
            counts: EventCounts::default(),
            flow: EnergyFlow::default(),
            virial: 0.0,
            max_overlap: 0.0,
            check: scene.check_invariants,
            event_limit: scene.max_events.unwrap_or(u64::MAX),
            interrupt: None,
            log: None,
            riders: Riders::default(),
            resting_contacts: scene.resting_contacts,
            releasing: Vec::new(),
        };
        if sim.floor.is_some() {
            sim.riders = Riders::new(n);
        }
        sim.check_initial_state()?;
        sim.remap().map_err(|e| match e {
            Error::Runtime(m) => Error::input("particles.placement", m),
            other => other,
        })?;
        sim.counts.rebuild = 0;
        let start = sim.snapshot(0.0);
        let (o, i, j) = sim.overlap_in(&start);
        if o > OVERLAP_TOLERANCE * (sim.disks.radius[i] + sim.disks.radius[j]) {
            return Err(Error::input(
                "particles.placement",
                format!("disks {i} and {j} overlap by {o:e} at the start"),
            ));
        }
        sim.max_overlap = o.max(0.0);
        Ok(sim)
    }

    /// Stop [`advance_to`](Self::advance_to) at the next event once `flag` is set (Ctrl-C).
    pub fn set_interrupt(&mut self, flag: &'static AtomicBool) {
        self.interrupt = Some(flag);
    }

    /// Starts (or stops) keeping a log of every collision, for comparison with the reference.
    pub fn set_logging(&mut self, on: bool) {
        self.log = on.then(Vec::new);
    }

    /// Takes the collisions logged so far.
    pub fn take_log(&mut self) -> Vec<Collision> {
        self.log.as_mut().map(std::mem::take).unwrap_or_default()
    }

    /// The scene's floor (its phase refers to the engine's current local clock).
    pub fn floor(&self) -> Option<&Floor> {
        self.floor.as_ref()
    }

    /// Switches the invariant checks on or off.
    pub fn set_checks(&mut self, on: bool) {
        self.check = on;
    }

    /// The disks (states at their own time stamps; use [`snapshot`](Self::snapshot) for a
    /// common time).
    pub fn disks(&self) -> &Disks {
        &self.disks
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

    /// `dense` or `hashed`: how the grid is stored.
    pub fn grid_kind(&self) -> &'static str {
        match self.cells {
            Cells::Dense(_) => "dense",
            Cells::Sparse(_) => "hashed",
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

    /// Bytes held by the engine's arrays (disks, events, tree, grid, neighbour lists).
    pub fn bytes(&self) -> usize {
        self.disks.bytes()
            + 8 * self.ev_time.capacity()
            + 4 * (self.ev_partner.capacity() + self.ev_counter.capacity())
            + self.tree.bytes()
            + self.cells.bytes()
            + self.lists.bytes()
            + self.restitution.bytes()
            + self.riders.bytes()
    }

    /// `true` when disk `i` rides the floor.
    #[inline(always)]
    fn is_riding(&self, i: usize) -> bool {
        self.riders.is_riding(i)
    }

    /// State of disk `i` at local time `t`: on its parabola (or line), or carried by the floor.
    #[inline(always)]
    fn state_at(&self, i: usize, t: f64) -> (f64, f64, f64, f64) {
        let m = &self.disks.motion[i];
        if self.is_riding(i) {
            let (h, hd) = self.floor.as_ref().expect("riders need a floor").ride(t);
            return (m.x + m.vx * (t - m.t), h + self.riders.lift(i), m.vx, hd);
        }
        self.flight.advance(m.x, m.y, m.vx, m.vy, t - m.t)
    }

    /// Brings disk `i` to local time `t` (its stored state then belongs to `t`). The work the
    /// floor does on a riding disk meanwhile is booked as injected energy.
    #[inline(always)]
    fn bring(&mut self, i: usize, t: f64) {
        let (x, y, vx, vy) = self.state_at(i, t);
        let mass = self.disks.mass[i];
        let g = self.flight.g();
        let m = &mut self.disks.motion[i];
        if self.riders.is_riding(i) {
            self.flow.injected += mass * (g * (y - m.y) + 0.5 * (vy * vy - m.vy * m.vy));
        }
        *m = crate::disks::Motion { x, y, vx, vy, t };
    }

    /// Energy flows up to absolute time `t`, including the work the floor has done on riding
    /// disks since they were last brought forward.
    pub fn energy_flow_at(&self, t: f64) -> EnergyFlow {
        let mut flow = self.flow;
        let local = self.base.local(t);
        let g = self.flight.g();
        for i in self.riders.iter() {
            let (_, y, _, vy) = self.state_at(i, local);
            let m = &self.disks.motion[i];
            flow.injected += self.disks.mass[i] * (g * (y - m.y) + 0.5 * (vy * vy - m.vy * m.vy));
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

    /// Contact search between riding disk `r` and flying disk `f` from now to `limit`.
    fn rider_contact(&self, r: usize, f: usize, limit: f64) -> Option<RiderContact> {
        let now = self.now;
        let floor = self.floor.as_ref().expect("riders need a floor");
        let g = self.flight.g();
        let limit = match floor.ride_end(now, g) {
            Some((t_end, _)) => limit.min(t_end),
            None => limit,
        };
        let (xr, _, vxr, _) = self.state_at(r, now);
        let (xf, yf, vxf, vyf) = self.state_at(f, now);
        let (dx, _) = self.wrap(xf - xr, 0.0);
        rider_contact(
            dx,
            vxf - vxr,
            yf,
            vyf,
            self.riders.lift(r),
            self.disks.radius[r] + self.disks.radius[f],
            g,
            floor.max_acceleration(),
            now,
            limit,
            |t| floor.ride(t),
            |t| floor.ride_acceleration(t),
        )
    }

    /// Minimum-image separation where periodic.
    #[inline(always)]
    fn wrap(&self, dx: f64, dy: f64) -> (f64, f64) {
        wrap(self.sides, self.top, dx, dy)
    }

    /// Finds disk `i`'s earliest event from now and files it in the tree.
    fn predict(&mut self, i: usize) {
        let (best, who, recheck) = self.pair_event(i);
        self.file_event(i, best, who, recheck);
        self.tree.update(&self.ev_time, i);
    }

    /// Earliest contact of disk `i` with a listed neighbour from now: (time from now, partner,
    /// time of a needed re-check).
    #[inline]
    fn pair_event(&self, i: usize) -> (f64, u32, f64) {
        let now = self.now;
        let (xi, yi, vxi, vyi) = self.state_at(i, now);
        let speed_i = vxi.abs() + vyi.abs();
        let ai = self.disks.radius[i];
        let rider = self.is_riding(i);
        let mut best = f64::INFINITY;
        let mut who = partner::NONE;
        let mut recheck = f64::INFINITY;
        for &j in self.lists.of(i) {
            let j = j as usize;
            let dt = if self.is_riding(j) == rider {
                // Both fly, or both ride the floor: relative motion is straight.
                let (xj, yj, vxj, vyj) = self.state_at(j, now);
                let (dx, dy) = self.wrap(xi - xj, yi - yj);
                let speed = speed_i + vxj.abs() + vyj.abs();
                contact_time(
                    dx,
                    dy,
                    vxi - vxj,
                    vyi - vyj,
                    ai + self.disks.radius[j],
                    speed,
                )
            } else {
                let limit = (now + best).min(self.dutc.deadline);
                let (r, f) = if rider { (i, j) } else { (j, i) };
                match self.rider_contact(r, f, limit) {
                    Some(RiderContact::At(t)) => Some(t - now),
                    Some(RiderContact::Recheck(t)) => {
                        recheck = recheck.min(t);
                        None
                    }
                    None => None,
                }
            };
            if let Some(dt) = dt {
                if dt < best {
                    best = dt;
                    who = j as u32;
                }
            }
        }
        (best, who, recheck)
    }

    /// Completes disk `i`'s event from its earliest pair contact (`best` from now, with `who`)
    /// with walls, lid, floor and ride ends, and stores it (the tree is not touched).
    fn file_event(&mut self, i: usize, mut best: f64, mut who: u32, mut recheck: f64) {
        let now = self.now;
        let (xi, yi, vxi, vyi) = self.state_at(i, now);
        let ai = self.disks.radius[i];
        let rider = self.is_riding(i);
        let mut counter = if who != partner::NONE {
            self.disks.counter[who as usize]
        } else {
            0
        };
        if let Some((dt, side)) = self.sides.impact(xi, vxi, ai) {
            if dt < best {
                best = dt;
                who = match side {
                    Side::Left => partner::LEFT,
                    Side::Right => partner::RIGHT,
                };
            }
        }
        let g = self.flight.g();
        let mut t = now + best;
        if let Some(floor) = &self.floor {
            if rider {
                if let Some((t_end, end)) = floor.ride_end(now, g) {
                    if t_end < t {
                        t = t_end;
                        who = partner::RIDE_END;
                        counter = matches!(end, RideEnd::Kick { .. }) as u32;
                    }
                }
                if !self.riders.on_floor(i) {
                    let t_off = self.unmount_time(i);
                    if t_off < t {
                        t = t_off;
                        who = partner::UNMOUNT;
                    }
                }
            } else {
                if let Some(dt) = self.top.impact(yi, vyi, ai, g) {
                    if now + dt < t {
                        t = now + dt;
                        who = partner::LID;
                    }
                }
                // Nothing after the re-mapping matters: it re-predicts every disk.
                let limit = t.min(self.dutc.deadline);
                match floor.next_event(yi, vyi, ai, g, now, limit) {
                    Some(FloorEvent::Impact(tf)) if tf < t => {
                        t = tf;
                        who = partner::FLOOR;
                    }
                    Some(FloorEvent::Recheck(tf)) => recheck = recheck.min(tf),
                    _ => {}
                }
            }
        } else if let Some(dt) = self.top.impact(yi, vyi, ai, g) {
            if dt < best {
                t = now + dt;
                who = partner::LID;
            }
        }
        if recheck < t {
            t = recheck;
            who = partner::RECHECK;
        }
        if who >= partner::RECHECK && who != partner::RIDE_END {
            counter = 0;
        }
        self.ev_time[i] = t;
        self.ev_partner[i] = who;
        self.ev_counter[i] = counter;
    }

    /// Predicts every disk's event after a mapping (all disks are at the present time): each
    /// listed pair's contact time is computed once, for both disks; the tree is built at once.
    fn predict_all(&mut self) {
        let n = self.disks.len();
        let mut best = std::mem::take(&mut self.ev_time);
        best.fill(f64::INFINITY);
        let mut who = std::mem::take(&mut self.ev_partner);
        who.fill(partner::NONE);
        let any_rider = self.riders.any();
        for (i, j) in
            (0..n).flat_map(|i| self.lists.half_of(i).iter().map(move |&j| (i, j as usize)))
        {
            if any_rider && (self.is_riding(i) || self.is_riding(j)) {
                continue; // done disk by disk below
            }
            let (mi, mj) = (&self.disks.motion[i], &self.disks.motion[j]);
            let (dx, dy) = self.wrap(mi.x - mj.x, mi.y - mj.y);
            let s = self.disks.radius[i] + self.disks.radius[j];
            let speed = mi.vx.abs() + mi.vy.abs() + mj.vx.abs() + mj.vy.abs();
            if let Some(dt) = contact_time(dx, dy, mi.vx - mj.vx, mi.vy - mj.vy, s, speed) {
                if dt < best[i] {
                    best[i] = dt;
                    who[i] = j as u32;
                }
                if dt < best[j] {
                    best[j] = dt;
                    who[j] = i as u32;
                }
            }
        }
        self.ev_time = best;
        self.ev_partner = who;
        for i in 0..n {
            let near_rider = any_rider
                && (self.is_riding(i)
                    || self.lists.of(i).iter().any(|&j| self.is_riding(j as usize)));
            let (b, w, r) = if near_rider {
                self.pair_event(i)
            } else {
                (self.ev_time[i], self.ev_partner[i], f64::INFINITY)
            };
            self.file_event(i, b, w, r);
        }
        self.tree = CompleteBinaryTree::build(&self.ev_time);
    }

    /// Squared speed of disk `i` (at its own time stamp) in the frame falling with gravity since
    /// the last mapping.
    #[inline(always)]
    fn falling_speed_sq(&self, i: usize) -> f64 {
        let vy = self.disks.motion[i].vy + self.flight.g() * self.disks.motion[i].t;
        self.disks.motion[i].vx * self.disks.motion[i].vx + vy * vy
    }

    /// Runs events until absolute time `target` (events at exactly `target` are left for later).
    pub fn advance_to(&mut self, target: f64) -> Result<Progress> {
        loop {
            let local_target = self.base.local(target);
            if self.counts.popped() >= self.event_limit {
                return Ok(Progress::EventLimit);
            }
            if self.counts.popped() & 0xfff == 0 {
                if let Some(flag) = self.interrupt {
                    if flag.load(Ordering::Relaxed) {
                        return Ok(Progress::Interrupted);
                    }
                }
            }
            let i = self.tree.min();
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
                    "event of disk {i} at {} is before the present {}",
                    self.base.absolute(te),
                    self.base.absolute(self.now)
                )));
            }
            self.now = te;
            self.fire(i)?;
        }
    }

    /// Processes the next `k` events (collisions, stale events, re-mappings), whatever their
    /// times: for benchmarks, which measure throughput rather than reach a time.
    pub fn step_events(&mut self, k: u64) -> Result<()> {
        for _ in 0..k {
            let i = self.tree.min();
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

    /// Carries out disk `i`'s event at the present time.
    fn fire(&mut self, i: usize) -> Result<()> {
        let now = self.now;
        let who = self.ev_partner[i];
        if let Some(log) = self.log.as_mut() {
            let p = match who {
                partner::LEFT => Some(Partner::Left),
                partner::RIGHT => Some(Partner::Right),
                partner::LID => Some(Partner::Lid),
                partner::FLOOR => Some(Partner::Floor),
                partner::RECHECK | partner::RIDE_END | partner::UNMOUNT | partner::NONE => None,
                j if self.disks.counter[j as usize] == self.ev_counter[i] => Some(Partner::Disk(j)),
                _ => None,
            };
            if let Some(p) = p {
                log.push(Collision::new(self.base.absolute(now), i, p));
            }
        }
        match who {
            partner::LEFT | partner::RIGHT => {
                self.bring(i, now);
                self.unsettle(i);
                let side = if who == partner::LEFT {
                    Side::Left
                } else {
                    Side::Right
                };
                let (m, mass) = (&mut self.disks.motion[i], self.disks.mass[i]);
                self.flow.dissipated +=
                    self.sides.hit(side, &mut self.restitution, i, now, m, mass);
                self.counts.wall += 1;
                self.moved(i);
                self.release_carried(i, None);
            }
            partner::LID => {
                self.bring(i, now);
                let (m, mass) = (&mut self.disks.motion[i], self.disks.mass[i]);
                self.flow.dissipated += self.top.hit(&mut self.restitution, i, now, m, mass);
                self.counts.lid += 1;
                self.moved(i);
            }
            partner::FLOOR => {
                self.bring(i, now);
                let floor = self.floor.as_ref().expect("floor events need a floor");
                let hd = floor.velocity(now);
                self.floor_impact(i, hd);
                self.moved(i);
            }
            partner::RIDE_END => {
                self.bring(i, now);
                let on_floor = self.riders.on_floor(i);
                self.riders.dismount(i);
                let floor = self.floor.as_ref().expect("riders need a floor");
                let g = self.flight.g();
                let kick = self.ev_counter[i] == 1;
                // The end that was predicted, evaluated at its own time.
                let end = floor
                    .ride_end(now - 1e-9 * floor.period_or_one(), g)
                    .map(|(_, e)| e);
                // Disks resting on disks leave with the floor's velocity before a kick (the disk
                // below then hits them) or with the launch velocity (they all fly together).
                let vy = match end {
                    Some(RideEnd::Kick { before, after }) if kick => {
                        self.set_vy(i, before);
                        if on_floor {
                            self.floor_impact(i, after);
                        }
                        before
                    }
                    Some(RideEnd::TakeOff { launch }) if !kick => {
                        self.counts.takeoff += 1;
                        self.set_vy(i, launch);
                        launch
                    }
                    _ => {
                        // Round-off moved us past the end: fly with the floor's velocity.
                        self.counts.takeoff += 1;
                        let hd = floor.velocity(now);
                        self.set_vy(i, hd);
                        hd
                    }
                };
                self.moved(i);
                self.release_carried(i, Some(vy));
            }
            partner::UNMOUNT => {
                self.bring(i, now);
                self.counts.unmount += 1;
                self.riders.dismount(i);
                self.moved(i);
                self.release_carried(i, None);
            }
            partner::RECHECK => {
                self.counts.recheck += 1;
                self.predict(i);
            }
            partner::NONE => unreachable!("a disk without an event is never the minimum"),
            j => {
                let j = j as usize;
                if self.disks.counter[j] != self.ev_counter[i] {
                    self.counts.stale += 1;
                    self.predict(i);
                    return Ok(());
                }
                self.pair(i, j)?;
            }
        }
        Ok(())
    }

    /// Disk `i`'s velocity changed: invalidate partners' predictions, watch DUTC, re-predict.
    #[inline]
    fn moved(&mut self, i: usize) {
        self.disks.counter[i] = self.disks.counter[i].wrapping_add(1);
        if !self.is_riding(i) {
            let s = self.falling_speed_sq(i);
            self.dutc.observe(self.now, s);
        }
        self.predict(i);
    }

    /// Sets the vertical velocity of (flying) disk `i`, booking the change as floor work.
    fn set_vy(&mut self, i: usize, vy: f64) {
        let m = &mut self.disks.motion[i];
        self.flow.injected += 0.5 * self.disks.mass[i] * (vy * vy - m.vy * m.vy);
        m.vy = vy;
    }

    /// Flying disk `i` (brought to now) hits the floor moving with velocity `hd`: it bounces,
    /// or comes to rest and rides the floor if the rebound is negligible.
    fn floor_impact(&mut self, i: usize, hd: f64) {
        let now = self.now;
        let g = self.flight.g();
        let floor = self.floor.as_ref().expect("floor impacts need a floor");
        let vy = self.disks.motion[i].vy;
        let elastic = self
            .restitution
            .boundary_elastic(i, now, (hd - vy).max(0.0));
        let after = floor.bounce_on(vy, hd, elastic);
        // Rebound relative to what a resting disk would do: move with the floor (exact model)
        // or stay put (fixed-position model).
        let (h, hd_ride) = floor.ride(now);
        let rests = floor.comes_to_rest(after - hd_ride, self.disks.radius[i], g, now);
        let lift = floor.max_speed();
        self.set_vy(i, after);
        self.counts.floor += 1;
        if rests {
            let mass = self.disks.mass[i];
            let a = self.disks.radius[i];
            let m = &mut self.disks.motion[i];
            self.flow.injected +=
                mass * (g * (h + a - m.y) + 0.5 * (hd_ride * hd_ride - m.vy * m.vy));
            m.y = h + a;
            m.vy = hd_ride;
            self.riders.mount_on_floor(i, a);
            self.counts.rest += 1;
            let vx = m.vx.abs();
            self.dutc.ride(now, vx + lift, g);
        }
    }

    fn pair(&mut self, i: usize, j: usize) -> Result<()> {
        let now = self.now;
        self.bring(i, now);
        self.bring(j, now);
        let rode = [self.is_riding(i), self.is_riding(j)];
        let d = &self.disks;
        let (dx, dy) = self.wrap(d.motion[i].x - d.motion[j].x, d.motion[i].y - d.motion[j].y);
        let e = self.restitution.collision(
            i,
            j,
            now,
            dx,
            dy,
            d.motion[i].vx - d.motion[j].vx,
            d.motion[i].vy - d.motion[j].vy,
        );
        // A disk landing on a rider (or a rider hit from above) is pressed onto it by gravity
        // and the floor: a rebound of at least the resting speed keeps the pair from Zeno.
        let min_rebound = if rode[0] != rode[1] {
            let floor = self.floor.as_ref().expect("riders need a floor");
            let g = self.flight.g();
            let dist = (dx * dx + dy * dy).sqrt();
            // Acceleration of i relative to j along n = (r_i − r_j)/|r_i − r_j|.
            let ride_acc = floor.ride_acceleration(now);
            let (ai, aj) = if rode[0] {
                (ride_acc, -g)
            } else {
                (-g, ride_acc)
            };
            let press = -(ai - aj) * dy / dist;
            if press > 0.0 {
                let a = self.disks.radius[i].min(self.disks.radius[j]);
                Floor::pair_rest_speed(a, press)
            } else {
                0.0
            }
        } else {
            0.0
        };
        if rode[0] != rode[1] && self.resting_contacts && min_rebound > 0.0 {
            let (k, s) = if rode[0] { (j, i) } else { (i, j) };
            if self.try_rest_on(k, s, e, min_rebound)? {
                return Ok(());
            }
        }
        // Riders leave the floor's grip for the collision; if it pushes a disk riding the floor
        // into it, the floor answers at once (sequential impulses).
        let on_floor = [
            rode[0] && self.riders.on_floor(i),
            rode[1] && self.riders.on_floor(j),
        ];
        for (k, rode) in [(i, rode[0]), (j, rode[1])] {
            if rode {
                self.riders.dismount(k);
            }
        }
        let d = &self.disks;
        let imp = collide_rebounding(
            dx,
            dy,
            d.motion[i].vx - d.motion[j].vx,
            d.motion[i].vy - d.motion[j].vy,
            d.mass[i],
            d.mass[j],
            e,
            min_rebound,
        );
        self.check_contact(i, j, imp.distance)?;
        let d = &mut self.disks;
        d.motion[i].vx += imp.dvx_i;
        d.motion[i].vy += imp.dvy_i;
        d.motion[j].vx += imp.dvx_j;
        d.motion[j].vy += imp.dvy_j;
        self.flow.dissipated += imp.energy_lost;
        self.virial += imp.distance * imp.momentum;
        self.counts.pair += 1;
        for (k, on_floor) in [(i, on_floor[0]), (j, on_floor[1])] {
            if on_floor {
                let floor = self.floor.as_ref().expect("riders need a floor");
                let (_, hd) = floor.ride(now);
                if self.disks.motion[k].vy < hd {
                    self.floor_impact(k, hd);
                }
            }
        }
        self.disks.counter[j] = self.disks.counter[j].wrapping_add(1);
        self.moved(i);
        if !self.is_riding(j) {
            let s = self.falling_speed_sq(j);
            self.dutc.observe(self.now, s);
        }
        self.predict(j);
        // What rested on them rested on disks that have now moved.
        for (k, rode) in [(i, rode[0]), (j, rode[1])] {
            if rode {
                self.release_carried(k, None);
            }
        }
        Ok(())
    }

    /// Books the overlap of disks `i` and `j` colliding at centre distance `distance`, and fails
    /// if it is beyond tolerance while the invariant checks are on.
    fn check_contact(&mut self, i: usize, j: usize, distance: f64) -> Result<()> {
        let contact = self.disks.radius[i] + self.disks.radius[j];
        let overlap = contact - distance;
        if overlap > self.max_overlap {
            self.max_overlap = overlap;
            if self.check && overlap > OVERLAP_TOLERANCE * contact {
                return Err(Error::Runtime(format!(
                    "disks {i} and {j} overlap by {overlap:e} at time {}",
                    self.time()
                )));
            }
        }
        Ok(())
    }

    /// Brings every disk to the present, re-bases the clock to it, re-maps the grid, rebuilds
    /// the neighbour lists and re-predicts every event.
    fn remap(&mut self) -> Result<()> {
        let now = self.now;
        let n = self.disks.len();
        for i in 0..n {
            self.bring(i, now);
            self.disks.motion[i].t = 0.0;
        }
        if let SideBounds::Periodic { width } = self.sides {
            for m in &mut self.disks.motion {
                m.x = into_period(m.x, width);
            }
        }
        if let Top::Periodic { height } = self.top {
            for m in &mut self.disks.motion {
                m.y = into_period(m.y, height);
            }
        }
        self.base.advance(now);
        self.now = 0.0;
        self.restitution.rebase(now);
        if let Some(floor) = &mut self.floor {
            floor.rebase(now);
        }
        // Pairs farther apart than contact + margin cannot meet before the DUTC deadline: the
        // lists keep only the closer ones (the mask guarantees every closer disk is seen).
        let margin = self.margin;
        let (disks, sides, top) = (&self.disks, self.sides, self.top);
        let geometry = &self.geometry;
        let cell = |i: usize| geometry.cell_of(disks.motion[i].x, disks.motion[i].y);
        let near = |i: usize, j: usize| {
            let (dx, dy) = wrap(
                sides,
                top,
                disks.motion[i].x - disks.motion[j].x,
                disks.motion[i].y - disks.motion[j].y,
            );
            let reach = disks.radius[i] + disks.radius[j] + margin;
            dx * dx + dy * dy <= reach * reach
        };
        self.cells
            .rebuild(geometry, &self.mask, n, cell, &mut self.lists, near)?;
        let lift = self.floor.as_ref().map_or(0.0, |f| f.max_speed());
        let speed = |i: usize| {
            if self.is_riding(i) {
                self.disks.motion[i].vx.abs() + lift
            } else {
                self.falling_speed_sq(i).sqrt()
            }
        };
        // The fastest disk, and the largest speed of the others.
        let (mut fastest, mut v1, mut v2) = (0, 0.0f64, 0.0f64);
        for i in 0..n {
            let v = speed(i);
            if v > v1 {
                (fastest, v1, v2) = (i, v, v1);
            } else {
                v2 = v2.max(v);
            }
        }
        let accel = if self.riders.any() {
            self.flight.g()
        } else {
            0.0
        };
        self.dutc = match self.isolation(fastest, v1, v2) {
            Some(clearance) => Dutc::with_isolated(margin, v2, accel, clearance, v1),
            None => Dutc::new(margin, v1, accel),
        };
        self.predict_all();
        self.counts.rebuild += 1;
        Ok(())
    }

    /// At a mapping: the gap between flying disk `f` (speed `v`) and every other disk if `f` is
    /// above all of them by more than the list margin and faster than all of them (`others` is
    /// their largest speed), so that it can get a DUTC deadline of its own; `None` otherwise.
    fn isolation(&self, f: usize, v: f64, others: f64) -> Option<f64> {
        let n = self.disks.len();
        let fast = n > 1 && !self.is_riding(f) && v > others;
        if !fast || matches!(self.top, Top::Periodic { .. }) {
            return None;
        }
        let top = (0..n)
            .filter(|&j| j != f)
            .map(|j| self.disks.motion[j].y + self.disks.radius[j])
            .fold(f64::NEG_INFINITY, f64::max);
        let clearance = self.disks.motion[f].y - self.disks.radius[f] - top;
        (clearance > self.margin).then_some(clearance)
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
        for i in 0..n {
            let (x, y, vx, vy) = self.state_at(i, local);
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
        for i in 0..self.disks.len() {
            for &j in self.lists.of(i) {
                let j = j as usize;
                let (dx, dy) = self.wrap(snap.x[i] - snap.x[j], snap.y[i] - snap.y[j]);
                let s = self.disks.radius[i] + self.disks.radius[j];
                let o = s - (dx * dx + dy * dy).sqrt();
                if o > worst.0 {
                    worst = (o, i, j);
                }
            }
        }
        worst
    }

    /// Refuses an initial state with overlaps beyond tolerance or disks outside the domain.
    fn check_initial_state(&self) -> Result<()> {
        let d = &self.disks;
        for i in 0..d.len() {
            let (x, y, a) = (d.motion[i].x, d.motion[i].y, d.radius[i]);
            let tol = OVERLAP_TOLERANCE * a;
            if !(x.is_finite()
                && y.is_finite()
                && d.motion[i].vx.is_finite()
                && d.motion[i].vy.is_finite())
            {
                return Err(Error::input(
                    "particles.placement",
                    format!("disk {i} has a non-finite position or velocity"),
                ));
            }
            if let SideBounds::Walls { width, .. } = self.sides {
                if x < a - tol || x > width - a + tol {
                    return Err(Error::input(
                        "particles.placement",
                        format!("disk {i} at x = {x} crosses a side wall"),
                    ));
                }
            }
            if let Some(f) = &self.floor {
                if y - a < f.height(0.0) - tol {
                    return Err(Error::input(
                        "particles.placement",
                        format!("disk {i} at y = {y} is below the floor"),
                    ));
                }
            }
            if let Top::Lid { height, .. } = self.top {
                if y + a > height + tol {
                    return Err(Error::input(
                        "particles.placement",
                        format!("disk {i} at y = {y} is above the lid"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Checks that no two disks overlap beyond tolerance, by brute force over all pairs within
    /// reach (O(N·neighbours), used at start and by tests).
    pub fn check_no_overlap(&self, snap: &Snapshot) -> Result<()> {
        let (o, i, j) = self.overlap_in(snap);
        let s = self.disks.radius[i] + self.disks.radius[j];
        if o > OVERLAP_TOLERANCE * s {
            return Err(Error::Runtime(format!(
                "disks {i} and {j} overlap by {o:e} at time {}",
                snap.time
            )));
        }
        Ok(())
    }
}
