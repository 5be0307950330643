//! **A slot on the floor a hair too narrow**, left by a row at rest that came to rest a hair
//! apart: a disk just above the floor that would rest on it but for a hair of overlap with a disk
//! of that row is let down onto the floor, the row pushed aside by at most
//! [`ROOM`](super::ROOM) radii (wedged, it would tilt every column above it).

use super::*;
use crate::engine::Simulation;
use crate::physics::flight::Flight;

impl<F: Flight> Simulation<F> {
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
        // Room behind the landing disk, to the wall away from the row.
        let mut free = (self.bounds.sides)
            .gap_to_wall(xk, a, -dir)
            .unwrap_or(f64::INFINITY);
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
            // (A row that fills the width exactly has no play but round-off.)
            if (self.bounds.sides)
                .gap_to_wall(x, ac, dir)
                .is_some_and(|gap| gap < rest - TIGHT * ac)
            {
                return None;
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
        self.tally.jams.floor_room += 1;
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
}

#[cfg(test)]
mod tests {
    use super::super::tests::jams_in;

    /// A disk just above a slot on the floor a hair too narrow is let down onto the floor, the row at rest pushed aside.
    #[test]
    fn a_slot_a_hair_too_narrow_makes_room_on_the_floor() {
        assert!(jams_in("slot_a_hair_narrow.json", &[]).floor_room > 0);
    }
}
