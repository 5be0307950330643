//! How a disk is found at a time: on its own parabola (or line) from its time stamp, or carried
//! by the floor; brought forward lazily, only when an event touches it.

use super::Simulation;
use crate::dynamics::Flight;
use crate::locals::{SideBounds, Top};

/// Minimum-image separation where periodic. Positions are wrapped at every mapping and drift
/// by less than the DUTC margin before the next, so one correction suffices.
#[inline(always)]
pub(super) fn wrap(sides: SideBounds, top: Top, mut dx: f64, mut dy: f64) -> (f64, f64) {
    if let SideBounds::Periodic { width } = sides {
        if dx > 0.5 * width {
            dx -= width;
        } else if dx < -0.5 * width {
            dx += width;
        }
    }
    if let Top::Periodic { height } = top {
        if dy > 0.5 * height {
            dy -= height;
        } else if dy < -0.5 * height {
            dy += height;
        }
    }
    (dx, dy)
}

impl<F: Flight> Simulation<F> {
    /// `true` when disk `i` rides the floor.
    #[inline(always)]
    pub(super) fn is_riding(&self, i: usize) -> bool {
        self.riders.is_riding(i)
    }

    /// State of disk `i` at local time `t`: on its parabola (or line), or carried by the floor.
    #[inline(always)]
    pub(super) fn state_at(&self, i: usize, t: f64) -> (f64, f64, f64, f64) {
        if self.is_riding(i) {
            return self.riding_state_at(i, t);
        }
        let m = &self.disks.motion[i];
        self.flight.advance(m.x, m.y, m.vx, m.vy, t - m.t)
    }

    /// [`state_at`](Self::state_at) of a riding disk. Kept out of line: inlined, the floor's
    /// phase (a sine and two remainders) is hoisted out of the pair loops and computed for every
    /// prediction, in scenes where no disk rides or without a floor at all.
    #[inline(never)]
    fn riding_state_at(&self, i: usize, t: f64) -> (f64, f64, f64, f64) {
        let m = &self.disks.motion[i];
        let (h, hd) = self.floor.as_ref().expect("riders need a floor").ride(t);
        (m.x + m.vx * (t - m.t), h + self.riders.lift(i), m.vx, hd)
    }

    /// Brings disk `i` to local time `t` (its stored state then belongs to `t`). The work the
    /// floor does on a riding disk meanwhile is booked as injected energy.
    #[inline(always)]
    pub(super) fn bring(&mut self, i: usize, t: f64) {
        let (x, y, vx, vy) = self.state_at(i, t);
        let mass = self.disks.mass[i];
        let g = self.flight.g();
        let m = &mut self.disks.motion[i];
        if self.riders.is_riding(i) {
            self.flow.injected += mass * (g * (y - m.y) + 0.5 * (vy * vy - m.vy * m.vy));
            self.flow.floor_impulse += mass * (g * (t - m.t) + (vy - m.vy));
        }
        *m = crate::disks::Motion { x, y, vx, vy, t };
    }

    /// Minimum-image separation where periodic.
    #[inline(always)]
    pub(super) fn wrap(&self, dx: f64, dy: f64) -> (f64, f64) {
        wrap(self.sides, self.top, dx, dy)
    }

    /// Squared speed of disk `i` (at its own time stamp) in the frame falling with gravity since
    /// the last mapping.
    #[inline(always)]
    pub(super) fn falling_speed_sq(&self, i: usize) -> f64 {
        let vy = self.disks.motion[i].vy + self.flight.g() * self.disks.motion[i].t;
        self.disks.motion[i].vx * self.disks.motion[i].vx + vy * vy
    }
}
