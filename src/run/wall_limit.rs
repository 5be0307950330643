//! The wall-clock limit of a run (`run.max_wall_seconds`): a watcher thread raises the run's own
//! stop flag once the time is spent (or as soon as a signal raises the process's flag), so that
//! the engine stops within the bounded wall time it stops in for a signal, and the run ends
//! `wall-limit` with its summary, checkpoint and recording.

use crate::output::summary::Ending;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How often the watcher looks at the clock and at the process's stop flag.
const TICK: Duration = Duration::from_millis(20);

/// A running wall-clock limit; the watcher stops when this is dropped.
pub(super) struct WallLimit {
    /// The run's stop flag, which the engine and the driver watch (one per limited run, leaked:
    /// the engines take a `'static` flag).
    stop: &'static AtomicBool,
    /// The process's stop flag (signals), passed on to `stop`.
    signal: Option<&'static AtomicBool>,
    /// Set by the watcher when the time was spent.
    spent: Arc<AtomicBool>,
    /// Set when the run is over: the watcher ends.
    over: Arc<AtomicBool>,
    watcher: Option<JoinHandle<()>>,
}

impl WallLimit {
    /// Starts the watcher: `seconds` of wall time from now, passing `signal` on as it is raised.
    pub(super) fn start(seconds: f64, signal: Option<&'static AtomicBool>) -> WallLimit {
        let stop: &'static AtomicBool = Box::leak(Box::new(AtomicBool::new(false)));
        let spent = Arc::new(AtomicBool::new(false));
        let over = Arc::new(AtomicBool::new(false));
        let deadline = Instant::now() + Duration::from_secs_f64(seconds);
        let (spent_w, over_w) = (Arc::clone(&spent), Arc::clone(&over));
        let watcher = std::thread::spawn(move || {
            while !over_w.load(Ordering::Relaxed) {
                if signal.is_some_and(|f| f.load(Ordering::Relaxed)) {
                    stop.store(true, Ordering::Relaxed);
                }
                let now = Instant::now();
                if now >= deadline {
                    spent_w.store(true, Ordering::Relaxed);
                    stop.store(true, Ordering::Relaxed);
                    return;
                }
                std::thread::sleep(TICK.min(deadline - now));
            }
        });
        WallLimit {
            stop,
            signal,
            spent,
            over,
            watcher: Some(watcher),
        }
    }

    /// The flag the run's engine and driver watch in place of the process's.
    pub(super) fn flag(&self) -> &'static AtomicBool {
        self.stop
    }

    /// How the run ended, told apart: stopped by its flag with the time spent and no signal
    /// is `wall-limit`.
    pub(super) fn ending(&self, ending: Ending) -> Ending {
        let signalled = self.signal.is_some_and(|f| f.load(Ordering::Relaxed));
        if ending == Ending::Interrupted && self.spent.load(Ordering::Relaxed) && !signalled {
            Ending::WallLimit
        } else {
            ending
        }
    }
}

impl Drop for WallLimit {
    fn drop(&mut self) {
        self.over.store(true, Ordering::Relaxed);
        if let Some(w) = self.watcher.take() {
            let _ = w.join();
        }
    }
}
