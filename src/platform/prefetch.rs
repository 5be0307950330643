//! Asking the memory system early for data the event loop will need (at N ≳ 10⁵ the engine's
//! arrays outgrow the caches, and a disk's anchor or its partner's counter would otherwise
//! each cost a full miss at the moment they are read).

/// Disks from which on the engine gives these hints: below, its arrays fit in the caches and
/// the hints would only cost time (chosen by measurement: the book's performance history has
/// the figures).
pub const PREFETCH_FROM: usize = 8192;

/// Disks from which on, under the local re-mapping, the event loop hints in a pipeline over the
/// next three events (see `Simulation::prefetch_next`) and the calendar keeps that many events
/// ahead in its sorted current bucket
/// ([`CalendarQueue::keeping_ahead`](crate::scheduler::CalendarQueue::keeping_ahead)). Set
/// below [`KEEP_AHEAD_FROM`], where the arrays outgrow the last-level cache: with a disk's
/// motion (both its cache lines) and its shell exit hinted too, scenes of about 10⁵ disks gain
/// already, most when a job on the other core shares the last-level cache (as in the peer
/// benchmark and in sweeps), while smaller ones would lose. Set for whole runs, not for the
/// throughput bench's short stretch right after a renumbering. Chosen by measurement: the
/// book's performance history has the figures.
pub const PIPELINE_FROM: usize = 1 << 16;

/// Disks from which on the calendar keeps events ahead whatever the re-mapping (the scenes of
/// Isobe's global one included, whose event loop does not hint in a pipeline): where every
/// scene's arrays outgrow the last-level cache.
pub const KEEP_AHEAD_FROM: usize = 1 << 18;

/// Hints that entry `i` of `v` will be read soon. Changes nothing but timing; an index out of
/// range is ignored.
///
/// An entry wider than 16 bytes may straddle two cache lines (a disk's 40-byte
/// [`Motion`](crate::physics::disks::Motion) does for half of the disks): its last byte is
/// asked for too, always, since a test of whether the two lines differ would be a branch the
/// predictor cannot learn. Where the arrays outgrow the caches, hinting both lines is clearly
/// faster than hinting the first alone (the book's performance history has the figures).
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
