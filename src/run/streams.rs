//! The outputs a run writes at its stops — the recording (or a caller's frame sink), the
//! trajectory, the checkpoint, the fields — as plugins: each one [`Output`], registered with
//! the stops it takes and what it does when it fails, under one failure policy. A failure is
//! said once on stderr and listed in the summary (`output_failures`); then an output that is
//! dropped on failure (a stream: its file removed, or found removed during the run) is closed
//! and the run goes on without it, and one that is tried again (the checkpoint: each write
//! whole on its own) is given its next stop, and said again only if it was written in between.

use super::checkpoint::Checkpoint;
use super::failures::Failures;
use crate::error::{Error, Result};
use crate::measure::fields::Fields;
use crate::output::frame::{FrameSink, FrameView};
use crate::output::partial::partial_name;
use crate::output::summary::Ending;
use crate::output::watch::Target;
use std::path::PathBuf;

/// What the run does when an output dropped on failure fails.
const WITHOUT_IT: &str = "the run goes on without it";

/// Which stops an output takes, and so what it is given at them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Takes {
    /// The frames (`output.frame_interval`), with the time series, live profiles and fields.
    Frames,
    /// The trajectory's frames (`output.trajectory_interval`): the disks alone.
    TrajectoryFrames,
    /// The checkpoints (`--checkpoint-every`, and the end): the run's whole state.
    Checkpoints,
    /// The end of the run: what it measured.
    End,
}

/// What a stop gives the outputs that take it.
pub(super) enum Given<'a> {
    /// A frame or a trajectory frame.
    Frame(&'a FrameView<'a>),
    /// The run's whole state, to resume from.
    Checkpoint(&'a Checkpoint),
    /// The end of the run: the fields measured (none before a sample after the warm-up), how
    /// the run ended and when.
    End(Option<&'a Fields>, Ending, f64),
}

/// What an output does when it fails.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum OnFailure {
    /// It is dropped (its file removed): the run goes on without it.
    Drop,
    /// It stays, and is tried again at its next stop and at the end (what it wrote before stays
    /// whole); one written at the end only is tried there, whatever became of its directory.
    TryAgain,
}

/// An output written at stops: what it is given there, a line of text, its end.
pub(super) trait Output {
    /// Takes what a stop gives.
    fn take(&mut self, given: &Given) -> Result<()>;
    /// A line of text at simulated time `time` (`level`: "INFO", "WARN", …).
    fn log_text(&mut self, _time: f64, _level: &str, _text: &str) -> Result<()> {
        Ok(())
    }
    /// Closes the output (footers, the file renamed into place).
    fn finish(self: Box<Self>) -> Result<()> {
        Ok(())
    }
    /// What the watch looks after for output `name`, if anything: a file being streamed, or
    /// the directory of one written whole at its stops.
    fn watched(&self, _name: &'static str) -> Option<Target> {
        None
    }
}

/// A frame sink (the recording, the trajectory, a caller's) is an output given frames.
impl Output for Box<dyn FrameSink> {
    fn take(&mut self, given: &Given) -> Result<()> {
        match given {
            Given::Frame(view) => self.frame(view),
            Given::Checkpoint(_) | Given::End(..) => Ok(()),
        }
    }
    fn log_text(&mut self, time: f64, level: &str, text: &str) -> Result<()> {
        (**self).log_text(time, level, text)
    }
    fn finish(self: Box<Self>) -> Result<()> {
        (*self).finish()
    }
    fn watched(&self, name: &'static str) -> Option<Target> {
        (**self).file().map(|f| Target::streamed(name, f))
    }
}

/// One registered output.
struct Stream {
    /// Its name in messages and in the summary's `output_failures`.
    name: &'static str,
    /// The file it writes (empty for a caller's sink that writes none).
    path: PathBuf,
    takes: Takes,
    on_failure: OnFailure,
    /// Its last write failed (an output tried again).
    failing: bool,
    output: Box<dyn Output>,
}

/// The outputs written at stops, in the order they were registered.
#[derive(Default)]
pub(super) struct Streams {
    list: Vec<Stream>,
}

