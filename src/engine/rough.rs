//! Rough disks in the engine: the tangential part of each collision (Walton's rule,
//! [`physics::rough`](crate::physics::rough)), applied after the normal part at pair
//! collisions, floor impacts, the side walls and the lid, its energy booked as dissipated. A
//! smooth scene has no laws here and no spins: every call returns at once.

use super::Simulation;
use crate::physics::flight::Flight;
use crate::physics::rough::{kick, Body, Friction, Roughness};

/// The boundary a disk hits, by the normal from it to the disk.
#[derive(Debug, Clone, Copy)]
pub(super) enum Boundary {
    Left,
    Right,
    Lid,
    Floor,
}

impl Boundary {
    fn normal(self) -> (f64, f64) {
        match self {
            Boundary::Left => (1.0, 0.0),
            Boundary::Right => (-1.0, 0.0),
            Boundary::Lid => (0.0, -1.0),
            Boundary::Floor => (0.0, 1.0),
        }
    }

    fn law(self, r: &Roughness) -> Friction {
        match self {
            Boundary::Floor => r.floor,
            _ => r.walls,
        }
    }
}

impl<F: Flight> Simulation<F> {
    /// Disk `i` as one side of a contact.
    fn body(&self, i: usize) -> Body {
        let d = &self.disks;
        Body {
            m: d.mass[i],
            a: d.radius[i],
            q: d.spins.as_ref().map_or(1.0, |s| s.q),
            w: d.spins.as_ref().map_or(0.0, |s| s.omega[i]),
        }
    }

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
        let k = kick(&laws.pair, n, dv, &self.body(i), &self.body(j), p_n);
        if k.j == 0.0 {
            return;
        }
        self.take_kick(i, k.dv_i, k.dw_i);
        self.take_kick(j, k.dv_j, k.dw_j);
        self.tally.flow.dissipated += k.energy_lost;
    }

    /// Disk `i` takes its side of a tangential kick: velocity change `dv`, spin change `dw`.
    fn take_kick(&mut self, i: usize, dv: (f64, f64), dw: f64) {
        let now = self.now;
        let d = &mut self.disks;
        d.motion[i].vx += dv.0;
        d.motion[i].vy += dv.1;
        d.spins
            .as_mut()
            .expect("rough disks have spins")
            .spin(i, now, dw);
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
        let n = boundary.normal();
        let m = &self.disks.motion[i];
        let mass = self.disks.mass[i];
        let p_n = mass * ((m.vx - before.0) * n.0 + (m.vy - before.1) * n.1);
        let dv = (m.vx - wall.0, m.vy - wall.1);
        let k = kick(&boundary.law(laws), n, dv, &self.body(i), &Body::WALL, p_n);
        if k.j == 0.0 {
            return;
        }
        self.take_kick(i, k.dv_i, k.dw_i);
        self.tally.flow.dissipated += k.energy_lost;
    }
}
