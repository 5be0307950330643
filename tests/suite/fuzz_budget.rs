//! How many of their cases the fuzzers on the binary (`fuzz_commands`, `fuzz_fields`) try: each
//! runs its cases in a fixed order until its time budget is spent. `VIBROBED_FUZZ_SECONDS=S`
//! gives each fuzzer S seconds; `VIBROBED_FUZZ_SECONDS=all` runs every case (tens of minutes: see
//! the book's contributing page). Each says how many of its cases it ran, on stderr and, when
//! `VIBROBED_FUZZ_LOG` names a file, in a line appended to it (CI prints that file: the share a
//! run of the suite tried is stated in its log).

use std::io::Write as _;
use std::time::{Duration, Instant};

/// How long a fuzzer goes on.
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    start: Instant,
    /// `None`: every case.
    seconds: Option<Duration>,
}

impl Budget {
    /// From `VIBROBED_FUZZ_SECONDS`, else `default` seconds; counted from now.
    pub fn from_env(default: u64) -> Budget {
        let seconds = match std::env::var("VIBROBED_FUZZ_SECONDS") {
            Ok(text) if text.trim() == "all" => None,
            Ok(text) => Some(text.trim().parse().unwrap_or_else(|_| {
                panic!("VIBROBED_FUZZ_SECONDS={text} is neither a number of seconds nor `all`")
            })),
            Err(_) => Some(default),
        };
        Budget {
            start: Instant::now(),
            seconds: seconds.map(Duration::from_secs),
        }
    }

    /// Whether the budget is spent (never, for every case).
    pub fn spent(&self) -> bool {
        self.seconds.is_some_and(|s| self.start.elapsed() > s)
    }

    /// Says that `name` ran `ran` of its `total` cases (`detail`: their exit codes), on stderr
    /// and in `VIBROBED_FUZZ_LOG`.
    pub fn report(&self, name: &str, ran: usize, total: usize, detail: &str) {
        let budget = self.seconds.map_or("every case".to_string(), |s| {
            format!("budget {} s", s.as_secs())
        });
        let line = format!(
            "{name}: {ran} of {total} cases ({:.0}%) in {:.0} s ({budget}): {detail}",
            100.0 * ran as f64 / total.max(1) as f64,
            self.start.elapsed().as_secs_f64()
        );
        eprintln!("{line}");
        if let Ok(path) = std::env::var("VIBROBED_FUZZ_LOG") {
            let file = std::fs::OpenOptions::new()
                .create(true)
                .append(true)
                .open(&path);
            if let Ok(mut file) = file {
                let _ = writeln!(file, "{line}");
            }
        }
    }
}
