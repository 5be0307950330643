//! What a run tells the user on stderr while it goes: a progress bar on a terminal (elapsed
//! wall time, ETA, simulated time over the duration, collisions per second); otherwise (logs of
//! batch jobs) one start line, a line every `--progress-every` seconds (simulated time,
//! collisions per second, the wall time to go) and one end line; nothing with `--quiet`. Both
//! forms end with the run's ending, at which simulated time; both say once when the run's wall
//! time per unit of simulated time has grown far above its start, or simulated time has stopped
//! advancing (a bed freezing into a collapse), naming the cures — and so does a sweep's run on a
//! terminal, whose progress the sweep's bar shows. A thread of the report's own
//! reads the run's [published clock](crate::engine::published_clock) on the wall clock's
//! schedule, so that a run crawling or frozen between two stops is seen and heard.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::engine::published_clock::{ClockReading, PublishedClock};
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
    /// Only the note on a growing cost, named (a sweep's run on a terminal: the sweep's bar
    /// shows its progress).
    Notes,
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

/// How often the reader looks at the clock (and redraws the bar).
const TICK: Duration = Duration::from_millis(50);

/// Watches a run's wall time per unit of simulated time, reading by reading: the first
/// reading that saw simulated time advance gives the start's; the first later one above
/// `COST_GROWTH` times it, or one over which simulated time did not advance at all, gives the
/// note (once) on a bed freezing into a collapse, naming the cures.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CostWatch {
    /// Wall time per unit of simulated time over the first reading, once taken.
    start: Option<f64>,
    /// The note was given.
    noted: bool,
}

impl CostWatch {
    /// Takes a reading: `simulated` units of simulated time in `wall` seconds, ending at
    /// simulated time `t`; returns the note when it is due, once per run.
    pub fn read(&mut self, t: f64, wall: f64, simulated: f64) -> Option<String> {
        if !(wall.is_finite() && wall > 0.0 && simulated >= 0.0) {
            return None;
        }
        let Some(start) = self.start else {
            if simulated > 0.0 {
                self.start = Some(wall / simulated);
            }
            return None;
        };
        if self.noted {
            return None;
        }
        let cost = wall / simulated;
        let what = if simulated == 0.0 {
            format!(
                "at t = {t:.6} simulated time has not advanced in {} of wall time",
                clock_time(wall)
            )
        } else if cost > COST_GROWTH * start {
            format!(
                "at t = {t:.6} a unit of simulated time costs {:.0} times the wall time it cost \
                 at the start",
                cost / start
            )
        } else {
            return None;
        };
        self.noted = true;
        Some(format!(
            "{what}: the bed may be freezing into an inelastic collapse (or a pile rattling \
             without coming to rest); cures: collisions.tc (the TC model, 10⁻³ √(d/g) is a good \
             start) or collisions.speed_cutoff, and run.max_wall_seconds to bound the run (see \
             the book's page Stability models and hard cases)"
        ))
    }
}

/// Bar resolution: positions per run.
const STEPS: u64 = 10_000;

/// Progress of one run (see the [module documentation](self)).
#[derive(Debug)]
pub struct ProgressReport {
    mode: ProgressMode,
    bar: Option<indicatif::ProgressBar>,
    duration: f64,
    started: Instant,
    /// The run's clock: published here at stops, read by the reader.
    clock: Arc<PublishedClock>,
    /// The thread reading the clock (not when quiet), and the flag that ends it.
    reader: Option<(JoinHandle<()>, Arc<AtomicBool>)>,
}

