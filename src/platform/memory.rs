//! Allocator settings for large scenes: glibc gives large freed blocks back to the system, and
//! large blocks are backed by transparent huge pages.

/// Disks from which the allocator is asked to give every large freed block back to the system,
/// and to back large blocks with huge pages.
pub const RETURN_BLOCKS_FROM: usize = 100_000;

/// From [`RETURN_BLOCKS_FROM`] disks on (where memory is what limits a run), every allocation
/// from 128 KiB on gets its own mapping, given back to the system when it is freed. glibc
/// otherwise raises that threshold after the first such block is freed (up to 32 MiB), and then
/// serves the transient arrays of a re-mapping (renumbering's sort keys, the degree count of the
/// neighbour lists) from its heap, where they stay resident after use: about 10 bytes per disk
/// of a million at the peak. Below, the setting is left alone: a fresh mapping for each
/// transient array would slow smaller scenes, whose re-mappings (Isobe's above all) are
/// frequent.
/// Only where glibc is the allocator (Linux); elsewhere nothing changes.
///
/// From the same size on, blocks of [`huge::BLOCK`] and more are backed by transparent huge
/// pages (see [`huge`]).
pub fn for_disks(n: usize) {
    if n < RETURN_BLOCKS_FROM {
        return;
    }
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets an allocator parameter; no allocation is in flight.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 * 1024);
    }
    #[cfg(target_os = "linux")]
    huge::enable();
}

/// Transparent huge pages for large blocks (Linux). The engine reads its per-disk arrays at
/// random: at N = 10⁶ they span about 130 MiB, and with 4 KiB pages nearly every read of
/// another disk's state, list or event also misses the address translation caches. Where the
/// kernel leaves huge pages to the program's request (`madvise`, the default of many
/// distributions), the global allocator [`huge::Allocator`] asks for them for blocks of
/// [`huge::BLOCK`] and more, once [`for_disks`] has enabled it: such blocks are aligned to 2 MiB
/// and marked before their first use (at N = 10⁶ about 100 of the 130 MiB then come on huge
/// pages). Large scenes run faster for it, at the same peak memory (the book's performance
/// history has the figures).
#[cfg(target_os = "linux")]
pub mod huge {
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::sync::atomic::{AtomicBool, Ordering};

    /// A huge page (x86-64, AArch64 with 4 KiB base pages).
    pub const PAGE: usize = 2 << 20;
    /// Blocks from this size on are aligned to [`PAGE`] (whether or not huge pages are
    /// enabled, so that a block's layout never depends on when it was allocated).
    pub const BLOCK: usize = 4 << 20;

    static ENABLED: AtomicBool = AtomicBool::new(false);

    /// From now on, large blocks are marked for huge pages (never turned off: blocks of
    /// other runs in the same process are only marked too).
    pub fn enable() {
        ENABLED.store(true, Ordering::Relaxed);
    }

    /// The system's allocator, but for blocks of [`BLOCK`] bytes and more: aligned to a huge
    /// page and, once [`enable`]d, marked for huge pages before they are used.
    pub struct Allocator;

    /// The layout a large block is allocated with.
    fn aligned(layout: Layout) -> Layout {
        // The size is unchanged and PAGE is a power of two no smaller than any alignment the
        // block asked for, so the layout is valid whenever `layout` is (sizes below isize::MAX
        // rounded up to PAGE: blocks that large cannot be allocated anyway).
        Layout::from_size_align(layout.size(), layout.align().max(PAGE)).unwrap_or(layout)
    }

    /// Marks `size` bytes at `p` (aligned to a huge page) for huge pages, if enabled.
    fn advise(p: *mut u8, size: usize) {
        if !p.is_null() && ENABLED.load(Ordering::Relaxed) {
            // SAFETY: madvise only advises the kernel about a range of the process's own
            // mapped memory (the block just allocated); MADV_HUGEPAGE changes no contents. A
            // failure (huge pages unsupported or off) leaves ordinary pages.
            unsafe {
                libc::madvise(p.cast(), size, libc::MADV_HUGEPAGE);
            }
        }
    }

    // SAFETY: every block is allocated and freed by `System` with one layout: small blocks
    // with the caller's, large ones with `aligned(layout)`, chosen from the size alone (the
    // caller gives the same layout to `dealloc` as to `alloc`).
    unsafe impl GlobalAlloc for Allocator {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            if layout.size() < BLOCK {
                return System.alloc(layout);
            }
            let p = System.alloc(aligned(layout));
            advise(p, layout.size());
            p
        }

        unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
            if layout.size() < BLOCK {
                return System.alloc_zeroed(layout);
            }
            // Marked before it is zeroed (its first use).
            let p = System.alloc(aligned(layout));
            advise(p, layout.size());
            if !p.is_null() {
                std::ptr::write_bytes(p, 0, layout.size());
            }
            p
        }

        unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
            if layout.size() < BLOCK {
                System.dealloc(p, layout)
            } else {
                System.dealloc(p, aligned(layout))
            }
        }

        unsafe fn realloc(&self, p: *mut u8, layout: Layout, size: usize) -> *mut u8 {
            if layout.size() < BLOCK && size < BLOCK {
                return System.realloc(p, layout, size);
            }
            let new = Layout::from_size_align_unchecked(size, layout.align());
            let q = self.alloc(new);
            if !q.is_null() {
                std::ptr::copy_nonoverlapping(p, q, layout.size().min(size));
                self.dealloc(p, layout);
            }
            q
        }
    }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::huge::{enable, BLOCK, PAGE};

    fn aligned<T>(v: &[T]) -> bool {
        (v.as_ptr() as usize).is_multiple_of(PAGE)
    }

    #[test]
    fn large_blocks_are_aligned_to_huge_pages_and_keep_their_contents() {
        enable();
        // Grown across the large-block size: moved to an aligned block, contents kept.
        let mut v: Vec<u32> = (0..1 << 16).collect();
        assert!(v.len() * 4 < BLOCK);
        v.extend(1 << 16..(BLOCK / 2) as u32);
        assert!(aligned(&v), "a grown large block");
        assert!(v.iter().enumerate().all(|(k, &x)| x == k as u32));
        // Shrunk below it: back to an ordinary block, contents kept.
        v.truncate(1000);
        v.shrink_to_fit();
        assert!(v.iter().enumerate().all(|(k, &x)| x == k as u32));
        // Zeroed large blocks are zero.
        let z = vec![0u64; BLOCK];
        assert!(aligned(&z), "a zeroed large block");
        assert!(z.iter().all(|&x| x == 0));
        let mut w = vec![7u8; 3 * BLOCK + 5];
        assert!(aligned(&w));
        w[3 * BLOCK + 4] = 9;
        assert_eq!(
            w.iter().map(|&x| x as usize).sum::<usize>(),
            7 * (3 * BLOCK + 4) + 9
        );
    }
}

/// Stack of a thread that runs a whole run (a local sweep's worker, an accuracy report's seed
/// run side by side with others): what a command's main thread runs one on.
pub const RUN_THREAD_STACK: usize = 16 << 20;

/// Bytes mapped beside each thread's stack (its guard page, signal stack and thread-local
/// storage), with room to spare.
const THREAD_EXTRA: u64 = 1 << 20;

/// Address space kept free for the runs themselves while threads start.
const RUN_ROOM: u64 = 512 << 20;

/// Checks that `threads` new threads with stacks of `stack` bytes fit in this process's address
/// space: under its limit (`RLIMIT_AS`, as `ulimit -v` sets it) beside what it maps now, with
/// room for the runs. A thread started near the limit can have its stack mapped and then fail
/// to map its signal stack, and the runtime aborts the whole process (a refusal is not
/// possible then): so none is started where they would not all fit. `Err` gives the limit in
/// bytes. Without a limit (or off Linux), always `Ok`.
pub fn threads_fit(threads: usize, stack: usize) -> Result<(), u64> {
    #[cfg(target_os = "linux")]
    {
        let mut limit = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        // SAFETY: getrlimit writes the one struct it is given.
        if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut limit) } != 0
            || limit.rlim_cur == libc::RLIM_INFINITY
        {
            return Ok(());
        }
        let limit = limit.rlim_cur;
        let need = (threads as u64).saturating_mul(stack as u64 + THREAD_EXTRA);
        if mapped_bytes().saturating_add(need).saturating_add(RUN_ROOM) > limit {
            return Err(limit);
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = (threads, stack);
    Ok(())
}

/// Bytes of address space this process maps now (`/proc/self/statm`'s first field, in pages);
/// 0 where it cannot be read.
#[cfg(target_os = "linux")]
fn mapped_bytes() -> u64 {
    let pages = std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .unwrap_or(0);
    // SAFETY: sysconf only reads a system constant.
    let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    pages.saturating_mul(page.max(4096) as u64)
}

/// The message of a refusal to start `threads` threads (`what`, e.g. "runs at once, a thread
/// each") under an address-space limit of `limit` bytes.
pub fn threads_refused(threads: usize, what: &str, limit: u64) -> String {
    format!(
        "cannot start {threads} {what} under this process's address-space limit of {:.1} GiB \
         (ulimit -v): give fewer",
        limit as f64 / (1u64 << 30) as f64
    )
}
