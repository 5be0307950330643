//! Rough disks in the engine: the tangential part of each collision (Walton's rule,
//! [`physics::rough`](crate::physics::rough)), applied after the normal part at pair
//! collisions, floor impacts, the side walls and the lid, its energy booked as dissipated; and
//! rough disks at rest, which do not turn against what holds them (see
//! [`hold_spin`](Simulation::hold_spin)). A smooth scene has no laws here and no spins: every
//! call returns at once.

use super::Simulation;
use crate::engine::rest::riders::RIGHT_WALL;
use crate::physics::flight::Flight;
pub(super) use crate::physics::rough::Boundary;
use crate::physics::rough::{fixed_kick, friction_holds, Body, Friction};

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
        let law = boundary.law(laws);
        self.rub_fixed(i, &law, boundary.normal(), wall, before, &Body::WALL);
    }

    /// The tangential part of flying disk `k`'s bounce off disk `s` held at rest (it does not
    /// give: see [`meet_held`](Self::meet_held)), with unit normal `n` from `s` to `k`, `s`
    /// moving with velocity `held` (the floor's), `k`'s velocity `before` the normal part. `s`
    /// turns as its rest allows (see [`hold_spin`](Self::hold_spin)); nothing for smooth disks.
    pub(in crate::engine) fn rub_held(
        &mut self,
        k: usize,
        s: usize,
        n: (f64, f64),
        held: (f64, f64),
        before: (f64, f64),
    ) {
        let Some(laws) = &self.friction else {
            return;
        };
        let law = laws.pair;
        let s = Body {
            m: f64::INFINITY,
            ..Body::disk(&self.disks, s)
        };
        self.rub_fixed(k, &law, n, held, before, &s);
    }

    /// The tangential part of disk `i`'s impact on a body `other` that does not give (a wall, or
    /// a disk held at rest), with unit normal `n` from it to the disk, moving with velocity
    /// `wall`, after the normal part changed the disk's velocity from `before` (its normal
    /// impulse). The loss is booked as dissipated, and the work of the moving body (the
    /// floor's, which carries it) as injected.
    fn rub_fixed(
        &mut self,
        i: usize,
        law: &Friction,
        n: (f64, f64),
        wall: (f64, f64),
        before: (f64, f64),
        other: &Body,
    ) {
        let mass = self.disks.mass[i];
        let k = fixed_kick(law, &self.disks, i, (n, wall, before), other);
        if k.j == 0.0 {
            return;
        }
        k.apply(&mut self.disks, i, None, self.now);
        self.tally.flow.dissipated += k.energy_lost;
        let work = mass * (wall.0 * k.dv_i.0 + wall.1 * k.dv_i.1);
        if work != 0.0 {
            self.tally.flow.injected += work;
            self.tally.flow.floor_impulse += mass * k.dv_i.1;
        }
    }

    /// Disk `i`, held by a rest rule (at rest on the floor or on disks at rest, or stopped in
    /// a slot), stops turning against what holds it: on a rough floor it rolls, `ω = −v_x/a`;
    /// elsewhere, among rough disks, it turns no more, `ω = 0` (static friction: the slip a
    /// spin would make at a contact at rest is undone at once, as the sliding speeds are by
    /// the rest rules; a disk held with a spin would drive what touches it like a belt). The
    /// rotational energy given up is booked as dissipated. Where neither the floor under it
    /// nor the pair contacts are rough, nothing holds the spin: it keeps it.
    #[inline(always)]
    pub(in crate::engine) fn hold_spin(&mut self, i: usize) {
        if self.friction.is_some() {
            self.hold_rough_spin(i);
        }
    }

    /// [`hold_spin`](Self::hold_spin) for rough disks.
    #[inline(never)]
    fn hold_rough_spin(&mut self, i: usize) {
        self.rest.riders.set_slide(i, None);
        let Some(laws) = &self.friction else {
            return;
        };
        let on_floor = self.is_riding(i) && self.rest.riders.on_floor(i);
        let a = self.disks.radius[i];
        let w = if on_floor && !laws.floor.is_smooth() {
            -self.disks.motion[i].vx / a
        } else if !laws.pair.is_smooth() {
            0.0
        } else {
            return;
        };
        let (now, mass) = (self.now, self.disks.mass[i]);
        let spins = self.disks.spins.as_mut().expect("rough disks have spins");
        let w0 = spins.omega[i];
        if w != w0 {
            self.tally.flow.dissipated += 0.5 * spins.q * mass * a * a * (w0 * w0 - w * w);
            spins.spin(i, now, w - w0);
        }
    }

    /// The floor's law when it is rough with a Coulomb cap (a disk on it slides until it
    /// rolls); `None` otherwise.
    pub(in crate::engine) fn floor_friction(&self) -> Option<Friction> {
        let law = self.friction.as_ref()?.floor;
        (!law.is_smooth() && law.mu.is_finite()).then_some(law)
    }

    /// Disk `i` has just come to rest on a rough floor (or, riding it, bounced off a wall),
    /// its contact point slipping at `s = v_x + a ω`. With a Coulomb cap it slides until it
    /// rolls, exactly in time ([`physics::slide`](crate::physics::slide)): the slide's end is
    /// its event. Without a cap (β alone), the contact sticks at once: it rolls on at
    /// `v_x − s q/(1 + q)` (angular momentum about the contact point kept), the loss booked.
    pub(in crate::engine) fn slide_on_floor(&mut self, i: usize) {
        let Some(laws) = &self.friction else {
            return;
        };
        let law = laws.floor;
        if law.is_smooth() {
            return;
        }
        let spins = self.disks.spins.as_ref().expect("rough disks have spins");
        let (a, q) = (self.disks.radius[i], spins.q);
        let slip = self.disks.motion[i].vx + a * spins.omega[i];
        if law.mu.is_finite() {
            let floor = self.bounds.floor.as_ref().expect("riders need a floor");
            let (now, g) = (self.now, self.flight.g());
            let ride_end = floor.ride_end(now, g).map(|(t, _)| t);
            let slide = crate::physics::slide::slide_from(
                slip,
                law.mu,
                q,
                g,
                now,
                ride_end,
                floor.drive().peak_velocity(),
                |t| floor.ride(t).1,
            );
            self.rest.riders.set_slide(i, slide);
            if slide.is_some() {
                let v_end = self.disks.motion[i].vx - slip * q / (1.0 + q);
                let lift = floor.drive().peak_velocity();
                self.map.dutc.ride(now, v_end.abs() + lift, g);
                return;
            }
        }
        self.roll_at_once(i);
    }

    /// Disk `i`, riding a rough floor, stops slipping at once: it rolls on at
    /// `v_x − s q/(1 + q)` (the friction impulse that ends a slip, whatever its history: the
    /// angular momentum about the contact point is kept), the loss booked.
    pub(in crate::engine) fn roll_at_once(&mut self, i: usize) {
        let spins = self.disks.spins.as_ref().expect("rough disks have spins");
        let (a, q) = (self.disks.radius[i], spins.q);
        let m = &mut self.disks.motion[i];
        let slip = m.vx + a * spins.omega[i];
        let vx = m.vx - slip * q / (1.0 + q);
        self.tally.flow.dissipated += 0.5 * self.disks.mass[i] * (m.vx * m.vx - vx * vx);
        m.vx = vx;
        self.hold_spin(i);
    }

    /// Sliding disk `i` brought from its time stamp to `t`, where its state is `(x, v_x)`: its
    /// spin follows the friction's torque (`δω = δv_x/(q a)`, the orientation `δx/(q a)` off its
    /// free turn), and the kinetic energy the friction took is booked as dissipated.
    pub(in crate::engine) fn bring_slide(&mut self, i: usize, t: f64, (x, vx): (f64, f64)) {
        let m = self.disks.motion[i];
        let (a, mass) = (self.disks.radius[i], self.disks.mass[i]);
        let spins = self.disks.spins.as_mut().expect("rough disks have spins");
        let qa = spins.q * a;
        let (dv, dx) = (vx - m.vx, x - m.x - m.vx * (t - m.t));
        let (w0, w1) = (spins.omega[i], spins.omega[i] + dv / qa);
        spins.phase[i] += dx / qa;
        spins.spin(i, t, dv / qa);
        self.tally.flow.dissipated +=
            0.5 * mass * ((m.vx * m.vx - vx * vx) + spins.q * a * a * (w0 * w0 - w1 * w1));
    }

    /// Disk `i`'s slide ends (its event): brought to now it rolls, `ω = −v_x/a` (the slip left
    /// is round-off, its energy booked), and its path is a line again.
    pub(in crate::engine) fn end_slide(&mut self, i: usize) {
        self.bring(i, self.now);
        self.tally.counts.slide_end += 1;
        self.hold_spin(i);
        self.stop_if_slow(i);
        self.moved(i);
    }

    /// Disk `i`, at rest on the floor and rolling, stops if slower than its sleep speed (as a
    /// disk coming to rest on the floor does).
    pub(in crate::engine) fn stop_if_slow(&mut self, i: usize) {
        if self.rest.resting_contacts && self.disks.motion[i].vx.abs() < self.sleep_speed(i) {
            self.stop_sliding(i);
        }
    }

    /// Two of the contacts of a disk at rest (`normals`: support code, unit normal from the
    /// support to the disk) on which static friction holds it under its weight, though their
    /// normals do not bracket the vertical: a disk on a slope of rough disks, or against a
    /// rough wall ([`friction_holds`]). `None` for smooth disks, or where no pair holds.
    pub(in crate::engine) fn held_by_friction(
        &self,
        normals: &[(u32, f64, f64)],
    ) -> Option<[u32; 2]> {
        let laws = self.friction.as_ref()?;
        let mu = |code: u32| {
            let law = if code < RIGHT_WALL {
                laws.pair
            } else {
                laws.walls
            };
            if law.is_smooth() {
                0.0
            } else {
                law.mu
            }
        };
        normals.iter().enumerate().find_map(|(k, &(c1, x1, y1))| {
            normals[k + 1..].iter().find_map(|&(c2, x2, y2)| {
                friction_holds((x1, y1), (x2, y2), mu(c1), mu(c2)).then_some([c1, c2])
            })
        })
    }
}