impl ProgressReport {
    /// Starts reporting a run of scene `name` with `disks` disks to simulated time `duration`,
    /// whose engine publishes to `clock` (which holds where the run starts): a line (and a
    /// reading of the cost) every `every` wall seconds. Prints the start line in `Lines` mode;
    /// `Periodic` lines are named `name`.
    pub fn start(
        mode: ProgressMode,
        (name, disks): (&str, usize),
        duration: f64,
        every: f64,
        clock: Arc<PublishedClock>,
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
        let started = Instant::now();
        let reader = (mode != ProgressMode::Quiet).then(|| {
            let over = Arc::new(AtomicBool::new(false));
            let reader = Reader {
                mode,
                bar: bar.clone(),
                duration,
                every,
                label: name.to_string(),
                started,
                last: clock.read(),
                cost: CostWatch::default(),
                clock: Arc::clone(&clock),
            };
            let over_r = Arc::clone(&over);
            (std::thread::spawn(move || reader.run(&over_r)), over)
        });
        ProgressReport {
            mode,
            bar,
            duration,
            started,
            clock,
            reader,
        }
    }

    /// The run has reached simulated time `t` after `collisions` collisions (a stop).
    pub fn update(&self, t: f64, collisions: u64) {
        self.clock.publish(t, collisions);
    }

    /// Ends the reader.
    fn stop_reading(&mut self) {
        if let Some((reader, over)) = self.reader.take() {
            over.store(true, Ordering::Relaxed);
            reader.thread().unpark();
            let _ = reader.join();
        }
    }

    /// The run ended (`ending` at simulated time `t`, after `collisions` collisions): clears the
    /// bar and prints the end line (in `Bar` and `Lines` modes).
    pub fn finish(mut self, ending: Ending, t: f64, collisions: u64) {
        self.stop_reading();
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
        if matches!(
            self.mode,
            ProgressMode::Quiet | ProgressMode::Periodic | ProgressMode::Notes
        ) {
            return;
        }
        let wall = self.started.elapsed().as_secs_f64();
        let how = ending.words();
        eprintln!(
            "vibrobed: {how} at t = {t} of {} in {wall:.1} s: {collisions} collisions ({}/s)",
            self.duration,
            rate(collisions as f64 / wall.max(1e-9))
        );
    }
}

impl Drop for ProgressReport {
    fn drop(&mut self) {
        self.stop_reading();
    }
}

/// The thread of a [`ProgressReport`] that reads the run's clock: the bar redrawn at every
/// look, a line and a reading of the cost every `every` seconds.
struct Reader {
    mode: ProgressMode,
    bar: Option<indicatif::ProgressBar>,
    duration: f64,
    every: f64,
    /// What the lines are named (`Periodic`: the sweep's run).
    label: String,
    started: Instant,
    /// The clock as read at the last line.
    last: ClockReading,
    cost: CostWatch,
    clock: Arc<PublishedClock>,
}

impl Reader {
    /// Looks at the clock every [`TICK`] until `over`.
    fn run(mut self, over: &AtomicBool) {
        let mut due = self.every;
        while !over.load(Ordering::Relaxed) {
            // Woken early when the run ends (`stop_reading` unparks it).
            std::thread::park_timeout(TICK.min(Duration::from_secs_f64(self.every)));
            if over.load(Ordering::Relaxed) {
                return;
            }
            let now = self.clock.read();
            let elapsed = self.started.elapsed().as_secs_f64();
            self.draw(now, elapsed);
            if elapsed >= due {
                due = elapsed + self.every;
                self.line(now);
            }
        }
    }

    /// The bar at `now`, `elapsed` wall seconds into the run.
    fn draw(&self, now: ClockReading, elapsed: f64) {
        if let Some(bar) = &self.bar {
            let t = now.time;
            bar.set_position((STEPS as f64 * t / self.duration).clamp(0.0, STEPS as f64) as u64);
            bar.set_message(format!(
                "t {t:.2}/{} · {} coll/s",
                self.duration,
                rate(now.collisions as f64 / elapsed.max(1e-9))
            ));
        }
    }

