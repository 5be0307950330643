//! Resting contacts between disks: a disk that lands gently in a stable place on disks at rest
//! comes to rest on them and moves with the floor; a support that moves releases what rests on it.
//!
//! Without this, a disk resting on a disk that rides the floor keeps bouncing with the smallest
//! rebound ([`PAIR_REST_HEIGHT`]), about 500 times per unit time, and a bed at rest costs
//! millions of events per unit time. The model is the pair analogue of the rest on the floor:
//!
//! - **Coming to rest.** A flying disk `k` hits a riding disk `s`. If its normal rebound `e·|u|`
//!   and its sliding speed along the contact are both below the sleep speed
//!   `v_s = √(2·(g + h'')·PAIR_REST_HEIGHT·a)` (the smallest rebound on a rider), and its weight
//!   is carried — by `s` straight below it (contact normal vertical to [`VERTICAL`]), by two
//!   supports whose contact normals bracket the vertical (disks at rest or side walls touching it
//!   to within [`TOUCH`] radii), or by the floor it touches — then `k` takes `s`'s velocity and
//!   rides: `y = h(t) + lift`, moving horizontally with `s`. A slow flying support comes to rest
//!   with it (an arch), and so do the slow flying disks around it that only hold as a whole
//!   (`settle_cluster`; also tried when two slow flying disks collide elastically under a
//!   cure). Its relative kinetic energy is booked as dissipated and the change
//!   of its absolute kinetic energy beyond that as work of the floor (the floor carries the
//!   stack). A disk balanced on one disk is an unstable equilibrium; freezing it when the
//!   normal is vertical to 10⁻⁹ suppresses a fall that would take ~ln(10⁹)·√(d/g) to develop.
//! - **Leaving rest.** A resting disk leaves when it is hit, hits a side wall, is thrown off or
//!   kicked by the floor (as riders do), or when its supports slide apart by [`TOUCH`] radii
//!   (an `unmount` event). Whatever rests on a disk that leaves is released at the same moment,
//!   recursively, with its current velocity: it then falls onto whatever is below and, if that
//!   is at rest and the place is stable, comes to rest again at once.
//! - **No TC against a disk at rest.** A collision of a flying disk with a disk at rest keeps
//!   the pair restitution even when the TC model would make it elastic
//!   ([`CollisionLaw::collision_with_rest`](crate::physics::restitution::CollisionLaw::collision_with_rest)):
//!   a disk pressed onto a disk at rest comes to rest on it, which ends the sequence TC would
//!   end. Otherwise a stack above a row at rest, colliding every ~10⁻⁵, keeps its energy for
//!   ever.
//! - **Static friction below v_s.** Disks at rest slower than `v_s` stop sliding (landing on the
//!   floor, reaching a wall); two touching disks at rest slide on together instead of colliding
//!   (`rest_together`); a flyer driven into a slot between supports at rest stops there
//!   (`stop_in_slot`). Without these a bed of frictionless disks never stops sliding and ringing.
//!
//! The rules that end the sequences a bed at rest would otherwise ring in for ever (slots,
//! jammed clusters and rows, pockets by a wall, Zeno wedges) are in [`jams`](crate::engine::rest::jams).

use crate::engine::rest::flying_and_riding;
use crate::engine::rest::riders::{LEFT_WALL, NO_DISK, RIGHT_WALL};
use crate::engine::Simulation;
use crate::error::Result;
use crate::physics::flight::Flight;
use crate::physics::floor::{Floor, PAIR_REST_HEIGHT};
use crate::physics::walls::{SideBounds, Top};

/// A contact normal within this of the vertical (|n_x| ≤ `VERTICAL`) carries a disk alone.
pub const VERTICAL: f64 = 1e-9;

/// A support touches a disk when their gap is at most `TOUCH` radii of the resting disk; a
/// resting disk leaves its supports when a gap grows beyond twice that.
pub const TOUCH: f64 = 10.0 * PAIR_REST_HEIGHT;

/// A hair, in radii: the most a row at rest is pushed aside to make room for a landing disk
/// ([`ROOM`](crate::engine::rest::jams::ROOM), in the landing disk's radii), and the gap across which a side
/// wall still supports a disk at rest ([`WALL_TOUCH`], in that disk's radii).
pub const HAIR: f64 = 1e-4;

