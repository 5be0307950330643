//! The floor as an event source: a flying disk's impact, and for a disk at rest the end of its
//! ride (take-off or a kick) or the loss of a support it rests on; what each does. The floor's
//! motion and its root searches are [`physics::floor`](crate::physics::floor)'s.

use super::event::code;
use super::predict::{Next, State};
use super::rough::Boundary;
use super::Simulation;
use crate::physics::flight::Flight;
use crate::physics::floor::{FloorEvent, RideEnd};

impl<F: Flight> Simulation<F> {
    /// The floor's events for disk `i` (and the lid's, in a scene with a floor), if earlier than
    /// `next`: for a rider the end of its ride or the loss of a support; for a flying disk an
    /// impact on the lid or the floor, or a re-check where the floor's search stopped.
    #[inline(always)]
    pub(super) fn floor_events(&self, i: usize, state: State, a: f64, next: &mut Next) {
        let (_, y, _, vy) = state;
        let floor = self
            .bounds
            .floor
            .as_ref()
            .expect("floor events need a floor");
        let (now, g) = (self.now, self.flight.g());
        if self.is_riding(i) {
            if let Some((t_end, end)) = floor.ride_end(now, g) {
                if t_end < next.t {
                    next.t = t_end;
                    next.who = code::RIDE_END;
                    next.counter = matches!(end, RideEnd::Kick { .. }) as u32;
                }
            }
            if let Some(slide) = self.rest.riders.slide(i) {
                if slide.end < next.t {
                    next.t = slide.end;
                    next.who = code::SLIDE_END;
                }
            }
            if !self.rest.riders.on_floor(i) {
                let t_off = self.unmount_time(i);
                if t_off < next.t {
                    next.t = t_off;
                    next.who = code::UNMOUNT;
                }
            } else if self.bounds.orifice.is_some() {
                *next = self.edge_event(state, *next);
            }
            return;
        }
        if self.bounds.outlets {
            // One test for scenes with an orifice or an exit height; the others run the code
            // below as before. `next` goes by value: a call taking its address would keep it out
            // of registers.
            *next = self.flying_with_outlets(state, a, *next);
            return;
        }
        self.lid_event(state, a, next);
        // Nothing after the re-mapping matters: it re-predicts every disk.
        let limit = next.t.min(self.map.dutc.deadline);
        match floor.next_event(y, vy, a, g, now, limit) {
            Some(FloorEvent::Impact(tf)) if tf < next.t => {
                next.t = tf;
                next.who = code::FLOOR;
            }
            Some(FloorEvent::Recheck(tf)) => next.recheck = next.recheck.min(tf),
            _ => {}
        }
    }

    /// [`floor_events`](Self::floor_events) of a flying disk in a scene whose disks may leave:
    /// the lid, the floor (where the centre lands beside the orifice's gap), the orifice's
    /// corners and exit, and the exit at the top.
    #[inline(never)]
    fn flying_with_outlets(&self, state: State, a: f64, mut next: Next) -> Next {
        let floor = self
            .bounds
            .floor
            .as_ref()
            .expect("outlets are in a scene with a floor");
        let (now, g) = (self.now, self.flight.g());
        let (_, y, _, vy) = state;
        self.lid_event(state, a, &mut next);
        let limit = next.t.min(self.map.dutc.deadline);
        match floor.next_event(y, vy, a, g, now, limit) {
            Some(FloorEvent::Impact(tf)) if tf < next.t && !self.lands_in_gap(state, tf) => {
                next.t = tf;
                next.who = code::FLOOR;
            }
            Some(FloorEvent::Recheck(tf)) => next.recheck = next.recheck.min(tf),
            _ => {}
        }
        if self.bounds.orifice.is_some() {
            self.orifice_events(state, a, &mut next);
        }
        if let Some(h) = self.bounds.exit_height {
            self.top_exit_event(state, h, &mut next);
        }
        next
    }

    /// The floor's height and velocity now: what disks at rest move with (a scene with disks at
    /// rest has a floor).
    pub(in crate::engine) fn floor_now(&self) -> (f64, f64) {
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        floor.ride(self.now)
    }

    /// Flying disk `i` hits the floor.
    pub(super) fn hit_floor(&mut self, i: usize) {
        self.bring(i, self.now);
        let floor = self
            .bounds
            .floor
            .as_ref()
            .expect("floor events need a floor");
        let hd = floor.velocity(self.now);
        self.floor_impact(i, hd);
        self.moved(i);
    }

