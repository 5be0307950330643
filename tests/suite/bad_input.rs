//! Bad input that once got past the checks, one test each: every one must be refused with exit 2
//! and an error naming the field (`vibrobed: <field>: <message>`), without a panic and without
//! writing anything; or, for a run that is legal but cannot finish, be stoppable by SIGINT.

use crate::guarded;

use guarded::{entries, error_field, error_line, fresh_dir, names, scenario, Limits, Outcome};
use std::ffi::OsString;
use std::path::Path;
use std::time::Duration;
use vibrobed::scenario::checks::MAX_OUTPUT_VISITS;
use vibrobed::scenario::Scenario;

/// A refusal takes well under a second; anything still running after this is stopped.
const LIMIT_SECS: u64 = 10;

/// Runs `vibrobed ARGS` from `dir` (empty before), under the guard.
fn vibrobed(dir: &Path, args: &[OsString]) -> Outcome {
    let logs = dir.with_extension("logs");
    let out = guarded::run(args, dir, &logs, Limits::secs(LIMIT_SECS));
    let _ = std::fs::remove_dir_all(&logs);
    out
}

/// Runs `vibrobed WORDS` from `dir` under the guard, interrupts it (SIGINT) once `ready` holds,
/// it has ended, or `wait` has passed, and gives it `grace` to stop.
fn interrupted(
    words: &[&str],
    dir: &Path,
    wait: Duration,
    grace: Duration,
    ready: impl Fn() -> bool,
) -> Outcome {
    let logs = dir.with_extension("logs");
    let mut child = guarded::start(&guarded::args(words), dir, &logs);
    while !child.ended() && !ready() && child.elapsed() < wait {
        std::thread::sleep(Duration::from_millis(5));
    }
    child.interrupt();
    let out = child.wait(Limits {
        interrupt_after: Duration::ZERO,
        kill_after: grace,
    });
    let _ = std::fs::remove_dir_all(&logs);
    out
}

/// `check SCENARIO --set S...`.
fn check(name: &str, sets: &[&str]) -> Vec<OsString> {
    let mut args: Vec<OsString> = vec!["check".into(), scenario(name).into()];
    for s in sets {
        args.push("--set".into());
        args.push((*s).into());
    }
    args
}

/// Asserts the outcome is a refusal (exit 2, without a panic, on its own) naming one of
/// `fields` (a field under one counts; empty: any field), and that `dir` holds nothing but
/// `allowed`.
fn assert_refused(out: &Outcome, fields: &[&str], dir: &Path, allowed: &[&str]) {
    let what = out.describe();
    assert!(!out.panicked(), "panicked: {what}");
    assert!(
        out.interrupted_at.is_none(),
        "did not end by itself within {LIMIT_SECS} s: {what}"
    );
    assert_eq!(out.code(), Some(2), "expected exit 2: {what}");
    let field = error_field(&out.stderr).unwrap_or_else(|| {
        panic!(
            "the error names no field ({:?}): {what}",
            error_line(&out.stderr)
        )
    });
    assert!(
        fields.is_empty() || fields.iter().any(|f| names(&field, f)),
        "the error names `{field}`, expected one of {fields:?}: {what}"
    );
    let left: Vec<String> = entries(dir)
        .into_iter()
        .filter(|e| !allowed.contains(&e.as_str()))
        .collect();
    assert!(left.is_empty(), "files left behind: {left:?}: {what}");
}

/// A `check` with these sets is refused naming one of `fields`.
fn check_refuses(test: &str, name: &str, sets: &[&str], fields: &[&str]) {
    let dir = fresh_dir(&format!("bad-{test}"));
    let out = vibrobed(&dir, &check(name, sets));
    assert_refused(&out, fields, &dir, &[]);
    let _ = std::fs::remove_dir_all(&dir);
}

// --- 1. A floor acceleration or gravity beyond reason. ---

#[test]
fn a_gamma_of_1e300_is_refused() {
    check_refuses(
        "gamma",
        "vibrated_bed.json",
        &["floor.gamma=1e300"],
        &["floor", "gravity"],
    );
}

#[test]
fn a_gravity_of_1e300_is_refused() {
    check_refuses(
        "gravity",
        "vibrated_bed.json",
        &["gravity=1e300"],
        &["gravity", "floor"],
    );
}

#[test]
fn an_amplitude_of_1e17_is_refused() {
    check_refuses(
        "amplitude",
        "vibrated_bed.json",
        &["floor.gamma=null", "floor.amplitude=1e17"],
        &["floor"],
    );
}

// --- 2. Sizes that overflow the grid, the profiles or the ensembles. ---

