//! The sweep's plot: one panel per summary field, its mean over seeds against a sweep axis, with
//! error bars of one standard error and, when asked, the fitted power law; one series per group
//! (`--by`) or sweep folder, each in its colour and marker. Axes are labelled with the field and
//! its unit ([`axis_label`]); the legend sits in a strip of its own under the title, so that it
//! never covers a point.

use crate::error::{Error, Result};
use crate::studies::figure::{
    chart, draw_markers, legend, Axis, Key, Room, Shape, FONT, X_LABEL_GAP, Y_LABEL_GAP,
};
use crate::studies::sweep::collect::Stat;
use crate::studies::sweep::fit::PowerFit;
use crate::studies::sweep::quantities::{axis_label, quantity};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// One series of a panel: a group's statistics per point, and its fit.
pub struct Series<'a> {
    /// The group's name in the legend (`all points` for a sweep not grouped).
    pub label: &'a str,
    /// (x, statistics) per point, sorted by x.
    pub points: &'a [(f64, Stat)],
    /// The fitted power law, drawn as a line.
    pub fit: Option<PowerFit>,
}

/// One panel: a field's series.
pub struct Panel<'a> {
    /// Summary field (y axis).
    pub field: &'a str,
    /// One per group, in the legend's order.
    pub series: Vec<Series<'a>>,
}

/// The colours and markers of the series, in turn.
const PALETTE: [(RGBColor, Shape); 8] = [
    (BLUE, Shape::Circle),
    (RGBColor(255, 127, 14), Shape::Square),
    (RGBColor(44, 160, 44), Shape::Triangle),
    (RGBColor(148, 103, 189), Shape::Diamond),
    (RGBColor(140, 86, 75), Shape::Circle),
    (RGBColor(227, 119, 194), Shape::Square),
    (RGBColor(127, 127, 127), Shape::Triangle),
    (RGBColor(23, 190, 207), Shape::Diamond),
];

/// The colour and marker of series `k`.
fn style(k: usize) -> (RGBColor, Shape) {
    PALETTE[k % PALETTE.len()]
}

/// Width of the figure, height of the title and legend strip and of each panel, in pixels.
const WIDTH: u32 = 900;
const HEAD: u32 = 120;
const PANEL_HEIGHT: u32 = 440;
/// Room around each plotting area for tick labels and axis descriptions.
const ROOM: Room = Room {
    margin: 14,
    x_area: 58,
    y_area: 96,
};
const CAPTION: u32 = 32;
const BLUE: RGBColor = RGBColor(31, 119, 180);
const RED: RGBColor = RGBColor(214, 39, 40);
/// The keys that stand for every series (markers and fit lines) when each has its colour.
const GREY: RGBColor = RGBColor(96, 96, 96);

/// Axis range padded by a margin: a factor on log axes, a fraction of the span on linear ones.
fn padded(lo: f64, hi: f64, log: bool) -> (f64, f64) {
    if log {
        let (lo, hi) = (lo.max(f64::MIN_POSITIVE), hi.max(f64::MIN_POSITIVE));
        let f = (hi / lo).powf(0.06).max(1.05);
        (lo / f, hi * f)
    } else {
        let pad = ((hi - lo) * 0.06).max(hi.abs().max(1e-12) * 1e-3);
        (lo - pad, hi + pad)
    }
}

/// Draws the panels stacked vertically into an SVG file at `path`, under `title` and a legend;
/// `x_name` is the sweep axis (described with [`axis_label`]).
pub fn draw(
    path: &Path,
    title: &str,
    x_name: &str,
    panels: &[Panel],
    log_x: bool,
    log_y: bool,
) -> Result<()> {
    let err = |e: String| Error::Io(format!("cannot draw {}: {e}", path.display()));
    let entries = legend_entries(panels);
    let columns = if entries.len() > 3 { 2 } else { 1 };
    let head = HEAD + 22 * (entries.len().div_ceil(columns).saturating_sub(2)) as u32;
    let height = head + PANEL_HEIGHT * panels.len().max(1) as u32;
    let root = SVGBackend::new(path, (WIDTH, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let root = root
        .titled(title, ("sans-serif", 24))
        .map_err(|e| err(e.to_string()))?;
    let (head, body) = root.split_vertically(head - 30);
    legend(
        &head.margin(4, 0, ROOM.y_area + ROOM.margin, 0),
        None,
        &entries,
        columns,
    )
    .map_err(err)?;
    let areas = body.split_evenly((panels.len().max(1), 1));
    for (panel, area) in panels.iter().zip(&areas) {
        draw_panel(area, x_name, panel, (log_x, log_y)).map_err(err)?;
    }
    root.present().map_err(|e| err(e.to_string()))?;
    Ok(())
}

/// The legend: what the markers and bars are, a series' name by its colour when there are
/// several, and the fit's line.
fn legend_entries(panels: &[Panel]) -> Vec<(Key, String)> {
    let bars = "mean over seeds, bar ± one standard error (hidden by the dot when smaller)";
    let series = panels.first().map_or(&[][..], |p| &p.series[..]);
    let mut entries = match series {
        [_] | [] => vec![(Key::ErrorBar(Shape::Circle, BLUE), bars.to_owned())],
        several => several
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let (colour, shape) = style(k);
                (Key::ErrorBar(shape, colour), s.label.to_owned())
            })
            .collect(),
    };
    if series.len() > 1 {
        entries.push((Key::ErrorBar(Shape::Circle, GREY), bars.to_owned()));
    }
    if panels
        .iter()
        .any(|p| p.series.iter().any(|s| s.fit.is_some()))
    {
        let line = if series.len() > 1 {
            "power-law fit of each series, in its colour"
        } else {
            "power-law fit c·x^δ (least squares on ln x, ln y)"
        };
        let colour = if series.len() > 1 { GREY } else { RED };
        entries.push((Key::Line(colour), line.to_owned()));
    }
    entries
}

