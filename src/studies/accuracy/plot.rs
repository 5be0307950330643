//! The accuracy report's figure (`accuracy.svg`): error against cost on log–log axes, one panel
//! per observable, all panels on the same cost axis; the reference's seed spread as a dashed line
//! (errors below it are noise) and its cost as a vertical line, with the cost of K exact runs
//! at once as a second one. One legend for all panels, in a column of its own on the right, so
//! that it never covers a point; under it, in words, the cheapest way to each observable within
//! [`FIGURE_LEVEL`].

use super::cheapest::{percent, FIGURE_LEVEL};
use super::{Errors, Report, Row};
use crate::error::{Error, Result};
use crate::studies::figure::{
    chart, draw_markers, legend, Axis, Key, Room, Shape, FONT, X_LABEL_GAP, Y_LABEL_GAP,
};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Width and height of the figure in pixels, and the width of the legend column.
const SIZE: (u32, u32) = (1560, 980);
const LEGEND_WIDTH: u32 = 340;
/// Room around each plotting area for tick labels and axis descriptions.
const ROOM: Room = Room {
    margin: 12,
    x_area: 58,
    y_area: 96,
};
/// Height of a panel's caption.
const CAPTION: u32 = 34;

/// How each family of variants is drawn: marker, colour, joined by a line, legend text.
const FAMILIES: [(&str, Shape, RGBColor, bool, &str); 7] = [
    (
        "reference",
        Shape::Circle,
        BLACK,
        false,
        "exact engine: its seed spread",
    ),
    (
        "time-step",
        Shape::Circle,
        RGBColor(31, 119, 180),
        true,
        "time-step, dt ×4 … ×¼",
    ),
    (
        "space-time",
        Shape::Square,
        RGBColor(214, 39, 40),
        true,
        "space-time, D ×4 … ×¼",
    ),
    (
        "floor",
        Shape::Triangle,
        RGBColor(44, 160, 44),
        false,
        "floor models",
    ),
    (
        "dissipation",
        Shape::Diamond,
        RGBColor(148, 103, 189),
        false,
        "TC and speed cutoff",
    ),
    (
        "resting",
        Shape::Triangle,
        RGBColor(140, 86, 75),
        false,
        "resting contacts off",
    ),
    (
        "recording",
        Shape::Square,
        RGBColor(127, 127, 127),
        false,
        "recording frames on",
    ),
];
/// Panel captions, in the order of [`Errors::entries`].
const CAPTIONS: [&str; 6] = [
    "density profile ρ(z)",
    "temperature profile T(z)",
    "centre-of-mass height",
    "granular temperature",
    "energy input rate",
    "pair collision rate",
];
/// Colour of the seed-spread line and of the reference's cost.
const SPREAD: RGBColor = RGBColor(80, 80, 80);
const REFERENCE_COST: RGBColor = RGBColor(150, 150, 150);
/// Colour of the cost of K exact runs at once.
const AT_ONCE_COST: RGBColor = RGBColor(230, 160, 60);

/// What every panel shares.
struct Frame<'a> {
    /// Rows with a measured cost.
    measured: Vec<&'a Row>,
    /// The reference's seed spread (the noise level of each observable).
    spread: Errors,
    /// The reference's cost (wall s per unit simulated time).
    ref_cost: f64,
    /// The cost of K exact runs at once, and K (none on one core).
    at_once: Option<(f64, usize)>,
    /// The answers at [`FIGURE_LEVEL`], in words.
    answers: Vec<String>,
    /// The cost axis.
    x: Axis,
}

