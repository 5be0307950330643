//! Allocator settings for large scenes.

/// Disks from which the allocator is asked to give every large freed block back to the system.
pub const RETURN_BLOCKS_FROM: usize = 100_000;

/// From [`RETURN_BLOCKS_FROM`] disks on (where memory is what limits a run), every allocation
/// from 128 KiB on gets its own mapping, given back to the system when it is freed. glibc
/// otherwise raises that threshold after the first such block is freed (up to 32 MiB), and then
/// serves the transient arrays of a re-mapping (renumbering's sort keys, the degree count of the
/// neighbour lists) from its heap, where they stay resident after use: about 10 bytes per disk
/// of a million at the peak. Below, the setting is left alone: fresh mappings cost smaller
/// scenes a few per cent (measured on a 20 000-disk bed, whose Isobe re-mappings are frequent).
/// Only where glibc is the allocator (Linux); elsewhere nothing changes.
pub fn for_disks(n: usize) {
    if n < RETURN_BLOCKS_FROM {
        return;
    }
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets an allocator parameter; no allocation is in flight.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 * 1024);
    }
}
