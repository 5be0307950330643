//! What a run tells the user on stderr while it goes: a progress bar on a terminal (elapsed
//! wall time, ETA, simulated time over the duration, collisions per second), one start line and
//! one end line otherwise (logs of batch jobs), nothing with `--quiet`. Both forms end with the
//! run's ending: completed, interrupted or stopped by the event limit, at which simulated time.

use std::io::IsTerminal;
use std::time::Instant;

use crate::output::summary::Ending;

/// How progress is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgressMode {
    /// Nothing (`--quiet`).
    Quiet,
    /// A bar redrawn in place (stderr is a terminal).
    Bar,
    /// One line at the start, one at the end (stderr is a file or a pipe).
    Lines,
}

impl ProgressMode {
    /// `Quiet` unless `show`; then `Bar` when stderr is a terminal, else `Lines`.
    pub fn for_stderr(show: bool) -> ProgressMode {
        if !show {
            ProgressMode::Quiet
        } else if std::io::stderr().is_terminal() {
            ProgressMode::Bar
        } else {
            ProgressMode::Lines
        }
    }
}

/// Collisions per second in a short form: `850`, `12.3k`, `4.56M`.
fn rate(per_second: f64) -> String {
    if per_second >= 1e6 {
        format!("{:.2}M", per_second / 1e6)
    } else if per_second >= 1e3 {
        format!("{:.1}k", per_second / 1e3)
    } else {
        format!("{per_second:.0}")
    }
}

/// Progress of one run (see the [module documentation](self)).
#[derive(Debug)]
pub struct ProgressReport {
    mode: ProgressMode,
    bar: Option<indicatif::ProgressBar>,
    duration: f64,
    clock: Instant,
}

/// Bar resolution: positions per run.
const STEPS: u64 = 10_000;

impl ProgressReport {
    /// Starts reporting a run of `duration` simulated time units of scene `name` with `disks`
    /// disks (prints the start line in `Lines` mode).
    pub fn start(mode: ProgressMode, name: &str, disks: usize, duration: f64) -> ProgressReport {
        let bar = (mode == ProgressMode::Bar).then(|| {
            let bar = indicatif::ProgressBar::new(STEPS);
            bar.set_style(
                indicatif::ProgressStyle::with_template(
                    "{spinner} {elapsed_precise} [{bar:30}] {percent:>3}% ETA {eta_precise} {msg}",
                )
                .expect("valid template")
                .progress_chars("=> "),
            );
            bar.enable_steady_tick(std::time::Duration::from_millis(250));
            bar
        });
        if mode == ProgressMode::Lines {
            eprintln!("vibrobed: running {name}: {disks} disks, {duration} time units");
        }
        ProgressReport {
            mode,
            bar,
            duration,
            clock: Instant::now(),
        }
    }

    /// The run has reached simulated time `t` after `collisions` collisions.
    pub fn update(&self, t: f64, collisions: u64) {
        if let Some(bar) = &self.bar {
            let elapsed = self.clock.elapsed().as_secs_f64().max(1e-9);
            bar.set_position((STEPS as f64 * t / self.duration).clamp(0.0, STEPS as f64) as u64);
            bar.set_message(format!(
                "t {t:.2}/{} · {} coll/s",
                self.duration,
                rate(collisions as f64 / elapsed)
            ));
        }
    }

    /// The run ended (`ending` at simulated time `t`, after `collisions` collisions): clears the
    /// bar and prints the end line (in `Bar` and `Lines` modes).
    pub fn finish(self, ending: Ending, t: f64, collisions: u64) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
        if self.mode == ProgressMode::Quiet {
            return;
        }
        let wall = self.clock.elapsed().as_secs_f64();
        let how = match ending {
            Ending::Completed => "completed",
            Ending::Interrupted => "interrupted",
            Ending::EventLimit => "stopped by the event limit",
            Ending::Stalled => "stopped: simulated time stalled",
        };
        eprintln!(
            "vibrobed: {how} at t = {t} of {} in {wall:.1} s: {collisions} collisions ({}/s)",
            self.duration,
            rate(collisions as f64 / wall.max(1e-9))
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_are_short() {
        assert_eq!(rate(850.4), "850");
        assert_eq!(rate(12_345.0), "12.3k");
        assert_eq!(rate(4_561_000.0), "4.56M");
    }

    #[test]
    fn quiet_unless_asked() {
        assert_eq!(ProgressMode::for_stderr(false), ProgressMode::Quiet);
        assert_ne!(ProgressMode::for_stderr(true), ProgressMode::Quiet);
    }
}
