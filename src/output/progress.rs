//! What a run tells the user on stderr while it goes: a progress bar on a terminal (elapsed
//! wall time, ETA, simulated time over the duration, collisions per second); otherwise (logs of
//! batch jobs) one start line, a line every `--progress-every` seconds (simulated time,
//! collisions per second, the wall time to go) and one end line; nothing with `--quiet`. Both
//! forms end with the run's ending, at which simulated time; both say once when the run's wall
//! time per unit of simulated time has grown far above its start (a bed freezing into a
//! collapse), naming the cures.

use std::cell::Cell;
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
    /// One line at the start, one every few seconds, one at the end (stderr is a file or a
    /// pipe).
    Lines,
    /// Only the lines every few seconds, each named (a sweep's run in a log: the sweep says
    /// when each run starts and ends).
    Periodic,
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

/// Default wall seconds between progress lines off a terminal.
pub const DEFAULT_EVERY: f64 = 60.0;

/// How many times its start's wall time per unit of simulated time a run may come to cost before
/// the note on a freezing bed.
const COST_GROWTH: f64 = 10.0;

/// Progress of one run (see the [module documentation](self)).
#[derive(Debug)]
pub struct ProgressReport {
    mode: ProgressMode,
    bar: Option<indicatif::ProgressBar>,
    duration: f64,
    clock: Instant,
    /// Wall seconds between lines (and between the cost's readings).
    every: f64,
    /// What the lines are named (`Periodic`: the sweep's run).
    label: String,
    /// The last reading: wall seconds, simulated time, collisions.
    last: Cell<(f64, f64, u64)>,
    /// The cost per unit of simulated time, against its start's.
    cost: Cell<CostWatch>,
}

/// Watches a run's wall time per unit of simulated time, reading by reading: the first
/// reading's is the start's; the first later one above [`COST_GROWTH`] times it gives the note
/// (once) on a bed freezing into a collapse, naming the cures.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CostWatch {
    /// Wall time per unit of simulated time over the first reading, once taken.
    start: Option<f64>,
    /// The note was given.
    noted: bool,
}

impl CostWatch {
    /// Takes a reading (`cost` wall seconds per unit of simulated time over the last interval,
    /// which ended at simulated time `t`); returns the note when it is due, once per run.
    pub fn read(&mut self, t: f64, cost: f64) -> Option<String> {
        if !(cost.is_finite() && cost > 0.0) {
            return None;
        }
        let Some(start) = self.start else {
            self.start = Some(cost);
            return None;
        };
        if cost <= COST_GROWTH * start || self.noted {
            return None;
        }
        self.noted = true;
        Some(format!(
            "at t = {t:.6} a unit of simulated time costs {:.0} times the wall time it cost at \
             the start: the bed may be freezing into an inelastic collapse (or a pile rattling \
             without coming to rest); cures: collisions.tc (the TC model, 10⁻³ √(d/g) is a good \
             start) or collisions.speed_cutoff, and run.max_wall_seconds to bound the run (see \
             the book's page Stability models and hard cases)",
            cost / start
        ))
    }
}

/// Bar resolution: positions per run.
const STEPS: u64 = 10_000;

