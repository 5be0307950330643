//! Long work off the interpreter: the engine runs on its own thread with the GIL released, while
//! the calling thread wakes every [`POLL`] to let Python handle its signals. Ctrl-C (a
//! `KeyboardInterrupt`, or a notebook's interrupt) sets the run's stop flag: the engine stops at
//! its next event and ends as the command line does on SIGINT, its result marked interrupted.

use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError};
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::Mutex;
use std::time::Duration;

/// How often the waiting thread looks at Python's signals: well within the second a user waits.
pub const POLL: Duration = Duration::from_millis(50);

/// Stack of the engine's thread, as a sweep's workers have (deep scenes recurse in set-up).
pub const STACK: usize = 16 << 20;

/// A fresh stop flag for one run. The engine takes a `'static` flag (the command line's is the
/// signal handler's); each run leaks its own, one byte.
pub fn stop_flag() -> &'static AtomicBool {
    Box::leak(Box::new(AtomicBool::new(false)))
}

/// Runs `work` on a thread of its own with the GIL released and returns what it returns. A
/// `KeyboardInterrupt` while it runs raises `stop` and is then absorbed: the work ends early and
/// its (interrupted) result is returned. Another exception from a signal handler also raises
/// `stop`, and is raised once the work has ended.
pub fn run<T: Send>(
    py: Python<'_>,
    stop: &AtomicBool,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    let (tx, rx) = mpsc::channel();
    let rx = Mutex::new(rx);
    std::thread::scope(|scope| {
        std::thread::Builder::new()
            .name("vibrobed".into())
            .stack_size(STACK)
            .spawn_scoped(scope, move || {
                let _ = tx.send(work());
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start the run's thread: {e}")))?;
        let mut raised: Option<PyErr> = None;
        loop {
            let got = py.detach(|| rx.lock().expect("one waiter").recv_timeout(POLL));
            match got {
                Ok(out) => return raised.map_or(Ok(out), Err),
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(PyRuntimeError::new_err(
                        "the run's thread ended without a result",
                    ))
                }
                Err(RecvTimeoutError::Timeout) => {}
            }
            if let Err(e) = py.check_signals() {
                stop.store(true, Ordering::Relaxed);
                if !e.is_instance_of::<PyKeyboardInterrupt>(py) && raised.is_none() {
                    raised = Some(e);
                }
            }
        }
    })
}
