//! How a disk is found at a time: on its own parabola (or line) from its time stamp, or carried
//! by the floor; brought forward lazily, only when an event touches it.

use super::Simulation;
use crate::physics::flight::Flight;

impl<F: Flight> Simulation<F> {
    /// `true` when disk `i` rides the floor.
    #[inline(always)]
    pub(super) fn is_riding(&self, i: usize) -> bool {
        self.rest.riders.is_riding(i)
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

    /// [`state_at`](Self::state_at) at the time `t` of the floor's `ride` (height, velocity):
    /// loops over neighbours at one time compute the floor's phase once, not per rider.
    #[inline(always)]
    pub(super) fn state_at_with(&self, i: usize, t: f64, ride: (f64, f64)) -> (f64, f64, f64, f64) {
        let m = &self.disks.motion[i];
        if self.is_riding(i) {
            let (dx, dv) = self.slide_offsets(i, t);
            return (
                m.x + m.vx * (t - m.t) + dx,
                ride.0 + self.rest.riders.lift(i),
                m.vx + dv,
                ride.1,
            );
        }
        self.flight.advance(m.x, m.y, m.vx, m.vy, t - m.t)
    }

    /// [`state_at`](Self::state_at) of a riding disk. Kept out of line: inlined, the floor's
    /// phase (a sine and two remainders) is hoisted out of the pair loops and computed for every
    /// prediction, in scenes where no disk rides or without a floor at all.
    #[inline(never)]
    fn riding_state_at(&self, i: usize, t: f64) -> (f64, f64, f64, f64) {
        let m = &self.disks.motion[i];
        let (h, hd) = self
            .bounds
            .floor
            .as_ref()
            .expect("riders need a floor")
            .ride(t);
        let (dx, dv) = self.slide_offsets(i, t);
        (
            m.x + m.vx * (t - m.t) + dx,
            h + self.rest.riders.lift(i),
            m.vx + dv,
            hd,
        )
    }

    /// How far riding disk `i`'s slide on a rough floor has taken it off its straight line by
    /// local time `t`: `(δx, δv_x)` ([`Slide::offsets`](crate::physics::slide::Slide::offsets));
    /// `(0, 0)` when it does not slide (the test inline, the slide out of line: few disks
    /// slide, and only on a rough floor).
    #[inline(always)]
    pub(super) fn slide_offsets(&self, i: usize, t: f64) -> (f64, f64) {
        if !self.rest.riders.any_sliding() {
            return (0.0, 0.0);
        }
        match self.rest.riders.slide(i) {
            Some(_) => self.sliding_offsets(i, t),
            None => (0.0, 0.0),
        }
    }

    #[inline(never)]
    fn sliding_offsets(&self, i: usize, t: f64) -> (f64, f64) {
        let slide = self.rest.riders.slide(i).expect("a slide");
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        let t0 = self.disks.motion[i].t;
        slide.offsets(self.flight.g(), t0, t, floor.ride(t0), |t| floor.ride(t))
    }

    /// A bound on riding disk `i`'s horizontal speed from its time stamp on, `vx` its velocity
    /// now: `|vx|`, or for a disk sliding on a rough floor the larger of that and its speed where
    /// the slide ends (its velocity changes monotonically until then).
    pub(super) fn riding_speed_bound(&self, i: usize, vx: f64) -> f64 {
        let Some(slide) = self.rest.riders.slide(i) else {
            return vx.abs();
        };
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        let m = &self.disks.motion[i];
        let stop = match floor.ride_end(self.now, self.flight.g()) {
            Some((t_end, _)) => slide.end.min(t_end),
            None => slide.end,
        };
        let g = self.flight.g();
        let (_, dv) = slide.offsets(g, m.t, stop, floor.ride(m.t), |t| floor.ride(t));
        vx.abs().max(m.vx.abs()).max((m.vx + dv).abs())
    }

    /// Brings disk `i` to local time `t` (its stored state then belongs to `t`). The work the
    /// floor does on a riding disk meanwhile is booked as injected energy.
    #[inline(always)]
    pub(super) fn bring(&mut self, i: usize, t: f64) {
        let (x, y, vx, vy) = self.state_at(i, t);
        let mass = self.disks.mass[i];
        let g = self.flight.g();
        if self.rest.riders.any_sliding() && self.rest.riders.slide(i).is_some() {
            self.bring_slide(i, t, (x, vx));
        }
        let m = &mut self.disks.motion[i];
        if self.rest.riders.is_riding(i) {
            self.tally
                .flow
                .floor_carry(mass, g, (m.y, m.vy, m.t), (y, vy, t));
        }
        *m = crate::physics::disks::Motion { x, y, vx, vy, t };
    }

    /// Minimum-image separation where periodic.
    #[inline(always)]
    pub(super) fn wrap(&self, dx: f64, dy: f64) -> (f64, f64) {
        self.bounds.images.wrap(dx, dy)
    }

    /// Squared speed of disk `i` (at its own time stamp) in the frame falling with gravity since
    /// the last mapping.
    #[inline(always)]
    pub(super) fn falling_speed_sq(&self, i: usize) -> f64 {
        let vy = self.disks.motion[i].vy + self.flight.g() * self.disks.motion[i].t;
        self.disks.motion[i].vx * self.disks.motion[i].vx + vy * vy
    }
}