impl Streams {
    /// Registers output `name`, writing `path`, which takes the stops of `takes` and does
    /// `on_failure` when it fails.
    pub(super) fn add(
        &mut self,
        (name, path): (&'static str, PathBuf),
        takes: Takes,
        on_failure: OnFailure,
        output: Box<dyn Output>,
    ) {
        self.list.push(Stream {
            name,
            path,
            takes,
            on_failure,
            failing: false,
            output,
        });
    }

    /// Whether some output takes the stops of `takes` (else those stops give nothing).
    pub(super) fn take(&self, takes: Takes) -> bool {
        self.list.iter().any(|s| s.takes == takes)
    }

    /// What the watch looks after, by output: the files being streamed, the directories of
    /// those written whole.
    pub(super) fn watched(&self) -> Vec<Target> {
        self.list
            .iter()
            .filter_map(|s| s.output.watched(s.name))
            .collect()
    }

    /// `given` to the outputs that take `takes`; `time`: the engine's, for a failure.
    pub(super) fn give(&mut self, takes: Takes, given: &Given, time: f64, failures: &mut Failures) {
        self.each(time, failures, |s| {
            if s.takes != takes {
                return Ok(());
            }
            let written = s.output.take(given);
            if written.is_ok() && std::mem::take(&mut s.failing) {
                eprintln!(
                    "vibrobed: note: {} {} written again at t = {time}",
                    s.name,
                    s.path.display()
                );
            }
            written
        });
    }

    /// A line of text at simulated time `at` to every output.
    pub(super) fn log_text(
        &mut self,
        at: f64,
        (level, text): (&str, &str),
        time: f64,
        failures: &mut Failures,
    ) {
        self.each(time, failures, |s| s.output.log_text(at, level, text));
    }

    /// The watch found the file of output `name` removed, or the directory of one written
    /// later (and has said so): a stream is dropped; one tried again stays, to be tried.
    pub(super) fn gone(&mut self, name: &str, time: f64, failures: &mut Failures) {
        let dropped = |s: &Stream| s.name == name && s.on_failure == OnFailure::Drop;
        if let Some(i) = self.list.iter().position(dropped) {
            let e = Error::Io(format!(
                "{name} {}: removed during the run",
                partial_name(&self.list[i].path).display()
            ));
            self.fail(i, e, time, true, failures);
        }
    }

    /// Closes every output, the last registered first, each with `note` (a line of text at
    /// simulated time `at`: how the run ended) before its end.
    pub(super) fn close(
        &mut self,
        (at, level, note): (f64, &str, &str),
        time: f64,
        failures: &mut Failures,
    ) {
        while let Some(mut s) = self.list.pop() {
            let noted = s.output.log_text(at, level, note);
            let closed = noted.and_then(|()| s.output.finish());
            if let Err(e) = closed {
                failures.record(s.name, &s.path, e, time, Some(WITHOUT_IT));
            }
        }
    }

    /// Runs `write` on each output, applying the failure policy to those it fails for.
    fn each(
        &mut self,
        time: f64,
        failures: &mut Failures,
        mut write: impl FnMut(&mut Stream) -> Result<()>,
    ) {
        let mut i = 0;
        while i < self.list.len() {
            match write(&mut self.list[i]) {
                Ok(()) => i += 1,
                Err(e) => {
                    if self.list[i].on_failure == OnFailure::Drop {
                        self.fail(i, e, time, false, failures);
                    } else {
                        self.fail_again(i, e, time, failures);
                        i += 1;
                    }
                }
            }
        }
    }

    /// Output `i`, dropped on failure, failed with `e` (`said`: the watch has said so): dropped
    /// (its writer has stopped; dropping it removes its temporary file), the failure recorded.
    fn fail(&mut self, i: usize, e: Error, time: f64, said: bool, failures: &mut Failures) {
        let s = self.list.remove(i);
        drop(s.output);
        failures.record(s.name, &s.path, e, time, (!said).then_some(WITHOUT_IT));
    }

    /// Output `i`, tried again on failure, failed with `e`: recorded, said if it had been
    /// written since it last failed.
    fn fail_again(&mut self, i: usize, e: Error, time: f64, failures: &mut Failures) {
        let s = &mut self.list[i];
        let goes_on = if s.takes == Takes::End {
            format!("the run ends without its {}", s.name)
        } else {
            format!(
                "the run goes on, and tries the {0} again at the next interval and at the end \
                 (an earlier {0} stays whole)",
                s.name
            )
        };
        let first = !std::mem::replace(&mut s.failing, true);
        failures.record(s.name, &s.path, e, time, first.then_some(goes_on.as_str()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::frame::FrameView;
    use std::cell::Cell;
    use std::rc::Rc;

    /// An output that fails at the takes `fails` lists (counted from 0), and counts its writes.
    struct Flaky {
        fails: &'static [usize],
        takes: usize,
        written: Rc<Cell<usize>>,
    }

    impl Output for Flaky {
        fn take(&mut self, _: &Given) -> Result<()> {
            let k = self.takes;
            self.takes += 1;
            if self.fails.contains(&k) {
                return Err(Error::Io(format!("take {k} failed")));
            }
            self.written.set(self.written.get() + 1);
            Ok(())
        }
    }

    fn flaky(fails: &'static [usize]) -> (Box<dyn Output>, Rc<Cell<usize>>) {
        let written = Rc::new(Cell::new(0));
        let output = Flaky {
            fails,
            takes: 0,
            written: Rc::clone(&written),
        };
        (Box::new(output), written)
    }

    /// Gives `n` frames to `streams`.
    fn frames(streams: &mut Streams, n: usize, failures: &mut Failures) {
        let snap = crate::engine::Snapshot::default();
        let view = FrameView::of(0, &snap, (&[], &[]), (&[], None), None);
        for k in 0..n {
            streams.give(Takes::Frames, &Given::Frame(&view), k as f64, failures);
        }
    }

    #[test]
    fn an_output_dropped_on_failure_is_gone_and_the_others_go_on() {
        let mut streams = Streams::default();
        let (a, a_written) = flaky(&[1]);
        let (b, b_written) = flaky(&[]);
        streams.add(("a", "a.out".into()), Takes::Frames, OnFailure::Drop, a);
        streams.add(("b", "b.out".into()), Takes::Frames, OnFailure::Drop, b);
        let mut failures = Failures::default();
        frames(&mut streams, 4, &mut failures);
        assert_eq!((a_written.get(), b_written.get()), (1, 4));
        let list = failures.list();
        assert_eq!(list.len(), 1);
        assert_eq!(
            (list[0].output, list[0].time, list[0].failures),
            ("a", 1.0, 1)
        );
        assert!(streams.take(Takes::Frames), "b still takes frames");
    }

    #[test]
    fn an_output_tried_again_stays_and_each_failure_is_counted() {
        let mut streams = Streams::default();
        let (c, written) = flaky(&[0, 1, 3]);
        streams.add(("c", "c.out".into()), Takes::Frames, OnFailure::TryAgain, c);
        let mut failures = Failures::default();
        frames(&mut streams, 5, &mut failures);
        assert_eq!(written.get(), 2, "written at takes 2 and 4");
        let list = failures.list();
        assert_eq!(list.len(), 1, "one entry per output");
        assert_eq!((list[0].time, list[0].failures), (0.0, 3));
        streams.gone("c", 5.0, &mut failures);
        assert!(streams.take(Takes::Frames), "the watch does not drop it");
    }

    #[test]
    fn outputs_are_given_only_the_stops_they_take() {
        let mut streams = Streams::default();
        let (t, written) = flaky(&[]);
        streams.add(
            ("t", "t.out".into()),
            Takes::TrajectoryFrames,
            OnFailure::Drop,
            t,
        );
        let mut failures = Failures::default();
        frames(&mut streams, 3, &mut failures);
        assert_eq!(written.get(), 0);
        assert!(!streams.take(Takes::Frames) && streams.take(Takes::TrajectoryFrames));
    }
}
