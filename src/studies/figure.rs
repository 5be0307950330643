//! What every SVG figure of vibrobed shares (`vibrobed accuracy`, `vibrobed sweep collect`): axes
//! a reader can read, point markers, and legends that never cover data.
//!
//! An [`Axis`] chooses its own ticks from the room it has: on a log axis the decades are labelled
//! (thinned to every second or fifth decade when they would crowd), with 2 and 5 (or 2, 3 and 5)
//! between them when there is room and fewer than three decades in view, the other mantissas
//! drawn as unlabelled grid lines; a linear axis gets 1-2-5 steps. Labels never come closer than
//! a minimum gap. A log axis is drawn in log10 coordinates, so every chart is a plain linear
//! chart whose tick positions and labels come from here (plotters' own log ticks crowd: `10`
//! printed over `9`).
//!
//! Legends go in an area of their own beside or above the plotting areas ([`legend`]), so they
//! cannot cover a point whatever the data. Plotting areas are filled with [`PLOT_BACKGROUND`] and
//! legend boxes framed in [`LEGEND_FRAME`]: the tests find both in the SVG by these colours.

use plotters::coord::cartesian::Cartesian2d;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::{Circle, EmptyElement, Polygon, Rectangle};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Fill of every plotting area (a light grey, so that the data region is visible).
pub const PLOT_BACKGROUND: RGBColor = RGBColor(250, 250, 250);
/// Frame of every legend box.
pub const LEGEND_FRAME: RGBColor = RGBColor(96, 96, 96);
/// Font size of tick labels, legend entries and axis descriptions (plotters draws SVG text at
/// 1/1.24 of the size asked for: 17 gives 13.7 px).
pub const FONT: f64 = 17.0;
/// Smallest gap in pixels between the positions of two labels on a horizontal axis.
pub const X_LABEL_GAP: f64 = 64.0;
/// Smallest gap in pixels between the positions of two labels on a vertical axis.
pub const Y_LABEL_GAP: f64 = 26.0;

/// One axis: its range in plot coordinates (log10 of the value on a log axis), its labelled
/// (major) and unlabelled (minor) ticks, and how it writes its labels.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Logarithmic axis (plot coordinate = log10 of the value).
    pub log: bool,
    /// Lower end, in plot coordinates.
    pub lo: f64,
    /// Upper end, in plot coordinates.
    pub hi: f64,
    /// Labelled ticks, in plot coordinates.
    pub major: Vec<f64>,
    /// Unlabelled grid lines, in plot coordinates.
    pub minor: Vec<f64>,
    /// Labels as powers of ten (`10⁻³`, `2×10⁻³`) rather than decimals.
    powers: bool,
    /// Decimals of a decimal label.
    decimals: usize,
}

impl Axis {
    /// An axis over the values `lo..hi` (both > 0 on a log axis) drawn `pixels` long, with labels
    /// at least `gap` pixels apart.
    pub fn new(lo: f64, hi: f64, log: bool, pixels: f64, gap: f64) -> Axis {
        let (lo, hi) = if log {
            (
                lo.max(f64::MIN_POSITIVE).log10(),
                hi.max(f64::MIN_POSITIVE).log10(),
            )
        } else {
            (lo, hi)
        };
        let (lo, hi) = if hi > lo {
            (lo, hi)
        } else {
            (lo - 0.5, lo + 0.5)
        };
        let per_unit = pixels.max(1.0) / (hi - lo);
        let (values, minor) = if log {
            log_ticks(lo, hi, per_unit, gap)
        } else {
            (linear_ticks(lo, hi, gap / per_unit), Vec::new())
        };
        let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let smallest = values
            .iter()
            .filter(|v| **v != 0.0)
            .fold(f64::INFINITY, |m, v| m.min(v.abs()));
        let powers = largest >= 1e5 || smallest < 1e-3;
        let decimals = values.iter().map(|&v| decimals_of(v)).max().unwrap_or(0);
        let to = |v: f64| if log { v.log10() } else { v };
        Axis {
            log,
            lo,
            hi,
            major: values.into_iter().map(to).collect(),
            minor: minor.into_iter().map(to).collect(),
            powers,
            decimals,
        }
    }

