//! DUTC, Isobe's Dynamical Upper Time Cut-off: when the grid must be re-mapped.
//!
//! At a mapping every pair missing from the neighbour lists is at least `r_NLmin = D·l_g` apart;
//! it can touch only after closing the gap `margin = r_NLmin − 2 a_max`, and two disks close in at
//! most `2 v_max` per unit time. So the lists stay complete until `margin/(2 v_max)`. When an event
//! raises the largest speed, the margin already used (at the old bound) is booked and the rest is
//! spent at the new one. Speeds are measured in the frame falling with gravity, where every disk
//! moves straight between collisions; relative distances are the same in every frame.

/// The re-mapping deadline and what it is made of.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dutc {
    margin: f64,
    used: f64,
    vmax: f64,
    since: f64,
    /// Local time by which the grid must be re-mapped.
    pub deadline: f64,
}

impl Dutc {
    /// After a mapping at local time 0 with the given margin and largest speed.
    pub fn new(margin: f64, vmax: f64) -> Dutc {
        let mut d = Dutc {
            margin,
            used: 0.0,
            vmax,
            since: 0.0,
            deadline: f64::INFINITY,
        };
        d.deadline = d.horizon(0.0);
        d
    }

    fn horizon(&self, now: f64) -> f64 {
        if self.vmax > 0.0 {
            now + ((self.margin - self.used).max(0.0)) / (2.0 * self.vmax)
        } else {
            f64::INFINITY
        }
    }

    /// Largest speed the deadline assumes.
    pub fn vmax(&self) -> f64 {
        self.vmax
    }

    /// A disk now moves at `speed` (falling frame); tightens the deadline if it is a new maximum.
    #[inline]
    pub fn observe(&mut self, now: f64, speed_sq: f64) {
        if speed_sq > self.vmax * self.vmax {
            self.used += 2.0 * self.vmax * (now - self.since);
            self.since = now;
            self.vmax = speed_sq.sqrt();
            self.deadline = self.horizon(now);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deadline_spends_the_margin_once() {
        let mut d = Dutc::new(1.0, 1.0);
        assert_eq!(d.deadline, 0.5);
        // At t = 0.25 half the margin is used; a speed of 2 leaves 0.5/(2·2) = 0.125.
        d.observe(0.25, 4.0);
        assert!((d.deadline - 0.375).abs() < 1e-15);
        d.observe(0.3, 1.0); // slower: no change
        assert!((d.deadline - 0.375).abs() < 1e-15);
        assert_eq!(Dutc::new(1.0, 0.0).deadline, f64::INFINITY);
    }
}