/// A side wall supports a disk at rest (with a disk on the other side of the vertical) when
/// their gap is at most `WALL_TOUCH` radii — a [`HAIR`] — and the disk leaves it beyond twice
/// that.
/// Frictionless, a disk on a support tilted toward the wall would slide the hair into it; but
/// a disk rattling in such a pocket under a cure is rarely within [`TOUCH`] of both at once
/// (in a column of disks by a wall, each hop elastic, one can stay 9·10⁻⁵ radii off the wall
/// for ever).
pub const WALL_TOUCH: f64 = HAIR;

impl<F: Flight> Simulation<F> {
    /// Disks `i` and `j` (brought to now, `(dx, dy)` from `j` to `i`; `rode`: whether each
    /// rode) collide with restitution `e`. Under the resting contacts, two riding disks may rest
    /// together ([`rest_together`](Self::rest_together)), and a flying disk may come to rest on
    /// a riding one ([`try_rest_on`](Self::try_rest_on)). Whether one did (the collision is
    /// then done).
    #[inline]
    pub(in crate::engine) fn resting_contact_takes(
        &mut self,
        i: usize,
        j: usize,
        rode: [bool; 2],
        (dx, dy): (f64, f64),
        e: f64,
    ) -> Result<bool> {
        if !self.rest.resting_contacts {
            return Ok(false);
        }
        match rode {
            [true, true] => self.rest_together(i, j, dx, dy),
            [false, false] => Ok(false),
            _ => {
                let (k, s) = flying_and_riding(i, j, rode);
                self.try_rest_on(k, s, e)
            }
        }
    }

    /// Flying disk `k` meets riding disk `s` (both brought to now) with restitution `e`. Comes to
    /// rest (and returns `true`) if the meeting is gentle — rebound and sliding speed below the
    /// sleep speed — and the place is stable (or on the floor beside `s`); stops in a slot (see
    /// [`stop_in_slot`](Self::stop_in_slot)) if it is not gentle. `false`: collide as usual.
    pub(in crate::engine) fn try_rest_on(&mut self, k: usize, s: usize, e: f64) -> Result<bool> {
        let (mk, ms) = (self.disks.motion[k], self.disks.motion[s]);
        let (dx, dy) = self.wrap(mk.x - ms.x, mk.y - ms.y);
        let dist = (dx * dx + dy * dy).sqrt();
        let (nx, ny) = (dx / dist, dy / dist);
        let (dvx, dvy) = (mk.vx - ms.vx, mk.vy - ms.vy);
        let u = dvx * nx + dvy * ny;
        let slide = (dvy * nx - dvx * ny).abs();
        let gentle = self.sleep_speed(k);
        if gentle == 0.0 || self.rest.riders.slide(s).is_some() {
            return Ok(false);
        }
        if -e * u > gentle || slide > gentle {
            return self.stop_in_slot(k, s, (nx, ny), dist);
        }
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        let now = self.now;
        let (h, hd) = floor.ride(now);
        let rest_v = (ms.vx, hd);
        let floor = self.floor_place(k, h);
        let on_floor = floor.is_some();
        let room = floor.flatten();
        let supports = if on_floor {
            [NO_DISK; 2] // beside s, on the floor (once there is room)
        } else {
            match self.stable_supports(k, s, Some(rest_v)) {
                Some(supports) => supports,
                None => return Ok(false),
            }
        };
        // Slow flying supports (an arch: each holds the other) must come to rest with k.
        let mut arch = [(NO_DISK, [NO_DISK; 2]); 2];
        for (slot, &c) in supports.iter().enumerate() {
            if c < RIGHT_WALL && !self.is_riding(c as usize) {
                let c = c as usize;
                let supports_c = if self.touches_floor(c, h) {
                    Some([NO_DISK; 2]) // on the floor
                } else {
                    self.stable_supports(c, k, None)
                };
                match supports_c {
                    Some(sc) if !self.squeezed(c, rest_v.0, hd) && !self.near_lid(c) => {
                        arch[slot] = (c as u32, sc)
                    }
                    _ => return Ok(false),
                }
            }
        }
        // Carried at s's velocity into a wall or a disk it touches, k is squeezed: no rest.
        if self.squeezed(k, ms.vx, hd) || self.near_lid(k) {
            return Ok(false);
        }
        self.check_contact(k, s, dist)?;
        if let Some(room) = room {
            self.make_room(k, room);
        }
        if !self.come_to_rest(k, h, supports, rest_v) {
            return Ok(false);
        }
        self.tally.virial += dist * self.disks.mass[k] * -u;
        self.tally.counts.pair += 1;
        for (c, sc) in arch {
            if c != NO_DISK {
                let c = c as usize;
                self.bring(c, now);
                if !self.come_to_rest(c, h, sc, rest_v) {
                    // c could not be carried (its supports are full): k falls from rest.
                    self.rest.riders.dismount(k);
                    self.moved(k);
                }
            }
        }
        // `s` did not change: only its own event (this one, if it was its) needs renewing.
        self.predict(s);
        if self.is_riding(k) {
            self.settle_cluster(k);
        }
        Ok(true)
    }

