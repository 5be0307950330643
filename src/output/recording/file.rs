//! The recording's file: Rerun's encoder writing `FILE.partial`, called on Rerun's forwarding
//! thread. It takes the place of Rerun's own file sink, whose writer thread stops silently on a
//! write error (a full disk) and whose flush then waits for ever. Here the first error is kept,
//! with the file and the operating system's reason; every later message is dropped, so nothing
//! waits on a file that cannot be written. [`RrdFile::finish`] completes the file (footer, sync,
//! rename to `FILE`) or, after an error, removes it.

use std::fs::File;
use std::path::Path;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use rerun::external::re_log_encoding::{CrateVersion, EncodeError, Encoder, EncodingOptions};
use rerun::log::LogMsg;
use rerun::sink::{LogSink, SinkFlushError};

use crate::output::partial::Partial;

/// The file and its encoder, shared by the sink (Rerun's thread) and the recorder's writer.
#[derive(Clone)]
pub(super) struct RrdFile(Arc<Mutex<State>>);

struct State {
    partial: Partial,
    /// `None` once finished.
    encoder: Option<Encoder<File>>,
    /// The first failure to write, said in full.
    error: Option<String>,
}

impl RrdFile {
    /// Creates `path`'s temporary file and writes the stream's header.
    pub(super) fn create(path: &Path) -> Result<RrdFile, String> {
        let (partial, file) = Partial::create(path).map_err(|e| cannot(path, &e))?;
        let encoder = Encoder::new_eager(
            CrateVersion::LOCAL,
            EncodingOptions::PROTOBUF_COMPRESSED,
            file,
        )
        .map_err(|e| {
            partial.discard();
            cannot_encode(&partial, &e)
        })?;
        Ok(RrdFile(Arc::new(Mutex::new(State {
            partial,
            encoder: Some(encoder),
            error: None,
        }))))
    }

    fn state(&self) -> MutexGuard<'_, State> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The first failure to write the file, if any.
    pub(super) fn error(&self) -> Option<String> {
        self.state().error.clone()
    }

    /// What the file is, on disk.
    pub(super) fn partial(&self) -> Partial {
        self.state().partial.clone()
    }

    /// Writes the footer, syncs the file and renames it to its final name; after a failure (now
    /// or earlier) removes it instead and returns the failure.
    pub(super) fn finish(&self) -> Result<(), String> {
        let mut s = self.state();
        let Some(mut encoder) = s.encoder.take() else {
            return s.error.clone().map_or(Ok(()), Err);
        };
        let completed = match &s.error {
            Some(e) => Err(e.clone()),
            None => encoder
                .finish()
                .and_then(|()| encoder.into_inner())
                .map_err(|e| cannot_encode(&s.partial, &e))
                .and_then(|file| {
                    s.partial
                        .commit(file)
                        .map_err(|e| cannot(&s.partial.tmp, &e))
                }),
        };
        if let Err(e) = &completed {
            s.partial.discard();
            s.error.get_or_insert_with(|| e.clone());
        }
        completed
    }
}

impl LogSink for RrdFile {
    fn send(&self, msg: LogMsg) {
        let mut s = self.state();
        if s.error.is_some() {
            return;
        }
        if let Some(encoder) = s.encoder.as_mut() {
            if let Err(e) = encoder.append(&msg) {
                s.error = Some(cannot_encode(&s.partial, &e));
            }
        }
    }

    fn flush_blocking(&self, _timeout: Duration) -> Result<(), SinkFlushError> {
        // Every message is written when sent: nothing is pending here.
        self.error()
            .map_or(Ok(()), |e| Err(SinkFlushError::failed(e)))
    }
}

/// `cannot write recording FILE: REASON`.
fn cannot(path: &Path, e: &std::io::Error) -> String {
    format!("cannot write recording {}: {e}", path.display())
}

/// The encoder's error, with the operating system's reason when it is one.
fn cannot_encode(partial: &Partial, e: &EncodeError) -> String {
    match e {
        EncodeError::Write(io) => cannot(&partial.tmp, io),
        other => format!("cannot write recording {}: {other}", partial.tmp.display()),
    }
}
