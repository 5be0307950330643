//! The 2D fields file (`--fields`), an output at the run's end: the fields measured after the
//! warm-up, as CSV or VTK image data (`*.vti`), written whole.

use super::streams::{Given, Output};
use crate::error::Result;
use crate::output::watch::Target;
use std::path::PathBuf;

/// The file the fields are written to.
pub(super) struct FieldsFile(pub(super) PathBuf);

impl Output for FieldsFile {
    fn take(&mut self, given: &Given) -> Result<()> {
        match given {
            Given::End(Some(fields), ..) => crate::output::fields::write(&self.0, fields),
            // No sample after the warm-up: zeros would read as a measurement.
            Given::End(None, ending, time) => {
                eprintln!(
                    "vibrobed: warning: no fields measured (the run ended, {}, at t = {time} \
                     before any sample after its warm-up): fields {} not written",
                    ending.words(),
                    self.0.display()
                );
                Ok(())
            }
            Given::Frame(_) | Given::Checkpoint(_) => Ok(()),
        }
    }
    fn watched(&self, name: &'static str) -> Option<Target> {
        Some(Target::later(name, &self.0))
    }
}
