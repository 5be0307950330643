//! Runs that end before their duration, as a user meets them on the real binary: a quantity
//! never measured is absent from the summary, never 0; each ending has its own exit code; a
//! wall-clock limit ends a run with its outputs kept; a long run off a terminal says how far it
//! is.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// A fresh, empty scratch directory for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("endings-{test}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// The shipped vibrated bed.
fn bed() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios/vibrated_bed.json")
        .display()
        .to_string()
}

fn vibrobed(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vibrobed"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the vibrobed binary starts")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn describe(out: &Output) -> String {
    format!(
        "exit {:?}\n--- stdout ---\n{}\n--- stderr ---\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        stderr(out)
    )
}

fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The shipped bed at Γ = 0.8, stopped by its event limit long before its warm-up (t = 50):
/// exit 4, `"ending": "event-limit"`, and no temperature, centre of mass, profiles or state in
/// the summary (never a 0 that reads as a measurement); the profiles and fields asked for are
/// not written, and stderr says why, naming each output and its file.
#[test]
fn a_run_stopped_by_its_event_limit_before_the_warm_up_measures_nothing() {
    let dir = scratch("event-limit");
    let bed = bed();
    let out = vibrobed(
        &dir,
        &[
            "run",
            &bed,
            "--quiet",
            "--set",
            "floor.gamma=0.8",
            "--set",
            "run.max_events=20000",
            "--summary",
            "s.json",
            "--profiles",
            "p.csv",
            "--fields",
            "f.csv",
        ],
    );
    assert_eq!(out.status.code(), Some(4), "{}", describe(&out));
    let s = read_json(&dir.join("s.json"));
    assert_eq!(s["ending"], "event-limit");
    let t = s["sim_time"].as_f64().unwrap();
    assert!(t > 0.0 && t < 50.0, "ends before the warm-up: t = {t}");
    for never in ["temperature", "com_height", "profiles", "state", "phase"] {
        assert!(s.get(never).is_none(), "{never} in {s:#}");
    }
    assert_eq!(s["engine"]["samples"], 0);
    for (output, file) in [("profiles", "p.csv"), ("fields", "f.csv")] {
        assert!(!dir.join(file).exists());
        let said = stderr(&out).lines().any(|l| {
            l.contains(&format!("no {output} measured"))
                && l.ends_with(&format!("{output} {file} not written"))
        });
        assert!(said, "{}", describe(&out));
    }
}

