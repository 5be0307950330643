//! `vibrobed accuracy`: the exact engine is the reference (zero error against itself on the same
//! seeds, a non-zero spread across seeds), the approximate schemes show errors that fall with
//! their step, and the command writes its table, CSV and SVG plot.

use crate::common::svg;

use std::path::{Path, PathBuf};
use std::process::Command;
use vibrobed::studies::accuracy::{report, Options};
use vibrobed::Scenario;

/// A small vibrated bed that runs in a blink.
const BED: &str = r#"{
  "name": "tiny vibrated bed",
  "seed": 21,
  "domain": { "width": 20.0, "x_boundary": "periodic", "y_boundary": "open" },
  "gravity": 1.0,
  "floor": { "gamma": 3.0, "frequency": 0.5, "restitution": 0.9 },
  "particles": { "count": 80, "radius": 0.5, "temperature": 0.5 },
  "collisions": { "restitution": 0.9 },
  "run": { "duration": 40.0, "warmup": 8.0 },
  "output": { "sample_interval": 0.25, "profile_bins": 16, "profile_height": 12.0 }
}"#;

fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("accuracy-{test}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

#[test]
fn the_exact_engine_is_the_reference() {
    let out = scratch("reference");
    let s = Scenario::from_json(BED).unwrap();
    let r = report(
        &s,
        &Options {
            out: out.clone(),
            quick: true,
            ..Default::default()
        },
    )
    .expect("report runs");
    let row = |variant: &str| {
        r.rows
            .iter()
            .find(|row| row.variant.starts_with(variant))
            .unwrap_or_else(|| panic!("no row {variant}"))
    };
    for variant in ["exact event-driven", "exact, re-run same seeds"] {
        let e = row(variant).errors;
        for (name, v) in e.entries() {
            assert_eq!(v, Some(0.0), "{variant}: {name} error is {v:?}");
        }
    }
    // Different seeds differ: the spread is the noise floor of every comparison.
    let spread = row("seed spread").errors;
    for (name, v) in spread.entries() {
        assert!(v.unwrap() > 0.0, "spread of {name} is {v:?}");
    }
    // Every variant ran (recording only where the build has it).
    for r in &r.rows {
        assert!(
            !r.note.starts_with("failed"),
            "{} {}: {}",
            r.family,
            r.variant,
            r.note
        );
    }
    // The approximate schemes report their overlaps (convergence is tested in tests/suite/schemes.rs
    // with enough statistics; this scene is too small for it).
    let ts: Vec<_> = r.rows.iter().filter(|r| r.family == "time-step").collect();
    assert_eq!(ts.len(), 3);
    for row in ts {
        assert_eq!(row.overlapped_fraction, Some(1.0), "{row:?}");
        assert!(row.max_overlap > 0.0 && row.missed_fraction.is_some());
    }
    assert!(r.rows.iter().any(|r| r.family == "space-time"));
    assert!(r.rows.iter().any(|r| r.family == "floor"));
    assert!(r.rows.iter().any(|r| r.family == "dissipation"));
    assert!(r.rows.iter().any(|r| r.family == "resting"));
}

/// On a bed that comes to rest, the report shows what resting contacts remove: without them
/// the same bed collides many times as often (its micro-bouncing), and no speed-cutoff row is
/// offered (a bed at rest has no thermal speed to scale it with).
#[test]
fn a_settling_bed_shows_what_resting_contacts_remove() {
    let out = scratch("resting");
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/hard/bed_at_rest_tc.json"
    ))
    .unwrap();
    // `--quick` runs a quarter of it: averages over t = 45–50, when the bed is at rest (from
    // t = 7 and 11 for seeds 5 and 6; seed 4 still rattles at t = 60).
    let sets = [
        "run.duration=200".to_string(),
        "run.warmup=180".to_string(),
        "seed=5".to_string(),
    ];
    let s = Scenario::from_json_with_overrides(&text, &sets).unwrap();
    let r = report(
        &s,
        &Options {
            out,
            quick: true,
            ..Default::default()
        },
    )
    .expect("report runs");
    let resting = r
        .rows
        .iter()
        .find(|row| row.family == "resting")
        .expect("a resting row");
    assert!(!resting.note.starts_with("failed"), "{resting:?}");
    let rate_error = resting
        .errors
        .collision_rate
        .expect("a collision-rate error");
    assert!(rate_error > 1.0, "collision rate error {rate_error}");
    assert!(!r
        .rows
        .iter()
        .any(|row| row.variant.starts_with("speed cutoff")));
}

#[test]
fn the_command_writes_table_csv_and_plot() {
    let dir = scratch("cli");
    let scenario = dir.join("bed.json");
    std::fs::write(&scenario, BED).unwrap();
    let out = dir.join("report");
    let o = Command::new(env!("CARGO_BIN_EXE_vibrobed"))
        .args([
            "accuracy",
            scenario.to_str().unwrap(),
            "--quick",
            "--effects",
        ])
        .arg("--out")
        .arg(&out)
        .args(["--set", "run.duration=20", "--set", "run.warmup=4"])
        .output()
        .expect("binary starts");
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stdout}\n{stderr}");
    for want in [
        "exact event-driven",
        "seed spread",
        "time-step",
        "space-time",
        "floor: fixed-position sine",
        "TC t_c",
        "speed cutoff",
        "recording",
        "what each effect costs",
        "polydispersity",
        "gravity",
        "friction",
        "it changes: ρ(z)",
    ] {
        assert!(stdout.contains(want), "table lacks {want}:\n{stdout}");
    }
    let csv = std::fs::read_to_string(out.join("accuracy.csv")).unwrap();
    assert!(csv.starts_with("family,variant,"));
    assert!(csv.lines().count() > 10, "{csv}");
    let svg = std::fs::read_to_string(out.join("accuracy.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("circle"), "not a plot");
    svg::check(&svg, 6);
    let effects = std::fs::read_to_string(out.join("effects.csv")).unwrap();
    assert!(effects.contains("walls vs periodic"));
    // The friction row: the bed with friction on pairs and floor against the bed without, and
    // what that changes (a rough bed is colder: its contacts also dissipate tangentially). The
    // row is three quoted texts, the numbers, and a quoted note.
    let header: Vec<&str> = effects.lines().next().unwrap().split(',').collect();
    let line = effects
        .lines()
        .find(|l| l.starts_with("\"friction\""))
        .expect("a friction row");
    let (texts, numbers) = line.rsplit_once("\",").unwrap();
    assert!(texts.ends_with("μ = 0.5, β = 0.4; floor μ = 0.5"), "{line}");
    let numbers: Vec<&str> = numbers.split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let t = column("change_temperature") - column("seconds_per_collision_without");
    let change: f64 = numbers[t].parse().unwrap();
    assert!(
        change < -0.1,
        "friction changes the temperature by {change}"
    );
    // Bad input exits 2 naming the field.
    let o = Command::new(env!("CARGO_BIN_EXE_vibrobed"))
        .args([
            "accuracy",
            scenario.to_str().unwrap(),
            "--set",
            "engine.dt=-1",
        ])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("engine.dt"));
}
