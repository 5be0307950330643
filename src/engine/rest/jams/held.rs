//! **A jammed row** — disks at rest side by side from wall to wall, or all the way round — and
//! **a gentle push** on a disk at rest (slower than the sleep speed): the disk hit does not give.
//! The flying disk comes to rest on it or bounces off it as off a fixed disk moving with the
//! floor, instead of sending the push through the row and back at one instant.

use crate::engine::rest::resting::TOUCH;
use crate::engine::Simulation;
use crate::error::Result;
use crate::physics::flight::Flight;
use crate::physics::walls::SideBounds;

impl<F: Flight> Simulation<F> {
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
        let (_, hd) = self.floor_now();
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
    /// disk moving with the floor (rough disks rubbing on it as on a wall), and the row stays at
    /// rest. The exact engine would send the
    /// push through the row to the wall and back in a chain of collisions at one instant, for
    /// ever under a cure (the *exact jam*).
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
    use super::super::tests::jams_in;

    /// A bouncing bed between walls lands on rows at rest from wall to wall, and pushes disks at rest gently.
    #[test]
    fn a_bed_coming_to_rest_meets_jammed_rows_and_gentle_pushes() {
        assert!(jams_in("bouncing_bed_gamma_1.5.json", &[]).jammed_row > 0);
    }

    /// A disk pushing one at rest slower than the sleep speed does not move it.
    #[test]
    fn a_gentle_push_does_not_move_a_disk_at_rest() {
        assert!(jams_in("pocket_by_a_wall.json", &[]).gentle_push > 0);
    }
}
