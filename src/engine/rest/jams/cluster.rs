//! **A jammed cluster**: slow flying disks touching a disk that has just come to rest (directly
//! or through each other), held only as a whole — a jammed layer or an arch — come to rest
//! together, those in a stable place; without this they rattle on their supports for ever.

use crate::engine::rest::resting::TOUCH;
use crate::engine::rest::riders::NO_DISK;
use crate::engine::Simulation;
use crate::physics::flight::Flight;

impl<F: Flight> Simulation<F> {
    /// Disks `i` and `j` have just collided (`rode`: whether each rode before; `e` the
    /// restitution it had). Two slow flying disks meeting among disks at rest, their collision
    /// made elastic by a cure, on a floor that never pulls away from a bed at rest: the jammed
    /// cluster they belong to may hold as a whole ([`settle_cluster`](Self::settle_cluster)).
    #[inline(always)]
    pub(in crate::engine) fn settle_if_jammed(
        &mut self,
        i: usize,
        j: usize,
        rode: [bool; 2],
        e: f64,
    ) {
        if rode == [false, false]
            && e == 1.0
            && self.restitution.law.inelastic()
            && self.rest.resting_contacts
            && self
                .bounds
                .floor
                .as_ref()
                .is_some_and(|f| f.max_acceleration() < self.flight.g())
            && self.slow(i)
            && self.slow(j)
        {
            self.settle_cluster(i);
        }
    }

    /// Gathers into `cluster` (marking `member`) disk `seed` if it flies, and the flying disks
    /// touching it, directly or through each other, that move slower than the sleep speed
    /// relative to the floor (moving at `hd`): breadth first from the seed.
    pub(in crate::engine) fn gather_slow(
        &self,
        seed: usize,
        hd: f64,
        member: &mut [bool],
        cluster: &mut Vec<u32>,
    ) {
        let now = self.now;
        if !self.is_riding(seed) {
            member[seed] = true;
            cluster.push(seed as u32);
        }
        let mut from = seed;
        let mut next = 0;
        loop {
            let (xs, ys, _, _) = self.state_at(from, now);
            for &c in self.map.lists.of(from) {
                let c = c as usize;
                if member[c] || self.is_riding(c) {
                    continue;
                }
                let (xc, yc, vxc, vyc) = self.state_at(c, now);
                let ac = self.disks.radius[c];
                let (dx, dy) = self.wrap(xc - xs, yc - ys);
                let gap = (dx * dx + dy * dy).sqrt() - ac - self.disks.radius[from];
                if gap <= TOUCH * ac && vxc.hypot(vyc - hd) <= self.sleep_speed(c) {
                    member[c] = true;
                    cluster.push(c as u32);
                }
            }
            let Some(&c) = cluster.get(next) else { break };
            from = c as usize;
            next += 1;
        }
    }

    /// Disk `seed` has just come to rest, or is a slow flying disk that has just met another.
    /// The flying disks touching it (and `seed` itself, if it flies), directly or through each
    /// other, that move slower than the sleep speed relative to the floor (a jammed layer or an
    /// arch, held only as a whole) come to rest together: those of them that are in a stable
    /// place among the disks at rest that do not slide, the side walls, the floor and each other —
    /// dropping, until none is left, any that is not. Each would land where it is, gently, within
    /// [`TOUCH`] radii; without this such a cluster rattles on its supports for ever.
    pub(in crate::engine) fn settle_cluster(&mut self, seed: usize) {
        let n = self.disks.len();
        let now = self.now;
        let (h, hd) = self.floor_now();
        let mut member = std::mem::take(&mut self.rest.in_cluster);
        member.resize(n, false);
        let mut cluster = std::mem::take(&mut self.rest.cluster);
        self.gather_slow(seed, hd, &mut member, &mut cluster);
        // Prune: drop the members that no place holds, until every remaining one is held.
        let place = |sim: &Self, c: usize, member: &[bool]| -> Option<[u32; 2]> {
            if sim.squeezed(c, 0.0, hd) || sim.near_lid(c) {
                return None;
            }
            if sim.touches_floor(c, h) {
                return Some([NO_DISK; 2]);
            }
            sim.stable_place(c, None, |s| {
                member[s] || (sim.is_riding(s) && sim.disks.motion[s].vx == 0.0)
            })
        };
        // The places of the last pass, the one that dropped nothing, hold together.
        let mut places = Vec::new();
        loop {
            places.clear();
            let mut dropped = false;
            for &c in &cluster {
                let c = c as usize;
                if !member[c] {
                    continue;
                }
                match place(self, c, &member) {
                    Some(p) => places.push((c, p)),
                    None => {
                        member[c] = false;
                        dropped = true;
                    }
                }
            }
            if !dropped {
                break;
            }
        }
        // Rest: every place is known first (they refer to each other), then every disk rests.
        let mut refused = Vec::new();
        let mut settled = false;
        for &(c, p) in &places {
            self.bring(c, now);
            if self.come_to_rest(c, h, p, (0.0, hd)) {
                settled = true;
            } else {
                refused.push(c);
            }
        }
        self.tally.jams.cluster += settled as u64;
        // A disk that could not be carried (its supports are full) lets go of what rests on it.
        for c in refused {
            self.release_carried(c, None);
        }
        for &c in &cluster {
            member[c as usize] = false;
        }
        cluster.clear();
        self.rest.cluster = cluster;
        self.rest.in_cluster = member;
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::jams_in;

    /// A column of slow disks by a wall, held only as a whole, comes to rest together.
    #[test]
    fn a_column_by_a_wall_settles_as_a_cluster() {
        assert!(jams_in("column_by_a_wall.json", &[]).cluster > 0);
    }
}
