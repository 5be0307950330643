//! The files a run from Python writes, named as the command line's options: the recording and
//! the trajectory while it runs, the checkpoint, and the profiles, fields and summary at the end.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use vibrobed::cli::OutputArgs;
use vibrobed::output::summary::Summary;
use vibrobed::output::write_output;
use vibrobed::{Error, Result};

/// The output paths asked for (each `None` when not).
#[derive(Debug, Default, Clone)]
pub struct Files {
    pub rrd: Option<PathBuf>,
    pub summary: Option<PathBuf>,
    pub profiles: Option<PathBuf>,
    pub fields: Option<PathBuf>,
    pub trajectory: Option<PathBuf>,
    pub checkpoint: Option<PathBuf>,
}

impl Files {
    /// The paths of `given`, keyed by option name (`rrd`, `summary`, …).
    pub fn from_map(given: HashMap<String, PathBuf>) -> Result<Files> {
        let mut files = Files::default();
        for (name, path) in given {
            let slot =
                match name.as_str() {
                    "rrd" => &mut files.rrd,
                    "summary" => &mut files.summary,
                    "profiles" => &mut files.profiles,
                    "fields" => &mut files.fields,
                    "trajectory" => &mut files.trajectory,
                    "checkpoint" => &mut files.checkpoint,
                    _ => return Err(Error::input(
                        name,
                        "not an output (rrd, summary, profiles, fields, trajectory, checkpoint)",
                    )),
                };
            *slot = Some(path);
        }
        Ok(files)
    }

    /// The paths, for the command line's check of them before a run, with the files the run
    /// reads (`SCENARIO`, the `CHECKPOINT` resumed), which no output may overwrite.
    pub fn args<'a>(&'a self, inputs: Vec<(&'static str, &'a Path)>) -> OutputArgs<'a> {
        OutputArgs {
            inputs,
            rrd: self.rrd.as_deref(),
            summary: self.summary.as_deref(),
            profiles: self.profiles.as_deref(),
            fields: self.fields.as_deref(),
            trajectory: self.trajectory.as_deref(),
            checkpoint: self.checkpoint.as_deref(),
        }
    }

    /// The files written once the run has ended, whose directories the run watches.
    pub fn written_after(&self) -> Vec<(&'static str, PathBuf)> {
        [("profiles", &self.profiles), ("summary", &self.summary)]
            .into_iter()
            .filter_map(|(output, path)| Some((output, path.clone()?)))
            .collect()
    }

    /// Writes the run's profiles and summary (the fields are an output of the run), as the
    /// command line does, each whatever becomes of the other; returns the first failure.
    pub fn write(&self, result: &Summary) -> Result<()> {
        let mut first = Ok(());
        let mut keep = |written: Result<()>| {
            if first.is_ok() {
                first = written;
            }
        };
        if let (Some(path), Some(p)) = (&self.profiles, &result.profiles) {
            keep(write_output("profiles", path, &p.to_csv()));
        }
        if let Some(path) = &self.summary {
            keep(write_output("summary", path, &result.to_json()));
        }
        first
    }
}
