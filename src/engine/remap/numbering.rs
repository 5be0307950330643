//! Renumbering: at a re-mapping the engine may give its disks new numbers along a Z-order
//! (Morton) curve of a coarse grid, so that disks close in space are close in memory — a
//! disk's neighbour list, its neighbours' states and the cells around it then share cache
//! lines instead of each costing a miss (the engine's arrays outgrow the caches from about
//! 10⁴ disks on, and disks wander away from their initial order).
//!
//! Renumbering changes no physics: only the order in which pairs are examined, hence which of
//! two contacts at exactly the same time comes first and the round-off of sums; outputs keep
//! the scenario's numbering ([`Numbering::id`]).

use crate::engine::Simulation;
use crate::physics::disks::{permute_in_place, Disks};
use crate::physics::flight::Flight;
use crate::physics::theory::mean_free_path;
use crate::scenario::{RenumberChoice, RENUMBER_FROM};

/// Pair collisions per disk between two renumberings in a gas at φ = 0.3 or below, and in every
/// scene with gravity or a floor (see [`renumber_every`]).
pub const RENUMBER_EVERY: u64 = 8;

/// Pair collisions per disk between two renumberings of disks of root mean square radius `a`
/// at packing `phi` (`settled`: gravity or a floor). What spoils the order is how far disks
/// move, about λ per collision in a random walk, so √(collisions)·λ: [`RENUMBER_EVERY`] times
/// (λ(0.3)/λ(φ))², the same reach as at φ = 0.3, at most eight times as many (64 from φ ≈ 0.5 on).
/// Under gravity (a bed dense below and dilute above: no one packing tells how far its disks
/// go) [`RENUMBER_EVERY`]. Each renumbering is a whole re-mapping under the local re-mapping,
/// which a dense gas renumbered as often as a dilute one would pay for with a noticeable share
/// of its speed.
pub fn renumber_every(a: f64, phi: f64, settled: bool) -> u64 {
    if settled {
        return RENUMBER_EVERY;
    }
    let ratio = mean_free_path(a, 0.3) / mean_free_path(a, phi);
    let scale = (ratio * ratio).clamp(1.0, 8.0);
    (RENUMBER_EVERY as f64 * scale).round() as u64
}

/// The engine's numbering of the disks against the scenario's.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct Numbering {
    /// Renumbering is on for this scene.
    pub on: bool,
    /// Scenario number of each engine disk (empty: the same numbers).
    id: Vec<u32>,
    /// The disks' radii, masses and species in the scenario's numbering (kept from the first
    /// renumbering on, for callers that pair them with snapshots; no motions or counters;
    /// `None` while the disks differ only in their motions).
    original: Option<Disks>,
    /// Pair collisions at the last renumbering (`None`: not yet renumbered).
    at: Option<u64>,
    /// Pair collisions per disk between two renumberings ([`renumber_every`]).
    every: u64,
}

impl Numbering {
    /// Renumbering as `choice` says for `n` disks, every `every` pair collisions per disk.
    pub fn new(choice: RenumberChoice, n: usize, every: u64) -> Numbering {
        Numbering {
            on: match choice {
                RenumberChoice::Auto => n >= RENUMBER_FROM,
                RenumberChoice::On => true,
                RenumberChoice::Off => false,
            },
            every: every.max(1),
            ..Numbering::default()
        }
    }

    /// Holds the scenario number of each of `n` engine disks explicitly (they start equal), so
    /// that disks may leave: a scene with an orifice keeps its disks' numbers this way and is
    /// never renumbered.
    pub fn keep_ids(&mut self, n: usize) {
        self.on = false;
        self.id = (0..n as u32).collect();
    }

    /// Engine disk `k` leaves, the last engine disk taking its number (see
    /// [`keep_ids`](Self::keep_ids)).
    pub fn swap_remove(&mut self, k: usize) {
        self.id.swap_remove(k);
    }

    /// A disk enters with scenario number `id` as the last engine disk.
    pub fn push(&mut self, id: u32) {
        self.id.push(id);
    }

    /// Room for `cap` disks.
    pub fn reserve_to(&mut self, cap: usize) {
        self.id.reserve_exact(cap.saturating_sub(self.id.len()));
    }

    /// Scenario number of engine disk `k`.
    #[inline]
    pub fn id(&self, k: usize) -> usize {
        if self.id.is_empty() {
            k
        } else {
            self.id[k] as usize
        }
    }

    /// The scenario number of every engine disk, if renumbered (`None`: the same numbers).
    pub fn ids(&self) -> Option<&[u32]> {
        (!self.id.is_empty()).then_some(&self.id[..])
    }

    /// `true` once `pairs` collisions (of `n` disks) call for a renumbering.
    #[inline]
    pub fn due(&self, pairs: u64, n: usize) -> bool {
        self.on && self.at.is_none_or(|at| pairs >= at + self.every * n as u64)
    }

