//! Watching a run's output files while it runs. Writes to a file that was removed (or whose
//! directory was) succeed and are lost, and a result written at the end would only then find its
//! directory gone; so a thread looks four times a second that each streamed file is still the
//! one being written and that the directory of each file written later still exists, and says
//! so on stderr the moment one is not. The run learns which outputs are gone from
//! [`Watch::gone`] and goes on without them.

use super::partial::Partial;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

/// Time between two looks.
const PERIOD: Duration = Duration::from_millis(250);

/// One output to watch.
#[derive(Debug)]
pub struct Target {
    /// What it is: `recording`, `trajectory`, `checkpoint`, `summary`, `profiles`.
    pub output: &'static str,
    what: What,
}

#[derive(Debug)]
enum What {
    /// A file written during the run under its temporary name.
    Streamed(Partial),
    /// A file written later: its directory must stay.
    Later(PathBuf),
}

impl Target {
    /// A file being written under its temporary name.
    pub fn streamed(output: &'static str, file: Partial) -> Target {
        Target {
            output,
            what: What::Streamed(file),
        }
    }

    /// A file that will be written in `path`'s directory.
    pub fn later(output: &'static str, path: &Path) -> Target {
        Target {
            output,
            what: What::Later(path.to_owned()),
        }
    }

    /// Whether the run is done with it (a streamed file renamed into place or removed).
    fn settled(&self) -> bool {
        matches!(&self.what, What::Streamed(p) if p.settled())
    }

    /// `None` while the output can still be written, else why not (a sentence naming the file).
    fn fault(&self) -> Option<String> {
        match &self.what {
            What::Streamed(p) => p.check().err().map(|e| {
                format!(
                    "{} {}: {e}; the run goes on without it",
                    self.output,
                    p.tmp.display()
                )
            }),
            What::Later(path) => {
                let dir = match path.parent() {
                    Some(d) if !d.as_os_str().is_empty() => d,
                    _ => Path::new("."),
                };
                match std::fs::metadata(dir) {
                    Ok(m) if m.is_dir() => None,
                    Ok(_) => Some(format!("{} is no longer a directory", dir.display())),
                    Err(e) => Some(format!("{}: {e}", dir.display())),
                }
                .map(|why| {
                    format!(
                        "{} {}: its directory is gone during the run ({why}); it cannot be \
                         written unless the directory comes back",
                        self.output,
                        path.display()
                    )
                })
            }
        }
    }
}

/// What the watching thread and the run share.
#[derive(Default)]
struct Shared {
    stop: AtomicBool,
    /// Outputs found gone, not yet taken by [`Watch::gone`].
    gone: Mutex<Vec<&'static str>>,
}

/// The watching thread (stopped and joined on drop).
pub struct Watch {
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
}

impl Watch {
    /// Starts watching `targets` (no thread when there are none).
    pub fn start(targets: Vec<Target>) -> Watch {
        let shared = Arc::new(Shared::default());
        let thread = if targets.is_empty() {
            None
        } else {
            let shared = Arc::clone(&shared);
            std::thread::Builder::new()
                .name("vibrobed-watch".into())
                .spawn(move || watch(targets, &shared))
                .ok()
        };
        Watch { shared, thread }
    }

    /// The outputs found gone since the last call.
    pub fn gone(&self) -> Vec<&'static str> {
        std::mem::take(&mut *self.shared.gone.lock().unwrap_or_else(|e| e.into_inner()))
    }
}

/// The thread: looks every [`PERIOD`] until stopped; says each fault once.
fn watch(mut targets: Vec<Target>, shared: &Shared) {
    while !shared.stop.load(Ordering::Relaxed) {
        targets.retain(|t| match t.fault() {
            _ if t.settled() => false,
            None => true,
            Some(fault) => {
                eprintln!("vibrobed: warning: {fault}");
                shared
                    .gone
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push(t.output);
                false
            }
        });
        std::thread::park_timeout(PERIOD);
    }
}

impl Drop for Watch {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            thread.thread().unpark();
            let _ = thread.join();
        }
    }
}