    /// The plot coordinate of value `v` (`None` for v ≤ 0 on a log axis).
    pub fn to(&self, v: f64) -> Option<f64> {
        match (self.log, v.is_finite()) {
            (_, false) => None,
            (true, true) if v <= 0.0 => None,
            (true, true) => Some(v.log10()),
            (false, true) => Some(v),
        }
    }

    /// The value at plot coordinate `p`.
    pub fn value(&self, p: f64) -> f64 {
        if self.log {
            10f64.powf(p)
        } else {
            p
        }
    }

    /// The label of the tick at plot coordinate `p`.
    pub fn label(&self, p: f64) -> String {
        let v = self.value(p);
        if self.powers {
            power_label(v)
        } else {
            // A log axis writes each label with its own digits (0.002, 0.005, 0.01); a linear
            // one with the digits of its step (0.0, 0.2, 0.4).
            let d = if self.log {
                decimals_of(v)
            } else {
                self.decimals
            };
            format!("{:.*}", d, if v == 0.0 { 0.0 } else { v })
        }
    }

    /// The axis for plotters: its range with the ticks as key points (bold: labelled, light:
    /// grid lines only).
    pub fn coord(&self) -> Ticked {
        Ticked {
            inner: (self.lo..self.hi).into(),
            major: self.major.clone(),
            minor: self.minor.clone(),
        }
    }
}

/// A linear range in plot coordinates whose key points are given (plotters' own
/// `WithKeyPoints` loses the label formatter of an `f64` range).
pub struct Ticked {
    inner: RangedCoordf64,
    major: Vec<f64>,
    minor: Vec<f64>,
}

impl Ranged for Ticked {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.minor.clone()
        } else {
            self.major.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }
}

/// Digits after the point that write `v` (a tick value) exactly enough: at most 6.
fn decimals_of(v: f64) -> usize {
    (0..=6)
        .find(|&d| {
            let s = 10f64.powi(d);
            ((v * s).round() - v * s).abs() < 1e-6 * s.max(v.abs() * s)
        })
        .unwrap_or(6) as usize
}

/// `10⁻³`, `2×10⁻³`, `1.5×10⁴`: a tick value as a power of ten.
pub fn power_label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let e = v.abs().log10().floor() as i32;
    let m = v / 10f64.powi(e);
    let (m, e) = if (m.abs() - 10.0).abs() < 1e-9 {
        (m / 10.0, e + 1)
    } else {
        (m, e)
    };
    let exp: String = e
        .to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            d => ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'][d as usize - '0' as usize],
        })
        .collect();
    if (m - 1.0).abs() < 1e-9 {
        format!("10{exp}")
    } else {
        let m = format!("{m:.2}");
        let m = m.trim_end_matches('0').trim_end_matches('.');
        format!("{m}×10{exp}")
    }
}

/// Values in `[10^lo, 10^hi]` of the form m·10ⁿ for m in `mantissas`, n a multiple of `every`.
fn decade_values(lo: f64, hi: f64, mantissas: &[f64], every: i32) -> Vec<f64> {
    let (a, b) = (lo.floor() as i32, hi.ceil() as i32);
    let eps = 1e-9 * (hi - lo).max(1e-9);
    (a..=b)
        .filter(|n| n.rem_euclid(every) == 0)
        .flat_map(|n| mantissas.iter().map(move |m| m * 10f64.powi(n)))
        .filter(|v| (lo - eps..=hi + eps).contains(&v.log10()))
        .collect()
}