/// A height bin no disk centre ever entered has no velocity and no temperature: the shipped
/// bouncing ball (one disk, profiles to height 6 in 30 bins, most of them above its highest
/// bounce or below its lowest centre) writes `NaN` in the CSV (pandas reads it as missing) and
/// null in the summary for those bins, never a 0 that reads as a cold, still bin; every bin the
/// ball visited has numbers, and the local temperature averages those alone.
#[test]
fn a_profile_bin_no_disk_entered_has_no_temperature_or_velocity() {
    let dir = scratch("empty-bins");
    let ball = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios/bouncing_ball.json")
        .display()
        .to_string();
    let out = vibrobed(
        &dir,
        &[
            "run",
            &ball,
            "--quiet",
            "--set",
            "run.duration=100",
            "--summary",
            "s.json",
            "--profiles",
            "p.csv",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", describe(&out));
    let s = read_json(&dir.join("s.json"));
    let p = &s["profiles"];
    let csv = std::fs::read_to_string(dir.join("p.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let unmeasured = ["temperature_x", "temperature_y", "velocity_x", "velocity_y"];
    let (mut empty, mut visited) = (0, 0);
    for (k, row) in rows.iter().enumerate() {
        let density: f64 = row[col("density")].parse().unwrap();
        assert_eq!(density, p["density"][k].as_f64().unwrap());
        for name in unmeasured {
            let (cell, json) = (row[col(name)], &p[name][k]);
            if density == 0.0 {
                assert_eq!(cell, "NaN", "bin {k} {name}: {row:?}");
                assert!(json.is_null(), "bin {k} {name}: {json}");
            } else {
                assert!(cell.parse::<f64>().unwrap().is_finite(), "bin {k} {name}");
                assert!(json.as_f64().is_some_and(f64::is_finite), "bin {k} {name}");
            }
        }
        // The packing fraction and the density are measured everywhere: 0 is a measurement.
        assert!(row[col("packing_fraction")].parse::<f64>().unwrap() >= 0.0);
        if density == 0.0 {
            empty += 1;
        } else {
            visited += 1;
        }
    }
    assert!(
        empty >= 10 && visited >= 5,
        "{empty} empty, {visited} visited bins"
    );
    let local = s["temperature"]["local"].as_f64().unwrap();
    assert!(
        local.is_finite() && local > 0.0,
        "local temperature {local}"
    );
}

/// `run.max_wall_seconds` ends a long run after that much wall time with its own ending and
/// exit code 5, its summary and checkpoint written; what it measured after the warm-up is
/// reported; resuming it may set a new limit.
#[test]
fn a_wall_clock_limit_ends_the_run_with_its_outputs() {
    let dir = scratch("wall-limit");
    let bed = bed();
    let started = Instant::now();
    let out = vibrobed(
        &dir,
        &[
            "run",
            &bed,
            "--quiet",
            "--set",
            "run.duration=100000",
            "--set",
            "run.warmup=1",
            "--set",
            "run.max_wall_seconds=1.5",
            "--summary",
            "s.json",
            "--checkpoint",
            "c.ckpt",
        ],
    );
    let took = started.elapsed();
    assert_eq!(out.status.code(), Some(5), "{}", describe(&out));
    assert!(took < Duration::from_secs(20), "took {took:?}");
    let s = read_json(&dir.join("s.json"));
    assert_eq!(s["ending"], "wall-limit");
    let wall = s["wall_seconds"].as_f64().unwrap();
    assert!((1.3..10.0).contains(&wall), "wall_seconds {wall}");
    let t = s["sim_time"].as_f64().unwrap();
    assert!(t > 1.0 && t < 100000.0, "t = {t}");
    assert!(s["temperature"]["mean"].as_f64().unwrap() > 0.0);
    assert!(dir.join("c.ckpt").exists());
    let resumed = vibrobed(
        &dir,
        &[
            "resume",
            "c.ckpt",
            "--quiet",
            "--set",
            "run.max_wall_seconds=0.5",
            "--summary",
            "r.json",
        ],
    );
    assert_eq!(resumed.status.code(), Some(5), "{}", describe(&resumed));
    let r = read_json(&dir.join("r.json"));
    assert_eq!(r["ending"], "wall-limit");
    assert!(r["sim_time"].as_f64().unwrap() > t);
}

/// Off a terminal, a run prints a progress line every `--progress-every` seconds: simulated
/// time of the duration, collisions per second, the time to go.
#[test]
fn a_long_run_off_a_terminal_says_how_far_it_is() {
    let dir = scratch("progress");
    let bed = bed();
    let out = vibrobed(
        &dir,
        &[
            "run",
            &bed,
            "--progress-every",
            "0.2",
            "--set",
            "run.duration=100000",
            "--set",
            "run.max_wall_seconds=1.5",
            "--summary",
            "s.json",
        ],
    );
    assert_eq!(out.status.code(), Some(5), "{}", describe(&out));
    let err = stderr(&out);
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("of 100000 (") && l.contains("collisions/s") && l.contains("to go"))
        .collect();
    assert!(lines.len() >= 3, "{}", describe(&out));
    assert!(lines[0].starts_with("vibrobed: t = "), "{}", lines[0]);
    assert!(
        err.contains("stopped by the wall-clock limit (run.max_wall_seconds)"),
        "{err}"
    );
}

/// A real run freezing into an inelastic collapse between two stops gives the note on its
/// growing cost, once, naming the cures, and its progress lines go on meanwhile: the hard case's
/// 1000 disks at φ = 0.7 without its TC model, at e = 0.4, crawl from t ≈ 6.7 on (15 M
/// collisions take them to t ≈ 8), while the first stop (a frame and a sample) is at t = 50 — the
/// progress report reads the clock the engine publishes as it goes.
#[test]
fn a_run_freezing_into_a_collapse_says_so_naming_the_cures() {
    let dir = scratch("collapse-note");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios/hard/collapse_tc.json")
        .display()
        .to_string();
    let mut args = vec!["run", scene.as_str(), "--progress-every", "0.1"];
    for set in [
        "collisions.tc=null",
        "collisions.restitution=0.4",
        "output.frame_interval=50",
        "engine.check_invariants=false",
        "run.max_events=1000000000",
        "run.max_wall_seconds=3",
    ] {
        args.extend(["--set", set]);
    }
    args.extend(["--summary", "s.json"]);
    let out = vibrobed(&dir, &args);
    assert_eq!(out.status.code(), Some(5), "{}", describe(&out));
    let err = stderr(&out);
    let notes: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("freezing into an inelastic collapse"))
        .collect();
    assert_eq!(notes.len(), 1, "{err}");
    assert!(
        notes[0].starts_with("vibrobed: note: at t = "),
        "{}",
        notes[0]
    );
    for cure in [
        "collisions.tc",
        "collisions.speed_cutoff",
        "run.max_wall_seconds",
    ] {
        assert!(notes[0].contains(cure), "{}", notes[0]);
    }
    let lines = err.lines().filter(|l| l.starts_with("vibrobed: t = "));
    assert!(lines.count() >= 5, "{err}");
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("s.json")).expect("summary"))
            .expect("JSON");
    // Stopped before the first stop at t = 50, so every progress line read the published clock.
    // (How far the crawl gets in the 3 wall seconds depends on the machine's speed: past the
    // collapse it still creeps on, t ≈ 8.0 after 3 s and 10.9 after 12 on an Intel Xeon.)
    assert!(summary["sim_time"].as_f64().unwrap() < 50.0, "{summary}");
}

