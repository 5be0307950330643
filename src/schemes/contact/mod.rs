//! The contact-dynamics scheme (Moreau–Jean): one global step dt, every contact of a step — pairs,
//! the floor, side walls, the lid — resolved together as one simultaneous impact. The step
//! follows the fastest impact (see [`IMPACT_REACH`]).
//!
//! A dense bed is a network of enduring contacts. The exact engine meets it as a sequence of
//! binary collisions that the TC model makes elastic, millions per unit time; a soft-sphere DEM
//! meets it with a step of a fraction of the contact time. Here each step first gives every disk
//! gravity's velocity, then solves for the impulses `p ≥ 0` of all the contacts that can close
//! within the step at once (projected Gauss–Seidel, warm-started from the previous step's
//! impulses), so that at the step's end:
//!
//! - no contact has closed past touching: `gap + dt·u⁺ ≥ 0` (the *speculative* condition, `u` the
//!   normal relative velocity), which also holds a resting contact shut; an overlap left by an
//!   unconverged step stops closing, and is opened by moving the disks apart, not by giving
//!   them speed (`recovery`);
//! - a contact that would close within the step, met faster than the rest speed (`2 g dt`,
//!   on the floor `2 (g + Aω²) dt`), rebounds at once by Newton's law, `u⁺ ≥ −e u⁻` (slower
//!   impacts are plastic: a step cannot resolve a rebound that rises less than a few g dt²);
//! - on rough disks, the tangential impulse of each contact lies in Coulomb's cone
//!   `|p_t| ≤ μ p` and sticks the contact (`u_t⁺ = 0`) where the cone allows;
//!
//! then moves each disk on the exact parabola of its new velocity (`x += dt·v⁺ + ½ g dt²`, plus
//! the overlaps' opening). There is no inelastic collapse to cure: TC and the speed cutoff are
//! not applied (the restitution `e` is used as it is). Energy changes only through the impulses
//! (and the overlaps' opening, which lifts disks): the floor's work is `Σ p·h'` (the floor's mean
//! velocity over the step), and the energy lost beyond it is booked as dissipated.
//!
//! On one thread: the Gauss–Seidel sweep takes the contacts in one order (the boundaries by disk
//! number, then the pairs from the lowest up, so that a stack's weight reaches the floor within a
//! sweep), four at a time where four in a row share no disk (`quads`), and runs repeat bit for
//! bit on any processor. The pairs are laid out in quads once a Verlet list (`pairs`; smooth
//! disks' in quads of what a smooth pair reads, `smooth`), the boundaries each step.

mod pairs;
mod quads;
mod recovery;
mod separations;
mod smooth;

use super::cells::CellList;
use super::time_step::{default_dt, DEEP_OVERLAP, DEFAULT_SKIN};
use super::{free_flight_visit, min_image, wrap, wrap_positions, Integrator, SchemeStats, Setup};
use crate::engine::{EnergyFlow, EventCounts, Progress, Scene};
use crate::error::{Error, Result};
use crate::physics::disks::{Disks, Motion};
use crate::physics::drive::FloorModel;
use crate::physics::flight::Flight;
use crate::physics::floor::Floor;
use crate::physics::rough::Roughness;
use crate::physics::walls::{SideBounds, Top};
use crate::platform::cpu::Lanes;
use crate::scenario::Engine;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};

/// Gauss–Seidel sweeps per step, at most. A bed of a few layers does not converge in a step
/// (the sweeps carry a change across the bed one contact at a time; most steps of a bouncing
/// bed end at the cap); the warm start carries each step's solve on into the next, and the rest
/// is left as overlap that the next step's speculative condition removes. On the shipped bed's
/// dense points 8 sweeps kept the centre of mass within 0.5 % of 16's, at 60–70 % of the cost
/// (the accuracy page's table).
pub const MAX_SWEEPS: u32 = 8;

/// A sweep that changes no relative velocity by more than this fraction of `(g + Aω²) dt` ends
/// the step's solve.
const TOLERANCE: f64 = 1e-2;

/// Sweeps of [`Contact::separate`], at most.
const SEPARATION_SWEEPS: u32 = 1000;

/// How far beyond contact [`Contact::separate`] leaves a disk: this part of the contact
/// distance (a hair, twice that between disks).
const CLEAR: f64 = 1e-12;

/// [`Contact::separate`] gives up when its deepest push has not halved in this many sweeps: a
/// row pressed together across a periodic width, or a jam deep in a tall bed, that pushing
/// upper disks along the normals does not open (the exact engine then refuses the state).
const SEPARATION_STALL: u32 = 50;

/// Contacts are gathered a hair beyond how far disks can close in a step: this many radii.
const HAIR: f64 = 1e-7;

/// Quiet steps in a row ([`Contact::fall_asleep`]) after which a bed the floor cannot throw
/// (Γ < 1, or a static floor) falls asleep: it then rides the floor as one rigid body, every disk
/// moving with it, and no contact is solved (nothing else acts on a closed bed; the exact
/// engine's riders do the same). At the coarse step, a fiftieth of the floor's period, this is a
/// period at rest.
const SLEEP_STEPS: u64 = 50;

/// The default step follows the fastest impact: the fastest contact that closes within a step
/// closes at most this many radii of the smallest disk in it. A bed's impacts are a sequence
/// (a landing bed meets the floor layer by layer, a caged disk its neighbours one after
/// another); a step resolves each contact's impact at most once, so a step that lets fast
/// impacts close far in one step meets a sequence as one simultaneous impact, which dissipates
/// less, and the bed runs hot. The accuracy page gives this reach against LAMMPS.
pub const IMPACT_REACH: f64 = 0.012;

/// The default step's range: from the coarse step ([`default_step`]) down to this part of it.
pub const STEP_RANGE: f64 = 8.0;

/// What a contact touches, for the tallies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Pair,
    Floor,
    Wall,
    Lid,
}

/// One contact of a step, as the solve reads it: disk `i` against disk `j`, or against a
/// boundary (`j` is then one past the last disk, an entry of the solve that never moves); unit
/// normal `n` from `j` (or the boundary) to `i`. A boundary's row goes straight into the quads
/// ([`quads::Packer`]), and what the booking needs besides is its [`Tag`]; the pairs' rows are
/// laid out once a Verlet list ([`pairs::lay_out`]).
#[derive(Debug, Clone, Copy)]
struct Row {
    i: u32,
    j: u32,
    n: (f64, f64),
    /// The boundary's velocity (0 for pairs and fixed boundaries).
    vb: (f64, f64),
    /// Inverse masses of `i` and `j` (0 for a boundary).
    wi: f64,
    wj: f64,
    /// Inverse effective masses along the normal and the tangent.
    wn: f64,
    wt: f64,
    /// Effective masses along the normal and the tangent (`1/wn`, `1/wt`).
    mn: f64,
    mt: f64,
    /// Lower bound on the normal relative velocity after the step.
    target: f64,
    /// Coulomb's coefficient (0: smooth).
    mu: f64,
    /// Accumulated impulses along the normal and the tangent (the warm start).
    pn: f64,
    pt: f64,
}

/// What the booking needs of a step's boundary contact beyond its impulses: what it touches,
/// and whether its bound is a rebound by Newton's law (not closing to touching).
#[derive(Debug, Clone, Copy)]
struct Tag {
    kind: Kind,
    bounce: bool,
}

/// A contact's inverse masses and effective masses (see [`Row`]), kept for the last two masses
/// met: a bed of equal disks divides once a step instead of six times a row.
struct Inertia {
    /// `1 + 1/q` (∞ for smooth disks): the tangent's inverse mass over the normal's.
    tangent: f64,
    masses: (f64, f64),
    w: [f64; 6],
}

