//! The space-time scheme (ReMoDy): every disk has its own time and is moved straight (or on its
//! parabola) to its next predicted collision, computed with the crate's exact pair, wall, lid and
//! floor formulas — but only against candidate partners from the linked cells around it, and
//! never past the global synchronisation time `t_sync + D/v` (D a few mean free paths, v the
//! largest speed). At each synchronisation every disk is brought to that time, the cells (side a
//! few mean free paths, at least a diameter) are rebuilt and every disk is predicted anew.
//!
//! The approximation: a partner that is not in a neighbouring cell at the synchronisation is not
//! a candidate until the next one, so a disk that travels farther than the cells reach within one
//! synchronisation step can pass through it (a missed collision) or be found overlapping it later
//! (a late collision, resolved at once if the pair approaches). As D shrinks the cells' reach
//! covers every partner a disk can meet, and the scheme becomes the exact engine without DUTC.
//!
//! The scheme has no state for a disk resting on the floor: an inelastic disk whose rebound
//! would be negligible (it would come to rest in the exact engine) instead hops
//! [`REST_HOP`] radii, which ends the infinite sequence of ever smaller bounces.
//!
//! Rough disks get the exact engine's tangential kick after the normal part of every collision
//! and bounce (a hop included).
//!
//! On several threads ([`Cores`]) the synchronisation is shared among them: bringing the disks
//! to its time, the candidate pairs and the prediction of every disk (each thread writes only
//! its own disks' predictions; they are queued in the order of the disks). The events between
//! two synchronisations run one after the other, in time order, on one thread: an event changes
//! what its disks' neighbours predict next.
//!
//! With `engine.strips` = S > 1 the columns of cells are cut into S vertical strips of equal
//! width (set by the scene, not by the threads), and each strip runs its own event loop through
//! the step on whichever thread takes it. A pair whose cells lie in two strips is not a
//! candidate within the step: if its disks meet, they are found overlapping at the next
//! synchronisation, where the borders have moved by half a strip, so the pair is a candidate
//! again and collides at once if it approaches (a late collision, counted as missed). The
//! strips' disks are copies, numbered in the order of their numbers in the scene; their tallies
//! (counts, energy, virial) are added in the order of the strips, so the results do not depend
//! on the threads. One strip is the undivided scheme: one event loop over every cell.

use super::cells::CellList;
use super::cores::{Cores, MIN_PIECE};
use super::rough::Rub;
use super::{free_flight_visit, min_image, wrap, Integrator, SchemeStats, Setup};
use crate::engine::{EnergyFlow, EventCounts, Progress, Scene};
use crate::error::{Error, Result};
use crate::physics::disks::{Disks, Motion};
use crate::physics::flight::Flight;
use crate::physics::floor::{Floor, FloorEvent};
use crate::physics::pair::{collide, contact_time};
use crate::physics::restitution::CollisionLaw;
use crate::physics::rough::Boundary;
use crate::physics::walls::{Side, SideBounds, Top};
use crate::scenario::Engine;
use rayon::prelude::*;
use std::cmp::Ordering as CmpOrdering;
use std::collections::{BinaryHeap, HashSet};
use std::sync::atomic::{AtomicBool, Ordering};

/// Default synchronisation distance D, in units of the smallest radius (three diameters).
pub const DEFAULT_SYNC_DISTANCE: f64 = 6.0;

/// Default reach of the cells beyond contact, in units of the smallest radius: the cell side is
/// `2 a_max + 3 a_min` unless `engine.cell_size` says otherwise. It does not follow D, so that
/// the scheme converges as D shrinks (a disk then cannot outrun the cells' reach before the next
/// synchronisation).
pub const DEFAULT_CELL_MARGIN: f64 = 3.0;

/// Height, in radii, of the smallest hop of a disk on the floor (see the module notes).
pub const REST_HOP: f64 = 1e-4;

/// Overlap (relative to the contact distance) beyond which a pair counts as overlapping.
const OVERLAP_TOLERANCE: f64 = 1e-9;

/// Event partner codes beyond the disk numbers.
const NONE: u32 = u32::MAX;
const LEFT: u32 = u32::MAX - 1;
const RIGHT: u32 = u32::MAX - 2;
const LID: u32 = u32::MAX - 3;
const FLOOR: u32 = u32::MAX - 4;
const RECHECK: u32 = u32::MAX - 5;

/// A queued event: its time, the disk, and the disk's prediction number when it was queued.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Queued {
    time: f64,
    disk: u32,
    seq: u32,
}

impl Eq for Queued {}

impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<CmpOrdering> {
        Some(self.cmp(other))
    }
}

