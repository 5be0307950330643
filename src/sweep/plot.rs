//! The sweep's plot: one panel per summary field, its mean over seeds against a sweep axis, with
//! error bars of one standard error and, when asked, the fitted power law.

use crate::error::{Error, Result};
use crate::sweep::collect::Stat;
use crate::sweep::fit::PowerFit;
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

/// A tick label: up to four decimals without trailing zeros, or an exponent for tiny and huge
/// values.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-3..1e5).contains(&a) {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".into()
        } else {
            s.into()
        }
    } else {
        format!("{v:.2e}")
    }
}

/// Draws the panels stacked vertically into an SVG file at `path`.
pub fn draw(
    path: &Path,
    title: &str,
    x_name: &str,
    panels: &[Panel],
    log_x: bool,
    log_y: bool,
) -> Result<()> {
    use plotters::coord::combinators::IntoLogRange;
    use plotters::prelude::*;
    let err = |e: String| Error::Io(format!("cannot draw {}: {e}", path.display()));
    let height = 60 + 380 * panels.len() as u32;
    let root = SVGBackend::new(path, (760, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let root = root
        .titled(title, ("sans-serif", 20))
        .map_err(|e| err(e.to_string()))?;
    let areas = root.split_evenly((panels.len().max(1), 1));
    let blue = RGBColor(31, 119, 180);
    let red = RGBColor(214, 39, 40);
    for (panel, area) in panels.iter().zip(&areas) {
        let pts: Vec<(f64, f64, f64)> = panel
            .series
            .iter()
            .map(|(x, s)| (*x, s.mean, s.se.unwrap_or(0.0)))
            .filter(|(x, y, _)| x.is_finite() && y.is_finite())
            .filter(|(x, y, _)| (!log_x || *x > 0.0) && (!log_y || *y > 0.0))
            .collect();
        if pts.is_empty() {
            area.draw(&Text::new(
                format!("{}: no completed runs to plot", panel.field),
                (20, 40),
                ("sans-serif", 16),
            ))
            .map_err(|e| err(e.to_string()))?;
            continue;
        }
        let fold = |f: &dyn Fn(&(f64, f64, f64)) -> f64| {
            pts.iter()
                .map(f)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(v), b.max(v))
                })
        };
        let (x0, x1) = fold(&|p| p.0);
        let (y0, _) = fold(&|p| if log_y { p.1 } else { p.1 - p.2 });
        let (_, y1) = fold(&|p| p.1 + p.2);
        let (x0, x1) = padded(x0, x1, log_x);
        let (y0, y1) = padded(y0, y1, log_y);
        let caption = match panel.fit {
            Some(f) => format!(
                "{}: fit ∝ x^δ, δ = {:.3}{}",
                panel.field,
                f.exponent,
                f.exponent_se
                    .map_or(String::new(), |se| format!(" ± {se:.3}"))
            ),
            None => panel.field.to_string(),
        };
        let mut builder = ChartBuilder::on(area);
        builder
            .caption(caption, ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70);
        // Four combinations of linear and log axes: one generic body.
        macro_rules! body {
            ($xr:expr, $yr:expr) => {{
                let mut chart = builder
                    .build_cartesian_2d($xr, $yr)
                    .map_err(|e| err(e.to_string()))?;
                chart
                    .configure_mesh()
                    .x_desc(x_name)
                    .y_desc(panel.field)
                    .x_label_formatter(&|v| tick(*v))
                    .y_label_formatter(&|v| tick(*v))
                    .draw()
                    .map_err(|e| err(e.to_string()))?;
                if let Some(f) = panel.fit {
                    let k = 50;
                    let line: Vec<(f64, f64)> = (0..=k)
                        .map(|i| {
                            let u = i as f64 / k as f64;
                            let x = if log_x {
                                x0 * (x1 / x0).powf(u)
                            } else {
                                x0 + (x1 - x0) * u
                            };
                            (x, f.at(x))
                        })
                        .filter(|(_, y)| *y >= y0 && *y <= y1)
                        .collect();
                    chart
                        .draw_series(LineSeries::new(line, red.stroke_width(1)))
                        .map_err(|e| err(e.to_string()))?
                        .label("power-law fit")
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], red));
                }
                chart
                    .draw_series(pts.iter().map(|&(x, y, se)| {
                        let lo = if log_y { (y - se).max(y0) } else { y - se };
                        ErrorBar::new_vertical(x, lo, y, y + se, blue.stroke_width(1), 8)
                    }))
                    .map_err(|e| err(e.to_string()))?;
                chart
                    .draw_series(
                        pts.iter()
                            .map(|&(x, y, _)| Circle::new((x, y), 3, blue.filled())),
                    )
                    .map_err(|e| err(e.to_string()))?
                    .label("mean over seeds ± standard error")
                    .legend(move |(x, y)| Circle::new((x + 10, y), 3, blue.filled()));
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperLeft)
                    .border_style(BLACK.mix(0.3))
                    .background_style(WHITE.mix(0.8))
                    .label_font(("sans-serif", 12))
                    .draw()
                    .map_err(|e| err(e.to_string()))?;
            }};
        }
        match (log_x, log_y) {
            (false, false) => body!(x0..x1, y0..y1),
            (true, false) => body!((x0..x1).log_scale(), y0..y1),
            (false, true) => body!(x0..x1, (y0..y1).log_scale()),
            (true, true) => body!((x0..x1).log_scale(), (y0..y1).log_scale()),
        }
    }
    root.present().map_err(|e| err(e.to_string()))?;
    Ok(())
}
