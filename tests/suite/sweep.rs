//! `vibrobed sweep`, end to end on the real binary: a small sweep run locally (resumable, the same
//! results on one worker as on two), collected into its tables, the same sweep as a Slurm job
//! array on a Slurm cluster (ignored unless asked for: `.ci/run` starts a one-node cluster with
//! `tests/slurm/cluster.sh start` and runs it), and bad sweep files rejected with exit 2 and the culprit named.

use crate::common::svg;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// A small vibrated bed: 60 disks, 4 time units (a fraction of a second per run).
const BED: &str = r#"{
  "name": "small vibrated bed",
  "seed": 3,
  "domain": { "width": 12.0, "x_boundary": "periodic", "y_boundary": "open" },
  "gravity": 1.0,
  "floor": { "gamma": 3.0, "frequency": 0.5, "restitution": 0.9 },
  "particles": { "count": 60, "radius": 0.5, "temperature": 0.5 },
  "collisions": { "restitution": 0.9 },
  "run": { "duration": 4.0, "warmup": 1.0 },
  "output": { "sample_interval": 0.1, "profile_bins": 10, "profile_height": 10.0 }
}"#;

/// Two points of the floor's Γ, two seeds each: four runs. The scenario path is relative to
/// the sweep file.
const SWEEP: &str = r#"{
  "name": "small",
  "scenario": "bed.json",
  "set": ["run.duration=3"],
  "axes": [{ "key": "floor.gamma", "values": [2.5, 4.0] }],
  "seeds": [5, 6]
}"#;

/// Fields that depend on the wall clock.
const TIMING: [&str; 2] = ["wall_seconds", "collisions_per_second"];

/// A fresh, empty scratch directory for one test, holding the bed and the sweep file.
fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("sweep-{test}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    std::fs::write(dir.join("bed.json"), BED).expect("write the scenario");
    std::fs::write(dir.join("small.json"), SWEEP).expect("write the sweep");
    dir
}

fn vibrobed<S: AsRef<std::ffi::OsStr>>(dir: &Path, args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vibrobed"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the vibrobed binary starts")
}

