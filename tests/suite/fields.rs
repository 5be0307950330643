//! The 2D fields (`run --fields`): what they integrate to, that both file forms read back to the
//! same numbers, that a seed gives the same files, and that a resumed run gives the fields of
//! the run that did not stop.

use crate::guarded::{fresh_dir, scenario};
use serde_json::Value;
use std::path::Path;
use std::process::Command;

/// A small vibrated bed (300 disks, 60 wide), 40 units after a warm-up of 10.
const BED: &[&str] = &[
    "particles.count=300",
    "domain.width=60",
    "run.duration=50",
    "run.warmup=10",
    "output.field_bins=[12,8]",
];

/// Runs `vibrobed COMMAND FILE ARGS` from `dir` (a `run` with the small bed's overrides);
/// asserts exit 0.
fn vibrobed(dir: &Path, args: &[&str]) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_vibrobed"));
    cmd.current_dir(dir).args(&args[..2]).arg("--quiet");
    if args[0] == "run" {
        for s in BED {
            cmd.args(["--set", s]);
        }
    }
    cmd.args(&args[2..]); // After the bed's overrides: a later --set wins.
    let out = cmd.output().expect("vibrobed runs");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The small bed run with these extra arguments.
fn run_bed(dir: &Path, extra: &[&str]) {
    let bed = scenario("vibrated_bed.json").display().to_string();
    let mut args = vec!["run", &bed];
    args.extend(extra);
    vibrobed(dir, &args);
}

/// A CSV file: its header and its rows of numbers.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).expect("fields CSV");
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap()).collect())
        .collect();
    (header, rows)
}

/// Column `name` of a CSV.
fn column(csv: &(Vec<String>, Vec<Vec<f64>>), name: &str) -> Vec<f64> {
    let k = csv.0.iter().position(|h| h == name).expect(name);
    csv.1.iter().map(|r| r[k]).collect()
}

