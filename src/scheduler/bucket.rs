//! The calendar's current bucket: its entries, and where each goes when a short bucket is
//! sorted — its place is the number of entries later than it (the keys differ), counted without
//! a branch, one comparison at a time or four lanes at a time where the processor has AVX2
//! (chosen at run time, [`Lanes`]). Both count the same comparisons, so the order is the same on
//! either path (a test compares them).

use crate::platform::cpu::Lanes;
use serde::{Deserialize, Serialize};

/// Length up to which the current bucket is searched and sorted entry by entry (beyond, by
/// bisection and a library sort: a bucket of many events at one time stays O(h log h)).
pub(super) const SHORT: usize = 16;

/// One event of the current bucket: its time, the disk's place in the tree's order, the disk.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub(super) struct Entry {
    pub(super) t: f64,
    pub(super) rank: u32,
    pub(super) disk: u32,
}

impl Entry {
    /// Earlier time first; equal times in the tree's order. Without a branch (`|`, `&`): which
    /// of two events is earlier is a toss-up, and a branch on each half of it mispredicts.
    #[inline(always)]
    pub(super) fn before(&self, other: &Entry) -> bool {
        (self.t < other.t) | ((self.t == other.t) & (self.rank < other.rank))
    }
}

/// Each entry's place in the order latest first (`current.len() <= SHORT`, keys distinct):
/// the number of entries later than it.
#[inline(always)]
pub(super) fn places(current: &[Entry], lanes: Lanes) -> [u8; SHORT] {
    debug_assert!(current.len() <= SHORT);
    #[cfg(target_arch = "x86_64")]
    if lanes.avx2() {
        // SAFETY: the four lanes are chosen only where the processor has AVX2.
        return unsafe { places_avx2(current) };
    }
    let _ = lanes;
    places_one_by_one(current)
}

/// [`places`] one comparison at a time: each pair is compared once, and its outcome counts
/// for one of the two; every comparison is made, none decides a branch.
fn places_one_by_one(current: &[Entry]) -> [u8; SHORT] {
    let mut place = [0u8; SHORT];
    for (k, e) in current.iter().enumerate() {
        for (m, other) in current.iter().enumerate().skip(k + 1) {
            let later = e.before(other) as u8;
            place[k] += later;
            place[m] += 1 - later;
        }
    }
    place
}

/// [`places`] four entries at a time: each entry against all (itself included: never before
/// itself), as [`Entry::before`] compares them — the time, then the tree's rank, exact as an
/// `f64` — and the later ones counted from the lanes' mask. The lanes past the bucket hold
/// +∞, which every entry is before (a filed event's time is finite); they are taken off the
/// count.
///
/// # Safety
///
/// Only where the processor has AVX2.
#[cfg(target_arch = "x86_64")]
#[cfg_attr(target_feature = "avx2", inline(always))]
#[cfg_attr(not(target_feature = "avx2"), target_feature(enable = "avx2"), inline)]
unsafe fn places_avx2(current: &[Entry]) -> [u8; SHORT] {
    use std::arch::x86_64::*;
    let mut time = [f64::INFINITY; SHORT];
    let mut rank = [0.0; SHORT];
    for (k, e) in current.iter().enumerate() {
        time[k] = e.t;
        rank[k] = e.rank as f64;
    }
    // Two groups of four cover most buckets; four cover the rest.
    let groups = if current.len() <= 8 { 2 } else { 4 };
    let pads = (4 * groups - current.len()) as u32;
    let lanes = |v: &[f64; SHORT], g: usize| _mm256_loadu_pd(v[4 * g..4 * g + 4].as_ptr());
    let times: [__m256d; 4] = std::array::from_fn(|g| lanes(&time, g));
    let ranks: [__m256d; 4] = std::array::from_fn(|g| lanes(&rank, g));
    let mut place = [0u8; SHORT];
    for (k, p) in place.iter_mut().enumerate().take(current.len()) {
        let (t, r) = (_mm256_set1_pd(time[k]), _mm256_set1_pd(rank[k]));
        let mut later = 0u32;
        for g in 0..groups {
            let earlier = _mm256_cmp_pd::<_CMP_LT_OQ>(t, times[g]);
            let tie = _mm256_cmp_pd::<_CMP_EQ_OQ>(t, times[g]);
            let first = _mm256_cmp_pd::<_CMP_LT_OQ>(r, ranks[g]);
            let before = _mm256_or_pd(earlier, _mm256_and_pd(tie, first));
            later |= (_mm256_movemask_pd(before) as u32) << (4 * g);
        }
        *p = (later.count_ones() - pads) as u8;
    }
    place
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// Both paths give every bucket length the same places, which are the order latest first,
    /// with ties of time broken by rank.
    #[test]
    fn both_paths_give_the_order() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        for round in 0..20_000 {
            let len = round % (SHORT + 1);
            let mut ranks: Vec<u32> = (0..40).collect();
            let current: Vec<Entry> = (0..len)
                .map(|_| {
                    let rank = ranks.swap_remove(rng.random_range(0..ranks.len()));
                    // Few distinct times in some rounds: ties abound.
                    let t = if round % 3 == 0 {
                        rng.random_range(0..3) as f64 * 0.5
                    } else {
                        rng.random::<f64>() * 1e3
                    };
                    Entry {
                        t,
                        rank,
                        disk: rank + 100,
                    }
                })
                .collect();
            let one = places_one_by_one(&current);
            let mut expect: Vec<usize> = (0..len).collect();
            expect.sort_by(|&a, &b| {
                let (x, y) = (&current[a], &current[b]);
                (y.t, y.rank).partial_cmp(&(x.t, x.rank)).unwrap()
            });
            for (p, &k) in expect.iter().enumerate() {
                assert_eq!(one[k] as usize, p, "round {round}: entry {k}");
            }
            assert_eq!(one, places(&current, Lanes::widest()), "round {round}");
        }
    }
}