fn describe(out: &Output) -> String {
    format!(
        "exit {:?}\n--- stdout ---\n{}\n--- stderr ---\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

fn assert_ok(out: &Output) {
    assert_eq!(out.status.code(), Some(0), "{}", describe(out));
}

fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Run i's summary without its wall-clock fields.
fn summary_sans_timing(out: &Path, i: usize) -> Value {
    let mut s = read_json(&out.join(i.to_string()).join("summary.json"));
    for k in TIMING {
        assert!(s.get(k).is_some(), "run {i} lacks {k}");
        s.as_object_mut().unwrap().remove(k);
    }
    s
}

/// Asserts two sweep outputs hold the same summaries for runs 0..n, timing aside.
fn assert_same_results(a: &Path, b: &Path, n: usize) {
    for i in 0..n {
        let (sa, sb) = (summary_sans_timing(a, i), summary_sans_timing(b, i));
        assert_eq!(
            sa,
            sb,
            "run {i} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}

/// A CSV file as a header and rows (the sweep's cells here hold no quotes).
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).expect("csv");
    let mut lines = text
        .lines()
        .map(|l| l.split(',').map(String::from).collect());
    let header = lines.next().expect("a header");
    (header, lines.collect())
}

#[test]
fn local_sweep_is_resumable_and_the_same_on_one_or_two_workers() {
    let dir = scratch("local");
    let out = vibrobed(&dir, &["sweep", "plan", "small.json", "--out", "two"]);
    assert_ok(&out);
    let listing = String::from_utf8_lossy(&out.stdout);
    assert!(listing.contains("4 runs (2 points × 2 seeds)"), "{listing}");
    assert!(
        listing.contains("3\t1\t6\tfloor.gamma=4.0\ttwo/3"),
        "{listing}"
    );

    // Two workers.
    assert_ok(&vibrobed(
        &dir,
        &["sweep", "run", "small.json", "--out", "two", "--jobs", "2"],
    ));
    let two = dir.join("two");
    let plan = read_json(&two.join("plan.json"));
    assert_eq!(plan["runs"].as_array().unwrap().len(), 4);
    for i in 0..4 {
        let run = two.join(i.to_string());
        let s = read_json(&run.join("summary.json"));
        assert_eq!(s["ending"], "completed", "run {i}");
        assert_eq!(s["seed"], [5, 6][i % 2], "run {i}");
        assert_eq!(s["sim_time"], 3.0, "the sweep's fixed override holds");
        assert!(run.join("profiles.csv").exists(), "run {i} has profiles");
    }
    let t0 = read_json(&two.join("0/summary.json"))["temperature"]["mean"].clone();
    let t2 = read_json(&two.join("2/summary.json"))["temperature"]["mean"].clone();
    assert_ne!(t0, t2, "points 0 and 1 differ in Γ, so in temperature");

    // Resume: a completed run is kept (marked to tell), a missing and an interrupted one redone.
    let marked = two.join("0/summary.json");
    let mut s0 = read_json(&marked);
    s0["marker"] = Value::from("kept");
    std::fs::write(&marked, serde_json::to_string_pretty(&s0).unwrap()).unwrap();
    std::fs::remove_file(two.join("1/summary.json")).unwrap();
    let path2 = two.join("2/summary.json");
    let text2 = std::fs::read_to_string(&path2).unwrap();
    std::fs::write(
        &path2,
        text2.replace("\"ending\": \"completed\"", "\"ending\": \"interrupted\""),
    )
    .unwrap();
    let out = vibrobed(
        &dir,
        &["sweep", "run", "small.json", "--out", "two", "-j", "2"],
    );
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("2 ran now, 2 done before"),
        "{}",
        describe(&out)
    );
    assert_eq!(read_json(&marked)["marker"], "kept", "run 0 was skipped");
    assert_eq!(read_json(&path2)["ending"], "completed", "run 2 was redone");
    s0.as_object_mut().unwrap().remove("marker");
    std::fs::write(&marked, serde_json::to_string_pretty(&s0).unwrap()).unwrap();

    // One worker: the same results.
    assert_ok(&vibrobed(
        &dir,
        &[
            "sweep",
            "run",
            "small.json",
            "--out",
            "one",
            "--jobs",
            "1",
            "--quiet",
        ],
    ));
    assert_same_results(&two, &dir.join("one"), 4);

    // One run as a Slurm task would run it: the same result again.
    assert_ok(&vibrobed(
        &dir,
        &[
            "sweep",
            "task",
            "small.json",
            "--index",
            "3",
            "--out",
            "task",
        ],
    ));
    assert_eq!(
        summary_sans_timing(&two, 3),
        summary_sans_timing(&dir.join("task"), 3)
    );

    // Collect: one row per run, one per point, means over the seeds.
    let out = vibrobed(
        &dir,
        &[
            "sweep",
            "collect",
            "two",
            "--x",
            "drive.peak_velocity",
            "--y",
            "temperature.mean",
            "--y",
            "com_height",
            "--fit",
            "power",
        ],
    );
    assert_ok(&out);
    assert!(String::from_utf8_lossy(&out.stdout)
        .contains("temperature.mean = c·(drive.peak_velocity)^δ: δ = "));
    let (header, rows) = read_csv(&two.join("runs.csv"));
    assert_eq!(rows.len(), 4);
    for col in [
        "index",
        "point",
        "seed",
        "ending",
        "floor.gamma",
        "drive.peak_velocity",
        "temperature.mean",
        "com_height",
        "events.pair",
        "wall_seconds",
    ] {
        assert!(
            header.iter().any(|h| h == col),
            "runs.csv lacks {col}: {header:?}"
        );
    }
    let (header, rows) = read_csv(&two.join("points.csv"));
    assert_eq!(rows.len(), 2);
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("points.csv lacks {name}"))
    };
    let mean_t: f64 = rows[1][col("temperature.mean:mean")].parse().unwrap();
    let expect = (read_json(&two.join("2/summary.json"))["temperature"]["mean"]
        .as_f64()
        .unwrap()
        + read_json(&two.join("3/summary.json"))["temperature"]["mean"]
            .as_f64()
            .unwrap())
        / 2.0;
    assert!(
        (mean_t - expect).abs() <= 1e-12 * expect,
        "{mean_t} vs {expect}"
    );
    assert_eq!(rows[1][col("temperature.mean:n")], "2");
    assert_eq!(rows[1][col("floor.gamma")], "4.0");
    assert!(!rows[1][col("temperature.mean:se")].is_empty());
    // A Slurm script for what is left: only the runs not completed.
    std::fs::remove_file(two.join("1/summary.json")).unwrap();
    let out = vibrobed(
        &dir,
        &[
            "sweep",
            "slurm",
            "small.json",
            "--out",
            "two",
            "--time",
            "00:05:00",
        ],
    );
    assert_ok(&out);
    let script = std::fs::read_to_string(two.join("sweep.sbatch")).unwrap();
    assert!(script.contains("#SBATCH --array=1\n"), "{script}");
    assert!(script.contains("#SBATCH --signal=B:INT@60\n"), "{script}");
    assert!(script.contains("#SBATCH --cpus-per-task=1\n"), "{script}");
    assert!(
        script.contains("--index \"$SLURM_ARRAY_TASK_ID\""),
        "{script}"
    );
    // A folder holds one sweep.
    std::fs::write(
        dir.join("other.json"),
        SWEEP.replace("[2.5, 4.0]", "[2.5, 5.0]"),
    )
    .unwrap();
    let out = vibrobed(&dir, &["sweep", "run", "other.json", "--out", "two"]);
    assert_eq!(out.status.code(), Some(2), "{}", describe(&out));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--out: "),
        "{}",
        describe(&out)
    );
    let svg = std::fs::read_to_string(two.join("plot.svg")).expect("the plot");
    assert!(svg.starts_with("<svg") && svg.contains("temperature.mean"));
    svg::check(&svg, 2);
    assert!(two.join("fit.json").exists());
}

