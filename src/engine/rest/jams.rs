//! What ends the sequences a bed coming to rest would otherwise ring in for ever, each a
//! rule of the resting contacts (`collisions.resting_contacts`, see [`resting`](crate::engine::rest::resting)):
//!
//! - **a slot** between supports at rest that do not give (`stop_in_slot`);
//! - **a jammed cluster** of slow flying disks that only hold as a whole (`settle_cluster`);
//! - **a jammed row**, disks at rest side by side from wall to wall (`in_jammed_row`,
//!   `meet_held`), and a **gentle push** on a disk at rest (`pushed_gently`);
//! - **a pocket** by a side wall, where a frictionless disk slides to the wall and back
//!   (`rest_in_pocket`);
//! - **a closed wedge**, or disks ringing in gaps of round-off, where a flying disk has events
//!   at one instant without end (`stop_zeno`);
//! - **a slot on the floor a hair too narrow**, left by a row of disks that came to rest a hair
//!   apart, where a disk would stay wedged above the floor and tilt every column above it
//!   (`room_on_floor`, `make_room`); **a full row of flying disks seated on a row at
//!   rest**, each a hair from the top of the disk below it, ringing sideways between the walls
//!   (`seat_row`); and **a full row on the floor** with no play but round-off, ringing sideways
//!   between the walls (`stop_floor_row`).

use crate::engine::rest::resting::{HAIR, TOUCH};
use crate::engine::rest::riders::{NO_DISK, RIGHT_WALL};
use crate::engine::Simulation;
use crate::error::Result;
use crate::physics::flight::Flight;
use crate::physics::floor::Floor;
use crate::physics::walls::SideBounds;

/// A slot whose two contact normals sum to less than this (they are within ~6° of opposite)
/// stops a disk moving deeper into it (see `stop_in_slot`).
pub const WEDGE: f64 = 0.1;

/// A slot whose two contact normals sum to less than this (within ~0.06° of opposite) has no
/// deeper end: a disk that bounces across it between supports that do not slide, barely moving
/// along it (slower than the sleep speed), would bounce at least ~π/10⁻³ times before it left,
/// either way (see `stop_in_slot`).
pub const PARALLEL: f64 = 1e-3;

/// More events than this for one flying disk at one instant stop it (see `stop_zeno`).
pub const ZENO: u32 = 64;

/// Events of one disk closer together than this many time units `√(a/g)` count as at one
/// instant (see `stop_zeno`): a disk at the sleep speed crosses 10⁻¹² radii in that time.
pub const INSTANT: f64 = 1e-9;

/// A flying disk within this many radii of the floor may be let down onto it (see
/// `room_on_floor`).
pub const WEDGE_DROP: f64 = 0.02;

/// The most, in radii of the landing disk, that a row of disks at rest on the floor is pushed
/// aside to make room for it (see `room_on_floor`): a [`HAIR`].
pub const ROOM: f64 = HAIR;

/// Round-off allowed when a row pushed aside fills the width exactly, in radii.
const TIGHT: f64 = 1e-12;

/// The longest row pushed aside (see `room_on_floor`).
const ROOM_ROW: usize = 64;

/// How to let a disk down onto the floor (see `room_on_floor`): move the disks `shifts` in the
/// direction `dir` (±1 in x), each by its distance (the landing disk first, by a negative one:
/// away from the row), and lower the landing disk by `drop`.
pub(in crate::engine) struct Room {
    dir: f64,
    drop: f64,
    shifts: Vec<(u32, f64)>,
}

/// The square of [`INSTANT`] time units per unit radius, `INSTANT² / (g + h''_max)`, for disks
/// pressed by gravity `g` and the floor's largest acceleration (0, exactly one instant, if
/// nothing presses).
pub fn instant2(g: f64, floor: Option<&Floor>) -> f64 {
    let press = g + floor.map_or(0.0, |f| f.max_acceleration());
    if press > 0.0 {
        INSTANT * INSTANT / press
    } else {
        0.0
    }
}