/// A series' points `(x, mean, standard error)` that the axes can show.
fn points(series: &Series, (log_x, log_y): (bool, bool)) -> Vec<(f64, f64, f64)> {
    series
        .points
        .iter()
        .map(|(x, s)| (*x, s.mean, s.se.unwrap_or(0.0)))
        .filter(|(x, y, _)| x.is_finite() && y.is_finite())
        .filter(|(x, y, _)| (!log_x || *x > 0.0) && (!log_y || *y > 0.0))
        .collect()
}

/// The caption of a panel: the field, its meaning, and the fitted exponents (in the series'
/// order).
fn caption(panel: &Panel) -> String {
    let name = match quantity(panel.field) {
        Some((meaning, _)) => format!("{}: {meaning}", panel.field),
        None => panel.field.to_owned(),
    };
    let exponents: Vec<String> = panel
        .series
        .iter()
        .filter_map(|s| s.fit)
        .map(|f| {
            format!(
                "{:.3}{}",
                f.exponent,
                f.exponent_se
                    .map_or(String::new(), |se| format!(" ± {se:.3}"))
            )
        })
        .collect();
    match exponents.len() {
        0 => name,
        1 => format!("{name}; fit ∝ x^δ, δ = {}", exponents[0]),
        _ => format!("{name}; δ = {}", exponents.join(", ")),
    }
}

/// The fitted power law across the panel, in plot coordinates, where it is inside the panel.
fn fit_line(f: PowerFit, x: &Axis, y: &Axis) -> Vec<(f64, f64)> {
    (0..=100)
        .map(|i| x.lo + (x.hi - x.lo) * f64::from(i) / 100.0)
        .filter_map(|p| Some((p, y.to(f.at(x.value(p)))?)))
        .filter(|(_, q)| (y.lo..=y.hi).contains(q))
        .collect()
}

/// One panel: each series' means with their error bars and its fit, against the sweep axis.
fn draw_panel(
    area: &DrawingArea<SVGBackend, Shift>,
    x_name: &str,
    panel: &Panel,
    (log_x, log_y): (bool, bool),
) -> std::result::Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let all: Vec<(f64, f64, f64)> = panel
        .series
        .iter()
        .flat_map(|s| points(s, (log_x, log_y)))
        .collect();
    if all.is_empty() {
        let text = format!("{}: no completed runs to plot", panel.field);
        return area
            .draw(&Text::new(text, (20, 40), ("sans-serif", FONT)))
            .map_err(e);
    }
    let range = |f: &dyn Fn(&(f64, f64, f64)) -> f64| {
        all.iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            })
    };
    let (x0, x1) = range(&|p| p.0);
    let (y0, _) = range(&|p| if log_y { p.1 } else { p.1 - p.2 });
    let (_, y1) = range(&|p| p.1 + p.2);
    let (x0, x1) = padded(x0, x1, log_x);
    let (y0, y1) = padded(y0, y1, log_y);
    let (w, h) = area.dim_in_pixel();
    let x = Axis::new(
        x0,
        x1,
        log_x,
        f64::from(w.saturating_sub(ROOM.y_area + 2 * ROOM.margin)),
        X_LABEL_GAP,
    );
    let height = h.saturating_sub(ROOM.x_area + CAPTION + 2 * ROOM.margin);
    let y = Axis::new(y0, y1, log_y, f64::from(height), Y_LABEL_GAP);
    let descriptions = (axis_label(x_name), axis_label(panel.field));
    let descriptions = (descriptions.0.as_str(), descriptions.1.as_str());
    let mut chart = chart(area, &caption(panel), (&x, &y), descriptions, ROOM)?;
    let several = panel.series.len() > 1;
    for (k, series) in panel.series.iter().enumerate() {
        let (colour, shape) = style(k);
        if let Some(f) = series.fit {
            let line_colour = if several { colour } else { RED };
            let line = LineSeries::new(fit_line(f, &x, &y), line_colour.stroke_width(2));
            chart.draw_series(line).map_err(|e| e.to_string())?;
        }
        let plotted: Vec<(f64, f64, f64, f64)> = points(series, (log_x, log_y))
            .iter()
            .filter_map(|&(xv, m, se)| {
                let lo = y.to(m - se).unwrap_or(y.lo).max(y.lo);
                Some((x.to(xv)?, lo, y.to(m)?, y.to(m + se)?))
            })
            .collect();
        let bars = plotted.iter().map(|&(p, lo, m, hi)| {
            ErrorBar::new_vertical(p, lo, m, hi, colour.stroke_width(1), 10)
        });
        chart.draw_series(bars).map_err(|e| e.to_string())?;
        let marks: Vec<(f64, f64)> = plotted.iter().map(|&(p, _, m, _)| (p, m)).collect();
        draw_markers(&mut chart, shape, &marks, colour, 5)?;
    }
    Ok(())
}
