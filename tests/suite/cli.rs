//! The command-line contract (the book's docs/book/src/command-line.md), checked on the real
//! binary: exit codes, where the summary goes, `--set`, and that every kind of bad input exits 2
//! with a message naming the field, without writing a summary.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A tiny scene that runs in a blink: 50 elastic disks in a periodic box.
const TINY: &str = r#"{
  "name": "tiny periodic gas",
  "seed": 11,
  "domain": { "width": 12.0, "x_boundary": "periodic", "y_boundary": "periodic" },
  "particles": { "count": 50, "radius": 0.5, "packing_fraction": 0.3, "temperature": 1.0 },
  "run": { "duration": 0.5, "warmup": 0.1 }
}"#;

/// A fresh, empty scratch directory for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cli-{test}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// Writes `text` as `name` in `dir` and returns its path.
fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write test file");
    path
}

/// Runs the binary with `args` (from the crate root, so relative scenario paths work).
fn vibrobed<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vibrobed"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .expect("the vibrobed binary starts")
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A one-line account of a finished process, for assertion messages.
fn describe(out: &Output) -> String {
    format!(
        "exit {:?}\n--- stdout ---\n{}\n--- stderr ---\n{}",
        out.status.code(),
        stdout(out),
        stderr(out)
    )
}

/// Asserts a successful exit.
fn assert_ok(out: &Output) {
    assert_eq!(
        out.status.code(),
        Some(0),
        "expected success: {}",
        describe(out)
    );
    assert!(!stderr(out).contains("panicked"), "{}", describe(out));
}

/// Looks up a dotted path in a JSON value.
fn at<'a>(v: &'a Value, path: &str) -> Option<&'a Value> {
    path.split('.').try_fold(v, |v, key| v.get(key))
}

/// Asserts the summary carries every field the contract names.
fn assert_contract_fields(summary: &Value) {
    for path in [
        "scenario",
        "particles",
        "sim_time",
        "wall_seconds",
        "events.pair",
        "events.floor",
        "events.wall",
        "events.rebuild",
        "collisions_per_second",
        "energy.initial.kinetic",
        "energy.initial.potential",
        "energy.final.kinetic",
        "energy.final.potential",
        "energy.injected",
        "energy.dissipated",
        "temperature.x",
        "temperature.y",
        "max_overlap",
    ] {
        assert!(
            at(summary, path).is_some(),
            "summary lacks `{path}`:\n{summary:#}"
        );
    }
    assert!(summary["scenario"].is_string());
    assert!(summary["particles"].is_u64());
    assert!(summary["events"]["pair"].is_u64());
    for path in [
        "sim_time",
        "wall_seconds",
        "collisions_per_second",
        "max_overlap",
    ] {
        assert!(
            at(summary, path).unwrap().is_number(),
            "`{path}` is not a number"
        );
    }
}

#[test]
fn check_accepts_a_shipped_scenario() {
    let out = vibrobed(&["check", "scenarios/gas_periodic_phi03.json"]);
    assert_ok(&out);
    assert!(
        stdout(&out).is_empty(),
        "check prints nothing on stdout: {}",
        describe(&out)
    );
}

/// A bed that can rest in a width of exactly a whole number of diameters gets a note (it is
/// valid, exit 0); a width off the multiple does not.
#[test]
fn check_notes_a_width_of_a_whole_number_of_diameters() {
    let file = "scenarios/hard/bed_at_rest_tc.json";
    let out = vibrobed(&["check", file, "--set", "domain.width=4"]);
    assert_ok(&out);
    let err = stderr(&out);
    assert!(
        err.contains("note: domain.width = 4 is exactly 4 disk diameters"),
        "{}",
        describe(&out)
    );
    let out = vibrobed(&["check", file]);
    assert_ok(&out);
    assert!(!stderr(&out).contains("note:"), "{}", describe(&out));
    // A floor vibrated with Γ > 1 does not let the bed rest: no note (sampled often enough that
    // the window resolves the floor's periods, which would have a note of its own).
    let shaken = [
        "check",
        file,
        "--set",
        "domain.width=4",
        "--set",
        r#"floor={"gamma": 2.0, "frequency": 1.0, "restitution": 0.5}"#,
        "--set",
        "output.sample_interval=0.05",
    ];
    let out = vibrobed(&shaken);
    assert_ok(&out);
    assert!(!stderr(&out).contains("note:"), "{}", describe(&out));
}