/// A sweep of a threaded scheme shares the cores: on K jobs each run gets cores / K threads
/// (the summaries say how many), with the same results as one job on all cores; a Slurm array
/// asks for the cores `engine.threads` gives each task.
#[test]
fn threaded_runs_share_the_cores() {
    let dir = scratch("threads");
    let threaded = SWEEP.replace(
        r#""set": ["run.duration=3"]"#,
        r#""set": ["run.duration=3", "engine.scheme=time-step"]"#,
    );
    std::fs::write(dir.join("threaded.json"), &threaded).unwrap();
    let cores = vibrobed::schemes::cores::available();
    let mut results = Vec::new();
    for jobs in [1, 2] {
        let out_dir = format!("jobs{jobs}");
        let args = ["sweep", "run", "threaded.json", "--out", &out_dir, "--jobs"];
        let out = vibrobed(&dir, &[&args[..], &[&jobs.to_string(), "--quiet"]].concat());
        assert_ok(&out);
        let mut runs = Vec::new();
        for i in 0..4 {
            let mut s = read_json(&dir.join(&out_dir).join(format!("{i}/summary.json")));
            let threads = s["engine"].as_object_mut().unwrap().remove("threads");
            assert_eq!(threads, Some(Value::from((cores / jobs).max(1))), "run {i}");
            for field in TIMING {
                s.as_object_mut().unwrap().remove(field);
            }
            runs.push(s);
        }
        results.push(runs);
    }
    assert_eq!(
        results[0], results[1],
        "one job on all cores and two sharing them"
    );
    let with_threads = threaded.replace(
        r#""engine.scheme=time-step"]"#,
        r#""engine.scheme=time-step", "engine.threads=3"]"#,
    );
    std::fs::write(dir.join("threaded.json"), with_threads).unwrap();
    let out = vibrobed(&dir, &["sweep", "slurm", "threaded.json", "--out", "array"]);
    assert_ok(&out);
    let script = std::fs::read_to_string(dir.join("array/sweep.sbatch")).unwrap();
    assert!(script.contains("#SBATCH --cpus-per-task=3\n"), "{script}");
}

/// SLURM_CONF for the client commands: the environment's, else the test cluster's default
/// (`tests/slurm/cluster.sh`).
fn slurm_conf() -> Option<PathBuf> {
    if let Some(conf) = std::env::var_os("SLURM_CONF") {
        return Some(conf.into());
    }
    let tmp = std::env::var_os("TMPDIR").map_or(PathBuf::from("/tmp"), PathBuf::from);
    let conf = tmp.join("vibrobed-slurm").join("slurm.conf");
    conf.exists().then_some(conf)
}

fn slurm_command(program: &str, conf: &Option<PathBuf>) -> Command {
    let mut c = Command::new(program);
    if let Some(conf) = conf {
        c.env("SLURM_CONF", conf);
    }
    c
}

/// Why Slurm cannot be used here, if it cannot.
fn slurm_unreachable(conf: &Option<PathBuf>) -> Option<String> {
    match slurm_command("sinfo", conf)
        .args(["-h", "-o", "%T"])
        .output()
    {
        Err(e) => Some(format!(
            "sinfo cannot run ({e}); start a cluster with tests/slurm/cluster.sh start"
        )),
        Ok(o) if !o.status.success() => Some(format!(
            "sinfo failed: {}",
            String::from_utf8_lossy(&o.stderr).trim()
        )),
        Ok(o) => {
            let states = String::from_utf8_lossy(&o.stdout);
            (!states.lines().any(|s| {
                ["idle", "mixed", "allocated", "completing"].contains(&s.trim_end_matches('*'))
            }))
            .then(|| format!("no Slurm node is up (sinfo says: {:?})", states.trim()))
        }
    }
}

