//! The outputs a run streams at its stops — the recording and the trajectory, or a caller's
//! frame sink — under one interface ([`FrameSink`]) and one failure policy: an output that
//! fails, or whose file is removed during the run, is said once on stderr, listed in the
//! summary, and dropped; the run goes on without it.

use super::failures::Failures;
use crate::error::Error;
use crate::output::frame::{FrameSink, FrameView};
use crate::output::partial::{partial_name, Partial};
use std::path::PathBuf;

/// Which stops an output takes frames at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Takes {
    /// The frames (`output.frame_interval`), with the time series, live profiles and fields.
    Frames,
    /// The trajectory's frames (`output.trajectory_interval`): the disks alone.
    TrajectoryFrames,
}

/// One streamed output.
struct Stream {
    /// Its name in messages and in the summary's `output_failures`.
    name: &'static str,
    /// The file it writes (empty for a caller's sink that writes none).
    path: PathBuf,
    takes: Takes,
    sink: Box<dyn FrameSink>,
}

/// The outputs streamed at stops, in the order they were opened.
#[derive(Default)]
pub(super) struct Streams {
    list: Vec<Stream>,
}

impl Streams {
    /// Adds output `name`, writing `path`, which takes the frames of `takes`.
    pub(super) fn add(
        &mut self,
        name: &'static str,
        path: PathBuf,
        takes: Takes,
        sink: Box<dyn FrameSink>,
    ) {
        self.list.push(Stream {
            name,
            path,
            takes,
            sink,
        });
    }

    /// Whether some output takes the frames of `takes` (else those stops are not made).
    pub(super) fn take(&self, takes: Takes) -> bool {
        self.list.iter().any(|s| s.takes == takes)
    }

    /// The files being written, by output, for the watch that notices them removed.
    pub(super) fn files(&self) -> Vec<(&'static str, Partial)> {
        let file = |s: &Stream| s.sink.file().map(|f| (s.name, f));
        self.list.iter().filter_map(file).collect()
    }

    /// Frame `view` to the outputs that take `takes`; `time`: the engine's, for a failure.
    pub(super) fn frame(
        &mut self,
        takes: Takes,
        view: &FrameView,
        time: f64,
        failures: &mut Failures,
    ) {
        self.each(time, failures, |s| {
            if s.takes == takes {
                s.sink.frame(view)
            } else {
                Ok(())
            }
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
        self.each(time, failures, |s| s.sink.log_text(at, level, text));
    }

    /// The watch found the file of output `name` removed (and has said so): it is dropped.
    pub(super) fn gone(&mut self, name: &str, time: f64, failures: &mut Failures) {
        if let Some(i) = self.list.iter().position(|s| s.name == name) {
            let e = Error::Io(format!(
                "{name} {}: removed during the run",
                partial_name(&self.list[i].path).display()
            ));
            self.fail(i, e, time, true, failures);
        }
    }

    /// Closes every output, the last opened first, each with `note` (a line of text at
    /// simulated time `at`: how the run ended) before its end.
    pub(super) fn close(
        &mut self,
        (at, level, note): (f64, &str, &str),
        time: f64,
        failures: &mut Failures,
    ) {
        while let Some(mut s) = self.list.pop() {
            let noted = s.sink.log_text(at, level, note);
            let closed = noted.and_then(|()| s.sink.finish());
            if let Err(e) = closed {
                failures.record(s.name, &s.path, e, time, false);
            }
        }
    }

    /// Runs `write` on each output, dropping those it fails for.
    fn each(
        &mut self,
        time: f64,
        failures: &mut Failures,
        mut write: impl FnMut(&mut Stream) -> crate::error::Result<()>,
    ) {
        let mut i = 0;
        while i < self.list.len() {
            match write(&mut self.list[i]) {
                Ok(()) => i += 1,
                Err(e) => self.fail(i, e, time, false, failures),
            }
        }
    }

    /// Output `i` failed with `e` (`said`: the watch has said so): dropped (its writer has
    /// stopped; dropping it removes its temporary file), the failure recorded.
    fn fail(&mut self, i: usize, e: Error, time: f64, said: bool, failures: &mut Failures) {
        let s = self.list.remove(i);
        drop(s.sink);
        failures.record(s.name, &s.path, e, time, said);
    }
}