impl Inertia {
    fn new(tangent: f64) -> Inertia {
        Inertia {
            tangent,
            masses: (f64::NAN, f64::NAN),
            w: [0.0; 6],
        }
    }

    /// `[wi, wj, wn, wt, mn, mt]` of a contact between masses `mi` and `mj` (∞: a boundary).
    fn of(&mut self, mi: f64, mj: f64) -> [f64; 6] {
        if (mi, mj) != self.masses {
            let (wi, wj) = (1.0 / mi, 1.0 / mj);
            let wn = wi + wj;
            let wt = wn * self.tangent;
            self.w = [wi, wj, wn, wt, 1.0 / wn, 1.0 / wt];
            self.masses = (mi, mj);
        }
        self.w
    }
}

/// The impulses of the pairs that pushed at the last step, carried over a rebuild of the Verlet
/// list: each pair under its lower-numbered disk, the disks' entries in one array (a pair is
/// found among the few of its disk, without hashing).
struct Carried {
    /// Where each disk's entries start (one more for the end).
    start: Vec<u32>,
    /// The other disk and the impulses.
    entries: Vec<(u32, (f64, f64))>,
}

impl Carried {
    /// The pushing pairs of `pairs` (impulses `warm`) among `n` disks.
    fn new(n: usize, pairs: &[(u32, u32)], warm: &[(f64, f64)]) -> Carried {
        let pushing = || (pairs.iter().zip(warm)).filter(|(_, p)| p.0 > 0.0);
        let mut start = vec![0u32; n + 1];
        for (&(i, j), _) in pushing() {
            start[i.min(j) as usize + 1] += 1;
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        let mut entries = vec![(0, (0.0, 0.0)); start[n] as usize];
        let mut at = start.clone();
        for (&(i, j), &p) in pushing() {
            let low = i.min(j) as usize;
            entries[at[low] as usize] = (i.max(j), p);
            at[low] += 1;
        }
        Carried { start, entries }
    }

    /// The impulses of the pair of disks `i` and `j` (either way round), if it pushed.
    fn impulses(&self, (i, j): (u32, u32)) -> Option<(f64, f64)> {
        let (low, high) = (i.min(j) as usize, i.max(j));
        let own = &self.entries[self.start[low] as usize..self.start[low + 1] as usize];
        own.iter().find(|e| e.0 == high).map(|e| e.1)
    }
}

/// A sleeping bed: the contacts that held it when it fell asleep (pairs, floor, walls, lid), and
/// the horizontal velocity it keeps (its mean where nothing can stop it sliding: periodic sides
/// and a smooth floor; else 0).
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
struct Asleep {
    held: [u64; 4],
    slide: f64,
}

/// A contact's bound on its normal velocity after the step.
struct Bound {
    target: f64,
    /// Whether the bound is a rebound by Newton's law.
    bounce: bool,
}

/// The contact-dynamics engine.
#[derive(Debug)]
pub struct Contact<F: Flight> {
    flight: F,
    disks: Disks,
    sides: SideBounds,
    top: Top,
    floor: Option<Floor>,
    /// Pair restitution (the cures of inelastic collapse are not applied).
    e: f64,
    rough: Option<Roughness>,
    /// The present step, and the range the step may take (`(dt, dt)`: a fixed step).
    dt: f64,
    dt_range: (f64, f64),
    /// Local time, and the fastest approach the next step can meet ([`Contact::look_ahead`]).
    t: f64,
    fastest: f64,
    /// The smallest radius.
    a_min: f64,
    skin: f64,
    verlet: f64,
    cell: f64,
    cells: CellList,
    pairs: Vec<(u32, u32)>,
    /// Each Verlet pair's separation `(dx, dy, dist)` between steps ([`Contact::look_ahead`]).
    separations: Vec<[f64; 3]>,
    /// Each Verlet pair's impulses at the end of the last step (warm start).
    warm: Vec<(f64, f64)>,
    /// Each disk's floor impulses at the end of the last step.
    warm_floor: Vec<(f64, f64)>,
    built_x: Vec<f64>,
    built_y: Vec<f64>,
    /// The Verlet pairs packed for the sweep once a list ([`pairs::lay_out`]; each step sets
    /// what changes, [`pairs::refresh`]), and whether each rebounds in the step; the step's
    /// boundary contacts packed as they are gathered, with their tags; how the sweep runs on
    /// this processor.
    pair_quads: pairs::Pairs,
    bounces: Vec<bool>,
    boundary_quads: Vec<quads::Quad>,
    tags: Vec<Tag>,
    lanes: Lanes,
    /// The step's overlaps and their pseudo-velocities ([`recovery`]).
    recovery: recovery::Recovery,
    /// The solve's copy of each disk's velocity, rim speed `ω a` (0 for smooth disks) and
    /// inverse mass, and one more entry that stays 0: the other side of a boundary contact (whose
    /// inverse mass is 0), so that every contact reads alike.
    vel: Vec<[f64; 4]>,
    /// `1/q` of rough disks' `I = q m a²` (0 for smooth disks).
    spin_factor: f64,
    step: u64,
    sweeps: u64,
    energy: f64,
    counts: EventCounts,
    flow: EnergyFlow,
    virial: f64,
    max_overlap: f64,
    stats: SchemeStats,
    /// Disks at rest after the last step ([`Contact::count_at_rest`]), and since when every disk
    /// has been.
    at_rest: usize,
    rest_since: Option<f64>,
    /// Scratch: which disks a contact pushed in the last step, and the floor's work in it.
    pushed: Vec<bool>,
    injected_step: f64,
    /// Steps in a row with every disk at rest, and whether the bed sleeps
    /// ([`Contact::fall_asleep`]).
    quiet_steps: u64,
    asleep: Option<Asleep>,
    event_limit: u64,
    interrupt: Option<&'static AtomicBool>,
}

/// Contact dynamics' state between steps, for a checkpoint: what a step carries to the next (the
/// disks, the Verlet list and its warm start, the clock, the tallies). The scene and the knobs are
/// rebuilt from the scenario; the step is kept, as it may have been chosen from the disks' speeds.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ContactState {
    disks: Disks,
    dt: f64,
    dt_range: (f64, f64),
    t: f64,
    pairs: Vec<(u32, u32)>,
    warm: Vec<(f64, f64)>,
    warm_floor: Vec<(f64, f64)>,
    built_x: Vec<f64>,
    built_y: Vec<f64>,
    step: u64,
    sweeps: u64,
    energy: f64,
    counts: EventCounts,
    flow: EnergyFlow,
    virial: f64,
    max_overlap: f64,
    deep_overlaps: u64,
    rebounds: u64,
    at_rest: usize,
    rest_since: Option<f64>,
    #[serde(default)]
    quiet_steps: u64,
    #[serde(default)]
    asleep: Option<Asleep>,
}

/// What a step sets of each laid-out pair ([`Fresher::pair`]), with what it books on the way.
struct Fresher<'a, F: Flight> {
    this: &'a Contact<F>,
    /// The gap beyond which a pair cannot close within the step.
    reach: f64,
    warm_scale: f64,
    /// The rest speed of a pair.
    rest: f64,
    bounces: Vec<bool>,
    recovery: &'a mut recovery::Recovery,
    deepest: f64,
    deep_overlaps: u64,
}