/// Labelled and unlabelled values of a log axis over log10 values `lo..hi`, `per_decade`
/// pixels a decade, labels at least `gap` pixels apart.
fn log_ticks(lo: f64, hi: f64, per_decade: f64, gap: f64) -> (Vec<f64>, Vec<f64>) {
    let decades = decade_values(lo, hi, &[1.0], 1);
    let mut major = Vec::new();
    if decades.len() >= 3 {
        // Every `every`-th decade: no closer than `gap`, at most eight labels.
        for every in [1, 2, 3, 5, 10, 20, 50, 100] {
            major = decade_values(lo, hi, &[1.0], every);
            if every as f64 * per_decade >= gap && major.len() <= 8 {
                break;
            }
        }
    } else {
        // Fewer than three decades in view: the richest of 1-2-3-5, 1-2-5, 1-3 and the decades
        // whose labels keep their distance and are at least two.
        let sets: [(&[f64], f64); 4] = [
            (&[1.0, 2.0, 3.0, 5.0], 1.5),
            (&[1.0, 2.0, 5.0], 2.0),
            (&[1.0, 3.0], 3.0),
            (&[1.0], 10.0),
        ];
        major = sets
            .iter()
            .filter(|(_, closest_ratio)| closest_ratio.log10() * per_decade >= gap)
            .map(|(mantissas, _)| decade_values(lo, hi, mantissas, 1))
            .find(|values| values.len() >= 2)
            .unwrap_or_default();
        if major.is_empty() {
            // A narrow range: linear steps, spaced by where they are closest (the top), and
            // at least two of them.
            let (a, b) = (10f64.powf(lo), 10f64.powf(hi));
            let step = gap / per_decade * b * std::f64::consts::LN_10;
            major = linear_ticks(a, b, step.min((b - a) / 5.0));
        }
    }
    let mantissas: &[f64] = if per_decade >= 60.0 {
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
    } else {
        &[1.0]
    };
    let minor = decade_values(lo, hi, mantissas, 1)
        .into_iter()
        .filter(|v| !major.iter().any(|m| (m / v - 1.0).abs() < 1e-9))
        .collect();
    (major, minor)
}

/// Multiples of a 1-2-5 step of at least `min_step` between `lo` and `hi`, at most ten.
fn linear_ticks(lo: f64, hi: f64, min_step: f64) -> Vec<f64> {
    let min_step = min_step.max((hi - lo) / 10.0).max(f64::MIN_POSITIVE);
    let p = 10f64.powf(min_step.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|&s| s >= min_step * (1.0 - 1e-9))
        .unwrap_or(10.0 * p);
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// Font size of panel captions.
pub const CAPTION_FONT: f64 = 21.0;

/// Room around a plotting area, in pixels: the margin of its panel, the label areas under it
/// (tick labels and x axis description) and left of it (tick labels and y axis description).
#[derive(Debug, Clone, Copy)]
pub struct Room {
    /// Margin around the panel.
    pub margin: u32,
    /// Height of the label area under the plotting area.
    pub x_area: u32,
    /// Width of the label area left of the plotting area.
    pub y_area: u32,
}

/// A panel on `area`: its caption, the plotting area filled with [`PLOT_BACKGROUND`], and the
/// axes `x` and `y` with their ticks, tick labels and descriptions (which should name units).
pub fn chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    (x, y): (&Axis, &Axis),
    (x_desc, y_desc): (&str, &str),
    room: Room,
) -> Result<ChartContext<'a, DB, Cartesian2d<Ticked, Ticked>>, String> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", CAPTION_FONT))
        .margin(room.margin)
        .x_label_area_size(room.x_area)
        .y_label_area_size(room.y_area)
        .build_cartesian_2d(x.coord(), y.coord())
        .map_err(|e| e.to_string())?;
    chart
        .plotting_area()
        .fill(&PLOT_BACKGROUND)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&|v| x.label(*v))
        .y_label_formatter(&|v| y.label(*v))
        .label_style(("sans-serif", FONT))
        .axis_desc_style(("sans-serif", FONT))
        .bold_line_style(BLACK.mix(0.16))
        .light_line_style(BLACK.mix(0.05))
        .draw()
        .map_err(|e| e.to_string())?;
    Ok(chart)
}

/// Marker shapes, told apart without colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// Filled disk.
    Circle,
    /// Filled square.
    Square,
    /// Filled triangle, point up.
    Triangle,
    /// Filled diamond.
    Diamond,
}