    /// Whether disk `k` (at now) touches the floor's surface `h`, to within [`TOUCH`] radii.
    pub(in crate::engine) fn touches_floor(&self, k: usize, h: f64) -> bool {
        let (_, y, _, _) = self.state_at(k, self.now);
        let a = self.disks.radius[k];
        y - h - a <= TOUCH * a
    }

    /// Whether disk `k` at rest could be pushed into the lid by the floor's motion.
    pub(in crate::engine) fn near_lid(&self, k: usize) -> bool {
        match (self.bounds.top, self.bounds.floor.as_ref()) {
            (Top::Lid { height, .. }, Some(floor)) => {
                let (_, y, _, _) = self.state_at(k, self.now);
                y + self.disks.radius[k] + 2.0 * floor.drive().amplitude >= height
            }
            _ => false,
        }
    }

    /// Flying disk `k` (brought to now) comes to rest on `supports`, moving with velocity
    /// `(vx, h'(now))`; the floor's surface is at `h`. Its kinetic energy relative to the floor's
    /// motion is booked as dissipated and the rest of the change as work of the floor (which
    /// carries the stack). `false` (nothing changed) if a support carries too many disks.
    pub(in crate::engine) fn come_to_rest(
        &mut self,
        k: usize,
        h: f64,
        supports: [u32; 2],
        (vx, hd): (f64, f64),
    ) -> bool {
        let (mk, now) = (self.disks.motion[k], self.time());
        if supports == [NO_DISK; 2] {
            // On the floor itself, where it is (within TOUCH radii of the surface: moving it
            // down could push it into a smaller neighbour).
            self.rest.riders.mount_on_floor(k, mk.y - h, now);
        } else if !self.rest.riders.mount_on_disks(k, mk.y - h, supports, now) {
            return false;
        }
        self.take_velocity(k, (vx, hd));
        self.tally.counts.rest += 1;
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        self.map.dutc.ride(
            self.now,
            vx.abs() + floor.drive().peak_velocity(),
            self.flight.g(),
        );
        self.moved(k);
        true
    }

    /// Disk `k` (brought to now) takes the velocity `(vx, h'(now))` of the disks at rest it
    /// meets: its kinetic energy relative to them is booked as dissipated and the rest of the
    /// change as work of the floor, which holds them and takes the momentum.
    pub(in crate::engine) fn take_velocity(&mut self, k: usize, (vx, hd): (f64, f64)) {
        let mass = self.disks.mass[k];
        let m = &mut self.disks.motion[k];
        let relative = 0.5 * mass * ((m.vx - vx).powi(2) + (m.vy - hd).powi(2));
        self.tally.flow.dissipated += relative;
        self.tally.flow.injected +=
            0.5 * mass * (vx * vx + hd * hd - m.vx * m.vx - m.vy * m.vy) + relative;
        self.tally.flow.floor_impulse += mass * (hd - m.vy);
        m.vx = vx;
        m.vy = hd;
        self.hold_spin(k);
    }

