//! When a disk next meets a listed neighbour: the search over its neighbour list (in flight, in
//! two branch-free passes; with riders, whose contacts need the floor's motion), and the
//! prediction of every disk at once after a mapping.

use crate::engine::event::code;
use crate::engine::Simulation;
use crate::physics::flight::Flight;
use crate::physics::pair::{
    contact_time_within, meeting_time, paths_meet, paths_meet_within, rider_contact, RiderContact,
};
use crate::physics::slide::{riders_contact, Slide};
use crate::platform::prefetch::prefetch;

impl<F: Flight> Simulation<F> {
    /// Time from now after which no pair contact matters to a prediction: under Isobe's global
    /// re-mapping, the DUTC deadline (the re-mapping then predicts every disk anew; the deadline
    /// only ever comes closer until it does); ∞ under the local one, whose deadline is far.
    #[inline]
    pub(in crate::engine) fn pair_horizon(&self) -> f64 {
        if self.map.shells.is_none() {
            self.map.dutc.deadline - self.now
        } else {
            f64::INFINITY
        }
    }

    /// Earliest contact of disk `i` with a listed neighbour from now: (time from now, partner,
    /// time of a needed re-check). A contact `horizon` or more from now may be left out.
    #[inline]
    pub(in crate::engine) fn pair_event(&self, i: usize, horizon: f64) -> (f64, u32, f64) {
        if !self.rest.riders.any() {
            return self.pair_event_over(i, self.map.lists.of(i), horizon);
        }
        self.pair_event_with_riders(i, horizon)
    }

    /// [`pair_event`](Self::pair_event) over `list` (disk `i`'s list, in its order, before it
    /// is stored: see `leave_shell`) while no disk rides.
    #[inline]
    pub(in crate::engine) fn pair_event_over(
        &self,
        i: usize,
        list: &[u32],
        horizon: f64,
    ) -> (f64, u32, f64) {
        let (best, who) = if horizon.is_finite() {
            self.pair_event_in_flight::<true>(i, list, horizon)
        } else {
            self.pair_event_in_flight::<false>(i, list, horizon)
        };
        (best, who, f64::INFINITY)
    }

    /// [`pair_event`](Self::pair_event) while some disks ride the floor or rest: pairs of a
    /// rider and a flyer need the floor's motion. Out of line: scenes where no disk rides keep
    /// a compact loop (it is cold there).
    #[inline(never)]
    fn pair_event_with_riders(&self, i: usize, horizon: f64) -> (f64, u32, f64) {
        let now = self.now;
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        let ride = floor.ride(now);
        let (xi, yi, vxi, vyi) = self.state_at_with(i, now, ride);
        let speed_i = vxi.abs() + vyi.abs();
        let ai = self.disks.radius[i];
        let rider = self.is_riding(i);
        let mut best = f64::INFINITY;
        let mut who = code::NONE;
        let mut recheck = f64::INFINITY;
        // Two passes per chunk, as in `pair_event_in_flight`; a pair of a rider and a flyer
        // always goes on to the second.
        const CHUNK: usize = 16;
        let mut meeting = [0u32; CHUNK];
        for chunk in self.map.lists.of(i).chunks(CHUNK) {
            let mut k = 0;
            for &j in chunk {
                let (xj, yj, vxj, vyj) = self.state_at_with(j as usize, now, ride);
                let (dx, dy) = self.wrap(xi - xj, yi - yj);
                let s = ai + self.disks.radius[j as usize];
                // A rider and a flyer, or a slider (its path bends): always to the second pass.
                let riding_j = self.is_riding(j as usize);
                let bent = riding_j != rider || (rider && self.slides_either(i, j as usize));
                meeting[k] = j;
                k += (bent | paths_meet(dx, dy, vxi - vxj, vyi - vyj, s)) as usize;
            }
            for &j in &meeting[..k] {
                let j = j as usize;
                let dt = if rider && self.is_riding(j) && self.slides_either(i, j) {
                    let limit = (now + best.min(horizon)).min(self.map.dutc.deadline);
                    match self.sliders_contact(i, j, limit) {
                        Some(RiderContact::At(t)) => Some(t - now),
                        Some(RiderContact::Recheck(t)) => {
                            recheck = recheck.min(t);
                            None
                        }
                        None => None,
                    }
                } else if self.is_riding(j) == rider {
                    // Both fly, or both ride the floor: relative motion is straight.
                    let (xj, yj, vxj, vyj) = self.state_at_with(j, now, ride);
                    let (dx, dy) = self.wrap(xi - xj, yi - yj);
                    let speed = speed_i + vxj.abs() + vyj.abs();
                    contact_time_within(
                        dx,
                        dy,
                        vxi - vxj,
                        vyi - vyj,
                        ai + self.disks.radius[j],
                        speed,
                        best.min(horizon),
                    )
                } else {
                    let mut limit = (now + best).min(self.map.dutc.deadline);
                    let (r, f) = if rider { (i, j) } else { (j, i) };
                    if f == j {
                        // The flyer re-predicts (against i too) at its own event, if not before:
                        // a contact after that is its to find (this keeps a rider from searching
                        // far along a flyer that bounces on the floor beside it).
                        limit = limit.min(self.events.time[j]);
                    }
                    match self.rider_contact(r, f, limit, ride) {
                        Some(RiderContact::At(t)) => Some(t - now),
                        Some(RiderContact::Recheck(t)) => {
                            recheck = recheck.min(t);
                            None
                        }
                        None => None,
                    }
                };
                if let Some(dt) = dt {
                    if dt < best {
                        best = dt;
                        who = j as u32;
                    }
                }
            }
        }
        (best, who, recheck)
    }