/// Draws the report's figure into an SVG file at `path`.
pub fn draw(report: &Report, path: &Path) -> Result<()> {
    let err = |e: String| Error::Io(format!("cannot draw {}: {e}", path.display()));
    let root = SVGBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let title = format!(
        "{}: error against the exact engine vs cost ({} disks, {} seeds, {} cores)",
        report.scenario,
        report.particles,
        report.seeds.len(),
        report.cores
    );
    let root = root
        .titled(&title, ("sans-serif", 26))
        .map_err(|e| err(e.to_string()))?;
    let (plots, side) = root.split_horizontally(SIZE.0 - LEGEND_WIDTH);
    let frame = frame(report, plots.dim_in_pixel().0 / 3);
    for (k, area) in plots.split_evenly((2, 3)).iter().enumerate() {
        panel(area, k, &frame).map_err(err)?;
    }
    draw_legend(&side.margin(30, 0, 8, 0), &frame).map_err(err)?;
    root.present().map_err(|e| err(e.to_string()))?;
    Ok(())
}

/// The rows with a measured cost, the reference's spread and cost, and the cost axis for panels
/// `panel_width` pixels wide.
fn frame(report: &Report, panel_width: u32) -> Frame<'_> {
    let measured: Vec<&Row> = report
        .rows
        .iter()
        .filter(|r| r.wall_per_time.is_finite() && r.wall_per_time > 0.0)
        .collect();
    let (mut x0, mut x1) = measured.iter().fold((f64::INFINITY, 0.0f64), |(a, b), r| {
        (a.min(r.wall_per_time), b.max(r.wall_per_time))
    });
    if !(x0.is_finite() && x1 > 0.0) {
        (x0, x1) = (1e-3, 1.0);
    }
    let pixels = f64::from(panel_width.saturating_sub(ROOM.y_area + 2 * ROOM.margin));
    Frame {
        spread: report.rows.get(1).map(|r| r.errors).unwrap_or_default(),
        ref_cost: report.rows.first().map_or(f64::NAN, |r| r.wall_per_time),
        at_once: report
            .rows
            .iter()
            .find(|r| r.family == "reference" && r.cores > 1)
            .map(|r| (r.wall_per_time, r.cores)),
        answers: report
            .answers
            .iter()
            .filter(|a| a.level == FIGURE_LEVEL)
            .flat_map(|a| {
                [
                    format!("{}:", a.observable),
                    format!("  seeds: {}", short(&a.over_seeds.what)),
                    format!("  one run: {}", short(&a.one_trajectory.what)),
                ]
            })
            .collect(),
        x: Axis::new(x0 / 1.5, x1 * 1.5, true, pixels, X_LABEL_GAP),
        measured,
    }
}

/// The error of observable `k`, when it is positive (a log axis cannot show 0).
fn pick(e: &Errors, k: usize) -> Option<f64> {
    e.entries()[k].1.filter(|v| v.is_finite() && *v > 0.0)
}

/// Whether row `r` has a point in some panel (a positive error). The reference and its re-run
/// have none (their errors are 0 by construction).
fn drawn(r: &Row) -> bool {
    (0..6).any(|k| pick(&r.errors, k).is_some())
}

