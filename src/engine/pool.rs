//! Pools of live and dead disks, for scenes whose disks enter (inlets) or leave (a floor
//! orifice, an exit height at the top).
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
use crate::physics::rough::Roughness;
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
    /// Of them, those that left at the top (the exit height).
    pub top: u64,
    /// Their mass.
    pub mass_out: f64,
    /// The energy they carried out (kinetic, rotational and potential, m g y, as they left).
    pub energy_out: f64,
    /// Impacts on the orifice's corners (also counted as floor impacts).
    pub corner: u64,
    /// Disks at rest on the floor that slid over an edge of the orifice and fell.
    pub edge: u64,
    /// The energy entering disks brought in (kinetic, rotational and potential as they
    /// entered).
    pub energy_in: f64,
    /// Entries that found no free place and waited.
    pub waits: u64,
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

/// Where a disk leaves the scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outlet {
    /// Through the floor's orifice, wholly below the floor.
    Orifice,
    /// At the top, its centre at the exit height.
    Top,
}

/// One inlet resolved for the engine: the box centres enter in, the schedule of its new disks,
/// their velocities, and whether it takes leaving disks back.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InletPlan {
    /// The box: x from `x0` to `x1`, y from `y0` to `y1`.
    pub x0: f64,
    pub x1: f64,
    pub y0: f64,
    pub y1: f64,
    /// New disk j enters at `start + j·period`, for j below `total`.
    pub start: f64,
    pub period: f64,
    pub total: u64,
    /// Downward speed and temperature of the disks entering.
    pub speed: f64,
    pub temperature: f64,
    /// Leaving disks come back in here.
    pub recycle: bool,
    /// New disk j takes the id `first_id + j`.
    pub first_id: u64,
    /// The next new disk's j.
    pub next: u64,
}

/// The radii, masses and species of the disks the inlets bring, in the order of their ids
/// (drawn when the scene is built: the grid is sized for the largest and smallest of them).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Newcomers {
    /// Radius of each.
    pub radius: Vec<f64>,
    /// Mass of each.
    pub mass: Vec<f64>,
    /// Species of each (numbered in its radius law's list; 0 for a number or a uniform law).
    pub species: Vec<u32>,
}

impl Newcomers {
    /// The smallest and largest radius (`(∞, 0)` without newcomers).
    pub fn radius_range(&self) -> (f64, f64) {
        self.radius
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| {
                (lo.min(r), hi.max(r))
            })
    }
}

