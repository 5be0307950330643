//! **A pressed slider**: a disk sliding on a rough floor, pressed by the friction under it into
//! a disk it meets slower than its sleep speed, would collide with it at one instant for ever,
//! exchanging next to nothing. It rolls at once instead (its test is the hard case
//! `pile_rough_pressed_slider` in the suite's hard cases).

use crate::engine::Simulation;
use crate::physics::flight::Flight;

impl<F: Flight> Simulation<F> {
    /// Disks `i` and `j` touch (`(dx, dy)` from `j` to `i`, both brought to now) and one of them
    /// slides on a rough floor, meeting the other slower than its sleep speed: the friction
    /// under it presses it into the other, and colliding would exchange next to nothing, at one
    /// instant, for ever. The slider takes the end of its slide at once and rolls (the
    /// friction impulse left, `q/(1 + q)` of its slip, at once, as if the slide were not
    /// followed: only for a contact this gentle); both are predicted again. `true` if it did.
    pub(in crate::engine) fn roll_pressed_slider(
        &mut self,
        i: usize,
        j: usize,
        (dx, dy): (f64, f64),
    ) -> bool {
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
