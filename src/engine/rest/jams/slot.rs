//! **A slot** between supports at rest that do not give: a flying disk hitting a disk at rest
//! while it touches, on the other side, a disk at rest or a wall whose contact normal is nearly
//! opposite would collide ~π/|n_s + n_c| times at one instant (for ever under a cure). It stops
//! at once: at rest if the place holds it, else still, to fall out of the slot.

use super::*;
use crate::engine::rest::resting::TOUCH;
use crate::engine::rest::riders::NO_DISK;
use crate::engine::Simulation;
use crate::error::Result;
use crate::physics::flight::Flight;
use crate::physics::walls::SideBounds;

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
        let (h, hd) = self.floor_now();
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
        self.tally.jams.slot += 1;
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
}

#[cfg(test)]
mod tests {
    use super::super::tests::jams_in;

    /// Three disks touching at the start on a floor: the one landing between the two at rest stops in their slot.
    #[test]
    fn a_disk_landing_between_two_at_rest_stops_in_the_slot() {
        assert!(jams_in("touching_start_floor.json", &[]).slot > 0);
    }
}