/// On a terminal a sweep draws its own bar in place of its runs' progress lines, and a run's note
/// on a growing cost still comes, once, named: the collapse above as a sweep's run, under a
/// pseudo-terminal from util-linux's `script` (without `script` the test says so and passes).
#[test]
fn a_sweep_on_a_terminal_notes_a_run_freezing_into_a_collapse() {
    let dir = scratch("sweep-terminal-note");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/hard/collapse_tc.json");
    let sweep = serde_json::json!({
        "name": "collapse",
        "scenario": scene.display().to_string(),
        "set": ["collisions.tc=null", "output.frame_interval=50",
                "engine.check_invariants=false", "run.max_events=1000000000"],
        "axes": [{ "key": "collisions.restitution", "values": [0.4] }],
        "seeds": 1
    });
    std::fs::write(dir.join("collapse.json"), sweep.to_string()).expect("sweep file");
    let command = format!(
        "{} sweep run collapse.json --out out --jobs 1 --progress-every 0.1 --max-run-seconds 3",
        env!("CARGO_BIN_EXE_vibrobed")
    );
    let out = match Command::new("script")
        .current_dir(&dir)
        .args(["-qec", &command, "/dev/null"])
        .output()
    {
        Ok(out) => out,
        Err(e) => {
            eprintln!("SKIPPED: no `script` to give the sweep a terminal ({e})");
            return;
        }
    };
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(5), "{}\n{text}", describe(&out));
    let notes: Vec<&str> = text
        .split(['\r', '\n'])
        .filter(|l| l.contains("freezing into an inelastic collapse"))
        .collect();
    assert_eq!(notes.len(), 1, "{text}");
    assert!(
        notes[0].contains("vibrobed: note: run 0: at t = "),
        "{}",
        notes[0]
    );
    assert!(notes[0].contains("collisions.tc"), "{}", notes[0]);
    assert!(
        !text.contains("vibrobed: run 0: t = "),
        "a progress line beside the bar: {text}"
    );
}

/// Bad values of the new limits exit 2 naming the field, and write nothing.
#[test]
fn bad_limits_are_refused_by_name() {
    let dir = scratch("bad-limits");
    let bed = bed();
    for (args, field) in [
        (
            vec!["--set", "run.max_wall_seconds=-1"],
            "run.max_wall_seconds",
        ),
        (vec!["--progress-every", "0"], "--progress-every"),
    ] {
        let mut all = vec!["run", bed.as_str(), "--summary", "s.json"];
        all.extend(args);
        let out = vibrobed(&dir, &all);
        assert_eq!(out.status.code(), Some(2), "{}", describe(&out));
        assert!(
            stderr(&out).contains(&format!("{field}: ")),
            "{}",
            describe(&out)
        );
        assert!(!dir.join("s.json").exists());
    }
}
