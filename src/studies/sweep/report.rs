//! `sweep collect`'s report: each sweep folder's tables, its points that did not complete (by
//! name), and with `--x` and `--y` one series per group (`--by`) and folder, each fitted apart,
//! into one plot and `fit.json`.

use crate::error::{Error, Result};
use crate::output::canonical;
use crate::studies::sweep::collect::{collect, Collected, Stat};
use crate::studies::sweep::fit::{fit, FitOptions, PowerFit};
use crate::studies::sweep::groups::{groups, Group};
use crate::studies::sweep::local::write_atomic;
use crate::studies::sweep::plot::{draw, Panel, Series};
use serde_json::json;
use std::path::{Path, PathBuf};

/// What `sweep collect` was asked to draw and fit.
pub struct Asked {
    /// The plot's axis.
    pub x: Option<String>,
    /// The fields, a panel each.
    pub ys: Vec<String>,
    /// The grouping keys.
    pub by: Vec<String>,
    /// The fit, if asked.
    pub fit: Option<FitOptions>,
    /// Logarithmic axes.
    pub log: bool,
    /// Where the plot goes (default: the first folder's plot.svg).
    pub plot: Option<PathBuf>,
}

/// One series: which folder and group, a field's statistics per point, the fit and the points
/// it left out for want of a completed run.
struct Line {
    sweep: String,
    group: String,
    field: String,
    points: Vec<(f64, Stat)>,
    fit: Option<PowerFit>,
    left_out: Vec<String>,
}

/// `sweep collect`: gathers each folder's runs into its `runs.csv` and `points.csv` and names
/// the points whose runs did not all complete; with `--x` and `--y`, plots each field's point
/// means against x, a series per group and folder (and with `--fit`, fits and reports each).
/// The plot's fields and groups are checked before anything is written.
pub fn collect_command(dirs: &[PathBuf], asked: Asked) -> Result<i32> {
    let sweeps = dirs
        .iter()
        .map(|d| collect(d))
        .collect::<Result<Vec<_>>>()?;
    let x = match (&asked.x, asked.ys.is_empty()) {
        (Some(x), false) => Some(x.clone()),
        (None, true) if asked.fit.is_none() && asked.plot.is_none() && !asked.log => None,
        (None, _) => return Err(Error::input("--x", "needed to plot or fit (with --y)")),
        (Some(_), true) => return Err(Error::input("--y", "needed with --x")),
    };
    let lines = match &x {
        Some(x) => lines(dirs, &sweeps, x, &asked)?,
        None => Vec::new(),
    };
    let path = asked
        .plot
        .clone()
        .unwrap_or_else(|| dirs[0].join("plot.svg"));
    if x.is_some() {
        writable_plot(&path, dirs)?;
    }
    for (dir, c) in dirs.iter().zip(&sweeps) {
        c.write_tables(dir)?;
        eprintln!(
            "{}: {} runs ({}); wrote runs.csv, points.csv",
            dir.display(),
            c.runs.len(),
            c.endings()
        );
        for (_, line) in c.incomplete() {
            eprintln!("vibrobed: warning: {}: {line}", dir.display());
        }
    }
    let Some(x) = x else { return Ok(0) };
    if asked.fit.is_some() {
        report_fits(&dirs[0], &x, &asked.by, &lines)?;
    }
    let panels: Vec<Panel> = asked
        .ys
        .iter()
        .map(|y| Panel {
            field: y,
            series: lines
                .iter()
                .filter(|l| &l.field == y)
                .map(|l| Series {
                    label: &l.group,
                    points: &l.points,
                    fit: l.fit,
                })
                .collect(),
        })
        .collect();
    let names: Vec<&str> = sweeps.iter().map(|c| c.plan.name.as_str()).collect();
    let title = format!(
        "sweep {}: against {x} ({} seeds per point)",
        names.join(", "),
        sweeps[0].plan.seeds_per_point()
    );
    draw(&path, &title, &x, &panels, asked.log, asked.log)?;
    eprintln!("wrote {}", path.display());
    Ok(0)
}

/// The files of a sweep folder that `sweep collect` reads or writes besides the plot.
const SWEEP_FILES: [&str; 5] = [
    "plan.json",
    "runs.csv",
    "points.csv",
    "fit.json",
    "states.svg",
];

