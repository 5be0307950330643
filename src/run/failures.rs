//! The outputs a run could not write (a recording, a trajectory, a checkpoint): each said on
//! stderr with what the run does about it, counted when it fails again, and listed in the
//! summary (`output_failures`), which makes the run exit 3. When to say it is the outputs'
//! policy (`streams`).

use crate::error::Error;
use crate::output::summary::OutputFailure;
use std::path::Path;

/// The failures so far.
#[derive(Debug, Default)]
pub(super) struct Failures {
    list: Vec<OutputFailure>,
}

impl Failures {
    /// `output`, written to `path`, failed with `e` at simulated time `time`; said on stderr
    /// with `goes_on`, what the run does about it, if given. Another failure of the same output
    /// is counted.
    pub(super) fn record(
        &mut self,
        output: &'static str,
        path: &Path,
        e: Error,
        time: f64,
        goes_on: Option<&str>,
    ) {
        let error = match e {
            Error::Io(m) | Error::Runtime(m) => m,
            other => other.to_string(),
        };
        if let Some(goes_on) = goes_on {
            eprintln!("vibrobed: warning: {error}; {goes_on}");
        }
        let path = path.display().to_string();
        let same = |f: &&mut OutputFailure| f.output == output && f.path == path;
        if let Some(f) = self.list.iter_mut().find(same) {
            f.failures += 1;
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

    /// All of them, for the summary.
    pub(super) fn list(&self) -> Vec<OutputFailure> {
        self.list.clone()
    }
}