impl Ord for Queued {
    /// Reversed, so that the max-heap yields the earliest event.
    fn cmp(&self, other: &Self) -> CmpOrdering {
        other
            .time
            .total_cmp(&self.time)
            .then_with(|| other.disk.cmp(&self.disk))
    }
}

/// The space-time engine.
#[derive(Debug)]
pub struct SpaceTime<F: Flight> {
    flight: F,
    disks: Disks,
    sides: SideBounds,
    top: Top,
    floor: Option<Floor>,
    restitution: CollisionLaw,
    sync_distance: f64,
    cell: f64,
    cells: CellList,
    start: Vec<u32>,
    partners: Vec<u32>,
    /// The event loops, one per strip; strip 0 also carries the tallies of the steps before.
    strips: Vec<Strip<F>>,
    /// With one strip: whether it holds the disks and the law (they are moved, not copied).
    lent: bool,
    /// Each disk's number within its strip (several strips only).
    local: Vec<u32>,
    overlapping: HashSet<(u32, u32)>,
    now: f64,
    sync_end: f64,
    counts: EventCounts,
    flow: EnergyFlow,
    virial: f64,
    max_overlap: f64,
    stats: SchemeStats,
    event_limit: u64,
    interrupt: Option<&'static AtomicBool>,
    cores: Cores,
}

/// One strip's event loop over a synchronisation step: its disks (numbered from 0 in the order
/// of their numbers in the scene), their candidates, predictions and queue, its clock and its
/// tallies. With one strip it is the whole scene.
#[derive(Debug)]
struct Strip<F: Flight> {
    flight: F,
    sides: SideBounds,
    top: Top,
    floor: Option<Floor>,
    rub: Rub,
    restitution: CollisionLaw,
    disks: Disks,
    /// The strip's disks by their numbers in the scene (several strips only).
    ids: Vec<u32>,
    start: Vec<u32>,
    partners: Vec<u32>,
    ev_time: Vec<f64>,
    ev_partner: Vec<u32>,
    ev_counter: Vec<u32>,
    seq: Vec<u32>,
    queue: BinaryHeap<Queued>,
    now: f64,
    sync_end: f64,
    counts: EventCounts,
    flow: EnergyFlow,
    virial: f64,
    max_overlap: f64,
    overlapped_collisions: u64,
    deep_overlaps: u64,
    event_limit: u64,
    interrupt: Option<&'static AtomicBool>,
}

/// A disk's next event: its time, its partner (a disk's number or one of the codes beyond),
/// and the partner's collision counter when it was predicted.
#[derive(Debug, Clone, Copy)]
struct Next {
    time: f64,
    who: u32,
    counter: u32,
}

/// Fewest columns of cells in a strip: a pair across a border is then inside a strip after the
/// borders shift by half a strip, unless it moved two columns in one step.
pub const MIN_STRIP_COLUMNS: usize = 4;

impl<F: Flight> SpaceTime<F> {
    /// Sets up the scheme for `scene` with its knobs from `engine` (`sync_distance`,
    /// `cell_size`, `strips`, `threads`).
    pub fn new(flight: F, scene: &Scene, disks: Disks, engine: &Engine) -> Result<SpaceTime<F>> {
        let n = disks.len();
        let (a_min, a_max) = disks.radius_range();
        let sync_distance = engine.sync_distance.unwrap_or(DEFAULT_SYNC_DISTANCE) * a_min;
        let cell = match engine.cell_size {
            Some(c) if c * a_min < 2.0 * a_max => {
                return Err(Error::input(
                    "engine.cell_size",
                    format!(
                        "must be at least the largest diameter ({:.4} radii)",
                        2.0 * a_max / a_min
                    ),
                ))
            }
            Some(c) => c * a_min,
            None => 2.0 * a_max + DEFAULT_CELL_MARGIN * a_min,
        };
        let strips = engine.strips.unwrap_or(1) as usize;
        if strips > 1 {
            let columns = CellList::columns_for(n, cell, scene.sides);
            let most = columns / MIN_STRIP_COLUMNS;
            if strips > most {
                return Err(Error::input(
                    "engine.strips",
                    format!(
                        "at most {} for this scene: its {columns} columns of cells, at least \
                         {MIN_STRIP_COLUMNS} to a strip (got {strips})",
                        most.max(1)
                    ),
                ));
            }
        }
        let restitution = CollisionLaw::new(scene.restitution, n);
        let event_limit = scene.max_events.unwrap_or(u64::MAX);
        let strip = Strip::empty(
            flight,
            (scene.sides, scene.top, scene.floor.clone()),
            (Rub::new(scene.rough), CollisionLaw::new(restitution.law, 0)),
            event_limit,
        );
        let mut st = SpaceTime {
            flight,
            disks,
            sides: scene.sides,
            top: scene.top,
            floor: scene.floor.clone(),
            restitution,
            sync_distance,
            cell,
            cells: CellList::default(),
            start: Vec::new(),
            partners: Vec::new(),
            strips: (0..strips).map(|_| strip.clone_empty()).collect(),
            lent: false,
            local: Vec::new(),
            overlapping: HashSet::new(),
            now: 0.0,
            sync_end: 0.0,
            counts: EventCounts::default(),
            flow: EnergyFlow::default(),
            virial: 0.0,
            max_overlap: 0.0,
            stats: SchemeStats::default(),
            event_limit,
            interrupt: None,
            cores: Cores::new(engine.threads)?,
        };
        if strips == 1 {
            st.strips[0].ev_time = vec![f64::INFINITY; n];
            st.strips[0].ev_partner = vec![NONE; n];
            st.strips[0].ev_counter = vec![0; n];
            st.strips[0].seq = vec![0; n];
        }
        for m in &mut st.disks.motion {
            m.t = 0.0;
        }
        st.cores.clone().run(|| st.synchronise());
        st.home();
        st.stats.missed = 0; // overlaps present at the start are the placement's, not missed
        Ok(st)
    }

