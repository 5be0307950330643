//! The run's clock as another thread reads it while the engine runs — the progress report,
//! which must see a run crawl or freeze between two stops, where the driver does not look. The
//! driver publishes at every stop, whatever the engine; the exact engine also every 1024 turns
//! of its event loop, to the clock installed on its thread by the run that drives it (so that a
//! scheme handing the run to the exact engine publishes through it unchanged).

use std::cell::RefCell;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// One publication: simulated time and collisions, and the wall time they were published at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClockReading {
    pub wall: Instant,
    pub time: f64,
    pub collisions: u64,
}

/// The last publication of a run's clock (see the [module documentation](self)).
#[derive(Debug)]
pub struct PublishedClock(Mutex<ClockReading>);

impl PublishedClock {
    /// A clock at simulated time `time` after `collisions` collisions, published now.
    pub fn new(time: f64, collisions: u64) -> PublishedClock {
        PublishedClock(Mutex::new(ClockReading {
            wall: Instant::now(),
            time,
            collisions,
        }))
    }

    /// Publishes simulated time `time` after `collisions` collisions, now.
    pub fn publish(&self, time: f64, collisions: u64) {
        let reading = ClockReading {
            wall: Instant::now(),
            time,
            collisions,
        };
        *self.0.lock().unwrap_or_else(|e| e.into_inner()) = reading;
    }

    /// The last publication.
    pub fn read(&self) -> ClockReading {
        *self.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Installs `clock` as this thread's (the exact engine publishes to it) until the guard is
    /// dropped.
    pub fn install(clock: Arc<PublishedClock>) -> Installed {
        let before = INSTALLED.with(|c| c.borrow_mut().replace(clock));
        Installed { before }
    }
}

thread_local! {
    /// The clock the exact engine on this thread publishes to, if a run installed one.
    static INSTALLED: RefCell<Option<Arc<PublishedClock>>> = const { RefCell::new(None) };
}

/// Publishes to this thread's installed clock, if any (the exact engine's event loop).
pub(super) fn publish_installed(time: impl FnOnce() -> f64, collisions: u64) {
    INSTALLED.with(|c| {
        if let Some(clock) = c.borrow().as_ref() {
            clock.publish(time(), collisions);
        }
    });
}

/// A clock installed on this thread; dropping it puts back the one before.
#[derive(Debug)]
pub struct Installed {
    before: Option<Arc<PublishedClock>>,
}

impl Drop for Installed {
    fn drop(&mut self) {
        let before = self.before.take();
        INSTALLED.with(|c| *c.borrow_mut() = before);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What is published on a thread with a clock installed is read from another; nothing is
    /// published once the guard is dropped.
    #[test]
    fn the_installed_clock_is_read_across_threads_until_uninstalled() {
        let clock = Arc::new(PublishedClock::new(0.0, 0));
        let guard = PublishedClock::install(Arc::clone(&clock));
        publish_installed(|| 2.5, 40);
        let seen = std::thread::scope(|s| s.spawn(|| clock.read()).join().unwrap());
        assert_eq!((seen.time, seen.collisions), (2.5, 40));
        drop(guard);
        publish_installed(|| 9.0, 99);
        assert_eq!(clock.read().time, 2.5);
    }
}