impl<F: Flight> Simulation<F> {
    /// Flying disk `k` hits disk `s` at rest (contact normal `n` from `s` to `k`) while it touches,
    /// on the other side, a disk at rest or a side wall whose normal is nearly opposite (the two
    /// sum to less than [`WEDGE`]): a slot between supports that do not give, and k moves deeper
    /// into it (or, in a slot within [`PARALLEL`] of straight, which has no deeper end, barely
    /// moves along it). Between rigid walls it would collide ~π/|n_s + n_c| times at once and
    /// stop (for e < 1; with a cure it would rattle in zero gaps for ever): it stops at once —
    /// it comes to rest if the place holds it, else it is left still to fall out of the slot.
    /// Returns whether it stopped (the collision is then done).
    pub(in crate::engine) fn stop_in_slot(
        &mut self,
        k: usize,
        s: usize,
        (nx, ny): (f64, f64),
        dist: f64,
    ) -> Result<bool> {
        let now = self.now;
        let (xk, yk, vxk, vyk) = self.state_at(k, now);
        let ak = self.disks.radius[k];
        let touch = TOUCH * ak;
        let vs = self.disks.motion[s].vx;
        let (h, hd) = self
            .bounds
            .floor
            .as_ref()
            .expect("riders need a floor")
            .ride(now);
        let (vx, vy) = (vxk - vs, vyk - hd);
        // A parallel slot holds a disk barely moving along it, between supports that do not
        // slide (a sliding one would close or open it).
        let (along, gentle, still) = ((vx * ny - vy * nx).abs(), self.sleep_speed(k), vs == 0.0);
        let into = |(cx, cy): (f64, f64)| {
            let (bx, by) = (nx + cx, ny + cy);
            let b = bx.hypot(by);
            b < WEDGE && (vx * bx + vy * by < 0.0 || (b < PARALLEL && along < gentle && still))
        };
        let wall = match self.bounds.sides {
            SideBounds::Walls { width, .. } => {
                (xk - ak <= touch && into((1.0, 0.0)))
                    || (width - xk - ak <= touch && into((-1.0, 0.0)))
            }
            _ => false,
        };
        let slot = wall
            || self.map.lists.of(k).iter().any(|&c| {
                let c = c as usize;
                if c == s || !self.is_riding(c) || self.disks.motion[c].vx != vs {
                    return false;
                }
                let (xc, yc, _, _) = self.state_at(c, now);
                let (dx, dy) = self.wrap(xk - xc, yk - yc);
                let d = (dx * dx + dy * dy).sqrt();
                d - ak - self.disks.radius[c] <= touch && into((dx / d, dy / d))
            });
        if !slot {
            return Ok(false);
        }
        self.check_contact(k, s, dist)?;
        self.tally.counts.pair += 1;
        let floor = self.floor_place(k, h);
        let on_floor = floor.is_some();
        let room = floor.flatten();
        let held = if on_floor {
            Some([NO_DISK; 2])
        } else {
            self.stable_supports(k, s, None)
        };
        if let Some(supports) = held {
            let free = !self.squeezed(k, vs, hd) && !self.near_lid(k);
            if free {
                if let Some(room) = room {
                    self.make_room(k, room);
                }
            }
            if free && self.come_to_rest(k, h, supports, (vs, hd)) {
                self.predict(s);
                self.settle_cluster(k);
                return Ok(true);
            }
        }
        // Still, relative to the supports, as a flying disk.
        self.take_velocity(k, (vs, hd));
        self.moved(k);
        self.predict(s);
        Ok(true)
    }

    /// A flying disk whose events keep happening at one instant — more than [`ZENO`] after the
    /// first, all within [`INSTANT`] — is caught in a closed wedge of neighbours and walls that
    /// do not give, or rings with its neighbours in gaps of round-off, where a cure makes the
    /// collisions elastic (with e < 1 the sequence would be infinite too, its limit a disk at
    /// rest among them). It stops: it takes the floor's velocity (kinetic energy relative to the
    /// floor booked as dissipated, the rest as floor work) and comes to rest if its place holds
    /// it, or else flies on from there, and the slow flying disks it touches stop with it.
    /// Returns whether it did (the event is then dropped; its partner's prediction is renewed
    /// as stale).
    #[inline]
    pub(in crate::engine) fn stop_zeno(&mut self, i: usize) -> bool {
        let now = self.now;
        if self.rest.same_instant.is_empty() || self.is_riding(i) {
            return false;
        }
        let instant2 = self.rest.zeno_instant2 * self.disks.radius[i];
        let seen = &mut self.rest.same_instant[i];
        // Within `INSTANT √(a/g)` of the first, squared (no square root per event); not so a
        // first event (NaN), or one from before the clock was re-based.
        let dt = now - seen.0;
        if !(dt >= 0.0 && dt * dt <= instant2) {
            *seen = (now, 0);
            return false;
        }
        seen.1 += 1;
        if seen.1 <= ZENO {
            return false;
        }
        seen.1 = 0;
        self.stop_caught(i);
        true
    }

