//! What ends the sequences a bed coming to rest would otherwise ring in for ever, each a
//! rule of the resting contacts (`collisions.resting_contacts`, see [`resting`](super::resting)):
//!
//! - **a slot** between supports at rest that do not give (`stop_in_slot`);
//! - **a jammed cluster** of slow flying disks that only hold as a whole (`settle_cluster`);
//! - **a jammed row**, disks at rest side by side from wall to wall (`in_jammed_row`,
//!   `meet_held`), and a **gentle push** on a disk at rest (`pushed_gently`);
//! - **a pocket** by a side wall, where a frictionless disk slides to the wall and back
//!   (`rest_in_pocket`);
//! - **a closed wedge**, or disks ringing in gaps of round-off, where a flying disk has events
//!   at one instant without end (`stop_zeno`).

use super::resting::TOUCH;
use super::riders::{NO_DISK, RIGHT_WALL};
use super::Simulation;
use crate::dynamics::Flight;
use crate::error::Result;
use crate::locals::floor::Floor;
use crate::locals::SideBounds;

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
    pub(super) fn stop_in_slot(
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
        let (h, hd) = self.floor.as_ref().expect("riders need a floor").ride(now);
        let (vx, vy) = (vxk - vs, vyk - hd);
        // A parallel slot holds a disk barely moving along it, between supports that do not
        // slide (a sliding one would close or open it).
        let (along, gentle, still) = ((vx * ny - vy * nx).abs(), self.sleep_speed(k), vs == 0.0);
        let into = |(cx, cy): (f64, f64)| {
            let (bx, by) = (nx + cx, ny + cy);
            let b = bx.hypot(by);
            b < WEDGE && (vx * bx + vy * by < 0.0 || (b < PARALLEL && along < gentle && still))
        };
        let wall = match self.sides {
            SideBounds::Walls { width, .. } => {
                (xk - ak <= touch && into((1.0, 0.0)))
                    || (width - xk - ak <= touch && into((-1.0, 0.0)))
            }
            _ => false,
        };
        let slot = wall
            || self.lists.of(k).iter().any(|&c| {
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
        self.counts.pair += 1;
        let held = if self.touches_floor(k, h) {
            Some([NO_DISK; 2])
        } else {
            self.stable_supports(k, s, None)
        };
        if let Some(supports) = held {
            if !self.squeezed(k, vs, hd)
                && !self.near_lid(k)
                && self.come_to_rest(k, h, supports, (vs, hd))
            {
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
    pub(super) fn stop_zeno(&mut self, i: usize) -> bool {
        let now = self.now;
        if self.same_instant.is_empty() || self.is_riding(i) {
            return false;
        }
        let instant2 = self.zeno_instant2 * self.disks.radius[i];
        let seen = &mut self.same_instant[i];
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
        self.counts.zeno += 1;
        self.bring(i, now);
        let (h, hd) = self.floor.as_ref().expect("riders need a floor").ride(now);
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
        let mut member = std::mem::take(&mut self.in_cluster);
        member.resize(self.disks.len(), false);
        let mut cluster = std::mem::take(&mut self.cluster);
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
        self.cluster = cluster;
        self.in_cluster = member;
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
    pub(super) fn rest_in_pocket(&mut self, k: usize, wall: u32) -> bool {
        if !self.resting_contacts || self.floor.is_none() || self.is_riding(k) {
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
        let floor = self.floor.as_ref().expect("riders need a floor");
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
        self.counts.wall += 1;
        true
    }

    /// Whether disk `s` is at rest in a *jammed row* against a horizontal push of sign `push`:
    /// a chain of disks at rest that do not slide, each touching the next side by side (within
    /// [`TOUCH`] radii, the contact within [`TOUCH`] of horizontal), from `s` to the side wall
    /// the push points to — or all the way round where the sides are periodic. The push is then
    /// taken by the wall, its downward part by what carries the row: the row cannot move.
    pub(super) fn in_jammed_row(&self, s: usize, push: f64) -> bool {
        let row = |c: usize| self.is_riding(c) && self.disks.motion[c].vx == 0.0;
        if push == 0.0 || !row(s) {
            return false;
        }
        let now = self.now;
        let width = self.sides.width();
        let mut cur = s;
        for _ in 0..self.disks.len() {
            let (x, y, _, _) = self.state_at(cur, now);
            let a = self.disks.radius[cur];
            if let SideBounds::Walls { .. } = self.sides {
                let gap = if push < 0.0 { x - a } else { width - x - a };
                if gap <= TOUCH * a {
                    return true;
                }
            }
            let next = self.lists.of(cur).iter().map(|&c| c as usize).find(|&c| {
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
    pub(super) fn pushed_gently(&self, k: usize, s: usize, (sx, sy): (f64, f64)) -> bool {
        if self.disks.motion[s].vx != 0.0 {
            return false;
        }
        let (_, hd) = self
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
    pub(super) fn meet_held(&mut self, k: usize, s: usize, (sx, sy): (f64, f64)) -> Result<()> {
        let now = self.now;
        let (_, hd) = self.floor.as_ref().expect("riders need a floor").ride(now);
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
        self.flow.dissipated += lost;
        self.flow.injected += gained + lost;
        self.flow.floor_impulse += mass * (after - u) * ny;
        self.virial += dist * mass * (after - u);
        self.counts.pair += 1;
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
            for &c in self.lists.of(from) {
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
    pub(super) fn settle_cluster(&mut self, seed: usize) {
        let n = self.disks.len();
        let now = self.now;
        let (h, hd) = self.floor.as_ref().expect("riders need a floor").ride(now);
        let mut member = std::mem::take(&mut self.in_cluster);
        member.resize(n, false);
        let mut cluster = std::mem::take(&mut self.cluster);
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
        self.cluster = cluster;
        self.in_cluster = member;
    }
}