impl<F: Flight> Fresher<'_, F> {
    /// Pair `k`'s normal, bound and warm start for the step (`None`: it cannot close within it);
    /// its overlap noted, and whether it rebounds.
    #[inline(always)]
    fn pair(&mut self, k: u32) -> Option<quads::Fresh> {
        let (c, k) = (self.this, k as usize);
        let d = &c.disks;
        let (i, j) = c.pairs[k];
        let (iu, ju) = (i as usize, j as usize);
        let [dx, dy, dist] = c.separations[k];
        let s = d.radius[iu] + d.radius[ju];
        let gap = dist - s;
        if gap > self.reach {
            self.bounces[k] = false;
            return None;
        }
        let (mi, mj) = (d.motion[iu], d.motion[ju]);
        let n = (dx / dist, dy / dist);
        let u = (mi.vx - mj.vx) * n.0 + (mi.vy - mj.vy) * n.1;
        self.deepest = self.deepest.max(-gap);
        if -gap > DEEP_OVERLAP * s {
            self.deep_overlaps += 1;
        }
        let (pn, pt) = c.warm[k];
        let bound = c.target(gap, 0.0, (u, 0.0), c.e, self.rest);
        if self.recovery.opens(gap) {
            let (wi, wj) = (1.0 / d.mass[iu], 1.0 / d.mass[ju]);
            self.recovery
                .add((i, j), n, (wi, wj, 1.0 / (wi + wj)), gap, c.dt);
        }
        self.bounces[k] = bound.bounce;
        Some(quads::Fresh {
            n,
            target: bound.target,
            pn: pn * self.warm_scale,
            pt: pt * self.warm_scale,
        })
    }
}

impl<F: Flight> Contact<F> {
    /// Sets up the scheme for `scene` with its knobs from `engine` (`dt`, `verlet_skin`,
    /// `cell_size`).
    pub fn new(flight: F, scene: &Scene, disks: Disks, engine: &Engine) -> Result<Contact<F>> {
        let n = disks.len();
        let (a_min, a_max) = disks.radius_range();
        let dt_range = match engine.dt {
            Some(dt) => (dt, dt),
            None => {
                let coarse = default_step(scene, &disks).ok_or_else(|| {
                    Error::input(
                        "engine.dt",
                        "cannot be chosen from the scene (nothing moves): give it",
                    )
                })?;
                (coarse / STEP_RANGE, coarse)
            }
        };
        let dt = dt_range.1;
        if matches!(
            scene.floor.as_ref().map(|f| f.drive().model),
            Some(FloorModel::FixedPosition)
        ) {
            return Err(Error::input(
                "floor.model",
                "engine.scheme = contact moves the floor as it moves (the exact floor model only)",
            ));
        }
        let skin = engine.verlet_skin.unwrap_or(DEFAULT_SKIN) * a_min;
        let verlet = 2.0 * a_max + skin;
        let cell = match engine.cell_size {
            Some(c) if c * a_min < verlet => {
                return Err(Error::input(
                    "engine.cell_size",
                    format!(
                        "must be at least the Verlet radius 2 a_max + skin = {:.4} radii",
                        verlet / a_min
                    ),
                ))
            }
            Some(c) => c * a_min,
            None => verlet,
        };
        let mut c = Contact {
            flight,
            disks,
            sides: scene.sides,
            top: scene.top,
            floor: scene.floor.clone(),
            e: scene.restitution.e,
            rough: scene.rough,
            dt,
            dt_range,
            t: 0.0,
            fastest: 0.0,
            a_min,
            skin,
            verlet,
            cell,
            cells: CellList::default(),
            pairs: Vec::new(),
            separations: Vec::new(),
            warm: Vec::new(),
            warm_floor: vec![(0.0, 0.0); n],
            built_x: vec![0.0; n],
            built_y: vec![0.0; n],
            pair_quads: pairs::Pairs::new(scene.rough.is_some()),
            bounces: Vec::new(),
            boundary_quads: Vec::new(),
            tags: Vec::new(),
            lanes: Lanes::found(),
            recovery: recovery::Recovery::new(n, a_min),
            vel: vec![[0.0; 4]; n + 1],
            spin_factor: scene.rough.map_or(0.0, |r| 1.0 / r.inertia_factor),
            step: 0,
            sweeps: 0,
            energy: 0.0,
            counts: EventCounts::default(),
            flow: EnergyFlow::default(),
            virial: 0.0,
            max_overlap: 0.0,
            stats: SchemeStats::default(),
            at_rest: 0,
            rest_since: None,
            pushed: vec![false; n + 1],
            injected_step: 0.0,
            quiet_steps: 0,
            asleep: None,
            event_limit: scene.max_events.unwrap_or(u64::MAX),
            interrupt: None,
        };
        for m in &mut c.disks.motion {
            m.t = 0.0;
        }
        wrap_positions(c.sides, c.top, &mut c.disks);
        c.load_inverse_masses();
        c.rebuild();
        c.look_ahead();
        c.energy = c.total_energy();
        Ok(c)
    }

    fn now(&self) -> f64 {
        self.t
    }

    /// The coarsest step.
    pub fn step(&self) -> f64 {
        self.dt_range.1
    }

    /// The next step: the fastest impact it can meet closes [`IMPACT_REACH`] radii in it, within
    /// the step's range; the coarsest where none can (a `fastest` of −0.0 would divide to −∞).
    fn next_step(&self) -> f64 {
        let (finest, coarsest) = self.dt_range;
        if self.fastest <= 0.0 {
            return coarsest;
        }
        (IMPACT_REACH * self.a_min / self.fastest).clamp(finest, coarsest)
    }

    /// Whether a whole step fits before local time `target`.
    pub fn can_step_to(&self, target: f64) -> bool {
        let dt = self.next_step();
        self.t + dt <= target + 1e-9 * dt
    }

    /// The state between steps, for a checkpoint.
    pub fn state(&self) -> ContactState {
        ContactState {
            disks: self.disks.clone(),
            dt: self.dt,
            dt_range: self.dt_range,
            t: self.t,
            pairs: self.pairs.clone(),
            warm: self.warm.clone(),
            warm_floor: self.warm_floor.clone(),
            built_x: self.built_x.clone(),
            built_y: self.built_y.clone(),
            step: self.step,
            sweeps: self.sweeps,
            energy: self.energy,
            counts: self.counts,
            flow: self.flow,
            virial: self.virial,
            max_overlap: self.max_overlap,
            deep_overlaps: self.stats.deep_overlaps,
            rebounds: self.stats.rebounds,
            at_rest: self.at_rest,
            rest_since: self.rest_since,
            quiet_steps: self.quiet_steps,
            asleep: self.asleep,
        }
    }

    /// Puts a saved state into an engine built for the same scene (a checkpoint's, or the one
    /// before a separation whose hand-back was refused); refuses one of another shape. The run
    /// then goes on bit for bit as from the saved state.
    pub fn restore(&mut self, state: ContactState) -> Result<()> {
        let n = self.disks.len();
        let d = &state.disks;
        let fits = d.len() == n
            && d.spins.is_some() == self.disks.spins.is_some()
            && state.warm.len() == state.pairs.len()
            && state.warm_floor.len() == n
            && state.built_x.len() == n
            && state.built_y.len() == n
            && state
                .pairs
                .iter()
                .all(|&(i, j)| (i as usize) < n && (j as usize) < n)
            && state.dt > 0.0
            && state.dt_range.0 > 0.0
            && state.dt_range.0 <= state.dt_range.1;
        if !fits {
            return Err(Error::input(
                "checkpoint",
                "the saved contact dynamics does not fit this scene",
            ));
        }
        self.disks = state.disks;
        self.load_inverse_masses();
        self.dt = state.dt;
        self.dt_range = state.dt_range;
        self.t = state.t;
        self.pairs = state.pairs;
        self.warm = state.warm;
        self.warm_floor = state.warm_floor;
        self.built_x = state.built_x;
        self.built_y = state.built_y;
        self.step = state.step;
        self.sweeps = state.sweeps;
        self.energy = state.energy;
        self.counts = state.counts;
        self.flow = state.flow;
        self.virial = state.virial;
        self.max_overlap = state.max_overlap;
        self.at_rest = state.at_rest;
        self.rest_since = state.rest_since;
        self.quiet_steps = state.quiet_steps;
        self.asleep = state.asleep;
        self.stats = SchemeStats {
            deep_overlaps: state.deep_overlaps,
            rebounds: state.rebounds,
            ..SchemeStats::default()
        };
        self.lay_out();
        self.look_ahead();
        Ok(())
    }

