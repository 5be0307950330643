//! Cost of recording: the vibrated bed (`scenarios/vibrated_bed.json`, shortened) run with and
//! without an `.rrd` recording, alternately, through `vibrobed::run::run`.
//!
//! ```text
//! cargo bench --bench recording
//! VIBROBED_BENCH_REPS=7 VIBROBED_BENCH_DURATION=100 VIBROBED_BENCH_FRAME_INTERVALS=0.5,0.1,0.02 \
//!     cargo bench --bench recording
//! ```
//!
//! Every run is a fresh process (this executable again, with `VIBROBED_BENCH_CHILD` set), so that
//! its peak memory is its own. For every frame interval it prints (medians over the repetitions):
//! wall seconds of `run()` (set-up, event loop, closing the file), CPU seconds of the process
//! (all threads: Rerun batches, encodes and writes on threads of its own), frames per second of
//! wall time, bytes per frame (file size / frames), the peak resident memory of the process
//! (`VmHWM`) and the slowdown (median wall time recorded / median wall time plain).
//! Environment: `VIBROBED_BENCH_REPS` (default 5), `VIBROBED_BENCH_DURATION` (simulated time,
//! default 100 of the scenario's 200; warm-up a fifth of it), `VIBROBED_BENCH_FRAME_INTERVALS`
//! (default `0.5,0.05`; 0.5 is the scenario's own), `VIBROBED_BENCH_SET` (more scenario
//! overrides, `KEY=VALUE` separated by spaces, e.g. `particles.count=10000 domain.width=2000`
//! for ten times the disks in the same five layers).

use std::path::{Path, PathBuf};
use std::time::Instant;

use vibrobed::output::recording::read_back;
use vibrobed::run::{run, RunOptions};
use vibrobed::Scenario;

fn env_or<T: std::str::FromStr>(key: &str, default: T) -> T {
    std::env::var(key)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// A field of `/proc/self/status` in kB (`VmHWM`, `VmRSS`), if readable.
fn status_kb(field: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with(field))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// User + system CPU seconds of this process (all threads), from `/proc/self/stat`.
fn cpu_seconds() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which is in parentheses and may hold spaces).
    let rest = &text[text.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    // utime and stime are fields 14 and 15 of the whole line, i.e. 11 and 12 after `comm`.
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0) // USER_HZ is 100 on Linux
}

#[derive(Debug, Clone, Copy)]
struct Measured {
    wall: f64,
    cpu: f64,
    peak_kb: u64,
    bytes: u64,
}

/// Runs `s` in this process (the child side) and prints the measurements on stdout.
fn child(s: &Scenario, rrd: Option<&Path>) {
    if let Some(p) = rrd {
        let _ = std::fs::remove_file(p);
    }
    let cpu0 = cpu_seconds().unwrap_or(f64::NAN);
    let start = Instant::now();
    let summary = run(
        s,
        RunOptions {
            rrd: rrd.map(Path::to_path_buf),
            ..RunOptions::default()
        },
    )
    .expect("bench run");
    let wall = start.elapsed().as_secs_f64();
    let cpu = cpu_seconds().unwrap_or(f64::NAN) - cpu0;
    assert_eq!(summary.ending, vibrobed::output::summary::Ending::Completed);
    let bytes = rrd
        .and_then(|p| std::fs::metadata(p).ok())
        .map_or(0, |m| m.len());
    println!("{wall} {cpu} {} {bytes}", status_kb("VmHWM:").unwrap_or(0));
}

/// One run in a fresh process.
fn one_run(sets: &[String], rrd: Option<&Path>) -> Measured {
    let out = std::process::Command::new(std::env::current_exe().expect("own path"))
        .env("VIBROBED_BENCH_CHILD", sets.join("\n"))
        .env(
            "VIBROBED_BENCH_CHILD_RRD",
            rrd.map_or(String::new(), |p| p.display().to_string()),
        )
        .output()
        .expect("child run");
    assert!(
        out.status.success(),
        "child failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let f: Vec<f64> = text
        .split_whitespace()
        .map(|v| v.parse().expect("child output"))
        .collect();
    Measured {
        wall: f[0],
        cpu: f[1],
        peak_kb: f[2] as u64,
        bytes: f[3] as u64,
    }
}

fn scenario(sets: &[String]) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/vibrated_bed.json");
    Scenario::load(&path, sets).expect("scenario loads")
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn main() {
    // `cargo bench` passes `--bench`; a name filter is not supported (there is one benchmark).
    if let Ok(sets) = std::env::var("VIBROBED_BENCH_CHILD") {
        let sets: Vec<String> = sets.lines().map(str::to_owned).collect();
        let rrd = std::env::var("VIBROBED_BENCH_CHILD_RRD").unwrap_or_default();
        child(&scenario(&sets), (!rrd.is_empty()).then(|| Path::new(&rrd)));
        return;
    }
    let reps: usize = env_or("VIBROBED_BENCH_REPS", 5).max(1);
    let duration: f64 = env_or("VIBROBED_BENCH_DURATION", 100.0);
    let intervals: Vec<f64> = std::env::var("VIBROBED_BENCH_FRAME_INTERVALS")
        .unwrap_or_else(|_| "0.5,0.05".into())
        .split(',')
        .filter_map(|v| v.trim().parse().ok())
        .collect();
    let mut sets = vec![
        format!("run.duration={duration}"),
        format!("run.warmup={}", duration / 5.0),
    ];
    if let Ok(more) = std::env::var("VIBROBED_BENCH_SET") {
        sets.extend(more.split_whitespace().map(str::to_owned));
    }
    let dir: PathBuf = std::env::temp_dir().join(format!("vibrobed-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let rrd = dir.join("bench.rrd");

    println!(
        "vibrated bed (scenarios/vibrated_bed.json) {}, {reps} repetitions each, alternating",
        sets.join(" ")
    );
    println!(
        "| frame interval | frames | run | wall s | CPU s | frames/s (wall) | bytes/frame | peak RSS MB | slowdown |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for &dt in &intervals {
        let mut sets = sets.clone();
        sets.push(format!("output.frame_interval={dt}"));
        // Warm the caches (and the page cache of the file) once.
        one_run(&sets, Some(&rrd));
        let (mut plain, mut recorded) = (Vec::new(), Vec::new());
        for _ in 0..reps {
            plain.push(one_run(&sets, None));
            recorded.push(one_run(&sets, Some(&rrd)));
        }
        let c = read_back(&rrd).expect("the recording reads back");
        assert!(c.has_footer);
        let frames = c.disks.len();
        let n = c.disks.first().map_or(0, |d| d.positions.len());
        for (name, runs) in [("plain", &plain), ("--rrd", &recorded)] {
            let wall = median(runs.iter().map(|m| m.wall).collect());
            let cpu = median(runs.iter().map(|m| m.cpu).collect());
            let peak = median(runs.iter().map(|m| m.peak_kb as f64).collect()) / 1024.0;
            let recording = name == "--rrd";
            let bytes = median(runs.iter().map(|m| m.bytes as f64).collect());
            let slowdown = wall / median(plain.iter().map(|m| m.wall).collect());
            println!(
                "| {dt} | {frames} × {n} disks | {name} | {wall:.3} | {cpu:.2} | {} | {} | {peak:.1} | {} |",
                if recording {
                    format!("{:.0}", frames as f64 / wall)
                } else {
                    "–".into()
                },
                if recording {
                    format!("{:.0}", bytes / frames as f64)
                } else {
                    "–".into()
                },
                if recording {
                    format!("{slowdown:.3}")
                } else {
                    "1".into()
                },
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
