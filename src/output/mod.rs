//! Output plugins: what the simulation writes out.
pub mod frame;
pub mod partial;
pub mod progress;
#[cfg(feature = "record")]
pub mod recording;
pub mod summary;
pub mod trajectory;
pub mod watch;

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// Writes `text` to `path` through a temporary file renamed into place.
pub fn write_atomic(path: &Path, text: &str) -> Result<()> {
    let tmp = temp_name(path);
    std::fs::write(&tmp, text)
        .and_then(|_| std::fs::rename(&tmp, path))
        .map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            Error::Io(format!("cannot write {}: {e}", path.display()))
        })
}

/// A temporary name beside `path`, unique to this process.
fn temp_name(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or("out".into(), |n| n.to_string_lossy());
    path.with_file_name(format!(".{name}.{}.partial", std::process::id()))
}