    /// Removes every overlap (pairs, floor, walls, lid) by moving disks apart, positions only: the
    /// floor and walls first, then the pairs from the lowest up, each moving its upper disk, so
    /// that a stack is lifted clear in one sweep; sweeps repeat until nothing overlaps (for the
    /// exact engine, which accepts no overlap), or until they stall (their deepest push not
    /// halved in 50 sweeps).
    pub fn separate(&mut self) {
        let before = self.total_energy();
        self.lift_clear();
        // The lift's potential energy is the separation's work: booked so that the budget closes.
        let after = self.total_energy();
        self.flow.dissipated -= after - before;
        self.energy = after;
        self.look_ahead();
    }

    /// [`Contact::separate`]'s moves: sweeps of the boundaries and the pairs.
    fn lift_clear(&mut self) {
        let t = self.now();
        let floor = self.floor.as_ref().map(|f| f.height(t));
        let mut mark = f64::INFINITY;
        for sweep in 0..SEPARATION_SWEEPS {
            let onto_bounds = self.clear_boundaries(floor);
            let deepest = self.clear_pairs();
            if !onto_bounds && deepest.is_none() {
                return;
            }
            let deepest = deepest.unwrap_or(0.0);
            if sweep % SEPARATION_STALL == 0 {
                if deepest > 0.5 * mark {
                    return;
                }
                mark = deepest;
            }
            // A disk lifted half a skin may now overlap one the list does not hold: deep in a
            // tall bed the lifts add up layer on layer.
            if self.moved_half_skin() {
                self.rebuild();
            }
        }
    }

    /// Puts every disk a hair inside the floor (at height `floor`), the walls and the lid; true
    /// if one moved.
    fn clear_boundaries(&mut self, floor: Option<f64>) -> bool {
        let mut moved = false;
        let d = &mut self.disks;
        for (k, m) in d.motion.iter_mut().enumerate() {
            let a = d.radius[k] * (1.0 + CLEAR);
            if let Some(h) = floor {
                if m.y < h + a {
                    (m.y, moved) = (h + a, true);
                }
            }
            if let SideBounds::Walls { width, .. } = self.sides {
                if m.x < a || m.x > width - a {
                    (m.x, moved) = (m.x.clamp(a, width - a), true);
                }
            }
            if let Top::Lid { height, .. } = self.top {
                if m.y > height - a {
                    (m.y, moved) = (height - a, true);
                }
            }
        }
        moved
    }

    /// One sweep over the Verlet pairs from the lowest up, moving each overlapping pair's upper
    /// disk along the normal: the deepest push, `None` if no pair overlapped. A pair counts as
    /// clear a hair beyond contact and is pushed to two, so that it stays clear whatever
    /// round-off its disk's new place carries.
    fn clear_pairs(&mut self) -> Option<f64> {
        let mut deepest = None;
        let d = &mut self.disks;
        for &(i, j) in &self.pairs {
            let (iu, ju) = (i as usize, j as usize);
            let (mi, mj) = (d.motion[iu], d.motion[ju]);
            let (dx, dy) = min_image(self.sides, self.top, mi.x - mj.x, mi.y - mj.y);
            let contact = d.radius[iu] + d.radius[ju];
            let (clear, s) = (contact * (1.0 + CLEAR), contact * (1.0 + 2.0 * CLEAR));
            let dist2 = dx * dx + dy * dy;
            if dist2 >= clear * clear {
                continue;
            }
            let dist = dist2.sqrt().max(1e-300);
            let push = s - dist;
            deepest = Some(push.max(deepest.unwrap_or(0.0)));
            let (up, sign) = if mi.y >= mj.y { (iu, 1.0) } else { (ju, -1.0) };
            let m = &mut d.motion[up];
            (m.x, m.y) = wrap(
                self.sides,
                self.top,
                m.x + sign * push * dx / dist,
                m.y + sign * push * dy / dist,
            );
        }
        deepest
    }

    /// Whether a disk has moved half the skin from where the Verlet list was built.
    fn moved_half_skin(&self) -> bool {
        let half = 0.5 * self.skin;
        (self.disks.motion.iter().enumerate()).any(|(k, m)| {
            let (dx, dy) = min_image(
                self.sides,
                self.top,
                m.x - self.built_x[k],
                m.y - self.built_y[k],
            );
            dx * dx + dy * dy > half * half
        })
    }

    fn g(&self) -> f64 {
        self.flight.g()
    }

    /// Rebuilds the cell list and the Verlet list, carrying each kept pair's impulses over.
    fn rebuild(&mut self) {
        let n = self.disks.len();
        let old = Carried::new(n, &self.pairs, &self.warm);
        let motion = &self.disks.motion;
        self.cells.build(
            n,
            |i| (motion[i].x, motion[i].y),
            self.cell,
            self.sides,
            self.top,
        );
        let (sides, top, skin, radius) = (self.sides, self.top, self.skin, &self.disks.radius);
        self.cells.pairs_where_into(&mut self.pairs, |i, j| {
            let (dx, dy) = min_image(
                sides,
                top,
                motion[i].x - motion[j].x,
                motion[i].y - motion[j].y,
            );
            let reach = radius[i] + radius[j] + skin;
            (dx * dx + dy * dy <= reach * reach).then_some((i as u32, j as u32))
        });
        order_pairs(&mut self.pairs, motion, 2.0 * self.disks.radius_range().1);
        self.warm.clear();
        self.warm
            .extend((self.pairs.iter()).map(|&pair| old.impulses(pair).unwrap_or((0.0, 0.0))));
        for (k, m) in motion.iter().enumerate() {
            (self.built_x[k], self.built_y[k]) = (m.x, m.y);
        }
        self.lay_out();
        self.counts.rebuild += 1;
    }

    /// Packs the Verlet pairs for the sweep, once a list ([`pairs::lay_out`]).
    fn lay_out(&mut self) {
        let (mu, q) = match &self.rough {
            Some(r) => (r.pair.mu, r.inertia_factor),
            None => (0.0, f64::INFINITY),
        };
        let mut inertia = Inertia::new(1.0 + 1.0 / q);
        let mass = &self.disks.mass;
        let boundary = self.disks.len() as u32;
        (self.pair_quads).lay_out(&self.pairs, boundary, mu, |i, j| {
            inertia.of(mass[i as usize], mass[j as usize])
        });
        self.bounces.clear();
        self.bounces.resize(self.pairs.len(), false);
    }

    /// Whole steps up to absolute time `target`.
    fn steps_to(&mut self, target: f64) -> Result<Progress> {
        while self.can_step_to(target) {
            if self.counts.popped() >= self.event_limit {
                return Ok(Progress::EventLimit);
            }
            if self
                .interrupt
                .is_some_and(|flag| flag.load(Ordering::Relaxed))
            {
                return Ok(Progress::Interrupted);
            }
            self.one_step();
        }
        Ok(Progress::Reached)
    }

