//! **A closed wedge**, or disks ringing in gaps of round-off: a flying disk with more than
//! [`ZENO`](super::ZENO) events within [`INSTANT`](super::INSTANT) of the first stops, with the
//! slow flying disks it touches.

use super::*;
use crate::engine::event::code;
use crate::engine::rest::riders::NO_DISK;
use crate::engine::Simulation;
use crate::physics::flight::Flight;

impl<F: Flight> Simulation<F> {
    /// A flying disk whose events keep happening at one instant — more than [`ZENO`] after the
    /// first, all within [`INSTANT`] — is caught in a closed wedge of neighbours and walls that
    /// do not give, or rings with its neighbours in gaps of round-off, where a cure makes the
    /// collisions elastic (with e < 1 the sequence would be infinite too, its limit a disk at
    /// rest among them). It stops: it takes the floor's velocity (kinetic energy relative to the
    /// floor booked as dissipated, the rest as floor work) and comes to rest if its place holds
    /// it, or else flies on from there, and the slow flying disks it touches stop with it.
    /// Returns whether it did (the event is then dropped; its partner's prediction is renewed
    /// as stale).
    #[inline]
    pub(in crate::engine) fn stop_zeno(&mut self, i: usize) -> bool {
        let now = self.now;
        if self.rest.same_instant.is_empty() || self.is_riding(i) {
            return false;
        }
        let instant2 = self.rest.zeno_instant2 * self.disks.radius[i];
        let seen = &mut self.rest.same_instant[i];
        // Within `INSTANT √(a/g)` of the first, squared (no square root per event); not so a
        // first event (NaN), or one from before the clock was re-based.
        let dt = now - seen.0;
        if !(dt >= 0.0 && dt * dt <= instant2) {
            *seen = (now, 0);
            return false;
        }
        seen.1 += 1;
        if seen.1 <= ZENO {
            return false;
        }
        seen.1 = 0;
        self.stop_caught(i);
        true
    }

    /// Disk `i`, caught at one instant (see [`stop_zeno`](Self::stop_zeno)), stops: at rest
    /// if its place holds it, else still relative to the floor together with the slow flying
    /// disks it touches, directly or through each other.
    #[cold]
    #[inline(never)]
    pub(in crate::engine) fn stop_caught(&mut self, i: usize) {
        let now = self.now;
        self.tally.counts.zeno += 1;
        self.tally.jams.zeno += 1;
        self.bring(i, now);
        let (h, hd) = self.floor_now();
        let pressed = self.sleep_speed(i) > 0.0;
        // At rest where it is, if the floor presses and the place holds it (on the floor, or
        // between disks at rest that do not slide, or walls): still, it would be pressed back
        // into the same neighbours at once. A flying disk about to hit it wakes it as usual.
        let place = if !pressed || self.near_lid(i) {
            None
        } else if self.touches_floor(i, h) {
            Some([NO_DISK; 2])
        } else {
            self.stable_place(i, None, |c| {
                self.is_riding(c) && self.disks.motion[c].vx == 0.0
            })
        };
        if let Some(place) = place {
            if self.come_to_rest(i, h, place, (0.0, hd)) {
                self.settle_cluster(i);
                return;
            }
        }
        self.take_velocity(i, (0.0, hd));
        if !pressed {
            self.moved(i);
            return;
        }
        // The slow flying disks it touches, directly or through each other, ring with it (a
        // push passes round them and back at one instant): they stop with it, and wait an
        // instant (see `wait_an_instant`).
        let mut member = std::mem::take(&mut self.rest.in_cluster);
        member.resize(self.disks.len(), false);
        let mut cluster = std::mem::take(&mut self.rest.cluster);
        self.gather_slow(i, hd, &mut member, &mut cluster);
        for &c in &cluster[1..] {
            self.bring(c as usize, now);
            self.take_velocity(c as usize, (0.0, hd));
        }
        for &c in &cluster {
            self.moved(c as usize);
            self.wait_an_instant(c as usize);
            member[c as usize] = false;
        }
        // The disks at rest beside them, rising with the floor, would press them into the ring
        // again at once: they wait the instant too.
        for &c in &cluster {
            for k in 0..self.map.lists.of(c as usize).len() {
                let r = self.map.lists.of(c as usize)[k] as usize;
                if self.is_riding(r) {
                    self.wait_an_instant(r);
                }
            }
        }
        cluster.clear();
        self.rest.cluster = cluster;
        self.rest.in_cluster = member;
    }

    /// Disk `k`, stopped where no place holds it, with its next event within an [`INSTANT`]
    /// (`INSTANT √(a/(g + h''_max))`): the event waits until the instant has passed, and a
    /// re-check then works it out afresh. Its ring would start again at once — a disk at rest
    /// beside it rises with the floor while it falls, a contact a hair off level closes in
    /// round-off, and the rebound of a landing sets it going — and ties go to the same disks
    /// each time: the neighbour whose move ends the ring (a support sliding away, due now or a
    /// little later) would never get its turn, and time would stop.
    fn wait_an_instant(&mut self, k: usize) {
        let now = self.now;
        let old = self.events.time[k];
        let after = now + (self.rest.zeno_instant2 * self.disks.radius[k]).sqrt();
        if old >= after {
            return;
        }
        self.events.time[k] = after;
        self.events.code[k] = code::RECHECK;
        self.events.counter[k] = 0;
        self.events.queue.update(&self.events.time, k, old);
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::jams_in;

    /// A stack on a floor shaken at Γ = 1.2 catches flying disks in wedges of disks at rest, where their events come at one instant.
    #[test]
    fn a_disk_caught_in_a_wedge_of_a_ringing_stack_stops() {
        assert!(jams_in("stack_gamma_1.2.json", &[]).zeno > 0);
    }
}
