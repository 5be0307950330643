//! **A pressed slider**: a disk sliding on a rough floor, pressed by the friction under it into
//! a disk it meets slower than its sleep speed, would collide with it at one instant for ever,
//! exchanging next to nothing. It rolls at once instead (its hard case is
//! `pile_rough_pressed_slider`). A rule of the slide, which riding the floor always follows: it
//! acts with or without the resting contacts.

use crate::engine::Simulation;
use crate::physics::flight::Flight;

impl<F: Flight> Simulation<F> {
    /// Disks `i` and `j` touch (`(dx, dy)` from `j` to `i`, both brought to now): where a disk
    /// slides on a rough floor, the one that slides may be pressed into the other and roll
    /// ([`roll_if_pressed`](Self::roll_if_pressed)). `true` if it did.
    #[inline]
    pub(in crate::engine) fn roll_pressed_slider(
        &mut self,
        i: usize,
        j: usize,
        sep: (f64, f64),
    ) -> bool {
        self.rest.riders.any_sliding() && self.roll_if_pressed(i, j, sep)
    }

    /// Disks `i` and `j` touch (`(dx, dy)` from `j` to `i`, both brought to now) and one of them
    /// slides on a rough floor, meeting the other slower than its sleep speed: the friction
    /// under it presses it into the other, and colliding would exchange next to nothing, at one
    /// instant, for ever. The slider takes the end of its slide at once and rolls (the
    /// friction impulse left, `q/(1 + q)` of its slip, at once, as if the slide were not
    /// followed: only for a contact this gentle); both are predicted again. `true` if it did.
    fn roll_if_pressed(&mut self, i: usize, j: usize, (dx, dy): (f64, f64)) -> bool {
        let (mi, mj) = (self.disks.motion[i], self.disks.motion[j]);
        let dist = (dx * dx + dy * dy).sqrt();
        let approach = -((mi.vx - mj.vx) * dx + (mi.vy - mj.vy) * dy) / dist;
        let slider = [i, j]
            .into_iter()
            .find(|&k| self.rest.riders.slide(k).is_some() && approach < self.sleep_speed(k));
        let Some(k) = slider else {
            return false;
        };
        self.roll_at_once(k);
        self.stop_if_slow(k);
        self.tally.jams.pressed_slider += 1;
        self.moved(k);
        self.predict(if k == i { j } else { i });
        true
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{jams_in, run_hard_case};

    /// The pile of rough disks lands with disks sliding into neighbours: pressed sliders roll.
    #[test]
    fn a_landing_pile_of_rough_disks_has_pressed_sliders() {
        assert!(jams_in("pile_rough_pressed_slider.json", &[]).pressed_slider > 0);
    }

    /// The one rule that acts without the resting contacts: a slide is part of riding the
    /// floor, always on, and a slider pressed gently rings at one instant with them off too.
    #[test]
    fn pressed_sliders_roll_without_resting_contacts_too() {
        let off = "collisions.resting_contacts=false";
        let jams = jams_in("pile_rough_pressed_slider.json", &[off]);
        assert!(jams.pressed_slider > 0, "{jams:?}");
    }

    /// The rule itself, at the pile's first slide: met slower than its sleep speed, the slider
    /// rolls (its slide ends) and is counted; met faster, the rule leaves both alone.
    #[test]
    fn a_slider_rolls_only_when_pressed_slower_than_its_sleep_speed() {
        let mut sim = run_hard_case("pile_rough_pressed_slider.json", &["run.duration=1e-3"]);
        let n = sim.disks.len();
        let k = loop {
            if let Some(k) = (0..n).find(|&k| sim.rest.riders.slide(k).is_some()) {
                break k;
            }
            let t = sim.time();
            assert!(t < 5.5, "no disk slid on the floor");
            sim.advance_to(t + 1e-3).expect("runs");
        };
        let j = (k + 1) % n;
        let now = sim.now;
        sim.bring(k, now);
        sim.bring(j, now);
        // Disk j placed beside the slider and moving towards it at `approach`.
        let press = |sim: &mut super::Simulation<_>, approach: f64| {
            let m = sim.disks.motion[k];
            let (dx, dy) = (1.0, 0.0);
            let other = &mut sim.disks.motion[j];
            (other.x, other.y) = (m.x - dx, m.y - dy);
            (other.vx, other.vy) = (m.vx + approach * dx, m.vy + approach * dy);
            sim.roll_pressed_slider(k, j, (dx, dy))
        };
        let slow = sim.sleep_speed(k);
        assert!(slow > 0.0, "the floor presses the slider");
        let before = sim.jam_counts().pressed_slider;
        assert!(!press(&mut sim, 2.0 * slow), "met faster: a collision");
        assert!(sim.rest.riders.slide(k).is_some(), "still sliding");
        assert_eq!(sim.jam_counts().pressed_slider, before);
        assert!(press(&mut sim, 0.5 * slow), "met slower: the slider rolls");
        assert!(sim.rest.riders.slide(k).is_none(), "its slide ended");
        assert_eq!(sim.jam_counts().pressed_slider, before + 1);
    }
}