    /// One step: gravity, the contacts solved together, the move.
    fn one_step(&mut self) {
        if let Some(asleep) = self.asleep {
            self.sleep_step(asleep);
            return;
        }
        let dt = self.next_step();
        // A resting contact's impulse is a step's weight: the warm start scales with the step.
        let warm_scale = dt / self.dt;
        self.dt = dt;
        let (t0, g) = (self.now(), self.g());
        let t1 = t0 + dt;
        for m in &mut self.disks.motion {
            m.vy -= g * dt;
        }
        self.load_velocities();
        self.gather_rows(t0, t1, warm_scale);
        self.solve();
        self.recovery.solve();
        self.book(t1);
        self.count_at_rest(t1);
        self.fall_asleep(t1);
        self.advance(t1);
        self.t = t1;
        self.look_ahead();
        self.step += 1;
    }

    /// After [`SLEEP_STEPS`] quiet steps in a row on a floor that cannot throw the bed, the bed
    /// falls asleep: every disk takes the floor's velocity at `t1` (the spins stop), it is at
    /// rest from then on, and from the next step on it rides the floor as one body
    /// ([`Contact::sleep_step`]). A step is quiet when a contact pushed every disk and the disks'
    /// root-mean-square speed against a disk resting on the floor ([`Contact::resting_vy`],
    /// sliding with the bed where it keeps its slide, [`Contact::slide`]) is below a step of
    /// gravity, `g dt`: the bed as a whole rests, while the unconverged solve lets a few lightly
    /// loaded disks (the top layer, where the floor pulls the bed down fastest) stray past that
    /// speed now and then.
    #[inline(never)]
    fn fall_asleep(&mut self, t1: f64) {
        let n = self.disks.len();
        let Some(f) = self
            .floor
            .as_ref()
            .filter(|f| f.max_acceleration() < self.g())
        else {
            return;
        };
        let (v, slow) = (f.velocity(t1), self.g() * self.dt);
        let pushed = self.pushed[..n].iter().all(|&p| p);
        let (slide, rest) = (self.slide(), self.resting_vy(t1));
        let square: f64 = (self.disks.motion.iter())
            .map(|m| (m.vx - slide) * (m.vx - slide) + (m.vy - rest) * (m.vy - rest))
            .sum();
        let quiet = pushed && square < n as f64 * slow * slow;
        self.quiet_steps = if quiet { self.quiet_steps + 1 } else { 0 };
        if self.quiet_steps < SLEEP_STEPS {
            return;
        }
        // The floor takes every disk along: its impulse is the change of momentum.
        let d = &mut self.disks;
        for (k, m) in d.motion.iter_mut().enumerate() {
            self.flow.floor_impulse += d.mass[k] * (v - m.vy);
            (m.vx, m.vy) = (slide, v);
        }
        if let Some(spins) = &mut self.disks.spins {
            for k in 0..spins.omega.len() {
                let w = spins.omega[k];
                if w != 0.0 {
                    spins.spin(k, t1, -w);
                }
            }
        }
        let mut held = [0u64; 4];
        for p in quads::pushing(&self.boundary_quads) {
            held[self.tags[p.row as usize].kind as usize] += 1;
        }
        self.pair_quads
            .each_pushing(|_| held[Kind::Pair as usize] += 1);
        self.asleep = Some(Asleep { held, slide });
        self.at_rest = n;
        self.rest_since = self.rest_since.or(Some(t1));
    }

    /// The vertical velocity of a disk resting on the floor (or on a fixed support) at the end
    /// of the step to `t1`: the floor's mean velocity over the step less `g dt/2`, which the
    /// move's `g dt²/2` makes up, so that the disk moves with the floor. (Against the floor's
    /// velocity at `t1` a resting disk is `(g + h'') dt/2` off, up to three quarters of the
    /// rest speed `g dt` at Γ = 0.5, and a resting bed's noise crossed it once a period.)
    fn resting_vy(&self, t1: f64) -> f64 {
        let dt = self.dt;
        let floor = (self.floor.as_ref()).map_or(0.0, |f| (f.height(t1) - f.height(t1 - dt)) / dt);
        floor - 0.5 * self.g() * dt
    }

    /// The horizontal velocity a bed keeps where nothing can change it (periodic sides, a smooth
    /// floor): its momentum over its mass; 0 elsewhere. A bed sliding on a smooth floor rests
    /// on it as it slides, and is quiet against that speed.
    fn slide(&self) -> f64 {
        let smooth_floor = self.rough.as_ref().is_none_or(|r| r.floor.mu == 0.0);
        match self.sides {
            SideBounds::Periodic { .. } if smooth_floor => {
                let d = &self.disks;
                let n = d.len();
                let p: f64 = (0..n).map(|k| d.mass[k] * d.motion[k].vx).sum();
                p / (0..n).map(|k| d.mass[k]).sum::<f64>()
            }
            _ => 0.0,
        }
    }

    /// A step of a sleeping bed: every disk moves with the floor, the contacts that held the bed
    /// when it fell asleep hold it still (counted as pushing), and the floor's impulse and work
    /// are what moving the bed with it takes: the change of momentum plus the weight's impulse,
    /// and the change of energy.
    #[inline(never)]
    fn sleep_step(&mut self, Asleep { held, slide }: Asleep) {
        let dt = self.next_step();
        self.dt = dt;
        let (t0, g) = (self.now(), self.g());
        let t1 = t0 + dt;
        let f = self.floor.as_ref().expect("a sleeping bed rides a floor");
        let (dh, v) = (f.height(t1) - f.height(t0), f.velocity(t1));
        let d = &mut self.disks;
        let mut impulse = 0.0;
        for (k, m) in d.motion.iter_mut().enumerate() {
            impulse += d.mass[k] * (v - m.vy + g * dt);
            (m.x, m.y) = wrap(self.sides, self.top, m.x + slide * dt, m.y + dh);
            (m.vy, m.t) = (v, t1);
            (self.built_x[k], self.built_y[k]) =
                (self.built_x[k] + slide * dt, self.built_y[k] + dh);
        }
        let [pair, floor, wall, lid] = held;
        self.counts.pair += pair;
        self.counts.floor += floor;
        self.counts.wall += wall;
        self.counts.lid += lid;
        let energy = self.total_energy();
        self.flow.injected += energy - self.energy;
        self.flow.floor_impulse += impulse;
        self.energy = energy;
        self.t = t1;
        self.step += 1;
    }

    /// Measures, between steps, each Verlet pair's separation (the next step's contacts are
    /// gathered from it) and the fastest approach of a pair or a disk and the floor that can
    /// close within the coarsest step, on the velocities now (a disk falling toward the floor
    /// counted with the speed the step's gravity adds): the impact the next step must resolve
    /// (0: none, or a fixed step). Taken before the step, so that a bed landing from flight
    /// meets the floor at the fine step.
    fn look_ahead(&mut self) {
        let adaptive = self.dt_range.0 < self.dt_range.1;
        let (dt, t, g) = (self.dt_range.1, self.now(), self.g());
        let d = &self.disks;
        let mut fastest = 0.0f64;
        if let Some(f) = self.floor.as_ref().filter(|_| adaptive) {
            let (h, hv) = (f.height(t), f.velocity(t));
            for (k, m) in d.motion.iter().enumerate() {
                let u = m.vy - g * dt - hv;
                if m.y - d.radius[k] - h + u * dt < 0.0 {
                    fastest = fastest.max(-u);
                }
            }
        }
        let m = separations::Measure {
            sides: self.sides,
            top: self.top,
            motion: &d.motion,
            radius: &d.radius,
            dt,
            adaptive,
        };
        let pairs = separations::measure(self.lanes, &m, &self.pairs, &mut self.separations);
        self.fastest = fastest.max(pairs);
    }