    /// [`pair_event`](Self::pair_event) over `list` (disk `i`'s list) while no disk rides
    /// (every scene without a floor, and beds while nothing rests): the same contacts, in a loop
    /// that carries nothing for disks at rest. `WITHIN`: the first pass also drops the pairs
    /// that cannot touch within `horizon` (it pays where the horizon is near, Isobe's deadline, and
    /// would only cost where it is far). Four neighbours at a time where the engine's lanes
    /// are AVX2's, else one by one: the same contact to the bit.
    #[inline]
    pub(in crate::engine) fn pair_event_in_flight<const WITHIN: bool>(
        &self,
        i: usize,
        list: &[u32],
        horizon: f64,
    ) -> (f64, u32) {
        #[cfg(target_arch = "x86_64")]
        if self.control.lanes.avx2() {
            let m = &self.disks.motion[i];
            let (x, y, vx, vy) = self.flight.advance(m.x, m.y, m.vx, m.vy, self.now - m.t);
            let probe = super::lanes::Probe {
                i: i as u32,
                now: self.now,
                x,
                y,
                vx,
                vy,
                speed: vx.abs() + vy.abs(),
                a: self.disks.radius[i],
                g: self.flight.g(),
                half: self.bounds.images.half(),
                period: self.bounds.images.period(),
            };
            let neighbours = super::lanes::Neighbours {
                list,
                motion: &self.disks.motion,
                common_radius: self.disks.radius.common(),
                each_radius: self.disks.radius.each(),
                counter: &self.disks.counter,
                prefetch: self.control.prefetching,
            };
            // SAFETY: the processor has AVX2, and AVX-512 where the lanes are its (the engine's
            // lanes say so); the states are `repr(C)` and every listed neighbour is a disk
            // (indexing is checked).
            return unsafe {
                super::lanes::earliest_contact_on::<WITHIN>(
                    self.control.lanes,
                    &probe,
                    &neighbours,
                    horizon,
                )
            };
        }
        self.pair_event_one_by_one::<WITHIN>(i, list, horizon)
    }

