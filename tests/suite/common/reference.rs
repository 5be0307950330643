//! A brute-force reference engine, for tests: all pairs, no grid, no neighbour lists, no tree,
//! every disk advanced together from one event to the next. It shares the physics (contact
//! times, collision rule, walls, floor) with the real engine and nothing of its machinery, so
//! agreement between the two checks the grid, masks, DUTC, lazy updates and the event tree.

use vibrobed::engine::{Collision, Partner, Snapshot};
use vibrobed::physics::flight::Flight;
use vibrobed::physics::floor::{Floor, FloorEvent};
use vibrobed::physics::pair::{collide, contact_time};
use vibrobed::physics::rough::{kick, Body, Friction, Roughness};
use vibrobed::physics::walls::{Side, SideBounds, Top};

/// All-pairs event-driven engine with synchronous advance.
#[derive(Debug, Clone)]
pub struct Reference<F: Flight> {
    flight: F,
    time: f64,
    x: Vec<f64>,
    y: Vec<f64>,
    vx: Vec<f64>,
    vy: Vec<f64>,
    radius: Vec<f64>,
    mass: Vec<f64>,
    sides: SideBounds,
    top: Top,
    floor: Option<Floor>,
    restitution: f64,
    /// Rough disks: the tangential laws and each disk's spin.
    rough: Option<(Roughness, Vec<f64>)>,
}

