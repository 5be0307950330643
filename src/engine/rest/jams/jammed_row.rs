//! **A jammed row**: disks at rest side by side from wall to wall, or all the way round. A
//! flying disk landing on it level does not move it: it comes to rest on the disk it hits or
//! bounces off it ([`held`](super::held)), instead of sending the push through the row to the
//! wall and back at one instant.

use super::level;
use crate::engine::rest::resting::TOUCH;
use crate::engine::Simulation;
use crate::error::Result;
use crate::physics::flight::Flight;

impl<F: Flight> Simulation<F> {
    /// Flying disk `k` (brought to now, `(sx, sy)` from `s` to it) hits disk `s` of a jammed
    /// row, level: `s` does not give ([`meet_held`](Self::meet_held)). Whether it did.
    pub(in crate::engine) fn hit_jammed_row(
        &mut self,
        k: usize,
        s: usize,
        (sx, sy): (f64, f64),
    ) -> Result<bool> {
        if !(level(sx, sy) && self.in_jammed_row(s, -sx)) {
            return Ok(false);
        }
        self.tally.jams.jammed_row += 1;
        self.meet_held(k, s, (sx, sy))?;
        Ok(true)
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
        let mut cur = s;
        for _ in 0..self.disks.len() {
            let (x, y, _, _) = self.state_at(cur, now);
            let a = self.disks.radius[cur];
            if (self.bounds.sides)
                .gap_to_wall(x, a, push)
                .is_some_and(|gap| gap <= TOUCH * a)
            {
                return true;
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
}

#[cfg(test)]
mod tests {
    use super::super::tests::jams_in;

    /// A bouncing bed between walls lands on rows at rest from wall to wall.
    #[test]
    fn a_bed_coming_to_rest_meets_jammed_rows() {
        assert!(jams_in("bouncing_bed_gamma_1.5.json", &[]).jammed_row > 0);
    }
}