impl InletPlan {
    /// Absolute time of the next new disk (∞ once all have entered).
    fn due(&self) -> f64 {
        if self.next < self.total {
            self.start + self.next as f64 * self.period
        } else {
            f64::INFINITY
        }
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
    /// The inlets.
    inlets: Vec<InletPlan>,
    /// Ids that left and wait to come back through the recycling inlet, in order, with the
    /// time the first of them left.
    waiting: Vec<u32>,
    waiting_since: f64,
    /// No entry is tried before this absolute time (the last found no free place).
    blocked_until: f64,
    /// Rough disks enter spinning with this rotational temperature (`None`: smooth disks).
    rotational_temperature: Option<f64>,
    /// Random numbers drawn for entries so far, and the scene's seed (positions, velocities and
    /// spins of entering disks: a counter-based generator, so the state is two numbers).
    draws: u64,
    seed: u64,
}

impl Pool {
    /// A pool holding `disks` (every id live) and the ids of the `newcomers` the `inlets`
    /// bring; exits count for the rate from absolute time `from`. Rough disks enter spinning
    /// at `rotational_temperature`.
    pub fn new(
        disks: &Disks,
        from: f64,
        (inlets, newcomers): (&[InletPlan], &Newcomers),
        rotational_temperature: Option<f64>,
        seed: u64,
    ) -> Pool {
        let n = disks.len();
        let capacity = n + newcomers.radius.len();
        let mut all = disks.clone();
        all.motion = Vec::new();
        all.counter = Vec::new();
        all.spins = None;
        for k in 0..newcomers.radius.len() {
            all.radius.push(newcomers.radius[k]);
            all.mass.push(newcomers.mass[k]);
            all.species.push(newcomers.species[k]);
        }
        let mut engine_of = Vec::with_capacity(capacity);
        engine_of.extend(0..n as u32);
        engine_of.resize(capacity, DEAD);
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
            inlets: inlets.to_vec(),
            waiting: Vec::with_capacity(capacity),
            waiting_since: f64::INFINITY,
            blocked_until: f64::NEG_INFINITY,
            rotational_temperature,
            draws: 0,
            seed,
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
        self.view.radius.fill_from(&self.all.radius, rows());
        self.view.mass.fill_from(&self.all.mass, rows());
        self.view.species.fill_from(&self.all.species, rows());
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
        self.engine_of.len()
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

    /// Absolute time of the next entry to try (∞: none).
    pub fn next_entry(&self) -> f64 {
        let mut t = self
            .inlets
            .iter()
            .map(InletPlan::due)
            .fold(f64::INFINITY, f64::min);
        if !self.waiting.is_empty() {
            t = t.min(self.waiting_since);
        }
        t.max(self.blocked_until)
    }

    /// Ids the pool may ever hold.
    pub fn ids_capacity(&self) -> usize {
        self.all.radius.len()
    }

    /// A uniform number in [0, 1) (SplitMix64 of the seed and the draw's number).
    fn uniform(&mut self) -> f64 {
        self.draws += 1;
        let mut z = self
            .seed
            .wrapping_add(self.draws.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// The spin of a rough disk of radius `a` and mass `mass` entering (`laws`: the rough
    /// disks' laws, `None` for smooth ones), normal with variance T_rot / I, and its energy
    /// ½ I ω²; `(0, 0)` for smooth disks or no rotational temperature (and no draw).
    fn spin_for(&mut self, a: f64, mass: f64, laws: Option<&Roughness>) -> (f64, f64) {
        let (Some(laws), Some(t_rot)) = (laws, self.rotational_temperature) else {
            return (0.0, 0.0);
        };
        if t_rot == 0.0 {
            return (0.0, 0.0);
        }
        let inertia = laws.inertia_factor * mass * a * a;
        let omega = self.normal() * (t_rot / inertia).sqrt();
        (omega, 0.5 * inertia * omega * omega)
    }

    /// A standard normal number (Box–Muller).
    fn normal(&mut self) -> f64 {
        let u = 1.0 - self.uniform();
        let v = self.uniform();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        4 * (self.engine_of.capacity() + self.ids.capacity()) + self.all.bytes() + self.view.bytes()
    }
}

impl<F: Flight> Simulation<F> {
    /// Disk `i` (flying, wholly below the floor in the orifice or its centre at the exit height)
    /// leaves the scene through `outlet`: its energy and mass are booked as carried out, it
    /// waits for the recycling inlet if there is one, the last engine disk takes its number,
    /// and the grid, lists and predictions are rebuilt over the disks that remain.
    pub(super) fn leave(&mut self, i: usize, outlet: Outlet) -> crate::error::Result<()> {
        let now = self.now;
        self.bring(i, now);
        let m = &self.disks.motion[i];
        let (mass, a) = (self.disks.mass[i], self.disks.radius[i]);
        let g = self.flight.g();
        let spin = self
            .disks
            .spins
            .as_ref()
            .map_or(0.0, |s| 0.5 * s.q * mass * a * a * s.omega[i] * s.omega[i]);
        let energy = mass * (0.5 * (m.vx * m.vx + m.vy * m.vy) + g * m.y) + spin;
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
        if outlet == Outlet::Top {
            pool.flow.top += 1;
        }
        if pool.inlets.iter().any(|p| p.recycle) {
            if pool.waiting.is_empty() {
                pool.waiting_since = time;
            }
            pool.waiting.push(id as u32);
        }
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
            self.schedule_entry();
            return Ok(());
        }
        self.remap()
    }

    /// Sets the local time of the next entry from the pool (after the clock was re-based).
    pub(super) fn schedule_entry(&mut self) {
        self.control.entry = match &self.pool {
            Some(p) => {
                let t = p.next_entry();
                if t.is_finite() {
                    self.base.local(t)
                } else {
                    f64::INFINITY
                }
            }
            None => f64::INFINITY,
        };
    }

    /// The entries due now: recycled disks first, then new disks in the order of their times,
    /// each at a free place of its inlet; the first that finds none waits (and those behind
    /// it), to be tried again after a disk could have moved a diameter. Then one re-mapping
    /// takes every disk that entered into the grid and the lists.
    pub(super) fn enter_due(&mut self) -> crate::error::Result<()> {
        let t = self.base.absolute(self.now);
        let g = self.flight.g();
        let mut entered = false;
        loop {
            let pool = self.pool.as_ref().expect("entries need a pool");
            // What is due: a recycled disk (its inlet), or the inlet whose new disk is earliest.
            let recycled = (!pool.waiting.is_empty() && pool.waiting_since <= t)
                .then(|| pool.inlets.iter().position(|p| p.recycle))
                .flatten();
            let due = recycled.map(|k| (k, true)).or_else(|| {
                let (k, p) = pool
                    .inlets
                    .iter()
                    .enumerate()
                    .min_by(|a, b| a.1.due().total_cmp(&b.1.due()))?;
                (p.due() <= t).then_some((k, false))
            });
            let Some((k, recycled)) = due else {
                break;
            };
            let plan = pool.inlets[k];
            let id = if recycled {
                pool.waiting[0]
            } else {
                (plan.first_id + plan.next) as u32
            };
            let (a, mass) = (pool.all.radius[id as usize], pool.all.mass[id as usize]);
            let Some((x, y)) = self.free_place(&plan, a) else {
                let pool = self.pool.as_mut().expect("a pool");
                let clear = 2.0 * a / plan.speed.max((g * a).sqrt());
                pool.blocked_until = t + clear;
                pool.flow.waits += 1;
                break;
            };
            let pool = self.pool.as_mut().expect("a pool");
            let sigma = (plan.temperature / mass).sqrt();
            let vx = sigma * pool.normal();
            let vy = -plan.speed + sigma * pool.normal();
            if recycled {
                pool.waiting.remove(0);
                if !pool.waiting.is_empty() {
                    pool.waiting_since = t;
                }
            } else {
                pool.inlets[k].next += 1;
            }
            let spin = pool.spin_for(a, mass, self.friction.as_ref());
            pool.flow.entered += 1;
            pool.flow.energy_in += mass * (0.5 * (vx * vx + vy * vy) + g * y) + spin.1;
            self.insert_disk(id, [x, y, vx, vy], spin.0);
            entered = true;
        }
        if entered {
            self.remap()?;
        }
        self.schedule_entry();
        Ok(())
    }

    /// A place in `plan`'s box where a disk of radius `a` overlaps no disk now (up to 64 draws).
    fn free_place(&mut self, plan: &InletPlan, a: f64) -> Option<(f64, f64)> {
        let now = self.now;
        for _ in 0..64 {
            let pool = self.pool.as_mut().expect("a pool");
            let x = plan.x0 + (plan.x1 - plan.x0) * pool.uniform();
            let y = plan.y0 + (plan.y1 - plan.y0) * pool.uniform();
            let free = (0..self.disks.len()).all(|k| {
                let (xk, yk, _, _) = self.state_at(k, now);
                let (dx, dy) = self.wrap(x - xk, y - yk);
                let s = (a + self.disks.radius[k]) * (1.0 + 1e-6);
                dx * dx + dy * dy > s * s
            });
            if free {
                return Some((x, y));
            }
        }
        None
    }

    /// Disk `id` enters now at `[x, y, vx, vy]` (spinning at `omega` if rough, at orientation
    /// 0) as engine disk n (the arrays grow by one within the capacity reserved at the start);
    /// the re-mapping that follows files it everywhere.
    fn insert_disk(&mut self, id: u32, [x, y, vx, vy]: [f64; 4], omega: f64) {
        let n = self.disks.len();
        let now = self.now;
        let pool = self.pool.as_ref().expect("a pool");
        let (a, mass, species) = (
            pool.all.radius[id as usize],
            pool.all.mass[id as usize],
            pool.all.species[id as usize],
        );
        let d = &mut self.disks;
        if let Some(s) = d.spins.as_mut() {
            s.omega.push(omega);
            s.phase.push(-omega * now);
        }
        d.motion.push(crate::physics::disks::Motion {
            x,
            y,
            vx,
            vy,
            t: now,
        });
        d.radius.push(a);
        d.mass.push(mass);
        d.species.push(species);
        d.counter.push(0);
        self.map.numbering.push(id);
        self.restitution.push();
        self.rest.riders.push();
        if !self.rest.same_instant.is_empty() {
            self.rest.same_instant.push((f64::NAN, 0));
        }
        if !self.rest.in_cluster.is_empty() {
            self.rest.in_cluster.push(false);
        }
        if let Some(sh) = self.map.shells.as_mut() {
            sh.push([x, y]);
        }
        let ev = &mut self.events;
        ev.time[n] = f64::INFINITY;
        ev.time.push(f64::INFINITY);
        ev.code.push(super::event::code::NONE);
        ev.counter.push(0);
        let pool = self.pool.as_mut().expect("a pool");
        pool.engine_of[id as usize] = n as u32;
        pool.stale = true;
    }

    /// The pool of live and dead disks, in scenes whose disks may leave.
    pub fn pool(&self) -> Option<&Pool> {
        self.pool.as_deref()
    }
}