    /// Disk `i`, caught at one instant (see [`stop_zeno`](Self::stop_zeno)), stops: at rest
    /// if its place holds it, else still relative to the floor together with the slow flying
    /// disks it touches, directly or through each other.
    #[cold]
    #[inline(never)]
    fn stop_caught(&mut self, i: usize) {
        let now = self.now;
        self.tally.counts.zeno += 1;
        self.bring(i, now);
        let (h, hd) = self
            .bounds
            .floor
            .as_ref()
            .expect("riders need a floor")
            .ride(now);
        let pressed = self.sleep_speed(i) > 0.0;
        // At rest where it is, if the floor presses and the place holds it (on the floor, or
        // between disks at rest that do not slide, or walls): still, it would be pressed back
        // into the same neighbours at once. A flying disk about to hit it wakes it as usual.
        let place = if !pressed || self.near_lid(i) {
            None
        } else if self.touches_floor(i, h) {
            Some([NO_DISK; 2])
        } else {
            self.stable_place(i, None, |c| {
                self.is_riding(c) && self.disks.motion[c].vx == 0.0
            })
        };
        if let Some(place) = place {
            if self.come_to_rest(i, h, place, (0.0, hd)) {
                self.settle_cluster(i);
                return;
            }
        }
        self.take_velocity(i, (0.0, hd));
        if !pressed {
            self.moved(i);
            return;
        }
        // The slow flying disks it touches, directly or through each other, ring with it (a
        // push passes round them and back at one instant): they stop with it.
        let mut member = std::mem::take(&mut self.rest.in_cluster);
        member.resize(self.disks.len(), false);
        let mut cluster = std::mem::take(&mut self.rest.cluster);
        self.gather_slow(i, hd, &mut member, &mut cluster);
        for &c in &cluster[1..] {
            self.bring(c as usize, now);
            self.take_velocity(c as usize, (0.0, hd));
        }
        for &c in &cluster {
            self.moved(c as usize);
            member[c as usize] = false;
        }
        cluster.clear();
        self.rest.cluster = cluster;
        self.rest.in_cluster = member;
    }

    /// Flying disk `k` (brought to now) reaches a side wall while it slides, in gentle hops, on
    /// a disk `s` at rest that holds it against that wall (the contact normal and the wall's
    /// bracket the vertical): a pocket. If its kinetic energy relative to `s` cannot carry it
    /// over the top of `s`, it is trapped there: frictionless and with an elastic wall (or a
    /// cure making its hops elastic) it would slide down to the wall and back for ever, at a few
    /// sleep speeds, one hop every ~10⁻³ — the static friction of real grains stops it, and so
    /// does this: it comes to rest on `s` and the wall. The energy it had (at most its weight
    /// times the pocket's depth) is booked as dissipated. Returns whether it did (the wall
    /// collision is then done).
    pub(in crate::engine) fn rest_in_pocket(&mut self, k: usize, wall: u32) -> bool {
        if !self.rest.resting_contacts || self.bounds.floor.is_none() || self.is_riding(k) {
            return false;
        }
        let gentle = self.sleep_speed(k);
        if gentle == 0.0 {
            return false;
        }
        let Some(supports) = self.stable_place(k, None, |c| self.is_riding(c)) else {
            return false;
        };
        let s = match supports {
            [s, w] | [w, s] if w == wall && s < RIGHT_WALL => s as usize,
            _ => return false,
        };
        let mk = self.disks.motion[k];
        let (xs, ys, vxs, vys) = self.state_at(s, self.now);
        let (dx, dy) = self.wrap(mk.x - xs, mk.y - ys);
        let dist = (dx * dx + dy * dy).sqrt();
        let (dvx, dvy) = (mk.vx - vxs, mk.vy - vys);
        // Sliding on s: no more than a gentle hop along the contact normal.
        if ((dvx * dx + dvy * dy) / dist).abs() > gentle {
            return false;
        }
        // Trapped: climbing to the top of s would take more than its kinetic energy.
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        let press = self.flight.g() + floor.ride_acceleration(self.now);
        if 0.5 * (dvx * dvx + dvy * dvy) >= press * (dist - dy) {
            return false;
        }
        let (h, hd) = floor.ride(self.now);
        if self.squeezed(k, vxs, hd) || self.near_lid(k) {
            return false;
        }
        if !self.come_to_rest(k, h, supports, (vxs, hd)) {
            return false;
        }
        self.tally.counts.wall += 1;
        true
    }

    /// Whether disk `s` is at rest in a *jammed row* against a horizontal push of sign `push`:
    /// a chain of disks at rest that do not slide, each touching the next side by side (within
    /// [`TOUCH`] radii, the contact within [`TOUCH`] of horizontal), from `s` to the side wall
    /// the push points to — or all the way round where the sides are periodic. The push is then
    /// taken by the wall, its downward part by what carries the row: the row cannot move.
    pub(in crate::engine) fn in_jammed_row(&self, s: usize, push: f64) -> bool {
        let row = |c: usize| self.is_riding(c) && self.disks.motion[c].vx == 0.0;
        if push == 0.0 || !row(s) {
            return false;
        }
        let now = self.now;
        let width = self.bounds.sides.width();
        let mut cur = s;
        for _ in 0..self.disks.len() {
            let (x, y, _, _) = self.state_at(cur, now);
            let a = self.disks.radius[cur];
            if let SideBounds::Walls { .. } = self.bounds.sides {
                let gap = if push < 0.0 { x - a } else { width - x - a };
                if gap <= TOUCH * a {
                    return true;
                }
            }
            let next = self
                .map
                .lists
                .of(cur)
                .iter()
                .map(|&c| c as usize)
                .find(|&c| {
                    if !row(c) {
                        return false;
                    }
                    let (xc, yc, _, _) = self.state_at(c, now);
                    let (dx, dy) = self.wrap(xc - x, yc - y);
                    let reach = a + self.disks.radius[c];
                    let dist = (dx * dx + dy * dy).sqrt();
                    dx * push > 0.0 && dist - reach <= TOUCH * a && dy.abs() <= TOUCH * reach
                });
            match next {
                Some(c) if c == s => return true, // round the periodic sides
                Some(c) => cur = c,
                None => return false,
            }
        }
        false
    }

