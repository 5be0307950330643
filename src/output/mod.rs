//! Output plugins: what the simulation writes out.
pub mod fields;
pub mod frame;
pub mod partial;
pub mod progress;
#[cfg(feature = "record")]
pub mod recording;
pub mod summary;
pub mod trajectory;
pub mod watch;

use crate::error::{Error, Result};
use crate::scenario::Scenario;
use frame::{FrameSink, SceneLayout};
use std::path::{Path, PathBuf};

/// The Rerun recording of a run to `path`, its disks coloured as `output.color_by` asks, under
/// the id of the run it belongs to (the parts of a resumed run share one).
#[cfg(feature = "record")]
pub fn open_recording(
    path: &Path,
    s: &Scenario,
    layout: &SceneLayout,
    recording_id: Option<&str>,
) -> Result<Box<dyn FrameSink>> {
    let color = s.output.color_by.into();
    let rec = recording::RerunRecorder::create_with_id(path, layout, color, recording_id)
        .map_err(|e| Error::Io(format!("cannot record to {}: {e}", path.display())))?;
    Ok(Box::new(rec))
}

/// A build without recording refuses one.
#[cfg(not(feature = "record"))]
pub fn open_recording(
    _path: &Path,
    _s: &Scenario,
    _layout: &SceneLayout,
    _recording_id: Option<&str>,
) -> Result<Box<dyn FrameSink>> {
    Err(Error::input(
        "--rrd",
        "this build of vibrobed has no recording (build with the `record` feature)",
    ))
}

/// Writes `text` to `path` through a temporary file renamed into place.
pub fn write_atomic(path: &Path, text: &str) -> Result<()> {
    write_whole(path, text).map_err(|e| Error::Io(format!("cannot write {}: {e}", path.display())))
}

/// Writes output `what` (its name in messages: `fields`, `profiles`, `summary`) to `path` as
/// [`write_atomic`] does; a failure names the output and its file ([`cannot_write`]).
pub fn write_output(what: &str, path: &Path, text: &str) -> Result<()> {
    write_whole(path, text).map_err(|e| cannot_write(what, path, e))
}

/// Output `what` could not be written to `path`, for `why`: the message names both, as every
/// output's does (`cannot write trajectory t.xyz.partial: …`).
pub fn cannot_write(what: &str, path: &Path, why: impl std::fmt::Display) -> Error {
    Error::Io(format!("cannot write {what} {}: {why}", path.display()))
}

/// Writes `text` to `path` through a temporary file renamed into place; the temporary file is
/// removed if that fails.
fn write_whole(path: &Path, text: &str) -> std::io::Result<()> {
    let tmp = temp_name(path);
    std::fs::write(&tmp, text)
        .and_then(|_| std::fs::rename(&tmp, path))
        .inspect_err(|_| {
            let _ = std::fs::remove_file(&tmp);
        })
}

/// A temporary name beside `path`, unique to this process.
fn temp_name(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or("out".into(), |n| n.to_string_lossy());
    path.with_file_name(format!(".{name}.{}.partial", std::process::id()))
}

/// `path` made absolute and canonical: itself if it exists, else its directory's canonical path
/// joined with its name (else `path` as given). Two spellings of one file compare equal.
pub fn canonical(path: &Path) -> PathBuf {
    if let Ok(p) = path.canonicalize() {
        return p;
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match (dir.canonicalize(), path.file_name()) {
        (Ok(d), Some(name)) => d.join(name),
        _ => path.to_path_buf(),
    }
}

/// Why no file can be written as `path`, if so: its directory does not exist, cannot be reached,
/// is not a directory, or refuses a new file (permissions, ownership, a read-only filesystem;
/// tried with an empty file, removed at once, so that what the system says is what a run would
/// meet). Checked before a run, which is then refused naming the option.
pub fn writable_directory(path: &Path) -> std::result::Result<(), String> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    match std::fs::metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(format!("the directory {} does not exist", dir.display()))
        }
        Err(e) => return Err(format!("cannot reach the directory {}: {e}", dir.display())),
        Ok(m) if !m.is_dir() => return Err(format!("{} is not a directory", dir.display())),
        Ok(_) => {}
    }
    let probe = dir.join(format!(".vibrobed-probe-{}", std::process::id()));
    match std::fs::File::create_new(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => Err(format!(
            "cannot write in the directory {}: {e}",
            dir.display()
        )),
    }
}

/// Refuses `-` as an output's path: only `--summary -` means stdout (the summary's default,
/// turned into it by the command line); any other output written to a file named `-` would be
/// a mistake found later. `field` is the option or field that names it.
pub fn not_dash(field: &str, path: &Path) -> crate::error::Result<()> {
    if path == Path::new("-") {
        return Err(crate::error::Error::input(
            field,
            "`-` names no file here: name a file (only the command line's --summary takes `-`, \
             for stdout)",
        ));
    }
    Ok(())
}
