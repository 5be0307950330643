//! The time-step scheme: one global step dt for every disk (ReMoDy's standard scheme, with the
//! neighbour-list tutorial's cell and Verlet lists).
//!
//! A step flies every disk exactly over dt (straight line or parabola), then looks for overlaps:
//! pairs from a Verlet list of radius `2 a_max + skin`, built from a cell list (head-of-chain +
//! linked list, cells at least the Verlet radius) and rebuilt when any disk has moved more than
//! half the skin since the last build. An overlapping pair that approaches gets the pair
//! collision rule with the scene's restitution law (TC, speed cutoff included), and rough disks
//! the exact engine's tangential kick after it; an overlapping pair that recedes is left alone.
//! Walls, the lid and the floor likewise: a disk below the floor (its position as in the exact
//! model, or y = 0 in the fixed-position model) that moves down relative to it bounces with the
//! floor's velocity at that time. Energy changes only at the bounces, where they are booked, so
//! the energy budget closes to round-off.
//!
//! On several threads ([`Cores`]) the flight (with the tests for a rebuild and for disks past a
//! boundary, in one pass), the Verlet list and the search for touching pairs are shared among
//! them. The collisions found are resolved on one thread in the list's order, piece after piece
//! while the threads search the rest ([`cores::in_order`]), as on one thread (a disk in two
//! contacts feels the first before the second is tested); then the bounces, by disk number. The
//! results do not depend on the number of threads.

use super::cells::CellList;
use super::cores::{self, Cores, MIN_PIECE};
use super::rough::Rub;
use super::{free_flight_visit, min_image, wrap, wrap_positions, Integrator, SchemeStats, Setup};
use crate::engine::{EnergyFlow, EventCounts, Progress, Scene};
use crate::error::{Error, Result};
use crate::physics::disks::{Disks, Motion};
use crate::physics::drive::FloorModel;
use crate::physics::flight::Flight;
use crate::physics::floor::Floor;
use crate::physics::pair::{collide, contact_time};
use crate::physics::restitution::CollisionLaw;
use crate::physics::rough::Boundary;
use crate::physics::walls::{Side, SideBounds, Top};
use crate::scenario::Engine;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Default Verlet skin in units of the smallest radius.
pub const DEFAULT_SKIN: f64 = 1.0;

/// Overlap (relative to the contact distance) beyond which a collision counts as overlapped.
const OVERLAP_TOLERANCE: f64 = 1e-9;

/// Overlap (relative to the contact distance) counted as deep.
pub const DEEP_OVERLAP: f64 = 0.1;

/// The default step: 0.1 × the smallest radius over the largest speed at the start, that speed
/// being at least √(g·a_min) (a disk falling its own radius) and the floor's peak speed Aω.
/// `None` when nothing moves and nothing will (no speed, no gravity, no moving floor).
pub fn default_dt(scene: &Scene, disks: &Disks) -> Option<f64> {
    let (a_min, _) = disks.radius_range();
    let v_disks = disks
        .motion
        .iter()
        .map(|m| (m.vx * m.vx + m.vy * m.vy).sqrt())
        .fold(0.0f64, f64::max);
    let v_fall = (scene.gravity.unwrap_or(0.0) * a_min).sqrt();
    let v_floor = scene
        .floor
        .as_ref()
        .map_or(0.0, |f| f.drive().peak_velocity());
    let v = v_disks.max(v_fall).max(v_floor);
    (v > 0.0).then(|| 0.1 * a_min / v)
}

/// The time-step engine.
#[derive(Debug)]
pub struct TimeStep<F: Flight> {
    flight: F,
    disks: Disks,
    sides: SideBounds,
    top: Top,
    floor: Option<Floor>,
    restitution: CollisionLaw,
    rub: Rub,
    dt: f64,
    skin: f64,
    verlet: f64,
    cell: f64,
    cells: CellList,
    pairs: Vec<(u32, u32)>,
    built_x: Vec<f64>,
    built_y: Vec<f64>,
    flown: Vec<Flown>,
    step: u64,
    counts: EventCounts,
    flow: EnergyFlow,
    virial: f64,
    max_overlap: f64,
    stats: SchemeStats,
    event_limit: u64,
    interrupt: Option<&'static AtomicBool>,
    cores: Cores,
}

