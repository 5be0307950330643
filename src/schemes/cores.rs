//! The cores an approximate scheme runs on (`engine.threads`): a rayon pool of its own, so that
//! a scheme never competes with another run's threads in the same process (tests, the accuracy
//! study) and a sweep can give each job its share of the machine.
//!
//! The parallel loops split disks or pairs among the threads (ReMoDy's multi-core loops) but
//! never let the split reach a result: each thread writes only what belongs to its own disks or
//! pairs, and everything that adds floating-point numbers or changes two disks at once (a
//! collision, a bounce, the energy budget) is applied afterwards in a fixed order. The results
//! are the same bit for bit whatever the number of threads.

use crate::error::{Error, Result};
use crate::scenario::{Scenario, Scheme};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

/// Work items (disks, pairs or rows of cells) below which a loop is not split: smaller pieces
/// cost more to hand to another thread than to do (a scene of 10³ disks runs on one thread).
pub const MIN_PIECE: usize = 1024;

/// Stack of each thread of a scheme's pool (the standard library's default, set here so that
/// the room the threads take is known before they start).
pub const POOL_STACK: usize = 2 << 20;

/// The threads of one scheme.
#[derive(Debug, Clone)]
pub struct Cores {
    pool: Arc<rayon::ThreadPool>,
}

impl Cores {
    /// A pool of `requested` threads (absent: [`available`]).
    pub fn new(requested: Option<u64>) -> Result<Cores> {
        let threads = requested.map_or_else(available, |t| t as usize);
        crate::platform::memory::threads_fit(threads, POOL_STACK).map_err(|limit| {
            Error::input(
                "engine.threads",
                crate::platform::memory::threads_refused(threads, "threads", limit),
            )
        })?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .stack_size(POOL_STACK)
            .thread_name(|i| format!("vibrobed-scheme-{i}"))
            .build()
            .map_err(|e| {
                Error::input(
                    "engine.threads",
                    format!("cannot start {threads} threads: {e}"),
                )
            })?;
        Ok(Cores {
            pool: Arc::new(pool),
        })
    }

    /// Number of threads.
    pub fn count(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// Runs `op` with its parallel loops on this pool.
    pub fn run<R: Send>(&self, op: impl FnOnce() -> R + Send) -> R {
        self.pool.install(op)
    }
}

/// Works out `pieces` pieces (`work(k)`) on every thread of the current pool and hands their
/// results to `consume` in the order of `k` on the calling thread, as soon as each is done: the
/// calling thread applies what the others find while they are still finding it, instead of
/// waiting for all of it (and the others do not fall asleep between the two). Pieces are taken
/// in order by whichever thread is free, the calling one included whenever the next result it
/// needs is not done yet; `consume` sees the same results in the same order on any number of threads.
pub fn in_order<T: Send + Sync>(
    pieces: usize,
    work: impl Fn(usize) -> T + Sync,
    mut consume: impl FnMut(&T),
) {
    let next = AtomicUsize::new(0);
    let done: Vec<OnceLock<T>> = (0..pieces).map(|_| OnceLock::new()).collect();
    // Takes the next piece not yet taken and works it out; false when none is left.
    let take = || {
        let k = next.fetch_add(1, Ordering::Relaxed);
        let left = k < pieces;
        if left {
            let _ = done[k].set(work(k));
        }
        left
    };
    rayon::in_place_scope(|s| {
        for _ in 1..rayon::current_num_threads().min(pieces) {
            s.spawn(|_| while take() {});
        }
        for piece in &done {
            let mut spins = 0u32;
            let result = loop {
                if let Some(result) = piece.get() {
                    break result;
                }
                // Another thread is working this piece out: take a later one meanwhile.
                if next.load(Ordering::Relaxed) < pieces && take() {
                    continue;
                }
                if spins < 1 << 12 {
                    spins += 1;
                    std::hint::spin_loop();
                } else {
                    std::thread::yield_now();
                }
            };
            consume(result);
        }
    });
}

/// The cores this process may use: the machine's, or fewer where an affinity mask or a cgroup
/// quota (a container, a Slurm allocation) says so, and at most `SLURM_CPUS_PER_TASK` inside a
/// Slurm task (where the cluster binds no affinity, the machine's count would oversubscribe).
pub fn available() -> usize {
    let here = std::thread::available_parallelism().map_or(1, |n| n.get());
    let slurm = std::env::var("SLURM_CPUS_PER_TASK")
        .ok()
        .and_then(|v| v.trim().parse::<usize>().ok())
        .filter(|&n| n > 0);
    slurm.map_or(here, |n| n.min(here))
}

/// `scenario` as one of `jobs` runs at once on `cores` cores: an approximate scheme that does not
/// set `engine.threads` gets an equal share of the cores (at least one), so that the runs
/// together use the cores once over; the exact engine (one core) and an explicit
/// `engine.threads` are left as they are.
pub fn share(scenario: &Scenario, jobs: usize, cores: usize) -> Scenario {
    let mut s = scenario.clone();
    if s.scheme() != Scheme::EventDriven && s.engine.threads.is_none() {
        s.engine.threads = Some((cores / jobs.max(1)).max(1) as u64);
    }
    s
}