    /// What carries flying disk `k` (at now) if it rests on riding disk `hit`: `hit` alone if it
    /// is straight below, else two supports (riding disks touching `k`, or side walls) whose
    /// contact normals bracket the vertical, so that normal forces alone balance `k`'s weight;
    /// `None` if `k` would slide or roll off. A support beside `k`, even a little above its
    /// centre, carries it together with one below on the other side.
    ///
    /// With `slow = Some(v)`, flying disks touching `k` that move with velocity within their
    /// sleep speed of `v` count as supports too (they can come to rest with `k`).
    pub(in crate::engine) fn stable_supports(
        &self,
        k: usize,
        hit: usize,
        slow: Option<(f64, f64)>,
    ) -> Option<[u32; 2]> {
        let now = self.now;
        self.stable_place(k, Some(hit), |c| {
            if self.is_riding(c) {
                return true;
            }
            let Some((vx, vy)) = slow else { return false };
            let (_, _, vxc, vyc) = self.state_at(c, now);
            (vxc - vx).hypot(vyc - vy) <= self.sleep_speed(c)
        })
    }

    /// Two supports of disk `k` (at now) whose contact normals bracket the vertical, among the
    /// disks touching it that `can_support` accepts (and `hit`, always), and the side walls; or
    /// one straight below it (only `hit`, if given; any accepted disk otherwise); or, for rough
    /// disks, two on which static friction holds it (see
    /// [`held_by_friction`](Self::held_by_friction)).
    pub(in crate::engine) fn stable_place(
        &self,
        k: usize,
        hit: Option<usize>,
        can_support: impl Fn(usize) -> bool,
    ) -> Option<[u32; 2]> {
        let now = self.now;
        let (xk, yk, _, _) = self.state_at(k, now);
        let ak = self.disks.radius[k];
        let touch = TOUCH * ak;
        // Contact normals (pointing from the support to k) of everything touching k.
        let mut normals: [(u32, f64, f64); 8] = [(NO_DISK, 0.0, 0.0); 8];
        let mut found = 0;
        let others = self
            .map
            .lists
            .of(k)
            .iter()
            .map(|&c| c as usize)
            .filter(|&c| Some(c) != hit && can_support(c));
        // A disk sliding on a rough floor carries nothing: its path bends under what it carried.
        if hit.is_some_and(|h| self.rest.riders.slide(h).is_some()) {
            return None;
        }
        let others = others.filter(|&c| self.rest.riders.slide(c).is_none());
        for c in hit.into_iter().chain(others) {
            let (xc, yc, _, _) = self.state_at(c, now);
            let (dx, dy) = self.wrap(xk - xc, yk - yc);
            let dist = (dx * dx + dy * dy).sqrt();
            if dist - (ak + self.disks.radius[c]) > touch {
                continue;
            }
            let (nx, ny) = (dx / dist, dy / dist);
            if hit.is_none_or(|h| h == c) && nx.abs() <= VERTICAL && ny > 0.0 {
                return Some([c as u32, NO_DISK]);
            }
            if found < normals.len() {
                normals[found] = (c as u32, nx, ny);
                found += 1;
            }
        }
        if let SideBounds::Walls { width, .. } = self.bounds.sides {
            let touch = WALL_TOUCH * ak;
            if xk - ak <= touch && found < normals.len() {
                normals[found] = (LEFT_WALL, 1.0, 0.0);
                found += 1;
            }
            if width - xk - ak <= touch && found < normals.len() {
                normals[found] = (RIGHT_WALL, -1.0, 0.0);
                found += 1;
            }
        }
        // The pair pushing from the left (n_x > 0) and from the right (n_x < 0) whose normals
        // bracket the vertical most widely: (0, 1) = α n_l + β n_r with α, β > 0 exactly when
        // n_l × n_r > 0.
        let normals = &normals[..found];
        let mut best: Option<([u32; 2], f64)> = None;
        for &(l, lx, ly) in normals.iter().filter(|n| n.1 > 0.0) {
            for &(r, rx, ry) in normals.iter().filter(|n| n.1 < 0.0) {
                let cross = lx * ry - ly * rx;
                if cross > VERTICAL && best.is_none_or(|(_, b)| cross > b) {
                    best = Some(([l, r], cross));
                }
            }
        }
        best.map(|(pair, _)| pair)
            .or_else(|| self.held_by_friction(normals))
    }