/// Runs `$body` with `$mk` bound to a closure that makes the marker `$shape` (radius `$r`,
/// style `$style`) at a position: each shape is its own element type, so the body is expanded
/// once per shape.
macro_rules! with_marker {
    ($shape:expr, $r:expr, $style:expr, |$mk:ident| $body:expr) => {{
        let (r, style): (i32, ShapeStyle) = ($r, $style);
        match $shape {
            Shape::Circle => {
                let $mk = |p| EmptyElement::at(p) + Circle::new((0, 0), r, style);
                $body
            }
            Shape::Square => {
                let $mk = |p| EmptyElement::at(p) + Rectangle::new([(-r, -r), (r, r)], style);
                $body
            }
            Shape::Triangle => {
                let pts = [(0, -r - 1), (r + 1, r), (-r - 1, r)];
                let $mk = |p| EmptyElement::at(p) + Polygon::new(pts.to_vec(), style);
                $body
            }
            Shape::Diamond => {
                let pts = [(0, -r - 1), (r + 1, 0), (0, r + 1), (-r - 1, 0)];
                let $mk = |p| EmptyElement::at(p) + Polygon::new(pts.to_vec(), style);
                $body
            }
        }
    }};
}

/// Draws markers of `shape` and `color`, `r` pixels from centre to edge, at `points` (plot
/// coordinates) into `chart`.
pub fn draw_markers<DB: DrawingBackend>(
    chart: &mut ChartContext<DB, Cartesian2d<Ticked, Ticked>>,
    shape: Shape,
    points: &[(f64, f64)],
    color: RGBColor,
    r: i32,
) -> Result<(), String> {
    with_marker!(shape, r, color.filled(), |mk| chart
        .draw_series(points.iter().map(|&p| mk(p)))
        .map(|_| ())
        .map_err(|e| e.to_string()))
}

/// What a legend entry shows in front of its text.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Key {
    /// A marker.
    Marker(Shape, RGBColor),
    /// A marker on a line (a joined series).
    Joined(Shape, RGBColor),
    /// A solid line.
    Line(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A short vertical line.
    Vertical(RGBColor),
    /// A marker with a vertical error bar.
    ErrorBar(Shape, RGBColor),
}

/// Draws the key of an entry centred at `(x, y)`, 28 pixels wide.
fn draw_key<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    key: Key,
    (x, y): (i32, i32),
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let line =
        |c: RGBColor, x0: i32, x1: i32| PathElement::new(vec![(x0, y), (x1, y)], c.stroke_width(2));
    match key {
        Key::Marker(s, c) => with_marker!(s, 5, c.filled(), |mk| area.draw(&mk((x, y))).map_err(e)),
        Key::Joined(s, c) => {
            area.draw(&line(c, x - 14, x + 14)).map_err(e)?;
            with_marker!(s, 5, c.filled(), |mk| area.draw(&mk((x, y))).map_err(e))
        }
        Key::Line(c) => area.draw(&line(c, x - 14, x + 14)).map_err(e),
        Key::Dashed(c) => {
            for x0 in [x - 14, x - 3, x + 8] {
                area.draw(&line(c, x0, x0 + 6)).map_err(e)?;
            }
            Ok(())
        }
        Key::Vertical(c) => area
            .draw(&PathElement::new(
                vec![(x, y - 9), (x, y + 9)],
                c.stroke_width(2),
            ))
            .map_err(e),
        Key::ErrorBar(s, c) => {
            let bar = PathElement::new(vec![(x, y - 10), (x, y + 10)], c.stroke_width(1));
            area.draw(&bar).map_err(e)?;
            for yy in [y - 10, y + 10] {
                let cap = PathElement::new(vec![(x - 4, yy), (x + 4, yy)], c.stroke_width(1));
                area.draw(&cap).map_err(e)?;
            }
            with_marker!(s, 4, c.filled(), |mk| area.draw(&mk((x, y))).map_err(e))
        }
    }
}

/// Width in pixels of `text` at font size `size`, estimated (SVG text has no metrics here).
pub fn text_width(text: &str, size: f64) -> i32 {
    (text.chars().count() as f64 * size / 1.24 * 0.56).ceil() as i32
}