#[test]
fn the_fields_integrate_to_the_disks_in_the_grid_and_read_back_alike() {
    let dir = fresh_dir("fields-integral");
    run_bed(
        &dir,
        &[
            "--fields",
            "f.csv",
            "--summary",
            "s.json",
            "--profiles",
            "p.csv",
        ],
    );
    run_bed(&dir, &["--fields", "f.vti"]);
    let s: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("s.json")).unwrap()).unwrap();
    let csv = read_csv(&dir.join("f.csv"));
    assert_eq!(
        csv.0,
        "i,j,x,y,number_density,packing_fraction,velocity_x,velocity_y,temperature_x,temperature_y"
            .split(',')
            .collect::<Vec<_>>()
    );
    assert_eq!(csv.1.len(), 12 * 8);
    let (x, y) = (column(&csv, "x"), column(&csv, "y"));
    let (dx, dy) = (x[1] - x[0], y[12] - y[0]);
    assert!((dx - 5.0).abs() < 1e-12, "cells 60/12 wide: {dx}");
    let cell = dx * dy;
    // The default top is the profiles' (output.profile_height = 20): the disks in the grid are
    // those below the profiles' top, N − above_top, on average over the same samples.
    let n = s["particles"].as_f64().unwrap();
    let above = s["profiles"]["above_top"].as_f64().unwrap();
    let counted: f64 = column(&csv, "number_density").iter().sum::<f64>() * cell;
    assert!(
        (counted - (n - above)).abs() < 1e-9 * n,
        "∫ n dA = {counted}, disks in the grid {}",
        n - above
    );
    // The area: the 2D split over cells adds up to the profiles' split over strips.
    let profiles = read_csv(&dir.join("p.csv"));
    let h = column(&profiles, "height");
    let strip = (h[1] - h[0]) * 60.0;
    let by_strips: f64 = column(&profiles, "packing_fraction").iter().sum::<f64>() * strip;
    let by_cells: f64 = column(&csv, "packing_fraction").iter().sum::<f64>() * cell;
    assert!(
        (by_cells - by_strips).abs() < 1e-9 * by_strips,
        "disk area by cells {by_cells}, by strips {by_strips}"
    );
    assert!(by_cells > 0.9 * n * std::f64::consts::PI * 0.25);
    // The VTK image data holds the same numbers, cell for cell.
    let text = std::fs::read_to_string(dir.join("f.vti")).unwrap();
    let vtk = vtkio::Vtk::parse_xml(text.as_bytes()).expect("the .vti parses");
    let vtkio::model::DataSet::ImageData {
        extent,
        origin,
        spacing,
        pieces,
        ..
    } = vtk.data
    else {
        panic!("not image data");
    };
    assert_eq!(extent, vtkio::model::Extent::Ranges([0..=12, 0..=8, 0..=0]));
    assert!((spacing[0] as f64 - dx).abs() < 1e-5 && (spacing[1] as f64 - dy).abs() < 1e-5);
    assert!((origin[1] as f64 - (y[0] - 0.5 * dy)).abs() < 1e-5);
    let vtkio::model::Piece::Inline(piece) = &pieces[0] else {
        panic!("an inline piece");
    };
    for attribute in &piece.data.cell {
        let vtkio::model::Attribute::DataArray(a) = attribute else {
            panic!("a data array");
        };
        let values: Vec<f64> = a.data.clone().cast_into().expect("f64 values");
        let expected: Vec<f64> = if a.name == "velocity" {
            let (ux, uy) = (column(&csv, "velocity_x"), column(&csv, "velocity_y"));
            (0..ux.len()).flat_map(|k| [ux[k], uy[k], 0.0]).collect()
        } else {
            column(&csv, &a.name)
        };
        let same = values
            .iter()
            .zip(&expected)
            .all(|(a, b)| a == b || (a.is_nan() && b.is_nan()));
        assert!(same && values.len() == expected.len(), "{}", a.name);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_seed_gives_the_same_fields_and_a_resumed_run_those_of_the_whole_run() {
    let dir = fresh_dir("fields-determinism");
    run_bed(&dir, &["--fields", "a.csv"]);
    run_bed(&dir, &["--fields", "b.csv"]);
    run_bed(
        &dir,
        &[
            "--fields",
            "half.csv",
            "--checkpoint",
            "c.ckpt",
            "--set",
            "run.duration=30",
        ],
    );
    vibrobed(
        &dir,
        &[
            "resume",
            "c.ckpt",
            "--set",
            "run.duration=50",
            "--fields",
            "resumed.csv",
        ],
    );
    let read = |f: &str| std::fs::read(dir.join(f)).unwrap();
    assert!(read("a.csv") == read("b.csv"), "same seed, same fields");
    assert!(read("a.csv") == read("resumed.csv"), "resumed = whole run");
    assert!(
        read("a.csv") != read("half.csv"),
        "half the run, other fields"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The summary's velocity distributions of a scenario run with these overrides.
fn velocity_distribution(
    name: &str,
    sets: &[&str],
) -> vibrobed::measure::velocities::VelocityDistribution {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let s = vibrobed::Scenario::load(&scenario(name), &sets).expect("scenario");
    let summary = vibrobed::run::run(&s, vibrobed::run::RunOptions::default()).expect("run");
    summary.velocity_distribution.expect("a distribution")
}

/// An elastic gas (2500 disks, φ = 0.3, periodic) relaxes to the Maxwell distribution: each
/// component Gaussian. 180 units after a warm-up of 20, sampled every 0.5: 9·10⁵ velocities.
/// Across seeds 1–6 the kurtosis came out 2.988–3.021 (spread 0.009, the samples being
/// correlated over a few collision times), the histogram within 0.005 of the Gaussian density:
/// the test allows 0.05 (about 5 spreads) and 0.015.
#[test]
fn an_elastic_gas_has_gaussian_velocities() {
    let d = velocity_distribution(
        "gas_periodic_phi03.json",
        &["run.duration=200", "run.warmup=20"],
    );
    assert_eq!(d.scaling, "whole box");
    for (axis, a) in [("x", &d.x), ("y", &d.y)] {
        assert!(
            (a.kurtosis - 3.0).abs() < 0.05,
            "{axis}: kurtosis {} (Gaussian: 3)",
            a.kurtosis
        );
        let gauss = |c: f64| (-0.5 * c * c).exp() / (2.0 * std::f64::consts::PI).sqrt();
        for (c, p) in d.c.iter().zip(&a.density) {
            assert!(
                (p - gauss(*c)).abs() < 0.015,
                "{axis}: density {p} at c = {c}"
            );
        }
        let total: f64 = a.density.iter().sum::<f64>() * (d.c[1] - d.c[0]);
        assert!((total - 1.0).abs() < 1e-3, "{axis}: ∫ p dc = {total}");
    }
}

/// A driven inelastic bed (the shipped vibrated bed, e = 0.9, Γ = 3) has overpopulated tails in
/// the horizontal velocity: kurtosis 3.47 here (seed 6), against 3 for a Gaussian and 3.76 for
/// the exp(−|c|^1.5) of Losert et al. (1999).
#[test]
fn a_vibrated_inelastic_bed_has_overpopulated_horizontal_tails() {
    let d = velocity_distribution("vibrated_bed.json", &[]);
    assert_eq!(d.scaling, "height bands");
    assert!(d.x.kurtosis > 3.3, "x: kurtosis {}", d.x.kurtosis);
    // The tails beyond |c| = 3 hold more than a Gaussian's 0.27 %.
    let w = d.c[1] - d.c[0];
    let tail: f64 =
        d.c.iter()
            .zip(&d.x.density)
            .filter(|(c, _)| c.abs() > 3.0)
            .map(|(_, p)| p * w)
            .sum();
    assert!(tail > 0.004, "x: {tail} beyond |c| = 3");
}
