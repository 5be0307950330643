//! DUTC, Isobe's Dynamical Upper Time Cut-off: when the grid must be re-mapped.
//!
//! At a mapping every pair missing from the neighbour lists is at least `r_NLmin = D·l_g` apart;
//! it can touch only after closing the gap `margin = r_NLmin − 2 a_max`, and two disks close in at
//! most `2 v_max` per unit time. So the lists stay complete until `margin/(2 v_max)`. When an event
//! raises the largest speed, the margin already used (at the old bound) is booked and the rest is
//! spent at the new one. Speeds are measured in the frame falling with gravity, where every flying
//! disk moves straight between collisions; relative distances are the same in every frame.
//!
//! A disk riding the floor is not in free fall: in the falling frame its speed grows like
//! `|vx| + max|h'| + g t`. While any disk rides, the bound is `v(t) = v_c + g t` (t since the
//! mapping), and the margin used is its integral.

/// The re-mapping deadline and what it is made of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dutc {
    margin: f64,
    used: f64,
    /// Constant part of the speed bound.
    vmax: f64,
    /// Growth rate of the bound (g while a disk rides the floor, else 0).
    accel: f64,
    since: f64,
    /// Local time by which the grid must be re-mapped.
    pub deadline: f64,
}

impl Dutc {
    /// After a mapping at local time 0 with the given margin, largest speed, and growth rate of
    /// the speed bound (g if a disk rides the floor, else 0).
    pub fn new(margin: f64, vmax: f64, accel: f64) -> Dutc {
        let mut d = Dutc {
            margin,
            used: 0.0,
            vmax,
            accel,
            since: 0.0,
            deadline: f64::INFINITY,
        };
        d.deadline = d.horizon();
        d
    }

    /// Margin used between `since` and `now` at the current bound.
    fn spent(&self, now: f64) -> f64 {
        2.0 * self.vmax * (now - self.since) + self.accel * (now * now - self.since * self.since)
    }

    /// The time T ≥ since at which the rest of the margin is used up.
    fn horizon(&self) -> f64 {
        let rest = (self.margin - self.used).max(0.0);
        let s = self.since;
        if self.accel > 0.0 {
            // accel·T² + 2 v T = rest + accel·s² + 2 v s
            let c = rest + self.accel * s * s + 2.0 * self.vmax * s;
            c / (self.vmax + (self.vmax * self.vmax + self.accel * c).sqrt())
        } else if self.vmax > 0.0 {
            s + rest / (2.0 * self.vmax)
        } else {
            f64::INFINITY
        }
    }

    /// Largest speed the deadline assumes (its constant part).
    pub fn vmax(&self) -> f64 {
        self.vmax
    }

    fn rebound(&mut self, now: f64, vmax: f64, accel: f64) {
        self.used += self.spent(now);
        self.since = now;
        self.vmax = vmax;
        self.accel = accel;
        self.deadline = self.horizon();
    }

    /// A disk now moves at speed √`speed_sq` (falling frame); tightens the deadline if it is a
    /// new maximum.
    #[inline]
    pub fn observe(&mut self, now: f64, speed_sq: f64) {
        let bound = self.vmax + self.accel * now;
        if speed_sq > bound * bound {
            let v = speed_sq.sqrt() - self.accel * now;
            self.rebound(now, v.max(self.vmax), self.accel);
        }
    }

    /// A disk starts riding the floor with falling-frame speed at most `speed + g·t` from now on.
    pub fn ride(&mut self, now: f64, speed: f64, g: f64) {
        if self.accel < g || speed > self.vmax {
            self.rebound(now, self.vmax.max(speed), self.accel.max(g));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deadline_spends_the_margin_once() {
        let mut d = Dutc::new(1.0, 1.0, 0.0);
        assert_eq!(d.deadline, 0.5);
        // At t = 0.25 half the margin is used; a speed of 2 leaves 0.5/(2·2) = 0.125.
        d.observe(0.25, 4.0);
        assert!((d.deadline - 0.375).abs() < 1e-15);
        d.observe(0.3, 1.0); // slower: no change
        assert!((d.deadline - 0.375).abs() < 1e-15);
        assert_eq!(Dutc::new(1.0, 0.0, 0.0).deadline, f64::INFINITY);
    }

    #[test]
    fn riding_bound_grows_with_gravity() {
        // v(t) = 1 + 2t: margin 2·(T + T²) = 4 → T = 1.
        let d = Dutc::new(4.0, 1.0, 2.0);
        assert!((d.deadline - 1.0).abs() < 1e-15);
        // Riding starts at 0.5 with g = 2 on a bound of 1: 2·0.5 = 1 used, then
        // 2(T − 0.5) + 2(T² − 0.25) = 3 → T² + T − 2.25 = 0.
        let mut d = Dutc::new(4.0, 1.0, 0.0);
        d.ride(0.5, 0.5, 2.0);
        let t = (-1.0 + (1.0f64 + 9.0).sqrt()) / 2.0;
        assert!((d.deadline - t).abs() < 1e-14, "{} vs {t}", d.deadline);
    }
}
