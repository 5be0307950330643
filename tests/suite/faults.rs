//! Faults of the machine, injected into the real binary (issue 43): a filesystem that fills (a
//! file-size limit per process, RLIMIT_FSIZE, which needs no root; a small tmpfs where the test
//! may mount one), a directory the run may not write (before and during the run), and outputs
//! removed during the run; each output alone and all together, under `run`, `resume` and
//! `sweep run`. Each case asserts the exit code, the message (the file and the system's reason),
//! the time to exit, that SIGINT and SIGTERM work during the fault, and which files exist after.
//!
//! The policy checked (docs/book/src/outputs.md): a recording, trajectory, checkpoint or 2D
//! fields file that cannot be written is a warning, the run goes on and exits 3, its summary
//! listing `output_failures`; a summary or profiles that cannot be written exit 1 (the summary then goes
//! to stdout); a directory that cannot be written in is refused before the run (exit 2); no
//! temporary file is left behind.
#![cfg(target_os = "linux")]

use crate::guarded::entries as names;
use serde_json::Value;
use std::io::Read;
use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The file-size limit of a filling disk: the summary (8 kB) fits, the recording, the
/// trajectory and the checkpoint of the vibrated bed do not.
const FILLS_AT: u64 = 150_000;

/// Longest a run of the vibrated bed to t = 20 may take, faults and all (it takes 0.1 s).
const SHORT_RUN: Duration = Duration::from_secs(30);

/// Longest an interrupted run may take to exit after the signal.
const AFTER_SIGNAL: Duration = Duration::from_secs(5);

/// The scene of the issue: the vibrated bed to t = 20.
fn bed(duration: &str) -> Vec<String> {
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/vibrated_bed.json");
    vec![
        "run".into(),
        scenario.display().to_string(),
        "--quiet".into(),
        "--set".into(),
        format!("run.duration={duration}"),
        "--set".into(),
        "run.warmup=5".into(),
        "--set".into(),
        "output.frame_interval=0.1".into(),
    ]
}

/// A fresh, empty directory for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("vibrobed-faults-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o777)).expect("chmod");
    dir
}

/// `vibrobed sweep run SWEEP --out OUT --quiet` and `more` arguments.
fn sweep_run_args(sweep: &Path, out: &Path, more: &[&str]) -> Vec<String> {
    let mut args = vec![
        "sweep".to_string(),
        "run".to_string(),
        sweep.display().to_string(),
        "--out".to_string(),
        out.display().to_string(),
        "--quiet".to_string(),
    ];
    args.extend(more.iter().map(|a| a.to_string()));
    args
}

/// What a started process runs under.
#[derive(Default, Clone)]
struct Under {
    /// RLIMIT_FSIZE in bytes.
    file_size: Option<u64>,
    /// Run as this user and group (a root test dropping its rights so that permissions deny).
    user: Option<(u32, u32)>,
    /// The binary to run (default: the one cargo built).
    binary: Option<PathBuf>,
}

/// A started vibrobed, its output read by threads (pipes: no file-size limit on them).
struct Running {
    child: Child,
    start: Instant,
    stdout: Arc<Mutex<String>>,
    stderr: Arc<Mutex<String>>,
    signalled: Option<Instant>,
}

/// How it ended.
struct Ended {
    code: Option<i32>,
    stdout: String,
    stderr: String,
    elapsed: Duration,
    /// Time from the signal to the exit, if one was sent.
    after_signal: Option<Duration>,
}

impl Ended {
    fn describe(&self) -> String {
        format!(
            "exit {:?} after {:.2} s{}\n--- stderr ---\n{}\n--- stdout (start) ---\n{}",
            self.code,
            self.elapsed.as_secs_f64(),
            self.after_signal.map_or(String::new(), |d| format!(
                " ({:.2} s after the signal)",
                d.as_secs_f64()
            )),
            self.stderr,
            self.stdout.chars().take(400).collect::<String>()
        )
    }

    /// Asserts the exit code, no panic, and that it ended in time.
    fn assert(&self, code: i32, within: Duration) {
        assert_eq!(self.code, Some(code), "{}", self.describe());
        assert!(!self.stderr.contains("panicked"), "{}", self.describe());
        let took = self.after_signal.unwrap_or(self.elapsed);
        assert!(took < within, "too slow: {}", self.describe());
    }

    /// Asserts a message on stderr holding all of `needles`, on one line.
    fn says(&self, needles: &[&str]) {
        assert!(
            self.stderr
                .lines()
                .any(|l| needles.iter().all(|n| l.contains(n))),
            "no line with {needles:?}: {}",
            self.describe()
        );
    }
}