    /// Whether disk `k` (at now), given the velocity `(vx, vy)`, would move into a side wall or a
    /// disk it touches (within [`TOUCH`] radii), other than a flying disk above its centre. Such a
    /// disk, pressed onto k, gets the floor of the rebound and leaves; a wall, a disk at rest, or
    /// a flying disk beside or below would push k off its supports at once, k would come to rest
    /// again, and so on in zero time.
    pub(in crate::engine) fn squeezed(&self, k: usize, vx: f64, vy: f64) -> bool {
        let now = self.now;
        let (xk, yk, _, _) = self.state_at(k, now);
        let ak = self.disks.radius[k];
        let touch = TOUCH * ak;
        if let SideBounds::Walls { width, .. } = self.bounds.sides {
            if (vx < 0.0 && xk - ak <= touch) || (vx > 0.0 && width - xk - ak <= touch) {
                return true;
            }
        }
        self.map.lists.of(k).iter().any(|&c| {
            let c = c as usize;
            let (xc, yc, vxc, vyc) = self.state_at(c, now);
            let (dx, dy) = self.wrap(xk - xc, yk - yc);
            let dist = (dx * dx + dy * dy).sqrt();
            (dy >= 0.0 || self.is_riding(c))
                && dist - (ak + self.disks.radius[c]) <= touch
                && dx * (vx - vxc) + dy * (vy - vyc) < 0.0
        })
    }

    /// When resting disk `k` leaves its supports because they slide apart (a gap beyond
    /// 2·[`TOUCH`] radii); infinity if they move together.
    pub(in crate::engine) fn unmount_time(&self, k: usize) -> f64 {
        let now = self.now;
        let (xk, yk, vxk, _) = self.state_at(k, now);
        let ak = self.disks.radius[k];
        let reach = 2.0 * TOUCH * ak;
        let wall_reach = 2.0 * WALL_TOUCH * ak;
        let mut t = f64::INFINITY;
        for s in self.rest.riders.supports(k) {
            let dt = match s {
                NO_DISK => continue,
                LEFT_WALL if vxk > 0.0 => (wall_reach - (xk - ak)).max(0.0) / vxk,
                RIGHT_WALL if vxk < 0.0 => {
                    (wall_reach - (self.bounds.sides.width() - xk - ak)).max(0.0) / -vxk
                }
                LEFT_WALL | RIGHT_WALL => continue,
                s => {
                    let s = s as usize;
                    let (xs, ys, vxs, _) = self.state_at(s, now);
                    let dvx = vxk - vxs;
                    if dvx == 0.0 {
                        continue;
                    }
                    // Both move with the floor: the separation changes along x only.
                    let (dx, dy) = self.wrap(xk - xs, yk - ys);
                    let r = ak + self.disks.radius[s] + reach;
                    let c = dx * dx + dy * dy - r * r;
                    if c >= 0.0 {
                        0.0
                    } else {
                        let b = dx * dvx;
                        let dv2 = dvx * dvx;
                        (-b + (b * b - dv2 * c).sqrt()) / dv2
                    }
                }
            };
            t = t.min(now + dt);
        }
        t
    }

    /// Below this horizontal speed a disk at rest stops sliding: the smallest rebound on a rider
    /// (`√(2·(g + h'')·PAIR_REST_HEIGHT·a)`), at the present floor acceleration; 0 (nothing
    /// comes to rest) where the floor no longer presses, with the floor's own margin of 10⁻⁹
    /// (a disk coming to rest on a rider a hair before the take-off would take off at once
    /// and be caught again, at one instant, for ever).
    pub(in crate::engine) fn sleep_speed(&self, i: usize) -> f64 {
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        let g = self.flight.g();
        let press = g + floor.ride_acceleration(self.now);
        if press <= 1e-9 * (g + floor.max_acceleration()) {
            return 0.0;
        }
        Floor::pair_rest_speed(self.disks.radius[i], press)
    }

    /// Whether flying disk `i` (brought to now) moves slower than the sleep speed relative to
    /// the floor.
    pub(in crate::engine) fn slow(&self, i: usize) -> bool {
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        let m = self.disks.motion[i];
        // Most collisions are far faster: rejected against the largest sleep speed the floor
        // allows, without the floor's phase.
        let a = self.disks.radius[i];
        if m.vx.abs() > Floor::pair_rest_speed(a, self.flight.g() + floor.max_acceleration()) {
            return false;
        }
        let (_, hd) = floor.ride(self.now);
        m.vx.hypot(m.vy - hd) <= self.sleep_speed(i)
    }

    /// Riding disk `i` (brought to now) stops sliding: its horizontal kinetic energy is lost
    /// (static friction with what carries it).
    pub(in crate::engine) fn stop_sliding(&mut self, i: usize) {
        let m = &mut self.disks.motion[i];
        self.tally.flow.dissipated += 0.5 * self.disks.mass[i] * m.vx * m.vx;
        m.vx = 0.0;
        self.hold_spin(i);
    }