/// Refuses, before anything is written, a plot `path` that cannot be written (a directory, a
/// directory that does not exist) or that would overwrite a file of a sweep in `dirs`: its plan,
/// its tables, or anything in a run's folder.
fn writable_plot(path: &Path, dirs: &[PathBuf]) -> Result<()> {
    crate::output::not_dash("--plot", path)?;
    if path.is_dir() {
        return Err(Error::input(
            "--plot",
            format!("{} is a directory: name a file", path.display()),
        ));
    }
    crate::output::writable_directory(path)
        .map_err(|why| Error::input("--plot", format!("{}: {why}", path.display())))?;
    let plot = canonical(path);
    for dir in dirs.iter().map(|d| canonical(d)) {
        let in_a_run = plot
            .parent()
            .is_some_and(|p| p != dir && p.starts_with(&dir));
        if in_a_run || SWEEP_FILES.iter().any(|f| plot == dir.join(f)) {
            return Err(Error::input(
                "--plot",
                format!(
                    "{} would overwrite a file of the sweep in {} (its plan, tables or runs): name another file",
                    path.display(),
                    dir.display()
                ),
            ));
        }
    }
    Ok(())
}

/// Every series: for each field, each folder and each of its groups, the statistics per point
/// and (if asked) the fit of the point means.
fn lines(dirs: &[PathBuf], sweeps: &[Collected], x: &str, asked: &Asked) -> Result<Vec<Line>> {
    let mut out = Vec::new();
    let grouped = sweeps
        .iter()
        .map(|c| groups(c, x, &asked.by))
        .collect::<Result<Vec<_>>>()?;
    for y in &asked.ys {
        for ((dir, c), gs) in dirs.iter().zip(sweeps).zip(&grouped) {
            for g in gs {
                out.push(line(dir, c, g, (x, y), asked, sweeps.len() > 1)?);
            }
        }
    }
    Ok(out)
}

/// The series of field `y` against `x` over group `g` of folder `dir`'s sweep `c` (named after
/// the folder too when `named`).
fn line(
    dir: &Path,
    c: &Collected,
    g: &Group,
    (x, y): (&str, &str),
    asked: &Asked,
    named: bool,
) -> Result<Line> {
    let points = c.series_of(x, y, &g.points)?;
    let fit = asked.fit.and_then(|options| {
        let runs: Vec<(f64, Vec<f64>)> = g
            .points
            .iter()
            .filter_map(|&p| Some((c.point_value(x, p)?, c.run_values(p, y))))
            .collect();
        fit(&runs, options)
    });
    let left = c.left_out(y);
    let left_out = g
        .points
        .iter()
        .filter(|p| left.contains(p))
        .map(|&p| format!("point {p} ({})", c.point_label(p)))
        .collect();
    let sweep = dir.display().to_string();
    let group = match (named, g.label.as_str()) {
        (true, "all points") => sweep.clone(),
        (true, label) => format!("{sweep}: {label}"),
        (false, label) => label.to_string(),
    };
    Ok(Line {
        sweep,
        group,
        field: y.to_string(),
        points,
        fit,
        left_out,
    })
}

/// Prints each series' power-law fit (or why it has none) with the points it left out, and
/// writes them all to `DIR/fit.json`.
fn report_fits(dir: &Path, x: &str, by: &[String], lines: &[Line]) -> Result<()> {
    let mut fits = Vec::new();
    for l in lines {
        let name = match l.group.as_str() {
            "all points" => l.field.clone(),
            group => format!("{} [{group}]", l.field),
        };
        match l.fit {
            Some(f) => println!("{}", fit_text(&name, x, &f)),
            None => println!(
                "{name}: no fit (it needs two points in the range with positive x and y, or y \
                 above the offset; a fitted offset, three)"
            ),
        }
        if !l.left_out.is_empty() {
            eprintln!(
                "vibrobed: warning: {name}: the fit leaves out {} (no completed run measured it)",
                l.left_out.join(", ")
            );
        }
        fits.push(json!({
            "field": l.field,
            "sweep": l.sweep,
            "group": l.group,
            "fit": l.fit,
            "left_out": l.left_out,
        }));
    }
    let text = serde_json::to_string_pretty(&json!({ "x": x, "by": by, "power_law": fits }))
        .expect("fit serialises")
        + "\n";
    write_atomic(&dir.join("fit.json"), &text)
}

/// A fit of `name` in words: `com_height − 2.1 = c·(x)^δ: δ = 1.92 ± 0.01 (scatter) ± 0.02
/// (seeds), c = …`.
fn fit_text(name: &str, x: &str, f: &PowerFit) -> String {
    let offset = match f.offset {
        None => String::new(),
        Some(y0) if y0 < 0.0 => format!(" + {:.6}", -y0),
        Some(y0) => format!(" − {y0:.6}"),
    };
    format!(
        "{name}{offset} = c·({x})^δ: δ = {:.4}{}{}, c = {:.4} ({} points, log–log least squares)",
        f.exponent,
        f.exponent_se.map_or(
            " (no scatter error: as many points as fitted parameters)".into(),
            |se| format!(" ± {se:.4} (scatter)")
        ),
        f.exponent_seed_se
            .map_or(String::new(), |se| format!(" ± {se:.4} (seeds)")),
        f.prefactor,
        f.points
    )
}
