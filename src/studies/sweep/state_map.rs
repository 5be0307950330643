//! The phase diagram of a sweep: each point's bed state (the state most of its completed runs
//! ended in) as a coloured marker over two axes, one colour and shape per state, with a legend.
//! A point whose runs disagree is drawn hollow.

use crate::error::{Error, Result};
use crate::studies::figure::{chart, legend, Axis, Key, Room, Shape, X_LABEL_GAP, Y_LABEL_GAP};
use crate::studies::sweep::quantities::axis_label;
use plotters::prelude::*;
use std::path::Path;

/// The states in the order of rising drive, each with its colour and marker shape.
pub const STATES: [(&str, RGBColor, Shape); 6] = [
    ("solid", RGBColor(110, 110, 110), Shape::Square),
    ("bouncing_bed", RGBColor(31, 119, 180), Shape::Circle),
    ("undulations", RGBColor(148, 103, 189), Shape::Diamond),
    ("leidenfrost", RGBColor(214, 39, 40), Shape::Triangle),
    ("convection", RGBColor(44, 160, 44), Shape::Diamond),
    ("gas", RGBColor(255, 127, 14), Shape::Square),
];

/// One point of the map.
#[derive(Debug, Clone, PartialEq)]
pub struct StatePoint {
    /// The point's value on the x and y axes.
    pub at: (f64, f64),
    /// The state most of its completed runs ended in.
    pub state: String,
    /// How many runs ended in it, of how many completed.
    pub agree: (usize, usize),
}

const WIDTH: u32 = 900;
const HEIGHT: u32 = 720;
const HEAD: u32 = 110;
const ROOM: Room = Room {
    margin: 14,
    x_area: 58,
    y_area: 96,
};
const MARKER: i32 = 11;

/// Draws the map of `points` over the axes `x_name` and `y_name` (logarithmic x if `log_x`)
/// into an SVG file at `path`, under `title`.
pub fn draw_states(
    path: &Path,
    title: &str,
    (x_name, y_name): (&str, &str),
    points: &[StatePoint],
    log_x: bool,
) -> Result<()> {
    let err = |e: String| Error::Io(format!("cannot draw {}: {e}", path.display()));
    let root = SVGBackend::new(path, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let root = root
        .titled(title, ("sans-serif", 24))
        .map_err(|e| err(e.to_string()))?;
    let (head, body) = root.split_vertically(HEAD - 30);
    let seen: Vec<_> = STATES
        .iter()
        .filter(|(name, ..)| points.iter().any(|p| p.state == *name))
        .map(|&(name, color, shape)| (Key::Marker(shape, color), name.to_owned()))
        .collect();
    let mut entries = seen;
    if points.iter().any(|p| p.agree.0 < p.agree.1) {
        entries.push((
            Key::Marker(Shape::Circle, RGBColor(0, 0, 0)),
            "hollow: the runs of the point disagree (the most frequent state drawn)".to_owned(),
        ));
    }
    legend(
        &head.margin(4, 0, ROOM.y_area + ROOM.margin, 0),
        None,
        &entries,
        3,
    )
    .map_err(err)?;
    draw_map(&body, (x_name, y_name), points, log_x).map_err(err)?;
    root.present().map_err(|e| err(e.to_string()))?;
    Ok(())
}

/// The axis over `values`, padded by half the smallest step between them.
fn axis_over(values: impl Iterator<Item = f64>, log: bool, pixels: u32, gap: f64) -> Axis {
    let mut v: Vec<f64> = values
        .filter(|x| x.is_finite() && (!log || *x > 0.0))
        .map(|x| if log { x.log10() } else { x })
        .collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    let (lo, hi) = (
        v.first().copied().unwrap_or(0.0),
        v.last().copied().unwrap_or(1.0),
    );
    let step = v
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min);
    let pad = if step.is_finite() { 0.5 * step } else { 0.5 };
    let (lo, hi) = (lo - pad, hi + pad);
    let (lo, hi) = if log {
        (10f64.powf(lo), 10f64.powf(hi))
    } else {
        (lo, hi)
    };
    Axis::new(lo, hi, log, f64::from(pixels), gap)
}

fn draw_map(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    (x_name, y_name): (&str, &str),
    points: &[StatePoint],
    log_x: bool,
) -> std::result::Result<(), String> {
    let (w, h) = area.dim_in_pixel();
    let x = axis_over(
        points.iter().map(|p| p.at.0),
        log_x,
        w.saturating_sub(ROOM.y_area + 2 * ROOM.margin),
        X_LABEL_GAP,
    );
    let y = axis_over(
        points.iter().map(|p| p.at.1),
        false,
        h.saturating_sub(ROOM.x_area + 2 * ROOM.margin + 32),
        Y_LABEL_GAP,
    );
    let caption = "the state of each point (most frequent over its seeds)";
    let (xd, yd) = (axis_label(x_name), axis_label(y_name));
    let mut chart = chart(area, caption, (&x, &y), (&xd, &yd), ROOM)?;
    for &(name, color, shape) in &STATES {
        for p in points.iter().filter(|p| p.state == name) {
            let (Some(px), Some(py)) = (x.to(p.at.0), y.to(p.at.1)) else {
                continue;
            };
            let outline = marker(shape);
            let at = EmptyElement::at((px, py));
            let drawn = if p.agree.0 < p.agree.1 {
                let mut closed = outline.clone();
                closed.push(outline[0]);
                let hollow = PathElement::new(closed, color.stroke_width(3));
                chart.draw_series(std::iter::once(at + hollow)).map(|_| ())
            } else {
                let filled = Polygon::new(outline, color.filled());
                chart.draw_series(std::iter::once(at + filled)).map(|_| ())
            };
            drawn.map_err(|e| e.to_string())?;
        }
    }
    Ok(())
}

/// The outline of a marker of `shape`, in pixels about its centre.
fn marker(shape: Shape) -> Vec<(i32, i32)> {
    let r = MARKER;
    let pts: Vec<(i32, i32)> = match shape {
        Shape::Square => vec![(-r, -r), (r, -r), (r, r), (-r, r)],
        Shape::Triangle => vec![(0, -r - 2), (r + 2, r), (-r - 2, r)],
        Shape::Diamond => vec![(0, -r - 2), (r + 2, 0), (0, r + 2), (-r - 2, 0)],
        Shape::Circle => (0..16)
            .map(|k| {
                let a = f64::from(k) * std::f64::consts::TAU / 16.0;
                let (x, y) = (f64::from(r) * a.cos(), f64::from(r) * a.sin());
                (x.round() as i32, y.round() as i32)
            })
            .collect(),
    };
    pts
}