#[test]
#[ignore = "needs a Slurm cluster (tests/slurm/cluster.sh start, SLURM_CONF); .ci/run runs it"]
fn slurm_job_array_gives_the_local_results() {
    let conf = slurm_conf();
    if let Some(reason) = slurm_unreachable(&conf) {
        panic!("Slurm is not reachable: {reason}");
    }
    let dir = scratch("slurm");
    assert_ok(&vibrobed(
        &dir,
        &["sweep", "run", "small.json", "--out", "local", "-q"],
    ));

    let mut submit = Command::new(env!("CARGO_BIN_EXE_vibrobed"));
    submit.current_dir(&dir).args([
        "sweep",
        "slurm",
        "small.json",
        "--out",
        "cluster",
        "--array-max",
        "2",
        "--time",
        "00:10:00",
        "--submit",
    ]);
    if let Some(conf) = &conf {
        submit.env("SLURM_CONF", conf);
    }
    let out = submit.output().expect("vibrobed starts");
    assert_ok(&out);
    let job = String::from_utf8_lossy(&out.stdout).trim().to_string();
    assert!(
        !job.is_empty() && job.chars().all(|c| c.is_ascii_digit()),
        "job id: {job:?}"
    );
    let cluster = dir.join("cluster");
    let script = std::fs::read_to_string(cluster.join("sweep.sbatch")).unwrap();
    assert!(script.contains("#SBATCH --array=0-3%2\n"), "{script}");
    assert!(script.contains(" sweep task "), "{script}");

    // Wait for the array: every run's summary, or the job gone without them, or 5 minutes.
    let done = |i: usize| {
        std::fs::read_to_string(cluster.join(i.to_string()).join("summary.json"))
            .is_ok_and(|t| t.contains("\"ending\": \"completed\""))
    };
    let start = Instant::now();
    let mut gone_since: Option<Instant> = None;
    loop {
        if (0..4).all(done) {
            break;
        }
        let queued = slurm_command("squeue", &conf)
            .args(["-h", "-j", &job])
            .output()
            .map(|o| !String::from_utf8_lossy(&o.stdout).trim().is_empty())
            .unwrap_or(false);
        let logs = || {
            std::fs::read_dir(cluster.join("slurm"))
                .map(|d| {
                    d.flatten()
                        .map(|e| {
                            format!(
                                "{}:\n{}",
                                e.path().display(),
                                std::fs::read_to_string(e.path()).unwrap_or_default()
                            )
                        })
                        .collect::<Vec<_>>()
                        .join("\n")
                })
                .unwrap_or_default()
        };
        if !queued {
            let since = *gone_since.get_or_insert_with(Instant::now);
            assert!(
                since.elapsed() < Duration::from_secs(10),
                "job {job} left the queue without all summaries; task logs:\n{}",
                logs()
            );
        }
        if start.elapsed() > Duration::from_secs(300) {
            let _ = slurm_command("scancel", &conf).arg(&job).status();
            panic!(
                "job {job} did not finish in 5 minutes; task logs:\n{}",
                logs()
            );
        }
        std::thread::sleep(Duration::from_millis(500));
    }
    assert_same_results(&dir.join("local"), &cluster, 4);
    let out = vibrobed(&dir, &["sweep", "collect", "cluster"]);
    assert_ok(&out);
    let (_, rows) = read_csv(&cluster.join("runs.csv"));
    assert_eq!(rows.len(), 4);
    assert!(rows.iter().all(|r| r[3] == "completed"), "{rows:?}");
}

/// Writes a sweep file into `dir` and runs `sweep plan` on it.
fn plan_of(dir: &Path, sweep: &str) -> Output {
    std::fs::write(dir.join("bad.json"), sweep).unwrap();
    vibrobed(dir, &["sweep", "plan", "bad.json"])
}

/// Asserts exit 2 with a message containing each of `parts`.
fn assert_bad(out: &Output, parts: &[&str]) {
    assert_eq!(out.status.code(), Some(2), "{}", describe(out));
    let err = String::from_utf8_lossy(&out.stderr);
    for p in parts {
        assert!(err.contains(p), "message lacks `{p}`: {}", describe(out));
    }
}

