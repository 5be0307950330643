//! Checkpoint and resume, end to end on the real binary: a run stopped at a checkpoint (by its
//! duration, its event budget or SIGTERM) and resumed gives the uninterrupted run's summary,
//! profiles and final state bit for bit; damaged, truncated, foreign and non-checkpoint files,
//! and resumes that would change the scene, are refused with exit 2 and a message.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Fields that measure the process, not the physics: wall time, and bytes held (vector
/// capacities differ after a resume).
const PROCESS: [&str; 3] = ["wall_seconds", "collisions_per_second", "bytes_per_disk"];

fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("checkpoint-{test}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

fn scenario(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios")
        .join(name)
        .to_string_lossy()
        .into_owned()
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

/// Exit 2, nothing on stdout, and every `needles` in the message.
fn assert_refused(out: &Output, needles: &[&str]) {
    assert_eq!(out.status.code(), Some(2), "{}", describe(out));
    let err = String::from_utf8_lossy(&out.stderr);
    for n in needles {
        assert!(err.contains(n), "message lacks {n:?}: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

/// The summary without its process measurements.
fn physics(path: &Path) -> Value {
    fn strip(v: &mut Value) {
        match v {
            Value::Object(map) => {
                for k in PROCESS {
                    map.remove(k);
                }
                map.values_mut().for_each(strip);
            }
            Value::Array(items) => items.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let text = std::fs::read_to_string(path).expect("summary written");
    let mut v: Value = serde_json::from_str(&text).expect("summary is JSON");
    strip(&mut v);
    v
}

/// The last frame of an extended XYZ trajectory: its time and its atom lines (the lattice, fitted
/// to the bed when each part starts, is left out).
fn last_frame(path: &Path) -> (String, Vec<String>) {
    let text = std::fs::read_to_string(path).expect("trajectory written");
    let lines: Vec<&str> = text.lines().collect();
    let n: usize = lines[0].trim().parse().expect("atom count");
    let frame = &lines[lines.len() - (n + 2)..];
    let time = frame[1]
        .split_whitespace()
        .find(|f| f.starts_with("Time="))
        .expect("frame time")
        .to_owned();
    (time, frame[2..].iter().map(|s| s.to_string()).collect())
}

/// `--profiles file` for scenes with gravity (the others have no height profiles).
fn profile_args(profiles: bool, file: &str) -> Vec<String> {
    if profiles {
        vec!["--profiles".into(), file.into()]
    } else {
        Vec::new()
    }
}

/// Runs `scene` to `duration` in one go, and again as a run to `cut` with a checkpoint plus a
/// resume to `duration`; the two must agree bit for bit on the summary (but for the process
/// measurements), the profiles and the last trajectory frame.
fn resumed_equals_uninterrupted(test: &str, scene: &str, sets: &[&str], cut: f64, duration: f64) {
    let profiles = !scene.starts_with("gas");
    let dir = scratch(test);
    let scene = scenario(scene);
    // The default frame interval follows the duration: fix the trajectory's so that both runs
    // have a frame at the end.
    let mut common: Vec<String> = vec![
        "-q".into(),
        "--set".into(),
        "output.trajectory_interval=0.25".into(),
    ];
    for s in sets {
        common.extend(["--set".into(), s.to_string()]);
    }
    let full = [
        vec!["run".to_string(), scene.clone()],
        common.clone(),
        [
            "--set",
            &format!("run.duration={duration}"),
            "--summary",
            "full.json",
            "--trajectory",
            "full.xyz",
        ]
        .map(String::from)
        .to_vec(),
        profile_args(profiles, "full.csv"),
    ]
    .concat();
    assert_ok(&vibrobed(&dir, &full));

    let first = [
        vec!["run".to_string(), scene],
        common,
        [
            "--set",
            &format!("run.duration={cut}"),
            "--summary",
            "first.json",
            "--checkpoint",
            "run.ckpt",
        ]
        .map(String::from)
        .to_vec(),
    ]
    .concat();
    assert_ok(&vibrobed(&dir, &first));
    let cut_summary = physics(&dir.join("first.json"));
    assert_eq!(cut_summary["ending"], "completed");

    let resume = [
        [
            "resume",
            "run.ckpt",
            "-q",
            "--set",
            &format!("run.duration={duration}"),
            "--summary",
            "resumed.json",
            "--trajectory",
            "resumed.xyz",
        ]
        .map(String::from)
        .to_vec(),
        profile_args(profiles, "resumed.csv"),
    ]
    .concat();
    assert_ok(&vibrobed(&dir, &resume));

    assert_eq!(
        physics(&dir.join("resumed.json")),
        physics(&dir.join("full.json")),
        "resumed summary differs from the uninterrupted run's ({test})"
    );
    if profiles {
        let read = |f: &str| std::fs::read_to_string(dir.join(f)).expect("profiles written");
        assert_eq!(read("resumed.csv"), read("full.csv"), "profiles ({test})");
    }
    let (resumed, full) = (
        last_frame(&dir.join("resumed.xyz")),
        last_frame(&dir.join("full.xyz")),
    );
    assert_eq!(resumed.0, full.0, "time of the last frame ({test})");
    let differ = (resumed.1.iter().zip(&full.1)).position(|(a, b)| a != b);
    assert!(
        differ.is_none() && resumed.1.len() == full.1.len(),
        "final state ({test}): first difference at disk {differ:?}"
    );
}

#[test]
fn a_resumed_gas_is_the_uninterrupted_gas() {
    resumed_equals_uninterrupted(
        "gas",
        "gas_periodic_phi03.json",
        &["particles.count=400", "domain.width=20", "run.warmup=1"],
        2.3,
        5.0,
    );
}

/// The local re-mapping keeps anchors and lists that change one disk at a time: they go into
/// the checkpoint too (a gas, and a bed with riders).
#[test]
fn a_resumed_run_with_local_remapping_is_the_uninterrupted_run() {
    resumed_equals_uninterrupted(
        "local-gas",
        "gas_periodic_phi03.json",
        &[
            "particles.count=400",
            "domain.width=20",
            "engine.remap=local",
            "run.warmup=1",
        ],
        2.3,
        5.0,
    );
    resumed_equals_uninterrupted(
        "local-bed",
        "vibrated_bed.json",
        &["engine.remap=local", "run.warmup=2"],
        4.7,
        9.0,
    );
}

/// Renumbered disks: the engine's numbering goes into the checkpoint (a gas, and a bed with
/// riders and the local re-mapping).
#[test]
fn a_resumed_renumbered_run_is_the_uninterrupted_run() {
    resumed_equals_uninterrupted(
        "renumbered-gas",
        "gas_periodic_phi03.json",
        &[
            "particles.count=400",
            "domain.width=20",
            "engine.renumber=on",
            "run.warmup=1",
        ],
        2.3,
        5.0,
    );
    resumed_equals_uninterrupted(
        "renumbered-bed",
        "hard/bed_at_rest_tc.json",
        &["engine.renumber=on", "engine.remap=local"],
        4.7,
        12.0,
    );
}

#[test]
fn a_resumed_vibrated_bed_is_the_uninterrupted_bed() {
    resumed_equals_uninterrupted("bed", "vibrated_bed.json", &["run.warmup=2"], 4.7, 9.0);
    let exact = ["run.warmup=2", "engine.scheme=event-driven"];
    resumed_equals_uninterrupted("exact-bed", "vibrated_bed.json", &exact, 4.7, 9.0);
}

/// A small bed riding the floor (200 disks, Γ = 0.5), which the hybrid hands to contact dynamics
/// near t = 12.
const RIDING: [&str; 5] = [
    "floor.gamma=0.5",
    "particles.temperature=0.01",
    "particles.count=200",
    "domain.width=40.3",
    "run.warmup=2",
];

/// The hybrid scheme (`auto` for this bed): riding the floor, the bed goes to contact dynamics
/// near t = 12 and falls asleep there near t = 24. Cut before the hand-over, after it, while the
/// bed grows quiet and while it sleeps, the resumed run is the uninterrupted one.
#[test]
fn a_resumed_hybrid_bed_is_the_uninterrupted_bed() {
    resumed_equals_uninterrupted("hybrid-exact", "vibrated_bed.json", &RIDING, 8.7, 20.0);
    resumed_equals_uninterrupted("hybrid-dense", "vibrated_bed.json", &RIDING, 15.3, 20.0);
    resumed_equals_uninterrupted("hybrid-quiet", "vibrated_bed.json", &RIDING, 22.7, 30.0);
    resumed_equals_uninterrupted("hybrid-asleep", "vibrated_bed.json", &RIDING, 26.3, 30.0);
    let asleep = Path::new(env!("CARGO_TARGET_TMPDIR")).join("checkpoint-hybrid-asleep");
    let cut = physics(&asleep.join("first.json"));
    let since = cut["at_rest_since"].as_f64();
    assert!(
        since < Some(26.3),
        "the bed was not asleep at the cut: {since:?}"
    );
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("checkpoint-hybrid-dense");
    let whole = physics(&dir.join("full.json"));
    let dense = &whole["approximation"];
    assert!(
        dense["handovers"].as_u64() >= Some(1) && dense["dense_time"].as_f64() > Some(5.0),
        "the bed did not go to contact dynamics: {dense}"
    );
    let cut = physics(&dir.join("first.json"));
    let cut_dense = cut["approximation"]["dense_time"].as_f64();
    assert!(cut_dense > Some(1.0), "the cut fell before the hand-over");
}

/// Rough disks on the hybrid scheme (`auto` for a rough bed too): their spins go over with the
/// contact dynamics' state, and the resumed run is the uninterrupted one.
#[test]
fn a_resumed_rough_hybrid_bed_is_the_uninterrupted_bed() {
    let rough = [
        "collisions.friction=0.5",
        "floor.friction=0.5",
        "particles.rotational_temperature=0.01",
    ];
    let riding: Vec<&str> = RIDING.into_iter().chain(rough).collect();
    resumed_equals_uninterrupted("hybrid-rough", "vibrated_bed.json", &riding, 15.3, 20.0);
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("checkpoint-hybrid-rough");
    let cut = physics(&dir.join("first.json"));
    let cut_dense = cut["approximation"]["dense_time"].as_f64();
    assert!(cut_dense > Some(1.0), "the cut fell before the hand-over");
    let whole = physics(&dir.join("full.json"));
    assert!(
        whole["temperature"]["rotational"].as_f64() > Some(0.0),
        "no spins: {}",
        whole["temperature"]
    );
}

/// The other event queue, Isobe's tree, goes into the checkpoint as well as the calendar.
#[test]
fn a_resumed_bed_on_the_tree_is_the_uninterrupted_bed() {
    resumed_equals_uninterrupted(
        "tree",
        "vibrated_bed.json",
        &["run.warmup=2", "engine.queue=tree"],
        4.7,
        9.0,
    );
}

/// Disks at rest riding the floor (the speed cut-off puts them on riders): the riders, their
/// floor phase and the engine's epoch go into the checkpoint too.
#[test]
fn a_resumed_bed_at_rest_is_the_uninterrupted_bed() {
    resumed_equals_uninterrupted(
        "rest",
        "hard/bed_at_rest_speed_cutoff.json",
        &[],
        13.0,
        30.0,
    );
}

/// Rough disks: their spins and orientations go into the checkpoint (the summary's rotational
/// energy and temperature compare them), renumbered and under the local re-mapping too.
#[test]
fn a_resumed_rough_bed_is_the_uninterrupted_bed() {
    let rough = [
        "run.warmup=2",
        "collisions.friction=0.4",
        "collisions.tangential_restitution=0.3",
        "floor.friction=0.5",
        "particles.rotational_temperature=0.3",
    ];
    resumed_equals_uninterrupted("rough", "vibrated_bed.json", &rough, 4.7, 9.0);
    let renumbered = [&rough[..], &["engine.renumber=on", "engine.remap=local"]].concat();
    resumed_equals_uninterrupted(
        "rough-renumbered",
        "vibrated_bed.json",
        &renumbered,
        4.7,
        9.0,
    );
}

/// The TC model (collisions within tc of the last one are elastic) keeps per-disk times.
#[test]
fn a_resumed_tc_bed_is_the_uninterrupted_bed() {
    resumed_equals_uninterrupted("tc", "hard/bed_at_rest_tc.json", &[], 7.5, 20.0);
}

/// A run stopped by its event budget resumes with a larger budget to the same end.
#[test]
fn an_event_budget_can_be_raised_on_resume() {
    let dir = scratch("budget");
    let scene = scenario("gas_periodic_phi03.json");
    let base = [
        "--set",
        "particles.count=300",
        "--set",
        "run.duration=4",
        "--set",
        "run.warmup=1",
        "-q",
    ];
    let mut full = vec!["run", &scene, "--summary", "full.json"];
    full.extend(base);
    assert_ok(&vibrobed(&dir, &full));
    let mut cut = vec![
        "run",
        &scene,
        "--summary",
        "cut.json",
        "--checkpoint",
        "run.ckpt",
        "--set",
        "run.max_events=500",
    ];
    cut.extend(base);
    let cut = vibrobed(&dir, &cut);
    assert_eq!(
        cut.status.code(),
        Some(4),
        "the event limit's own exit code"
    );
    assert_eq!(physics(&dir.join("cut.json"))["ending"], "event-limit");
    assert_ok(&vibrobed(
        &dir,
        &[
            "resume",
            "run.ckpt",
            "-q",
            "--set",
            "run.max_events=1000000000",
            "--summary",
            "resumed.json",
        ],
    ));
    assert_eq!(
        physics(&dir.join("resumed.json")),
        physics(&dir.join("full.json"))
    );
}

/// SIGTERM (what a batch system sends at the end of a job's time) stops the run at the next
/// event with exit 143, a summary marked interrupted and a checkpoint of that moment; resuming
/// it gives the uninterrupted run. Periodic checkpoints are written while it runs.
#[cfg(unix)]
#[test]
fn sigterm_checkpoints_and_the_resume_finishes_the_run() {
    let dir = scratch("sigterm");
    let scene = scenario("gas_periodic_phi03.json");
    let sets = [
        "--set",
        "particles.count=2000",
        "--set",
        "run.duration=60",
        "--set",
        "run.warmup=1",
        "-q",
    ];
    let mut child = Command::new(env!("CARGO_BIN_EXE_vibrobed"))
        .current_dir(&dir)
        .args(["run", &scene, "--summary", "cut.json"])
        .args(["--checkpoint", "run.ckpt", "--checkpoint-every", "0.5"])
        .args(sets)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the vibrobed binary starts");
    // Wait for the first periodic checkpoint: the run is under way.
    let start = Instant::now();
    while !dir.join("run.ckpt").exists() {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no periodic checkpoint after 2 minutes"
        );
        if let Some(status) = child.try_wait().expect("wait") {
            panic!("the run ended ({status}) before its first checkpoint");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let killed = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(killed.success());
    let out = child.wait_with_output().expect("the run ends");
    assert_eq!(out.status.code(), Some(143), "{}", describe(&out));
    let cut = physics(&dir.join("cut.json"));
    assert_eq!(cut["ending"], "interrupted", "{cut}");

    assert_ok(&vibrobed(
        &dir,
        &["resume", "run.ckpt", "-q", "--summary", "resumed.json"],
    ));
    let mut full = vec!["run", &scene, "--summary", "full.json"];
    full.extend(sets);
    assert_ok(&vibrobed(&dir, &full));
    assert_eq!(
        physics(&dir.join("resumed.json")),
        physics(&dir.join("full.json"))
    );
}

/// A checkpoint written at the end of a short gas run, for the refusal tests.
fn a_checkpoint(dir: &Path) -> PathBuf {
    let scene = scenario("gas_periodic_phi03.json");
    assert_ok(&vibrobed(
        dir,
        &[
            "run",
            &scene,
            "-q",
            "--set",
            "particles.count=100",
            "--set",
            "domain.width=12",
            "--set",
            "run.duration=1",
            "--set",
            "run.warmup=0",
            "--summary",
            "first.json",
            "--checkpoint",
            "run.ckpt",
        ],
    ));
    dir.join("run.ckpt")
}

#[test]
fn damaged_truncated_foreign_and_other_files_are_refused() {
    let dir = scratch("refusals");
    let good = std::fs::read(a_checkpoint(&dir)).unwrap();
    let try_resume = |bytes: &[u8], needles: &[&str]| {
        std::fs::write(dir.join("bad.ckpt"), bytes).unwrap();
        let out = vibrobed(&dir, &["resume", "bad.ckpt", "-q", "--summary", "out.json"]);
        assert_refused(&out, needles);
        assert!(
            !dir.join("out.json").exists(),
            "a refused resume wrote a summary"
        );
    };
    // Not a checkpoint at all.
    try_resume(
        b"{\"name\": \"a scenario\"}",
        &["CHECKPOINT", "not a vibrobed checkpoint"],
    );
    try_resume(b"", &["CHECKPOINT"]);
    // Cut short, in the header and in the payload.
    try_resume(&good[..20], &["CHECKPOINT", "truncated"]);
    try_resume(&good[..good.len() / 2], &["CHECKPOINT", "truncated"]);
    // One payload bit flipped.
    let mut flipped = good.clone();
    let i = good.len() - 100;
    flipped[i] ^= 0x10;
    try_resume(&flipped, &["CHECKPOINT", "damaged"]);
    // Written by another build (its build id differs).
    let mut foreign = good.clone();
    foreign[12] ^= 0xff;
    try_resume(&foreign, &["CHECKPOINT", "another build"]);
    // Another format version.
    let mut version = good.clone();
    version[8] = version[8].wrapping_add(1);
    try_resume(&version, &["CHECKPOINT", "format"]);
    // A file that is not there.
    assert_refused(
        &vibrobed(&dir, &["resume", "missing.ckpt", "-q"]),
        &["missing.ckpt"],
    );
}

#[test]
fn a_resume_changes_only_the_duration_and_the_event_budget() {
    let dir = scratch("sets");
    a_checkpoint(&dir);
    assert_refused(
        &vibrobed(
            &dir,
            &["resume", "run.ckpt", "-q", "--set", "particles.count=5"],
        ),
        &["particles.count", "run.duration", "run.max_events"],
    );
    assert_refused(
        &vibrobed(&dir, &["resume", "run.ckpt", "-q", "--set", "gravity=2"]),
        &["gravity"],
    );
    // A duration before the checkpoint cannot be reached.
    assert_refused(
        &vibrobed(
            &dir,
            &["resume", "run.ckpt", "-q", "--set", "run.duration=0.5"],
        ),
        &["run.duration"],
    );
    assert_refused(
        &vibrobed(
            &dir,
            &["resume", "run.ckpt", "-q", "--set", "run.duration=-"],
        ),
        &["run.duration"],
    );
}

#[test]
fn only_the_event_driven_engine_checkpoints() {
    let dir = scratch("scheme");
    let scene = scenario("gas_periodic_phi03.json");
    assert_refused(
        &vibrobed(
            &dir,
            &[
                "run",
                &scene,
                "-q",
                "--set",
                "engine.scheme=time_stepped",
                "--checkpoint",
                "run.ckpt",
            ],
        ),
        &["engine.scheme"],
    );
    assert!(!dir.join("run.ckpt").exists());
    assert_refused(
        &vibrobed(
            &dir,
            &[
                "run",
                &scene,
                "-q",
                "--checkpoint",
                "c",
                "--checkpoint-every",
                "0",
            ],
        ),
        &["--checkpoint-every"],
    );
}

/// The resumed part records to a new file under the run's recording id (the viewer merges
/// files with one id into one recording); the earlier part's file is not overwritten.
#[cfg(feature = "record")]
#[test]
fn a_resumed_recording_continues_the_run_in_a_new_file() {
    use vibrobed::output::recording::read_back;
    let dir = scratch("record");
    let scene = scenario("vibrated_bed.json");
    assert_ok(&vibrobed(
        &dir,
        &[
            "run",
            &scene,
            "-q",
            "--set",
            "run.duration=3",
            "--set",
            "run.warmup=1",
            "--rrd",
            "part1.rrd",
            "--checkpoint",
            "run.ckpt",
            "--summary",
            "s1.json",
        ],
    ));
    let before = std::fs::read(dir.join("part1.rrd")).unwrap();
    assert_refused(
        &vibrobed(
            &dir,
            &[
                "resume",
                "run.ckpt",
                "-q",
                "--set",
                "run.duration=6",
                "--rrd",
                "part1.rrd",
            ],
        ),
        &["--rrd", "part1.rrd"],
    );
    assert_eq!(std::fs::read(dir.join("part1.rrd")).unwrap(), before);
    assert_ok(&vibrobed(
        &dir,
        &[
            "resume",
            "run.ckpt",
            "-q",
            "--set",
            "run.duration=6",
            "--rrd",
            "part2.rrd",
            "--summary",
            "s2.json",
        ],
    ));
    let one = read_back(&dir.join("part1.rrd")).unwrap();
    let two = read_back(&dir.join("part2.rrd")).unwrap();
    assert!(one.has_footer && two.has_footer);
    assert!(one.recording_id.is_some());
    assert_eq!(one.recording_id, two.recording_id);
    let last_one = one.disks.last().expect("frames in part 1").frame;
    let first_two = two.disks.first().expect("frames in part 2").frame;
    assert!(
        first_two > last_one,
        "part 2 continues the frame count ({last_one} then {first_two})"
    );
}

/// Disks leaving through a floor orifice: the pool of live and dead disks, their ids and the
/// flow go into the checkpoint; the cut falls while the silo drains.
#[test]
fn a_resumed_draining_silo_is_the_uninterrupted_silo() {
    resumed_equals_uninterrupted(
        "silo",
        "silo.json",
        &["run.warmup=2", "engine.check_invariants=true"],
        7.3,
        15.0,
    );
}

/// Disks leaving at the top of a strongly vibrated bed and recycled by an inlet: the cut falls
/// while they leave and come back.
#[test]
fn a_resumed_bed_losing_disks_at_the_top_is_the_uninterrupted_bed() {
    resumed_equals_uninterrupted(
        "exit-top",
        "vibrated_bed.json",
        &[
            "floor.gamma=6",
            "domain.exit_height=12",
            r#"inlets=[{"x":{"from":1,"to":199},"y":{"from":9,"to":10},"recycle":true}]"#,
            "run.warmup=2",
            "engine.check_invariants=true",
        ],
        7.3,
        15.0,
    );
}
