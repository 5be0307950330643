//! Rough disks in the engine: the tangential part of each collision (Walton's rule,
//! [`physics::rough`](crate::physics::rough)), applied after the normal part at pair
//! collisions, floor impacts, the side walls and the lid, its energy booked as dissipated. A
//! smooth scene has no laws here and no spins: every call returns at once.

use super::Simulation;
use crate::physics::flight::Flight;
pub(super) use crate::physics::rough::Boundary;

impl<F: Flight> Simulation<F> {
    /// The tangential part of the collision of disks `i` and `j` (separation `(dx, dy)` from
    /// `j` to `i` at contact `distance`, centres' relative velocity `dv` before the normal
    /// impulse `p_n`): the velocities and spins change, the loss is booked. Nothing for smooth
    /// disks, at the cost of one test in the collision (the rule itself is out of line).
    #[inline(always)]
    pub(super) fn rub_pair(
        &mut self,
        i: usize,
        j: usize,
        contact: (f64, f64, f64),
        dv: (f64, f64),
        p_n: f64,
    ) {
        if self.friction.is_some() {
            self.rub_rough_pair(i, j, contact, dv, p_n);
        }
    }

    /// [`rub_pair`](Self::rub_pair) for rough disks.
    #[inline(never)]
    fn rub_rough_pair(
        &mut self,
        i: usize,
        j: usize,
        (dx, dy, distance): (f64, f64, f64),
        dv: (f64, f64),
        p_n: f64,
    ) {
        let Some(laws) = &self.friction else {
            return;
        };
        let n = (dx / distance, dy / distance);
        let k = laws.pair_kick(&self.disks, (i, j), n, dv, p_n);
        if k.j == 0.0 {
            return;
        }
        k.apply(&mut self.disks, i, Some(j), self.now);
        self.tally.flow.dissipated += k.energy_lost;
    }

    /// The tangential part of disk `i`'s impact on `boundary` moving with velocity `wall`
    /// (the floor's; 0 for the others), after the normal part changed the disk's normal
    /// velocity from `before` to now (its normal impulse). Nothing for smooth disks.
    #[inline(always)]
    pub(super) fn rub_boundary(
        &mut self,
        i: usize,
        boundary: Boundary,
        wall: (f64, f64),
        before: (f64, f64),
    ) {
        if self.friction.is_some() {
            self.rub_rough_boundary(i, boundary, wall, before);
        }
    }

    /// [`rub_boundary`](Self::rub_boundary) for rough disks.
    #[inline(never)]
    fn rub_rough_boundary(
        &mut self,
        i: usize,
        boundary: Boundary,
        wall: (f64, f64),
        before: (f64, f64),
    ) {
        let Some(laws) = &self.friction else {
            return;
        };
        let k = laws.boundary_kick(&self.disks, i, boundary, wall, before);
        if k.j == 0.0 {
            return;
        }
        k.apply(&mut self.disks, i, None, self.now);
        self.tally.flow.dissipated += k.energy_lost;
    }
}