/// A bed that can rest, with inelastic collisions and no cure, on the exact engine, gets a note
/// that it may collapse (valid, exit 0); with a cure, elastic collisions, a floor that throws the
/// bed off, or on `auto` (which runs such a bed on the hybrid scheme), none.
#[test]
fn check_notes_a_resting_bed_without_a_cure() {
    let file = "scenarios/hard/bed_at_rest_tc.json";
    let bare = |e: &str| format!(r#"collisions={{"restitution": {e}}}"#);
    let exact = "engine.scheme=event-driven";
    let out = vibrobed(&["check", file, "--set", &bare("0.5"), "--set", exact]);
    assert_ok(&out);
    assert!(
        stderr(&out).contains("note: collisions.restitution = 0.5 with no cure"),
        "{}",
        describe(&out)
    );
    let out = vibrobed(&["check", file, "--set", &bare("0.5")]);
    assert_ok(&out);
    assert!(!stderr(&out).contains("note:"), "{}", describe(&out));
    let out = vibrobed(&["check", file, "--set", &bare("1.0"), "--set", exact]);
    assert_ok(&out);
    assert!(!stderr(&out).contains("note:"), "{}", describe(&out));
    let thrown = [
        "check",
        file,
        "--set",
        &bare("0.5"),
        "--set",
        r#"floor={"gamma": 2.0, "frequency": 1.0, "restitution": 0.5}"#,
        "--set",
        "output.sample_interval=0.05",
        "--set",
        exact,
    ];
    let out = vibrobed(&thrown);
    assert_ok(&out);
    assert!(!stderr(&out).contains("note:"), "{}", describe(&out));
}

/// A deep pile that can rest with the speed cutoff gets a note that it may keep rattling; a
/// shallow one, or one with TC, does not.
#[test]
fn check_notes_the_speed_cutoff_in_a_deep_pile() {
    let file = "scenarios/hard/pile_poly_walls_cutoff.json";
    let deep = ["particles.count=400", "domain.width=20.3"];
    let mut args = vec!["check", file];
    for set in deep {
        args.extend(["--set", set]);
    }
    let out = vibrobed(&args);
    assert_ok(&out);
    assert!(
        stderr(&out).contains("note: collisions.speed_cutoff = 0.01 in a pile about 20 layers"),
        "{}",
        describe(&out)
    );
    let out = vibrobed(&["check", file]);
    assert_ok(&out);
    assert!(!stderr(&out).contains("note:"), "{}", describe(&out));
}

#[test]
fn run_prints_the_summary_on_stdout() {
    let dir = scratch("stdout");
    let scenario = write(&dir, "tiny.json", TINY);
    let out = vibrobed(&["run".as_ref(), "--quiet".as_ref(), scenario.as_os_str()]);
    assert_ok(&out);
    let summary: Value = serde_json::from_str(&stdout(&out))
        .unwrap_or_else(|e| panic!("stdout is not a JSON summary ({e}): {}", describe(&out)));
    assert_contract_fields(&summary);
    assert_eq!(summary["scenario"], "tiny periodic gas");
    assert_eq!(summary["particles"], 50);
    assert_eq!(summary["ending"], "completed");
    assert!((summary["sim_time"].as_f64().unwrap() - 0.5).abs() < 1e-12);
    assert!(summary["events"]["pair"].as_u64().unwrap() > 0);
    // Elastic and closed: the energy does not move.
    let e0 = summary["energy"]["initial"]["kinetic"].as_f64().unwrap();
    let e1 = summary["energy"]["final"]["kinetic"].as_f64().unwrap();
    assert!((e1 - e0).abs() <= 1e-9 * e0, "energy drifted: {e0} → {e1}");
}

#[test]
fn run_writes_the_summary_file_and_leaves_stdout_empty() {
    let dir = scratch("summary-file");
    let scenario = write(&dir, "tiny.json", TINY);
    let summary_path = dir.join("out.json");
    let out = vibrobed(&[
        "run".as_ref(),
        scenario.as_os_str(),
        "--summary".as_ref(),
        summary_path.as_os_str(),
    ]);
    assert_ok(&out);
    assert!(
        stdout(&out).is_empty(),
        "stdout must be empty with --summary: {}",
        describe(&out)
    );
    let text = std::fs::read_to_string(&summary_path).expect("summary file written");
    let summary: Value = serde_json::from_str(&text).expect("summary file is JSON");
    assert_contract_fields(&summary);
    assert_eq!(summary["particles"], 50);
    // The atomic write leaves no temporary file behind.
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "tiny.json" && n != "out.json")
        .collect();
    assert!(leftovers.is_empty(), "unexpected files: {leftovers:?}");
}