    /// Whether flying disk `k` (brought to now, `(sx, sy)` from `s` to it) pushes disk `s`, at
    /// rest and not sliding, slower than the sleep speed: too gently to move it (the static
    /// friction of resting contacts). Without this a push passes along a row of disks at rest,
    /// each knocked off its supports and at rest again at once, and back, at one instant.
    pub(in crate::engine) fn pushed_gently(
        &self,
        k: usize,
        s: usize,
        (sx, sy): (f64, f64),
    ) -> bool {
        if self.disks.motion[s].vx != 0.0 {
            return false;
        }
        let (_, hd) = self
            .bounds
            .floor
            .as_ref()
            .expect("riders need a floor")
            .ride(self.now);
        let mk = &self.disks.motion[k];
        let u = (mk.vx * sx + (mk.vy - hd) * sy) / sx.hypot(sy);
        -u < self.sleep_speed(k)
    }

    /// Flying disk `k` (brought to now, `(sx, sy)` from `s` to it) hits disk `s` of a jammed
    /// row (see [`in_jammed_row`](Self::in_jammed_row)), or pushes it gently (see
    /// [`pushed_gently`](Self::pushed_gently)): `s` does not give. Its restitution is that of
    /// an impact on a boundary (a cure acts only through k's own past, as at a wall: the row, hit
    /// over and over, does not make every impact on it elastic). It comes to rest on `s` if the meeting
    /// is gentle (see [`try_rest_on`](Self::try_rest_on)); else it bounces off `s` as off a fixed
    /// disk moving with the floor, and the row stays at rest. The exact engine would send the
    /// push through the row to the wall and back in a chain of collisions at one instant, for
    /// ever under a cure (the *exact jam*).
    pub(in crate::engine) fn meet_held(
        &mut self,
        k: usize,
        s: usize,
        (sx, sy): (f64, f64),
    ) -> Result<()> {
        let now = self.now;
        let (_, hd) = self
            .bounds
            .floor
            .as_ref()
            .expect("riders need a floor")
            .ride(now);
        let dist = (sx * sx + sy * sy).sqrt();
        let (nx, ny) = (sx / dist, sy / dist);
        // Normal velocity relative to the row, which moves with the floor.
        let mk = self.disks.motion[k];
        let u = mk.vx * nx + (mk.vy - hd) * ny;
        let e = if self.restitution.boundary_elastic(k, now, (-u).max(0.0)) {
            1.0
        } else {
            self.restitution.law.e
        };
        if self.try_rest_on(k, s, e)? {
            return Ok(());
        }
        let after = (-e * u).max(u).max(self.landing_rebound(k, s, sy, dist));
        self.check_contact(k, s, dist)?;
        let mass = self.disks.mass[k];
        let m = &mut self.disks.motion[k];
        m.vx += (after - u) * nx;
        m.vy += (after - u) * ny;
        let gained = 0.5 * mass * (m.vx * m.vx + m.vy * m.vy - mk.vx * mk.vx - mk.vy * mk.vy);
        let lost = 0.5 * mass * (u * u - after * after);
        self.tally.flow.dissipated += lost;
        self.tally.flow.injected += gained + lost;
        self.tally.flow.floor_impulse += mass * (after - u) * ny;
        self.tally.virial += dist * mass * (after - u);
        self.tally.counts.pair += 1;
        self.moved(k);
        // `s` did not change: only its own event (this one, if it was its) needs renewing.
        self.predict(s);
        Ok(())
    }

