//! Every SVG figure vibrobed writes can be read: tick labels on every axis that do not overlap,
//! axis descriptions with units, legends that cover no data, log axes labelled at decades. The
//! figures are drawn here from made-up reports and sweeps (fast, no simulation), with points
//! where the old legends sat; the book's figures (`docs/book/src/figures/`) are held to the same bar.

use crate::common::svg;

use std::path::PathBuf;
use vibrobed::studies::accuracy::{Errors, Report, Row};
use vibrobed::studies::sweep::collect::Stat;
use vibrobed::studies::sweep::fit::power_law;
use vibrobed::studies::sweep::plot::{draw, Panel, Series};

fn out(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(format!("figures-{}-{name}.svg", std::process::id()))
}

/// A row of `family` at `cost` whose errors are `e` times a fixed pattern (0: error 0).
fn row(family: &str, variant: &str, cost: f64, e: f64) -> Row {
    let v = |k: f64| Some(e * k);
    Row {
        family: family.into(),
        variant: variant.into(),
        settings: String::new(),
        seeds: 3,
        wall_per_time: cost,
        relative_cost: cost / 0.006,
        cores: if family.ends_with("-step") || family == "space-time" {
            2
        } else {
            1
        },
        core_per_time: cost,
        errors: Errors {
            density_profile: v(1.0),
            temperature_profile: v(2.0),
            com_height: v(0.1),
            temperature: v(0.5),
            energy_input: v(0.03),
            collision_rate: v(0.2),
        },
        max_overlap: 0.0,
        overlapped_fraction: None,
        deep_fraction: None,
        missed_fraction: None,
        note: String::new(),
    }
}

/// A report like the vibrated bed's, with errors from 10⁻⁵ to 1 and costs over a decade.
fn report() -> Report {
    let mut rows = vec![
        row("reference", "exact event-driven", 0.006, 0.0),
        row("reference", "seed spread", 0.006, 0.006),
        row("reference", "exact, re-run same seeds", 0.0055, 0.0),
    ];
    let mut at_once = row("reference", "exact, 2 runs at once", 0.0033, 0.0);
    at_once.cores = 2;
    rows.insert(2, at_once);
    for (i, m) in [4.0, 2.0, 1.0, 0.5, 0.25].iter().enumerate() {
        rows.push(row(
            "time-step",
            &format!("dt ×{m}"),
            0.0019 * 1.5f64.powi(i as i32),
            0.15 * m,
        ));
        rows.push(row(
            "space-time",
            &format!("D ×{m}"),
            0.0066 + 0.001 * i as f64,
            0.004 * m,
        ));
    }
    // Low and left: where the old legend (lower left of each panel) sat.
    rows.push(row("dissipation", "TC small", 0.0016, 0.0004));
    rows.push(row("dissipation", "speed cutoff small", 0.0059, 0.0));
    rows.push(row("floor", "fixed-position sine", 0.0057, 0.47));
    rows.push(row("resting", "resting contacts off", 0.0061, 0.002));
    rows.push(row("recording", "recording frames on", 0.0062, 0.0));
    Report {
        scenario: "test bed".into(),
        particles: 1000,
        duration: 200.0,
        seeds: vec![6, 7, 8],
        cores: 2,
        machine: "a test machine".into(),
        answers: vibrobed::studies::accuracy::cheapest::answers(&rows),
        rows,
        effects: Vec::new(),
        wall_seconds: 1.0,
    }
}

#[test]
fn the_accuracy_figure_can_be_read() {
    let path = out("accuracy");
    vibrobed::studies::accuracy::plot::draw(&report(), &path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    svg::check(&text, 6);
    // Errors are labelled at decades, as decimals down to 0.001 and as powers of ten below;
    // the cost axis has several labels (the old figure had one: `1e-2`).
    let f = svg::parse(&text);
    let labels = |k: usize| -> Vec<String> {
        let (left, _) = svg::tick_labels(&f, f.plots[k]);
        left.iter().map(|t| t.content.clone()).collect()
    };
    let (density, com) = (labels(0), labels(2));
    assert!(
        density.contains(&"0.001".into()) && density.contains(&"0.1".into()),
        "{density:?}"
    );
    assert!(
        com.contains(&"10⁻⁴".into()) && com.contains(&"10⁻²".into()),
        "{com:?}"
    );
    let (_, under) = svg::tick_labels(&f, f.plots[0]);
    assert!(
        under.len() >= 3,
        "{:?}",
        under.iter().map(|t| &t.content).collect::<Vec<_>>()
    );
    // Every family is drawn and in the legend; variants with error 0 everywhere are named.
    assert!(text.contains("resting contacts off"));
    assert!(text.contains("recording frames on") && text.contains("speed cutoff small"));
    std::fs::remove_file(&path).ok();
}

/// (x, statistics) of y = c·x^δ with a 2 % error, at `n` points from `x0` to `x1` in equal ratios.
fn series(c: f64, delta: f64, x0: f64, x1: f64, n: usize) -> Vec<(f64, Stat)> {
    (0..n)
        .map(|i| {
            let x = x0 * (x1 / x0).powf(i as f64 / (n - 1) as f64);
            let mean = c * x.powf(delta) * (1.0 + 0.05 * (i as f64).sin());
            (
                x,
                Stat {
                    mean,
                    se: Some(0.02 * mean),
                    n: 3,
                },
            )
        })
        .collect()
}

#[test]
fn the_sweep_figures_can_be_read_on_log_and_linear_axes() {
    // The shipped sweep's ranges: T from 0.3 to 12 (crowded `10` over `9` before), the centre
    // of mass within a decade (one label before), Aω from 0.6 to 5.
    let t = series(0.73, 1.72, 0.63, 5.0, 7);
    let z = series(3.8, 0.83, 0.63, 5.0, 7);
    let fit =
        |s: &[(f64, Stat)]| power_law(&s.iter().map(|(x, st)| (*x, st.mean)).collect::<Vec<_>>());
    let panels = [
        Panel {
            field: "temperature.mean",
            series: vec![Series {
                label: "all points",
                points: &t,
                fit: fit(&t),
            }],
        },
        Panel {
            field: "com_height",
            series: vec![Series {
                label: "all points",
                points: &z,
                fit: fit(&z),
            }],
        },
    ];
    for (log, name) in [(true, "log"), (false, "linear")] {
        let path = out(name);
        draw(
            &path,
            "sweep test",
            "drive.peak_velocity",
            &panels,
            log,
            log,
        )
        .unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        svg::check(&text, 2);
        assert!(
            text.contains("drive.peak_velocity (length/time)"),
            "x axis unit"
        );
        assert!(
            text.contains("temperature.mean (mass·length²/time²)"),
            "y axis unit"
        );
        std::fs::remove_file(&path).ok();
    }
    // A field without a known unit still says what its unit is.
    let w = series(2.0, 1.0, 1.0, 100.0, 5);
    let path = out("unknown");
    let panel = [Panel {
        field: "something.new",
        series: vec![Series {
            label: "all points",
            points: &w,
            fit: None,
        }],
    }];
    draw(&path, "sweep test", "floor.gamma", &panel, true, true).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    svg::check(&text, 1);
    assert!(
        text.contains("something.new (scenario units)")
            && text.contains("floor.gamma (dimensionless)")
    );
    std::fs::remove_file(&path).ok();
}

#[test]
fn the_shipped_figures_can_be_read() {
    let docs = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("docs/book/src/figures");
    for (name, panels) in [
        ("accuracy-vibrated-bed.svg", 6),
        ("sweep-temperature.svg", 2),
    ] {
        let path = docs.join(name);
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        svg::check(&text, panels);
    }
}
