//! What a collision of two disks does: the impulse with the restitution of the collision law,
//! the floor's answer to disks it carried, and the re-prediction of both disks. The rest rules
//! that may take a collision over (a landing on a disk at rest, jammed rows and clusters) are
//! only asked here: each decides, acts and counts in its own file under `engine/rest/`.

use crate::engine::{Simulation, OVERLAP_TOLERANCE};
use crate::error::{Error, Result};
use crate::physics::flight::Flight;
use crate::physics::floor::Floor;
use crate::physics::pair::collide_rebounding;

impl<F: Flight> Simulation<F> {
    /// Disks `i` and `j` changed velocity together (a collision): both are counted, observed by
    /// the DUTC and re-predicted, as [`moved`](Self::moved)`(i)` and then `j`'s prediction.
    /// Where no disk rides, the two neighbour searches run side by side before either event is
    /// filed: they are independent (a search in flight reads the disks' states, not the queue
    /// nor the event times), so the processor overlaps their square roots and divisions, and
    /// the events filed are the same. Always inlined into [`pair`](Self::pair), as are the
    /// floor's answer and the jammed cluster's trigger: every collision runs them.
    #[inline(always)]
    fn moved_pair(&mut self, i: usize, j: usize) {
        self.disks.counter[j] = self.disks.counter[j].wrapping_add(1);
        if self.rest.riders.any() {
            self.moved(i);
            if !self.is_riding(j) {
                let s = self.falling_speed_sq(j);
                self.map.dutc.observe(self.now, s);
            }
            self.predict(j);
            return;
        }
        self.disks.counter[i] = self.disks.counter[i].wrapping_add(1);
        let s = self.falling_speed_sq(i);
        self.map.dutc.observe(self.now, s);
        let found_i = self.pair_event(i, self.pair_horizon());
        // `i`'s event is completed with the DUTC deadline its search saw (the one part of the
        // DUTC an event's completion reads: a floor event is looked for up to it, and `j`'s
        // speed may bring it closer).
        let deadline_i = self.map.dutc.deadline;
        let s = self.falling_speed_sq(j);
        self.map.dutc.observe(self.now, s);
        let found_j = self.pair_event(j, self.pair_horizon());
        let deadline_ij = std::mem::replace(&mut self.map.dutc.deadline, deadline_i);
        self.file_found(i, found_i);
        self.map.dutc.deadline = deadline_ij;
        self.file_found(j, found_j);
    }

    /// Hints the memory system at what a collision of `i` and `j` reads next: both disks'
    /// shells and queue entries, once their new events are known, and their neighbours'
    /// states, for the new predictions.
    fn prefetch_pair(&self, i: usize, j: usize) {
        if let Some(shells) = &self.map.shells {
            shells.prefetch(i);
            shells.prefetch(j);
        }
        self.events.queue.prefetch(i);
        self.events.queue.prefetch(j);
        for k in [i, j] {
            for &n in self.map.lists.of(k) {
                crate::platform::prefetch::prefetch(&self.disks.motion, n as usize);
            }
        }
    }