/// Starts the binary with `args` in `cwd` under `under`.
fn start(args: &[String], cwd: &Path, under: &Under) -> Running {
    let binary = under
        .binary
        .clone()
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_vibrobed")));
    let mut cmd = Command::new(binary);
    cmd.args(args)
        .current_dir(cwd)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let (file_size, user) = (under.file_size, under.user);
    // SAFETY: only async-signal-safe calls between fork and exec.
    unsafe {
        cmd.pre_exec(move || {
            if let Some(bytes) = file_size {
                let limit = libc::rlimit {
                    rlim_cur: bytes,
                    rlim_max: bytes,
                };
                if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
            }
            if let Some((uid, gid)) = user {
                if libc::setgroups(0, std::ptr::null()) != 0
                    || libc::setgid(gid) != 0
                    || libc::setuid(uid) != 0
                {
                    return Err(std::io::Error::last_os_error());
                }
            }
            Ok(())
        });
    }
    // A copy of the binary just written may be busy while another test forks (the copy's
    // descriptor lives in that child until it execs): try again.
    let mut tries = 0;
    let mut child = loop {
        match cmd.spawn() {
            Err(e) if e.kind() == std::io::ErrorKind::ExecutableFileBusy && tries < 100 => {
                tries += 1;
                std::thread::sleep(Duration::from_millis(20));
            }
            spawned => break spawned.expect("the vibrobed binary starts"),
        }
    };
    let reader = |mut pipe: Box<dyn Read + Send>| {
        let text = Arc::new(Mutex::new(String::new()));
        let sink = Arc::clone(&text);
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n @ 1..) = pipe.read(&mut buf) {
                sink.lock()
                    .unwrap()
                    .push_str(&String::from_utf8_lossy(&buf[..n]));
            }
        });
        text
    };
    let stdout = reader(Box::new(child.stdout.take().unwrap()));
    let stderr = reader(Box::new(child.stderr.take().unwrap()));
    Running {
        child,
        start: Instant::now(),
        stdout,
        stderr,
        signalled: None,
    }
}