#[test]
fn bad_sweep_inputs_exit_2_naming_the_culprit() {
    let dir = scratch("bad");
    assert_bad(
        &plan_of(&dir, r#"{"scenario": "bed.json", "axis": []}"#),
        &["axis: unknown field `axis`"],
    );
    assert_bad(
        &plan_of(
            &dir,
            r#"{"scenario": "bed.json", "axes": [{"key": "floor.gama", "values": [1]}]}"#,
        ),
        &["point 0 (floor.gama=1)", "floor", "unknown field `gama`"],
    );
    assert_bad(
        &plan_of(
            &dir,
            r#"{"scenario": "bed.json", "axes": [{"key": "floor.gamma", "values": [2, -1]}], "seeds": 2}"#,
        ),
        &["point 1 (floor.gamma=-1): floor.gamma"],
    );
    assert_bad(
        &plan_of(
            &dir,
            r#"{"scenario": "bed.json", "axes": [{"key": "floor.gamma", "range": {"from": 1, "to": 2, "count": 0}}]}"#,
        ),
        &["axes[0].range.count: must lie in [1, 100000]"],
    );
    assert_bad(
        &plan_of(
            &dir,
            r#"{"scenario": "bed.json", "axes": [{"key": "floor.gamma", "range": {"from": 0, "to": 2, "count": 3, "scale": "log"}}]}"#,
        ),
        &["axes[0].range.from: a log range needs positive bounds"],
    );
    assert_bad(
        &plan_of(
            &dir,
            r#"{"scenario": "bed.json", "axes": [{"key": "floor.gamma", "range": {"from": 1, "to": 2, "count": 3, "step": 1}}]}"#,
        ),
        &["axes[0].range", "unknown field `step`"],
    );
    assert_bad(
        &plan_of(&dir, r#"{"scenario": "bed.json", "seeds": 0}"#),
        &["seeds: must lie in [1, 100000]"],
    );
    // Sizes that cannot be planned in memory are refused before anything is expanded.
    assert_bad(
        &plan_of(
            &dir,
            r#"{"scenario": "bed.json", "seeds": 18446744073709551615}"#,
        ),
        &["seeds: must lie in [1, 100000]"],
    );
    assert_bad(
        &plan_of(
            &dir,
            r#"{"scenario": "bed.json", "axes": [{"key": "floor.gamma", "range": {"from": 1, "to": 2, "count": 1000}},
                {"key": "floor.frequency", "range": {"from": 1, "to": 2, "count": 1000}}]}"#,
        ),
        &["axes: every combination of the axes makes more than 100000 points"],
    );
    assert_bad(
        &plan_of(
            &dir,
            r#"{"scenario": "bed.json", "axes": [{"key": "floor.gamma", "range": {"from": 1, "to": 2, "count": 1000}}], "seeds": 1000}"#,
        ),
        &["seeds: 1000 points × 1000 seeds make more than 100000 runs"],
    );
    assert_bad(
        &plan_of(&dir, r#"{"scenario": "missing.json"}"#),
        &["scenario: cannot read"],
    );

    // A bad point stops `sweep run` before anything runs or is written.
    std::fs::write(
        dir.join("bad.json"),
        r#"{"scenario": "bed.json", "axes": [{"key": "particles.count", "values": [10, 0]}]}"#,
    )
    .unwrap();
    let out = vibrobed(&dir, &["sweep", "run", "bad.json", "--out", "never"]);
    assert_bad(&out, &["point 1 (particles.count=0): particles.count"]);
    assert!(
        !dir.join("never").exists(),
        "nothing is written for a bad sweep"
    );

    assert_bad(
        &vibrobed(
            &dir,
            &["sweep", "run", "small.json", "--out", "x", "--jobs", "0"],
        ),
        &["--jobs: must be at least 1"],
    );
    assert_bad(
        &vibrobed(
            &dir,
            &["sweep", "task", "small.json", "--index", "4", "--out", "x"],
        ),
        &["--index: the sweep has 4 runs (0 to 3)"],
    );
    assert_bad(
        &vibrobed(
            &dir,
            &["sweep", "slurm", "small.json", "--out", "x", "--time", "1h"],
        ),
        &["--time: `1h` is not a Slurm time limit"],
    );
    assert_bad(
        &vibrobed(&dir, &["sweep", "collect", "nowhere"]),
        &["DIR: cannot read", "plan.json"],
    );
}

#[test]
fn the_shipped_sweeps_plan() {
    for (file, runs) in [
        ("temperature_vs_drive", "21 runs (7 points × 3 seeds)"),
        ("phase_diagram", "24 runs (24 points × 1 seed)"),
        ("beverloo", "18 runs (6 points × 3 seeds)"),
    ] {
        let path = format!("scenarios/sweeps/{file}.json");
        let out = vibrobed(
            Path::new(env!("CARGO_MANIFEST_DIR")),
            &["sweep", "plan", &path],
        );
        assert_ok(&out);
        let listing = String::from_utf8_lossy(&out.stdout);
        assert!(listing.contains(runs), "{file}: {listing}");
    }
}

/// `"record": true` records each run into its folder, through a temporary name.
#[cfg(feature = "record")]
#[test]
fn a_recording_sweep_records_every_run() {
    let dir = scratch("record");
    std::fs::write(
        dir.join("rec.json"),
        r#"{"scenario": "bed.json", "set": ["run.duration=1", "run.warmup=0"], "seeds": 2, "record": true}"#,
    )
    .unwrap();
    assert_ok(&vibrobed(
        &dir,
        &["sweep", "run", "rec.json", "--out", "rec", "-q"],
    ));
    for i in 0..2 {
        let run = dir.join("rec").join(i.to_string());
        let size = std::fs::metadata(run.join("recording.rrd")).map_or(0, |m| m.len());
        assert!(size > 0, "run {i} has a recording");
        let leftovers: Vec<_> = std::fs::read_dir(&run)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains("partial"))
            .collect();
        assert!(leftovers.is_empty(), "run {i} left {leftovers:?}");
    }
}

/// Without the recording feature, a sweep that asks for recordings is refused before it runs.
#[cfg(not(feature = "record"))]
#[test]
fn a_recording_sweep_needs_the_record_feature() {
    let dir = scratch("record");
    std::fs::write(
        dir.join("rec.json"),
        r#"{"scenario": "bed.json", "record": true}"#,
    )
    .unwrap();
    assert_bad(
        &vibrobed(&dir, &["sweep", "run", "rec.json", "--out", "rec"]),
        &["record: this build of vibrobed has no recording"],
    );
    assert!(!dir.join("rec").exists());
}

/// Summaries are read back (a sweep's resume and tables): JSON floats must parse to the value
/// written, bit for bit. This one (a run's energy balance error) came back one unit in the
/// last place off with serde_json's default parser, which is not correctly rounded.
#[test]
fn json_floats_read_back_bit_for_bit() {
    for text in [
        "7.083831250870836e-16",
        "1.0000000000000013",
        "2.0446465522847452",
    ] {
        let parsed: f64 = serde_json::from_str(text).unwrap();
        assert_eq!(parsed, text.parse::<f64>().unwrap(), "{text}");
        assert_eq!(serde_json::to_string(&parsed).unwrap(), text);
    }
}

