//! The sweep's plot: one panel per summary field, its mean over seeds against a sweep axis, with
//! error bars of one standard error and, when asked, the fitted power law. Axes are labelled with
//! the field and its unit ([`axis_label`]); the legend sits in a strip of its own under the
//! title, so that it never covers a point.

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

/// One panel: a field's statistics per point, and its fit.
pub struct Panel<'a> {
    /// Summary field (y axis).
    pub field: &'a str,
    /// (x, statistics) per point, sorted by x.
    pub series: &'a [(f64, Stat)],
    /// The fitted power law, drawn as a line.
    pub fit: Option<PowerFit>,
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
    let height = HEAD + PANEL_HEIGHT * panels.len().max(1) as u32;
    let root = SVGBackend::new(path, (WIDTH, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let root = root
        .titled(title, ("sans-serif", 24))
        .map_err(|e| err(e.to_string()))?;
    let (head, body) = root.split_vertically(HEAD - 30);
    let mut entries = vec![(
        Key::ErrorBar(Shape::Circle, BLUE),
        "mean over seeds, bar ± one standard error (hidden by the dot when smaller)".to_owned(),
    )];
    if panels.iter().any(|p| p.fit.is_some()) {
        entries.push((
            Key::Line(RED),
            "power-law fit c·x^δ (least squares on ln x, ln y)".to_owned(),
        ));
    }
    legend(
        &head.margin(4, 0, ROOM.y_area + ROOM.margin, 0),
        None,
        &entries,
        1,
    )
    .map_err(err)?;
    let areas = body.split_evenly((panels.len().max(1), 1));
    for (panel, area) in panels.iter().zip(&areas) {
        draw_panel(area, x_name, panel, (log_x, log_y)).map_err(err)?;
    }
    root.present().map_err(|e| err(e.to_string()))?;
    Ok(())
}

/// The panel's points `(x, mean, standard error)` that its axes can show.
fn points(panel: &Panel, (log_x, log_y): (bool, bool)) -> Vec<(f64, f64, f64)> {
    panel
        .series
        .iter()
        .map(|(x, s)| (*x, s.mean, s.se.unwrap_or(0.0)))
        .filter(|(x, y, _)| x.is_finite() && y.is_finite())
        .filter(|(x, y, _)| (!log_x || *x > 0.0) && (!log_y || *y > 0.0))
        .collect()
}

/// The caption of a panel: the field, its meaning, and the fitted exponent.
fn caption(panel: &Panel) -> String {
    let name = match quantity(panel.field) {
        Some((meaning, _)) => format!("{}: {meaning}", panel.field),
        None => panel.field.to_owned(),
    };
    match panel.fit {
        Some(f) => format!(
            "{name}; fit ∝ x^δ, δ = {:.3}{}",
            f.exponent,
            f.exponent_se
                .map_or(String::new(), |se| format!(" ± {se:.3}"))
        ),
        None => name,
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

/// One panel: the means with their error bars and the fit, against the sweep axis.
fn draw_panel(
    area: &DrawingArea<SVGBackend, Shift>,
    x_name: &str,
    panel: &Panel,
    (log_x, log_y): (bool, bool),
) -> std::result::Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let pts = points(panel, (log_x, log_y));
    if pts.is_empty() {
        let text = format!("{}: no completed runs to plot", panel.field);
        return area
            .draw(&Text::new(text, (20, 40), ("sans-serif", FONT)))
            .map_err(e);
    }
    let range = |f: &dyn Fn(&(f64, f64, f64)) -> f64| {
        pts.iter()
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
    if let Some(f) = panel.fit {
        let line = LineSeries::new(fit_line(f, &x, &y), RED.stroke_width(2));
        chart.draw_series(line).map_err(|e| e.to_string())?;
    }
    let plotted: Vec<(f64, f64, f64, f64)> = pts
        .iter()
        .filter_map(|&(xv, m, se)| {
            let lo = y.to(m - se).unwrap_or(y.lo).max(y.lo);
            Some((x.to(xv)?, lo, y.to(m)?, y.to(m + se)?))
        })
        .collect();
    let bars = plotted
        .iter()
        .map(|&(p, lo, m, hi)| ErrorBar::new_vertical(p, lo, m, hi, BLUE.stroke_width(1), 10));
    chart.draw_series(bars).map_err(|e| e.to_string())?;
    let marks: Vec<(f64, f64)> = plotted.iter().map(|&(p, _, m, _)| (p, m)).collect();
    draw_markers(&mut chart, Shape::Circle, &marks, BLUE, 5)?;
    Ok(())
}
