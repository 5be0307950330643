//! **A disk at rest that does not give** — one of a jammed row
//! ([`jammed_row`](super::jammed_row)) or pushed gently ([`gentle_push`](super::gentle_push)):
//! the flying disk comes to rest on it or bounces off it as off a fixed disk moving with the
//! floor.

use crate::engine::rest::flying_and_riding;
use crate::engine::Simulation;
use crate::error::Result;
use crate::physics::flight::Flight;

impl<F: Flight> Simulation<F> {
    /// Disks `i` and `j` (brought to now, `(dx, dy)` from `j` to `i`; `rode`: whether each
    /// rode) meet, one flying and one at rest: under the resting contacts, the one at rest does
    /// not give if pushed gently ([`push_gently`](Self::push_gently)) or hit in a jammed row
    /// ([`hit_jammed_row`](Self::hit_jammed_row)). Whether it held.
    #[inline]
    pub(in crate::engine) fn held_at_rest(
        &mut self,
        i: usize,
        j: usize,
        rode: [bool; 2],
        (dx, dy): (f64, f64),
    ) -> Result<bool> {
        if !(rode[0] != rode[1] && self.rest.resting_contacts) {
            return Ok(false);
        }
        let (k, s) = flying_and_riding(i, j, rode);
        // Separation from the disk at rest to the flying one.
        let sep = if k == i { (dx, dy) } else { (-dx, -dy) };
        Ok(self.push_gently(k, s, sep)? || self.hit_jammed_row(k, s, sep)?)
    }

    /// Flying disk `k` (brought to now, `(sx, sy)` from `s` to it) meets disk `s`, which does
    /// not give. Its restitution is that of an impact on a boundary (a cure acts only through
    /// `k`'s own past, as at a wall: the row, hit over and over, does not make every impact on
    /// it elastic). It comes to rest on `s` if the meeting is gentle (see
    /// [`try_rest_on`](Self::try_rest_on)); else it bounces off `s` as off a fixed disk moving
    /// with the floor (rough disks rubbing on it as on a wall), and `s` stays at rest. The
    /// exact engine would send the push through the row to the wall and back in a chain of
    /// collisions at one instant, for ever under a cure (the *exact jam*).
    pub(in crate::engine) fn meet_held(
        &mut self,
        k: usize,
        s: usize,
        (sx, sy): (f64, f64),
    ) -> Result<()> {
        let now = self.now;
        let (_, hd) = self.floor_now();
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
        // Rough disks rub on the held disk as on a wall: a layer sliding over disks at rest
        // slows.
        self.rub_held(k, s, (nx, ny), (0.0, hd), (mk.vx, mk.vy));
        self.tally.counts.pair += 1;
        self.moved(k);
        // `s` did not change: only its own event (this one, if it was its) needs renewing.
        self.predict(s);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::run_hard_case_to;
    use crate::engine::Progress;

    /// A disk wedged a hair above the floor between two disks of a jammed row, all at rest,
    /// takes off with them at Γ = 2: it leaves a few ulps before its neighbours, touching them
    /// while g + h'' is round-off, and does not ring between them, held, at one instant (it
    /// did for ever, until the event budget ran out at the first take-off, t = 1/6).
    #[test]
    fn a_disk_wedged_in_a_jammed_row_takes_off_with_it() {
        let (sim, progress) = run_hard_case_to("wedged_at_take_off.json", &[]);
        assert_eq!(progress, Progress::Reached, "at t = {}", sim.time());
        assert_eq!(sim.counts().takeoff, 3, "the three disks take off once");
    }
}
