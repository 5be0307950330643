//! Restitution: what fraction of the normal approach speed a collision gives back — a constant
//! `e`, made elastic by the optional cures of inelastic collapse (TC model, normal-speed cutoff) —
//! and the per-disk memory the cures need. One home for choosing `e`, for pair collisions and for
//! impacts on walls, the lid and the floor alike, in every integration scheme.

/// The restitution law of pair collisions: a constant `e`, made elastic by the optional cures
/// of inelastic collapse (TC model, normal-speed cutoff).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Restitution {
    /// Normal restitution.
    pub e: f64,
    /// TC model: elastic when either disk collided less than `tc` ago.
    pub tc: Option<f64>,
    /// Elastic when the normal approach speed is below this.
    pub speed_cutoff: Option<f64>,
}

impl Restitution {
    /// The restitution of a collision with normal approach speed `u ≥ 0`, where the two disks'
    /// previous collisions were `since_i` and `since_j` ago.
    #[inline]
    pub fn of(&self, u: f64, since_i: f64, since_j: f64) -> f64 {
        if self.e == 1.0 {
            return 1.0;
        }
        if let Some(tc) = self.tc {
            if since_i < tc || since_j < tc {
                return 1.0;
            }
        }
        if let Some(v) = self.speed_cutoff {
            if u < v {
                return 1.0;
            }
        }
        self.e
    }

    /// Whether collisions lose energy (`e < 1`).
    pub fn inelastic(&self) -> bool {
        self.e < 1.0
    }

    /// Whether a cure of inelastic collapse is on (the TC model or the speed cutoff): each needs
    /// the disks' memory of their last collisions.
    pub fn cured(&self) -> bool {
        self.tc.is_some() || self.speed_cutoff.is_some()
    }
}

/// The restitution law together with the memory it needs: each disk's last collision time
/// (TC model only; nothing is allocated otherwise). One home for choosing `e`, shared by every
/// integration scheme.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CollisionLaw {
    /// The law.
    pub law: Restitution,
    /// Time of each disk's last collision (with a disk or a boundary).
    last: Vec<f64>,
    /// Whether that collision was with another disk.
    paired: Vec<bool>,
}

impl CollisionLaw {
    /// The law for `n` disks.
    pub fn new(law: Restitution, n: usize) -> CollisionLaw {
        CollisionLaw {
            law,
            last: vec![f64::NEG_INFINITY; if law.tc.is_some() { n } else { 0 }],
            paired: vec![false; if law.cured() { n } else { 0 }],
        }
    }

    /// Hints that disk `i`'s last collision will be read soon (where TC keeps it).
    #[inline(always)]
    pub fn prefetch(&self, i: usize) {
        crate::platform::prefetch::prefetch(&self.last, i);
    }

    /// A disk enters as the last one, with no collision yet.
    pub fn push(&mut self) {
        if self.law.tc.is_some() {
            self.last.push(f64::NEG_INFINITY);
        }
        if self.law.cured() {
            self.paired.push(false);
        }
    }

    /// Disk `k` leaves, the last disk taking its number.
    pub fn swap_remove(&mut self, k: usize) {
        if !self.last.is_empty() {
            self.last.swap_remove(k);
        }
        if !self.paired.is_empty() {
            self.paired.swap_remove(k);
        }
    }

    /// Follows a renumbering of the disks: new disk k is old disk `from[k]`.
    pub fn permute(&mut self, from: &[u32]) {
        if !self.last.is_empty() {
            crate::physics::disks::permute_in_place(&mut self.last, from);
        }
        if !self.paired.is_empty() {
            crate::physics::disks::permute_in_place(&mut self.paired, from);
        }
    }