#[test]
fn set_overrides_a_field() {
    let dir = scratch("set");
    let scenario = write(&dir, "tiny.json", TINY);
    let out = vibrobed(&[
        "run".as_ref(),
        "-q".as_ref(),
        scenario.as_os_str(),
        "--set".as_ref(),
        "particles.count=60".as_ref(),
        "--set".as_ref(),
        "run.duration=0.25".as_ref(),
    ]);
    assert_ok(&out);
    let summary: Value = serde_json::from_str(&stdout(&out)).expect("JSON summary");
    assert_eq!(summary["particles"], 60, "{summary:#}");
    assert!((summary["sim_time"].as_f64().unwrap() - 0.25).abs() < 1e-12);
    // `check` takes the same overrides.
    let out = vibrobed(&[
        "check".as_ref(),
        scenario.as_os_str(),
        "--set".as_ref(),
        "particles.count=60".as_ref(),
    ]);
    assert_ok(&out);
    assert!(stderr(&out).contains("60 disks"), "{}", describe(&out));
}

/// Runs `vibrobed run SCENARIO --summary OUT [extra…]` and `vibrobed check SCENARIO [extra…]`
/// and asserts both exit 2 naming every one of `names` on stderr, without a panic and without
/// a summary file.
fn assert_bad_input(case: &str, scenario: &Path, extra: &[&str], names: &[&str]) {
    let dir = scenario.parent().unwrap().to_path_buf();
    let summary_path = dir.join(format!("{case}-summary.json"));
    let mut run_args: Vec<std::ffi::OsString> = vec![
        "run".into(),
        "-q".into(),
        scenario.into(),
        "--summary".into(),
        summary_path.clone().into(),
    ];
    run_args.extend(extra.iter().map(Into::into));
    let mut check_args: Vec<std::ffi::OsString> = vec!["check".into(), scenario.into()];
    check_args.extend(extra.iter().map(Into::into));
    for (what, args) in [("run", run_args), ("check", check_args)] {
        let out = vibrobed(&args);
        let err = stderr(&out);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{case} ({what}): expected exit 2 for bad input: {}",
            describe(&out)
        );
        assert!(
            !err.contains("panicked"),
            "{case} ({what}) panicked: {}",
            describe(&out)
        );
        for name in names {
            assert!(
                err.contains(name),
                "{case} ({what}): the message does not name `{name}`: {}",
                describe(&out)
            );
        }
        assert!(
            stdout(&out).is_empty(),
            "{case} ({what}): output on stdout: {}",
            describe(&out)
        );
    }
    assert!(
        !summary_path.exists(),
        "{case}: a summary was written despite bad input"
    );
    assert!(
        partials_of(&summary_path).is_empty(),
        "{case}: a partial summary was left behind: {:?}",
        partials_of(&summary_path)
    );
}

/// Temporary files beside `path` named after it (a summary is written to one, then renamed).
fn partials_of(path: &std::path::Path) -> Vec<String> {
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    std::fs::read_dir(path.parent().unwrap())
        .map(|it| {
            it.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.contains(&name) && n.contains("partial"))
                .collect()
        })
        .unwrap_or_default()
}

/// The tiny scenario with one field replaced (`pointer` is a JSON pointer).
fn tiny_with(pointer: &str, value: Value) -> String {
    let mut v: Value = serde_json::from_str(TINY).unwrap();
    *v.pointer_mut(pointer)
        .unwrap_or_else(|| panic!("no {pointer} in TINY")) = value;
    serde_json::to_string_pretty(&v).unwrap()
}

#[test]
fn malformed_json_is_bad_input() {
    let dir = scratch("malformed");
    let scenario = write(
        &dir,
        "broken.json",
        &TINY.replace("\"seed\": 11,", "\"seed\": 11"),
    );
    assert_bad_input("malformed", &scenario, &[], &["JSON", "line 4"]);
}

#[test]
fn unknown_field_is_bad_input() {
    let dir = scratch("unknown-field");
    let text = TINY.replace("\"count\": 50", "\"cont\": 50");
    let scenario = write(&dir, "unknown.json", &text);
    assert_bad_input("unknown-field", &scenario, &[], &["particles.cont"]);
}

#[test]
fn negative_radius_is_bad_input() {
    let dir = scratch("negative-radius");
    let scenario = write(
        &dir,
        "neg.json",
        &tiny_with("/particles/radius", (-0.5).into()),
    );
    assert_bad_input("negative-radius", &scenario, &[], &["particles.radius"]);
    // The same through an override.
    let scenario = write(&dir, "tiny.json", TINY);
    assert_bad_input(
        "negative-radius-set",
        &scenario,
        &["--set", "particles.radius=-1"],
        &["particles.radius"],
    );
}

