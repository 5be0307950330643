//! Running the real binary under guard, for the input-robustness tests: bounded address space
//! (a runaway allocation fails instead of starving the machine), bounded wall time (SIGINT first,
//! then SIGKILL), output captured to files, and the error line parsed into the field it names.
#![allow(dead_code)]

use std::ffi::OsString;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// Address space allowed to the binary, in KiB (4 GiB).
const ADDRESS_SPACE_KIB: u64 = 4 * 1024 * 1024;

/// The crate root: shipped scenarios are found relative to it.
pub fn crate_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A shipped scenario, by its name under `scenarios/`.
pub fn scenario(name: &str) -> PathBuf {
    crate_root().join("scenarios").join(name)
}

/// A fresh, empty directory under the system's temporary directory.
pub fn fresh_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("vibrobed-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temporary directory");
    dir
}

/// The names of the entries of `dir` (sorted; empty when it does not exist).
pub fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|it| {
            it.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

/// When to stop a process that does not end by itself.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// SIGINT after this long.
    pub interrupt_after: Duration,
    /// SIGKILL this long after the SIGINT.
    pub kill_after: Duration,
}

impl Limits {
    /// SIGINT after `secs` seconds, SIGKILL 5 s later.
    pub fn secs(secs: u64) -> Limits {
        Limits {
            interrupt_after: Duration::from_secs(secs),
            kill_after: Duration::from_secs(5),
        }
    }
}

/// How a guarded process ended.
#[derive(Debug)]
pub struct Outcome {
    /// Its exit status.
    pub status: ExitStatus,
    /// What it wrote on stdout.
    pub stdout: String,
    /// What it wrote on stderr.
    pub stderr: String,
    /// Wall time until it ended.
    pub elapsed: Duration,
    /// When the guard sent SIGINT (since the start), if it had to.
    pub interrupted_at: Option<Duration>,
    /// The guard had to SIGKILL it.
    pub killed: bool,
}

impl Outcome {
    /// The exit code (None when a signal ended it).
    pub fn code(&self) -> Option<i32> {
        self.status.code()
    }

    /// The signal that ended it, if one did.
    pub fn signal(&self) -> Option<i32> {
        self.status.signal()
    }

    /// It panicked (the message on stderr, or the panic's exit code 101, or an abort).
    pub fn panicked(&self) -> bool {
        self.stderr.contains("panicked")
            || self.code() == Some(101)
            || self.code() == Some(134)
            || self.signal() == Some(6)
    }

    /// For a `run` whose outputs went to `dir`: whether it ended early within the contract
    /// (`Some`) — 4 or 5, stopped by `run.max_events` or `run.max_wall_seconds`, with
    /// `dir/summary.json` saying so, or 6, a clock that stopped advancing, said on stderr — and
    /// what is wrong with it, if anything. `None` for any other ending.
    pub fn ended_early(&self, dir: &Path) -> Option<Result<(), String>> {
        let code = self.code()?;
        let ending = match code {
            4 => "event-limit",
            5 => "wall-limit",
            6 if self.stderr.contains("stopped advancing") => return Some(Ok(())),
            _ => return None,
        };
        let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap_or_default();
        let said = serde_json::from_str::<serde_json::Value>(&summary)
            .ok()
            .and_then(|v| v["ending"].as_str().map(String::from));
        Some(match said.as_deref() == Some(ending) {
            true => Ok(()),
            false => Err(format!(
                "exit {code} with a summary ending {said:?}, not {ending:?}"
            )),
        })
    }

    /// A one-paragraph account, for assertion messages.
    pub fn describe(&self) -> String {
        format!(
            "exit {:?}, signal {:?}, {:.2} s{}{}\n--- stdout ---\n{}\n--- stderr ---\n{}",
            self.code(),
            self.signal(),
            self.elapsed.as_secs_f64(),
            match self.interrupted_at {
                Some(t) => format!(", SIGINT sent at {:.2} s", t.as_secs_f64()),
                None => String::new(),
            },
            if self.killed { ", SIGKILL sent" } else { "" },
            tail(&self.stdout, 2000),
            tail(&self.stderr, 4000),
        )
    }
}

/// The last `n` bytes of `s` (on a character boundary).
fn tail(s: &str, n: usize) -> &str {
    let mut start = s.len().saturating_sub(n);
    while !s.is_char_boundary(start) {
        start += 1;
    }
    &s[start..]
}