    /// The bound on the normal velocity after the step of a contact with gap `gap` (`lift`:
    /// what the step's gravity adds to it) met at normal velocity `u` after gravity (whose
    /// component along the normal is `gn`, 0 between disks), with restitution `e`.
    ///
    /// A contact that would close within the step, met faster than the rest speed, rebounds at
    /// once by Newton's law on its approach before the step's gravity, `u_0 = u + g n_y dt`, and
    /// then flies the step: `u⁺ = −e u_0 − g n_y dt` (a disk that meets the floor within a step
    /// turns a gap's width early, at most its speed × dt). Any other contact closes at most to
    /// touching, or does not close further where it overlaps.
    fn target(&self, gap: f64, lift: f64, (u, gn): (f64, f64), e: f64, rest: f64) -> Bound {
        let close = -(gap.max(0.0) + lift) / self.dt;
        let u0 = u + gn * self.dt;
        if u < close && -u0 > rest {
            let b = -e * u0 - gn * self.dt;
            Bound {
                target: close.max(b),
                bounce: b > close,
            }
        } else {
            Bound {
                target: close,
                bounce: false,
            }
        }
    }

    /// Impacts slower than this are plastic: `2 g dt` between disks and on fixed walls, and
    /// `2 (g + Aω²) dt` on the floor (`floor`): twice the approach a resting contact gains in a
    /// step, so that a step's solve left unconverged does not set contacts at rest ringing.
    fn rest_speed(&self, floor: bool) -> f64 {
        let shake = match &self.floor {
            Some(f) if floor => f.max_acceleration(),
            _ => 0.0,
        };
        2.0 * (self.g() + shake) * self.dt
    }

    /// The contacts that can close within the step from `t0` to `t1`, packed for the sweep as
    /// they are gathered (their warm starts applied to the solve's velocities).
    fn gather_rows(&mut self, t0: f64, t1: f64, warm_scale: f64) {
        let dt = self.dt;
        let (mut quads, mut vel) = (
            std::mem::take(&mut self.boundary_quads),
            std::mem::take(&mut self.vel),
        );
        let mut tags = std::mem::take(&mut self.tags);
        tags.clear();
        let mut rows = quads::Packer::new(
            &mut quads,
            &mut vel,
            self.disks.len() as u32,
            self.spin_factor,
        );
        let mut recovery = std::mem::take(&mut self.recovery);
        recovery.clear();
        let vmax = (self.disks.motion.iter())
            .map(|m| m.vx.abs().max(m.vy.abs()))
            .fold(0.0f64, f64::max);
        let (a_min, _) = self.disks.radius_range();
        let reach = 4.0 * vmax * dt + self.g() * dt * dt + HAIR * a_min;
        let (mu_floor, mu_walls, q) = match &self.rough {
            Some(r) => (r.floor.mu, r.walls.mu, r.inertia_factor),
            None => (0.0, 0.0, f64::INFINITY),
        };
        let mut inertia = Inertia::new(1.0 + 1.0 / q);
        let rest_pair = self.rest_speed(false);
        let n_disks = self.disks.len() as u32;
        let d = &self.disks;
        let floor_at = self.floor.as_ref().map(|f| {
            let (h0, h1) = (f.height(t0), f.height(t1));
            (h0, (h1 - h0) / dt, f.restitution)
        });
        let walls = match self.sides {
            SideBounds::Walls { width, e } => Some((width, e)),
            SideBounds::Periodic { .. } => None,
        };
        let lid = match self.top {
            Top::Lid { height, e } => Some((height, e)),
            _ => None,
        };
        // The parabola's ½ g dt² lifts a disk above its velocity's dt·v⁺: toward the lid, away
        // from the floor.
        let g = self.g();
        let lift = 0.5 * g * dt * dt;
        let mut deepest = self.max_overlap;
        for (i, m) in d.motion.iter().enumerate() {
            let (a, mass) = (d.radius[i], d.mass[i]);
            let mut boundary = |kind, n: (f64, f64), vb: (f64, f64), gap: f64, lift, e, mu| {
                if gap > reach {
                    return;
                }
                deepest = deepest.max(-gap);
                let u = (m.vx - vb.0) * n.0 + (m.vy - vb.1) * n.1;
                let bound = self.target(
                    gap,
                    lift,
                    (u, g * n.1),
                    e,
                    self.rest_speed(kind == Kind::Floor),
                );
                let (pn, pt) = match kind {
                    Kind::Floor => {
                        let (pn, pt) = self.warm_floor[i];
                        (pn * warm_scale, pt * warm_scale)
                    }
                    _ => (0.0, 0.0),
                };
                let [wi, wj, wn, wt, mn, mt] = inertia.of(mass, f64::INFINITY);
                recovery.add((i as u32, n_disks), n, (wi, wj, mn), gap, dt);
                rows.push(&Row {
                    i: i as u32,
                    j: n_disks,
                    n,
                    vb,
                    wi,
                    wj,
                    wn,
                    wt,
                    mn,
                    mt,
                    target: bound.target,
                    mu,
                    pn,
                    pt,
                });
                tags.push(Tag {
                    kind,
                    bounce: bound.bounce,
                });
            };
            if let Some((h0, hd, e)) = floor_at {
                boundary(
                    Kind::Floor,
                    (0.0, 1.0),
                    (0.0, hd),
                    m.y - a - h0,
                    lift,
                    e,
                    mu_floor,
                );
            }
            if let Some((width, e)) = walls {
                boundary(
                    Kind::Wall,
                    (1.0, 0.0),
                    (0.0, 0.0),
                    m.x - a,
                    0.0,
                    e,
                    mu_walls,
                );
                let right = width - m.x - a;
                boundary(Kind::Wall, (-1.0, 0.0), (0.0, 0.0), right, 0.0, e, mu_walls);
            }
            if let Some((height, e)) = lid {
                boundary(
                    Kind::Lid,
                    (0.0, -1.0),
                    (0.0, 0.0),
                    height - m.y - a,
                    -lift,
                    e,
                    mu_walls,
                );
            }
        }
        rows.finish();
        let mut pair_quads = std::mem::replace(&mut self.pair_quads, pairs::Pairs::new(false));
        let bounces = std::mem::take(&mut self.bounces);
        let mut fresh = Fresher {
            this: self,
            reach,
            warm_scale,
            rest: rest_pair,
            bounces,
            recovery: &mut recovery,
            deepest,
            deep_overlaps: 0,
        };
        let sf = self.spin_factor;
        // Two closures, each inlined into its own layout's loop.
        match &mut pair_quads {
            pairs::Pairs::Smooth(q) => pairs::refresh(q, &mut vel, sf, |k| fresh.pair(k)),
            pairs::Pairs::Rough(q) => pairs::refresh(q, &mut vel, sf, |k| fresh.pair(k)),
        }
        let Fresher {
            bounces,
            deepest,
            deep_overlaps,
            ..
        } = fresh;
        self.max_overlap = deepest;
        self.stats.deep_overlaps += deep_overlaps;
        (self.pair_quads, self.bounces) = (pair_quads, bounces);
        (self.boundary_quads, self.vel, self.tags) = (quads, vel, tags);
        self.recovery = recovery;
    }

    /// The solve's copy of the disks' inverse masses (which the velocities' loads leave alone).
    fn load_inverse_masses(&mut self) {
        for k in 0..self.disks.len() {
            self.vel[k][3] = 1.0 / self.disks.mass[k];
        }
    }

    /// The solve's copy of the disks' velocities and rim speeds.
    fn load_velocities(&mut self) {
        for (v, m) in self.vel.iter_mut().zip(&self.disks.motion) {
            (v[0], v[1]) = (m.vx, m.vy);
        }
        if let Some(spins) = &self.disks.spins {
            for (k, w) in spins.omega.iter().enumerate() {
                self.vel[k][2] = w * self.disks.radius[k];
            }
        }
    }