#[test]
fn impossible_packing_is_bad_input() {
    let dir = scratch("packing");
    // 500 disks of area π/4 cannot fit in a 10 × 10 box.
    let text = r#"{
      "name": "overfull box",
      "domain": { "width": 10.0, "height": 10.0, "y_boundary": "lid" },
      "floor": {},
      "particles": { "count": 500, "radius": 0.5 },
      "run": { "duration": 1.0 }
    }"#;
    let scenario = write(&dir, "overfull.json", text);
    assert_bad_input("too-many-disks", &scenario, &[], &["particles.count"]);
    let scenario = write(&dir, "tiny.json", TINY);
    assert_bad_input(
        "packing-fraction",
        &scenario,
        &["--set", "particles.packing_fraction=0.95"],
        &["particles.packing_fraction"],
    );
}

#[test]
fn bad_overrides_are_bad_input() {
    let dir = scratch("bad-set");
    let scenario = write(&dir, "tiny.json", TINY);
    assert_bad_input(
        "set-into-a-number",
        &scenario,
        &["--set", "particles.count.x=3"],
        &["particles.count"],
    );
    assert_bad_input(
        "set-unknown-field",
        &scenario,
        &["--set", "nosuchfield=1"],
        &["nosuchfield"],
    );
    assert_bad_input(
        "set-without-value",
        &scenario,
        &["--set", "foo"],
        &["--set", "foo"],
    );
    assert_bad_input(
        "set-wrong-enum",
        &scenario,
        &["--set", "domain.x_boundary=sideways"],
        &["domain.x_boundary", "sideways"],
    );
}

#[test]
fn wrong_enum_value_in_the_file_is_bad_input() {
    let dir = scratch("enum");
    let scenario = write(
        &dir,
        "enum.json",
        &tiny_with("/domain/x_boundary", "sideways".into()),
    );
    assert_bad_input(
        "wrong-enum",
        &scenario,
        &[],
        &["domain.x_boundary", "sideways"],
    );
}

#[test]
fn missing_scenario_file_is_bad_input() {
    let dir = scratch("missing");
    let scenario = dir.join("no-such-scenario.json");
    assert_bad_input("missing-file", &scenario, &[], &["no-such-scenario.json"]);
}