/// A disk at the end of a step's flight, before any collision or bounce, with its radius: what
/// the search for touching pairs reads. It is the search's own copy (one cache line a disk), so
/// that the collisions already found can be applied while it runs.
#[derive(Debug, Clone, Copy)]
struct Flown {
    x: f64,
    y: f64,
    vx: f64,
    vy: f64,
    a: f64,
}

/// Pairs of the Verlet list searched as one piece (the pieces do not depend on the threads).
const PAIRS_PIECE: usize = 1024;

/// What the search of the Verlet list found in a pair after a step.
#[derive(Clone, Copy)]
enum Found {
    /// The pair overlaps: `(dx, dy)` = r_i − r_j (nearest image), and by how much.
    Touching {
        i: u32,
        j: u32,
        dx: f64,
        dy: f64,
        overlap: f64,
    },
    /// The pair does not overlap, but the paths touched during the step.
    Missed,
}

impl<F: Flight> TimeStep<F> {
    /// Sets up the scheme for `scene` with its knobs from `engine` (`dt`, `verlet_skin`,
    /// `cell_size`, `threads`).
    pub fn new(flight: F, scene: &Scene, disks: Disks, engine: &Engine) -> Result<TimeStep<F>> {
        let n = disks.len();
        let (a_min, a_max) = disks.radius_range();
        let dt = match engine.dt {
            Some(dt) => dt,
            None => default_dt(scene, &disks).ok_or_else(|| {
                Error::input(
                    "engine.dt",
                    "cannot be chosen from the scene (nothing moves): give it",
                )
            })?,
        };
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
        let mut ts = TimeStep {
            flight,
            disks,
            sides: scene.sides,
            top: scene.top,
            floor: scene.floor.clone(),
            restitution: CollisionLaw::new(scene.restitution, n),
            rub: Rub::new(scene.rough),
            dt,
            skin,
            verlet,
            cell,
            cells: CellList::default(),
            pairs: Vec::new(),
            built_x: vec![0.0; n],
            built_y: vec![0.0; n],
            flown: Vec::new(),
            step: 0,
            counts: EventCounts::default(),
            flow: EnergyFlow::default(),
            virial: 0.0,
            max_overlap: 0.0,
            stats: SchemeStats {
                step: dt,
                ..SchemeStats::default()
            },
            event_limit: scene.max_events.unwrap_or(u64::MAX),
            interrupt: None,
            cores: Cores::new(engine.threads)?,
        };
        for m in &mut ts.disks.motion {
            m.t = 0.0;
        }
        ts.flown = (ts.disks.motion.iter().enumerate())
            .map(|(i, m)| Flown {
                x: m.x,
                y: m.y,
                vx: m.vx,
                vy: m.vy,
                a: ts.disks.radius[i],
            })
            .collect();
        wrap_positions(ts.sides, ts.top, &mut ts.disks);
        ts.cores.clone().run(|| ts.rebuild());
        Ok(ts)
    }