    /// Disk `i`, at rest on disks, loses a support: it flies.
    pub(super) fn unmount(&mut self, i: usize) {
        self.bring(i, self.now);
        self.tally.counts.unmount += 1;
        self.rest.riders.dismount(i);
        self.moved(i);
        self.release_carried(i, None);
    }

    /// Disk `i`'s ride on the floor ends: it takes off, or the floor kicks it (the disks resting
    /// on it leave with it).
    pub(super) fn end_ride(&mut self, i: usize) {
        let now = self.now;
        self.bring(i, now);
        let on_floor = self.rest.riders.on_floor(i);
        self.rest.riders.leave(i);
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        let g = self.flight.g();
        let kick = self.events.counter[i] == 1;
        // The end that was predicted, evaluated at its own time.
        let end = floor
            .ride_end(now - 1e-9 * floor.period_or_one(), g)
            .map(|(_, e)| e);
        // Disks resting on disks leave with the floor's velocity before a kick (the disk
        // below then hits them) or with the launch velocity (they all fly together).
        let vy = match end {
            Some(RideEnd::Kick { before, after }) if kick => {
                self.set_vy(i, before);
                if on_floor {
                    self.floor_impact(i, after);
                }
                before
            }
            Some(RideEnd::TakeOff { launch }) if !kick => {
                self.tally.counts.takeoff += 1;
                self.set_vy(i, launch);
                launch
            }
            _ => {
                // Round-off moved us past the end: fly with the floor's velocity.
                self.tally.counts.takeoff += 1;
                let hd = floor.velocity(now);
                self.set_vy(i, hd);
                hd
            }
        };
        self.moved(i);
        self.release_carried(i, Some(vy));
    }

    /// Sets the vertical velocity of (flying) disk `i`, booking the change as floor work (and
    /// floor momentum).
    pub(super) fn set_vy(&mut self, i: usize, vy: f64) {
        let m = &mut self.disks.motion[i];
        self.tally.flow.floor_work(self.disks.mass[i], m.vy, vy);
        m.vy = vy;
    }

    /// Flying disk `i` (brought to now) hits the floor moving with velocity `hd`: it bounces,
    /// or comes to rest and rides the floor if the rebound is negligible.
    pub(super) fn floor_impact(&mut self, i: usize, hd: f64) {
        let now = self.now;
        let g = self.flight.g();
        let floor = self
            .bounds
            .floor
            .as_ref()
            .expect("floor impacts need a floor");
        let vy = self.disks.motion[i].vy;
        let after = floor.hit(&mut self.restitution, i, now, vy, hd);
        // Rebound relative to what a resting disk would do: move with the floor (exact model)
        // or stay put (fixed-position model).
        let (h, hd_ride) = floor.ride(now);
        let rests = floor.comes_to_rest(after - hd_ride, self.disks.radius[i], g, now);
        let lift_speed = floor.drive().peak_velocity();
        let before = (self.disks.motion[i].vx, vy);
        self.set_vy(i, after);
        self.rub_boundary(i, Boundary::Floor, (0.0, hd), before);
        self.tally.counts.floor += 1;
        if rests {
            let mass = self.disks.mass[i];
            let a = self.disks.radius[i];
            let m = &mut self.disks.motion[i];
            // A disk that rested a little above the surface (it came to rest beside a disk at
            // rest, within TOUCH radii of the floor) and is knocked onto the floor keeps its
            // height: moving it down could push it into a smaller neighbour.
            let above = if m.y - h > a * (1.0 + 1e-12) {
                m.y - h
            } else {
                a
            };
            // Seated on the floor at once: no time passes.
            let seat = (h + above, hd_ride, now);
            self.tally.flow.floor_carry(mass, g, (m.y, m.vy, now), seat);
            m.y = h + above;
            m.vy = hd_ride;
            let t = self.time();
            self.rest.riders.mount_on_floor(i, above, t);
            self.tally.counts.rest += 1;
            self.slide_on_floor(i);
            if self.rest.resting_contacts && self.disks.motion[i].vx.abs() < self.sleep_speed(i) {
                self.stop_sliding(i);
            }
            if self.rest.resting_contacts {
                self.settle_cluster(i);
            }
            let m = &self.disks.motion[i];
            let vx = m.vx.abs();
            self.map.dutc.ride(now, vx + lift_speed, g);
        }
    }
}
