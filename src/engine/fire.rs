//! Firing an event: the disk whose event is due is handed to its source ([`pair`](super::pair),
//! [`walls`](super::walls), [`floor`](super::floor), the shells of the local re-mapping), after
//! the rule that ends a burst of events at one instant has had its say; a disk whose velocity
//! changed is re-predicted.

use super::event::Event;
use super::pool::Outlet;
use super::{Collision, Partner, Simulation};
use crate::error::Result;
use crate::physics::flight::Flight;

impl<F: Flight> Simulation<F> {
    /// Carries out disk `i`'s event at the present time.
    pub(super) fn fire(&mut self, i: usize) -> Result<()> {
        let event = Event::of(self.events.code[i]);
        if self.stop_zeno(i) {
            return Ok(());
        }
        if self.control.log.is_some() {
            self.log_collision(i, event);
        }
        match event {
            Event::Wall(side) => self.hit_wall(i, side),
            Event::Lid => self.hit_lid(i),
            Event::Floor => self.hit_floor(i),
            Event::RideEnd => self.end_ride(i),
            Event::Unmount => self.unmount(i),
            Event::SlideEnd => self.end_slide(i),
            Event::Recheck => {
                self.tally.counts.recheck += 1;
                self.predict(i);
            }
            Event::ShellExit => self.leave_shell(i)?,
            Event::Corner(right) => self.hit_corner(i, right),
            Event::Exit => self.leave(i, Outlet::Orifice)?,
            Event::ExitTop => self.leave(i, Outlet::Top)?,
            Event::Edge => self.slide_over_edge(i),
            Event::None => unreachable!("a disk without an event is never the minimum"),
            Event::Pair(j) => {
                let j = j as usize;
                if self.disks.counter[j] != self.events.counter[i] {
                    self.tally.counts.stale += 1;
                    self.predict(i);
                    return Ok(());
                }
                self.pair(i, j)?;
            }
        }
        Ok(())
    }

    /// Records disk `i`'s impact `event` in the collision log (a pair only while still due), by
    /// the scenario's disk numbers.
    #[cold]
    fn log_collision(&mut self, i: usize, event: Event) {
        let partner = match event.partner() {
            Some(Partner::Disk(j)) if self.disks.counter[j as usize] != self.events.counter[i] => {
                None
            }
            Some(Partner::Disk(j)) => Some(Partner::Disk(self.map.numbering.id(j as usize) as u32)),
            other => other,
        };
        if let (Some(p), Some(log)) = (partner, self.control.log.as_mut()) {
            let time = self.base.absolute(self.now);
            log.push(Collision::new(time, self.map.numbering.id(i), p));
        }
    }

    /// Disk `i`'s velocity changed: invalidate partners' predictions, watch DUTC, re-predict.
    #[inline]
    pub(super) fn moved(&mut self, i: usize) {
        self.disks.counter[i] = self.disks.counter[i].wrapping_add(1);
        if !self.is_riding(i) {
            let s = self.falling_speed_sq(i);
            self.map.dutc.observe(self.now, s);
        }
        self.predict(i);
    }
}
