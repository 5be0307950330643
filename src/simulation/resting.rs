//! Resting contacts between disks: a disk that lands gently in a stable place on disks at rest
//! comes to rest on them and moves with the floor; a support that moves releases what rests on it.
//!
//! Without this, a disk resting on a disk that rides the floor keeps bouncing with the smallest
//! rebound ([`PAIR_REST_HEIGHT`]), about 500 times per unit time, and a bed at rest costs
//! millions of events per unit time. The model is the pair analogue of the rest on the floor:
//!
//! - **Coming to rest.** A flying disk `k` hits a riding disk `s` that is pressed onto it
//!   (`g + h'' > 0`, `k` above `s`). If its normal rebound `e·|u|` and its sliding speed along the
//!   contact are both below the smallest rebound `√(2·press·PAIR_REST_HEIGHT·a)`, and its weight is
//!   carried — by `s` straight below it (contact normal vertical to [`VERTICAL`]), or by supports
//!   on both sides of the vertical (disks at rest or side walls touching it to within
//!   [`TOUCH`] radii) — then `k` takes `s`'s velocity and rides: `y = h(t) + lift`, moving
//!   horizontally with `s`. Its relative kinetic energy is booked as dissipated and the change
//!   of its absolute kinetic energy beyond that as work of the floor (the floor carries the
//!   stack). A disk balanced on one disk is an unstable equilibrium; freezing it when the
//!   normal is vertical to 10⁻⁹ suppresses a fall that would take ~ln(10⁹)·√(d/g) to develop.
//! - **Leaving rest.** A resting disk leaves when it is hit, hits a side wall, is thrown off or
//!   kicked by the floor (as riders do), or when its supports slide apart by [`TOUCH`] radii
//!   (an `unmount` event). Whatever rests on a disk that leaves is released at the same moment,
//!   recursively, with its current velocity: it then falls onto whatever is below and, if that
//!   is at rest and the place is stable, comes to rest again at once.

use super::riders::{LEFT_WALL, NO_DISK, RIGHT_WALL};
use super::Simulation;
use crate::dynamics::Flight;
use crate::error::Result;
use crate::locals::floor::PAIR_REST_HEIGHT;
use crate::locals::{SideBounds, Top};

/// A contact normal within this of the vertical (|n_x| ≤ `VERTICAL`) carries a disk alone.
pub const VERTICAL: f64 = 1e-9;

/// A support touches a disk when their gap is at most `TOUCH` radii of the resting disk; a
/// resting disk leaves its supports when a gap grows beyond twice that.
pub const TOUCH: f64 = 10.0 * PAIR_REST_HEIGHT;

impl<F: Flight> Simulation<F> {
    /// Flying disk `k` lands on riding disk `s` (both brought to now) with restitution `e`,
    /// pressed together so that the smallest rebound is `min_rebound > 0`. Comes to rest on
    /// `s` (and returns `true`) if the landing is gentle and the place is stable.
    pub(super) fn try_rest_on(
        &mut self,
        k: usize,
        s: usize,
        e: f64,
        min_rebound: f64,
    ) -> Result<bool> {
        let (mk, ms) = (self.disks.motion[k], self.disks.motion[s]);
        let (dx, dy) = self.wrap(mk.x - ms.x, mk.y - ms.y);
        let dist = (dx * dx + dy * dy).sqrt();
        let (nx, ny) = (dx / dist, dy / dist);
        let (dvx, dvy) = (mk.vx - ms.vx, mk.vy - ms.vy);
        let u = dvx * nx + dvy * ny;
        let slide = (dvy * nx - dvx * ny).abs();
        if -e * u > min_rebound || slide > min_rebound {
            return Ok(false);
        }
        let Some(supports) = self.stable_supports(k, s) else {
            return Ok(false);
        };
        let floor = self.floor.as_ref().expect("riders need a floor");
        let now = self.now;
        let (h, hd) = floor.ride(now);
        // Carried at s's velocity into a wall or a disk it touches, k is squeezed: no rest.
        if self.squeezed(k, ms.vx, hd) {
            return Ok(false);
        }
        if let Top::Lid { height, .. } = self.top {
            if mk.y + self.disks.radius[k] + 2.0 * floor.amplitude >= height {
                return Ok(false); // the stack could be pushed into the lid
            }
        }
        let lift_speed = floor.max_speed();
        self.check_contact(k, s, dist)?;
        if !self.riders.mount_on_disks(k, mk.y - h, supports) {
            return Ok(false);
        }
        let mass = self.disks.mass[k];
        let relative = 0.5 * mass * (dvx * dvx + (mk.vy - hd).powi(2));
        self.flow.dissipated += relative;
        self.flow.injected +=
            0.5 * mass * (ms.vx * ms.vx + hd * hd - mk.vx * mk.vx - mk.vy * mk.vy) + relative;
        // The disks at rest below it are held by the floor, which takes the landing.
        self.flow.floor_impulse += mass * (hd - mk.vy);
        let m = &mut self.disks.motion[k];
        m.vx = ms.vx;
        m.vy = hd;
        self.virial += dist * mass * -u;
        self.counts.pair += 1;
        self.counts.rest += 1;
        self.dutc
            .ride(now, ms.vx.abs() + lift_speed, self.flight.g());
        self.moved(k);
        // `s` did not change: only its own event (this one, if it was its) needs renewing.
        self.predict(s);
        Ok(true)
    }

