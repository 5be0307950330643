//! How much of a disk's area lies in a cell: the exact split of each disk over the bins of the
//! height profiles (horizontal strips) and the cells of the 2D fields (rectangles), so that a
//! packing fraction never exceeds 1 (the cell covered whole) and the parts add up to the disk.

/// Area of a disk of radius `a` below a horizontal line at height `z` above its centre:
/// `a² (u √(1 − u²) + asin u + π/2)` with `u = z/a` clamped to [−1, 1].
pub(crate) fn area_below(z: f64, a: f64) -> f64 {
    let u = (z / a).clamp(-1.0, 1.0);
    a * a * (u * (1.0 - u * u).sqrt() + u.asin() + std::f64::consts::FRAC_PI_2)
}

/// Area of a disk of radius `a` in the quadrant `x < X, y < Y` (relative to its centre):
/// the columns left of `X` are whole chords `2s(x)` (s = √(a² − x²)) where `Y` lies above the
/// chord's top, `Y + s(x)` where it cuts the chord (|x| < c = √(a² − Y²)), nothing below.
pub(crate) fn area_below_left(x: f64, y: f64, a: f64) -> f64 {
    // ∫_{-a}^{u} s(x) dx: half the area of a disk left of a vertical line at u.
    let half = |u: f64| 0.5 * area_below(u, a);
    let c = (a * a - y * y).max(0.0).sqrt();
    let hi = x.min(c);
    let (cut, len) = if hi > -c {
        (half(hi) - half(-c), hi + c)
    } else {
        (0.0, 0.0)
    };
    if y >= 0.0 {
        2.0 * half(x) - (cut - y * len)
    } else {
        cut + y * len
    }
}

/// Area of a disk of radius `a` centred at `(cx, cy)` inside the rectangle `[x0, x1] × [y0, y1]`
/// (the fields split a disk over many rectangles at once from the corners they share).
#[cfg(test)]
pub(crate) fn area_in_rectangle(
    (cx, cy): (f64, f64),
    a: f64,
    [x0, x1]: [f64; 2],
    [y0, y1]: [f64; 2],
) -> f64 {
    let f = |x: f64, y: f64| area_below_left(x - cx, y - cy, a);
    (f(x1, y1) - f(x0, y1) - f(x1, y0) + f(x0, y0)).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn quadrants_and_rectangles_add_up() {
        let a = 0.5;
        // The four quadrants about the centre are a quarter each.
        assert!((area_below_left(0.0, 0.0, a) - 0.25 * PI * a * a).abs() < 1e-15);
        assert!((area_below_left(9.0, 9.0, a) - PI * a * a).abs() < 1e-15);
        assert_eq!(area_below_left(-9.0, 9.0, a), 0.0);
        assert_eq!(area_below_left(9.0, -9.0, a), 0.0);
        // A half plane is what the strip split gives.
        for y in [-0.4, -0.1, 0.0, 0.2, 0.45] {
            assert!((area_below_left(9.0, y, a) - area_below(y, a)).abs() < 1e-15);
        }
        // A grid of 0.3-cells over a disk off any grid line: the parts sum to the disk, and a
        // cell's part agrees with a fine count of points.
        let centre = (1.13, 0.71);
        let mut sum = 0.0;
        for i in 0..8 {
            for j in 0..6 {
                let (xs, ys) = (
                    [i as f64 * 0.3, (i + 1) as f64 * 0.3],
                    [j as f64 * 0.3, (j + 1) as f64 * 0.3],
                );
                let part = area_in_rectangle(centre, a, xs, ys);
                sum += part;
                let n = 400;
                let h = 0.3 / n as f64;
                let mut inside = 0usize;
                for p in 0..n {
                    for q in 0..n {
                        let x = xs[0] + (p as f64 + 0.5) * h - centre.0;
                        let y = ys[0] + (q as f64 + 0.5) * h - centre.1;
                        inside += usize::from(x * x + y * y < a * a);
                    }
                }
                assert!(
                    (part - inside as f64 * h * h).abs() < 2e-4,
                    "cell ({i}, {j}): {part}"
                );
            }
        }
        assert!((sum - PI * a * a).abs() < 1e-14, "{sum}");
    }
}
