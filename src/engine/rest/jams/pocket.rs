//! **A pocket** by a side wall: a frictionless disk sliding in gentle hops on a disk at rest
//! that holds it against the wall, too slow to climb out, would slide to the wall and back for
//! ever; it comes to rest on the disk and the wall, as static friction would have it.

use crate::engine::rest::riders::RIGHT_WALL;
use crate::engine::Simulation;
use crate::physics::flight::Flight;

impl<F: Flight> Simulation<F> {
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
        self.tally.jams.pocket += 1;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::jams_in;

    /// A disk sliding on a disk at rest towards the wall it holds the disk against rests in the pocket.
    #[test]
    fn a_disk_sliding_into_a_pocket_by_a_wall_rests_there() {
        assert!(jams_in("pocket_by_a_wall.json", &[]).pocket > 0);
    }
}
