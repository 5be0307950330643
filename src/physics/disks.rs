//! The disks, as a structure of arrays: positions, velocities and the time stamp each state
//! belongs to (disks are advanced lazily), radii, masses, collision counters, and the spins of
//! rough disks. A property that every disk shares (equal disks, one species) is stored once.

use std::ops::Index;

/// A disk's motion: its state at its own time stamp (kept together: the hot data of the event
/// loop, one cache line's worth per disk).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[repr(C)]
pub struct Motion {
    /// Centre x at time `t`.
    pub x: f64,
    /// Centre y at time `t`.
    pub y: f64,
    /// Velocity x at time `t`.
    pub vx: f64,
    /// Velocity y at time `t`.
    pub vy: f64,
    /// The (engine-local) time the stored state belongs to.
    pub t: f64,
}

/// Storage of N disks: motions together, static properties in their own arrays.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Disks {
    /// Position, velocity and time stamp of each disk.
    pub motion: Vec<Motion>,
    /// Radius.
    pub radius: PerDisk<f64>,
    /// Mass.
    pub mass: PerDisk<f64>,
    /// Species index (for output).
    pub species: PerDisk<u32>,
    /// Number of velocity changes so far (invalidates partners' predicted events).
    pub counter: Vec<u32>,
    /// Spins and orientations of rough disks; `None` (nothing allocated) for smooth ones.
    pub spins: Option<Spins>,
}

impl Disks {
    /// Disks at rest at the given positions with the given radii and masses, all at time 0.
    pub fn new(
        positions: &[[f64; 2]],
        radius: Vec<f64>,
        mass: Vec<f64>,
        species: Vec<u32>,
    ) -> Disks {
        let n = positions.len();
        assert!(radius.len() == n && mass.len() == n && species.len() == n);
        Disks {
            motion: positions
                .iter()
                .map(|p| Motion {
                    x: p[0],
                    y: p[1],
                    ..Motion::default()
                })
                .collect(),
            radius: PerDisk::new(radius),
            mass: PerDisk::new(mass),
            species: PerDisk::new(species),
            counter: vec![0; n],
            spins: None,
        }
    }

    /// Number of disks.
    pub fn len(&self) -> usize {
        self.radius.len()
    }

    /// `true` when there are no disks.
    pub fn is_empty(&self) -> bool {
        self.radius.is_empty()
    }

    /// Smallest and largest radius.
    pub fn radius_range(&self) -> (f64, f64) {
        self.radius
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
                (lo.min(r), hi.max(r))
            })
    }

    /// Root mean square radius (0 without disks).
    pub fn rms_radius(&self) -> f64 {
        let n = self.radius.len().max(1) as f64;
        (self.radius.iter().map(|a| a * a).sum::<f64>() / n).sqrt()
    }

    /// Bytes held by these arrays.
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<Motion>() * self.motion.capacity()
            + self.radius.bytes()
            + self.mass.bytes()
            + self.species.bytes()
            + 4 * self.counter.capacity()
            + self.spins.as_ref().map_or(0, |s| s.bytes())
    }

    /// Disks `ids` (global numbers, in this order) as a set of their own, numbered from 0: a
    /// part of the scene that one thread moves on its own.
    pub fn gather(&self, ids: &[u32]) -> Disks {
        Disks {
            motion: ids.iter().map(|&g| self.motion[g as usize]).collect(),
            radius: self.radius.gather(ids),
            mass: self.mass.gather(ids),
            species: self.species.gather(ids),
            counter: ids.iter().map(|&g| self.counter[g as usize]).collect(),
            spins: self.spins.as_ref().map(|s| s.gather(ids)),
        }
    }

    /// Copies back what moves (motion, counters, spins) from `part`, gathered from `ids`.
    pub fn scatter(&mut self, part: &Disks, ids: &[u32]) {
        for (k, &g) in ids.iter().enumerate() {
            self.motion[g as usize] = part.motion[k];
            self.counter[g as usize] = part.counter[k];
        }
        if let (Some(all), Some(some)) = (self.spins.as_mut(), part.spins.as_ref()) {
            all.scatter(some, ids);
        }
    }

    /// Rotational kinetic energy `Σ ½ I ω²` (0 for smooth disks).
    pub fn rotational_energy(&self) -> f64 {
        self.spins
            .as_ref()
            .map_or(0.0, |s| s.energy(self.mass.iter(), self.radius.iter()))
    }
}

impl Disks {
    /// Reserves room for `cap` disks in every array, so that disks entering allocate nothing.
    pub fn reserve_to(&mut self, cap: usize) {
        let more = cap.saturating_sub(self.motion.len());
        self.motion.reserve_exact(more);
        self.counter.reserve_exact(more);
        if let Some(s) = &mut self.spins {
            s.omega.reserve_exact(more);
            s.phase.reserve_exact(more);
        }
    }