    /// The line (off a terminal) and the cost's reading for the clock as published `now`,
    /// against its last reading: the wall time between the two publications, not between the
    /// two looks, so that an engine publishing only at stops is read at the stops.
    fn line(&mut self, now: ClockReading) {
        let last = self.last;
        let t = now.time;
        let head = format!(
            "vibrobed: {}t = {t:.6} of {} ({:.1}%)",
            self.name_part(),
            self.duration,
            100.0 * t / self.duration
        );
        if now.wall <= last.wall {
            // Nothing published since the last line: an engine that publishes at stops only,
            // between two of them.
            if self.prints_lines() {
                let since = now.wall.elapsed().as_secs_f64();
                self.print(format!("{head}, as of {} ago", clock_time(since)));
            }
            return;
        }
        self.last = now;
        let wall = (now.wall - last.wall).as_secs_f64();
        let simulated = t - last.time;
        let news = if simulated > 0.0 {
            let collisions = now.collisions.saturating_sub(last.collisions);
            format!(
                "{head}, {} collisions/s, {} to go",
                rate(collisions as f64 / wall),
                clock_time(wall / simulated * (self.duration - t).max(0.0)),
            )
        } else {
            format!(
                "{head}: simulated time has not advanced in {}",
                clock_time(wall)
            )
        };
        if self.prints_lines() {
            self.print(news);
        }
        if let Some(note) = self.cost.read(t, wall, simulated) {
            self.print(format!("vibrobed: note: {}{note}", self.name_part()));
        }
    }

    /// A line on stderr, above the bar if there is one: ours, or a sweep's (`Notes`: its line
    /// cleared first, as the bar's own `println` does; the bar redraws below).
    fn print(&self, line: String) {
        match &self.bar {
            Some(bar) => bar.println(line),
            None if self.mode == ProgressMode::Notes => eprintln!("\r\x1b[2K{line}"),
            None => eprintln!("{line}"),
        }
    }

    /// Progress goes out as lines (off a terminal), not as a bar or not at all.
    fn prints_lines(&self) -> bool {
        matches!(self.mode, ProgressMode::Lines | ProgressMode::Periodic)
    }

    /// `name: ` on a sweep's lines, nothing on a run's own.
    fn name_part(&self) -> String {
        match self.mode {
            ProgressMode::Periodic | ProgressMode::Notes => format!("{}: ", self.label),
            _ => String::new(),
        }
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
    /// times, names the cures, and comes once; a reading before simulated time first advanced
    /// is not the start's.
    #[test]
    fn the_note_on_a_growing_cost_comes_once_past_ten_times_the_start() {
        let mut watch = CostWatch::default();
        assert_eq!(watch.read(0.0, 1.0, 0.0), None, "not started: no reading");
        assert_eq!(watch.read(2.0, 1.0, 2.0), None, "the start's reading, 0.5");
        for (t, wall) in [(3.0, 1.0), (4.0, 4.5), (5.0, 0.1), (6.0, 5.0)] {
            assert_eq!(
                watch.read(t, wall, 1.0),
                None,
                "{wall} is at most ten times 0.5"
            );
        }
        let note = watch.read(7.25, 6.0, 1.0).expect("twelve times the start");
        assert!(note.starts_with("at t = 7.250000 a unit of simulated time costs 12 times"));
        for cure in [
            "collisions.tc",
            "collisions.speed_cutoff",
            "run.max_wall_seconds",
        ] {
            assert!(note.contains(cure), "{cure} not named: {note}");
        }
        assert_eq!(watch.read(8.0, 60.0, 1.0), None, "said once");
        assert_eq!(watch.read(8.0, 60.0, 0.0), None, "said once, frozen or not");
    }

    /// Simulated time that does not advance over a reading after the start gives the note
    /// at once, whatever the start's cost.
    #[test]
    fn the_note_comes_when_simulated_time_stops() {
        let mut watch = CostWatch::default();
        assert_eq!(watch.read(1.0, 1.0, 1.0), None, "the start's reading");
        let note = watch.read(1.0, 2.0, 0.0).expect("frozen");
        assert!(
            note.starts_with("at t = 1.000000 simulated time has not advanced in 2 s"),
            "{note}"
        );
        assert!(note.contains("collisions.tc"), "{note}");
    }

    #[test]
    fn quiet_unless_asked() {
        assert_eq!(ProgressMode::for_stderr(false), ProgressMode::Quiet);
        assert_ne!(ProgressMode::for_stderr(true), ProgressMode::Quiet);
    }
}
