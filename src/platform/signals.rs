//! Signals that stop a run: SIGINT (Ctrl-C), SIGTERM (a batch system at its time limit) and
//! SIGHUP (a closed terminal) all set one stop flag, which the engines and the drivers watch; the
//! run then ends cleanly (summary marked interrupted, recording closed, checkpoint written).
//! While the command line's run is still building its scene ([`building`] until [`built`]),
//! nothing watches the flag yet and nothing is written: a signal then ends the process at once.

use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::sync::{Arc, LazyLock};

/// Set by SIGINT, SIGTERM or SIGHUP: the run stops at the next event (or stop) and ends cleanly.
static INTERRUPTED: LazyLock<Arc<AtomicBool>> = LazyLock::new(|| Arc::new(AtomicBool::new(false)));

/// The signal that stopped the run (0: none).
static SIGNAL: LazyLock<Arc<AtomicI32>> = LazyLock::new(|| Arc::new(AtomicI32::new(0)));

/// Set from [`building`] to [`built`]: the command line's one run is placing its disks and
/// building its engine (grid, neighbour lists, first predictions), which takes seconds per
/// million disks and opens no output.
static BUILDING: LazyLock<Arc<AtomicBool>> = LazyLock::new(|| Arc::new(AtomicBool::new(false)));

/// What a signal during [`building`] prints before the process ends.
const STOPPED_BUILDING: &[u8] =
    b"vibrobed: interrupted while the scene was built, before its first event: nothing run, \
      nothing written\n";

/// The command line's run starts building its scene: until [`built`], a stop signal ends the
/// process at once (exit 128 + the signal, a line on stderr, nothing written) instead of after
/// the build. Only for a process with one run and nothing of its own to finish (`run`,
/// `resume`).
pub fn building() {
    BUILDING.store(true, Ordering::SeqCst);
}

/// The run's engine is built and watches the stop flag: a signal stops it cleanly from here.
/// Called before any output is opened.
pub fn built() {
    BUILDING.store(false, Ordering::SeqCst);
}

/// Ends the process on `sig` if the run is still [`building`]: registered before every other
/// action, so that nothing else is done first.
fn exit_if_building(sig: i32) {
    let building = Arc::clone(&BUILDING);
    // SAFETY: the action loads an atomic, writes a static buffer to stderr with write(2) and
    // calls _exit(2), all async-signal-safe.
    let _ = unsafe {
        signal_hook::low_level::register(sig, move || {
            if building.load(Ordering::SeqCst) {
                #[cfg(target_os = "linux")]
                libc::write(2, STOPPED_BUILDING.as_ptr().cast(), STOPPED_BUILDING.len());
                signal_hook::low_level::exit(128 + sig);
            }
        })
    };
}

/// Handles SIGINT (Ctrl-C), SIGTERM (batch systems at their time limit) and SIGHUP (a closed
/// terminal) alike: the first asks the run to stop cleanly; a second SIGINT ends the process at
/// once (exit 130), for a user who does not want to wait. SIGXFSZ (a file grown past the
/// process's size limit, `ulimit -f`) is caught and does nothing, so that the write fails with
/// EFBIG and the run handles it as any other failure to write, instead of being killed.
pub fn install() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM, SIGXFSZ};
    // SAFETY: the action does nothing, which is async-signal-safe.
    let _ = unsafe { signal_hook::low_level::register(SIGXFSZ, || {}) };
    for sig in [SIGINT, SIGTERM, SIGHUP] {
        exit_if_building(sig);
        if sig == SIGINT {
            // Registered first, so it sees the flag as it was before this signal.
            let _ = signal_hook::flag::register_conditional_shutdown(
                sig,
                130,
                Arc::clone(&INTERRUPTED),
            );
        }
        let _ = signal_hook::flag::register(sig, Arc::clone(&INTERRUPTED));
        let which = Arc::clone(&SIGNAL);
        // SAFETY: the action only stores into an atomic, which is async-signal-safe.
        let _ = unsafe {
            signal_hook::low_level::register(sig, move || {
                which.store(sig, Ordering::Relaxed);
            })
        };
    }
}

/// The flag the engine watches, as a `'static` reference.
pub fn stop_flag() -> &'static AtomicBool {
    &INTERRUPTED
}

/// Exit code of an interrupted run: 128 + the signal's number (130 SIGINT, 143 SIGTERM,
/// 129 SIGHUP).
pub fn exit_code() -> i32 {
    match SIGNAL.load(Ordering::Relaxed) {
        0 => 130,
        sig => 128 + sig,
    }
}