impl<F: Flight> Reference<F> {
    /// Starts from a snapshot (all disks at `snap.time`). The floor's phase must refer to
    /// absolute time 0.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        flight: F,
        snap: &Snapshot,
        radius: &[f64],
        mass: &[f64],
        sides: SideBounds,
        top: Top,
        floor: Option<Floor>,
        restitution: f64,
    ) -> Reference<F> {
        Reference {
            flight,
            time: snap.time,
            x: snap.x.clone(),
            y: snap.y.clone(),
            vx: snap.vx.clone(),
            vy: snap.vy.clone(),
            radius: radius.to_vec(),
            mass: mass.to_vec(),
            sides,
            top,
            floor,
            restitution,
            rough: None,
        }
    }

    /// Makes the disks rough, with the laws `laws` and spins `omega` (the scenario's numbering).
    pub fn with_spins(mut self, laws: Roughness, omega: Vec<f64>) -> Reference<F> {
        self.rough = Some((laws, omega));
        self
    }

    /// Each disk's spin (rough disks).
    pub fn spins(&self) -> Option<&[f64]> {
        self.rough.as_ref().map(|(_, w)| w.as_slice())
    }

    /// Disk `k` as one side of a contact.
    fn body(&self, k: usize) -> Body {
        let (laws, omega) = self.rough.as_ref().expect("rough disks");
        Body {
            m: self.mass[k],
            a: self.radius[k],
            q: laws.inertia_factor,
            w: omega[k],
        }
    }

    /// The tangential part of disk `i`'s impact on a boundary with normal `n` (from it to the
    /// disk) and law `law`, moving with `wall`, after the normal part changed the velocity from
    /// `before`.
    fn rub_boundary(
        &mut self,
        i: usize,
        n: (f64, f64),
        law: impl Fn(&Roughness) -> Friction,
        wall: (f64, f64),
        before: (f64, f64),
    ) {
        let Some((laws, _)) = &self.rough else {
            return;
        };
        let law = law(laws);
        let p_n = self.mass[i] * ((self.vx[i] - before.0) * n.0 + (self.vy[i] - before.1) * n.1);
        let dv = (self.vx[i] - wall.0, self.vy[i] - wall.1);
        let k = kick(&law, n, dv, &self.body(i), &Body::WALL, p_n);
        self.vx[i] += k.dv_i.0;
        self.vy[i] += k.dv_i.1;
        self.rough.as_mut().unwrap().1[i] += k.dw_i;
    }

    fn wrap(&self, mut dx: f64, mut dy: f64) -> (f64, f64) {
        if let SideBounds::Periodic { width } = self.sides {
            dx -= width * (dx / width).round();
        }
        if let Top::Periodic { height } = self.top {
            dy -= height * (dy / height).round();
        }
        (dx, dy)
    }

    /// The next collision: (time from now, disk, partner).
    fn next(&self) -> Option<(f64, usize, Partner)> {
        let n = self.x.len();
        let mut best: Option<(f64, usize, Partner)> = None;
        let mut consider = |dt: f64, i: usize, p: Partner| {
            if best.is_none_or(|b| dt < b.0) {
                best = Some((dt, i, p));
            }
        };
        for i in 0..n {
            for j in i + 1..n {
                let (dx, dy) = self.wrap(self.x[i] - self.x[j], self.y[i] - self.y[j]);
                let s = self.radius[i] + self.radius[j];
                if let Some(dt) = contact_time(
                    dx,
                    dy,
                    self.vx[i] - self.vx[j],
                    self.vy[i] - self.vy[j],
                    s,
                    0.0,
                ) {
                    consider(dt, i, Partner::Disk(j as u32));
                }
            }
            if let Some((dt, side)) = self.sides.impact(self.x[i], self.vx[i], self.radius[i]) {
                consider(
                    dt,
                    i,
                    if side == Side::Left {
                        Partner::Left
                    } else {
                        Partner::Right
                    },
                );
            }
            if let Some(dt) =
                self.top
                    .impact(self.y[i], self.vy[i], self.radius[i], self.flight.g())
            {
                consider(dt, i, Partner::Lid);
            }
            if let Some(floor) = &self.floor {
                if let Some(FloorEvent::Impact(t)) = floor.next_event(
                    self.y[i],
                    self.vy[i],
                    self.radius[i],
                    self.flight.g(),
                    self.time,
                    f64::INFINITY,
                ) {
                    consider(t - self.time, i, Partner::Floor);
                }
            }
        }
        best
    }

    /// Runs every collision before absolute time `until` and returns them in order.
    pub fn run_until(&mut self, until: f64) -> Vec<Collision> {
        let mut log = Vec::new();
        while let Some((dt, i, p)) = self.next() {
            if self.time + dt >= until {
                break;
            }
            for k in 0..self.x.len() {
                let (x, y, vx, vy) = self
                    .flight
                    .advance(self.x[k], self.y[k], self.vx[k], self.vy[k], dt);
                self.x[k] = x;
                self.y[k] = y;
                self.vx[k] = vx;
                self.vy[k] = vy;
            }
            self.time += dt;
            match p {
                Partner::Disk(j) => {
                    let j = j as usize;
                    let (dx, dy) = self.wrap(self.x[i] - self.x[j], self.y[i] - self.y[j]);
                    let imp = collide(
                        dx,
                        dy,
                        self.vx[i] - self.vx[j],
                        self.vy[i] - self.vy[j],
                        self.mass[i],
                        self.mass[j],
                        self.restitution,
                    );
                    let dv = (self.vx[i] - self.vx[j], self.vy[i] - self.vy[j]);
                    self.vx[i] += imp.dvx_i;
                    self.vy[i] += imp.dvy_i;
                    self.vx[j] += imp.dvx_j;
                    self.vy[j] += imp.dvy_j;
                    if let Some((laws, _)) = &self.rough {
                        let n = (dx / imp.distance, dy / imp.distance);
                        let k = kick(
                            &laws.pair,
                            n,
                            dv,
                            &self.body(i),
                            &self.body(j),
                            imp.momentum,
                        );
                        self.vx[i] += k.dv_i.0;
                        self.vy[i] += k.dv_i.1;
                        self.vx[j] += k.dv_j.0;
                        self.vy[j] += k.dv_j.1;
                        let omega = &mut self.rough.as_mut().unwrap().1;
                        omega[i] += k.dw_i;
                        omega[j] += k.dw_j;
                    }
                }
                Partner::Left => {
                    let before = (self.vx[i], self.vy[i]);
                    self.vx[i] = self.sides.bounce(self.vx[i], Side::Left, false);
                    self.rub_boundary(i, (1.0, 0.0), |r| r.walls, (0.0, 0.0), before);
                }
                Partner::Right => {
                    let before = (self.vx[i], self.vy[i]);
                    self.vx[i] = self.sides.bounce(self.vx[i], Side::Right, false);
                    self.rub_boundary(i, (-1.0, 0.0), |r| r.walls, (0.0, 0.0), before);
                }
                Partner::Lid => {
                    let before = (self.vx[i], self.vy[i]);
                    self.vy[i] = self.top.bounce(self.vy[i], false);
                    self.rub_boundary(i, (0.0, -1.0), |r| r.walls, (0.0, 0.0), before);
                }
                Partner::Floor => {
                    let floor = self.floor.as_ref().expect("floor");
                    let before = (self.vx[i], self.vy[i]);
                    let hd = floor.velocity(self.time);
                    self.vy[i] = floor.bounce(self.vy[i], self.time);
                    self.rub_boundary(i, (0.0, 1.0), |r| r.floor, (0.0, hd), before);
                }
            }
            log.push(Collision::new(self.time, i, p));
        }
        log
    }
}
