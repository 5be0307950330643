//! Checkpoint files: a run's complete state at an event boundary, so that `vibrobed resume`
//! continues it exactly (same events, same summary, bit for bit, on the same build).
//!
//! A file holds a header and a payload:
//!
//! | bytes | what |
//! |---|---|
//! | 8 | magic `VBEDCKPT` |
//! | 4 | format version (little-endian) |
//! | 8 | build id: a hash of the executable that wrote it |
//! | 8 | payload length |
//! | 8 | payload checksum (SipHash of the bytes) |
//! | … | payload: [`Checkpoint`] in postcard (compact binary serde) |
//!
//! The payload carries the scenario *text* and its `--set` overrides (the resumed run parses them
//! again, so the scene is the one that was saved, wherever the file has moved), the driver's state
//! (stop schedule, averages, profiles, the initial energy) and the engine's
//! ([`crate::schemes::SavedState`]). Floating-point values are stored as their
//! bits, so nothing is rounded. A file written by another build (whose engine could pop events in
//! another order), cut short, or damaged is refused with a message, never half read.

use super::state::DriverState;
use crate::error::{Error, Result};
use crate::scenario::Scenario;
use crate::schemes::SavedState;
use serde::{Deserialize, Serialize};
use std::hash::Hasher;
use std::path::{Path, PathBuf};
use std::sync::LazyLock;

const MAGIC: &[u8; 8] = b"VBEDCKPT";
/// Bumped whenever the payload's layout or meaning changes.
const FORMAT_VERSION: u32 = 25;
const HEADER: usize = 8 + 4 + 8 + 8 + 8;

/// Everything a resumed run needs.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Checkpoint {
    /// The scenario file's text, as read at the start of the run.
    pub scenario: String,
    /// Where the scenario was read from (for messages only).
    pub source: PathBuf,
    /// The `--set` overrides of the run, in order (a resume appends its own).
    pub sets: Vec<String>,
    /// Simulated time between checkpoints (`--checkpoint-every`), if any.
    pub every: Option<f64>,
    /// Id of the run's Rerun recording, kept by every resumed part.
    pub recording_id: Option<String>,
    /// Recordings written so far (a resume must not overwrite them).
    pub recordings: Vec<PathBuf>,
    /// The driver: stop schedule, averages, initial energy, counters.
    pub driver: DriverState,
    /// The engine.
    pub engine: SavedState,
}

/// A hash of the file this code was loaded from (the executable, or the Python package's
/// extension module): checkpoints are exact only on the build that wrote them.
static BUILD_ID: LazyLock<u64> = LazyLock::new(|| {
    let mut h = std::hash::DefaultHasher::new();
    h.write(env!("CARGO_PKG_VERSION").as_bytes());
    if let Some(bytes) = crate::platform::binary::own_file().and_then(|p| std::fs::read(p).ok()) {
        h.write(&bytes);
    }
    h.finish()
});

fn checksum(bytes: &[u8]) -> u64 {
    let mut h = std::hash::DefaultHasher::new();
    h.write(bytes);
    h.finish()
}

/// `FILE.tmp`, the name a checkpoint is written under before it is renamed over `FILE`.
pub fn temporary_name(path: &Path) -> PathBuf {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    PathBuf::from(tmp)
}

fn refuse(path: &Path, why: impl std::fmt::Display) -> Error {
    Error::input("CHECKPOINT", format!("{}: {why}", path.display()))
}

impl Checkpoint {
    /// Writes the checkpoint to `path` atomically: a temporary file next to it (`FILE.tmp`),
    /// synced and renamed over it, so that a run killed while writing leaves the previous
    /// checkpoint intact. A failure removes the temporary file and names it with the operating
    /// system's reason.
    pub fn write(&self, path: &Path) -> Result<()> {
        let payload = postcard::to_stdvec(self)
            .map_err(|e| Error::Runtime(format!("cannot encode the checkpoint: {e}")))?;
        let mut bytes = Vec::with_capacity(HEADER + payload.len());
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        bytes.extend_from_slice(&BUILD_ID.to_le_bytes());
        bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        bytes.extend_from_slice(&checksum(&payload).to_le_bytes());
        bytes.extend_from_slice(&payload);
        let tmp = temporary_name(path);
        let written = (|| {
            use std::io::Write;
            let mut f = std::fs::File::create(&tmp)?;
            f.write_all(&bytes)?;
            f.sync_all()?;
            std::fs::rename(&tmp, path)
        })();
        written.map_err(|e| {
            let left = match std::fs::remove_file(&tmp) {
                Err(r) if r.kind() != std::io::ErrorKind::NotFound => {
                    format!(" ({} is left: cannot remove it: {r})", tmp.display())
                }
                _ => String::new(),
            };
            Error::Io(format!(
                "cannot write checkpoint {}: {e}{left}",
                path.display()
            ))
        })
    }

