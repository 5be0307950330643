//! The outlets as event sources: the floor's orifice (impacts on its two corners, a flying disk
//! leaving once wholly below the floor, a disk at rest on the floor sliding over an edge) and
//! the exit height of an open top (a flying disk leaving when its centre rises to it). The
//! orifice's geometry and root finding are [`physics::orifice`](crate::physics::orifice)'s; a
//! disk leaving is the [`pool`](super::pool)'s.

use super::event::code;
use super::predict::{Next, State};
use super::Simulation;
use crate::physics::flight::{time_to_rise, Flight};
use crate::physics::orifice::{corner_contact, time_below};
use crate::physics::walls::into_period;
use crate::physics::walls::SideBounds;

impl<F: Flight> Simulation<F> {
    /// `true` if flying disk `state` (now) has its centre over the gap at local time `t`: the
    /// flat floor cannot hold it there.
    #[inline]
    pub(super) fn lands_in_gap(&self, (x, _, vx, _): State, t: f64) -> bool {
        let Some(o) = self.bounds.orifice else {
            return false;
        };
        let mut x = x + vx * (t - self.now);
        if let SideBounds::Periodic { width } = self.bounds.sides {
            x = into_period(x, width);
        }
        o.over_gap(x)
    }

    /// A flying disk's orifice events, if earlier than `next`: an impact on a corner, or its
    /// exit once its centre is a radius below the floor. Kept out of line: scenes without an
    /// orifice never call it, and the floor's prediction stays as small as before.
    #[inline(never)]
    pub(super) fn orifice_events(&self, (x, y, vx, vy): State, a: f64, next: &mut Next) {
        let o = self.bounds.orifice.expect("an orifice");
        let (now, g) = (self.now, self.flight.g());
        if let Some(dt) = time_below(y, vy, g, a) {
            if now + dt < next.t {
                next.t = now + dt;
                next.who = code::EXIT;
            }
        }
        let limit = next.t.min(self.map.dutc.deadline) - now;
        for (c, who) in [(o.from, code::CORNER_LEFT), (o.to, code::CORNER_RIGHT)] {
            let (dx, dy) = self.wrap(x - c, y);
            if let Some(dt) = corner_contact((dx, dy), (vx, vy), g, a, limit) {
                if now + dt < next.t {
                    next.t = now + dt;
                    next.who = who;
                }
            }
        }
    }

    /// A flying disk's exit at the top, if earlier than `next`: the first time its centre
    /// rises to the exit height `h`, the smaller root of y + vy t − ½ g t² = h in its stable
    /// form (none if the parabola's top stays below `h`).
    #[inline(never)]
    pub(super) fn top_exit_event(&self, (_, y, _, vy): State, h: f64, next: &mut Next) {
        if let Some(dt) = time_to_rise(h - y, vy, self.flight.g()) {
            if self.now + dt < next.t {
                next.t = self.now + dt;
                next.who = code::EXIT_TOP;
            }
        }
    }

    /// A disk at rest on the floor (`state` now) reaches an edge of the orifice, if earlier
    /// than `next`.
    #[inline(never)]
    pub(super) fn edge_event(&self, (x, _, vx, _): State, mut next: Next) -> Next {
        let o = self.bounds.orifice.expect("an orifice");
        if vx == 0.0 {
            return next;
        }
        let d = match (self.bounds.sides, vx > 0.0) {
            (SideBounds::Periodic { width }, true) => (o.from - x).rem_euclid(width),
            (SideBounds::Periodic { width }, false) => (x - o.to).rem_euclid(width),
            (_, true) if x <= o.from => o.from - x,
            (_, false) if x >= o.to => x - o.to,
            _ => return next,
        };
        let t = self.now + d / vx.abs();
        if t < next.t {
            next.t = t;
            next.who = code::EDGE;
        }
        next
    }

    /// Disk `i` hits a corner of the orifice (`right`: the right one): an elastic, smooth
    /// impact on a fixed point, along the line from the corner to the centre.
    pub(super) fn hit_corner(&mut self, i: usize, right: bool) {
        self.bring(i, self.now);
        let o = self.bounds.orifice.expect("an orifice");
        let c = if right { o.to } else { o.from };
        let m = self.disks.motion[i];
        let (dx, dy) = self.wrap(m.x - c, m.y);
        let d = (dx * dx + dy * dy).sqrt();
        let (nx, ny) = (dx / d, dy / d);
        let vn = m.vx * nx + m.vy * ny;
        if vn < 0.0 {
            let mass = self.disks.mass[i];
            let mo = &mut self.disks.motion[i];
            mo.vx -= 2.0 * vn * nx;
            mo.vy -= 2.0 * vn * ny;
            self.tally.flow.floor_impulse += mass * (mo.vy - m.vy);
        }
        self.tally.counts.floor += 1;
        if let Some(p) = self.pool.as_mut() {
            p.flow.corner += 1;
        }
        self.moved(i);
    }

    /// Disk `i`, at rest on the floor, reaches an edge of the orifice: it leaves the floor
    /// and flies. A disk slower than √(g a) would roll round the corner, which hard disks
    /// cannot do; it leaves at √(g a), the least speed that clears the corner, the kinetic
    /// energy gained booked as work of the floor.
    pub(super) fn slide_over_edge(&mut self, i: usize) {
        self.bring(i, self.now);
        self.rest.riders.leave(i);
        let (g, a) = (self.flight.g(), self.disks.radius[i]);
        let least = (g * a).sqrt();
        let m = &mut self.disks.motion[i];
        if m.vx.abs() < least {
            let vx = least.copysign(m.vx);
            self.tally.flow.injected += 0.5 * self.disks.mass[i] * (vx * vx - m.vx * m.vx);
            m.vx = vx;
        }
        if let Some(p) = self.pool.as_mut() {
            p.flow.edge += 1;
        }
        self.moved(i);
        self.release_carried(i, None);
    }
}
