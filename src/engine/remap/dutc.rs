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
//!
//! One fast disk far above all the others (a disk dropped from 10⁷ diameters) would set `v_max`
//! alone and force a mapping every `margin/(2 v)`: ~2·height/margin mappings during its fall. It
//! is *isolated* instead: left out of `v_max`, it gets a deadline of its own — its clearance
//! above the others' tops, closed at its speed plus theirs. The lists stay complete until the
//! earlier of the two deadlines.

/// The re-mapping deadline and what it is made of.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Dutc {
    margin: f64,
    used: f64,
    /// Constant part of the speed bound.
    vmax: f64,
    /// Growth rate of the bound (g while a disk rides the floor, else 0).
    accel: f64,
    since: f64,
    /// Gap between the isolated disk and every other disk at the mapping (∞ if none).
    iso_clearance: f64,
    /// Falling-frame speed of the isolated disk.
    iso_speed: f64,
    /// Clearance used up to `since`.
    iso_used: f64,
    /// Local time by which the grid must be re-mapped.
    pub deadline: f64,
    /// The lists are kept complete another way (the local re-mapping): speeds do not move the
    /// deadline, which is only when the clock is next re-based.
    #[serde(default)]
    frozen: bool,
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
            iso_clearance: f64::INFINITY,
            iso_speed: 0.0,
            iso_used: 0.0,
            deadline: f64::INFINITY,
            frozen: false,
        };
        d.deadline = d.horizon();
        d
    }

    /// As [`new`](Self::new), with one disk moving at `speed` (left out of `vmax`) isolated by
    /// a gap `clearance` from every other disk.
    pub fn with_isolated(margin: f64, vmax: f64, accel: f64, clearance: f64, speed: f64) -> Dutc {
        let mut d = Dutc::new(margin, vmax, accel);
        d.iso_clearance = clearance;
        d.iso_speed = speed;
        d.deadline = d.horizon();
        d
    }

    /// Margin used between `since` and `now` at the current bound: two disks close in at
    /// `2 v(t)`.
    fn spent(&self, now: f64) -> f64 {
        2.0 * self.vmax * (now - self.since) + self.accel * (now * now - self.since * self.since)
    }

    /// Clearance of the isolated disk used between `since` and `now`: it closes in on another
    /// disk at `iso_speed + v(t)`.
    fn iso_spent(&self, now: f64) -> f64 {
        (self.iso_speed + self.vmax) * (now - self.since)
            + 0.5 * self.accel * (now * now - self.since * self.since)
    }

    /// The time T ≥ since at which `rest` more is used when two disks close in at `w + a·t`:
    /// `½ a (T² − s²) + w (T − s) = rest`.
    fn time_to_use(rest: f64, w: f64, a: f64, s: f64) -> f64 {
        if a > 0.0 {
            let c = rest + 0.5 * a * s * s + w * s;
            2.0 * c / (w + (w * w + 2.0 * a * c).sqrt())
        } else if w > 0.0 {
            s + rest / w
        } else {
            f64::INFINITY
        }
    }

    /// The time T ≥ since at which the rest of the margin (or of the isolated disk's clearance)
    /// is used up.
    fn horizon(&self) -> f64 {
        let s = self.since;
        let lists = Self::time_to_use(
            (self.margin - self.used).max(0.0),
            2.0 * self.vmax,
            2.0 * self.accel,
            s,
        );
        if self.iso_clearance.is_finite() {
            let iso = Self::time_to_use(
                (self.iso_clearance - self.iso_used).max(0.0),
                self.iso_speed + self.vmax,
                self.accel,
                s,
            );
            lists.min(iso)
        } else {
            lists
        }
    }

    /// A deadline that speeds do not move (the local re-mapping keeps the lists complete; the
    /// grid is re-mapped at `deadline` only to re-base the clock).
    pub fn frozen(deadline: f64) -> Dutc {
        let mut d = Dutc::new(0.0, 0.0, 0.0);
        d.deadline = deadline;
        d.frozen = true;
        d
    }

    /// Largest speed the deadline assumes (its constant part).
    pub fn vmax(&self) -> f64 {
        self.vmax
    }

    fn rebound(&mut self, now: f64, vmax: f64, accel: f64) {
        self.used += self.spent(now);
        if self.iso_clearance.is_finite() {
            self.iso_used += self.iso_spent(now);
        }
        self.since = now;
        self.vmax = vmax;
        self.accel = accel;
        // Faster bounds only bring the deadline forward; the minimum keeps round-off from
        // moving it back (predictions leave out contacts after it).
        self.deadline = self.horizon().min(self.deadline);
    }

    /// A disk was moved by `d` at once (a rule of the resting contacts): two disks may be `d`
    /// closer than their speeds allow.
    pub fn displaced(&mut self, now: f64, d: f64) {
        if self.frozen {
            return;
        }
        self.used += d;
        self.deadline = self.horizon().max(now).min(self.deadline);
    }

    /// A disk now moves at speed √`speed_sq` (falling frame); tightens the deadline if it is a
    /// new maximum.
    #[inline]
    pub fn observe(&mut self, now: f64, speed_sq: f64) {
        if self.frozen {
            return;
        }
        let bound = self.vmax + self.accel * now;
        if speed_sq > bound * bound {
            let v = speed_sq.sqrt() - self.accel * now;
            self.rebound(now, v.max(self.vmax), self.accel);
        }
    }

    /// A disk starts riding the floor with falling-frame speed at most `speed + g·t` from now on.
    pub fn ride(&mut self, now: f64, speed: f64, g: f64) {
        if self.frozen {
            return;
        }
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
    fn an_isolated_disk_has_a_deadline_of_its_own() {
        // Lists: 1/(2·1) = 0.5; isolated: clearance 100 closed at 999 + 1 → 0.1.
        let d = Dutc::with_isolated(1.0, 1.0, 0.0, 100.0, 999.0);
        assert!((d.deadline - 0.1).abs() < 1e-15);
        // Far enough: the lists decide.
        let d = Dutc::with_isolated(1.0, 1.0, 0.0, 1e4, 999.0);
        assert_eq!(d.deadline, 0.5);
        // A faster disk at t = 0.05 (half the clearance used): 50 left at 999 + 9 → 0.05 + 50/1008.
        let mut d = Dutc::with_isolated(1.0, 1.0, 0.0, 100.0, 999.0);
        d.observe(0.05, 81.0);
        let lists: f64 = 0.05 + 0.9 / 18.0;
        assert!((d.deadline - lists.min(0.05 + 50.0 / 1008.0)).abs() < 1e-15);
        // With a rider: ½·2·T² + 1000 T = 100.
        let d = Dutc::with_isolated(1e9, 1.0, 2.0, 100.0, 999.0);
        let t = (-1000.0 + (1e6f64 + 400.0).sqrt()) / 2.0;
        assert!((d.deadline - t).abs() < 1e-12, "{} vs {t}", d.deadline);
    }

    #[test]
    fn a_disk_moved_at_once_uses_the_margin() {
        // Margin 1 at speeds 1: deadline 0.5. At t = 0.1 a disk moves by 0.2 at once: 0.4 of
        // the margin is used, 0.6 left at 2 → 0.4.
        let mut d = Dutc::new(1.0, 1.0, 0.0);
        d.displaced(0.1, 0.2);
        assert!((d.deadline - 0.4).abs() < 1e-15, "{}", d.deadline);
        // More than the margin left: re-map now, never in the past.
        d.displaced(0.3, 1.0);
        assert_eq!(d.deadline, 0.3);
        // The local re-mapping's frozen deadline does not move.
        let mut f = Dutc::frozen(7.0);
        f.displaced(1.0, 5.0);
        assert_eq!(f.deadline, 7.0);
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
