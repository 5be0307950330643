//! Errors and their exit codes: 2 for bad input (naming the field), 1 for a runtime failure;
//! [`EXIT_OUTPUT_FAILED`] for a run that ended well but could not write one of its outputs.

use std::fmt;

/// Exit code of a run that went on without an output it could not write (a recording, a
/// trajectory, a checkpoint): its summary is written and lists them under `output_failures`.
pub const EXIT_OUTPUT_FAILED: i32 = 3;

/// Everything that can stop vibrobed.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// The scenario or the command line is wrong. `field` is the dotted path of the culprit.
    Input {
        /// Dotted path of the offending field (e.g. `particles.radius`), or the argument name.
        field: String,
        /// What is wrong with it.
        message: String,
    },
    /// The simulation failed while running (e.g. an invariant check fired).
    Runtime(String),
    /// Reading or writing a file failed.
    Io(String),
}

impl Error {
    /// A bad-input error about `field`.
    pub fn input(field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Input {
            field: field.into(),
            message: message.into(),
        }
    }

    /// The process exit code for this error: 2 for bad input, 1 otherwise.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Input { .. } => 2,
            Error::Runtime(_) | Error::Io(_) => 1,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Input { field, message } if field.is_empty() => write!(f, "{message}"),
            Error::Input { field, message } => write!(f, "{field}: {message}"),
            Error::Runtime(m) => write!(f, "runtime failure: {m}"),
            Error::Io(m) => write!(f, "i/o error: {m}"),
        }
    }
}

impl std::error::Error for Error {}

/// Most characters of a user's value a message echoes: a value of megabytes (a broken JSON
/// `--set`, a long key) is quoted by its start.
pub const ECHO_CHARS: usize = 80;

/// `text` as a message quotes it: whole up to [`ECHO_CHARS`] characters, else its first
/// [`ECHO_CHARS`] followed by `…` and how many characters it has.
pub fn excerpt(text: &str) -> String {
    match text.char_indices().nth(ECHO_CHARS) {
        None => text.to_string(),
        Some((end, _)) => format!("{}… ({} characters)", &text[..end], text.chars().count()),
    }
}

/// Shorthand for results in this crate.
pub type Result<T> = std::result::Result<T, Error>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_excerpt_keeps_short_text_and_cuts_long_text_at_a_character() {
        assert_eq!(excerpt("[1,2"), "[1,2");
        let long = "é".repeat(1000);
        let cut = excerpt(&long);
        assert!(cut.starts_with(&"é".repeat(ECHO_CHARS)), "{cut}");
        assert!(cut.ends_with("… (1000 characters)"), "{cut}");
        assert_eq!(excerpt(&"x".repeat(ECHO_CHARS)), "x".repeat(ECHO_CHARS));
    }
}