/// `sweep collect --states X Y`: each point's bed state (the most frequent over its seeds) in
/// points.csv and as a phase diagram with one marker per point and a legend naming the states.
#[test]
fn a_sweep_over_two_axes_draws_the_states() {
    let dir = scratch("states");
    let sweep = r#"{
      "name": "states",
      "scenario": "bed.json",
      "set": ["run.duration=12", "run.warmup=4"],
      "axes": [
        { "key": "floor.gamma", "values": [1.5, 8.0] },
        { "key": "particles.count", "values": [20, 60] }
      ],
      "seeds": [5, 6]
    }"#;
    std::fs::write(dir.join("states.json"), sweep).unwrap();
    assert_ok(&vibrobed(
        &dir,
        &["sweep", "run", "states.json", "--out", "out", "--jobs", "2"],
    ));
    let out = dir.join("out");
    // A bad axis is refused before anything is drawn ...
    let bad = vibrobed(
        &dir,
        &[
            "sweep",
            "collect",
            "out",
            "--states",
            "floor.gamma",
            "nothing",
        ],
    );
    assert_eq!(bad.status.code(), Some(2), "{}", describe(&bad));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--states"));
    // ... nor are the tables written (they once were, before the exit 2: issue 62).
    for table in ["runs.csv", "points.csv", "states.svg"] {
        assert!(
            !out.join(table).exists(),
            "{table} written by a refused collect"
        );
    }
    assert_ok(&vibrobed(
        &dir,
        &[
            "sweep",
            "collect",
            "out",
            "--states",
            "floor.gamma",
            "particles.count",
        ],
    ));
    // Every run carries its state; each point's is the most frequent of its two runs'.
    let (header, rows) = read_csv(&out.join("runs.csv"));
    let name = header.iter().position(|h| h == "state.name").unwrap();
    let point = header.iter().position(|h| h == "point").unwrap();
    let (pheader, points) = read_csv(&out.join("points.csv"));
    let (state, n) = (
        pheader.iter().position(|h| h == "state").unwrap(),
        pheader.iter().position(|h| h == "state:n").unwrap(),
    );
    assert_eq!(points.len(), 4);
    let mut names = Vec::new();
    for (p, row) in points.iter().enumerate() {
        let runs: Vec<&str> = rows
            .iter()
            .filter(|r| r[point] == p.to_string())
            .map(|r| r[name].as_str())
            .collect();
        assert_eq!(runs.len(), 2);
        let agree = runs.iter().filter(|s| **s == row[state]).count();
        assert_eq!(row[n], agree.to_string(), "point {p}: {runs:?}");
        assert!(agree == 2 || runs[0] == row[state], "point {p}: {runs:?}");
        names.push(row[state].clone());
    }
    let svg = std::fs::read_to_string(out.join("states.svg")).expect("the map");
    let fig = svg::parse(&svg);
    let texts: Vec<&str> = fig.texts.iter().map(|t| t.content.trim()).collect();
    for s in &names {
        assert!(texts.contains(&s.as_str()), "legend lacks {s}: {texts:?}");
    }
    assert!(texts.contains(&"particles.count (count)"), "{texts:?}");
    assert!(texts.contains(&"floor.gamma (dimensionless)"), "{texts:?}");
}

