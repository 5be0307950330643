//! Re-mapping (Isobe's DUTC): at the deadline every disk is brought to the present, the clock
//! is re-based, the grid and neighbour lists are rebuilt and every event re-predicted.

pub mod dutc;
pub mod numbering;
pub mod shells;

use crate::engine::images::Images;
use crate::engine::Simulation;
use crate::error::Result;
use crate::physics::disks::Disks;
use crate::physics::flight::Flight;
use crate::physics::walls::Top;
use dutc::Dutc;

impl<F: Flight> Simulation<F> {
    /// Brings every disk to the present, re-bases the clock to it, re-maps the grid, rebuilds
    /// the neighbour lists and re-predicts every event.
    pub(in crate::engine) fn remap(&mut self) -> Result<()> {
        let now = self.now;
        let n = self.disks.len();
        if n == 0 {
            // Every disk has left: nothing to map, no deadline.
            self.map.dutc = Dutc::frozen(f64::INFINITY);
            self.schedule_entry();
            return Ok(());
        }
        // Every list is rebuilt below: rows can go now, before renumbering takes memory.
        self.map.lists.release();
        for i in 0..n {
            self.bring(i, now);
            self.disks.motion[i].t = 0.0;
            self.wrap_position(i);
        }
        self.renumber_if_due();
        self.base.advance(now);
        self.now = 0.0;
        if self.pool.is_some() {
            self.schedule_entry();
        }
        self.restitution.rebase(now);
        if let Some(spins) = &mut self.disks.spins {
            spins.rebase(now);
        }
        if let Some(floor) = &mut self.bounds.floor {
            floor.rebase(now);
        }
        self.rest.riders.rebase(now);
        // Pairs farther apart than contact + margin cannot meet before the DUTC deadline: the
        // lists keep only the closer ones (the mask guarantees every closer disk is seen).
        let (disks, geometry) = (&self.disks, &self.map.geometry);
        let cell = |i: usize| geometry.cell_of(disks.motion[i].x, disks.motion[i].y);
        let (images, margin) = (self.bounds.images, self.map.margin);
        let near = |i: usize, j: usize| near_at_mapping(disks, images, margin, i, j);
        // Under the local re-mapping the lists change one at a time from here: rows with room,
        // which keep the pairs found for the predictions below where memory allows.
        if self.map.shells.is_some() {
            self.map.lists.in_rows(n < shells::LEAN_LISTS_FROM);
        }
        self.map
            .cells
            .rebuild(geometry, &self.map.mask, n, cell, &mut self.map.lists, near)?;
        let lift = self
            .bounds
            .floor
            .as_ref()
            .map_or(0.0, |f| f.drive().peak_velocity());
        let speed = |i: usize| {
            if self.is_riding(i) {
                self.riding_speed_bound(i, self.disks.motion[i].vx) + lift
            } else {
                self.falling_speed_sq(i).sqrt()
            }
        };
        // The fastest disk, and the largest speed of the others.
        let (mut fastest, mut v1, mut v2) = (0, 0.0f64, 0.0f64);
        for i in 0..n {
            let v = speed(i);
            if v > v1 {
                (fastest, v1, v2) = (i, v, v1);
            } else {
                v2 = v2.max(v);
            }
        }
        let accel = if self.rest.riders.any() {
            self.flight.g()
        } else {
            0.0
        };
        self.map.dutc = match self.isolation(fastest, v1, v2) {
            Some(clearance) => Dutc::with_isolated(self.map.margin, v2, accel, clearance, v1),
            None => Dutc::new(self.map.margin, v1, accel),
        };
        if self.map.shells.is_some() {
            // Local re-mapping: the grid is next re-mapped only to re-base the clock, long
            // after the published deadline.
            self.anchor_all();
            self.map.dutc = Dutc::frozen(64.0 * self.map.dutc.deadline);
        }
        self.predict_all();
        self.map.lists.drop_halves();
        self.tally.counts.rebuild += 1;
        Ok(())
    }

    /// At a mapping (every disk at the present): `true` if disks `i` and `j` are close enough
    /// to meet before the DUTC deadline, contact plus the list margin (the lists keep only
    /// such pairs).
    #[inline(always)]
    pub(in crate::engine) fn near_at_mapping(&self, i: usize, j: usize) -> bool {
        near_at_mapping(&self.disks, self.bounds.images, self.map.margin, i, j)
    }

    /// At a mapping: the half of disk `i`'s list found from its own half mask (each listed
    /// pair once over all disks, in the order the lists were built), into `out`, for lists that
    /// keep no half lists (the local re-mapping's rows: found again from the cells rather than
    /// held beside the rows).
    pub(in crate::engine) fn find_half_list(&self, i: usize, out: &mut Vec<u32>) {
        out.clear();
        let m = &self.disks.motion[i];
        let cell = self.map.geometry.cell_of(m.x, m.y);
        self.map
            .cells
            .gather_half(&self.map.geometry, &self.map.mask, i, cell, out);
        out.retain(|&j| self.near_at_mapping(i, j as usize));
    }

    /// At a mapping: the gap between flying disk `f` (speed `v`) and every other disk if `f` is
    /// above all of them by more than the list margin and faster than all of them (`others` is
    /// their largest speed), so that it can get a DUTC deadline of its own; `None` otherwise.
    pub(in crate::engine) fn isolation(&self, f: usize, v: f64, others: f64) -> Option<f64> {
        let n = self.disks.len();
        let fast = n > 1 && !self.is_riding(f) && v > others;
        if !fast || matches!(self.bounds.top, Top::Periodic { .. }) {
            return None;
        }
        let top = (0..n)
            .filter(|&j| j != f)
            .map(|j| self.disks.motion[j].y + self.disks.radius[j])
            .fold(f64::NEG_INFINITY, f64::max);
        let clearance = self.disks.motion[f].y - self.disks.radius[f] - top;
        (clearance > self.map.margin).then_some(clearance)
    }
}

/// At a mapping: `true` if disks `i` and `j` are within contact plus `margin` (see
/// [`Simulation::near_at_mapping`]).
#[inline(always)]
fn near_at_mapping(disks: &Disks, images: Images, margin: f64, i: usize, j: usize) -> bool {
    let (mi, mj) = (&disks.motion[i], &disks.motion[j]);
    let (dx, dy) = images.wrap(mi.x - mj.x, mi.y - mj.y);
    let reach = disks.radius[i] + disks.radius[j] + margin;
    dx * dx + dy * dy <= reach * reach
}