impl ProgressReport {
    /// Starts reporting a run of `duration` simulated time units of scene `name` with `disks`
    /// disks, a line (or a reading of the cost) every `every` wall seconds (prints the start
    /// line in `Lines` mode; `Periodic` lines are named `name`).
    pub fn start(
        mode: ProgressMode,
        name: &str,
        disks: usize,
        duration: f64,
        every: f64,
    ) -> ProgressReport {
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
            every,
            label: name.to_string(),
            last: Cell::new((0.0, 0.0, 0)),
            cost: Cell::new(CostWatch::default()),
        }
    }

    /// The run has reached simulated time `t` after `collisions` collisions.
    pub fn update(&self, t: f64, collisions: u64) {
        if self.mode == ProgressMode::Quiet {
            return;
        }
        let elapsed = self.clock.elapsed().as_secs_f64().max(1e-9);
        if let Some(bar) = &self.bar {
            bar.set_position((STEPS as f64 * t / self.duration).clamp(0.0, STEPS as f64) as u64);
            bar.set_message(format!(
                "t {t:.2}/{} · {} coll/s",
                self.duration,
                rate(collisions as f64 / elapsed)
            ));
        }
        let (wall0, t0, collisions0) = self.last.get();
        if elapsed - wall0 < self.every || t <= t0 {
            return;
        }
        self.last.set((elapsed, t, collisions));
        let (wall, simulated) = (elapsed - wall0, t - t0);
        let cost = wall / simulated;
        if self.bar.is_none() {
            eprintln!(
                "vibrobed: {}t = {t:.6} of {} ({:.1}%), {} collisions/s, {} to go",
                self.name_part(),
                self.duration,
                100.0 * t / self.duration,
                rate((collisions - collisions0) as f64 / wall),
                clock_time(cost * (self.duration - t).max(0.0)),
            );
        }
        self.watch_cost(t, cost);
    }

    /// `name: ` on a sweep's lines, nothing on a run's own.
    fn name_part(&self) -> String {
        match self.mode {
            ProgressMode::Periodic => format!("{}: ", self.label),
            _ => String::new(),
        }
    }

    /// Keeps the first reading's cost, and says once when a later one is far above it.
    fn watch_cost(&self, t: f64, cost: f64) {
        let mut watch = self.cost.get();
        let due = watch.read(t, cost);
        self.cost.set(watch);
        if let Some(note) = due {
            let note = format!("vibrobed: note: {}{note}", self.name_part());
            match &self.bar {
                Some(bar) => bar.println(note),
                None => eprintln!("{note}"),
            }
        }
    }

    /// The run ended (`ending` at simulated time `t`, after `collisions` collisions): clears the
    /// bar and prints the end line (in `Bar` and `Lines` modes).
    pub fn finish(self, ending: Ending, t: f64, collisions: u64) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
        if matches!(self.mode, ProgressMode::Quiet | ProgressMode::Periodic) {
            return;
        }
        let wall = self.clock.elapsed().as_secs_f64();
        let how = ending.words();
        eprintln!(
            "vibrobed: {how} at t = {t} of {} in {wall:.1} s: {collisions} collisions ({}/s)",
            self.duration,
            rate(collisions as f64 / wall.max(1e-9))
        );
    }
}

/// Wall seconds as `42 s`, `3 min 20 s` or `5 h 07 min`.
pub fn clock_time(seconds: f64) -> String {
    let s = seconds.round() as u64;
    if s < 60 {
        format!("{s} s")
    } else if s < 3600 {
        format!("{} min {:02} s", s / 60, s % 60)
    } else {
        format!("{} h {:02} min", s / 3600, (s % 3600) / 60)
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
    fn times_to_go_are_short() {
        assert_eq!(clock_time(42.4), "42 s");
        assert_eq!(clock_time(200.0), "3 min 20 s");
        assert_eq!(clock_time(5.0 * 3600.0 + 7.0 * 60.0), "5 h 07 min");
    }

    /// The note comes at the first reading above ten times the start's cost, not at nine
    /// times, names the cures, and comes once; readings that measured nothing do not count.
    #[test]
    fn the_note_on_a_growing_cost_comes_once_past_ten_times_the_start() {
        let mut watch = CostWatch::default();
        assert_eq!(
            watch.read(1.0, f64::INFINITY),
            None,
            "no simulated time: no reading"
        );
        assert_eq!(watch.read(2.0, 0.5), None, "the start's reading");
        for (t, cost) in [(3.0, 1.0), (4.0, 4.5), (5.0, 0.1), (6.0, 5.0)] {
            assert_eq!(watch.read(t, cost), None, "{cost} is at most ten times 0.5");
        }
        let note = watch.read(7.25, 6.0).expect("twelve times the start");
        assert!(note.starts_with("at t = 7.250000 a unit of simulated time costs 12 times"));
        for cure in [
            "collisions.tc",
            "collisions.speed_cutoff",
            "run.max_wall_seconds",
        ] {
            assert!(note.contains(cure), "{cure} not named: {note}");
        }
        assert_eq!(watch.read(8.0, 60.0), None, "said once");
    }

    #[test]
    fn quiet_unless_asked() {
        assert_eq!(ProgressMode::for_stderr(false), ProgressMode::Quiet);
        assert_ne!(ProgressMode::for_stderr(true), ProgressMode::Quiet);
    }
}
