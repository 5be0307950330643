//! How the recording looks: the colours of species, speeds, walls and profiles, and the labels
//! of ticks and of the clock.

use super::*;

/// Colours of species 0, 1, … (cycled), also used for the annotation context.
pub(super) const SPECIES_PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];
pub(super) const WALL_COLOR: [u8; 3] = [170, 170, 170];
pub(super) const EDGE_COLOR: [u8; 3] = [90, 90, 90];
pub(super) const FLOOR_COLOR: [u8; 3] = [230, 140, 30];
pub(super) const AXIS_COLOR: [u8; 3] = [150, 150, 150];
pub(super) const PACKING_COLOR: [u8; 3] = [80, 170, 255];
pub(super) const TEMPERATURE_COLOR: [u8; 3] = [255, 110, 80];
pub(super) const CLOCK_COLOR: [u8; 3] = [230, 230, 230];
/// Rough disks' radius lines: dark on every colour of the disks.
pub(super) const ORIENTATION_COLOR: [u8; 3] = [25, 25, 25];
/// Half the width of a radius line, in units of the smallest disk radius.
pub(super) const ORIENTATION_HALF_WIDTH: f64 = 0.08;
/// Width of a profile view in units of its height range (its values are stretched to it).
pub(super) const PROFILE_ASPECT: f64 = 0.6;

pub(super) fn rgb(c: [u8; 3]) -> Color {
    Color::from_rgb(c[0], c[1], c[2])
}

/// Blue (at rest) → light grey → red (`t` ≥ 1), `t` = speed / scale, clamped ("coolwarm").
pub fn speed_color(t: f64) -> Color {
    const STOPS: [[f64; 3]; 3] = [
        [59.0, 76.0, 192.0],
        [221.0, 221.0, 221.0],
        [180.0, 4.0, 38.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let (a, b, s) = if t < 0.5 {
        (STOPS[0], STOPS[1], t * 2.0)
    } else {
        (STOPS[1], STOPS[2], t * 2.0 - 1.0)
    };
    let mix = |i: usize| (a[i] + (b[i] - a[i]) * s).round() as u8;
    Color::from_rgb(mix(0), mix(1), mix(2))
}

/// The same diverging map centred on zero, `s` = rim speed ω a / scale: blue turning
/// clockwise (`s` ≤ −1) → light grey not turning → red anticlockwise (`s` ≥ 1).
pub fn spin_color(s: f64) -> Color {
    speed_color(0.5 + 0.5 * s)
}

/// The radius line of a disk of radius `a` centred at `(x, y)` and turned by `angle`: from the
/// centre to the point of its rim at that angle (anticlockwise from +x), in f32 as logged.
pub fn orientation_line(x: f64, y: f64, a: f64, angle: f64) -> [[f32; 2]; 2] {
    let (sin, cos) = angle.sin_cos();
    line([[x, y], [x + a * cos, y + a * sin]])
}

pub(super) fn line(points: [[f64; 2]; 2]) -> [[f32; 2]; 2] {
    points.map(|[x, y]| [x as f32, y as f32])
}

pub(super) fn tick_label(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// A "nice" axis end at or above `v` (1, 2, 2.5 or 5 times a power of ten).
pub(super) fn nice_ceiling(v: f64) -> f64 {
    if !(v.is_finite() && v > 0.0) {
        return 1.0;
    }
    let p = 10f64.powf(v.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|&c| c >= v * (1.0 - 1e-12))
        .unwrap_or(10.0 * p)
}

/// The clock's label for simulated time `time`: `t = 137`, `t = 0.45`, with the digits that tell
/// frames `step` apart (one more than the step's first significant digit), trailing zeros
/// dropped; three decimals when the step is not known (the first frame).
pub fn clock_label(time: f64, step: Option<f64>) -> String {
    let decimals = step
        .filter(|s| s.is_finite() && *s > 0.0)
        .map_or(3, |s| ((-s.log10()).ceil() as i64 + 1).clamp(0, 9) as usize);
    let s = format!("{time:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    format!("t = {}", if s == "-0" { "0" } else { s })
}
