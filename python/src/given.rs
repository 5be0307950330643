//! A scenario as Python hands it over: a file (read here, refused with the command line's
//! message when it cannot be) or the JSON text of a dict, and its `--set` overrides.

use std::path::PathBuf;
use vibrobed::{Error, Result, Scenario};

/// The scenario's text, where it came from, and the overrides to apply, in order.
pub struct Given {
    /// The JSON text (kept whole: a checkpoint carries it).
    pub text: String,
    /// The file, or `<dict>`.
    pub source: PathBuf,
    /// `KEY=VALUE` overrides, applied in order as `--set` applies them.
    pub sets: Vec<String>,
}

impl Given {
    /// The scenario in `path`, or in `text` (a dict dumped by the Python side).
    pub fn new(path: Option<PathBuf>, text: Option<String>, sets: Vec<String>) -> Result<Given> {
        match (path, text) {
            (Some(path), None) => Ok(Given {
                text: Scenario::read_text(&path)?,
                source: path,
                sets,
            }),
            (None, Some(text)) => Ok(Given {
                text,
                source: PathBuf::from("<dict>"),
                sets,
            }),
            _ => Err(Error::input(
                "scenario",
                "give a scenario file or a dict, one of them",
            )),
        }
    }

    /// The typed and validated scenario, overrides applied.
    pub fn scenario(&self) -> Result<Scenario> {
        Scenario::from_json_with_overrides(&self.text, &self.sets)
    }
}