/// Panel `k`: the error of observable `k` against cost, every family, the spread and the
/// reference's cost.
fn panel(
    area: &DrawingArea<SVGBackend, Shift>,
    k: usize,
    f: &Frame,
) -> std::result::Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let name = CAPTIONS[k];
    let noise = pick(&f.spread, k);
    let values: Vec<f64> = f
        .measured
        .iter()
        .filter_map(|r| pick(&r.errors, k))
        .chain(noise)
        .collect();
    if values.is_empty() {
        let text = format!("{name}: not measured in this scene");
        return area
            .draw(&Text::new(text, (20, 40), ("sans-serif", FONT)))
            .map_err(e);
    }
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min) / 2.0;
    let hi = values.iter().copied().fold(0.0, f64::max) * 2.0;
    let height = area
        .dim_in_pixel()
        .1
        .saturating_sub(ROOM.x_area + CAPTION + 2 * ROOM.margin);
    let y = Axis::new(lo, hi, true, f64::from(height), Y_LABEL_GAP);
    let x = &f.x;
    let descriptions = (
        "cost (wall-clock s per unit of simulated time, on its cores)",
        "relative error (dimensionless)",
    );
    let mut chart = chart(area, name, (x, &y), descriptions, ROOM)?;
    let (x0, x1, y0, y1) = (x.lo, x.hi, y.lo, y.hi);
    if let Some(n) = noise.and_then(|n| y.to(n)) {
        let dashes = DashedLineSeries::new(vec![(x0, n), (x1, n)], 8, 5, SPREAD.stroke_width(2));
        chart.draw_series(dashes).map_err(|e| e.to_string())?;
    }
    if let Some(c) = x.to(f.ref_cost) {
        let line = LineSeries::new(vec![(c, y0), (c, y1)], REFERENCE_COST.stroke_width(2));
        chart.draw_series(line).map_err(|e| e.to_string())?;
    }
    if let Some(c) = f.at_once.and_then(|(cost, _)| x.to(cost)) {
        let line = LineSeries::new(vec![(c, y0), (c, y1)], AT_ONCE_COST.stroke_width(2));
        chart.draw_series(line).map_err(|e| e.to_string())?;
    }
    for (family, shape, color, joined, _) in FAMILIES {
        let points: Vec<(f64, f64)> = f
            .measured
            .iter()
            .filter(|r| r.family == family)
            .filter_map(|r| Some((x.to(r.wall_per_time)?, y.to(pick(&r.errors, k)?)?)))
            .collect();
        if joined {
            let line = LineSeries::new(points.clone(), color.stroke_width(2));
            chart.draw_series(line).map_err(|e| e.to_string())?;
        }
        draw_markers(&mut chart, shape, &points, color, 5)?;
    }
    Ok(())
}

/// The legend column: the families drawn, the spread line, the reference's cost, and a note on
/// zero errors.
fn draw_legend(
    area: &DrawingArea<SVGBackend, Shift>,
    f: &Frame,
) -> std::result::Result<(), String> {
    let mut entries: Vec<(Key, String)> = FAMILIES
        .iter()
        .filter(|(family, ..)| f.measured.iter().any(|r| r.family == *family && drawn(r)))
        .map(|&(_, shape, color, joined, text)| {
            let key = if joined {
                Key::Joined(shape, color)
            } else {
                Key::Marker(shape, color)
            };
            (key, text.to_owned())
        })
        .collect();
    entries.push((Key::Dashed(SPREAD), "seed spread: below it is noise".into()));
    entries.push((
        Key::Vertical(REFERENCE_COST),
        "cost of the exact engine".into(),
    ));
    if let Some((_, k)) = f.at_once {
        entries.push((
            Key::Vertical(AT_ONCE_COST),
            format!("{k} exact runs at once"),
        ));
    }
    let (_, y, _, h) = legend(area, Some("variants"), &entries, 1)?;
    // Variants with no error to draw (a log axis has no 0): named under the legend.
    let mut note = vec![
        "Error 0 everywhere, not drawn".to_owned(),
        "(a log axis has no 0):".to_owned(),
    ];
    let hidden: Vec<String> = f
        .measured
        .iter()
        .filter(|r| r.family != "reference" && !drawn(r))
        .map(|r| format!("· {}", r.variant))
        .collect();
    if hidden.is_empty() {
        note.clear();
    }
    note.extend(hidden);
    if !f.answers.is_empty() {
        note.push(String::new());
        note.push(format!("Cheapest within {}:", percent(FIGURE_LEVEL)));
        note.extend(f.answers.iter().cloned());
    }
    let style = ("sans-serif", FONT).into_font().color(&BLACK.mix(0.75));
    for (i, line) in note.iter().enumerate() {
        let at = (14, y + h + 24 + 22 * i as i32);
        area.draw(&Text::new(line.as_str(), at, style.clone()))
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// A way in the few words the legend column has room for.
fn short(way: &str) -> String {
    way.replace(" on ", ", ")
        .replace("time-step dt = ", "time-step dt ")
        .replace("space-time D = ", "space-time D ")
}