    /// Disk `i`'s earliest contact with a neighbour of `list` one neighbour at a time
    /// (processors without AVX2, or `VIBROBED_CPU=scalar`; the tests compare it with the four
    /// lanes). Out of line where the whole build has AVX2 (the four lanes' loop then stays as
    /// it was without the choice).
    #[cfg_attr(not(target_feature = "avx2"), inline)]
    #[cfg_attr(target_feature = "avx2", inline(never))]
    pub(in crate::engine) fn pair_event_one_by_one<const WITHIN: bool>(
        &self,
        i: usize,
        list: &[u32],
        horizon: f64,
    ) -> (f64, u32) {
        let now = self.now;
        let motion = &self.disks.motion;
        let radius = &self.disks.radius;
        let m = &motion[i];
        let (xi, yi, vxi, vyi) = self.flight.advance(m.x, m.y, m.vx, m.vy, now - m.t);
        let speed_i = vxi.abs() + vyi.abs();
        let ai = radius[i];
        let mut best = f64::INFINITY;
        let mut who = code::NONE;
        // Two passes over each chunk of the list, neither with a branch on what it finds (a
        // third of the pairs meet, at random: such a branch mispredicts often). First the
        // neighbours that approach and whose paths meet; then their contact times, in list
        // order, the earliest taken by selection: exactly what one pass would find.
        const CHUNK: usize = 16;
        let mut meeting = [0u32; CHUNK];
        for chunk in list.chunks(CHUNK) {
            let mut k = 0;
            for &j in chunk {
                let m = &motion[j as usize];
                let (xj, yj, vxj, vyj) = self.flight.advance(m.x, m.y, m.vx, m.vy, now - m.t);
                let (dx, dy) = self.wrap(xi - xj, yi - yj);
                let s = ai + radius[j as usize];
                meeting[k] = j;
                k += if WITHIN {
                    paths_meet_within(dx, dy, vxi - vxj, vyi - vyj, s, horizon)
                } else {
                    paths_meet(dx, dy, vxi - vxj, vyi - vyj, s)
                } as usize;
            }
            for &j in &meeting[..k] {
                // The partner's counter is read once the earliest contact is known.
                if self.control.prefetching {
                    prefetch(&self.disks.counter, j as usize);
                }
                let m = &motion[j as usize];
                let (xj, yj, vxj, vyj) = self.flight.advance(m.x, m.y, m.vx, m.vy, now - m.t);
                let (dx, dy) = self.wrap(xi - xj, yi - yj);
                let speed = speed_i + vxj.abs() + vyj.abs();
                // Every kept pair's time is computed (no early rejection against the earliest
                // so far: see `meeting_time`).
                let dt = meeting_time(dx, dy, vxi - vxj, vyi - vyj, ai + radius[j as usize], speed);
                let earlier = dt < best;
                who = if earlier { j } else { who };
                best = if earlier { dt } else { best };
            }
        }
        (best, who)
    }

    /// `true` when riding disk `i` or `j` slides on a rough floor.
    #[inline(always)]
    fn slides_either(&self, i: usize, j: usize) -> bool {
        let riders = &self.rest.riders;
        riders.any_sliding() && (riders.slide(i).is_some() || riders.slide(j).is_some())
    }

    /// Contact search between riding disks `i` and `j`, one of which slides, from now to
    /// `limit` (no further than either slide's end or the ride's).
    fn sliders_contact(&self, i: usize, j: usize, limit: f64) -> Option<RiderContact> {
        let now = self.now;
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        let g = self.flight.g();
        let slide = |k: usize| self.rest.riders.slide(k).unwrap_or(Slide::NONE);
        let (si, sj) = (slide(i), slide(j));
        let mut limit = limit;
        for sl in [si, sj].iter().filter(|sl| sl.is_on()) {
            limit = limit.min(sl.end);
        }
        if let Some((t_end, _)) = floor.ride_end(now, g) {
            limit = limit.min(t_end);
        }
        let ride = floor.ride(now);
        let (xi, yi, vxi, _) = self.state_at_with(i, now, ride);
        let (xj, yj, vxj, _) = self.state_at_with(j, now, ride);
        let (dx, dy) = self.wrap(xi - xj, yi - yj);
        let s = self.disks.radius[i] + self.disks.radius[j];
        let kappa = si.kappa - sj.kappa;
        riders_contact(
            (dx, vxi - vxj, dy),
            kappa,
            s,
            g,
            floor.max_acceleration(),
            now,
            limit,
            |t| floor.ride(t),
        )
    }