    /// Moves (one strip) or copies (several) the disks and the law's record back from the
    /// strips.
    fn home(&mut self) {
        if self.strips.len() == 1 {
            if self.lent {
                let strip = &mut self.strips[0];
                std::mem::swap(&mut self.disks, &mut strip.disks);
                std::mem::swap(&mut self.restitution, &mut strip.restitution);
                self.lent = false;
            }
        } else {
            for strip in &self.strips {
                self.disks.scatter(&strip.disks, &strip.ids);
                self.restitution.scatter(&strip.restitution, &strip.ids);
            }
        }
    }

    /// Hands the disks and the law's record to the one strip (several keep their copies).
    fn lend(&mut self) {
        if self.strips.len() == 1 && !self.lent {
            let strip = &mut self.strips[0];
            std::mem::swap(&mut self.disks, &mut strip.disks);
            std::mem::swap(&mut self.restitution, &mut strip.restitution);
            self.lent = true;
        }
    }

    /// The totals: strip 0's (which carry those of the steps before) and then each other
    /// strip's, added in the order of the strips whatever thread ran them.
    fn tally(&mut self) {
        let (first, rest) = self.strips.split_first().expect("at least one strip");
        let mut counts = first.counts;
        let mut flow = first.flow;
        let mut virial = first.virial;
        let mut overlapped = first.overlapped_collisions;
        let mut deep = first.deep_overlaps;
        let mut worst = self.max_overlap.max(first.max_overlap);
        for s in rest {
            counts += s.counts;
            flow.injected += s.flow.injected;
            flow.dissipated += s.flow.dissipated;
            flow.floor_impulse += s.flow.floor_impulse;
            virial += s.virial;
            overlapped += s.overlapped_collisions;
            deep += s.deep_overlaps;
            worst = worst.max(s.max_overlap);
        }
        self.counts = counts;
        self.flow = flow;
        self.virial = virial;
        self.stats.overlapped_collisions = overlapped;
        self.stats.deep_overlaps = deep;
        self.max_overlap = worst;
    }

    /// Brings every disk to the synchronisation time, rebuilds the cells and candidate lists,
    /// counts the pairs found overlapping, chooses the next synchronisation time and predicts
    /// every disk.
    fn synchronise(&mut self) {
        self.home();
        self.tally();
        let now = self.now;
        let (flight, sides, top) = (self.flight, self.sides, self.top);
        self.disks
            .motion
            .par_iter_mut()
            .with_min_len(MIN_PIECE)
            .for_each(|m| {
                let (x, y, vx, vy) = flight.advance(m.x, m.y, m.vx, m.vy, now - m.t);
                let (x, y) = wrap(sides, top, x, y);
                *m = Motion {
                    x,
                    y,
                    vx,
                    vy,
                    t: now,
                };
            });
        let n = self.disks.len();
        let motion = &self.disks.motion;
        self.cells.build(
            n,
            |i| (motion[i].x, motion[i].y),
            self.cell,
            self.sides,
            self.top,
        );
        self.sync_end = now + self.sync_step();
        self.counts.rebuild += 1;
        self.stats.steps += 1;
        // Strip 0 carries the totals; the others count from zero and are added after it.
        let base = self.counts.popped();
        for (k, strip) in self.strips.iter_mut().enumerate() {
            strip.now = now;
            strip.sync_end = self.sync_end;
            strip.queue.clear();
            if k == 0 {
                strip.counts = self.counts;
                strip.flow = self.flow;
                strip.virial = self.virial;
                strip.overlapped_collisions = self.stats.overlapped_collisions;
                strip.deep_overlaps = self.stats.deep_overlaps;
                strip.event_limit = self.event_limit;
            } else {
                strip.counts = EventCounts::default();
                strip.flow = EnergyFlow::default();
                strip.virial = 0.0;
                strip.overlapped_collisions = 0;
                strip.deep_overlaps = 0;
                strip.event_limit = self.event_limit.saturating_sub(base);
            }
            strip.max_overlap = 0.0;
            strip.interrupt = self.interrupt;
        }
        if self.strips.len() == 1 {
            self.candidates();
            self.lend();
            let strip = &mut self.strips[0];
            strip.start = std::mem::take(&mut self.start);
            strip.partners = std::mem::take(&mut self.partners);
            let next: Vec<Option<Next>> = (0..n)
                .into_par_iter()
                .with_min_len(MIN_PIECE)
                .map(|i| strip.next_event(i))
                .collect();
            for (i, next) in next.into_iter().enumerate() {
                strip.schedule(i, next);
            }
        } else {
            self.split();
        }
    }

