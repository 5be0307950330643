//! Prediction: each disk's earliest event, asked of each event source in turn (pair contacts
//! in [`pair`](super::pair), then [`walls`](super::walls), [`floor`](super::floor) and the
//! local re-mapping's shells) and filed in the event queue.

use super::event::code;
use super::Simulation;
use crate::physics::flight::Flight;

/// A disk's state at a time: `(x, y, vx, vy)`.
pub(super) type State = (f64, f64, f64, f64);

/// A disk's event while its prediction is completed: absolute time, code, the counter filed
/// with it, and the time of a re-check some source needs.
#[derive(Clone, Copy)]
pub(super) struct Next {
    pub t: f64,
    pub who: u32,
    pub counter: u32,
    pub recheck: f64,
}

impl<F: Flight> Simulation<F> {
    /// Finds disk `i`'s earliest event from now and files it in the queue.
    pub(super) fn predict(&mut self, i: usize) {
        let found = self.pair_event(i, self.pair_horizon());
        self.file_found(i, found);
    }

    /// Completes disk `i`'s event from its earliest pair contact `found` (as
    /// [`pair_event`](Self::pair_event) gives it) and files it in the queue.
    #[inline(always)]
    pub(super) fn file_found(&mut self, i: usize, (best, who, recheck): (f64, u32, f64)) {
        if self.control.prefetching {
            // The queue's bucket for the pair contact (the likely event), asked for before the
            // rest of the event is worked out.
            self.events.queue.prefetch_time(self.now + best);
        }
        let old = self.events.time[i];
        self.file_event(i, best, who, recheck);
        self.events.queue.update(&self.events.time, i, old);
    }

    /// Completes disk `i`'s event from its earliest pair contact (`best` from now, with `who`)
    /// with each other source — walls, lid, floor and ride ends, its shell — and stores it (the
    /// queue is not touched). Ties go to the source asked first.
    pub(super) fn file_event(&mut self, i: usize, best: f64, who: u32, recheck: f64) {
        let now = self.now;
        let state = self.state_at(i, now);
        let a = self.disks.radius[i];
        let counter = if who != code::NONE {
            self.disks.counter[who as usize]
        } else {
            0
        };
        let mut recheck = recheck;
        let (best, who) = if self.rest.riders.any_sliding() && self.rest.riders.slide(i).is_some() {
            self.sliding_wall_event(i, state, a, (best, who), &mut recheck)
        } else {
            self.wall_event(state, a, best, who)
        };
        let mut next = Next {
            t: now + best,
            who,
            counter,
            recheck,
        };
        if self.bounds.floor.is_some() {
            self.floor_events(i, state, a, &mut next);
        } else {
            self.lid_event(state, a, &mut next);
        }
        if self.map.shells.is_some() {
            let exit = self.shell_exit(i, state);
            if exit < next.t {
                next.t = exit;
                next.who = code::SHELL;
            }
        }
        if next.recheck < next.t {
            next.t = next.recheck;
            next.who = code::RECHECK;
        }
        if next.who >= code::FIRST_NOT_A_DISK && next.who != code::RIDE_END {
            next.counter = 0;
        }
        self.events.time[i] = next.t;
        self.events.code[i] = next.who;
        self.events.counter[i] = next.counter;
    }
}
