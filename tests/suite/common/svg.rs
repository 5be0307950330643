//! Reads what a reader sees in an SVG figure written by vibrobed (plotters' SVG: one element per
//! line of attributes) and checks it against the bar every figure must meet: each plotting area
//! has at least two tick labels on each axis, which do not overlap; each axis has a description
//! with its unit in parentheses; every legend lies outside every plotting area; every data point
//! lies inside a plotting area (or is a legend's key).

use vibrobed::studies::figure::{LEGEND_FRAME, PLOT_BACKGROUND};

/// A `<text>` element.
#[derive(Debug, Clone)]
pub struct Text {
    pub x: f64,
    pub y: f64,
    pub anchor: String,
    pub size: f64,
    pub rotated: bool,
    pub content: String,
}

/// A rectangle `(x, y, width, height)`.
pub type Rect = (f64, f64, f64, f64);

/// The elements a check needs.
#[derive(Debug, Default)]
pub struct Figure {
    pub texts: Vec<Text>,
    /// Plotting areas (rectangles filled with [`PLOT_BACKGROUND`]).
    pub plots: Vec<Rect>,
    /// Legend frames (rectangles stroked with [`LEGEND_FRAME`]).
    pub legends: Vec<Rect>,
    /// Centres of circles and polygons (the data markers; legend keys too).
    pub marks: Vec<(f64, f64)>,
}

fn attr(tag: &str, name: &str) -> Option<String> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let end = tag[start..].find('"')? + start;
    Some(tag[start..end].to_owned())
}

fn num(tag: &str, name: &str) -> f64 {
    attr(tag, name)
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN)
}

/// A colour as plotters writes it in SVG, `#RRGGBB`.
fn hex((r, g, b): (u8, u8, u8)) -> String {
    format!("#{r:02X}{g:02X}{b:02X}")
}

fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// Parses the SVG text `svg`.
pub fn parse(svg: &str) -> Figure {
    let mut f = Figure::default();
    let (p, l) = (PLOT_BACKGROUND, LEGEND_FRAME);
    let (plot_fill, legend_stroke) = (hex((p.0, p.1, p.2)), hex((l.0, l.1, l.2)));
    let mut rest = svg;
    while let Some(i) = rest.find('<') {
        rest = &rest[i..];
        let end = rest.find('>').map_or(rest.len(), |e| e + 1);
        let tag = &rest[..end];
        if tag.starts_with("<text") {
            let close = rest.find("</text>").unwrap_or(rest.len());
            f.texts.push(Text {
                x: num(tag, "x"),
                y: num(tag, "y"),
                anchor: attr(tag, "text-anchor").unwrap_or_default(),
                size: num(tag, "font-size"),
                rotated: attr(tag, "transform").is_some(),
                content: unescape(rest[end..close].trim()),
            });
        } else if tag.starts_with("<rect") {
            let r = (
                num(tag, "x"),
                num(tag, "y"),
                num(tag, "width"),
                num(tag, "height"),
            );
            if attr(tag, "fill").as_deref() == Some(plot_fill.as_str()) {
                f.plots.push(r);
            }
            if attr(tag, "stroke").as_deref() == Some(legend_stroke.as_str()) {
                f.legends.push(r);
            }
        } else if tag.starts_with("<circle") {
            f.marks.push((num(tag, "cx"), num(tag, "cy")));
        } else if tag.starts_with("<polygon") {
            let pts: Vec<(f64, f64)> = attr(tag, "points")
                .unwrap_or_default()
                .split_whitespace()
                .filter_map(|p| p.split_once(','))
                .filter_map(|(x, y)| Some((x.parse().ok()?, y.parse().ok()?)))
                .collect();
            let n = pts.len().max(1) as f64;
            let c = pts.iter().fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
            f.marks.push((c.0 / n, c.1 / n));
        }
        rest = &rest[end..];
    }
    f
}