    /// Gathers into `cluster` (marking `member`) disk `seed` if it flies, and the flying disks
    /// touching it, directly or through each other, that move slower than the sleep speed
    /// relative to the floor (moving at `hd`): breadth first from the seed.
    fn gather_slow(&self, seed: usize, hd: f64, member: &mut [bool], cluster: &mut Vec<u32>) {
        let now = self.now;
        if !self.is_riding(seed) {
            member[seed] = true;
            cluster.push(seed as u32);
        }
        let mut from = seed;
        let mut next = 0;
        loop {
            let (xs, ys, _, _) = self.state_at(from, now);
            for &c in self.map.lists.of(from) {
                let c = c as usize;
                if member[c] || self.is_riding(c) {
                    continue;
                }
                let (xc, yc, vxc, vyc) = self.state_at(c, now);
                let ac = self.disks.radius[c];
                let (dx, dy) = self.wrap(xc - xs, yc - ys);
                let gap = (dx * dx + dy * dy).sqrt() - ac - self.disks.radius[from];
                if gap <= TOUCH * ac && vxc.hypot(vyc - hd) <= self.sleep_speed(c) {
                    member[c] = true;
                    cluster.push(c as u32);
                }
            }
            let Some(&c) = cluster.get(next) else { break };
            from = c as usize;
            next += 1;
        }
    }

    /// Disk `seed` has just come to rest, or is a slow flying disk that has just met another.
    /// The flying disks touching it (and `seed` itself, if it flies), directly or through each
    /// other, that move slower than the sleep speed relative to the floor (a jammed layer or an
    /// arch, held only as a whole) come to rest together: those of them that are in a stable
    /// place among the disks at rest that do not slide, the side walls, the floor and each other —
    /// dropping, until none is left, any that is not. Each would land where it is, gently, within
    /// [`TOUCH`] radii; without this such a cluster rattles on its supports for ever.
    pub(in crate::engine) fn settle_cluster(&mut self, seed: usize) {
        let n = self.disks.len();
        let now = self.now;
        let (h, hd) = self
            .bounds
            .floor
            .as_ref()
            .expect("riders need a floor")
            .ride(now);
        let mut member = std::mem::take(&mut self.rest.in_cluster);
        member.resize(n, false);
        let mut cluster = std::mem::take(&mut self.rest.cluster);
        self.gather_slow(seed, hd, &mut member, &mut cluster);
        // Prune: drop the members that no place holds, until every remaining one is held.
        let place = |sim: &Self, c: usize, member: &[bool]| -> Option<[u32; 2]> {
            if sim.squeezed(c, 0.0, hd) || sim.near_lid(c) {
                return None;
            }
            if sim.touches_floor(c, h) {
                return Some([NO_DISK; 2]);
            }
            sim.stable_place(c, None, |s| {
                member[s] || (sim.is_riding(s) && sim.disks.motion[s].vx == 0.0)
            })
        };
        // The places of the last pass, the one that dropped nothing, hold together.
        let mut places = Vec::new();
        loop {
            places.clear();
            let mut dropped = false;
            for &c in &cluster {
                let c = c as usize;
                if !member[c] {
                    continue;
                }
                match place(self, c, &member) {
                    Some(p) => places.push((c, p)),
                    None => {
                        member[c] = false;
                        dropped = true;
                    }
                }
            }
            if !dropped {
                break;
            }
        }
        // Rest: every place is known first (they refer to each other), then every disk rests.
        let mut refused = Vec::new();
        for &(c, p) in &places {
            self.bring(c, now);
            if !self.come_to_rest(c, h, p, (0.0, hd)) {
                refused.push(c);
            }
        }
        // A disk that could not be carried (its supports are full) lets go of what rests on it.
        for c in refused {
            self.release_carried(c, None);
        }
        for &c in &cluster {
            member[c as usize] = false;
        }
        cluster.clear();
        self.rest.cluster = cluster;
        self.rest.in_cluster = member;
    }
    /// Whether flying disk `k` (at now) can rest on the floor's surface `h`: `Some(None)` if it
    /// touches it, `Some(room)` if it can be let down onto it ([`room_on_floor`](Self::room_on_floor),
    /// to be done with [`make_room`](Self::make_room)), `None` otherwise.
    pub(in crate::engine) fn floor_place(&self, k: usize, h: f64) -> Option<Option<Room>> {
        if self.touches_floor(k, h) {
            Some(None)
        } else {
            self.room_on_floor(k, h).map(Some)
        }
    }

