//! Files written under a temporary name: a streamed output (recording, trajectory) goes to
//! `FILE.partial` beside `FILE` and is renamed into place only when complete, so that nothing
//! incomplete ever sits under a final name. A killed process leaves `FILE.partial`; a run that
//! cannot write it removes it (the disk it filled gets its room back).

use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// `FILE.partial`, the name `FILE` is written under until it is complete.
pub fn partial_name(path: &Path) -> PathBuf {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".partial");
    PathBuf::from(tmp)
}

/// A file being written under its temporary name: which file it is on disk, so that its removal
/// (or its directory's) during the run can be noticed. Clones share whether the writer is done
/// with it (renamed or removed it), after which it is no longer watched.
#[derive(Debug, Clone)]
pub struct Partial {
    /// The temporary name.
    pub tmp: PathBuf,
    /// The final name.
    pub path: PathBuf,
    /// Device and inode of the file created.
    id: (u64, u64),
    /// Renamed into place or removed by its writer.
    settled: Arc<AtomicBool>,
}

impl Partial {
    /// Creates (truncating) `FILE.partial` for `path`.
    pub fn create(path: &Path) -> io::Result<(Partial, File)> {
        let tmp = partial_name(path);
        let file = File::create(&tmp)?;
        let partial = Partial {
            id: file_id(&file.metadata()?),
            tmp,
            path: path.to_owned(),
            settled: Arc::default(),
        };
        Ok((partial, file))
    }

    /// Whether its writer is done with it (renamed it into place or removed it).
    pub fn settled(&self) -> bool {
        self.settled.load(Ordering::Relaxed)
    }

    /// Fails when the temporary file is no longer the one created: removed, replaced, or its
    /// directory gone. Writes to such a file would succeed and be lost.
    pub fn check(&self) -> io::Result<()> {
        match std::fs::metadata(&self.tmp) {
            Ok(m) if file_id(&m) == self.id => Ok(()),
            Ok(_) => Err(io::Error::other("replaced by another file during the run")),
            Err(e) if e.kind() == io::ErrorKind::NotFound => Err(io::Error::new(
                io::ErrorKind::NotFound,
                "removed during the run (or its directory)",
            )),
            Err(e) => Err(e),
        }
    }

    /// Syncs `file` and renames it to its final name.
    pub fn commit(&self, file: File) -> io::Result<()> {
        self.check()?;
        self.settled.store(true, Ordering::Relaxed);
        file.sync_all()?;
        drop(file);
        std::fs::rename(&self.tmp, &self.path)
    }

    /// Removes the temporary file (a failed output: its room goes back to the disk).
    pub fn discard(&self) {
        if self.check().is_ok() && !self.settled.swap(true, Ordering::Relaxed) {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

#[cfg(unix)]
fn file_id(m: &std::fs::Metadata) -> (u64, u64) {
    use std::os::unix::fs::MetadataExt;
    (m.dev(), m.ino())
}

#[cfg(not(unix))]
fn file_id(_: &std::fs::Metadata) -> (u64, u64) {
    (0, 0)
}