#[test]
#[cfg(not(feature = "record"))]
fn rrd_without_the_record_feature_is_bad_input() {
    let dir = scratch("rrd");
    let scenario = write(&dir, "tiny.json", TINY);
    let summary_path = dir.join("summary.json");
    let rrd = dir.join("out.rrd");
    let out = vibrobed(&[
        "run".as_ref(),
        "-q".as_ref(),
        scenario.as_os_str(),
        "--rrd".as_ref(),
        rrd.as_os_str(),
        "--summary".as_ref(),
        summary_path.as_os_str(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", describe(&out));
    assert!(stderr(&out).contains("--rrd"), "{}", describe(&out));
    assert!(!stderr(&out).contains("panicked"), "{}", describe(&out));
    assert!(!summary_path.exists(), "a summary was written");
    assert!(!rrd.exists(), "a recording was written");
}

/// Runs the binary with `args` in the working directory `dir`.
fn vibrobed_in<S: AsRef<std::ffi::OsStr>>(dir: &Path, args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vibrobed"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the vibrobed binary starts")
}

/// The names of the files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn summary_dash_is_stdout() {
    let dir = scratch("summary-dash");
    write(&dir, "tiny.json", TINY);
    let out = vibrobed_in(&dir, &["run", "-q", "tiny.json", "--summary", "-"]);
    assert_ok(&out);
    let summary: Value = serde_json::from_str(&stdout(&out))
        .unwrap_or_else(|e| panic!("stdout is not a JSON summary ({e}): {}", describe(&out)));
    assert_eq!(summary["particles"], 50);
    assert_eq!(listing(&dir), ["tiny.json"], "a file was written");
}

#[test]
fn every_other_output_given_dash_is_refused_by_name() {
    let dir = scratch("output-dash");
    write(&dir, "tiny.json", TINY);
    let bed = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/vibrated_bed.json");
    let cases: [(&str, &[&str], &str); 9] = [
        ("tiny.json", &["--trajectory", "-"], "--trajectory"),
        ("tiny.json", &["--checkpoint", "-"], "--checkpoint"),
        ("tiny.json", &["--rrd", "-"], "--rrd"),
        (bed, &["--profiles", "-"], "--profiles"),
        (bed, &["--fields", "-"], "--fields"),
        (
            "tiny.json",
            &["--set", "output.trajectory=-"],
            "output.trajectory",
        ),
        (
            "tiny.json",
            &["--summary", "-", "--trajectory", "-"],
            "--trajectory",
        ),
        (
            "tiny.json",
            &["--checkpoint", "c.ckpt", "--rrd", "-"],
            "--rrd",
        ),
        (
            bed,
            &["--summary", "s.json", "--profiles", "-"],
            "--profiles",
        ),
    ];
    for (scenario, extra, name) in cases {
        let mut args = vec!["run", "-q", scenario];
        args.extend(extra);
        let out = vibrobed_in(&dir, &args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {}", describe(&out));
        assert!(
            err.contains(name),
            "{extra:?} is not named: {}",
            describe(&out)
        );
        assert!(err.contains("`-`"), "{extra:?}: {}", describe(&out));
        assert!(stdout(&out).is_empty(), "{extra:?}: {}", describe(&out));
        assert_eq!(listing(&dir), ["tiny.json"], "{extra:?} wrote a file");
    }
    let sweep = r#"{"scenario": "tiny.json", "seeds": 1}"#;
    write(&dir, "sweep.json", sweep);
    let commands: [&[&str]; 4] = [
        &["sweep", "run", "sweep.json", "--out", "-"],
        &["sweep", "task", "sweep.json", "--index", "0", "--out", "-"],
        &["sweep", "slurm", "sweep.json", "--out", "-"],
        &["accuracy", "tiny.json", "--quick", "--out", "-"],
    ];
    for args in commands {
        let out = vibrobed_in(&dir, args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", describe(&out));
        assert!(
            stderr(&out).contains("--out: `-`"),
            "{args:?}: {}",
            describe(&out)
        );
        assert_eq!(
            listing(&dir),
            ["sweep.json", "tiny.json"],
            "{args:?} wrote a file"
        );
    }
}

#[test]
fn a_broken_json_override_is_refused_quoting_only_its_start() {
    let dir = scratch("broken-set");
    let scenario = write(&dir, "tiny.json", TINY);
    let broken = format!("particles.count=[1,2,{}", "3,".repeat(50_000));
    assert_bad_input(
        "broken-json",
        &scenario,
        &["--set", &broken],
        &["--set particles.count", "not valid JSON", "characters)"],
    );
    let out = vibrobed(&[
        "check".as_ref(),
        scenario.as_os_str(),
        "--set".as_ref(),
        broken.as_ref(),
    ]);
    assert!(stderr(&out).len() < 400, "{}", describe(&out));
    // A long value of the wrong type, in a file or a --set, is quoted by its start too.
    let long = format!("particles.count={}", "x".repeat(50_000));
    let out = vibrobed(&[
        "check".as_ref(),
        scenario.as_os_str(),
        "--set".as_ref(),
        long.as_ref(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", describe(&out));
    assert!(
        stderr(&out).contains("particles.count"),
        "{}",
        describe(&out)
    );
    assert!(stderr(&out).len() < 400, "{}", describe(&out));
}

/// A wall-clock limit past what the clock holds (1.8·10¹⁹ s) aborted the run; one past 10⁹ s
/// (32 years) is refused by name, in the scene and as `sweep run --max-run-seconds`.
#[test]
fn a_wall_clock_limit_past_32_years_is_refused_by_name() {
    let dir = scratch("wall-limit");
    let scenario = write(&dir, "tiny.json", TINY);
    for v in ["1e19", "1e50", "1.000001e9"] {
        assert_bad_input(
            &format!("max-wall-{v}"),
            &scenario,
            &["--set", &format!("run.max_wall_seconds={v}")],
            &["run.max_wall_seconds", "32 years"],
        );
    }
    let out = vibrobed(&[
        "check".as_ref(),
        scenario.as_os_str(),
        "--set".as_ref(),
        "run.max_wall_seconds=1e9".as_ref(),
    ]);
    assert_ok(&out);
    write(
        &dir,
        "sweep.json",
        r#"{"scenario": "tiny.json", "seeds": 1}"#,
    );
    for v in ["1e101", "1.7e308", "1e19"] {
        let out = vibrobed_in(
            &dir,
            &[
                "sweep",
                "run",
                "sweep.json",
                "--out",
                "out",
                "--max-run-seconds",
                v,
            ],
        );
        assert_eq!(out.status.code(), Some(2), "{v}: {}", describe(&out));
        assert!(
            stderr(&out).contains("--max-run-seconds: "),
            "{v}: {}",
            describe(&out)
        );
        assert!(
            !stderr(&out).contains("panicked"),
            "{v}: {}",
            describe(&out)
        );
        assert_eq!(
            listing(&dir),
            ["sweep.json", "tiny.json"],
            "{v}: wrote a file"
        );
    }
}