    /// Removes disk `k`, the last disk taking its number (no allocation).
    pub fn swap_remove(&mut self, k: usize) {
        self.motion.swap_remove(k);
        self.radius.swap_remove(k);
        self.mass.swap_remove(k);
        self.species.swap_remove(k);
        self.counter.swap_remove(k);
        if let Some(s) = &mut self.spins {
            s.omega.swap_remove(k);
            s.phase.swap_remove(k);
        }
    }
}

/// The rotational state of rough disks: each disk's angular velocity, constant in flight, and
/// its orientation as the angle at local time 0 (`angle(t) = phase + ω t` on the engine's
/// clock), so that the orientation advances without touching the disk. Allocated only for a
/// rough scene.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Spins {
    /// `q` in `I = q m a²`.
    pub q: f64,
    /// Angular velocity of each disk.
    pub omega: Vec<f64>,
    /// Orientation at local time 0.
    pub phase: Vec<f64>,
}

impl Spins {
    /// `n` disks at orientation 0 with spins `omega`.
    pub fn new(q: f64, omega: Vec<f64>) -> Spins {
        let n = omega.len();
        Spins {
            q,
            omega,
            phase: vec![0.0; n],
        }
    }

    /// Disk `k`'s orientation at local time `t`, in [0, 2π) up to round-off.
    pub fn angle(&self, k: usize, t: f64) -> f64 {
        (self.phase[k] + self.omega[k] * t).rem_euclid(std::f64::consts::TAU)
    }

    /// Every disk's `(orientation, ω)` at local time `t`, in their own order.
    pub fn at(&self, t: f64) -> Vec<(f64, f64)> {
        (0..self.omega.len())
            .map(|k| (self.angle(k, t), self.omega[k]))
            .collect()
    }

    /// Disk `k`'s spin changes by `dw` at local time `now`: the orientation carries on from
    /// where it is.
    #[inline]
    pub fn spin(&mut self, k: usize, now: f64, dw: f64) {
        self.phase[k] -= dw * now;
        self.omega[k] += dw;
    }

    /// The clock's origin moved forward by `dt`: each orientation is re-based, reduced mod 2π.
    pub fn rebase(&mut self, dt: f64) {
        for (p, w) in self.phase.iter_mut().zip(&self.omega) {
            *p = (*p + w * dt).rem_euclid(std::f64::consts::TAU);
        }
    }

    /// The spins of disks `ids`, numbered from 0 in that order.
    pub fn gather(&self, ids: &[u32]) -> Spins {
        Spins {
            q: self.q,
            omega: ids.iter().map(|&g| self.omega[g as usize]).collect(),
            phase: ids.iter().map(|&g| self.phase[g as usize]).collect(),
        }
    }

    /// Copies back the spins of `part`, gathered from `ids`.
    pub fn scatter(&mut self, part: &Spins, ids: &[u32]) {
        for (k, &g) in ids.iter().enumerate() {
            self.omega[g as usize] = part.omega[k];
            self.phase[g as usize] = part.phase[k];
        }
    }

    /// Follows a renumbering of the disks: new disk k is old disk `from[k]`.
    pub fn permute(&mut self, from: &[u32]) {
        permute_in_place(&mut self.omega, from);
        permute_in_place(&mut self.phase, from);
    }

    /// Rotational kinetic energy `Σ ½ q m a² ω²` of disks with masses `m` and radii `a`.
    pub fn energy(&self, m: impl Iterator<Item = f64>, a: impl Iterator<Item = f64>) -> f64 {
        self.omega
            .iter()
            .zip(m.zip(a))
            .map(|(w, (m, a))| 0.5 * self.q * m * a * a * w * w)
            .sum()
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        8 * (self.omega.capacity() + self.phase.capacity())
    }
}

/// Reorders `v` in place so that its entry `k` is the old entry `from[k]` (`from` a
/// permutation of `0..v.len()`): cycle by cycle, with one bit per entry to mark those done, so
/// that renumbering a million disks needs no second copy of their arrays.
pub fn permute_in_place<T: Copy>(v: &mut [T], from: &[u32]) {
    assert_eq!(v.len(), from.len(), "a permutation of every entry");
    let mut done = vec![0u64; v.len().div_ceil(64)];
    for start in 0..v.len() {
        if done[start / 64] >> (start % 64) & 1 == 1 {
            continue;
        }
        let first = v[start];
        let mut k = start;
        loop {
            done[k / 64] |= 1 << (k % 64);
            let src = from[k] as usize;
            if src == start {
                v[k] = first;
                break;
            }
            v[k] = v[src];
            k = src;
        }
    }
}

/// A property of each disk, held once when all disks share it (N values otherwise).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PerDisk<T> {
    /// Number of disks.
    len: usize,
    /// The value all disks share (when `each` is empty).
    common: T,
    /// One value per disk, unless all are equal.
    each: Vec<T>,
}

impl<T: Copy + PartialEq + Default> PerDisk<T> {
    /// The values of `v`, stored once if they are all equal.
    pub fn new(v: Vec<T>) -> PerDisk<T> {
        match v.first() {
            Some(&first) if v.iter().all(|&x| x == first) => PerDisk {
                len: v.len(),
                common: first,
                each: Vec::new(),
            },
            _ => PerDisk {
                len: v.len(),
                common: T::default(),
                each: v,
            },
        }
    }