    /// Disk `i` (brought to now) reaches a side wall: if it is at rest and slower than the sleep
    /// speed it stops there, and what rested on it (sliding with it) is released. Returns whether
    /// it stopped (the wall collision is then done).
    pub(in crate::engine) fn stop_at_wall(&mut self, i: usize) -> bool {
        if !(self.rest.resting_contacts
            && self.is_riding(i)
            && self.disks.motion[i].vx.abs() < self.sleep_speed(i))
        {
            return false;
        }
        self.stop_sliding(i);
        self.tally.counts.wall += 1;
        self.moved(i);
        self.release_carried(i, None);
        true
    }

    /// Riding disks `i` and `j` (brought to now, `(dx, dy)` from `j` to `i`) touch while
    /// approaching slower than the sleep speed: instead of a collision that would throw both
    /// off their supports, they stay at rest and slide on together with their common horizontal
    /// velocity (momentum kept, the relative kinetic energy booked as dissipated), or stop if
    /// that is below the sleep speed too. On the floor, the whole row touching them that slides
    /// within the sleep speed of that velocity joins them
    /// ([`slide_row_together`](Self::slide_row_together)). Returns `false` (nothing done) for a
    /// faster approach.
    pub(in crate::engine) fn rest_together(
        &mut self,
        i: usize,
        j: usize,
        dx: f64,
        dy: f64,
    ) -> Result<bool> {
        let dist = (dx * dx + dy * dy).sqrt();
        let (vi, vj) = (self.disks.motion[i].vx, self.disks.motion[j].vx);
        let u = (vi - vj) * dx / dist;
        let sleep = self.sleep_speed(i).min(self.sleep_speed(j));
        if u.abs() >= sleep {
            return Ok(false);
        }
        self.check_contact(i, j, dist)?;
        if self.rest.riders.on_floor(i)
            && self.rest.riders.on_floor(j)
            && self.slide_row_together(i, j, dx, sleep)
        {
            return Ok(true);
        }
        let (mi, mj) = (self.disks.mass[i], self.disks.mass[j]);
        let v = (mi * vi + mj * vj) / (mi + mj);
        self.tally.flow.dissipated += 0.5 * mi * mj / (mi + mj) * (vi - vj).powi(2);
        self.tally.virial += dist * mi * (v - vi) * dx / dist;
        self.disks.motion[i].vx = v;
        self.disks.motion[j].vx = v;
        if v.abs() < sleep {
            self.stop_sliding(i);
            self.stop_sliding(j);
        }
        self.hold_spin(i);
        self.hold_spin(j);
        self.tally.counts.pair += 1;
        self.disks.counter[j] = self.disks.counter[j].wrapping_add(1);
        self.moved(i);
        self.predict(j);
        // What rested on them slid with their old velocities.
        self.release_carried(i, None);
        self.release_carried(j, None);
        Ok(true)
    }

    /// Disks `i` and `j` riding the floor (`dx` from `j` to `i`) come to slide together, and
    /// other disks riding the floor touch them, directly or through each other, sliding within
    /// `sleep` of their common velocity: the whole row slides on together with its common
    /// velocity (or stops, below `sleep`), momentum kept. Merging pair by pair instead, a row of
    /// three or more passes the difference back and forth at one instant without end, each
    /// merge halving it (a ring of 200 disks round the periodic sides stalled so). Returns
    /// `false`, doing nothing, if no other disk joins them.
    fn slide_row_together(&mut self, i: usize, j: usize, dx: f64, sleep: f64) -> bool {
        let now = self.now;
        let (mi, mj) = (self.disks.mass[i], self.disks.mass[j]);
        let (vi, vj) = (self.disks.motion[i].vx, self.disks.motion[j].vx);
        let v_pair = (mi * vi + mj * vj) / (mi + mj);
        // Members and their positions along the row, relative to `i`.
        let mut row = std::mem::take(&mut self.rest.cluster);
        let mut along = vec![0.0, -dx];
        row.extend([i as u32, j as u32]);
        let mut next = 0;
        while let Some(&from) = row.get(next) {
            let from = from as usize;
            let (xf, yf, _, _) = self.state_at(from, now);
            for &c in self.map.lists.of(from) {
                let c = c as usize;
                if !self.rest.riders.is_riding(c)
                    || !self.rest.riders.on_floor(c)
                    || row.contains(&(c as u32))
                    || (self.disks.motion[c].vx - v_pair).abs() >= sleep
                {
                    continue;
                }
                let (xc, yc, _, _) = self.state_at(c, now);
                let (dxc, dyc) = self.wrap(xc - xf, yc - yf);
                let gap = dxc.hypot(dyc) - self.disks.radius[c] - self.disks.radius[from];
                if gap <= TOUCH * self.disks.radius[c] {
                    row.push(c as u32);
                    along.push(along[next] + dxc);
                }
            }
            next += 1;
        }
        let joined = row.len() > 2;
        if joined {
            self.slide_on_together(&row, &along, sleep);
        }
        row.clear();
        self.rest.cluster = row;
        joined
    }