    /// Cuts the cells into the strips (shifted by half a strip at every other synchronisation)
    /// and sets each strip up on the threads: its disks, its candidates (pairs of disks in its
    /// own cells only) and their predictions; counts the pairs found overlapping, those across
    /// the borders included.
    fn split(&mut self) {
        let s = self.strips.len();
        let nx = self.cells.columns();
        let shift = if self.stats.steps.is_multiple_of(2) {
            nx / (2 * s)
        } else {
            0
        };
        let columns: Vec<Vec<usize>> = (0..s)
            .map(|k| {
                (k * nx / s..(k + 1) * nx / s)
                    .map(|c| (c + shift) % nx)
                    .collect()
            })
            .collect();
        let mut group = vec![0u32; nx];
        for (k, cols) in columns.iter().enumerate() {
            for &c in cols {
                group[c] = k as u32;
            }
        }
        let cells = &self.cells;
        let members: Vec<Vec<u32>> = columns
            .par_iter()
            .map(|cols| {
                let mut ids = Vec::new();
                cells.for_each_disk_in_columns(cols, |i| ids.push(i as u32));
                ids.sort_unstable();
                ids
            })
            .collect();
        self.local.resize(self.disks.len(), 0);
        for ids in &members {
            for (k, &g) in ids.iter().enumerate() {
                self.local[g as usize] = k as u32;
            }
        }
        let (disks, law, local) = (&self.disks, &self.restitution, &self.local);
        let overlaps: Vec<Vec<(u32, u32, f64)>> = self
            .strips
            .par_iter_mut()
            .zip(members)
            .zip(&columns)
            .map(|((strip, ids), cols)| strip.load(ids, cols, &group, local, cells, disks, law))
            .collect();
        let mut overlapping = HashSet::new();
        for &(i, j, overlap) in overlaps.iter().flatten() {
            self.max_overlap = self.max_overlap.max(overlap);
            overlapping.insert((i, j));
        }
        self.stats.missed += overlapping.difference(&self.overlapping).count() as u64;
        self.overlapping = overlapping;
    }

