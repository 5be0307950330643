use clap::Parser;

fn main() {
    return_large_blocks_to_the_system();
    let cli = vibrobed::cli::Cli::parse();
    std::process::exit(vibrobed::cli::main_with(cli));
}

/// Every allocation from 128 KiB on gets its own mapping, given back to the system when it is
/// freed. glibc otherwise raises that threshold after the first such block is freed (up to 32
/// MiB), and then serves the transient arrays of a re-mapping (renumbering's sort keys, the
/// degree count of the neighbour lists) from its heap, where they stay resident after use:
/// about 10 bytes per disk of a million at the peak. The event loop allocates nothing, so the
/// fixed threshold costs it nothing.
fn return_large_blocks_to_the_system() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets an allocator parameter, before any thread is started.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 * 1024);
    }
}