    /// Reads and checks a checkpoint: refused (exit 2) if it is not one, comes from another
    /// build or format, is cut short or damaged.
    pub fn read(path: &Path) -> Result<Checkpoint> {
        let bytes = std::fs::read(path).map_err(|e| refuse(path, format!("cannot read: {e}")))?;
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(refuse(path, "not a vibrobed checkpoint"));
        }
        if bytes.len() < HEADER {
            return Err(refuse(path, "truncated (the header is incomplete)"));
        }
        let word = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"));
        let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
        if version != FORMAT_VERSION {
            return Err(refuse(
                path,
                format!("format version {version}; this build reads version {FORMAT_VERSION}"),
            ));
        }
        if word(12) != *BUILD_ID {
            return Err(refuse(
                path,
                "written by another build of vibrobed; a checkpoint resumes exactly only on the \
                 build that wrote it (run that build, or start the run again)",
            ));
        }
        let length = word(20);
        let payload = &bytes[HEADER..];
        if (payload.len() as u64) < length {
            return Err(refuse(
                path,
                format!("truncated ({} of {length} payload bytes)", payload.len()),
            ));
        }
        if payload.len() as u64 > length {
            return Err(refuse(path, "damaged (bytes after the payload)"));
        }
        if checksum(payload) != word(28) {
            return Err(refuse(path, "damaged (checksum mismatch)"));
        }
        postcard::from_bytes(payload).map_err(|e| refuse(path, format!("damaged ({e})")))
    }
}

/// The only scenario fields a resume may change: how long the run goes on.
pub const RESUMABLE_FIELDS: [&str; 3] = ["run.duration", "run.max_events", "run.max_wall_seconds"];

/// Checks that resume overrides touch only [`RESUMABLE_FIELDS`].
pub fn check_resume_sets(sets: &[String]) -> Result<()> {
    for set in sets {
        let key = set.split_once('=').map_or(set.as_str(), |(k, _)| k).trim();
        if !RESUMABLE_FIELDS.contains(&key) {
            return Err(Error::input(
                "--set",
                format!(
                    "a resumed run can change only {} (got `{set}`): the rest of the scene is \
                     the checkpoint's",
                    RESUMABLE_FIELDS.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses a resume that changes `run.duration` where a default of the scene follows the
/// duration (`saved`: the scene as checkpointed, `resumed`: with the resume's overrides;
/// `frames`: the resume writes frames at the default frame interval): the resumed run would
/// keep the first part's values and differ from the run made in one go. Inlets without `end`
/// (their window is the run), sampling at neither `output.sample_interval` nor
/// `output.frame_interval` (a 200th of the run), frames at no `output.frame_interval`.
pub fn check_resume_duration(saved: &Scenario, resumed: &Scenario, frames: bool) -> Result<()> {
    if saved.run.duration == resumed.run.duration {
        return Ok(());
    }
    let o = &saved.output;
    // An inlet that only recycles brings no disks of its own: its window does not matter.
    let brings = |i: &crate::scenario::Inlet| i.rate.is_some() || i.count.is_some();
    let inlet = (saved
        .inlets
        .iter()
        .position(|i| i.end.is_none() && brings(i)))
    .map(|k| format!("inlets.{k}.end is not given: the inlet's window is the run"));
    let sampling = (o.sample_interval.is_none() && o.frame_interval.is_none()).then(|| {
        "neither output.sample_interval nor output.frame_interval is given: samples are a \
         200th of the run apart"
            .to_string()
    });
    let framing = (frames && o.frame_interval.is_none()).then(|| {
        "output.frame_interval is not given: frames are a 200th of the run apart".to_string()
    });
    match inlet.or(sampling).or(framing) {
        None => Ok(()),
        Some(why) => Err(Error::input(
            "run.duration",
            format!(
                "this run cannot be resumed to another duration ({} → {}): {why}, so the \
                 resumed run would differ from one run to the new duration; run it again with \
                 that field given to extend it later, or resume it to its own duration",
                saved.run.duration, resumed.run.duration
            ),
        )),
    }
}