    /// Contact search between riding disk `r` and flying disk `f` from now to `limit`; `ride`:
    /// the floor's height and velocity now.
    fn rider_contact(
        &self,
        r: usize,
        f: usize,
        limit: f64,
        ride: (f64, f64),
    ) -> Option<RiderContact> {
        let now = self.now;
        let floor = self.bounds.floor.as_ref().expect("riders need a floor");
        let g = self.flight.g();
        let limit = match floor.ride_end(now, g) {
            Some((t_end, _)) => limit.min(t_end),
            None => limit,
        };
        // A sliding rider's path is followed to the end of its slide (its event: it is then
        // predicted again, against the flyer too).
        let (kappa, limit) = match self.rest.riders.slide(r) {
            Some(slide) => (slide.kappa, limit.min(slide.end)),
            None => (0.0, limit),
        };
        let (xr, _, vxr, _) = self.state_at_with(r, now, ride);
        let (xf, yf, vxf, vyf) = self.state_at_with(f, now, ride);
        let (dx, _) = self.wrap(xf - xr, 0.0);
        rider_contact(
            dx,
            vxf - vxr,
            yf,
            vyf,
            self.rest.riders.lift(r),
            self.disks.radius[r] + self.disks.radius[f],
            g,
            floor.max_acceleration(),
            kappa,
            now,
            limit,
            |t| floor.ride(t),
            // The floor presses the pair together only beyond its margin, as it presses a
            // flyer touching it (see `Floor::presses`): at a take-off, where g + h'' is
            // round-off, a flyer touching a rider with no normal approach is not pressed into
            // it (the rider leaves the floor at this instant too).
            |t| {
                let acc = floor.ride_acceleration(t);
                if floor.presses(t, g) {
                    acc
                } else {
                    acc.min(-g)
                }
            },
        )
    }

    /// Predicts every disk's event after a mapping (all disks are at the present time): each
    /// listed pair's contact time is computed once, for both disks; the queue is built at once.
    pub(in crate::engine) fn predict_all(&mut self) {
        let n = self.disks.len();
        let mut best = std::mem::take(&mut self.events.time);
        best.fill(f64::INFINITY);
        let mut who = std::mem::take(&mut self.events.code);
        who.fill(code::NONE);
        let any_rider = self.rest.riders.any();
        let (motion, radius) = (&self.disks.motion, &self.disks.radius);
        // Contacts after the next re-mapping do not matter (see `pair_horizon`).
        let limit = self.pair_horizon();
        let within = limit.is_finite();
        // Two passes per chunk of each half list, as in `pair_event_in_flight`.
        const CHUNK: usize = 16;
        let mut meeting = [0u32; CHUNK];
        let mut half = Vec::new();
        for i in 0..n {
            let mi = &motion[i];
            let riding_i = any_rider && self.is_riding(i);
            let pairs = match self.map.lists.half_of(i) {
                Some(kept) => kept,
                None => {
                    self.find_half_list(i, &mut half);
                    &half[..]
                }
            };
            for chunk in pairs.chunks(CHUNK) {
                let mut k = 0;
                for &j in chunk {
                    let mj = &motion[j as usize];
                    let (dx, dy) = self.wrap(mi.x - mj.x, mi.y - mj.y);
                    let s = radius[i] + radius[j as usize];
                    // Pairs with a rider are done disk by disk below.
                    let flying = !riding_i & !(any_rider && self.is_riding(j as usize));
                    let (dvx, dvy) = (mi.vx - mj.vx, mi.vy - mj.vy);
                    let meet = if within {
                        paths_meet_within(dx, dy, dvx, dvy, s, limit)
                    } else {
                        paths_meet(dx, dy, dvx, dvy, s)
                    };
                    meeting[k] = j;
                    k += (flying & meet) as usize;
                }
                for &j in &meeting[..k] {
                    let j = j as usize;
                    let mj = &motion[j];
                    let (dx, dy) = self.wrap(mi.x - mj.x, mi.y - mj.y);
                    let s = radius[i] + radius[j];
                    let speed = mi.vx.abs() + mi.vy.abs() + mj.vx.abs() + mj.vy.abs();
                    let horizon = best[i].max(best[j]).min(limit);
                    if let Some(dt) =
                        contact_time_within(dx, dy, mi.vx - mj.vx, mi.vy - mj.vy, s, speed, horizon)
                    {
                        if dt < best[i] {
                            best[i] = dt;
                            who[i] = j as u32;
                        }
                        if dt < best[j] {
                            best[j] = dt;
                            who[j] = i as u32;
                        }
                    }
                }
            }
        }
        self.events.time = best;
        self.events.code = who;
        for i in 0..n {
            let near_rider = any_rider
                && (self.is_riding(i)
                    || self
                        .map
                        .lists
                        .of(i)
                        .iter()
                        .any(|&j| self.is_riding(j as usize)));
            let (b, w, r) = if near_rider {
                self.pair_event(i, self.pair_horizon())
            } else {
                (self.events.time[i], self.events.code[i], f64::INFINITY)
            };
            self.file_event(i, b, w, r);
        }
        self.events.queue.rebuild(&self.events.time);
    }
}