    /// Projected Gauss–Seidel over the step's contacts, from their warm-start impulses, on the
    /// solve's copy of the velocities and rim speeds, written back at the end.
    fn solve(&mut self) {
        let n = self.disks.len();
        let sf = self.spin_factor;
        let tol = TOLERANCE * (0.5 * self.rest_speed(true)).max(1e-12);
        for _ in 0..MAX_SWEEPS {
            self.sweeps += 1;
            let (lanes, vel) = (self.lanes, &mut self.vel);
            let boundaries = quads::sweep(lanes, &mut self.boundary_quads, vel, sf);
            let pairs = self.pair_quads.sweep(lanes, vel, sf);
            if quads::larger(pairs, boundaries) <= tol {
                break;
            }
        }
        for (m, v) in self.disks.motion.iter_mut().zip(&self.vel[..n]) {
            (m.vx, m.vy) = (v[0], v[1]);
        }
    }

    /// Keeps the impulses for the next step, counts the contacts that pushed and marks their
    /// disks, and books the floor's work and impulse, the virial, and (at `t1`) the spins.
    fn book(&mut self, t1: f64) {
        let n = self.disks.len();
        self.warm_floor.iter_mut().for_each(|w| *w = (0.0, 0.0));
        self.warm.iter_mut().for_each(|w| *w = (0.0, 0.0));
        self.pushed.iter_mut().for_each(|p| *p = false);
        self.injected_step = 0.0;
        for r in quads::pushing(&self.boundary_quads) {
            let tag = self.tags[r.row as usize];
            self.stats.rebounds += tag.bounce as u64;
            self.pushed[r.i as usize] = true;
            self.pushed[(r.j as usize).min(n)] = true;
            match tag.kind {
                Kind::Pair => unreachable!("pairs are laid out apart"),
                Kind::Floor => {
                    self.warm_floor[r.i as usize] = (r.pn, r.pt);
                    self.counts.floor += 1;
                    let work = r.pn * r.vby;
                    self.flow.injected += work;
                    self.injected_step += work;
                    self.flow.floor_impulse += r.pn;
                }
                Kind::Wall => self.counts.wall += 1,
                Kind::Lid => self.counts.lid += 1,
            }
        }
        self.pair_quads.each_pushing(|r| {
            let k = r.row as usize;
            self.stats.rebounds += self.bounces[k] as u64;
            self.pushed[r.i as usize] = true;
            self.pushed[r.j as usize] = true;
            self.warm[k] = (r.pn, r.pt);
            self.counts.pair += 1;
            self.virial += self.separations[k][2] * r.pn;
        });
        if let Some(spins) = &mut self.disks.spins {
            for (k, v) in self.vel[..spins.omega.len()].iter().enumerate() {
                let dw = v[2] / self.disks.radius[k] - spins.omega[k];
                if dw != 0.0 {
                    spins.spin(k, t1, dw);
                }
            }
        }
    }

    /// Counts the disks at rest after the step ending at `t1`: held by a contact that pushed in
    /// the step ([`Contact::book`] marks them) and moving with the floor (still, on a static
    /// one: [`Contact::resting_vy`]) to within a step of gravity, `g dt`, and not pushed by an
    /// overlap's opening ([`recovery`]: a disk pushed apart moves). A bed riding the floor below
    /// Γ = 1 is at rest as a whole, as the exact engine's riders are.
    fn count_at_rest(&mut self, t1: f64) {
        let n = self.disks.len();
        let rest_vy = self.resting_vy(t1);
        let slow = self.g() * self.dt;
        let recovery = &self.recovery;
        self.at_rest = (self.disks.motion.iter().zip(&self.pushed).enumerate())
            .filter(|&(k, (m, &pushed))| {
                let still = recovery.push(k) == [0.0; 2];
                pushed && still && m.vx.abs() < slow && (m.vy - rest_vy).abs() < slow
            })
            .count();
        self.rest_since = match self.rest_since {
            _ if self.at_rest < n => None,
            None => Some(t1),
            since => since,
        };
    }

    /// Every disk moves on its new velocity's parabola to `t1`, and by its overlaps' opening
    /// ([`recovery`]); the energy lost beyond the floor's work is booked as dissipated; the
    /// Verlet list is rebuilt when a disk has moved half the skin.
    fn advance(&mut self, t1: f64) {
        let (dt, g, sides, top) = (self.dt, self.g(), self.sides, self.top);
        for (k, m) in self.disks.motion.iter_mut().enumerate() {
            let [wx, wy] = self.recovery.push(k);
            let x = m.x + dt * (m.vx + wx);
            let y = m.y + dt * (m.vy + wy) + 0.5 * g * dt * dt;
            (m.x, m.y) = wrap(sides, top, x, y);
            m.t = t1;
        }
        let energy = self.total_energy();
        self.flow.dissipated += self.energy + self.injected_step - energy;
        self.energy = energy;
        if self.moved_half_skin() {
            self.rebuild();
        }
    }

    /// Kinetic (translation and spin) plus potential energy.
    fn total_energy(&self) -> f64 {
        let d = &self.disks;
        let g = self.g();
        let translation: f64 = (d.motion.iter().enumerate())
            .map(|(k, m)| d.mass[k] * (0.5 * (m.vx * m.vx + m.vy * m.vy) + g * m.y))
            .sum();
        translation + d.rotational_energy()
    }
}

/// Orders the Verlet pairs for the Gauss–Seidel sweep: bottom up, by the lower disk's height,
/// in bands `band` high, so that the weight of a stack reaches the floor within a sweep; within
/// a band, in groups of pairs that share no disk (a greedy colouring), so that the sweep finds
/// four in a row that it can solve at once ([`quads`]).
fn order_pairs(pairs: &mut Vec<(u32, u32)>, motion: &[Motion], band: f64) {
    let low = |&(i, j): &(u32, u32)| motion[i as usize].y.min(motion[j as usize].y);
    // By the lower disk's height, ties in list order (a stable sort), each key made once.
    let mut by_low: Vec<(i64, u32)> = (pairs.iter().enumerate())
        .map(|(k, p)| (ordered(low(p)), k as u32))
        .collect();
    by_low.sort_unstable();
    let sorted: Vec<(u32, u32)> = by_low.iter().map(|&(_, k)| pairs[k as usize]).collect();
    *pairs = sorted;
    let keyed = bands_and_colours(pairs, motion, band);
    *pairs = by_band_and_colour(pairs, &keyed);
}

/// Each pair's band (of its lower disk's height, `band` high) and colour: the first that
/// neither disk has taken in that band (a greedy colouring, in list order; at most 31).
fn bands_and_colours(pairs: &[(u32, u32)], motion: &[Motion], band: f64) -> Vec<(i64, u32)> {
    // Each disk's colours taken in the band `seen[k]`.
    let mut taken = vec![0u32; motion.len()];
    let mut seen = vec![i64::MIN; motion.len()];
    let mut keyed = Vec::with_capacity(pairs.len());
    for &(i, j) in pairs {
        let (iu, ju) = (i as usize, j as usize);
        let b = (motion[iu].y.min(motion[ju].y) / band).floor() as i64;
        for d in [iu, ju] {
            if seen[d] != b {
                (seen[d], taken[d]) = (b, 0);
            }
        }
        let colour = (!(taken[iu] | taken[ju])).trailing_zeros().min(31);
        taken[iu] |= 1 << colour;
        taken[ju] |= 1 << colour;
        keyed.push((b, colour));
    }
    keyed
}