/// Whether `s` is a tick label: a number, possibly written as a power of ten (`10⁻³`, `2×10⁴`).
pub fn is_number(s: &str) -> bool {
    let plain: String = s
        .chars()
        .map(|c| match c {
            '⁰'..='⁹' | '¹' | '²' | '³' | '⁻' | '×' => 'e',
            c => c,
        })
        .collect();
    !s.is_empty()
        && (s.parse::<f64>().is_ok()
            || (plain.starts_with("10e") || plain.contains("e10e"))
                && s.chars().next().is_some_and(|c| c.is_ascii_digit()))
}

fn inside((x, y): (f64, f64), (rx, ry, w, h): Rect, pad: f64) -> bool {
    x >= rx - pad && x <= rx + w + pad && y >= ry - pad && y <= ry + h + pad
}

fn overlap(a: Rect, b: Rect) -> bool {
    a.0 < b.0 + b.2 && b.0 < a.0 + a.2 && a.1 < b.1 + b.3 && b.1 < a.1 + a.3
}

/// Estimated width of a text in pixels (no font metrics: 0.6 em a character).
fn width(t: &Text) -> f64 {
    t.content.chars().count() as f64 * t.size * 0.6
}

/// The tick labels of plotting area `p`: (labels left of it, labels under it).
pub fn tick_labels(f: &Figure, p: Rect) -> (Vec<&Text>, Vec<&Text>) {
    let (x, y, w, h) = p;
    let numbers = f
        .texts
        .iter()
        .filter(|t| !t.rotated && is_number(&t.content));
    let left = numbers
        .clone()
        .filter(|t| t.anchor == "end" && t.x <= x && t.x >= x - 60.0)
        .filter(|t| t.y >= y - 2.0 && t.y <= y + h + 2.0)
        .collect();
    let under = numbers
        .filter(|t| t.anchor == "middle" && t.y >= y + h && t.y <= y + h + 30.0)
        .filter(|t| t.x >= x - 2.0 && t.x <= x + w + 2.0)
        .collect();
    (left, under)
}

/// Checks a figure against the bar; panics naming what fails. `panels` is how many plotting
/// areas the figure must have.
pub fn check(svg: &str, panels: usize) {
    let f = parse(svg);
    assert_eq!(f.plots.len(), panels, "plotting areas: {:?}", f.plots);
    assert!(!f.legends.is_empty(), "no legend");
    for &p in &f.plots {
        let (left, under) = tick_labels(&f, p);
        let show = |v: &[&Text]| v.iter().map(|t| t.content.clone()).collect::<Vec<_>>();
        assert!(
            left.len() >= 2,
            "area {p:?}: y tick labels {:?}",
            show(&left)
        );
        assert!(
            under.len() >= 2,
            "area {p:?}: x tick labels {:?}",
            show(&under)
        );
        for pair in left.windows(2) {
            let gap = (pair[0].y - pair[1].y).abs();
            assert!(
                gap >= pair[0].size * 1.2,
                "y labels {:?} overlap",
                show(pair)
            );
        }
        for pair in under.windows(2) {
            let gap = (pair[0].x - pair[1].x).abs();
            let room = (width(pair[0]) + width(pair[1])) / 2.0;
            assert!(gap >= room, "x labels {:?} overlap", show(pair));
        }
        // Axis descriptions with a unit: one rotated left of the area, one under its labels.
        let described = |t: &&Text| t.content.contains('(') && t.content.ends_with(')');
        let y_desc =
            f.texts.iter().filter(described).any(|t| {
                t.rotated && t.x < p.0 && t.x > p.0 - 110.0 && t.y > p.1 && t.y < p.1 + p.3
            });
        assert!(y_desc, "area {p:?}: no y axis description with a unit");
        let x_desc = f.texts.iter().filter(described).any(|t| {
            !t.rotated && t.y > p.1 + p.3 && t.y < p.1 + p.3 + 70.0 && inside((t.x, p.1), p, 0.0)
        });
        assert!(x_desc, "area {p:?}: no x axis description with a unit");
        for &l in &f.legends {
            assert!(!overlap(p, l), "legend {l:?} over plotting area {p:?}");
        }
    }
    for &m in &f.marks {
        let placed = f.plots.iter().any(|&p| inside(m, p, 1.0))
            || f.legends.iter().any(|&l| inside(m, l, 0.0));
        assert!(
            placed,
            "a point at {m:?} lies outside every plotting area and legend"
        );
    }
}