    /// The step dt.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    fn now(&self) -> f64 {
        self.step as f64 * self.dt
    }

    /// Rebuilds the cell list and, from it, the Verlet list.
    fn rebuild(&mut self) {
        let n = self.disks.len();
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
        (self.built_x.par_iter_mut(), self.built_y.par_iter_mut())
            .into_par_iter()
            .zip(motion.par_iter())
            .with_min_len(MIN_PIECE)
            .for_each(|((x, y), m)| (*x, *y) = (m.x, m.y));
        self.counts.rebuild += 1;
    }

    /// Whole steps up to absolute time `target`: the state between steps is free flight (see
    /// `visit_states`).
    fn steps_to(&mut self, target: f64) -> Result<Progress> {
        while (self.step + 1) as f64 * self.dt <= target + 1e-9 * self.dt {
            if self.counts.popped() >= self.event_limit {
                return Ok(Progress::EventLimit);
            }
            // A step costs O(N): the flag is looked at before each.
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

    /// One step of dt.
    fn one_step(&mut self) {
        let t1 = (self.step + 1) as f64 * self.dt;
        let floor_now = self.floor_at(t1);
        let (moved_far, past) = self.fly(t1, floor_now.map(|(h, _)| h));
        self.step += 1;
        if moved_far {
            self.rebuild();
        }
        self.pairs_step(t1);
        self.boundaries_step(past, floor_now, t1);
        self.stats.steps = self.step;
    }

    /// The floor's height (as the floor model places it) and velocity at `now`.
    fn floor_at(&self, now: f64) -> Option<(f64, f64)> {
        self.floor.as_ref().map(|f| {
            let h = match f.drive().model {
                FloorModel::Exact => f.height(now),
                FloorModel::FixedPosition => 0.0,
            };
            (h, f.velocity(now))
        })
    }

    /// Every disk flies over dt to `t1` (into the periodic box), and is copied for the search of
    /// touching pairs (its flight velocity for the test of missed collisions). Returns whether some disk has moved more than half the
    /// skin since the Verlet list was built, and the disks that reach past a boundary (the
    /// floor at height `floor`) in the order of their numbers: one hand-over to the threads for
    /// all three.
    fn fly(&mut self, t1: f64, floor: Option<f64>) -> (bool, Vec<u32>) {
        let (flight, dt, sides, top) = (self.flight, self.dt, self.sides, self.top);
        let half = 0.5 * self.skin;
        let past = self.boundary_test(floor);
        self.disks
            .motion
            .par_iter_mut()
            .zip(self.flown.par_iter_mut())
            .zip(self.built_x.par_iter().zip(self.built_y.par_iter()))
            .enumerate()
            .with_min_len(MIN_PIECE)
            .fold(
                || (false, Vec::new()),
                |(far, mut beyond), (i, ((m, f), (x0, y0)))| {
                    let (x, y, vx, vy) = flight.advance(m.x, m.y, m.vx, m.vy, dt);
                    let (x, y) = wrap(sides, top, x, y);
                    *m = Motion {
                        x,
                        y,
                        vx,
                        vy,
                        t: t1,
                    };
                    (f.x, f.y, f.vx, f.vy) = (x, y, vx, vy);
                    let (dx, dy) = min_image(sides, top, x - x0, y - y0);
                    if past(f.a, x, y) {
                        beyond.push(i as u32);
                    }
                    (far || dx * dx + dy * dy > half * half, beyond)
                },
            )
            .reduce(
                || (false, Vec::new()),
                |(far_a, mut a), (far_b, b)| {
                    a.extend(b);
                    (far_a || far_b, a)
                },
            )
    }

    /// Searches the Verlet list for the pairs that overlap after the step (or whose paths
    /// touched during it), piece by piece on the threads, and resolves the approaching ones on
    /// this thread in the list's order while the search goes on; counts the missed ones.
    fn pairs_step(&mut self, now: f64) {
        let (pairs, flown) = (
            std::mem::take(&mut self.pairs),
            std::mem::take(&mut self.flown),
        );
        let (dt, sides, top) = (self.dt, self.sides, self.top);
        cores::in_order(
            pairs.len().div_ceil(PAIRS_PIECE),
            |k| {
                let piece = &pairs[k * PAIRS_PIECE..((k + 1) * PAIRS_PIECE).min(pairs.len())];
                search_pairs(piece, &flown, dt, sides, top)
            },
            |found| {
                for &found in found {
                    match found {
                        Found::Missed => self.stats.missed += 1,
                        Found::Touching {
                            i,
                            j,
                            dx,
                            dy,
                            overlap,
                        } => self.touching(i as usize, j as usize, dx, dy, overlap, now),
                    }
                }
            },
        );
        (self.pairs, self.flown) = (pairs, flown);
    }

    /// A pair found overlapping by `overlap` at separation `(dx, dy)`: collides if it
    /// approaches (with the velocities it has now), is left alone if it recedes.
    fn touching(&mut self, i: usize, j: usize, dx: f64, dy: f64, overlap: f64, now: f64) {
        self.max_overlap = self.max_overlap.max(overlap);
        let d = &self.disks;
        let (mi, mj) = (d.motion[i], d.motion[j]);
        let s = d.radius[i] + d.radius[j];
        let (dvx, dvy) = (mi.vx - mj.vx, mi.vy - mj.vy);
        if dx * dvx + dy * dvy >= 0.0 {
            return; // receding: left alone
        }
        if overlap > OVERLAP_TOLERANCE * s {
            self.stats.overlapped_collisions += 1;
        }
        if overlap > DEEP_OVERLAP * s {
            self.stats.deep_overlaps += 1;
        }
        let e = self.restitution.collision(i, j, now, dx, dy, dvx, dvy);
        let imp = collide(dx, dy, dvx, dvy, d.mass[i], d.mass[j], e);
        imp.apply(&mut self.disks.motion, i, j);
        self.flow.dissipated += imp.energy_lost;
        self.flow.dissipated +=
            self.rub
                .pair(&mut self.disks, (i, j), (dx, dy), (dvx, dvy), &imp, now);
        self.virial += imp.distance * imp.momentum;
        self.counts.pair += 1;
    }

    /// Bounces the disks `past` a boundary (in the order of their numbers) that are still
    /// moving into it: a side wall, the lid, or the floor at `floor_now` (height, velocity).
    fn boundaries_step(&mut self, past: Vec<u32>, floor_now: Option<(f64, f64)>, now: f64) {
        for i in past {
            let i = i as usize;
            self.side_wall(i, now);
            self.lid(i, now);
            if let Some(floor_now) = floor_now {
                self.floor(i, floor_now, now);
            }
        }
    }

    /// Disk `i` bounces off a side wall it reaches past while moving into it.
    fn side_wall(&mut self, i: usize, now: f64) {
        let SideBounds::Walls { width, .. } = self.sides else {
            return;
        };
        let (a, mass) = (self.disks.radius[i], self.disks.mass[i]);
        let m = &mut self.disks.motion[i];
        let (side, depth) = if m.x - a < 0.0 && m.vx < 0.0 {
            (Side::Left, a - m.x)
        } else if m.x + a > width && m.vx > 0.0 {
            (Side::Right, m.x + a - width)
        } else {
            return;
        };
        let before = (m.vx, m.vy);
        self.flow.dissipated += self.sides.hit(side, &mut self.restitution, i, now, m, mass);
        let wall = Boundary::side(side);
        self.flow.dissipated +=
            self.rub
                .boundary(&mut self.disks, i, wall, (0.0, 0.0), before, now);
        self.counts.wall += 1;
        self.stats.max_boundary_penetration = self.stats.max_boundary_penetration.max(depth);
    }

    /// Disk `i` bounces off the lid it reaches past while moving into it.
    fn lid(&mut self, i: usize, now: f64) {
        let Top::Lid { height, .. } = self.top else {
            return;
        };
        let (a, mass) = (self.disks.radius[i], self.disks.mass[i]);
        let m = &mut self.disks.motion[i];
        if m.y + a > height && m.vy > 0.0 {
            let before = (m.vx, m.vy);
            self.flow.dissipated += self.top.hit(&mut self.restitution, i, now, m, mass);
            self.stats.max_boundary_penetration =
                self.stats.max_boundary_penetration.max(m.y + a - height);
            self.flow.dissipated +=
                self.rub
                    .boundary(&mut self.disks, i, Boundary::Lid, (0.0, 0.0), before, now);
            self.counts.lid += 1;
        }
    }

    /// Disk `i` bounces off the floor at height `h` moving with velocity `hd`, if it is below
    /// it and moves down relative to it.
    fn floor(&mut self, i: usize, (h, hd): (f64, f64), now: f64) {
        let Some(floor) = &self.floor else {
            return;
        };
        let (a, mass) = (self.disks.radius[i], self.disks.mass[i]);
        let m = &mut self.disks.motion[i];
        if m.y - a < h && m.vy < hd {
            let after = floor.hit(&mut self.restitution, i, now, m.vy, hd);
            self.flow.floor_work(mass, m.vy, after);
            self.stats.max_boundary_penetration =
                self.stats.max_boundary_penetration.max(h - (m.y - a));
            let before = (m.vx, m.vy);
            m.vy = after;
            self.counts.floor += 1;
            self.flow.dissipated +=
                self.rub
                    .boundary(&mut self.disks, i, Boundary::Floor, (0.0, hd), before, now);
        }
    }

    /// Whether a disk of radius `a` at `(x, y)` reaches past a side wall, the lid or the floor
    /// (at height `floor`), whichever way it moves.
    fn boundary_test(&self, floor: Option<f64>) -> impl Fn(f64, f64, f64) -> bool + Sync {
        let width = match self.sides {
            SideBounds::Walls { width, .. } => Some(width),
            SideBounds::Periodic { .. } => None,
        };
        let lid = match self.top {
            Top::Lid { height, .. } => Some(height),
            _ => None,
        };
        move |a, x, y| {
            width.is_some_and(|w| x - a < 0.0 || x + a > w)
                || lid.is_some_and(|h| y + a > h)
                || floor.is_some_and(|h| y - a < h)
        }
    }
}

impl<F: Flight> Integrator for TimeStep<F> {
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
        self.cores.clone().run(|| self.steps_to(target))
    }
    fn has_threads(&self) -> bool {
        true
    }
    fn advance_beside(&mut self, target: f64, beside: impl FnOnce() + Send) -> Result<Progress> {
        self.cores
            .clone()
            .run(|| rayon::join(|| self.steps_to(target), beside).0)
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
            scheme: "time-step",
            mask: format!("verlet r={:.4}", self.verlet),
            cell: self.cells.cell(),
            grid: "cell-list".into(),
            queue: None,
            remap: None,
            bytes: self.disks.bytes()
                + self.cells.bytes()
                + 8 * self.pairs.capacity()
                + 8 * (self.built_x.capacity() + self.built_y.capacity())
                + std::mem::size_of::<Flown>() * self.flown.capacity()
                + self.restitution.bytes(),
            threads: Some(self.cores.count()),
        }
    }
    fn approximation(&self) -> Option<SchemeStats> {
        Some(self.stats)
    }
}

/// The `pairs` that overlap after the step, or whose paths touched during it (`flown`: the disks
/// at the end of the step's flight), in the list's order.
fn search_pairs(
    pairs: &[(u32, u32)],
    flown: &[Flown],
    dt: f64,
    sides: SideBounds,
    top: Top,
) -> Vec<Found> {
    pairs
        .iter()
        .filter_map(|&(i, j)| {
            let (fi, fj) = (flown[i as usize], flown[j as usize]);
            let (dx, dy) = min_image(sides, top, fi.x - fj.x, fi.y - fj.y);
            let s = fi.a + fj.a;
            let d2 = dx * dx + dy * dy;
            if d2 < s * s {
                let overlap = s - d2.sqrt();
                return Some(Found::Touching {
                    i,
                    j,
                    dx,
                    dy,
                    overlap,
                });
            }
            // Did their paths touch during the step? Relative motion is straight.
            let (fvx, fvy) = (fi.vx - fj.vx, fi.vy - fj.vy);
            let tc = contact_time(dx - fvx * dt, dy - fvy * dt, fvx, fvy, s, 0.0)?;
            (tc < dt).then_some(Found::Missed)
        })
        .collect()
}