/// Sends `signal` (a name such as `INT`) to process `pid`.
pub fn send_signal(pid: u32, signal: &str) {
    let _ = Command::new("kill")
        .arg(format!("-{signal}"))
        .arg(pid.to_string())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
}

/// A started vibrobed process, its output going to files in `logs`.
pub struct Running {
    child: std::process::Child,
    logs: PathBuf,
    start: Instant,
    interrupted_at: Option<Duration>,
}

/// Starts the binary with `args` in `cwd`, under the address-space bound, its output captured
/// in `logs` (which must not be where the binary writes).
pub fn start(args: &[OsString], cwd: &Path, logs: &Path) -> Running {
    std::fs::create_dir_all(logs).expect("log directory");
    let out = std::fs::File::create(logs.join("stdout.txt")).expect("stdout file");
    let err = std::fs::File::create(logs.join("stderr.txt")).expect("stderr file");
    let child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {ADDRESS_SPACE_KIB} 2>/dev/null; exec \"$0\" \"$@\""
        ))
        .arg(env!("CARGO_BIN_EXE_vibrobed"))
        .args(args)
        .current_dir(cwd)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(out)
        .stderr(err)
        .spawn()
        .expect("the vibrobed binary starts");
    Running {
        child,
        logs: logs.to_path_buf(),
        start: Instant::now(),
        interrupted_at: None,
    }
}

impl Running {
    /// Time since the start.
    pub fn elapsed(&self) -> Duration {
        self.start.elapsed()
    }

    /// Whether it has ended.
    pub fn ended(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(Some(_)))
    }

    /// Sends SIGINT now.
    pub fn interrupt(&mut self) {
        if self.interrupted_at.is_none() {
            self.interrupted_at = Some(self.start.elapsed());
        }
        send_signal(self.child.id(), "INT");
    }

    /// Waits for the end, interrupting then killing it by `limits` (counted from the start for
    /// the SIGINT, from the SIGINT for the SIGKILL).
    pub fn wait(mut self, limits: Limits) -> Outcome {
        let mut killed = false;
        let status = loop {
            if let Some(status) = self.child.try_wait().expect("wait on vibrobed") {
                break status;
            }
            let now = self.start.elapsed();
            match self.interrupted_at {
                None if now >= limits.interrupt_after => self.interrupt(),
                Some(at) if !killed && now >= at + limits.kill_after => {
                    let _ = self.child.kill();
                    killed = true;
                }
                _ => {}
            }
            std::thread::sleep(Duration::from_millis(10));
        };
        let elapsed = self.start.elapsed();
        let read = |name: &str| {
            String::from_utf8_lossy(&std::fs::read(self.logs.join(name)).unwrap_or_default())
                .into_owned()
        };
        Outcome {
            status,
            stdout: read("stdout.txt"),
            stderr: read("stderr.txt"),
            elapsed,
            interrupted_at: self.interrupted_at,
            killed,
        }
    }
}

/// Runs the binary with `args` in `cwd` to its end under `limits`.
pub fn run(args: &[OsString], cwd: &Path, logs: &Path, limits: Limits) -> Outcome {
    start(args, cwd, logs).wait(limits)
}

/// Arguments from anything string-like.
pub fn args<S: AsRef<std::ffi::OsStr>>(items: &[S]) -> Vec<OsString> {
    items.iter().map(|s| s.as_ref().to_os_string()).collect()
}

/// The error line of a refusal: the last `vibrobed: …` line that is not a note.
pub fn error_line(stderr: &str) -> Option<&str> {
    stderr
        .lines()
        .rev()
        .filter_map(|l| l.strip_prefix("vibrobed: "))
        .find(|rest| !rest.starts_with("note:"))
}

/// The field a refusal names (`vibrobed: <field>: <message>`): a dotted path or an argument
/// (`--seeds`, `--set particles.count`, `SCENARIO`); None when the error line names none.
pub fn error_field(stderr: &str) -> Option<String> {
    let line = error_line(stderr)?;
    let (field, _) = line.split_once(": ")?;
    let path = field.strip_prefix("--set ").unwrap_or(field);
    let plausible = !path.is_empty()
        && path
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "._-[]".contains(c));
    plausible.then(|| field.to_string())
}

/// Whether `field` is `expected` or lies under it (`particles.radius.species.0.count` lies under
/// `particles.radius.species`).
pub fn names(field: &str, expected: &str) -> bool {
    let field = field.strip_prefix("--set ").unwrap_or(field);
    field == expected
        || field
            .strip_prefix(expected)
            .is_some_and(|rest| rest.starts_with('.') || rest.starts_with('['))
}