    /// A collision of disks `i` and `j` (or what stands in for one: a landing, a jammed row).
    ///
    /// Out of line: the event loop and `fire` then compile to one compact loop, which the
    /// fluidized beds run faster.
    #[inline(never)]
    pub(in crate::engine) fn pair(&mut self, i: usize, j: usize) -> Result<()> {
        let now = self.now;
        if self.control.prefetching {
            self.prefetch_pair(i, j);
        }
        self.bring(i, now);
        self.bring(j, now);
        let rode = [self.is_riding(i), self.is_riding(j)];
        let d = &self.disks;
        let (dx, dy) = self.wrap(d.motion[i].x - d.motion[j].x, d.motion[i].y - d.motion[j].y);
        if self.roll_pressed_slider(i, j, (dx, dy)) || self.held_at_rest(i, j, rode, (dx, dy))? {
            return Ok(());
        }
        let d = &self.disks;
        let (dvx, dvy) = (
            d.motion[i].vx - d.motion[j].vx,
            d.motion[i].vy - d.motion[j].vy,
        );
        let e = if rode[0] != rode[1] && self.rest.resting_contacts {
            self.restitution
                .collision_with_rest(i, j, now, (dx, dy, dvx, dvy))
        } else {
            self.restitution.collision(i, j, now, dx, dy, dvx, dvy)
        };
        // A disk landing on a rider (or a rider hit from above) is pressed onto it by gravity
        // and the floor: a rebound of at least the resting speed keeps the pair from Zeno.
        let min_rebound = if rode[0] != rode[1] {
            // The separation's vertical part, from the rider to the flying disk.
            let up = if rode[0] { -dy } else { dy };
            self.landing_rebound(i, j, up, (dx * dx + dy * dy).sqrt())
        } else {
            0.0
        };
        if self.rest_rules_take(i, j, rode, (dx, dy), e)? {
            return Ok(());
        }
        // Riders leave the floor's grip for the collision; if it pushes a disk riding the floor
        // into it, the floor answers at once (sequential impulses).
        let on_floor = [
            rode[0] && self.rest.riders.on_floor(i),
            rode[1] && self.rest.riders.on_floor(j),
        ];
        for (k, rode) in [(i, rode[0]), (j, rode[1])] {
            if rode {
                self.rest.riders.dismount(k);
            }
        }
        let d = &self.disks;
        let dv = (
            d.motion[i].vx - d.motion[j].vx,
            d.motion[i].vy - d.motion[j].vy,
        );
        let imp = collide_rebounding(dx, dy, dv.0, dv.1, d.mass[i], d.mass[j], e, min_rebound);
        self.check_contact(i, j, imp.distance)?;
        imp.apply(&mut self.disks.motion, i, j);
        self.rub_pair(i, j, (dx, dy, imp.distance), dv, imp.momentum);
        self.tally.flow.dissipated += imp.energy_lost;
        self.tally.virial += imp.distance * imp.momentum;
        self.tally.counts.pair += 1;
        self.floor_answers([(i, on_floor[0]), (j, on_floor[1])]);
        self.moved_pair(i, j);
        // What rested on them rested on disks that have now moved.
        for (k, rode) in [(i, rode[0]), (j, rode[1])] {
            if rode {
                self.release_carried(k, None);
            }
        }
        self.settle_if_jammed(i, j, rode, e);
        Ok(())
    }

    /// The rest rules that may take a collision of disks `i` and `j` over (`rode`: whether each
    /// rode before; `sep` from `j` to `i`; `e` the restitution it would have), asked in turn,
    /// each deciding whether it applies: the resting contacts (two disks at rest that come to
    /// rest together, a disk coming to rest on one at rest), then the full rows (on the floor,
    /// seated on a row at rest). True if one did.
    fn rest_rules_take(
        &mut self,
        i: usize,
        j: usize,
        rode: [bool; 2],
        sep: (f64, f64),
        e: f64,
    ) -> Result<bool> {
        Ok(self.resting_contact_takes(i, j, rode, sep, e)? || self.full_row_takes(i, j, rode, sep))
    }

    /// After a collision, the floor answers at once each disk that rode it and was pushed into
    /// it (sequential impulses).
    #[inline(always)]
    fn floor_answers(&mut self, riders: [(usize, bool); 2]) {
        for (k, on_floor) in riders {
            if on_floor {
                let floor = self.bounds.floor.as_ref().expect("riders need a floor");
                let (_, hd) = floor.ride(self.now);
                if self.disks.motion[k].vy < hd {
                    self.floor_impact(k, hd);
                }
            }
        }
    }

    /// The least rebound of a flying disk landing on a riding one (disks `i` and `j`, either
    /// way round, centres `dist` apart, the flying one `up` higher): gravity and the floor press
    /// them together at `(g + h'')·up/dist`, and a rebound of at least the resting speed at that
    /// pressure keeps the pair from Zeno (0 if not pressed).
    pub(in crate::engine) fn landing_rebound(&self, i: usize, j: usize, up: f64, dist: f64) -> f64 {
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        let press = (self.flight.g() + floor.ride_acceleration(self.now)) * up / dist;
        if press > 0.0 {
            Floor::pair_rest_speed(self.disks.radius[i].min(self.disks.radius[j]), press)
        } else {
            0.0
        }
    }

    /// Books the overlap of disks `i` and `j` colliding at centre distance `distance`, and fails
    /// if it is beyond tolerance while the invariant checks are on.
    pub(in crate::engine) fn check_contact(
        &mut self,
        i: usize,
        j: usize,
        distance: f64,
    ) -> Result<()> {
        let contact = self.disks.radius[i] + self.disks.radius[j];
        let overlap = contact - distance;
        if overlap > self.tally.max_overlap {
            self.tally.max_overlap = overlap;
            if self.control.check && overlap > OVERLAP_TOLERANCE * contact {
                return Err(Error::Runtime(format!(
                    "disks {} and {} overlap by {overlap:e} at time {}",
                    self.map.numbering.id(i),
                    self.map.numbering.id(j),
                    self.time()
                )));
            }
        }
        Ok(())
    }
}