    /// Rebuilds every disk's candidate partners from the cells (symmetric lists in CSR form);
    /// counts the pairs found overlapping that were not at the last synchronisation.
    fn candidates(&mut self) {
        let n = self.disks.len();
        let motion = &self.disks.motion;
        let (sides, top, radius) = (self.sides, self.top, &self.disks.radius);
        // Every candidate pair, with its overlap where the disks overlap.
        let pairs: Vec<(u32, u32, Option<f64>)> = self.cells.pairs_where(|i, j| {
            Some((
                i as u32,
                j as u32,
                overlap(sides, top, motion, radius, i, j),
            ))
        });
        let mut start = vec![0u32; n + 1];
        for &(i, j, _) in &pairs {
            start[i as usize + 1] += 1;
            start[j as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut partners = vec![0u32; start[n] as usize];
        let mut overlapping = HashSet::new();
        let mut worst = 0.0f64;
        for &(i, j, overlap) in &pairs {
            partners[fill[i as usize] as usize] = j;
            fill[i as usize] += 1;
            partners[fill[j as usize] as usize] = i;
            fill[j as usize] += 1;
            if let Some(overlap) = overlap {
                worst = worst.max(overlap);
                overlapping.insert((i.min(j), i.max(j)));
            }
        }
        self.max_overlap = self.max_overlap.max(worst);
        self.stats.missed += overlapping.difference(&self.overlapping).count() as u64;
        self.overlapping = overlapping;
        self.start = start;
        self.partners = partners;
    }

    /// The synchronisation step: D over the largest speed (at least the floor's and that of a
    /// fall through one radius).
    fn sync_step(&self) -> f64 {
        let (a_min, _) = self.disks.radius_range();
        let v_disks = self
            .disks
            .motion
            .par_iter()
            .with_min_len(MIN_PIECE)
            .map(|m| m.vx * m.vx + m.vy * m.vy)
            .reduce(|| 0.0f64, f64::max)
            .sqrt();
        let v = v_disks
            .max(
                self.floor
                    .as_ref()
                    .map_or(0.0, |f| f.drive().peak_velocity()),
            )
            .max((self.flight.g() * a_min).sqrt());
        if v > 0.0 {
            self.sync_distance / v
        } else {
            f64::INFINITY
        }
    }

    /// Runs events and synchronisations up to absolute time `target`.
    fn run_to(&mut self, target: f64) -> Result<Progress> {
        self.lend();
        let progress = self.steps_to(target);
        self.home();
        self.tally();
        progress
    }

    fn steps_to(&mut self, target: f64) -> Result<Progress> {
        loop {
            // A synchronisation costs O(N): the flag is looked at before each.
            if self
                .interrupt
                .is_some_and(|flag| flag.load(Ordering::Relaxed))
            {
                return Ok(Progress::Interrupted);
            }
            if self.sync_end <= target {
                if let Some(p) = self.run_events(self.sync_end)? {
                    return Ok(p);
                }
                self.now = self.sync_end;
                self.synchronise();
                self.stats.step = self.now / self.stats.steps.saturating_sub(1).max(1) as f64;
            } else {
                if let Some(p) = self.run_events(target)? {
                    return Ok(p);
                }
                self.now = self.now.max(target);
                for strip in &mut self.strips {
                    strip.now = strip.now.max(target);
                }
                return Ok(Progress::Reached);
            }
        }
    }

    /// Runs every strip's events before `until` (at most the synchronisation time), the strips
    /// on the threads; the first strip (in their order) that stopped early says why.
    fn run_events(&mut self, until: f64) -> Result<Option<Progress>> {
        if let [strip] = &mut self.strips[..] {
            return strip.run_events(until);
        }
        let stops: Vec<Result<Option<Progress>>> = self
            .strips
            .par_iter_mut()
            .map(|strip| strip.run_events(until))
            .collect();
        for stop in stops {
            if let Some(p) = stop? {
                return Ok(Some(p));
            }
        }
        Ok(None)
    }
}

/// The overlap of disks `i` and `j` where they overlap (by more than the tolerance).
#[inline]
fn overlap(
    sides: SideBounds,
    top: Top,
    motion: &[Motion],
    radius: &crate::physics::disks::PerDisk<f64>,
    i: usize,
    j: usize,
) -> Option<f64> {
    let (dx, dy) = min_image(
        sides,
        top,
        motion[i].x - motion[j].x,
        motion[i].y - motion[j].y,
    );
    let s = radius[i] + radius[j];
    let d2 = dx * dx + dy * dy;
    (d2 < s * s && s - d2.sqrt() > OVERLAP_TOLERANCE * s).then(|| s - d2.sqrt())
}

impl<F: Flight> Strip<F> {
    /// A strip of the same scene, without disks.
    fn clone_empty(&self) -> Strip<F> {
        Strip::empty(
            self.flight,
            (self.sides, self.top, self.floor.clone()),
            (self.rub, self.restitution.clone()),
            self.event_limit,
        )
    }

    /// A strip of a scene's flight, boundaries (sides, top, floor) and contact laws (friction,
    /// restitution), without disks.
    fn empty(
        flight: F,
        (sides, top, floor): (SideBounds, Top, Option<Floor>),
        (rub, restitution): (Rub, CollisionLaw),
        event_limit: u64,
    ) -> Strip<F> {
        Strip {
            flight,
            sides,
            top,
            floor,
            rub,
            restitution,
            disks: Disks::default(),
            ids: Vec::new(),
            start: Vec::new(),
            partners: Vec::new(),
            ev_time: Vec::new(),
            ev_partner: Vec::new(),
            ev_counter: Vec::new(),
            seq: Vec::new(),
            queue: BinaryHeap::new(),
            now: 0.0,
            sync_end: 0.0,
            counts: EventCounts::default(),
            flow: EnergyFlow::default(),
            virial: 0.0,
            max_overlap: 0.0,
            overlapped_collisions: 0,
            deep_overlaps: 0,
            event_limit,
            interrupt: None,
        }
    }

    /// Takes disks `ids` (in the order of their numbers) from `all`, with the law's record of
    /// them; makes their candidates the pairs in the strip's cells (`columns`, of group
    /// `group[column]`) and predicts every disk. Returns every pair found overlapping among
    /// the pairs its cells visit (those across a border included), by the disks' numbers in
    /// the scene, with its overlap.
    #[allow(clippy::too_many_arguments)]
    fn load(
        &mut self,
        ids: Vec<u32>,
        columns: &[usize],
        group: &[u32],
        local: &[u32],
        cells: &CellList,
        all: &Disks,
        law: &CollisionLaw,
    ) -> Vec<(u32, u32, f64)> {
        let n = ids.len();
        let (sides, top, motion, radius) = (self.sides, self.top, &all.motion, &all.radius);
        let mut pairs = Vec::new();
        let mut overlapping = Vec::new();
        cells.for_each_pair_in_columns(columns, group, |i, j, same| {
            if let Some(o) = overlap(sides, top, motion, radius, i, j) {
                let (i, j) = (i as u32, j as u32);
                overlapping.push((i.min(j), i.max(j), o));
            }
            if same {
                pairs.push((local[i], local[j]));
            }
        });
        let mut start = std::mem::take(&mut self.start);
        start.clear();
        start.resize(n + 1, 0);
        for &(i, j) in &pairs {
            start[i as usize + 1] += 1;
            start[j as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut partners = std::mem::take(&mut self.partners);
        partners.clear();
        partners.resize(start[n] as usize, 0);
        for &(i, j) in &pairs {
            partners[fill[i as usize] as usize] = j;
            fill[i as usize] += 1;
            partners[fill[j as usize] as usize] = i;
            fill[j as usize] += 1;
        }
        self.start = start;
        self.partners = partners;
        self.disks = all.gather(&ids);
        self.restitution = law.gather(&ids);
        self.ids = ids;
        self.ev_time.clear();
        self.ev_time.resize(n, f64::INFINITY);
        self.ev_partner.clear();
        self.ev_partner.resize(n, NONE);
        self.ev_counter.clear();
        self.ev_counter.resize(n, 0);
        self.seq.clear();
        self.seq.resize(n, 0);
        for i in 0..n {
            self.predict(i);
        }
        overlapping
    }

    /// Bytes held beyond the disks the scheme holds itself (a strip's copies of them
    /// included, when there are several).
    fn bytes(&self) -> usize {
        let copies = if self.ids.is_empty() {
            0
        } else {
            self.disks.bytes() + self.restitution.bytes()
        };
        copies
            + 4 * (self.ids.capacity() + self.start.capacity() + self.partners.capacity())
            + 8 * self.ev_time.capacity()
            + 4 * (self.ev_partner.capacity() + self.ev_counter.capacity() + self.seq.capacity())
            + 24 * self.queue.capacity()
    }

    /// State of disk `i` at time `t` (on its flight from its own time stamp).
    #[inline(always)]
    fn state_at(&self, i: usize, t: f64) -> (f64, f64, f64, f64) {
        let m = &self.disks.motion[i];
        self.flight.advance(m.x, m.y, m.vx, m.vy, t - m.t)
    }

    #[inline(always)]
    fn bring(&mut self, i: usize, t: f64) {
        let (x, y, vx, vy) = self.state_at(i, t);
        self.disks.motion[i] = Motion { x, y, vx, vy, t };
    }

    fn of(&self, i: usize) -> &[u32] {
        &self.partners[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Finds disk `i`'s earliest event from now (disk `i` is at now) and queues it if it comes
    /// before the synchronisation.
    fn predict(&mut self, i: usize) {
        let next = self.next_event(i);
        self.schedule(i, next);
    }

    /// Disk `i`'s earliest event from now (disk `i` is at now), if it comes before the
    /// synchronisation.
    fn next_event(&self, i: usize) -> Option<Next> {
        let now = self.now;
        let limit = self.sync_end;
        let (xi, yi, vxi, vyi) = self.state_at(i, now);
        let speed_i = vxi.abs() + vyi.abs();
        let ai = self.disks.radius[i];
        let mut best = f64::INFINITY;
        let mut who = NONE;
        for &j in self.of(i) {
            let j = j as usize;
            let (xj, yj, vxj, vyj) = self.state_at(j, now);
            let (dx, dy) = min_image(self.sides, self.top, xi - xj, yi - yj);
            let speed = speed_i + vxj.abs() + vyj.abs();
            let s = ai + self.disks.radius[j];
            if let Some(dt) = contact_time(dx, dy, vxi - vxj, vyi - vyj, s, speed) {
                if dt < best {
                    best = dt;
                    who = j as u32;
                }
            }
        }
        let mut counter = if who != NONE {
            self.disks.counter[who as usize]
        } else {
            0
        };
        if let Some((dt, side)) = self.sides.impact(xi, vxi, ai) {
            if dt < best {
                best = dt;
                who = if side == Side::Left { LEFT } else { RIGHT };
            }
        }
        let g = self.flight.g();
        if let Some(dt) = self.top.impact(yi, vyi, ai, g) {
            if dt < best {
                best = dt;
                who = LID;
            }
        }
        let mut t = now + best;
        if let Some(floor) = &self.floor {
            match floor.next_event(yi, vyi, ai, g, now, t.min(limit)) {
                Some(FloorEvent::Impact(tf)) if tf < t => {
                    t = tf;
                    who = FLOOR;
                }
                Some(FloorEvent::Recheck(tf)) if tf < t => {
                    t = tf;
                    who = RECHECK;
                }
                _ => {}
            }
        }
        if who >= RECHECK {
            counter = 0;
        }
        (t <= limit).then_some(Next {
            time: t,
            who,
            counter,
        })
    }

    /// Makes `next` disk `i`'s event (superseding its earlier one), and queues it.
    fn schedule(&mut self, i: usize, next: Option<Next>) {
        self.seq[i] = self.seq[i].wrapping_add(1);
        match next {
            Some(Next { time, who, counter }) => {
                self.ev_time[i] = time;
                self.ev_partner[i] = who;
                self.ev_counter[i] = counter;
                self.queue.push(Queued {
                    time,
                    disk: i as u32,
                    seq: self.seq[i],
                });
            }
            None => {
                self.ev_time[i] = f64::INFINITY;
                self.ev_partner[i] = NONE;
            }
        }
    }

    /// Runs the events before `until` (at most the synchronisation time).
    fn run_events(&mut self, until: f64) -> Result<Option<Progress>> {
        while let Some(&q) = self.queue.peek() {
            if q.time >= until {
                break;
            }
            self.queue.pop();
            let i = q.disk as usize;
            if q.seq != self.seq[i] {
                continue; // superseded prediction
            }
            if self.counts.popped() >= self.event_limit {
                return Ok(Some(Progress::EventLimit));
            }
            if self.counts.popped() & 0xfff == 0 {
                if let Some(flag) = self.interrupt {
                    if flag.load(Ordering::Relaxed) {
                        return Ok(Some(Progress::Interrupted));
                    }
                }
            }
            self.now = q.time.max(self.now);
            self.fire(i);
        }
        Ok(None)
    }

    fn fire(&mut self, i: usize) {
        let now = self.now;
        let who = self.ev_partner[i];
        match who {
            LEFT | RIGHT => {
                self.bring(i, now);
                let side = if who == LEFT { Side::Left } else { Side::Right };
                let (m, mass) = (&mut self.disks.motion[i], self.disks.mass[i]);
                let before = (m.vx, m.vy);
                self.flow.dissipated +=
                    self.sides.hit(side, &mut self.restitution, i, now, m, mass);
                let wall = Boundary::side(side);
                self.flow.dissipated +=
                    self.rub
                        .boundary(&mut self.disks, i, wall, (0.0, 0.0), before, now);
                self.counts.wall += 1;
                self.moved(i);
            }
            LID => {
                self.bring(i, now);
                let (m, mass) = (&mut self.disks.motion[i], self.disks.mass[i]);
                let before = (m.vx, m.vy);
                self.flow.dissipated += self.top.hit(&mut self.restitution, i, now, m, mass);
                self.flow.dissipated +=
                    self.rub
                        .boundary(&mut self.disks, i, Boundary::Lid, (0.0, 0.0), before, now);
                self.counts.lid += 1;
                self.moved(i);
            }
            FLOOR => {
                self.bring(i, now);
                let floor = self.floor.as_ref().expect("floor events need a floor");
                let g = self.flight.g();
                let a = self.disks.radius[i];
                let before = self.disks.motion[i].vy;
                let hd = floor.velocity(now);
                let mut after = floor.hit(&mut self.restitution, i, now, before, hd);
                if floor.comes_to_rest(after - hd, a, g, now) {
                    let (_, hd_ride) = floor.ride(now);
                    after = hd_ride + (2.0 * g * REST_HOP * a).sqrt();
                    self.counts.rest += 1;
                }
                self.flow.floor_work(self.disks.mass[i], before, after);
                let vx = self.disks.motion[i].vx;
                self.disks.motion[i].vy = after;
                self.flow.dissipated += self.rub.boundary(
                    &mut self.disks,
                    i,
                    Boundary::Floor,
                    (0.0, hd),
                    (vx, before),
                    now,
                );
                self.counts.floor += 1;
                self.moved(i);
            }
            RECHECK => {
                self.counts.recheck += 1;
                self.bring(i, now);
                self.predict(i);
            }
            NONE => {}
            j => {
                let j = j as usize;
                if self.disks.counter[j] != self.ev_counter[i] {
                    self.counts.stale += 1;
                    self.bring(i, now);
                    self.predict(i);
                    return;
                }
                self.pair(i, j);
            }
        }
    }

    fn moved(&mut self, i: usize) {
        self.disks.counter[i] = self.disks.counter[i].wrapping_add(1);
        self.predict(i);
    }

    fn pair(&mut self, i: usize, j: usize) {
        let now = self.now;
        self.bring(i, now);
        self.bring(j, now);
        let d = &self.disks;
        let (mi, mj) = (d.motion[i], d.motion[j]);
        let (dx, dy) = min_image(self.sides, self.top, mi.x - mj.x, mi.y - mj.y);
        let (dvx, dvy) = (mi.vx - mj.vx, mi.vy - mj.vy);
        let s = d.radius[i] + d.radius[j];
        let e = self.restitution.collision(i, j, now, dx, dy, dvx, dvy);
        let imp = collide(dx, dy, dvx, dvy, d.mass[i], d.mass[j], e);
        let overlap = s - imp.distance;
        if overlap > OVERLAP_TOLERANCE * s {
            self.overlapped_collisions += 1;
            self.max_overlap = self.max_overlap.max(overlap);
            if overlap > super::time_step::DEEP_OVERLAP * s {
                self.deep_overlaps += 1;
            }
        }
        imp.apply(&mut self.disks.motion, i, j);
        self.flow.dissipated += imp.energy_lost;
        self.flow.dissipated +=
            self.rub
                .pair(&mut self.disks, (i, j), (dx, dy), (dvx, dvy), &imp, now);
        self.virial += imp.distance * imp.momentum;
        self.counts.pair += 1;
        self.disks.counter[j] = self.disks.counter[j].wrapping_add(1);
        self.moved(i);
        self.predict(j);
    }
}

impl<F: Flight> Integrator for SpaceTime<F> {
    fn set_interrupt(&mut self, flag: &'static AtomicBool) {
        self.interrupt = Some(flag);
        for strip in &mut self.strips {
            strip.interrupt = Some(flag);
        }
    }
    fn disks(&self) -> &Disks {
        &self.disks
    }
    fn time(&self) -> f64 {
        self.now
    }
    fn advance_to(&mut self, target: f64) -> Result<Progress> {
        self.cores.clone().run(|| self.run_to(target))
    }
    fn has_threads(&self) -> bool {
        true
    }
    fn advance_beside(&mut self, target: f64, beside: impl FnOnce() + Send) -> Result<Progress> {
        self.cores
            .clone()
            .run(|| rayon::join(|| self.run_to(target), beside).0)
    }
    fn visit_states(&self, t: f64, visit: impl FnMut(usize, [f64; 4])) {
        free_flight_visit(self.flight, &self.disks, self.sides, self.top, t, visit);
    }
    fn floor_height_at(&self, t: f64) -> Option<f64> {
        self.floor.as_ref().map(|f| f.height(t))
    }
    fn counts(&self) -> EventCounts {
        self.counts
    }
    fn energy_flow_at(&self, _t: f64) -> EnergyFlow {
        self.flow
    }
    fn virial(&self) -> f64 {
        self.virial
    }
    fn max_overlap(&self) -> f64 {
        self.max_overlap
    }
    fn check_state(&self, _t: f64) -> Result<()> {
        Ok(())
    }
    fn setup(&self) -> Setup {
        Setup {
            scheme: "space-time",
            mask: match self.strips.len() {
                1 => format!("3×3 linked cells, D = {:.4}", self.sync_distance),
                s => format!(
                    "3×3 linked cells, D = {:.4}, {s} strips",
                    self.sync_distance
                ),
            },
            cell: self.cells.cell(),
            grid: "linked-cells".into(),
            queue: None,
            remap: None,
            bytes: self.disks.bytes()
                + self.cells.bytes()
                + 4 * (self.start.capacity() + self.partners.capacity() + self.local.capacity())
                + self.strips.iter().map(Strip::bytes).sum::<usize>()
                + self.restitution.bytes(),
            threads: Some(self.cores.count()),
        }
    }
    fn approximation(&self) -> Option<SchemeStats> {
        Some(self.stats)
    }
}
