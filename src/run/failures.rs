//! The outputs a run could not write (a recording, a trajectory, a checkpoint): each said once
//! on stderr with what the run does about it, counted when it fails again, and listed in the
//! summary (`output_failures`), which makes the run exit 3.

use crate::error::Error;
use crate::output::summary::OutputFailure;
use std::path::Path;

/// The failures so far.
#[derive(Debug, Default)]
pub(super) struct Failures {
    list: Vec<OutputFailure>,
    /// The last checkpoint could not be written.
    checkpoint_failing: bool,
}

impl Failures {
    /// `output`, written to `path`, failed with `e` at simulated time `time`; said on stderr
    /// unless `said` already (by the watch). Another failure of the same output is counted, and
    /// said only for a checkpoint that was written again in between.
    pub(super) fn record(
        &mut self,
        output: &'static str,
        path: &Path,
        e: Error,
        time: f64,
        said: bool,
    ) {
        let again =
            output == "checkpoint" && !std::mem::replace(&mut self.checkpoint_failing, true);
        let error = match e {
            Error::Io(m) | Error::Runtime(m) => m,
            other => other.to_string(),
        };
        let path = path.display().to_string();
        let same = |f: &&mut OutputFailure| f.output == output && f.path == path;
        let earlier = self.list.iter_mut().find(same);
        let first = earlier.is_none();
        if let Some(f) = earlier {
            f.failures += 1;
        }
        if !said && (first || again) {
            let goes_on = match output {
                "checkpoint" => {
                    "the run goes on, and tries the checkpoint again at the next interval and at \
                     the end (an earlier checkpoint stays whole)"
                }
                _ => "the run goes on without it",
            };
            eprintln!("vibrobed: warning: {error}; {goes_on}");
        }
        if !first {
            return;
        }
        self.list.push(OutputFailure {
            output,
            path,
            time,
            error,
            failures: 1,
        });
    }

    /// The checkpoint `path` was written at simulated time `time`: said when it had failed.
    pub(super) fn checkpoint_written(&mut self, path: &Path, time: f64) {
        if std::mem::take(&mut self.checkpoint_failing) {
            eprintln!(
                "vibrobed: note: checkpoint {} written again at t = {time}",
                path.display()
            );
        }
    }

    /// All of them, for the summary.
    pub(super) fn list(&self) -> Vec<OutputFailure> {
        self.list.clone()
    }
}