impl Running {
    /// Waits until stderr holds every one of `needles` (fails after `within`).
    fn wait_for(&mut self, needles: &[&str], within: Duration) -> Duration {
        let since = Instant::now();
        loop {
            let err = self.stderr.lock().unwrap().clone();
            if needles.iter().all(|n| err.contains(n)) {
                return since.elapsed();
            }
            if since.elapsed() > within || matches!(self.child.try_wait(), Ok(Some(_))) {
                let _ = self.child.kill();
                panic!("{needles:?} not said within {within:?}; stderr:\n{err}");
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Waits until `path` exists.
    fn wait_for_file(&mut self, path: &Path) {
        let since = Instant::now();
        while !path.exists() {
            assert!(
                since.elapsed() < SHORT_RUN && matches!(self.child.try_wait(), Ok(None)),
                "{} never appeared; stderr:\n{}",
                path.display(),
                self.stderr.lock().unwrap()
            );
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Sends `signal` (libc's number).
    fn signal(&mut self, signal: i32) {
        self.signalled = Some(Instant::now());
        // SAFETY: kill(2) on our own child.
        unsafe { libc::kill(self.child.id() as i32, signal) };
    }

    /// Waits for the end; kills it after `limit`.
    fn wait(mut self, limit: Duration) -> Ended {
        let status = loop {
            if let Some(status) = self.child.try_wait().expect("wait") {
                break status;
            }
            if self.start.elapsed() > limit {
                let _ = self.child.kill();
            }
            std::thread::sleep(Duration::from_millis(5));
        };
        let elapsed = self.start.elapsed();
        let after_signal = self.signalled.map(|t| t.elapsed());
        std::thread::sleep(Duration::from_millis(50)); // the readers take the last bytes
        let text = |t: &Arc<Mutex<String>>| t.lock().unwrap().clone();
        Ended {
            code: status.code(),
            stdout: text(&self.stdout),
            stderr: text(&self.stderr),
            elapsed,
            after_signal,
        }
    }
}

/// Runs to the end.
fn run(args: &[String], cwd: &Path, under: &Under) -> Ended {
    start(args, cwd, under).wait(SHORT_RUN * 2)
}

/// The summary in `path`.
fn summary(path: &Path) -> Value {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("no summary {}: {e}", path.display()));
    serde_json::from_str(&text).expect("the summary is JSON")
}

/// The outputs a summary lists as failed, sorted.
fn failed_outputs(summary: &Value) -> Vec<String> {
    let mut outputs: Vec<String> = summary["output_failures"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|f| f["output"].as_str().unwrap().to_string())
                .collect()
        })
        .unwrap_or_default();
    outputs.sort();
    outputs
}

/// `--rrd`, `--trajectory`, `--checkpoint` (every 1) into `dir`, for the outputs named.
fn output_args(dir: &Path, outputs: &[&str]) -> Vec<String> {
    let mut args = Vec::new();
    for output in outputs {
        let (flag, file) = match *output {
            "recording" => ("--rrd", "a.rrd"),
            "trajectory" => ("--trajectory", "a.xyz"),
            "checkpoint" => ("--checkpoint", "a.ckpt"),
            other => panic!("{other}"),
        };
        args.extend([flag.to_string(), dir.join(file).display().to_string()]);
        if *output == "checkpoint" {
            args.extend(["--checkpoint-every".into(), "1".into()]);
        }
    }
    args
}

/// Each file an output writes, by its name.
fn file_of(output: &str) -> &'static str {
    match output {
        "recording" => "a.rrd",
        "trajectory" => "a.xyz",
        _ => "a.ckpt",
    }
}

/// Each output alone and all together, on a disk that fills during the run: a warning naming the
/// file and the reason, the run goes on, the summary lists the failure, exit 3, and no temporary
/// file or incomplete output is left.
#[test]
fn a_filling_disk_costs_only_the_outputs_that_fill_it() {
    let under = Under {
        file_size: Some(FILLS_AT),
        ..Under::default()
    };
    let all = ["checkpoint", "recording", "trajectory"];
    let cases: Vec<Vec<&str>> = vec![
        vec!["recording"],
        vec!["trajectory"],
        vec!["checkpoint"],
        all.to_vec(),
    ];
    for outputs in cases {
        let dir = scratch(&format!("fill-{}", outputs.len()));
        let mut args = bed("20");
        args.extend(output_args(&dir, &outputs));
        args.extend(["--summary".into(), dir.join("s.json").display().to_string()]);
        args.extend(["--profiles".into(), dir.join("p.csv").display().to_string()]);
        let ended = run(&args, &dir, &under);
        ended.assert(3, SHORT_RUN);
        for output in &outputs {
            ended.says(&[
                &format!("warning: cannot write {output} "),
                &dir.join(file_of(output)).display().to_string(),
                "File too large",
            ]);
        }
        let s = summary(&dir.join("s.json"));
        assert_eq!(s["ending"], "completed", "{outputs:?}");
        assert_eq!(s["sim_time"], 20.0);
        assert_eq!(failed_outputs(&s), outputs, "{}", ended.describe());
        assert_eq!(names(&dir), ["p.csv", "s.json"], "{}", ended.describe());
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// The file-size limit under which the bed's 2D fields (76 kB as VTI, 109 kB as CSV) cannot be
/// written but its summary (12 kB) can.
const FIELDS_DO_NOT_FIT: u64 = 40_000;

/// The 2D fields, an output at the run's end, that cannot be written: said once, naming the file
/// and the reason, and that the run ends without them; the summary lists them alone in
/// `output_failures` and the completed run exits 3; neither the file nor a temporary one is left.
#[test]
fn fields_that_cannot_be_written_exit_3() {
    let under = Under {
        file_size: Some(FIELDS_DO_NOT_FIT),
        ..Under::default()
    };
    for file in ["f.vti", "f.csv"] {
        let dir = scratch(&format!("fields-{file}"));
        let path = dir.join(file).display().to_string();
        let mut args = bed("20");
        args.extend(["--fields".into(), path.clone()]);
        args.extend(["--summary".into(), dir.join("s.json").display().to_string()]);
        let ended = run(&args, &dir, &under);
        ended.assert(3, SHORT_RUN);
        ended.says(&[
            &format!("warning: cannot write fields {path}: File too large"),
            "the run ends without its fields",
        ]);
        let s = summary(&dir.join("s.json"));
        assert_eq!(s["ending"], "completed", "{file}");
        assert_eq!(failed_outputs(&s), ["fields"], "{}", ended.describe());
        assert_eq!(s["output_failures"][0]["path"], path.as_str());
        assert_eq!(names(&dir), ["s.json"], "{}", ended.describe());
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// `resume` on a disk that fills: the checkpoint it resumed from stays whole (a failed write
/// never replaces it), the recording and trajectory of the resumed part are dropped, exit 3.
#[test]
fn a_resume_on_a_filling_disk_keeps_its_checkpoint() {
    let dir = scratch("resume");
    let ckpt = dir.join("a.ckpt");
    let mut args = bed("20");
    args.extend(["--set".into(), "run.duration=6".into()]);
    args.extend(["--checkpoint".into(), ckpt.display().to_string()]);
    args.extend([
        "--summary".into(),
        dir.join("first.json").display().to_string(),
    ]);
    run(&args, &dir, &Under::default()).assert(0, SHORT_RUN);
    let saved = std::fs::read(&ckpt).expect("the first part's checkpoint");

    let mut args: Vec<String> = ["resume", &ckpt.display().to_string(), "--quiet"]
        .map(String::from)
        .to_vec();
    args.extend(["--set".into(), "run.duration=20".into()]);
    args.extend(["--checkpoint-every".into(), "1".into()]);
    args.extend(output_args(&dir, &["recording", "trajectory"]));
    args.extend(["--summary".into(), dir.join("s.json").display().to_string()]);
    let ended = run(
        &args,
        &dir,
        &Under {
            file_size: Some(FILLS_AT),
            ..Under::default()
        },
    );
    ended.assert(3, SHORT_RUN);
    ended.says(&[
        "cannot write checkpoint",
        &ckpt.display().to_string(),
        "File too large",
    ]);
    let s = summary(&dir.join("s.json"));
    assert_eq!(s["ending"], "completed");
    assert_eq!(s["sim_time"], 20.0);
    assert_eq!(
        failed_outputs(&s),
        ["checkpoint", "recording", "trajectory"]
    );
    let checkpoint_failures = s["output_failures"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["output"] == "checkpoint")
        .unwrap()["failures"]
        .as_u64()
        .unwrap();
    assert!(checkpoint_failures > 10, "tried again at every interval");
    assert_eq!(
        std::fs::read(&ckpt).unwrap(),
        saved,
        "the checkpoint changed"
    );
    assert_eq!(names(&dir), ["a.ckpt", "first.json", "s.json"]);
    std::fs::remove_dir_all(&dir).ok();
}

/// `sweep run` on a disk that fills: each run that lost its recording keeps its summary beside
/// error.txt, the sweep exits 1 naming the failures, and the next `sweep run` runs them again.
#[test]
fn a_sweep_on_a_filling_disk_runs_its_lost_recordings_again() {
    let dir = scratch("sweep");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/vibrated_bed.json");
    let sweep = dir.join("sweep.json");
    std::fs::write(
        &sweep,
        format!(
            r#"{{ "name": "fills", "scenario": "{}", "set": ["run.duration=20", "run.warmup=5"],
                 "axes": [{{ "key": "floor.gamma", "values": [2.5, 3.0] }}], "record": true }}"#,
            scenario.display()
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let args = sweep_run_args(&sweep, &out, &["--jobs", "1"]);
    let ended = run(
        &args,
        &dir,
        &Under {
            file_size: Some(FILLS_AT),
            ..Under::default()
        },
    );
    ended.assert(1, SHORT_RUN);
    ended.says(&[
        "2 of 2 runs failed",
        "recording.rrd.partial",
        "File too large",
    ]);
    for k in ["0", "1"] {
        let folder = out.join(k);
        assert_eq!(
            names(&folder),
            ["error.txt", "profiles.csv", "summary.json"],
            "run {k}"
        );
        let error = std::fs::read_to_string(folder.join("error.txt")).unwrap();
        assert!(error.contains("File too large"), "{error}");
        assert_eq!(
            failed_outputs(&summary(&folder.join("summary.json"))),
            ["recording"]
        );
    }

    let again = run(&args, &dir, &Under::default());
    again.assert(0, SHORT_RUN);
    again.says(&["2 ran now, 0 done before"]);
    for k in ["0", "1"] {
        assert_eq!(
            names(&out.join(k)),
            ["profiles.csv", "recording.rrd", "summary.json"]
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// SIGINT and SIGTERM while every output is failing: the run stops at once with the signal's
/// exit code, and its summary says it was interrupted and what it could not write.
#[test]
fn signals_are_honoured_while_outputs_fail() {
    for (signal, code) in [(libc::SIGINT, 130), (libc::SIGTERM, 143)] {
        let dir = scratch(&format!("signal-{signal}"));
        let mut args = bed("100000");
        args.extend(output_args(
            &dir,
            &["checkpoint", "recording", "trajectory"],
        ));
        args.extend(["--summary".into(), dir.join("s.json").display().to_string()]);
        let mut running = start(
            &args,
            &dir,
            &Under {
                file_size: Some(FILLS_AT),
                ..Under::default()
            },
        );
        running.wait_for(
            &[
                "cannot write checkpoint",
                "cannot write recording",
                "cannot write trajectory",
            ],
            SHORT_RUN,
        );
        running.signal(signal);
        let ended = running.wait(SHORT_RUN * 2);
        ended.assert(code, AFTER_SIGNAL);
        let s = summary(&dir.join("s.json"));
        assert_eq!(s["ending"], "interrupted");
        assert_eq!(
            failed_outputs(&s),
            ["checkpoint", "recording", "trajectory"]
        );
        assert_eq!(names(&dir), ["s.json"], "{}", ended.describe());
        std::fs::remove_dir_all(&dir).ok();
    }
}

/// SIGINT during the fault under `resume` (its checkpoint stays as it was) and `sweep run` (the
/// run in flight stops, its summary says so and lists the lost recording; a rerun runs it again).
#[test]
fn sigint_is_honoured_while_outputs_fail_under_resume_and_sweep() {
    let dir = scratch("signal-resume");
    let ckpt = dir.join("a.ckpt");
    let mut args = bed("6");
    args.extend(["--checkpoint".into(), ckpt.display().to_string()]);
    args.extend([
        "--summary".into(),
        dir.join("first.json").display().to_string(),
    ]);
    run(&args, &dir, &Under::default()).assert(0, SHORT_RUN);
    let saved = std::fs::read(&ckpt).unwrap();
    let mut args: Vec<String> = ["resume", &ckpt.display().to_string(), "--quiet"]
        .map(String::from)
        .to_vec();
    args.extend(["--set".into(), "run.duration=100000".into()]);
    args.extend(["--checkpoint-every".into(), "1".into()]);
    args.extend(output_args(&dir, &["recording"]));
    args.extend(["--summary".into(), dir.join("s.json").display().to_string()]);
    let filling = Under {
        file_size: Some(FILLS_AT),
        ..Under::default()
    };
    let mut running = start(&args, &dir, &filling);
    running.wait_for(
        &["cannot write checkpoint", "cannot write recording"],
        SHORT_RUN,
    );
    running.signal(libc::SIGINT);
    let ended = running.wait(SHORT_RUN * 2);
    ended.assert(130, AFTER_SIGNAL);
    assert_eq!(summary(&dir.join("s.json"))["ending"], "interrupted");
    assert_eq!(
        std::fs::read(&ckpt).unwrap(),
        saved,
        "the checkpoint changed"
    );
    assert_eq!(names(&dir), ["a.ckpt", "first.json", "s.json"]);
    std::fs::remove_dir_all(&dir).ok();

    let dir = scratch("signal-sweep");
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/vibrated_bed.json");
    let sweep = dir.join("sweep.json");
    std::fs::write(
        &sweep,
        format!(
            r#"{{ "scenario": "{}", "record": true,
                 "set": ["run.duration=100000", "run.warmup=5", "output.frame_interval=0.1"] }}"#,
            scenario.display()
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let args = sweep_run_args(&sweep, &out, &[]);
    let mut running = start(&args, &dir, &filling);
    running.wait_for_file(&out.join("0").join("recording.rrd.partial"));
    // The recording fills its 150 kB within the first hundred frames; give it a second.
    std::thread::sleep(Duration::from_secs(1));
    running.signal(libc::SIGINT);
    let ended = running.wait(SHORT_RUN * 2);
    ended.assert(130, AFTER_SIGNAL);
    let folder = out.join("0");
    let s = summary(&folder.join("summary.json"));
    assert_eq!(s["ending"], "interrupted");
    assert_eq!(failed_outputs(&s), ["recording"]);
    assert_eq!(
        names(&folder),
        ["error.txt", "profiles.csv", "summary.json"]
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Outputs removed during the run (the files, then the directory of the checkpoint and the
/// summary): each is said within a second, the run goes on without them, SIGINT ends it, and
/// the summary, which cannot be written where asked, comes on stdout (exit 1).
#[test]
fn outputs_removed_during_the_run_are_noticed_within_a_second() {
    let dir = scratch("removed");
    let sub = dir.join("sub");
    std::fs::create_dir(&sub).unwrap();
    let mut args = bed("100000");
    args.extend(output_args(&dir, &["recording", "trajectory"]));
    args.extend([
        "--checkpoint".into(),
        sub.join("c.ckpt").display().to_string(),
    ]);
    args.extend(["--checkpoint-every".into(), "1".into()]);
    args.extend(["--summary".into(), sub.join("s.json").display().to_string()]);
    let mut running = start(&args, &dir, &Under::default());
    let (rrd, xyz) = (dir.join("a.rrd.partial"), dir.join("a.xyz.partial"));
    running.wait_for_file(&rrd);
    running.wait_for_file(&xyz);
    std::fs::remove_file(&rrd).unwrap();
    std::fs::remove_file(&xyz).unwrap();
    let took = running.wait_for(
        &[
            "recording a.rrd.partial: removed during the run",
            "trajectory a.xyz.partial: removed during the run",
        ]
        .map(|n| n.replace("a.", &format!("{}/a.", dir.display())))
        .each_ref()
        .map(String::as_str),
        SHORT_RUN,
    );
    assert!(took < Duration::from_secs(1), "said after {took:?}");
    // The run may create a checkpoint's temporary file in it while it goes: try again.
    while let Err(e) = std::fs::remove_dir_all(&sub) {
        assert_eq!(e.kind(), std::io::ErrorKind::DirectoryNotEmpty, "{e}");
    }
    let took = running.wait_for(&["summary", "its directory is gone"], SHORT_RUN);
    assert!(took < Duration::from_secs(1), "said after {took:?}");
    running.signal(libc::SIGINT);
    let ended = running.wait(SHORT_RUN * 2);
    ended.assert(1, AFTER_SIGNAL);
    ended.says(&[
        "cannot write",
        "s.json",
        "No such file or directory",
        "stdout",
    ]);
    let s: Value = serde_json::from_str(&ended.stdout).expect("the summary on stdout");
    assert_eq!(s["ending"], "interrupted");
    assert_eq!(
        failed_outputs(&s),
        ["checkpoint", "recording", "trajectory"]
    );
    assert_eq!(names(&dir), Vec::<String>::new());
    std::fs::remove_dir_all(&dir).ok();
}

/// Whether this process runs as root (for which permissions do not deny).
fn root() -> bool {
    // SAFETY: geteuid has no preconditions.
    unsafe { libc::geteuid() == 0 }
}

/// How to run the binary so that a directory's permissions deny it: as this user when not root;
/// as root, as `nobody` from a copy of the binary that `nobody` can reach (`None`, with a printed
/// reason, when that cannot be arranged).
fn unprivileged(dir: &Path) -> Option<Under> {
    if !root() {
        return Some(Under::default());
    }
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).ok()?;
    std::fs::set_permissions(&bin, std::fs::Permissions::from_mode(0o755)).ok()?;
    let binary = bin.join("vibrobed");
    std::fs::copy(env!("CARGO_BIN_EXE_vibrobed"), &binary).ok()?;
    let under = Under {
        user: Some((65534, 65534)),
        binary: Some(binary),
        ..Under::default()
    };
    let probe = run(&["--version".to_string()], dir, &under);
    if probe.code != Some(0) {
        eprintln!(
            "SKIPPED: running as root, and the binary cannot be run as nobody (uid 65534) to \
             make permissions deny: {}",
            probe.describe()
        );
        return None;
    }
    Some(under)
}

/// A copy of the bed scenario that any user can read, in `dir`.
fn readable_bed(dir: &Path) -> Vec<String> {
    let copy = dir.join("bed.json");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/vibrated_bed.json"),
        &copy,
    )
    .unwrap();
    let mut args = bed("20");
    args[1] = copy.display().to_string();
    args
}

/// Before the run: a directory the user may not write in is refused naming the option, the
/// file and "Permission denied", told apart from a directory that does not exist; exit 2 and
/// nothing written; `sweep run --out` likewise.
#[test]
fn a_denied_directory_is_refused_before_the_run() {
    let dir = scratch("denied");
    let Some(under) = unprivileged(&dir) else {
        return;
    };
    let denied = dir.join("denied");
    std::fs::create_dir(&denied).unwrap();
    std::fs::set_permissions(&denied, std::fs::Permissions::from_mode(0o555)).unwrap();
    let base = readable_bed(&dir);
    for (flag, file) in [
        ("--summary", "s.json"),
        ("--profiles", "p.csv"),
        ("--fields", "f.vti"),
        ("--rrd", "a.rrd"),
        ("--trajectory", "a.xyz"),
        ("--checkpoint", "a.ckpt"),
    ] {
        let mut args = base.clone();
        args.extend([flag.to_string(), denied.join(file).display().to_string()]);
        let ended = run(&args, &dir, &under);
        ended.assert(2, SHORT_RUN);
        ended.says(&[
            &format!("vibrobed: {flag}: "),
            &denied.join(file).display().to_string(),
            "cannot write in the directory",
            "Permission denied",
        ]);
        let mut args = base.clone();
        args.extend([
            flag.to_string(),
            dir.join("missing").join(file).display().to_string(),
        ]);
        let ended = run(&args, &dir, &under);
        ended.assert(2, SHORT_RUN);
        ended.says(&[&format!("vibrobed: {flag}: "), "does not exist"]);
    }
    let sweep = dir.join("sweep.json");
    std::fs::write(
        &sweep,
        r#"{ "scenario": "bed.json", "set": ["run.duration=1", "run.warmup=0"] }"#,
    )
    .unwrap();
    let args = sweep_run_args(Path::new("sweep.json"), Path::new("denied/out"), &[]);
    let ended = run(&args, &dir, &under);
    ended.assert(2, SHORT_RUN);
    ended.says(&["vibrobed: --out: ", "denied/out", "Permission denied"]);
    assert!(names(&denied).is_empty(), "{:?}", names(&denied));
    std::fs::remove_dir_all(&dir).ok();
}

/// A directory made read-only during the run: the checkpoint that cannot be replaced is a
/// warning (the last one stays whole), and the summary, which cannot be written there at the
/// end, comes on stdout with exit 1.
#[test]
fn a_directory_made_read_only_during_the_run() {
    let dir = scratch("read-only");
    let Some(under) = unprivileged(&dir) else {
        return;
    };
    let out = dir.join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o777)).unwrap();
    let mut args = readable_bed(&dir);
    args[4] = "run.duration=100000".into();
    args.extend([
        "--checkpoint".into(),
        out.join("c.ckpt").display().to_string(),
    ]);
    args.extend(["--checkpoint-every".into(), "1".into()]);
    args.extend(["--summary".into(), out.join("s.json").display().to_string()]);
    let mut running = start(&args, &dir, &under);
    running.wait_for_file(&out.join("c.ckpt"));
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o555)).unwrap();
    running.wait_for(&["cannot write checkpoint", "Permission denied"], SHORT_RUN);
    running.signal(libc::SIGINT);
    let ended = running.wait(SHORT_RUN * 2);
    ended.assert(1, AFTER_SIGNAL);
    ended.says(&[
        "cannot write summary",
        "s.json",
        "Permission denied",
        "stdout",
    ]);
    let s: Value = serde_json::from_str(&ended.stdout).expect("the summary on stdout");
    assert_eq!(s["ending"], "interrupted");
    assert_eq!(failed_outputs(&s), ["checkpoint"]);
    if names(&out) != ["c.ckpt"] {
        // The directory turned read-only between creating the temporary file and renaming it:
        // nobody can remove it then, and the warning says so.
        assert_eq!(names(&out), ["c.ckpt", "c.ckpt.tmp"]);
        ended.says(&["c.ckpt.tmp is left: cannot remove it: Permission denied"]);
    }
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o777)).unwrap();
    let resumed = run(
        &[
            "resume".into(),
            out.join("c.ckpt").display().to_string(),
            "--quiet".into(),
            "--set".into(),
            "run.max_events=1".into(),
        ],
        &dir,
        &under,
    );
    resumed.assert(4, SHORT_RUN); // The checkpoint left is whole (and the event limit ends it).
    std::fs::remove_dir_all(&dir).ok();
}

/// A mounted tmpfs of 256 kB (the checkpoint, about 190 kB with the bed state's coarse fields, and the summary, about 17 kB, fit once the recording and trajectory gave their room back), removed when dropped.
struct Tmpfs(PathBuf);

impl Tmpfs {
    /// Mounts one at `at`, or says why not (a printed reason).
    fn mount(at: &Path) -> Option<Tmpfs> {
        std::fs::create_dir_all(at).ok()?;
        let mounted = Command::new("mount")
            .args(["-t", "tmpfs", "-o", "size=256k", "tmpfs"])
            .arg(at)
            .output();
        match mounted {
            Ok(out) if out.status.success() => Some(Tmpfs(at.to_owned())),
            Ok(out) => {
                eprintln!(
                    "SKIPPED: cannot mount a tmpfs: {}",
                    String::from_utf8_lossy(&out.stderr).trim()
                );
                None
            }
            Err(e) => {
                eprintln!("SKIPPED: cannot run mount: {e}");
                None
            }
        }
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

/// A real full filesystem (a 256 kB tmpfs, where the test may mount one): every output on it,
/// as in the issue. The recording and the trajectory that fill it are dropped and their files
/// removed, which gives the checkpoint (tried again), the summary and the profiles the room they
/// need: exit 3, all three written. Then, with the disk
/// full to the last byte, the profiles and the 2D fields cannot be written but the summary
/// elsewhere is (exit 1).
#[test]
fn a_full_filesystem_keeps_the_summary_and_the_profiles() {
    let dir = scratch("tmpfs");
    let Some(disk) = Tmpfs::mount(&dir.join("disk")) else {
        return;
    };
    let d = disk.0.clone();
    let mut args = bed("20");
    args.extend(output_args(&d, &["checkpoint", "recording", "trajectory"]));
    args.extend(["--summary".into(), d.join("s.json").display().to_string()]);
    args.extend(["--profiles".into(), d.join("p.csv").display().to_string()]);
    let ended = run(&args, &dir, &Under::default());
    ended.assert(3, SHORT_RUN);
    ended.says(&["cannot write recording", "No space left on device"]);
    assert_eq!(
        failed_outputs(&summary(&d.join("s.json"))),
        ["checkpoint", "recording", "trajectory"]
    );
    // A checkpoint (165 kB) may have been written before the disk filled, or again once the
    // recording and the trajectory gave their room back (said on stderr), though not a second
    // one beside it: either way the last one written is there, whole — it resumes. (Which,
    // depends on when the recorder's writes fill the disk.)
    let mut left = names(&d);
    if left.first().map(String::as_str) == Some("a.ckpt") {
        // (A copy off the full disk: a resumed run writes its checkpoint where it read it.)
        let copy = dir.join("copy.ckpt");
        std::fs::copy(d.join("a.ckpt"), &copy).unwrap();
        let resume: Vec<String> = ["resume", &copy.display().to_string(), "--quiet"]
            .map(String::from)
            .to_vec();
        run(&resume, &dir, &Under::default()).assert(0, SHORT_RUN);
        left.remove(0);
    }
    assert_eq!(left, ["p.csv", "s.json"], "{}", ended.describe());

    let filler = std::fs::File::create(d.join("filler")).unwrap();
    let _ = std::io::Write::write_all(&mut &filler, &vec![0u8; 400_000]);
    drop(filler);
    let mut args = bed("20");
    args.extend(["--summary".into(), dir.join("s.json").display().to_string()]);
    args.extend(["--profiles".into(), d.join("q.csv").display().to_string()]);
    args.extend(["--fields".into(), d.join("q.vti").display().to_string()]);
    let ended = run(&args, &dir, &Under::default());
    ended.assert(1, SHORT_RUN);
    let named = |what: &str, file: &str| format!("cannot write {what} {}", d.join(file).display());
    ended.says(&[&named("profiles", "q.csv"), "No space left on device"]);
    ended.says(&[&named("fields", "q.vti"), "No space left on device"]);
    assert_eq!(summary(&dir.join("s.json"))["ending"], "completed");
    assert!(names(&d).ends_with(&["filler", "p.csv", "s.json"].map(String::from)));
    drop(disk);
    std::fs::remove_dir_all(&dir).ok();
}

/// A run killed outright (SIGKILL, no destructor runs) leaves its recording and trajectory under
/// their temporary names only, never under the final ones; the recording decodes message by
/// message as far as it got (what the viewer shows of it).
#[cfg(feature = "record")]
#[test]
fn a_killed_run_leaves_readable_partial_files() {
    use rerun::external::re_log_encoding::DecoderApp;
    let dir = scratch("killed");
    let mut args = bed("100000");
    args.extend(output_args(&dir, &["recording", "trajectory"]));
    let mut running = start(&args, &dir, &Under::default());
    let partial = dir.join("a.rrd.partial");
    running.wait_for_file(&partial);
    let since = Instant::now();
    while std::fs::metadata(&partial).map_or(0, |m| m.len()) < 200_000 {
        assert!(since.elapsed() < SHORT_RUN, "the recording does not grow");
        std::thread::sleep(Duration::from_millis(20));
    }
    running.signal(libc::SIGKILL);
    let ended = running.wait(SHORT_RUN);
    assert_eq!(ended.code, None, "{}", ended.describe());
    assert_eq!(names(&dir), ["a.rrd.partial", "a.xyz.partial"]);
    let reader = std::io::BufReader::new(std::fs::File::open(&partial).unwrap());
    let decoder = DecoderApp::decode_eager(reader).expect("an RRD stream");
    let chunks = decoder.take_while(Result::is_ok).count();
    assert!(chunks > 10, "only {chunks} messages decode");
    std::fs::remove_dir_all(&dir).ok();
}