    /// The disks of `row` (riding the floor, in contact, at positions `along` the row) slide on
    /// with their common horizontal velocity, or stop if it is below `sleep`; the kinetic
    /// energy of their relative motion is booked as dissipated, the contact impulses in the
    /// virial.
    fn slide_on_together(&mut self, row: &[u32], along: &[f64], sleep: f64) {
        let now = self.now;
        let (mut mass, mut momentum) = (0.0, 0.0);
        for &k in row {
            let k = k as usize;
            mass += self.disks.mass[k];
            momentum += self.disks.mass[k] * self.disks.motion[k].vx;
        }
        let v = momentum / mass;
        for (&k, &x) in row.iter().zip(along) {
            let k = k as usize;
            self.bring(k, now);
            let (m, vk) = (self.disks.mass[k], self.disks.motion[k].vx);
            self.tally.flow.dissipated += 0.5 * m * (vk - v).powi(2);
            // Internal impulses sum to zero: Σ x·Δp is the contacts' virial.
            self.tally.virial += x * m * (v - vk);
            self.disks.motion[k].vx = v;
            if v.abs() < sleep {
                self.stop_sliding(k);
            }
            self.hold_spin(k);
        }
        self.tally.counts.pair += 1;
        for &k in row {
            self.moved(k as usize);
        }
        // What rested on them slid with their old velocities.
        for &k in row {
            self.release_carried(k as usize, None);
        }
    }

    /// Riding disk `i` is about to change velocity: if it rests on disks, it leaves them.
    pub(in crate::engine) fn unsettle(&mut self, i: usize) {
        if self.rest.riders.is_riding(i) && !self.rest.riders.on_floor(i) {
            self.rest.riders.dismount(i);
        }
    }

    /// Releases, recursively, every disk resting on disk `s` (which has just moved or left
    /// rest), each with its current velocity, or with vertical velocity `vy` if given.
    pub(in crate::engine) fn release_carried(&mut self, s: usize, vy: Option<f64>) {
        if !self.rest.riders.carries_any(s) {
            return;
        }
        let now = self.now;
        let mut stack = std::mem::take(&mut self.rest.releasing);
        let mut carried = std::mem::take(&mut self.rest.carried);
        stack.push(s as u32);
        while let Some(c) = stack.pop() {
            carried.clear();
            self.rest.riders.take_carried(c as usize, &mut carried);
            for &k in &carried {
                let k = k as usize;
                self.bring(k, now);
                self.rest.riders.dismount(k);
                if let Some(v) = vy {
                    self.set_vy(k, v);
                }
                self.moved(k);
                stack.push(k as u32);
            }
        }
        self.rest.releasing = stack;
        self.rest.carried = carried;
    }
}

#[cfg(test)]
mod tests {
    use crate::engine::rest::jams::tests::run_hard_case;

    /// A bed poured on a static floor ends with disks resting on disks (and so costs no events);
    /// without resting contacts none rests on another.
    #[test]
    fn a_poured_bed_rests_on_disks_only_with_resting_contacts() {
        let with = run_hard_case("bed_at_rest_60.json", &[]);
        assert!(with.stacked() > 0, "disks at rest on disks");
        assert!(with.counts().rest > 0);
        let without = run_hard_case(
            "bed_at_rest_60.json",
            &["collisions.resting_contacts=false"],
        );
        assert_eq!(without.stacked(), 0);
    }
}
