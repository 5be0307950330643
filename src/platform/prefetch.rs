//! Asking the memory system early for data the event loop will need (at N ≳ 10⁵ the engine's
//! arrays outgrow the caches, and a disk's anchor or its partner's counter would otherwise
//! each cost a full miss at the moment they are read).

/// Disks from which on the engine gives these hints: below, its arrays fit in the caches and
/// the hints would only cost (measured: 2% at N = 2500).
pub const PREFETCH_FROM: usize = 8192;

/// Disks from which on, under the local re-mapping, the event loop hints in a pipeline over the
/// next three events (see `Simulation::prefetch_next`) and the calendar keeps that many events
/// ahead in its sorted current bucket
/// ([`CalendarQueue::keeping_ahead`](crate::scheduler::CalendarQueue::keeping_ahead)). At
/// first from 2¹⁸ disks, where the arrays outgrow the last-level cache (32 MiB here): at
/// N = 10⁶ 1.06–1.08× (φ 0.7) and 1.026× (φ 0.3), at N = 10⁵ 0.96× and 0.97× then. With the
/// hints since (two cache lines of a disk's motion, shell exits), N = 10⁵ gains too, most when
/// the other core runs a job of its own (which then shares the last-level cache, as in the
/// peer benchmark and in sweeps): in-run collisions per second, alternated runs, against the
/// pipeline from 2¹⁸ on — N = 10⁵ 1.21× (φ 0.3) and 1.15× (φ 0.7) beside a peer run on the
/// other core, 1.11× and 1.00× alone (1.19× at φ 0.3 over 25 time units in another series,
/// 1.04× over 3); N = 7·10⁴ 1.00× either way; N = 3·10⁴ and 5·10⁴ 0.93–0.95×. The throughput
/// bench, which measures right after its melt (the disks freshly renumbered), disagrees at
/// N = 10⁵: 0.94× (φ 0.3) and 0.90× (φ 0.7); whole runs are what this is set for.
pub const PIPELINE_FROM: usize = 1 << 16;

/// Disks from which on the calendar keeps events ahead whatever the re-mapping (the scenes of
/// Isobe's global one included, whose event loop does not hint in a pipeline): where every
/// scene's arrays outgrow the last-level cache.
pub const KEEP_AHEAD_FROM: usize = 1 << 18;

/// Hints that entry `i` of `v` will be read soon. Changes nothing but timing; an index out of
/// range is ignored.
///
/// An entry wider than 16 bytes may straddle two cache lines (a disk's 40-byte
/// [`Motion`](crate::physics::disks::Motion) does for half of the disks): its last byte is asked for
/// too, always (a test of whether the two lines differ is a branch the predictor cannot learn:
/// measured 0.73× at N = 10⁵). Measured against hinting the first line alone (in-run
/// collisions per second, alternated runs, the same events): N = 10⁶ 1.26× at φ 0.7 (3/3)
/// and 1.13× at φ 0.3 (3/3); N = 10⁵ 1.06× at φ 0.7, φ 0.3 within the noise.
#[inline(always)]
pub fn prefetch<T>(v: &[T], i: usize) {
    #[cfg(target_arch = "x86_64")]
    if let Some(entry) = v.get(i) {
        // SAFETY: a prefetch only hints the cache; it never faults or changes memory, and the
        // address is that of a live entry.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let first = entry as *const T as *const i8;
            _mm_prefetch::<_MM_HINT_T0>(first);
            // The entry's last byte: the same line or the next (the pointer stays within `v`).
            if std::mem::size_of::<T>() > 16 {
                _mm_prefetch::<_MM_HINT_T0>(first.add(std::mem::size_of::<T>() - 1));
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (v, i);
}