    /// The disks in the scenario's numbering, if the engine's differs.
    pub fn original(&self) -> Option<&Disks> {
        self.original.as_ref()
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        4 * self.id.capacity() + self.original.as_ref().map_or(0, |d| d.bytes())
    }
}

/// Interleaves the bits of `x` and `y` (Z-order).
fn morton(x: u32, y: u32) -> u64 {
    let spread = |v: u32| {
        let mut v = v as u64;
        v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
        v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        v = (v | (v << 1)) & 0x5555_5555_5555_5555;
        v
    };
    spread(x) | (spread(y) << 1)
}

impl<F: Flight> Simulation<F> {
    /// At a re-mapping (every disk brought to the present, before the grid is rebuilt): if it
    /// is due, renumbers the disks along a Z-order curve of square tiles about two diameters
    /// wide. Everything that holds disk numbers between events follows; the grid, the lists,
    /// the anchors and the predictions are rebuilt by the re-mapping itself.
    pub(in crate::engine) fn renumber_if_due(&mut self) {
        let n = self.disks.len();
        if !self.map.numbering.due(self.tally.counts.pair, n) {
            return;
        }
        self.map.numbering.at = Some(self.tally.counts.pair);
        let (_, a_max) = self.disks.radius_range();
        let tile = 4.0 * a_max;
        let y0 = self.map.geometry.y0;
        let key = |k: usize| {
            let m = &self.disks.motion[k];
            let tx = (m.x / tile).max(0.0) as u32;
            let ty = ((m.y - y0) / tile).max(0.0) as u32;
            morton(tx, ty)
        };
        // Stable: disks of one tile keep their order, so the result depends only on the state.
        let mut keys: Vec<u64> = (0..n).map(key).collect();
        let owned: Vec<u32>;
        let from: &[u32] = if keys.iter().all(|&k| k < 1 << 32) {
            // Key and number packed in one word: the sort needs no second array, and the
            // numbers are then moved down to the first half of the keys' own memory (word k
            // takes the low half of key k, never a key not yet read): no second array at the
            // peak either.
            for (k, key) in keys.iter_mut().enumerate() {
                *key = *key << 32 | k as u64;
            }
            keys.sort_unstable();
            let words: &mut [u32] = bytemuck::cast_slice_mut(&mut keys);
            let low = usize::from(cfg!(target_endian = "big"));
            for k in 0..n {
                words[k] = words[2 * k + low];
            }
            &words[..n]
        } else {
            let mut from: Vec<u32> = (0..n as u32).collect();
            from.sort_by_key(|&k| keys[k as usize]);
            owned = from;
            &owned
        };
        if from.iter().enumerate().all(|(k, &f)| k == f as usize) {
            return;
        }
        // Disks that differ only in their motions (equal radii, masses and species) need no
        // copy in the scenario's numbering: their properties read the same in either.
        let d = &self.disks;
        let uniform = d.radius.common().is_some()
            && d.mass.common().is_some()
            && d.species.common().is_some();
        if self.map.numbering.original.is_none() && !uniform {
            self.map.numbering.original = Some(Disks {
                motion: Vec::new(),
                radius: d.radius.clone(),
                mass: d.mass.clone(),
                species: d.species.clone(),
                counter: Vec::new(),
                spins: None,
            });
        }
        self.rest.riders.permute(from);
        if self.map.numbering.id.is_empty() {
            self.map.numbering.id = (0..n as u32).collect();
        }
        permute_in_place(&mut self.map.numbering.id, from);
        let d = &mut self.disks;
        permute_in_place(&mut d.motion, from);
        d.radius.permute(from);
        d.mass.permute(from);
        d.species.permute(from);
        permute_in_place(&mut d.counter, from);
        if let Some(spins) = &mut d.spins {
            spins.permute(from);
        }
        self.restitution.permute(from);
        if !self.rest.same_instant.is_empty() {
            permute_in_place(&mut self.rest.same_instant, from);
        }
        if !self.rest.in_cluster.is_empty() {
            permute_in_place(&mut self.rest.in_cluster, from);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_interleaves_bits() {
        assert_eq!(morton(0, 0), 0);
        assert_eq!(morton(1, 0), 1);
        assert_eq!(morton(0, 1), 2);
        assert_eq!(morton(3, 3), 15);
        assert_eq!(morton(u32::MAX, 0), 0x5555_5555_5555_5555);
    }

    #[test]
    fn dense_gases_renumber_less_often_beds_as_dilute_gases() {
        let every = |phi: f64| renumber_every(0.5, phi, false);
        assert_eq!(every(0.3), RENUMBER_EVERY);
        assert_eq!(
            every(0.1),
            RENUMBER_EVERY,
            "never more often than at φ = 0.3"
        );
        assert_eq!(
            every(0.7),
            8 * RENUMBER_EVERY,
            "at most eight times as rarely"
        );
        assert!(every(0.35) > RENUMBER_EVERY && every(0.35) < every(0.4));
        for phi in [0.1, 0.5, 0.7] {
            assert_eq!(renumber_every(0.5, phi, true), RENUMBER_EVERY, "φ = {phi}");
        }
    }
}