    /// What carries flying disk `k` (at now) if it rests on riding disk `hit`: `hit` alone if it
    /// is straight below, else one support on each side of the vertical (riding disks touching
    /// `k`, or side walls); `None` if `k` would slide or roll off.
    fn stable_supports(&self, k: usize, hit: usize) -> Option<[u32; 2]> {
        let now = self.now;
        let (xk, yk, _, _) = self.state_at(k, now);
        let ak = self.disks.radius[k];
        let touch = TOUCH * ak;
        // Supports pushing k towards +x (below-left of it) and towards −x (below-right).
        let mut from_left = None;
        let mut from_right = None;
        let others = self
            .lists
            .of(k)
            .iter()
            .map(|&c| c as usize)
            .filter(|&c| c != hit && self.is_riding(c));
        for c in std::iter::once(hit).chain(others) {
            let (xc, yc, _, _) = self.state_at(c, now);
            let (dx, dy) = self.wrap(xk - xc, yk - yc);
            let dist = (dx * dx + dy * dy).sqrt();
            if dist - (ak + self.disks.radius[c]) > touch {
                continue;
            }
            let (nx, ny) = (dx / dist, dy / dist);
            if ny < -VERTICAL {
                continue; // above k: carries nothing
            }
            if nx.abs() <= VERTICAL && ny > 0.0 {
                if c == hit {
                    return Some([c as u32, NO_DISK]);
                }
                continue;
            }
            if nx > 0.0 {
                from_left.get_or_insert(c as u32);
            } else {
                from_right.get_or_insert(c as u32);
            }
        }
        if let SideBounds::Walls { width, .. } = self.sides {
            if xk - ak <= touch {
                from_left.get_or_insert(LEFT_WALL);
            }
            if width - xk - ak <= touch {
                from_right.get_or_insert(RIGHT_WALL);
            }
        }
        Some([from_left?, from_right?])
    }

    /// Whether disk `k` (at now), given the velocity `(vx, vy)`, would move into a side wall or a
    /// disk it touches (within [`TOUCH`] radii), other than a flying disk above its centre. Such a
    /// disk, pressed onto k, gets the floor of the rebound and leaves; a wall, a disk at rest, or
    /// a flying disk beside or below would push k off its supports at once, k would come to rest
    /// again, and so on in zero time.
    fn squeezed(&self, k: usize, vx: f64, vy: f64) -> bool {
        let now = self.now;
        let (xk, yk, _, _) = self.state_at(k, now);
        let ak = self.disks.radius[k];
        let touch = TOUCH * ak;
        if let SideBounds::Walls { width, .. } = self.sides {
            if (vx < 0.0 && xk - ak <= touch) || (vx > 0.0 && width - xk - ak <= touch) {
                return true;
            }
        }
        self.lists.of(k).iter().any(|&c| {
            let c = c as usize;
            let (xc, yc, vxc, vyc) = self.state_at(c, now);
            let (dx, dy) = self.wrap(xk - xc, yk - yc);
            let dist = (dx * dx + dy * dy).sqrt();
            (dy >= 0.0 || self.is_riding(c))
                && dist - (ak + self.disks.radius[c]) <= touch
                && dx * (vx - vxc) + dy * (vy - vyc) < 0.0
        })
    }

    /// When resting disk `k` leaves its supports because they slide apart (a gap beyond
    /// 2·[`TOUCH`] radii); infinity if they move together.
    pub(super) fn unmount_time(&self, k: usize) -> f64 {
        let now = self.now;
        let (xk, yk, vxk, _) = self.state_at(k, now);
        let ak = self.disks.radius[k];
        let reach = 2.0 * TOUCH * ak;
        let mut t = f64::INFINITY;
        for s in self.riders.supports(k) {
            let dt = match s {
                NO_DISK => continue,
                LEFT_WALL if vxk > 0.0 => (reach - (xk - ak)).max(0.0) / vxk,
                RIGHT_WALL if vxk < 0.0 => (reach - (self.sides.width() - xk - ak)).max(0.0) / -vxk,
                LEFT_WALL | RIGHT_WALL => continue,
                s => {
                    let s = s as usize;
                    let (xs, ys, vxs, _) = self.state_at(s, now);
                    let dvx = vxk - vxs;
                    if dvx == 0.0 {
                        continue;
                    }
                    // Both move with the floor: the separation changes along x only.
                    let (dx, dy) = self.wrap(xk - xs, yk - ys);
                    let r = ak + self.disks.radius[s] + reach;
                    let c = dx * dx + dy * dy - r * r;
                    if c >= 0.0 {
                        0.0
                    } else {
                        let b = dx * dvx;
                        let dv2 = dvx * dvx;
                        (-b + (b * b - dv2 * c).sqrt()) / dv2
                    }
                }
            };
            t = t.min(now + dt);
        }
        t
    }

    /// Riding disk `i` is about to change velocity: if it rests on disks, it leaves them.
    pub(super) fn unsettle(&mut self, i: usize) {
        if self.riders.is_riding(i) && !self.riders.on_floor(i) {
            self.riders.dismount(i);
        }
    }

    /// Releases, recursively, every disk resting on disk `s` (which has just moved or left
    /// rest), each with its current velocity, or with vertical velocity `vy` if given.
    pub(super) fn release_carried(&mut self, s: usize, vy: Option<f64>) {
        if !self.riders.carries_any(s) {
            return;
        }
        let now = self.now;
        let mut stack = std::mem::take(&mut self.releasing);
        stack.push(s as u32);
        while let Some(c) = stack.pop() {
            for k in self.riders.take_carried(c as usize) {
                if k == NO_DISK {
                    continue;
                }
                let k = k as usize;
                self.bring(k, now);
                self.riders.dismount(k);
                if let Some(v) = vy {
                    self.set_vy(k, v);
                }
                self.moved(k);
                stack.push(k as u32);
            }
        }
        self.releasing = stack;
    }
}