    /// Number of disks.
    pub fn len(&self) -> usize {
        self.len
    }

    /// `true` without disks.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The value every disk shares, if they do.
    pub fn common(&self) -> Option<T> {
        (self.each.is_empty() && self.len > 0).then_some(self.common)
    }

    /// Each disk's own value; empty when they share one ([`common`](Self::common)).
    pub fn each(&self) -> &[T] {
        &self.each
    }

    /// The values in disk order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = T> + '_ {
        (0..self.len).map(|i| self[i])
    }

    /// The values as a vector.
    pub fn to_vec(&self) -> Vec<T> {
        self.iter().collect()
    }

    /// The entries `ids`, in that order.
    pub fn gather(&self, ids: &[u32]) -> PerDisk<T> {
        if self.each.is_empty() {
            PerDisk {
                len: ids.len(),
                common: self.common,
                each: Vec::new(),
            }
        } else {
            PerDisk::new(ids.iter().map(|&g| self.each[g as usize]).collect())
        }
    }

    /// Reordered so that entry `k` is the old entry `from[k]`.
    pub fn permute(&mut self, from: &[u32]) {
        if !self.each.is_empty() {
            permute_in_place(&mut self.each, from);
        }
    }

    /// Appends an entry (no allocation while the value is the common one, or within the room
    /// reserved).
    pub fn push(&mut self, v: T) {
        if self.each.is_empty() && (self.len == 0 || v == self.common) {
            self.common = v;
        } else {
            if self.each.is_empty() {
                self.each = vec![self.common; self.len];
            }
            self.each.push(v);
        }
        self.len += 1;
    }

    /// Removes entry `k`, the last taking its place (no allocation).
    pub fn swap_remove(&mut self, k: usize) {
        if !self.each.is_empty() {
            self.each.swap_remove(k);
        }
        self.len -= 1;
    }

    /// Becomes `src`'s entries at `rows`, in that order, reusing its memory (no allocation once
    /// it has held as many).
    pub fn fill_from(&mut self, src: &PerDisk<T>, rows: impl Iterator<Item = usize>) {
        self.common = src.common;
        self.each.clear();
        self.len = 0;
        for k in rows {
            if !src.each.is_empty() {
                self.each.push(src.each[k]);
            }
            self.len += 1;
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<T>() * self.each.capacity()
    }
}

impl<T> Index<usize> for PerDisk<T> {
    type Output = T;

    #[inline(always)]
    fn index(&self, i: usize) -> &T {
        if self.each.is_empty() {
            debug_assert!(i < self.len, "disk {i} of {}", self.len);
            &self.common
        } else {
            &self.each[i]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shared_value_is_stored_once_and_reads_the_same() {
        let shared = PerDisk::new(vec![0.5; 4]);
        assert_eq!(
            (shared.common(), shared.bytes(), shared.len()),
            (Some(0.5), 0, 4)
        );
        assert_eq!(shared[3], 0.5);
        assert_eq!(shared.to_vec(), vec![0.5; 4]);
        let mut each = PerDisk::new(vec![1u32, 2, 3, 4]);
        assert_eq!((each.common(), each.bytes()), (None, 16));
        each.permute(&[2, 0, 3, 1]);
        assert_eq!(each.to_vec(), [3, 1, 4, 2]);
        assert_eq!(PerDisk::<f64>::new(Vec::new()).common(), None);
    }

    #[test]
    fn permuting_in_place_takes_entries_from_the_old_places() {
        let mut v = [10, 11, 12, 13, 14, 15];
        // Cycles (0 2 3 1) and (4 5).
        permute_in_place(&mut v, &[2, 0, 3, 1, 5, 4]);
        assert_eq!(v, [12, 10, 13, 11, 15, 14]);
        let n = 1000;
        let from: Vec<u32> = (0..n).map(|k| (k * 7 + 3) % n).collect();
        let mut w: Vec<u32> = (0..n).map(|k| k * k).collect();
        permute_in_place(&mut w, &from);
        assert!((0..n as usize).all(|k| w[k] == from[k] * from[k]));
    }

    #[test]
    fn spins_advance_with_their_own_clock_and_rebase() {
        let mut s = Spins::new(0.5, vec![2.0, -1.0]);
        s.spin(0, 1.0, 1.0); // ω 2 → 3 at t = 1, angle 2 there.
        assert!((s.angle(0, 2.0) - 5.0).abs() < 1e-15);
        s.rebase(2.0);
        assert!((s.angle(0, 0.0) - 5.0).abs() < 1e-15);
        assert!((s.angle(1, 0.5) - (std::f64::consts::TAU - 2.5)).abs() < 1e-14);
        s.permute(&[1, 0]);
        assert_eq!(s.omega, [-1.0, 3.0]);
    }
}