    /// Flying disk `k` (at now), within [`WEDGE_DROP`] radii above the floor's surface `h`, would
    /// rest on the floor but for one disk at rest on the floor (not sliding) beside it, which
    /// overlaps its place there by at most [`ROOM`] radii: a row at rest that came to rest a hair
    /// apart (gaps within [`TOUCH`]) and left a slot a hair too narrow. Left there, k rests wedged
    /// between that disk and a wall (or another disk) on a contact a few milliradians from
    /// horizontal — held by a sideways force hundreds of times its weight, which the row's own
    /// gaps could not take — and every column that comes to rest above it stands tilted, so that
    /// the rows above ring sideways for ever under a cure (the exact jam). Frictionless, k would
    /// slide down, pushing the row aside. Returns how: k moves away from the row as far as it
    /// can, the row (disks at rest on the floor, each pushing the next) takes the rest, if it has
    /// the play before a side wall and nothing else (a disk it carries, a flying disk) is in the
    /// way; `None` otherwise.
    pub(in crate::engine) fn room_on_floor(&self, k: usize, h: f64) -> Option<Room> {
        let now = self.now;
        let (xk, yk, _, _) = self.state_at(k, now);
        let a = self.disks.radius[k];
        let drop = yk - h - a;
        if drop <= 0.0 || drop > WEDGE_DROP * a {
            return None;
        }
        let at_rest = |c: usize| {
            self.is_riding(c) && self.rest.riders.on_floor(c) && self.disks.motion[c].vx == 0.0
        };
        // What is in k's place on the floor: one disk at rest, a hair in; and how far k can
        // move the other way (to a side wall or the next disk).
        let mut blocker = None;
        for &c in self.map.lists.of(k) {
            let c = c as usize;
            let (xc, yc, _, _) = self.state_at(c, now);
            let (dx, dy) = self.wrap(xc - xk, yc - (h + a));
            let reach = a + self.disks.radius[c];
            if dx * dx + dy * dy >= reach * reach {
                continue;
            }
            if blocker.is_some() || !at_rest(c) || dx == 0.0 {
                return None;
            }
            let need = (reach * reach - dy * dy).sqrt() - dx.abs();
            if need > ROOM * a {
                return None;
            }
            blocker = Some((c, dx.signum(), need));
        }
        let (first, dir, need) = blocker?;
        let mut free = f64::INFINITY;
        if let SideBounds::Walls { width, .. } = self.bounds.sides {
            free = if dir > 0.0 { xk - a } else { width - xk - a };
        }
        for &c in self.map.lists.of(k) {
            let c = c as usize;
            let (xc, yc, _, _) = self.state_at(c, now);
            let (dx, dy) = self.wrap(xc - xk, yc - (h + a));
            let reach = a + self.disks.radius[c];
            if dx * dir < 0.0 && dy.abs() < reach {
                free = free.min(dx.abs() - (reach * reach - dy * dy).sqrt());
            }
        }
        let aside = free.clamp(0.0, need);
        let mut shifts = vec![(k as u32, -aside)];
        // The row from the blocker on, each pushed as far as it must be.
        let (mut cur, mut rest) = (first, need - aside);
        for _ in 0..ROOM_ROW {
            if rest <= 0.0 {
                return Some(Room { dir, drop, shifts });
            }
            shifts.push((cur as u32, rest));
            let (x, y, _, _) = self.state_at(cur, now);
            let ac = self.disks.radius[cur];
            if let SideBounds::Walls { width, .. } = self.bounds.sides {
                let gap = if dir < 0.0 { x - ac } else { width - x - ac };
                // (A row that fills the width exactly has no play but round-off.)
                if gap < rest - TIGHT * ac {
                    return None;
                }
            }
            let mut next = None;
            for &c in self.map.lists.of(cur) {
                let c = c as usize;
                if shifts.iter().any(|&(d, _)| d as usize == c) {
                    continue;
                }
                let (xc, yc, _, _) = self.state_at(c, now);
                let (dx, dy) = self.wrap(xc - x, yc - y);
                let reach = ac + self.disks.radius[c];
                let sx = dx - dir * rest;
                if sx * sx + dy * dy >= reach * reach {
                    continue;
                }
                if next.is_some() || !at_rest(c) || dx * dir <= 0.0 {
                    return None;
                }
                let room = dx.abs() - (reach * reach - dy * dy).sqrt();
                next = Some((c, rest - room.max(0.0)));
            }
            match next {
                None => return Some(Room { dir, drop, shifts }),
                Some((c, r)) => (cur, rest) = (c, r),
            }
        }
        None
    }

    /// Does what [`room_on_floor`](Self::room_on_floor) found: moves the landing disk `k` (at
    /// now) aside and down onto the floor, its potential energy booked as dissipated (taken by
    /// the row's contacts), and pushes the row aside (each disk of it lets go of what rests on
    /// it, which falls the hair back onto it). The DUTC margin is charged with the largest move.
    pub(in crate::engine) fn make_room(&mut self, k: usize, room: Room) {
        let now = self.now;
        // k moves aside (its shift, the first) and down.
        let mut most = room.shifts[0].1.hypot(room.drop);
        for &(c, d) in &room.shifts {
            let c = c as usize;
            self.bring(c, now);
            self.disks.motion[c].x += room.dir * d;
            self.wrap_position(c);
            most = most.max(d.abs());
        }
        let mass = self.disks.mass[k];
        self.tally.flow.dissipated += mass * self.flight.g() * room.drop;
        self.disks.motion[k].y -= room.drop;
        self.map.dutc.displaced(now, most);
        for &(c, _) in &room.shifts[1..] {
            let c = c as usize;
            self.release_carried(c, None);
            self.disks.counter[c] = self.disks.counter[c].wrapping_add(1);
            self.predict(c);
        }
    }

