//! The side walls and the lid as event sources: when a disk next hits one (the impact times are
//! [`physics::walls`](crate::physics::walls)'s), and what the impact does.

use super::event::{code, Event};
use super::predict::{Next, State};
use super::rest::riders::{LEFT_WALL, RIGHT_WALL};
use super::rough::Boundary;
use super::Simulation;
use crate::physics::flight::Flight;
use crate::physics::pair::RiderContact;
use crate::physics::slide::riders_contact;
use crate::physics::walls::{Side, SideBounds};

impl<F: Flight> Simulation<F> {
    /// A side wall's impact, if earlier than the pair contact `best` from now (partner `who`):
    /// the earlier of the two, from now, with its code.
    #[inline(always)]
    pub(super) fn wall_event(
        &self,
        (x, _, vx, _): State,
        a: f64,
        best: f64,
        who: u32,
    ) -> (f64, u32) {
        match self.bounds.sides.impact(x, vx, a) {
            Some((dt, side)) if dt < best => (dt, Event::Wall(side).code()),
            _ => (best, who),
        }
    }

    /// [`wall_event`](Self::wall_event) of disk `i` while it slides on a rough floor: its path
    /// bends, followed to the end of its slide (its event) or of its ride. A search that did
    /// not conclude asks for a re-check (`recheck`, absolute).
    pub(super) fn sliding_wall_event(
        &self,
        i: usize,
        (x, _, vx, _): State,
        a: f64,
        (best, who): (f64, u32),
        recheck: &mut f64,
    ) -> (f64, u32) {
        let SideBounds::Walls { width, .. } = self.bounds.sides else {
            return (best, who);
        };
        let slide = self.rest.riders.slide(i).expect("a sliding disk");
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        let (now, g) = (self.now, self.flight.g());
        let mut limit = (now + best).min(slide.end);
        if let Some((t_end, _)) = floor.ride_end(now, g) {
            limit = limit.min(t_end);
        }
        let mut first = (best, who);
        // Each wall as a fixed point the centre must come within `a` of.
        for (wall_x, side) in [(0.0, Side::Left), (width, Side::Right)] {
            let contact = riders_contact(
                (x - wall_x, vx, 0.0),
                slide.kappa,
                a,
                g,
                floor.max_acceleration(),
                now,
                limit.min(now + first.0),
                |t| floor.ride(t),
            );
            match contact {
                Some(RiderContact::At(t)) if t - now < first.0 => {
                    first = (t - now, Event::Wall(side).code())
                }
                Some(RiderContact::Recheck(t)) => *recheck = recheck.min(t),
                _ => {}
            }
        }
        first
    }

    /// The lid's impact, if earlier than `next`: it becomes `next`.
    #[inline(always)]
    pub(super) fn lid_event(&self, (_, y, _, vy): State, a: f64, next: &mut Next) {
        if let Some(dt) = self.bounds.top.impact(y, vy, a, self.flight.g()) {
            if self.now + dt < next.t {
                next.t = self.now + dt;
                next.who = code::LID;
            }
        }
    }

    /// Disk `i` hits the side wall `side`, unless it comes to rest against it.
    pub(super) fn hit_wall(&mut self, i: usize, side: Side) {
        let now = self.now;
        self.bring(i, now);
        let wall = match side {
            Side::Left => LEFT_WALL,
            Side::Right => RIGHT_WALL,
        };
        if self.stop_at_wall(i) || self.rest_in_pocket(i, wall) {
            return;
        }
        self.unsettle(i);
        let (m, mass) = (&mut self.disks.motion[i], self.disks.mass[i]);
        let before = (m.vx, m.vy);
        self.tally.flow.dissipated +=
            self.bounds
                .sides
                .hit(side, &mut self.restitution, i, now, m, mass);
        let boundary = match side {
            Side::Left => Boundary::Left,
            Side::Right => Boundary::Right,
        };
        self.rub_boundary(i, boundary, (0.0, 0.0), before);
        if self.is_riding(i) && self.rest.riders.on_floor(i) {
            // Sent back along a rough floor, it slides until it rolls again.
            self.slide_on_floor(i);
        }
        self.tally.counts.wall += 1;
        self.moved(i);
        self.release_carried(i, None);
    }

    /// Disk `i` hits the lid.
    pub(super) fn hit_lid(&mut self, i: usize) {
        self.bring(i, self.now);
        let (m, mass) = (&mut self.disks.motion[i], self.disks.mass[i]);
        let before = (m.vx, m.vy);
        self.tally.flow.dissipated +=
            self.bounds
                .top
                .hit(&mut self.restitution, i, self.now, m, mass);
        self.rub_boundary(i, Boundary::Lid, (0.0, 0.0), before);
        self.tally.counts.lid += 1;
        self.moved(i);
    }
}