    /// The law's record of disks `ids`, numbered from 0 in that order.
    pub fn gather(&self, ids: &[u32]) -> CollisionLaw {
        let pick = |v: &[f64]| ids.iter().map(|&g| v[g as usize]).collect::<Vec<_>>();
        CollisionLaw {
            law: self.law,
            last: if self.last.is_empty() {
                Vec::new()
            } else {
                pick(&self.last)
            },
            paired: if self.paired.is_empty() {
                Vec::new()
            } else {
                ids.iter().map(|&g| self.paired[g as usize]).collect()
            },
        }
    }

    /// Copies back the record of `part`, gathered from `ids`.
    pub fn scatter(&mut self, part: &CollisionLaw, ids: &[u32]) {
        for (k, &g) in ids.iter().enumerate() {
            if !self.last.is_empty() {
                self.last[g as usize] = part.last[k];
            }
            if !self.paired.is_empty() {
                self.paired[g as usize] = part.paired[k];
            }
        }
    }

    /// Restitution of a collision of disks `i` and `j` happening at `now`, with separation
    /// `(dx, dy) = r_i − r_j` and relative velocity `(dvx, dvy) = v_i − v_j`; records it.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn collision(
        &mut self,
        i: usize,
        j: usize,
        now: f64,
        dx: f64,
        dy: f64,
        dvx: f64,
        dvy: f64,
    ) -> f64 {
        self.record(i, j, now, (dx, dy, dvx, dvy), true)
    }

    /// [`collision`](Self::collision) of a flying disk with a disk at rest (resting contacts):
    /// the TC model does not make it elastic — a disk pressed onto a disk at rest comes to rest
    /// there, which ends the sequence TC would end (the floor, by contrast, keeps the cure
    /// right after a pair collision: see [`boundary_elastic`](Self::boundary_elastic)). The
    /// speed cutoff still applies.
    /// `(dx, dy, dvx, dvy)` as for [`collision`](Self::collision).
    #[inline]
    pub fn collision_with_rest(
        &mut self,
        i: usize,
        j: usize,
        now: f64,
        relative: (f64, f64, f64, f64),
    ) -> f64 {
        self.record(i, j, now, relative, false)
    }

    /// The restitution of a collision, TC counted if `timed`, and the collision recorded.
    #[inline]
    fn record(
        &mut self,
        i: usize,
        j: usize,
        now: f64,
        (dx, dy, dvx, dvy): (f64, f64, f64, f64),
        timed: bool,
    ) -> f64 {
        let e = if self.law.e == 1.0 {
            1.0
        } else {
            let u = -(dx * dvx + dy * dvy) / (dx * dx + dy * dy).sqrt();
            let since = |k: usize| match self.last.get(k) {
                Some(&t) if timed => now - t,
                _ => f64::INFINITY,
            };
            self.law.of(u, since(i), since(j))
        };
        if !self.last.is_empty() {
            self.last[i] = now;
            self.last[j] = now;
        }
        if !self.paired.is_empty() {
            self.paired[i] = true;
            self.paired[j] = true;
        }
        e
    }

    /// Whether a cure makes the impact of disk `i` on a wall, the lid or the floor at `now`,
    /// with normal approach speed `u ≥ 0`, elastic; records the impact. A cure acts on a boundary
    /// impact only when the disk's previous collision was with another disk (the disk is pressed
    /// between a disk and the boundary): the TC model when that collision was less than `tc` ago,
    /// the speed cutoff when `u` is below it. A disk alone on the floor keeps the boundary's
    /// restitution, so it can come to rest.
    #[inline]
    pub fn boundary_elastic(&mut self, i: usize, now: f64, u: f64) -> bool {
        let Some(paired) = self.paired.get_mut(i) else {
            return false;
        };
        let after_pair = std::mem::replace(paired, false);
        let recent = match (self.law.tc, self.last.get_mut(i)) {
            (Some(tc), Some(last)) => std::mem::replace(last, now) > now - tc,
            _ => false,
        };
        after_pair && (recent || self.law.speed_cutoff.is_some_and(|v| u < v))
    }

    /// The clock's origin moved forward by `dt`.
    pub fn rebase(&mut self, dt: f64) {
        for t in &mut self.last {
            *t -= dt;
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        8 * self.last.capacity() + self.paired.capacity()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law(tc: Option<f64>, speed_cutoff: Option<f64>) -> CollisionLaw {
        CollisionLaw::new(
            Restitution {
                e: 0.5,
                tc,
                speed_cutoff,
            },
            2,
        )
    }

    #[test]
    fn tc_makes_a_boundary_impact_elastic_only_right_after_a_pair_collision() {
        let mut tc = law(Some(1e-3), None);
        // Alone on the floor: its own bounces never count, however frequent.
        assert!(!tc.boundary_elastic(0, 0.0, 1e-6));
        assert!(!tc.boundary_elastic(0, 1e-4, 1e-6));
        // Pressed between a disk and the floor: elastic within tc of the pair collision...
        assert_eq!(tc.collision(0, 1, 1.0, 0.0, 1.0, 0.0, -1.0), 0.5);
        assert!(tc.boundary_elastic(0, 1.0 + 5e-4, 1.0));
        // ...once: the next floor impact follows a floor impact.
        assert!(!tc.boundary_elastic(0, 1.0 + 6e-4, 1.0));
        // A floor impact within tc makes the next pair collision elastic.
        assert_eq!(tc.collision(0, 1, 1.0 + 7e-4, 0.0, 1.0, 0.0, -1.0), 1.0);
        // Too late after the pair collision: the floor's own restitution.
        assert!(!tc.boundary_elastic(0, 1.1, 1.0));
        assert!(!tc.boundary_elastic(1, 2.0, 1.0));
    }

    #[test]
    fn the_speed_cutoff_acts_on_a_boundary_impact_after_a_pair_collision() {
        let mut cut = law(None, Some(1e-2));
        assert!(
            !cut.boundary_elastic(0, 0.0, 1e-3),
            "alone: the floor's own restitution"
        );
        cut.collision(0, 1, 1.0, 0.0, 1.0, 0.0, -1.0);
        assert!(!cut.boundary_elastic(1, 5.0, 0.1), "faster than the cutoff");
        assert!(cut.boundary_elastic(0, 5.0, 1e-3));
        assert!(!cut.boundary_elastic(0, 5.0, 1e-3));
        // No cure: nothing is allocated and every boundary keeps its restitution.
        let mut none = law(None, None);
        none.collision(0, 1, 1.0, 0.0, 1.0, 0.0, -1.0);
        assert!(!none.boundary_elastic(0, 1.0, 0.0));
        assert_eq!(none.bytes(), 0);
    }

    #[test]
    fn tc_does_not_act_on_a_collision_with_a_disk_at_rest_but_the_cutoff_does() {
        let mut tc = law(Some(1e-3), None);
        assert_eq!(tc.collision(0, 1, 1.0, 0.0, 1.0, 0.0, -1.0), 0.5);
        // Right after: elastic between two flying disks, not against one at rest.
        assert_eq!(tc.collision(0, 1, 1.0 + 1e-4, 0.0, 1.0, 0.0, -1.0), 1.0);
        assert_eq!(
            tc.collision_with_rest(0, 1, 1.0 + 2e-4, (0.0, 1.0, 0.0, -1.0)),
            0.5
        );
        // It is recorded all the same: the next collision of the two is within tc of it.
        assert_eq!(tc.collision(0, 1, 1.0 + 3e-4, 0.0, 1.0, 0.0, -1.0), 1.0);
        let mut cut = law(None, Some(1e-2));
        assert_eq!(
            cut.collision_with_rest(0, 1, 1.0, (0.0, 1.0, 0.0, -1e-3)),
            1.0
        );
        assert_eq!(
            cut.collision_with_rest(0, 1, 2.0, (0.0, 1.0, 0.0, -0.1)),
            0.5
        );
    }
}