#[test]
fn a_width_of_1e300_is_refused_by_the_time_step_scheme() {
    let dir = fresh_dir("bad-width");
    let args: Vec<OsString> = guarded::args(&[
        "run",
        &scenario("box_walls.json").display().to_string(),
        "--quiet",
        "--summary",
        "summary.json",
        "--set",
        "domain.width=1e300",
        "--set",
        "engine.scheme=time-step",
    ]);
    let out = vibrobed(&dir, &args);
    assert_refused(&out, &[], &dir, &[]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn profile_bins_at_u64_max_are_refused() {
    check_refuses(
        "bins",
        "vibrated_bed.json",
        &["output.profile_bins=18446744073709551615"],
        &["output.profile_bins"],
    );
}

#[test]
fn a_height_of_1e18_is_refused() {
    check_refuses(
        "height-1e18",
        "box_walls.json",
        &["domain.height=1e18"],
        &[],
    );
}

#[test]
fn accuracy_with_u64_max_seeds_is_refused() {
    let dir = fresh_dir("bad-seeds");
    let args: Vec<OsString> = guarded::args(&[
        "accuracy",
        &scenario("bouncing_ball.json").display().to_string(),
        "--quiet",
        "--seeds",
        "18446744073709551615",
        "--out",
        "acc",
    ]);
    let out = vibrobed(&dir, &args);
    assert_refused(&out, &["--seeds"], &dir, &[]);
    let _ = std::fs::remove_dir_all(&dir);
}

// --- 3. Counts and boxes too large to hold. ---

#[test]
fn a_trillion_disks_are_refused() {
    check_refuses(
        "trillion",
        "vibrated_bed.json",
        &["particles.count=1000000000000"],
        &["particles.count"],
    );
}

#[test]
fn a_height_of_1e9_is_refused() {
    check_refuses("height-1e9", "box_walls.json", &["domain.height=1e9"], &[]);
}

/// A closed box of 10⁵ × 10⁵ holding two disks: a dense grid would need ~5·10⁹ cells (an 88 GB
/// allocation that aborted); `auto` takes the hashed array, and the run finishes under the
/// guard's 4 GiB address space.
#[test]
fn a_huge_sparse_box_runs_in_little_memory() {
    let dir = fresh_dir("bad-sparse-box");
    let out = vibrobed(
        &dir,
        &run_args(
            "box_walls.json",
            &["--summary", "s.json"],
            &[
                "domain.width=1e5",
                "domain.height=1e5",
                "particles.count=2",
                "run.duration=1",
                "run.warmup=0",
            ],
        ),
    );
    let what = out.describe();
    assert!(!out.panicked(), "panicked: {what}");
    assert_eq!(out.code(), Some(0), "{what}");
    assert!(dir.join("s.json").exists(), "{what}");
    let _ = std::fs::remove_dir_all(&dir);
}

// --- 4. Species counts whose sum overflows. ---

#[test]
fn species_counts_summing_past_u64_are_refused() {
    check_refuses(
        "species-sum",
        "vibrated_bed.json",
        &[
            r#"particles.radius={"species":[{"radius":0.5,"count":18446744073709551615},{"radius":0.5,"count":2}]}"#,
            "particles.count=null",
        ],
        &["particles.radius.species"],
    );
}

// --- 5. The culprit is named, not a field it upsets. ---

#[test]
fn a_radius_of_1e_300_is_blamed_on_the_radius() {
    check_refuses(
        "radius",
        "vibrated_bed.json",
        &["particles.radius=1e-300"],
        &["particles.radius"],
    );
}

#[test]
fn a_subnormal_density_is_refused() {
    check_refuses(
        "density",
        "vibrated_bed.json",
        &["particles.density=5e-324"],
        &["particles.density"],
    );
}

// --- 6. Runs that could never finish. ---

#[test]
fn a_sample_interval_of_1e_7_is_refused() {
    check_refuses(
        "sample",
        "vibrated_bed.json",
        &["output.sample_interval=1e-7"],
        &["output.sample_interval"],
    );
}

#[test]
fn a_frame_interval_of_1e_7_is_refused() {
    check_refuses(
        "frame",
        "vibrated_bed.json",
        &["output.frame_interval=1e-7"],
        &["output.frame_interval"],
    );
}

#[test]
fn a_duration_of_1e308_is_refused() {
    check_refuses(
        "duration",
        "vibrated_bed.json",
        &["run.duration=1e308"],
        &["run.duration"],
    );
}

/// A run with `set` is refused naming `field`, or ends by itself, or stops on SIGINT within
/// [`STOP_GRACE`].
fn refused_or_interruptible(test: &str, set: &str, fields: &[&str]) {
    refused_or_interruptible_with(test, &[set], fields)
}

/// How long a run may take to stop after SIGINT. A stop takes a fraction of a second of CPU;
/// on a loaded machine (the suite's processes on two cores) that can be a second of wall time
/// or more. A run deaf to SIGINT (the engine's build once was, for 18 s) is still caught.
const STOP_GRACE: Duration = Duration::from_secs(5);

/// [`refused_or_interruptible`] with several `--set`s. A run still going after 3 s is sent
/// SIGINT; it must then end by itself within [`STOP_GRACE`]: with exit 130 (stopped, its
/// report written), or with its refusal (exit 2 naming one of `fields`: a refusal slowed past
/// the 3 s by load), or by the signal itself (it came before the handler was installed, while
/// the scene was still being checked: nothing written yet).
fn refused_or_interruptible_with(test: &str, sets: &[&str], fields: &[&str]) {
    let dir = fresh_dir(&format!("bad-{test}"));
    let path = scenario("vibrated_bed.json").display().to_string();
    let mut words = vec!["run", &path, "--quiet", "--summary", "summary.json"];
    for set in sets {
        words.extend(["--set", set]);
    }
    let args: Vec<OsString> = guarded::args(&words);
    let logs = dir.with_extension("logs");
    let mut child = guarded::start(&args, &dir, &logs);
    while !child.ended() && child.elapsed() < Duration::from_secs(3) {
        std::thread::sleep(Duration::from_millis(10));
    }
    let out = if child.ended() {
        child.wait(Limits::secs(LIMIT_SECS))
    } else {
        child.interrupt();
        child.wait(Limits {
            interrupt_after: Duration::ZERO,
            kill_after: 2 * STOP_GRACE,
        })
    };
    let _ = std::fs::remove_dir_all(&logs);
    let what = out.describe();
    assert!(!out.panicked(), "panicked: {what}");
    assert!(!out.killed, "did not stop on SIGINT: {what}");
    if let Some(at) = out.interrupted_at {
        assert!(
            out.elapsed - at <= STOP_GRACE,
            "took more than {STOP_GRACE:?} to stop after SIGINT: {what}"
        );
    }
    match (out.interrupted_at, out.code(), out.signal()) {
        (_, Some(2), _) => assert_refused(
            &Outcome {
                interrupted_at: None,
                ..out
            },
            fields,
            &dir,
            &[],
        ),
        (None, Some(0), _) | (Some(_), Some(130), _) => {}
        (Some(_), None, Some(2)) => assert!(entries(&dir).is_empty(), "{what}"),
        _ => panic!("neither refused naming {fields:?} nor ended nor stopped by SIGINT: {what}"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_disk_thrown_up_at_1000_is_interruptible() {
    refused_or_interruptible_with(
        "thrown",
        &[
            "particles.count=1",
            r#"particles.placement={"positions": [[100, 1]], "velocities": [[0, 1000]]}"#,
            "floor.gamma=null",
            "floor.frequency=null",
            "run.duration=1e6",
            "output.frame_interval=1e5",
        ],
        &["particles.placement"],
    );
}

#[test]
fn a_tiny_time_step_is_interruptible() {
    refused_or_interruptible_with(
        "tiny-dt",
        &["engine.scheme=time-step", "engine.dt=1e-9"],
        &["engine.dt"],
    );
}

#[test]
fn a_tiny_synchronisation_distance_is_interruptible() {
    refused_or_interruptible_with(
        "tiny-sync",
        &["engine.scheme=space-time", "engine.sync_distance=1e-3"],
        &["engine.sync_distance"],
    );
}

/// Thermal speeds of 4·10⁹ carry a disk 1.7·10¹² radii in the run: past what can be simulated.
#[test]
fn a_temperature_of_1_8e19_is_refused() {
    run_refuses(
        "temperature",
        "vibrated_bed.json",
        &["--summary", "summary.json"],
        &["particles.temperature=1.8e19"],
        &["particles.temperature"],
    );
}

/// Half that thermal speed is within the travel bound, but a thousand disks at it are past the
/// work bound: refused naming the temperature set (or, were it legal, stopped by SIGINT).
#[test]
fn a_temperature_just_within_the_bound_is_interruptible() {
    refused_or_interruptible(
        "temperature-within",
        "particles.temperature=4.5e18",
        &["particles.temperature"],
    );
}

#[test]
fn a_gravity_of_2_31_is_refused_or_interruptible() {
    // The scene's floor is given by Γ: a stronger gravity means a larger amplitude Γg/ω².
    refused_or_interruptible(
        "gravity-2-31",
        "gravity=2147483648",
        &["gravity", "floor.gamma"],
    );
}

// --- 7. Output paths: refused before the run, and nothing left behind. ---

/// `run SCENARIO --quiet EXTRA... --set SETS...`, from `dir`.
fn run_args(name: &str, extra: &[&str], sets: &[&str]) -> Vec<OsString> {
    let mut args: Vec<OsString> = vec!["run".into(), scenario(name).into(), "--quiet".into()];
    args.extend(extra.iter().map(OsString::from));
    for s in sets {
        args.push("--set".into());
        args.push((*s).into());
    }
    args
}

/// `run` with these arguments is refused naming one of `fields`, from a fresh directory it
/// leaves empty.
fn run_refuses(test: &str, name: &str, extra: &[&str], sets: &[&str], fields: &[&str]) {
    let dir = fresh_dir(&format!("bad-{test}"));
    let out = vibrobed(&dir, &run_args(name, extra, sets));
    assert_refused(&out, fields, &dir, &[]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A run long enough that simulating before refusing shows as a timeout.
const LONG: &[&str] = &["run.duration=100000"];

/// A run that ends in a blink.
const SHORT: &[&str] = &["run.duration=1", "run.warmup=0"];

#[test]
fn profiles_without_gravity_are_refused_before_the_run() {
    run_refuses(
        "profiles",
        "box_walls.json",
        &["--profiles", "p.csv", "--summary", "s.json"],
        LONG,
        &["--profiles"],
    );
}

#[cfg(feature = "record")]
#[test]
fn profiles_without_gravity_are_refused_before_recording() {
    run_refuses(
        "profiles-rrd",
        "box_walls.json",
        &["--profiles", "p.csv", "--rrd", "r.rrd"],
        LONG,
        &["--profiles"],
    );
}

#[test]
fn a_summary_into_a_directory_is_refused() {
    let dir = fresh_dir("bad-summary-dir");
    std::fs::create_dir(dir.join("sum")).expect("a directory");
    let out = vibrobed(
        &dir,
        &run_args("bouncing_ball.json", &["--summary", "sum"], SHORT),
    );
    assert_refused(&out, &["--summary"], &dir, &["sum"]);
    assert!(
        entries(&dir.join("sum")).is_empty(),
        "files left in the directory"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every output given a fifo is refused before the run naming its option, and the fifo is left
/// a fifo with nothing else written: an output renamed over it would replace it.
#[cfg(unix)]
#[test]
fn outputs_onto_a_fifo_are_refused() {
    use std::os::unix::fs::FileTypeExt;
    let options = [
        "--summary",
        "--trajectory",
        "--fields",
        "--profiles",
        "--checkpoint",
    ];
    for option in options {
        let dir = fresh_dir(&format!("bad-fifo{option}"));
        let made = std::process::Command::new("mkfifo")
            .arg(dir.join("pipe"))
            .status()
            .expect("mkfifo runs");
        assert!(made.success(), "mkfifo failed");
        let out = vibrobed(
            &dir,
            &run_args("vibrated_bed.json", &[option, "pipe"], LONG),
        );
        assert_refused(&out, &[option], &dir, &["pipe"]);
        let message = error_line(&out.stderr).unwrap_or_default();
        assert!(
            message.contains("pipe is not a regular file"),
            "{option}: {message:?}"
        );
        let kind = std::fs::symlink_metadata(dir.join("pipe")).expect("the fifo is there");
        assert!(
            kind.file_type().is_fifo(),
            "{option}: the fifo was replaced"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn a_summary_in_a_missing_directory_is_refused() {
    run_refuses(
        "summary-nodir",
        "bouncing_ball.json",
        &["--summary", "nodir/x.json"],
        SHORT,
        &["--summary"],
    );
}

#[cfg(feature = "record")]
#[test]
fn a_recording_in_a_missing_directory_is_refused() {
    run_refuses(
        "rrd-nodir",
        "bouncing_ball.json",
        &["--rrd", "nodir/r.rrd", "--summary", "s.json"],
        SHORT,
        &["--rrd"],
    );
}

#[test]
fn an_existing_partial_file_survives_the_summary() {
    let dir = fresh_dir("bad-partial");
    std::fs::write(dir.join("out.partial"), "someone's data").expect("write");
    let out = vibrobed(
        &dir,
        &run_args("bouncing_ball.json", &["--summary", "out.json"], SHORT),
    );
    let what = out.describe();
    assert!(!out.panicked(), "panicked: {what}");
    assert_eq!(out.code(), Some(0), "{what}");
    let summary = std::fs::read_to_string(dir.join("out.json")).expect("the summary");
    assert!(serde_json::from_str::<serde_json::Value>(&summary).is_ok());
    assert_eq!(
        std::fs::read_to_string(dir.join("out.partial"))
            .ok()
            .as_deref(),
        Some("someone's data"),
        "out.partial was overwritten or removed: {what}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `accuracy` of a scenario with these sets fails and leaves no `--out` directory.
fn accuracy_leaves_no_out_directory(test: &str, name: &str, sets: &[&str]) {
    let dir = fresh_dir(&format!("bad-{test}"));
    let mut args: Vec<OsString> = guarded::args(&[
        "accuracy",
        &scenario(name).display().to_string(),
        "--quick",
        "--quiet",
        "--out",
        "acc",
    ]);
    for s in sets {
        args.push("--set".into());
        args.push((*s).into());
    }
    let out = vibrobed(&dir, &args);
    let what = out.describe();
    assert!(!out.panicked(), "panicked: {what}");
    assert!(
        out.interrupted_at.is_none(),
        "did not end by itself: {what}"
    );
    assert!(
        matches!(out.code(), Some(1 | 2)),
        "expected a failure: {what}"
    );
    assert!(
        entries(&dir).is_empty(),
        "left behind: {:?}: {what}",
        entries(&dir)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A report whose variant stops at its event cap fails as it runs (exit 1): the `--out` folder
/// it had made for the recording variant goes too (the commands fuzz found it left, empty).
#[test]
fn accuracy_that_fails_as_it_runs_leaves_no_out_directory() {
    accuracy_leaves_no_out_directory(
        "accuracy-fails-running",
        "bouncing_ball.json",
        &["run.duration=2", "run.warmup=0", "floor.amplitude=5e5"],
    );
}

/// `--cores 4096` runs 4096 seeds at once, a thread each with a 16 MiB stack: under the guard's
/// 4 GiB they cannot all start, which panicked (the commands fuzz found it). Refused naming
/// `--cores`, or run.
#[test]
fn accuracy_on_more_cores_than_threads_start_is_refused_naming_cores() {
    let dir = fresh_dir("bad-accuracy-cores");
    let ball = scenario("bouncing_ball.json").display().to_string();
    let args = guarded::args(&[
        "accuracy",
        &ball,
        "--quick",
        "--quiet",
        "--out",
        "acc",
        "--cores",
        "4096",
        "--set",
        "run.duration=2",
        "--set",
        "run.warmup=0",
    ]);
    let out = vibrobed(&dir, &args);
    if out.code() != Some(0) {
        assert_refused(&out, &["--cores"], &dir, &[]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn accuracy_of_an_invalid_scenario_creates_no_out_directory() {
    accuracy_leaves_no_out_directory(
        "accuracy-invalid",
        "bouncing_ball.json",
        &["particles.radius=-1"],
    );
}

#[test]
fn accuracy_of_an_unbuildable_scene_creates_no_out_directory() {
    // Valid field by field, but 100 000 disks do not fit in the 40 × 40 box.
    accuracy_leaves_no_out_directory(
        "accuracy-unbuildable",
        "box_walls.json",
        &["particles.count=100000"],
    );
}

#[test]
fn accuracy_into_a_file_is_refused_naming_out() {
    let dir = fresh_dir("bad-accuracy-out-file");
    std::fs::write(dir.join("acc"), "a file, not a directory").expect("write");
    let args = guarded::args(&[
        "accuracy",
        &scenario("bouncing_ball.json").display().to_string(),
        "--quick",
        "--quiet",
        "--out",
        "acc",
    ]);
    let out = vibrobed(&dir, &args);
    assert_refused(&out, &["--out"], &dir, &["acc"]);
    let _ = std::fs::remove_dir_all(&dir);
}

// --- 8. The file itself. ---

#[test]
fn a_byte_order_mark_is_accepted() {
    let dir = fresh_dir("bad-bom");
    let text = std::fs::read_to_string(scenario("bouncing_ball.json")).expect("scenario");
    let path = dir.with_extension("json");
    std::fs::write(&path, format!("\u{feff}{text}")).expect("write");
    let out = vibrobed(
        &dir,
        &guarded::args(&["check".into(), path.clone().into_os_string()]),
    );
    let _ = std::fs::remove_file(&path);
    let what = out.describe();
    assert!(!out.panicked(), "panicked: {what}");
    assert_eq!(out.code(), Some(0), "a BOM is refused: {what}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_duplicate_key_is_refused_naming_it() {
    let dir = fresh_dir("bad-duplicate");
    let text = std::fs::read_to_string(scenario("vibrated_bed.json")).expect("scenario");
    assert!(text.contains("\"gravity\""));
    let doubled = text.replacen('{', "{\n  \"gravity\": 2.0,", 1);
    let path = dir.with_extension("json");
    std::fs::write(&path, doubled).expect("write");
    let out = vibrobed(
        &dir,
        &guarded::args(&["check".into(), path.clone().into_os_string()]),
    );
    let _ = std::fs::remove_file(&path);
    let what = out.describe();
    assert!(!out.panicked(), "panicked: {what}");
    assert_eq!(out.code(), Some(2), "a duplicate key is accepted: {what}");
    assert!(
        error_line(&out.stderr).is_some_and(|l| l.contains("gravity")),
        "the error does not name `gravity`: {what}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn output_as_a_list_is_refused_naming_it() {
    check_refuses(
        "output-list",
        "vibrated_bed.json",
        &["output=[]"],
        &["output"],
    );
}

// --- The local re-mapping's own limits. ---

#[test]
fn a_named_mask_with_the_local_re_mapping_is_refused() {
    run_refuses(
        "local-mask",
        "gas_periodic_phi03.json",
        &[],
        &["engine.remap=local", "engine.mask=r5"],
        &["engine.mask"],
    );
}

#[test]
fn a_periodic_box_narrower_than_three_diameters_is_refused_by_the_local_re_mapping() {
    run_refuses(
        "local-narrow",
        "gas_periodic_phi03.json",
        &[],
        &[
            "engine.remap=local",
            "domain.width=2.9",
            "particles.count=3",
            "particles.packing_fraction=0.01",
        ],
        &["domain.width"],
    );
}

// --- Rough disks: each field out of range is refused by name. ---

#[test]
fn rough_fields_out_of_range_are_refused_by_name() {
    for (k, (set, field)) in [
        ("collisions.friction=-0.1", "collisions.friction"),
        (
            "collisions.tangential_restitution=1.5",
            "collisions.tangential_restitution",
        ),
        ("floor.friction=1e300", "floor.friction"),
        (
            "floor.tangential_restitution=-2",
            "floor.tangential_restitution",
        ),
        ("domain.wall_friction=-1", "domain.wall_friction"),
        (
            "domain.wall_tangential_restitution=3",
            "domain.wall_tangential_restitution",
        ),
        ("particles.inertia_factor=0", "particles.inertia_factor"),
        ("particles.inertia_factor=1.5", "particles.inertia_factor"),
        (
            "particles.rotational_temperature=-1",
            "particles.rotational_temperature",
        ),
    ]
    .into_iter()
    .enumerate()
    {
        check_refuses(&format!("rough-{k}"), "vibrated_bed.json", &[set], &[field]);
    }
}

// --- The 2D fields (`run --fields`, `output.field_bins`, `output.field_height`). ---

#[test]
fn field_bins_that_are_not_two_positive_integers_are_refused() {
    for (k, bins) in [
        "[0,3]",
        "[4,0]",
        "[-1,3]",
        "[1.5,3]",
        "[4]",
        "[4,3,2]",
        "7",
        "[100001,2]",
    ]
    .iter()
    .enumerate()
    {
        check_refuses(
            &format!("field-bins-{k}"),
            "vibrated_bed.json",
            &[&format!("output.field_bins={bins}")],
            &["output.field_bins"],
        );
    }
}

#[test]
fn a_field_height_that_is_not_positive_is_refused() {
    for (k, h) in ["0", "-1", "1e300"].iter().enumerate() {
        check_refuses(
            &format!("field-height-{k}"),
            "vibrated_bed.json",
            &[&format!("output.field_height={h}")],
            &["output.field_height"],
        );
    }
}

#[test]
fn fields_without_gravity_are_refused() {
    check_refuses(
        "field-bins-no-gravity",
        "box_walls.json",
        &["output.field_bins=[4,4]"],
        &["output.field_bins"],
    );
    check_refuses(
        "record-fields-no-gravity",
        "box_walls.json",
        &["output.record_fields=true"],
        &["output.record_fields"],
    );
    run_refuses(
        "fields-no-gravity",
        "box_walls.json",
        &["--fields", "f.csv", "--summary", "s.json"],
        LONG,
        &["--fields"],
    );
}

#[test]
fn fields_in_a_missing_directory_are_refused() {
    run_refuses(
        "fields-nodir",
        "vibrated_bed.json",
        &["--fields", "nodir/f.vti", "--summary", "s.json"],
        LONG,
        &["--fields"],
    );
}

// --- Disks that leave and enter: orifices and inlets. ---

/// `run SCENE --set S... --summary --trajectory --rrd` refused with exit 2 naming `field`, and
/// nothing written.
fn pool_refuses(test: &str, scene: &str, sets: &[&str], field: &str) {
    let dir = fresh_dir(&format!("bad-{test}"));
    let path = scenario(scene).display().to_string();
    let mut words = vec![
        "run",
        &path,
        "--quiet",
        "--summary",
        "summary.json",
        "--trajectory",
        "t.xyz",
    ];
    for set in sets {
        words.extend(["--set", set]);
    }
    let out = vibrobed(&dir, &guarded::args(&words));
    assert_refused(&out, &[field], &dir, &[]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn orifices_that_cannot_be_are_refused_and_nothing_is_written() {
    pool_refuses(
        "orifice-wide",
        "silo.json",
        &["floor.orifice.to=99"],
        "floor.orifice.to",
    );
    pool_refuses(
        "orifice-narrow",
        "silo.json",
        &["floor.orifice.to=13.5"],
        "floor.orifice.to",
    );
    pool_refuses(
        "orifice-vibrating",
        "silo.json",
        &["floor.amplitude=0.1", "floor.frequency=1"],
        "floor.orifice",
    );
    pool_refuses(
        "orifice-rough",
        "silo.json",
        &["floor.friction=0.5"],
        "floor.orifice",
    );
    pool_refuses(
        "orifice-scheme",
        "silo.json",
        &["engine.scheme=space-time"],
        "floor.orifice",
    );
}

#[test]
fn inlets_that_cannot_be_are_refused_and_nothing_is_written() {
    pool_refuses(
        "inlet-low",
        "pour.json",
        &["inlets.0.y.from=0.1"],
        "inlets.0.y.from",
    );
    pool_refuses(
        "inlet-rate",
        "pour.json",
        &["inlets.0.rate=-2"],
        "inlets.0.rate",
    );
    pool_refuses(
        "inlet-both",
        "pour.json",
        &["inlets.0.count=3"],
        "inlets.0.count",
    );
    pool_refuses(
        "inlet-recycle",
        "pour.json",
        &["inlets.0.recycle=true"],
        "inlets.0.recycle",
    );
    pool_refuses(
        "inlet-ratio",
        "pour.json",
        &["inlets.0.radius={\"min\":0.05,\"max\":0.5}"],
        "inlets.0.radius",
    );
    pool_refuses(
        "inlet-radius-order",
        "pour.json",
        &["inlets.0.radius={\"min\":0.6,\"max\":0.5}"],
        "inlets.0.radius.min",
    );
    pool_refuses(
        "inlet-mass-and-density",
        "pour.json",
        &["inlets.0.mass=2", "inlets.0.density=1"],
        "inlets.0.density",
    );
    pool_refuses(
        "inlet-species-none",
        "pour.json",
        &["inlets.0.radius={\"species\":[{\"count\":0,\"radius\":0.4}]}"],
        "inlets.0.radius.species",
    );
    // The inlet's largest disk must fit above the floor.
    pool_refuses(
        "inlet-large-low",
        "pour.json",
        &["inlets.0.radius=1.5", "inlets.0.y.from=1.2"],
        "inlets.0.y.from",
    );
    pool_refuses("inlet-list", "pour.json", &["inlets={\"x\":1}"], "inlets");
}

#[test]
fn exit_heights_that_cannot_be_are_refused_and_nothing_is_written() {
    let cases: [(&str, &str, &[&str]); 5] = [
        (
            "exit-negative",
            "vibrated_bed.json",
            &["domain.exit_height=-1"],
        ),
        (
            "exit-lid",
            "vibrated_bed.json",
            &[
                "domain.y_boundary=lid",
                "domain.height=40",
                "domain.exit_height=30",
            ],
        ),
        // The initial bed reaches above 6 (checked where the bed is placed).
        ("exit-bed", "vibrated_bed.json", &["domain.exit_height=6"]),
        // The inlet's box reaches 27 and its disks a radius more.
        ("exit-inlet", "pour.json", &["domain.exit_height=27.2"]),
        (
            "exit-scheme",
            "vibrated_bed.json",
            &["domain.exit_height=30", "engine.scheme=time-step"],
        ),
    ];
    for (test, scene, sets) in cases {
        pool_refuses(test, scene, sets, "domain.exit_height");
    }
}

// --- Second round (issue 62): what a scene costs, bounded before the run. ---

#[test]
fn field_cells_are_bounded_as_a_product() {
    for (test, bins) in [
        ("cells-square", "[100000,100000]"),
        ("cells-strip", "[100000,2000]"),
    ] {
        let set = format!("output.field_bins={bins}");
        check_refuses(test, "vibrated_bed.json", &[&set], &["output.field_bins"]);
    }
}

#[test]
fn inlets_are_bounded_with_the_scene_s_other_disks() {
    let inlet = r#"{"x": {"from": 1, "to": 29}, "y": {"from": 20, "to": 24}, "count": 10000000}"#;
    let two = format!("inlets=[{inlet}, {inlet}]");
    check_refuses("inlets-total", "silo.json", &[&two], &["inlets.1.count"]);
    check_refuses(
        "inlet-one",
        "silo.json",
        &["inlets.0.recycle=false", "inlets.0.count=20000000"],
        &["inlets.0.count"],
    );
}

#[test]
fn a_trajectory_of_2e10_disk_frames_is_refused_before_the_run() {
    run_refuses(
        "trajectory-size",
        "vibrated_bed.json",
        &["--trajectory", "t.xyz", "--summary", "s.json"],
        &["particles.count=10000", "output.trajectory_interval=1e-4"],
        &["--trajectory"],
    );
}

#[test]
fn a_checkpoint_every_1e_9_is_refused() {
    run_refuses(
        "checkpoint-every",
        "vibrated_bed.json",
        &["--checkpoint", "c.ckpt", "--checkpoint-every", "1e-9"],
        &[],
        &["--checkpoint-every"],
    );
}

/// Every interval or wall-clock limit given beside a scene (`--progress-every`,
/// `--checkpoint-every`, `run.max_wall_seconds`, `sweep run --max-run-seconds`, `sweep plan
/// --estimate`) refuses the ends of double precision and a step past its bounds, naming the
/// option and the bound, writing nothing; its bounds themselves are accepted.
#[test]
fn intervals_past_their_bounds_are_refused_naming_the_option_and_bound() {
    let sweep = serde_json::json!({
        "name": "ball",
        "scenario": scenario("bouncing_ball.json"),
        "set": ["run.duration=1", "run.warmup=0"],
        "axes": [{ "key": "floor.restitution", "values": [0.5] }],
        "seeds": 1
    });
    let home = fresh_dir("bad-interval-sweep");
    let file = home.join("ball.json");
    std::fs::write(&file, sweep.to_string()).expect("sweep file");
    let sweep = file.display().to_string();
    let run = |extra: &[&str]| run_args("bouncing_ball.json", extra, SHORT);
    let sweep_run = |extra: &[&str]| {
        let mut args = guarded::args(&["sweep", "run", &sweep, "--out", "out", "--quiet"]);
        args.extend(extra.iter().map(OsString::from));
        args
    };
    let plan = |s: &str| guarded::args(&["sweep", "plan", &sweep, "--estimate", s]);
    let progress = |s: &str| run(&["--summary", "s.json", "--progress-every", s]);
    let checkpoint = |s: &str| run(&["--checkpoint", "c.ckpt", "--checkpoint-every", s]);
    let wall = |s: &str| {
        let set = format!("run.max_wall_seconds={s}");
        run(&["--summary", "s.json", "--set", &set])
    };
    let cases: Vec<(Vec<OsString>, &str, &str)> = vec![
        (progress("5e-324"), "--progress-every", "0.1 s"),
        (progress("0.0999"), "--progress-every", "0.1 s"),
        (progress("1e308"), "--progress-every", "1e9 s"),
        (progress("1.0001e9"), "--progress-every", "1e9 s"),
        (checkpoint("5e-324"), "--checkpoint-every", "1e-100"),
        (checkpoint("1e308"), "--checkpoint-every", "1e100"),
        (checkpoint("1e-9"), "--checkpoint-every", "1e5"),
        (wall("5e-324"), "run.max_wall_seconds", "0.001 s"),
        (wall("1e308"), "run.max_wall_seconds", "1e9 s"),
        (
            sweep_run(&["--max-run-seconds", "5e-324"]),
            "--max-run-seconds",
            "0.001 s",
        ),
        (
            sweep_run(&["--progress-every", "5e-324"]),
            "--progress-every",
            "0.1 s",
        ),
        (
            sweep_run(&["--progress-every", "1e308"]),
            "--progress-every",
            "1e9 s",
        ),
        (plan("5e-324"), "--estimate", "0.001 s"),
        (plan("1e308"), "--estimate", "1e9 s"),
    ];
    for (i, (args, option, bound)) in cases.iter().enumerate() {
        let dir = fresh_dir(&format!("bad-interval-{i}"));
        let out = vibrobed(&dir, args);
        assert_refused(&out, &[option], &dir, &[]);
        let line = error_line(&out.stderr).unwrap_or_default();
        assert!(
            line.contains(bound),
            "{line:?} does not name the bound {bound}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
    for (args, written) in [
        (progress("0.1"), "s.json"),
        (progress("1e9"), "s.json"),
        (checkpoint("1e100"), "c.ckpt"),
        (wall("1e9"), "s.json"),
        (sweep_run(&["--max-run-seconds", "1e9"]), "out/plan.json"),
    ] {
        let dir = fresh_dir("interval-at-bound");
        let out = vibrobed(&dir, &args);
        assert_eq!(out.code(), Some(0), "{}", out.describe());
        assert!(dir.join(written).exists(), "{}", out.describe());
        let _ = std::fs::remove_dir_all(&dir);
    }
    let _ = std::fs::remove_dir_all(&home);
}

#[test]
fn a_set_path_of_60000_fields_is_refused_at_once() {
    let key = vec!["a"; 60_000].join(".");
    let set = format!("{key}=1");
    check_refuses("deep-set", "vibrated_bed.json", &[&set], &["--set"]);
}

/// The deep bed 10⁶ times wider (domain.width = 2e8, 20 000 disks): the placement's rows sit at
/// one end of the region, and the Monte Carlo that melts them once merged its cells until a few
/// coarse cells held every disk — each trial looked at thousands, minutes deaf to SIGINT (the
/// fields fuzz found it). Cells now stay 2 radii wide, a list per occupied one: `check` and a
/// short run end by themselves, well within the limit (0.7 s each on an idle core).
#[test]
fn a_bed_a_million_times_wider_than_deep_is_placed_at_once() {
    let dir = fresh_dir("bad-wide-bed");
    let sets = ["domain.width=2e8"];
    let runs = [
        check("deep_bed.json", &sets),
        run_args(
            "deep_bed.json",
            &["--summary", "s.json"],
            &[sets[0], "run.duration=0.05", "run.warmup=0"],
        ),
    ];
    for args in runs {
        let out = vibrobed(&dir, &args);
        let what = out.describe();
        assert!(!out.panicked(), "panicked: {what}");
        assert!(
            out.interrupted_at.is_none(),
            "did not end by itself within {LIMIT_SECS} s: {what}"
        );
        assert_eq!(out.code(), Some(0), "{what}");
    }
    assert!(dir.join("s.json").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

// --- Speeds the engine cannot run with. ---

#[test]
fn speeds_beyond_what_a_run_can_simulate_are_refused_naming_them() {
    let one_disk = |v: &str| {
        format!(r#"particles.placement={{"positions": [[10, 1]], "velocities": [[0, {v}]]}}"#)
    };
    let thrown = one_disk("1e200");
    let cases: [(&str, &str, Vec<&str>, &str); 4] = [
        (
            "velocity-1e200",
            "vibrated_bed.json",
            vec!["particles.count=1", &thrown],
            "particles.placement.velocities",
        ),
        (
            "inlet-1e308",
            "silo.json",
            vec!["inlets.0.speed=1e308"],
            "inlets.0.speed",
        ),
        (
            "temperature-1e308",
            "vibrated_bed.json",
            vec!["particles.temperature=1e308"],
            "particles.temperature",
        ),
        (
            "inertia-subnormal",
            "rough_vibrated_bed.json",
            vec!["particles.inertia_factor=5e-324"],
            "particles.inertia_factor",
        ),
    ];
    for (test, scene, sets, field) in cases {
        check_refuses(test, scene, &sets, &[field]);
    }
}

/// One disk thrown up at `speed` from a static floor, under the other `sets`.
fn thrown_disk(speed: &str, sets: &[&str]) -> Vec<OsString> {
    let placement =
        format!(r#"particles.placement={{"positions": [[10, 1]], "velocities": [[0, {speed}]]}}"#);
    let mut all = vec![
        "particles.count=1",
        &placement,
        "floor.gamma=null",
        "floor.frequency=null",
        "run.warmup=0",
    ];
    all.extend(sets);
    run_args("vibrated_bed.json", &["--summary", "s.json"], &all)
}

#[test]
fn the_event_limit_counts_re_mappings() {
    // At 10⁹ the grid is re-mapped about once a radius of flight: 10⁹ re-mappings in the run.
    let dir = fresh_dir("bad-remap-limit");
    let args = thrown_disk("1e9", &["run.duration=1", "run.max_events=1000"]);
    let out = vibrobed(&dir, &args);
    let what = out.describe();
    // A run stopped by its event limit exits 4, its summary written.
    assert_eq!(out.code(), Some(4), "{what}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("s.json")).expect("summary"))
            .expect("json");
    assert_eq!(s["ending"], "event-limit", "{what}");
    assert_eq!(s["events"]["rebuild"], 1000, "{what}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn re_mappings_that_leave_the_clock_standing_end_the_run_with_its_report() {
    // At 10⁹⁰ over a run of 10⁻⁸⁰ the disk crosses a radius in 10⁻⁹⁰: the clock moves by
    // less than the stall guard's span over its 10⁷ events (some 15 s of re-mappings).
    let dir = fresh_dir("bad-remap-stall");
    let args = thrown_disk(
        "1e90",
        &["run.duration=1e-80", "output.frame_interval=1e-82"],
    );
    let logs = dir.with_extension("logs");
    let out = guarded::run(&args, &dir, &logs, Limits::secs(120));
    let _ = std::fs::remove_dir_all(&logs);
    let what = out.describe();
    assert_eq!(out.code(), Some(6), "{what}");
    assert!(
        out.stderr.contains("simulated time has stopped advancing")
            && out.stderr.contains("re-mapping ×"),
        "{what}"
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("s.json")).expect("summary"))
            .expect("json");
    assert_eq!(s["ending"], "stalled", "{what}");
    let _ = std::fs::remove_dir_all(&dir);
}

// --- Outputs over inputs or over each other. ---

#[test]
fn a_summary_over_the_scenario_is_refused_and_the_scenario_kept() {
    let dir = fresh_dir("bad-over-scenario");
    let text = std::fs::read_to_string(scenario("bouncing_ball.json")).expect("scenario");
    std::fs::write(dir.join("s.json"), &text).expect("copy");
    std::fs::create_dir(dir.join("sub")).expect("a directory");
    // The same file under another spelling.
    for summary in ["s.json", "./sub/../s.json"] {
        let args = guarded::args(&["run", "s.json", "--quiet", "--summary", summary]);
        let out = vibrobed(&dir, &args);
        assert_refused(&out, &["--summary"], &dir, &["s.json", "sub"]);
        let kept = std::fs::read_to_string(dir.join("s.json")).expect("scenario");
        assert_eq!(kept, text, "the scenario was changed");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn two_outputs_on_one_path_are_refused() {
    run_refuses(
        "same-output",
        "vibrated_bed.json",
        &["--profiles", "x.csv", "--fields", "x.csv"],
        SHORT,
        &["--fields"],
    );
    run_refuses(
        "same-output-spelled",
        "vibrated_bed.json",
        &["--summary", "x.json", "--trajectory", "./x.json"],
        SHORT,
        &["--trajectory"],
    );
}

/// A streamed output goes to `FILE.partial`, a checkpoint to `FILE.tmp`, until complete: another
/// output given that name would be overwritten by it (or replace it mid-run), and a scenario so
/// named would be destroyed.
#[test]
fn an_output_on_another_s_temporary_name_is_refused() {
    run_refuses(
        "over-partial",
        "vibrated_bed.json",
        &["--trajectory", "t.xyz", "--checkpoint", "t.xyz.partial"],
        SHORT,
        &["--checkpoint"],
    );
    run_refuses(
        "over-tmp",
        "vibrated_bed.json",
        &["--checkpoint", "c.ckpt", "--trajectory", "./c.ckpt.tmp"],
        SHORT,
        &["--trajectory"],
    );
    let dir = fresh_dir("bad-scenario-as-partial");
    let text = std::fs::read_to_string(scenario("bouncing_ball.json")).expect("scenario");
    std::fs::write(dir.join("t.xyz.partial"), &text).expect("copy");
    let args = guarded::args(&["run", "t.xyz.partial", "--quiet", "--trajectory", "t.xyz"]);
    let out = vibrobed(&dir, &args);
    assert_refused(&out, &["--trajectory"], &dir, &["t.xyz.partial"]);
    let kept = std::fs::read_to_string(dir.join("t.xyz.partial")).expect("scenario");
    assert_eq!(kept, text, "the scenario was changed");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs the shipped `scene` to `cut` with a checkpoint `c.ckpt` in a fresh directory.
fn checkpointed(test: &str, scene: &str, sets: &[&str], cut: &str) -> std::path::PathBuf {
    let dir = fresh_dir(&format!("bad-{test}"));
    let duration = format!("run.duration={cut}");
    let mut all = vec!["run.warmup=0", &duration];
    all.extend(sets);
    let args = run_args(
        scene,
        &["--checkpoint", "c.ckpt", "--summary", "first.json"],
        &all,
    );
    let out = vibrobed(&dir, &args);
    assert_eq!(out.code(), Some(0), "{}", out.describe());
    dir
}

/// `resume c.ckpt EXTRA...` in `dir` is refused naming `field`, the checkpoint unchanged and
/// nothing else written.
fn resume_refuses(dir: &Path, extra: &[&str], field: &str) {
    let saved = std::fs::read(dir.join("c.ckpt")).expect("checkpoint");
    let mut words = vec!["resume", "c.ckpt", "--quiet"];
    words.extend(extra);
    let out = vibrobed(dir, &guarded::args(&words));
    assert_refused(&out, &[field], dir, &["c.ckpt", "first.json"]);
    assert_eq!(
        std::fs::read(dir.join("c.ckpt")).expect("checkpoint"),
        saved
    );
}

#[test]
fn a_summary_over_the_resumed_checkpoint_is_refused() {
    let dir = checkpointed("over-checkpoint", "bouncing_ball.json", &[], "1");
    resume_refuses(&dir, &["--summary", "c.ckpt"], "--summary");
    resume_refuses(
        &dir,
        &["--checkpoint", "d.ckpt", "--profiles", "./c.ckpt"],
        "--profiles",
    );
    // A resume checkpoints into the file it resumed, through `c.ckpt.tmp`.
    resume_refuses(&dir, &["--trajectory", "c.ckpt.tmp"], "--trajectory");
    let _ = std::fs::remove_dir_all(&dir);
}

// --- Resume across a change of duration, where a default follows the duration. ---

#[test]
fn a_resume_longer_is_refused_where_a_default_follows_the_duration() {
    // An inlet without `end` that brings disks: its window is the run.
    let dir = checkpointed("resume-inlet", "silo.json", &["inlets.0.rate=5"], "2");
    resume_refuses(&dir, &["--set", "run.duration=4"], "run.duration");
    let _ = std::fs::remove_dir_all(&dir);
    // Samples a 200th of the run apart.
    let dir = checkpointed(
        "resume-sampling",
        "bouncing_ball.json",
        &["output.frame_interval=null", "output.sample_interval=null"],
        "1",
    );
    resume_refuses(&dir, &["--set", "run.duration=2"], "run.duration");
    let _ = std::fs::remove_dir_all(&dir);
    // Frames a 200th of the run apart, in a trajectory written by the resume.
    let dir = checkpointed(
        "resume-frames",
        "bouncing_ball.json",
        &["output.frame_interval=null", "output.sample_interval=0.01"],
        "1",
    );
    resume_refuses(
        &dir,
        &["--set", "run.duration=2", "--trajectory", "t.xyz"],
        "run.duration",
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// --- Wrong blame: each message names the field the user set. ---

#[test]
fn a_bad_duration_of_a_scene_with_inlets_is_blamed_on_the_duration() {
    check_refuses(
        "silo-duration",
        "silo.json",
        &["run.duration=-1"],
        &["run.duration"],
    );
    check_refuses(
        "silo-start",
        "silo.json",
        &["run.duration=12", "inlets.0.start=13"],
        &["inlets.0.start"],
    );
    // A duration set shorter than the file's warm-up (10) is the duration's fault ...
    check_refuses(
        "silo-short",
        "silo.json",
        &["run.duration=5"],
        &["run.duration"],
    );
    // ... and a warm-up set past the file's duration (60), the warm-up's.
    check_refuses(
        "silo-warmup",
        "silo.json",
        &["run.warmup=70"],
        &["run.warmup"],
    );
}

// --- sweep collect: a bad plot or axis is refused before any table is written. ---

/// A sweep of the bouncing ball over two restitutions, one short run each, run in `dir`/out.
fn small_sweep(dir: &Path) {
    let ball = scenario("bouncing_ball.json");
    let sweep = serde_json::json!({
        "name": "ball",
        "scenario": ball,
        "set": ["run.duration=1", "run.warmup=0"],
        "axes": [{ "key": "floor.restitution", "values": [0.5, 0.9] }],
        "seeds": 1
    });
    std::fs::write(dir.join("ball.json"), sweep.to_string()).expect("sweep file");
    let args = guarded::args(&["sweep", "run", "ball.json", "--out", "out", "--quiet"]);
    let out = vibrobed(dir, &args);
    assert_eq!(out.code(), Some(0), "{}", out.describe());
}

#[test]
fn sweep_collect_refuses_a_plot_over_the_sweep_s_files_or_a_bad_axis_writing_nothing() {
    let dir = fresh_dir("bad-collect");
    small_sweep(&dir);
    let out = dir.join("out");
    let plan = std::fs::read(out.join("plan.json")).expect("plan");
    let ran = entries(&out);
    let x = ["--x", "floor.restitution", "--y", "com_height"];
    let cases: [(&[&str], &str); 5] = [
        (&["--x", "nope", "--y", "com_height"], "--x"),
        (&["--plot", "out/plan.json"], "--plot"),
        (&["--plot", "out/0"], "--plot"),
        (&["--plot", "./out/1/plot.svg"], "--plot"),
        (&["--plot", "missing/plot.svg"], "--plot"),
    ];
    for (extra, field) in cases {
        let mut words = vec!["sweep", "collect", "out"];
        if field == "--plot" {
            words.extend(x);
        }
        words.extend(extra);
        let got = vibrobed(&dir, &guarded::args(&words));
        let allowed: Vec<&str> = ran.iter().map(String::as_str).collect();
        assert_refused(&got, &[field], &out, &allowed);
        let plan_now = std::fs::read(out.join("plan.json")).expect("plan");
        assert!(plan_now == plan, "{words:?} changed the sweep's plan");
    }
    // The same plot elsewhere is drawn.
    let mut words = vec!["sweep", "collect", "out", "--plot", "plot.svg"];
    words.extend(x);
    let got = vibrobed(&dir, &guarded::args(&words));
    assert_eq!(got.code(), Some(0), "{}", got.describe());
    assert!(dir.join("plot.svg").exists() && out.join("runs.csv").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

// --- What frames and samples cost. ---

/// Each frame and each sample visits every disk (some nanoseconds each): 10⁶ disks with 10⁶
/// frames and samples are 2·10¹² visits, hours of a run doing little else. Refused before the
/// run naming the interval that asks for them; at the bound, accepted.
#[test]
fn frames_and_samples_of_many_disks_are_bounded_by_their_visits() {
    let many = "particles.count=1000000";
    check_refuses(
        "visits-frames",
        "vibrated_bed.json",
        &[many, "output.frame_interval=2e-4"],
        &["output.frame_interval"],
    );
    check_refuses(
        "visits-samples",
        "vibrated_bed.json",
        &[many, "output.sample_interval=2e-4"],
        &["output.sample_interval"],
    );
    // The frame interval alone sets both (samples follow frames): 10⁶ × 2 × (200/dt + 1).
    let text = std::fs::read_to_string(scenario("vibrated_bed.json")).expect("scenario");
    let with = |dt: f64| {
        let sets = [many.to_string(), format!("output.frame_interval={dt:e}")];
        Scenario::from_json_with_overrides(&text, &sets)
    };
    let dt = 200.0 / (MAX_OUTPUT_VISITS / 2e6 - 1.0);
    assert!(with(dt * (1.0 + 1e-9)).is_ok(), "refused at the bound");
    let past = with(dt * (1.0 - 1e-9)).expect_err("accepted past the bound");
    assert!(
        past.to_string().starts_with("output.frame_interval: "),
        "{past}"
    );
}

/// A run interrupted while its scene is built (10⁶ disks: seconds of placement and of the
/// engine's grid, lists and first predictions before the first event, 20 times as long for the
/// largest scenes) ends at once: exit 130, said on stderr, nothing written — not the summary,
/// not the checkpoint.
#[test]
fn a_run_interrupted_while_its_scene_is_built_ends_at_once_writing_nothing() {
    let dir = fresh_dir("interrupted-build");
    let path = scenario("gas_periodic_phi03.json").display().to_string();
    let words = [
        "run",
        &path,
        "--quiet",
        "--summary",
        "summary.json",
        "--checkpoint",
        "c.ckpt",
        "--set",
        "particles.count=1000000",
        "--set",
        "domain.width=900",
    ];
    let out = interrupted(&words, &dir, Duration::from_secs(1), 2 * STOP_GRACE, || {
        false
    });
    let what = out.describe();
    assert_eq!(out.code(), Some(130), "{what}");
    assert!(out.stderr.contains("before its first event"), "{what}");
    assert!(out.stdout.is_empty(), "{what}");
    assert!(
        entries(&dir).is_empty(),
        "files written: {:?}",
        entries(&dir)
    );
    let at = out.interrupted_at.expect("interrupted");
    assert!(out.elapsed - at <= STOP_GRACE, "{what}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// An accuracy report interrupted while a variant runs (found by the commands fuzz: a floor
/// thrown at 5·10⁵ makes the time-step variants run for minutes; the command watched no signal)
/// stops the run in hand: exit 130 within the grace, said on stderr, and no report written.
#[test]
fn an_accuracy_report_interrupted_as_it_runs_exits_130_writing_nothing() {
    let dir = fresh_dir("interrupted-accuracy");
    let path = scenario("bouncing_ball.json").display().to_string();
    let words = [
        "accuracy",
        &path,
        "--quick",
        "--quiet",
        "--out",
        "a",
        "--cores",
        "1",
        "--set",
        "run.duration=2",
        "--set",
        "run.warmup=0",
        "--set",
        "floor.amplitude=5e5",
    ];
    let out = interrupted(&words, &dir, Duration::from_secs(3), 2 * STOP_GRACE, || {
        false
    });
    let what = out.describe();
    assert_eq!(out.code(), Some(130), "{what}");
    assert!(out.stderr.contains("interrupted"), "{what}");
    assert!(
        entries(&dir).is_empty(),
        "files written: {:?}",
        entries(&dir)
    );
    let at = out.interrupted_at.expect("interrupted");
    assert!(out.elapsed - at <= STOP_GRACE, "{what}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A sweep interrupted while its first run builds its scene (2·10⁵ disks: about a second of
/// placement and of the engine's build) stops once that build ends, as the book's Sweeps page
/// says: exit 130; its sweep file and scenario untouched; its folder holds the plan and run 0's
/// summary, marked `interrupted` at t = 0 (a rerun runs it again), and no other run started.
#[test]
fn a_sweep_interrupted_while_its_first_run_builds_exits_130_keeping_its_inputs() {
    let dir = fresh_dir("interrupted-sweep-build");
    let scene = dir.join("gas.json");
    std::fs::copy(scenario("gas_periodic_phi03.json"), &scene).expect("a scenario");
    let sweep = serde_json::json!({
        "name": "big",
        "scenario": "gas.json",
        "set": ["particles.count=200000", "domain.width=400"],
        "axes": [{ "key": "collisions.restitution", "values": [0.9, 0.95] }],
        "seeds": 1
    })
    .to_string();
    std::fs::write(dir.join("big.json"), &sweep).expect("sweep file");
    let inputs = || {
        (
            std::fs::read(&scene).ok(),
            std::fs::read(dir.join("big.json")).ok(),
        )
    };
    let before = inputs();
    let words = ["sweep", "run", "big.json", "--out", "out", "--jobs", "1"];
    // Run 0's folder is made just before it builds its scene. (The plan, written as the pool
    // starts, is too early a sign: a signal before the first worker looks starts no run.)
    let out = dir.join("out");
    let first_run = out.join("0");
    let got = interrupted(
        &words,
        &dir,
        Duration::from_secs(60),
        6 * STOP_GRACE,
        || first_run.exists(),
    );
    let what = got.describe();
    assert_eq!(got.code(), Some(130), "{what}");
    assert!(
        inputs() == before,
        "the sweep file or its scenario changed: {what}"
    );
    assert_eq!(entries(&dir), ["big.json", "gas.json", "out"], "{what}");
    assert_eq!(entries(&out), ["0", "plan.json"], "{what}");
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("0").join("summary.json")).expect("run 0's summary"),
    )
    .expect("a summary");
    assert_eq!(summary["ending"], "interrupted", "{what}");
    assert_eq!(
        summary["sim_time"], 0.0,
        "interrupted before its first event: {what}"
    );
    assert!(!vibrobed::studies::sweep::local::is_done(&out, 0));
    let _ = std::fs::remove_dir_all(&dir);
}

// --- The work a run is asked for. ---

/// The gas of 2500 disks of radius 1/2 at T = 1 (mass 1: speed 1, a crossing every 1/2): its
/// work bound is 10¹² crossings at a duration of 10¹² / (2500 × 2) = 2·10⁸, worked out here
/// by hand, not by the code under test.
const GAS_LONGEST: f64 = 2e8;

/// The gas run for `duration`, its samples left to follow the frames, with `more` sets.
fn gas_for(duration: f64, more: &[&str]) -> vibrobed::error::Result<Scenario> {
    let text = std::fs::read_to_string(scenario("gas_periodic_phi03.json")).expect("scenario");
    let mut sets = vec![
        format!("run.duration={duration:e}"),
        "output.sample_interval=null".to_string(),
    ];
    sets.extend(more.iter().map(|s| s.to_string()));
    Scenario::from_json_with_overrides(&text, &sets)
}

/// Disks × duration past 10¹² crossings is refused naming `run.duration` and the bound; at the
/// bound it is accepted.
#[test]
fn the_work_of_a_run_is_bounded_at_its_limit() {
    assert!(
        gas_for(GAS_LONGEST * (1.0 - 1e-9), &[]).is_ok(),
        "refused within the bound"
    );
    let past = gas_for(GAS_LONGEST * (1.0 + 1e-9), &[]).expect_err("accepted past the bound");
    let text = past.to_string();
    assert!(text.starts_with("run.duration: "), "{text}");
    assert!(
        text.contains("at most 1e12"),
        "the bound is not named: {text}"
    );
    assert!(
        text.contains("2.000e8"),
        "the longest duration is not named: {text}"
    );
}

/// Past the bound, a run that bounds itself is accepted: `run.max_events` up to 10¹⁵ (one
/// more is refused naming it), or any `run.max_wall_seconds`.
#[test]
fn a_budget_of_the_scene_s_own_lets_a_run_past_the_work_bound() {
    let long = 10.0 * GAS_LONGEST;
    assert!(gas_for(long, &["run.max_events=1000000000000000"]).is_ok());
    let past = gas_for(long, &["run.max_events=1000000000000001"]).expect_err("past 1e15");
    assert!(past.to_string().starts_with("run.max_events: "), "{past}");
    assert!(gas_for(long, &["run.max_wall_seconds=3600"]).is_ok());
    // Within the bound, an event limit needs no bound of its own.
    assert!(gas_for(GAS_LONGEST / 2.0, &["run.max_events=18446744073709551615"]).is_ok());
}

/// A step scheme's own `engine.dt` sets the pace when shorter than a crossing: ten steps
/// count as one; refused naming `engine.dt`, at the bound accepted.
#[test]
fn a_step_scheme_s_work_is_counted_in_its_steps() {
    let duration = 4.0;
    // 2500 × 4 / (10 dt) = 10¹² at dt = 10⁻⁹ (a crossing takes 1/2), 4·10⁹ steps.
    let dt = 1e-9;
    let with = |dt: f64| {
        let step = format!("engine.dt={dt:e}");
        gas_for(
            duration,
            &["run.warmup=0", "engine.scheme=time-step", &step],
        )
    };
    if let Err(e) = with(dt * (1.0 + 1e-9)) {
        panic!("refused within the bound: {e}");
    }
    let past = with(dt * (1.0 - 1e-9)).expect_err("accepted past the bound");
    assert!(past.to_string().starts_with("engine.dt: "), "{past}");
}

/// Issue 62's case: 10⁹ time units of the thousand-disk bed are refused by `check` and by
/// `run`, exit 2 naming `run.duration`, nothing written.
#[test]
fn a_billion_time_units_of_a_thousand_disks_are_refused() {
    let sets = ["run.duration=1e9", "output.frame_interval=null"];
    check_refuses("work-check", "vibrated_bed.json", &sets, &["run.duration"]);
    run_refuses(
        "work-run",
        "vibrated_bed.json",
        &["--summary", "s.json", "--checkpoint", "c.ckpt"],
        &sets,
        &["run.duration"],
    );
}

/// The work's refusal names the factor the user set when the duration was not set: the field
/// of the scene's speed, or the disks' count; the duration when it was set.
#[test]
fn the_work_s_refusal_names_the_factor_that_was_set() {
    let bed = std::fs::read_to_string(scenario("vibrated_bed.json")).expect("scenario");
    // The same bed, run for 10⁵ in its file: 1.9·10⁸ crossings, 10⁴ times as many disks past
    // the bound.
    let long_bed = bed.replace("\"duration\": 200.0", "\"duration\": 1e5");
    assert_ne!(long_bed, bed, "the bed's duration moved in its file");
    let refused = |text: &str, sets: &[&str]| {
        let mut all = vec!["output.frame_interval=null".to_string()];
        all.extend(sets.iter().map(|s| s.to_string()));
        let e = Scenario::from_json_with_overrides(text, &all).expect_err("past the bound");
        let line = e.to_string();
        assert!(
            line.contains("disk crossings"),
            "not the work's refusal: {line}"
        );
        line.split_once(": ").expect("a field").0.to_string()
    };
    assert_eq!(
        refused(&bed, &["particles.temperature=4.5e18"]),
        "particles.temperature"
    );
    assert_eq!(
        refused(&long_bed, &["particles.count=10000000"]),
        "particles.count"
    );
    assert_eq!(
        refused(&long_bed, &["particles.count=10000000", "run.duration=1e5"]),
        "run.duration"
    );
    assert!(Scenario::from_json_with_overrides(&long_bed, &[]).is_ok());
}