/// A two-axis sweep (Γ × depth, two seeds), as a study of T against Aω for two depths meets it:
/// collected against x without `--by` it is refused (exit 2, naming the other axis) rather than
/// pooled into one fit; `--by particles.count` gives a series and a fit per depth, with the
/// exponent's error from the seeds beside the scatter's, a legend naming each series, and fits
/// over an x range and of y − y₀; two sweep folders are overlaid in one plot.
#[test]
fn a_two_axis_sweep_is_grouped_and_fitted_per_group() {
    let dir = scratch("groups");
    let sweep = r#"{
      "name": "depths",
      "scenario": "bed.json",
      "set": ["run.duration=3"],
      "axes": [
        { "key": "floor.gamma", "values": [2.5, 4.0, 6.0] },
        { "key": "particles.count", "values": [30, 60] }
      ],
      "seeds": [5, 6]
    }"#;
    std::fs::write(dir.join("depths.json"), sweep).unwrap();
    assert_ok(&vibrobed(
        &dir,
        &["sweep", "run", "depths.json", "--out", "out", "--jobs", "2"],
    ));
    let collect = |extra: &[&str]| {
        let mut args = vec![
            "sweep",
            "collect",
            "out",
            "--x",
            "drive.peak_velocity",
            "--y",
            "temperature.mean",
            "--fit",
            "power",
        ];
        args.extend(extra);
        vibrobed(&dir, &args)
    };
    let pooled = collect(&[]);
    assert_eq!(pooled.status.code(), Some(2), "{}", describe(&pooled));
    let err = String::from_utf8_lossy(&pooled.stderr).into_owned();
    assert!(
        err.contains(
            "--by: the axis particles.count also varies (30, 60) at one drive.peak_velocity"
        ),
        "{err}"
    );
    assert!(!dir.join("out/fit.json").exists(), "nothing written");

    let grouped = collect(&["--by", "particles.count"]);
    assert_ok(&grouped);
    let text = String::from_utf8_lossy(&grouped.stdout).into_owned();
    for depth in ["30", "60"] {
        let line =
            format!("temperature.mean [particles.count={depth}] = c·(drive.peak_velocity)^δ");
        assert!(text.contains(&line), "{text}");
    }
    assert!(
        text.contains("(scatter)") && text.contains("(seeds)"),
        "{text}"
    );
    let fits = read_json(&dir.join("out/fit.json"));
    let fits = fits["power_law"].as_array().unwrap();
    assert_eq!(fits.len(), 2);
    for f in fits {
        assert_eq!(f["fit"]["points"], 3, "{f}");
        assert!(f["fit"]["exponent_seed_se"].as_f64().unwrap() > 0.0, "{f}");
    }
    assert_ne!(fits[0]["fit"]["exponent"], fits[1]["fit"]["exponent"]);
    let svg = std::fs::read_to_string(dir.join("out/plot.svg")).unwrap();
    let fig = svg::parse(&svg);
    let texts: Vec<&str> = fig.texts.iter().map(|t| t.content.trim()).collect();
    for label in ["particles.count=30", "particles.count=60"] {
        assert!(texts.contains(&label), "legend lacks {label}: {texts:?}");
    }

    // An x range keeps two of the three points; a given offset is taken off y.
    let ranged = collect(&[
        "--by",
        "particles.count",
        "--fit-range",
        "0.0",
        "1.5",
        "--offset",
        "0.01",
    ]);
    assert_ok(&ranged);
    let fits = read_json(&dir.join("out/fit.json"));
    for f in fits["power_law"].as_array().unwrap() {
        assert_eq!(f["fit"]["points"], 2, "{f}");
        assert_eq!(f["fit"]["offset"], 0.01, "{f}");
    }
    let vs: Vec<f64> = (0..6)
        .map(|p| {
            let (header, rows) = read_csv(&dir.join("out/points.csv"));
            let col = header
                .iter()
                .position(|h| h == "drive.peak_velocity")
                .unwrap();
            rows[p][col].parse().unwrap()
        })
        .collect();
    assert_eq!(vs.iter().filter(|v| **v <= 1.5).count(), 4, "{vs:?}");

    // Two folders overlaid: the same sweep run again into another folder, a series each.
    assert_ok(&vibrobed(
        &dir,
        &[
            "sweep",
            "run",
            "depths.json",
            "--out",
            "again",
            "--jobs",
            "2",
        ],
    ));
    let both = vibrobed(
        &dir,
        &[
            "sweep",
            "collect",
            "out",
            "again",
            "--x",
            "floor.gamma",
            "--y",
            "com_height",
            "--by",
            "particles.count",
            "--plot",
            "both.svg",
        ],
    );
    assert_ok(&both);
    let svg = std::fs::read_to_string(dir.join("both.svg")).unwrap();
    let fig = svg::parse(&svg);
    let texts: Vec<&str> = fig.texts.iter().map(|t| t.content.trim()).collect();
    for label in ["out: particles.count=30", "again: particles.count=60"] {
        assert!(texts.contains(&label), "legend lacks {label}: {texts:?}");
    }
    assert!(dir.join("again/points.csv").exists());
}

/// A sweep whose first point ends at its event limit before its warm-up (the shipped bed's
/// Γ = 0.8 at a small `run.max_events`): its runs leave the measurements out of runs.csv (empty,
/// not 0), and `sweep collect` names the point, how its runs ended, and the fit it left out.
#[test]
fn incomplete_points_are_named_with_the_fits_they_left_out() {
    let dir = scratch("incomplete");
    let sweep = r#"{
      "name": "early",
      "scenario": "bed.json",
      "set": ["run.duration=3"],
      "combine": "zip",
      "axes": [
        { "key": "floor.gamma", "values": [0.8, 2.5, 4.0] },
        { "key": "run.max_events", "values": [100, 100000000, 100000000] }
      ],
      "seeds": [5, 6]
    }"#;
    std::fs::write(dir.join("early.json"), sweep).unwrap();
    let ran = vibrobed(&dir, &["sweep", "run", "early.json", "--out", "out"]);
    // Runs stopped by their event limit leave the sweep incomplete: it exits as they do (4).
    assert_eq!(ran.status.code(), Some(4), "{}", describe(&ran));
    let err = String::from_utf8_lossy(&ran.stderr).into_owned();
    assert!(
        err.contains("run 0 stopped by the event limit (run.max_events)"),
        "{err}"
    );
    // A rerun skips them (it would only repeat them) and still exits 4, naming them.
    let again = vibrobed(&dir, &["sweep", "run", "early.json", "--out", "out"]);
    assert_eq!(again.status.code(), Some(4), "{}", describe(&again));
    assert!(
        String::from_utf8_lossy(&again.stderr)
            .contains("6 done before (of them stopped by the event limit: run 0, 1)"),
        "{}",
        describe(&again)
    );
    // So does the Slurm task of such a run; one of a completed run exits 0.
    let task = |i: &str| {
        vibrobed(
            &dir,
            &["sweep", "task", "early.json", "--index", i, "--out", "out"],
        )
    };
    let limited = task("1");
    assert_eq!(limited.status.code(), Some(4), "{}", describe(&limited));
    assert!(String::from_utf8_lossy(&limited.stderr)
        .contains("run 1: already ran, stopped by the event limit"));
    assert_ok(&task("2"));
    let out = vibrobed(
        &dir,
        &[
            "sweep",
            "collect",
            "out",
            "--x",
            "floor.gamma",
            "--y",
            "temperature.mean",
            "--fit",
            "power",
        ],
    );
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        err.contains(
            "point 0 (floor.gamma=0.8, run.max_events=100): 0 of 2 runs completed (2 event-limit)"
        ),
        "{err}"
    );
    assert!(
        err.contains("temperature.mean: the fit leaves out point 0 (floor.gamma=0.8"),
        "{err}"
    );
    let (header, rows) = read_csv(&dir.join("out/runs.csv"));
    let t = header.iter().position(|h| h == "temperature.mean").unwrap();
    assert_eq!(rows[0][t], "", "no temperature measured: {:?}", rows[0]);
    assert!(!rows[2][t].is_empty());
}

