//! Asking the memory system early for data the event loop will need (at N ≳ 10⁵ the engine's
//! arrays outgrow the caches, and a disk's anchor or its partner's counter would otherwise
//! each cost a full miss at the moment they are read).

/// Disks from which on the engine gives these hints: below, its arrays fit in the caches and
/// the hints would only cost (measured: 2% at N = 2500).
pub const PREFETCH_FROM: usize = 8192;

/// Disks from which on, under the local re-mapping, the event loop hints in a pipeline over the
/// next three events (see `Simulation::prefetch_next`) and the calendar keeps that many events
/// ahead in its sorted current bucket: where the arrays outgrow the last-level cache (32 MiB
/// here, about 2.5·10⁵ disks). Measured (in-run, alternated pairs): N = 10⁶ 1.06–1.08× (φ 0.7,
/// two builds) and 1.026× (φ 0.3); at N = 10⁵, whose arrays are cached, 0.96× and 0.97×.
pub const PIPELINE_FROM: usize = 1 << 18;

/// Hints that entry `i` of `v` will be read soon. Changes nothing but timing; an index out of
/// range is ignored.
///
/// An entry wider than 16 bytes may straddle two cache lines (a disk's 40-byte
/// [`Motion`](crate::disks::Motion) does for half of the disks): its last byte is asked for
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
