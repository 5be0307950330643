//! **A gentle push** on a disk at rest, slower than the sleep speed: the disk pushed does not
//! give (the static friction of resting contacts). The flying disk comes to rest on it or
//! bounces off it ([`held`](super::held)); without this a push passes along a row of disks at
//! rest, each knocked off its supports and at rest again at once, and back, at one instant.

use super::level;
use crate::engine::Simulation;
use crate::error::Result;
use crate::physics::flight::Flight;

impl<F: Flight> Simulation<F> {
    /// Flying disk `k` (brought to now, `(sx, sy)` from `s` to it) pushes disk `s`, at rest,
    /// gently and level: `s` does not give ([`meet_held`](Self::meet_held)). Whether it did.
    pub(in crate::engine) fn push_gently(
        &mut self,
        k: usize,
        s: usize,
        (sx, sy): (f64, f64),
    ) -> Result<bool> {
        if !(level(sx, sy) && self.pushed_gently(k, s, (sx, sy))) {
            return Ok(false);
        }
        self.tally.jams.gentle_push += 1;
        self.meet_held(k, s, (sx, sy))?;
        Ok(true)
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
}

#[cfg(test)]
mod tests {
    use super::super::tests::jams_in;

    /// A disk pushing one at rest slower than the sleep speed does not move it.
    #[test]
    fn a_gentle_push_does_not_move_a_disk_at_rest() {
        assert!(jams_in("pocket_by_a_wall.json", &[]).gentle_push > 0);
    }
}