    /// Flying disks `i` and `j` (brought to now) meet side by side. If they belong to a *full
    /// row seated on a row at rest* — disks side by side from side wall to side wall (or round
    /// the periodic sides), each at rest (not sliding, on one support) or flying within [`ROOM`]
    /// radii sideways and [`WEDGE_DROP`] radii up from the top of a disk at rest, not sliding,
    /// straight below it — the row comes to rest seated: each flying disk on the top of its
    /// seat, its kinetic energy relative to the seat and the potential energy of the hair it
    /// drops booked as dissipated. Returns whether it did (the collision is then done).
    ///
    /// Such a row has no room sideways but round-off: its disks ring between each other and the
    /// walls in gaps of 10⁻⁶ radii, and under a cure every such collision is elastic, so the row
    /// never slows; a disk a hair out of line stands a few milliradians up on its neighbour and
    /// turns the bouncing of the rows above into sideways motion (the exact jam). Without a
    /// cure the sideways motion would collapse inelastically, in infinitely many collisions, to
    /// the row at rest on its seats: the rule goes there at once.
    pub(in crate::engine) fn seat_row(&mut self, i: usize, j: usize) -> bool {
        let now = self.now;
        let (h, hd) = self
            .bounds
            .floor
            .as_ref()
            .expect("riders need a floor")
            .ride(now);
        let mut row = std::mem::take(&mut self.rest.cluster);
        let mut seats = Vec::new();
        let ok = self.full_row(i, j, &mut row)
            && row.iter().all(|&m| match self.seat_of(m as usize) {
                Some(seat) => {
                    seats.push(seat);
                    true
                }
                None => false,
            })
            && self.seats_hold(&row, &seats);
        if ok {
            // Two seated disks may close in by both their moves: the margin is charged the sum.
            let mut moved = 0.0;
            for (&m, &(seat, x, y)) in row.iter().zip(&seats) {
                let m = m as usize;
                if self.is_riding(m) {
                    continue;
                }
                self.bring(m, now);
                let mass = self.disks.mass[m];
                let (x0, y0) = (self.disks.motion[m].x, self.disks.motion[m].y);
                self.tally.flow.dissipated += mass * self.flight.g() * (y0 - y);
                self.take_velocity(m, (0.0, hd));
                self.disks.motion[m].x = x;
                self.disks.motion[m].y = y;
                self.wrap_position(m);
                moved += (x - x0).hypot(y - y0);
                if self.rest.riders.mount_on_disks(m, y - h, [seat, NO_DISK]) {
                    self.tally.counts.rest += 1;
                }
            }
            self.map.dutc.displaced(now, moved);
            self.tally.counts.pair += 1;
            for &m in &row {
                self.moved(m as usize);
            }
        }
        row.clear();
        self.rest.cluster = row;
        ok
    }

    /// Disks `i` and `j` (brought to now), both riding on the floor, meet side by side. If they
    /// belong to a *full row on the floor* — disks side by side from side wall to side wall
    /// (or round the periodic sides), no gap between neighbours or at a wall wider than
    /// [`ROOM`] radii, each on the floor or flying within [`WEDGE_DROP`] radii above it
    /// (wedged a hair high) — the row stops: every disk takes the floor's velocity, its kinetic energy relative to the
    /// floor booked as dissipated. Returns whether it did (the collision is then done).
    ///
    /// Such a row has no room but round-off (the exact jam): its disks ring between each
    /// other and the walls, every collision elastic under a cure; without one the sideways
    /// motion would collapse inelastically to the row at rest.
    pub(in crate::engine) fn stop_floor_row(&mut self, i: usize, j: usize) -> bool {
        let now = self.now;
        let (h, hd) = self
            .bounds
            .floor
            .as_ref()
            .expect("riders need a floor")
            .ride(now);
        let mut row = std::mem::take(&mut self.rest.cluster);
        let ok = self.full_row(i, j, &mut row)
            && row.iter().all(|&m| {
                let m = m as usize;
                if self.is_riding(m) {
                    return self.rest.riders.on_floor(m);
                }
                let (_, y, _, _) = self.state_at(m, now);
                let a = self.disks.radius[m];
                y - a - h <= WEDGE_DROP * a
            });
        if ok {
            for &m in &row {
                let m = m as usize;
                self.bring(m, now);
                self.take_velocity(m, (0.0, hd));
            }
            self.tally.counts.pair += 1;
            for &m in &row {
                let m = m as usize;
                self.moved(m);
                if self.is_riding(m) {
                    self.release_carried(m, None);
                }
            }
        }
        row.clear();
        self.rest.cluster = row;
        ok
    }