/// `pairs` ordered by (band, colour) of `keyed`, in list order within each: the bands come in
/// rising runs (the pairs are ordered by height), so each run is sorted by counting its colours.
/// A run out of order (a height that is not a number) falls back to a sort.
fn by_band_and_colour(pairs: &[(u32, u32)], keyed: &[(i64, u32)]) -> Vec<(u32, u32)> {
    if keyed.windows(2).any(|w| w[1].0 < w[0].0) {
        let mut order: Vec<(i64, u32, u32)> = (keyed.iter().enumerate())
            .map(|(k, &(b, colour))| (b, colour, k as u32))
            .collect();
        order.sort_unstable();
        return order.iter().map(|&(_, _, k)| pairs[k as usize]).collect();
    }
    let mut out = Vec::with_capacity(pairs.len());
    let mut start = 0;
    while start < keyed.len() {
        let b = keyed[start].0;
        let end = start + keyed[start..].iter().take_while(|k| k.0 == b).count();
        let mut at = [0usize; 33];
        for &(_, colour) in &keyed[start..end] {
            at[colour as usize + 1] += 1;
        }
        for c in 1..33 {
            at[c] += at[c - 1];
        }
        out.resize(end, (0, 0));
        for (k, &(_, colour)) in keyed[start..end].iter().enumerate() {
            out[start + at[colour as usize]] = pairs[start + k];
            at[colour as usize] += 1;
        }
        start = end;
    }
    out
}

/// An `f64` as an `i64` that orders as [`f64::total_cmp`] does.
fn ordered(x: f64) -> i64 {
    let bits = x.to_bits() as i64;
    bits ^ ((((bits >> 63) as u64) >> 1) as i64)
}

/// Steps of the floor's period in the coarse step: dense beds move at about the floor's speed,
/// and no collision is missed at any step (a contact that can close within a step is in its
/// solve). The book's accuracy page gives what the step costs in accuracy against LAMMPS.
pub const STEPS_PER_PERIOD: f64 = 50.0;

/// The default coarse step: a part of the floor's period under a vibrating floor (the scheme is
/// for dense beds, which move with the floor); without one, the time-step scheme's (a tenth of
/// the smallest radius at the largest speed).
pub fn default_step(scene: &Scene, disks: &Disks) -> Option<f64> {
    match scene.floor.as_ref().filter(|f| !f.is_static()) {
        Some(f) => Some(f.period_or_one() / STEPS_PER_PERIOD),
        None => default_dt(scene, disks),
    }
}

impl<F: Flight> Integrator for Contact<F> {
    fn set_interrupt(&mut self, flag: &'static AtomicBool) {
        self.interrupt = Some(flag);
    }
    fn disks(&self) -> &Disks {
        &self.disks
    }
    fn time(&self) -> f64 {
        self.now()
    }
    fn advance_to(&mut self, target: f64) -> Result<Progress> {
        self.steps_to(target)
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
    fn disks_at_rest(&self) -> usize {
        self.at_rest
    }
    fn at_rest_since(&self) -> Option<f64> {
        self.rest_since
    }
    fn check_state(&self, _t: f64) -> Result<()> {
        Ok(())
    }
    fn setup(&self) -> Setup {
        Setup {
            scheme: "contact",
            mask: format!("verlet r={:.4}", self.verlet),
            cell: self.cells.cell(),
            grid: "cell-list".into(),
            queue: None,
            remap: None,
            bytes: self.disks.bytes()
                + self.cells.bytes()
                + 8 * self.pairs.capacity()
                + 16 * (self.warm.capacity() + self.warm_floor.capacity())
                + 8 * (self.built_x.capacity() + self.built_y.capacity())
                + self.pair_quads.bytes()
                + std::mem::size_of::<quads::Quad>() * self.boundary_quads.capacity()
                + self.bounces.capacity()
                + std::mem::size_of::<Tag>() * self.tags.capacity(),
            threads: Some(1),
        }
    }
    fn approximation(&self) -> Option<SchemeStats> {
        Some(SchemeStats {
            step: match self.step {
                0 => self.dt,
                steps => self.t / steps as f64,
            },
            steps: self.step,
            sweeps: self.sweeps,
            ..self.stats
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ordering as first written: a stable sort by height, then a sort by (band, colour,
    /// place).
    fn order_pairs_by_sorts(pairs: &mut Vec<(u32, u32)>, motion: &[Motion], band: f64) {
        let low = |&(i, j): &(u32, u32)| motion[i as usize].y.min(motion[j as usize].y);
        pairs.sort_by(|p, q| low(p).total_cmp(&low(q)));
        let mut keyed: Vec<(i64, u32, u32)> = (bands_and_colours(pairs, motion, band).iter())
            .enumerate()
            .map(|(k, &(b, colour))| (b, colour, k as u32))
            .collect();
        keyed.sort_unstable();
        *pairs = keyed.iter().map(|&(_, _, k)| pairs[k as usize]).collect();
    }

    /// A rebuild carries the impulses of exactly the pairs that pushed, found either way round,
    /// and of no other pair.
    #[test]
    fn carried_impulses_are_the_pushing_pairs_own() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let n = 50u32;
        let mut pairs = Vec::new();
        for i in 0..n {
            for j in (i + 1)..n {
                if rng.random_bool(0.1) {
                    pairs.push(if rng.random_bool(0.5) { (i, j) } else { (j, i) });
                }
            }
        }
        let warm: Vec<(f64, f64)> = (0..pairs.len())
            .map(|k| match k % 3 {
                0 => (0.0, 0.0),
                _ => (1.0 + k as f64, -(k as f64)),
            })
            .collect();
        let carried = Carried::new(n as usize, &pairs, &warm);
        for (&(i, j), &p) in pairs.iter().zip(&warm) {
            let want = (p.0 > 0.0).then_some(p);
            assert_eq!(carried.impulses((i, j)), want);
            assert_eq!(carried.impulses((j, i)), want);
        }
        let listed = |i, j| pairs.contains(&(i, j)) || pairs.contains(&(j, i));
        for i in 0..n {
            for j in (0..n).filter(|&j| j != i && !listed(i, j)) {
                assert_eq!(carried.impulses((i, j)), None);
            }
        }
    }

    /// The counting order gives the sorts' order on random beds: heights with ties, negative
    /// heights (a floor below zero), a disk in many pairs (colours up to 31), and a pair of
    /// disks whose heights are not numbers (the bands out of order).
    #[test]
    fn pairs_are_ordered_as_the_sorts_order_them() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        for case in 0..200 {
            let n = rng.random_range(2..300usize);
            let motion: Vec<Motion> = (0..n)
                .map(|_| Motion {
                    y: match rng.random_range(0..4) {
                        0 => rng.random_range(-2..20) as f64 * 0.5,
                        _ => rng.random_range(-1.0..10.0),
                    },
                    ..Motion::default()
                })
                .collect();
            let mut motion = motion;
            let mut pairs = Vec::new();
            if case % 50 == 49 {
                (motion[0].y, motion[1].y) = (f64::NAN, f64::NAN);
                pairs.push((0, 1));
            }
            pairs.extend((0..rng.random_range(0..4 * n)).map(|k| {
                let i = if k % 7 == 0 {
                    1
                } else {
                    rng.random_range(0..n)
                };
                let j = (i + rng.random_range(1..n)) % n;
                (i as u32, j as u32)
            }));
            let (mut fast, mut reference) = (pairs.clone(), pairs);
            order_pairs(&mut fast, &motion, 1.0);
            order_pairs_by_sorts(&mut reference, &motion, 1.0);
            assert_eq!(fast, reference, "case {case}");
        }
    }
}