/// `sweep run --max-run-seconds` ends each run at that wall time (`wall-limit`, the summary
/// kept) and says so; off a terminal each run prints its progress lines, named.
#[test]
fn a_sweep_bounds_the_wall_time_of_each_run() {
    let dir = scratch("max-run-seconds");
    let long = SWEEP.replace("run.duration=3", "run.duration=100000");
    std::fs::write(dir.join("long.json"), long).unwrap();
    let out = vibrobed(
        &dir,
        &[
            "sweep",
            "run",
            "long.json",
            "--out",
            "out",
            "--jobs",
            "2",
            "--max-run-seconds",
            "0.6",
            "--progress-every",
            "0.2",
        ],
    );
    // Runs stopped by their wall-clock limit leave the sweep incomplete: it exits 5.
    assert_eq!(out.status.code(), Some(5), "{}", describe(&out));
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    for i in 0..4 {
        let s = read_json(&dir.join(format!("out/{i}/summary.json")));
        assert_eq!(s["ending"], "wall-limit", "run {i}");
        assert!(
            err.contains(&format!("run {i} stopped by the wall-clock limit")),
            "{err}"
        );
    }
    assert!(err.contains("vibrobed: run 0: t = "), "{err}");
    let bad = vibrobed(
        &dir,
        &[
            "sweep",
            "run",
            "long.json",
            "--out",
            "o2",
            "--max-run-seconds",
            "0",
        ],
    );
    assert_eq!(bad.status.code(), Some(2), "{}", describe(&bad));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--max-run-seconds: "));
}

/// `sweep plan --estimate` runs a trial of each point's first run and tells the CPU time per
/// run, per point (its seeds) and in total, without writing anything: a point whose trial ends
/// the run was measured whole (one by its duration, one by its event limit), one cut by its own
/// wall-clock limit (0.3 s, far before its 10⁶ time units) is extrapolated no further than that
/// limit. A bad trial length is refused by name.
#[test]
fn sweep_plan_estimates_the_cost_from_a_trial_of_each_point() {
    let dir = scratch("estimate");
    let sweep = r#"{
      "name": "costs",
      "scenario": "bed.json",
      "combine": "zip",
      "axes": [
        { "key": "floor.gamma", "values": [2.5, 3.0, 4.0] },
        { "key": "run.max_events", "values": [100000000, 100, 100000000] },
        { "key": "run.duration", "values": [3, 3, 1000000] },
        { "key": "run.max_wall_seconds", "values": [1000, 1000, 0.3] }
      ],
      "seeds": [5, 6]
    }"#;
    std::fs::write(dir.join("costs.json"), sweep).unwrap();
    let out = vibrobed(&dir, &["sweep", "plan", "costs.json", "--estimate", "30"]);
    assert_ok(&out);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let row = |point: &str| -> Vec<String> {
        let line = text
            .lines()
            .skip_while(|l| !l.starts_with("estimated cost"))
            .find(|l| l.starts_with(&format!("{point} ")))
            .unwrap_or_else(|| panic!("no row for point {point}:\n{}", describe(&out)));
        // The trial's words, then per run, runs, per point, settings: split on 2+ spaces.
        line.split("  ")
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect()
    };
    let (r0, r1, r2) = (row("0"), row("1"), row("2"));
    assert_eq!(r0[1], "whole run", "{r0:?}");
    assert_eq!(r1[1], "whole run (event limit)", "{r1:?}");
    assert!(
        r2[1].starts_with("to t = ") && r2[1].ends_with(", extrapolated"),
        "{r2:?}"
    );
    assert_eq!(
        (r2[2].as_str(), r2[4].as_str()),
        ("0.30 s", "0.60 s"),
        "{r2:?}"
    );
    for r in [&r0, &r1, &r2] {
        assert_eq!(r[3], "2", "two seeds per point: {r:?}");
    }
    assert!(r1[5].contains("run.max_events=100,"), "{r1:?}");
    assert!(text.contains("\ntotal: 6 runs, "), "{}", describe(&out));
    assert!(!text.contains("without point"), "{}", describe(&out));
    let written: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n != "bed.json" && n != "small.json" && n != "costs.json")
        .collect();
    assert!(written.is_empty(), "the trials wrote {written:?}");

    let bad = vibrobed(&dir, &["sweep", "plan", "costs.json", "--estimate=0"]);
    assert_eq!(bad.status.code(), Some(2), "{}", describe(&bad));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--estimate"));
}