    /// Puts in `row` (cleared first) the row through disks `i` and `j` (side by side, at now):
    /// the disks side by side with them leftwards, then rightwards; `true` if it reaches from
    /// side wall to side wall (or round the periodic sides). See [`row_from`](Self::row_from).
    fn full_row(&self, i: usize, j: usize, row: &mut Vec<u32>) -> bool {
        let now = self.now;
        let (xi, _, _, _) = self.state_at(i, now);
        let (xj, _, _, _) = self.state_at(j, now);
        let (left, right) = if self.wrap(xj - xi, 0.0).0 > 0.0 {
            (i, j)
        } else {
            (j, i)
        };
        row.clear();
        self.row_from(left, -1.0, row) && self.row_from(right, 1.0, row)
    }

    /// Adds to `row` disk `start` and the disks side by side with it in direction `dir` (±1),
    /// up to a side wall; `true` if the chain reaches the wall (or comes round to a disk already
    /// in `row`, where the sides are periodic).
    fn row_from(&self, start: usize, dir: f64, row: &mut Vec<u32>) -> bool {
        let now = self.now;
        let mut cur = start;
        for _ in 0..ROOM_ROW {
            if row.contains(&(cur as u32)) {
                return matches!(self.bounds.sides, SideBounds::Periodic { .. });
            }
            row.push(cur as u32);
            let (x, y, _, _) = self.state_at(cur, now);
            let a = self.disks.radius[cur];
            if let SideBounds::Walls { width, .. } = self.bounds.sides {
                let gap = if dir < 0.0 { x - a } else { width - x - a };
                if gap <= ROOM * a {
                    return true;
                }
            }
            let next = self
                .map
                .lists
                .of(cur)
                .iter()
                .map(|&c| c as usize)
                .find(|&c| {
                    let (xc, yc, _, _) = self.state_at(c, now);
                    let (dx, dy) = self.wrap(xc - x, yc - y);
                    let reach = a + self.disks.radius[c];
                    dx * dir > 0.0 && dx.abs() - reach <= ROOM * a && dy.abs() <= WEDGE_DROP * a
                });
            match next {
                Some(c) => cur = c,
                None => return false,
            }
        }
        false
    }

    /// The seat of disk `m` (at now), and where `m` sits on it: a disk at rest, not sliding,
    /// straight below it to within [`ROOM`] radii sideways, whose top is at most
    /// [`WEDGE_DROP`] radii below `m`'s bottom. A disk at rest on one disk, not sliding, is
    /// seated where it is.
    fn seat_of(&self, m: usize) -> Option<(u32, f64, f64)> {
        let now = self.now;
        let (x, y, _, _) = self.state_at(m, now);
        if self.is_riding(m) {
            let [s, other] = self.rest.riders.supports(m);
            return (self.disks.motion[m].vx == 0.0 && s != NO_DISK && other == NO_DISK)
                .then_some((s, x, y));
        }
        let a = self.disks.radius[m];
        self.map.lists.of(m).iter().find_map(|&c| {
            let c = c as usize;
            if !self.is_riding(c) || self.disks.motion[c].vx != 0.0 {
                return None;
            }
            let (xc, yc, _, _) = self.state_at(c, now);
            let (dx, dy) = self.wrap(x - xc, y - yc);
            let reach = a + self.disks.radius[c];
            let above = dy - reach;
            (dx.abs() <= ROOM * a && above <= WEDGE_DROP * a && above >= -ROOM * a).then_some((
                c as u32,
                x - dx,
                y - above,
            ))
        })
    }

    /// Whether the row's disks, each on its seat, overlap nothing: the side walls, each other,
    /// or any other disk near them (round-off aside).
    fn seats_hold(&self, row: &[u32], seats: &[(u32, f64, f64)]) -> bool {
        let now = self.now;
        let place = |m: usize| {
            row.iter()
                .position(|&r| r as usize == m)
                .map(|k| (seats[k].1, seats[k].2))
        };
        row.iter().zip(seats).all(|(&m, &(seat, x, y))| {
            let m = m as usize;
            let a = self.disks.radius[m];
            if let SideBounds::Walls { width, .. } = self.bounds.sides {
                if x - a < -TIGHT * a || width - x - a < -TIGHT * a {
                    return false;
                }
            }
            self.map.lists.of(m).iter().all(|&c| {
                let c = c as usize;
                if c == seat as usize {
                    return true;
                }
                let (xc, yc) = place(c).unwrap_or_else(|| {
                    let (xc, yc, _, _) = self.state_at(c, now);
                    (xc, yc)
                });
                let (dx, dy) = self.wrap(x - xc, y - yc);
                let reach = a + self.disks.radius[c];
                dx * dx + dy * dy >= reach * reach * (1.0 - 2.0 * TIGHT)
            })
        })
    }
}