/// Draws a framed legend into `area` (an area of its own, outside every plotting area): the
/// entries one under the other in `columns` columns, from the top left, with an optional
/// heading. Returns the legend's frame `(x, y, width, height)` in the area's pixels.
pub fn legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    heading: Option<&str>,
    entries: &[(Key, String)],
    columns: usize,
) -> Result<(i32, i32, i32, i32), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let columns = columns.clamp(1, entries.len().max(1));
    let rows = entries.len().div_ceil(columns) as i32;
    let (pad, line_height, key_width) = (10, 26, 40);
    let col_width = entries
        .iter()
        .map(|(_, t)| key_width + text_width(t, FONT))
        .max()
        .unwrap_or(0)
        + 24;
    let head = heading.map_or(0, |_| line_height);
    let width =
        (col_width * columns as i32).max(heading.map_or(0, |h| text_width(h, FONT))) + 2 * pad;
    let height = head + rows * line_height + 2 * pad - 6;
    let (x0, y0) = (4, 4);
    let frame = Rectangle::new(
        [(x0, y0), (x0 + width, y0 + height)],
        LEGEND_FRAME.stroke_width(1),
    );
    area.draw(&Rectangle::new(
        [(x0, y0), (x0 + width, y0 + height)],
        WHITE.filled(),
    ))
    .map_err(e)?;
    area.draw(&frame).map_err(e)?;
    let font = ("sans-serif", FONT).into_font().color(&BLACK);
    let left = font.pos(Pos::new(HPos::Left, VPos::Center));
    if let Some(h) = heading {
        area.draw(&Text::new(
            h.to_owned(),
            (x0 + pad, y0 + pad + line_height / 2 - 3),
            left.clone(),
        ))
        .map_err(e)?;
    }
    for (i, (key, text)) in entries.iter().enumerate() {
        let (col, row) = (i as i32 / rows, i as i32 % rows);
        let x = x0 + pad + col * col_width;
        let y = y0 + pad + head + row * line_height + line_height / 2 - 3;
        draw_key(area, *key, (x + key_width / 2 - 4, y))?;
        area.draw(&Text::new(text.clone(), (x + key_width, y), left.clone()))
            .map_err(e)?;
    }
    Ok((x0, y0, width, height))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(a: &Axis) -> Vec<String> {
        a.major.iter().map(|&p| a.label(p)).collect()
    }

    #[test]
    fn a_log_axis_over_decades_labels_the_decades_only() {
        let a = Axis::new(4e-5, 0.9, true, 300.0, Y_LABEL_GAP);
        assert_eq!(labels(&a), ["10⁻⁴", "10⁻³", "10⁻²", "10⁻¹"]);
        assert!(a.minor.len() > 20, "mantissas 2..9 as grid lines");
    }

    #[test]
    fn a_log_axis_over_less_than_three_decades_adds_two_and_five() {
        let a = Axis::new(0.29, 13.0, true, 300.0, Y_LABEL_GAP);
        assert_eq!(labels(&a), ["0.3", "0.5", "1", "2", "3", "5", "10"]);
        let a = Axis::new(0.0013, 0.016, true, 330.0, X_LABEL_GAP);
        assert_eq!(labels(&a), ["0.002", "0.005", "0.01"]);
    }

    #[test]
    fn a_log_axis_within_a_decade_still_gets_labels_that_do_not_crowd() {
        for (lo, hi, want) in [(2.7, 19.0, 3), (2.7, 3.5, 2), (0.00107, 0.0159, 2)] {
            let a = Axis::new(lo, hi, true, 300.0, Y_LABEL_GAP);
            assert!(a.major.len() >= want, "{lo}..{hi}: {:?}", labels(&a));
            for w in a.major.windows(2) {
                assert!((w[1] - w[0]) * 300.0 / (a.hi - a.lo) >= Y_LABEL_GAP - 1e-9);
            }
        }
    }

    #[test]
    fn many_decades_are_thinned() {
        let a = Axis::new(1e-12, 1e3, true, 300.0, Y_LABEL_GAP);
        assert!(a.major.len() <= 8 && a.major.len() >= 3, "{:?}", labels(&a));
        assert!(labels(&a).iter().all(|l| l.starts_with("10")));
    }

    #[test]
    fn linear_labels_have_the_decimals_of_their_step() {
        let a = Axis::new(0.0, 1.25, false, 300.0, Y_LABEL_GAP);
        assert_eq!(labels(&a)[..3], ["0.0", "0.2", "0.4"]);
        assert_eq!(power_label(2e-5), "2×10⁻⁵");
        assert_eq!(power_label(1e6), "10⁶");
    }
}
