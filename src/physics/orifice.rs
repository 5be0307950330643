//! The floor's orifice: a gap in a static floor at height 0 from x = `from` to x = `to`. Its two
//! edges are corners, points the disks collide with (elastic and smooth); the flat floor holds
//! only disks whose centres are not over the gap; a disk that falls wholly below the floor
//! (its centre at −a) leaves the scene.
//!
//! Under gravity the squared distance from a flying disk's centre to a corner is a quartic in
//! time; its first root is found exactly (to the last bits) by isolating the roots through the
//! derivatives and bisecting on each monotone piece.

/// A gap in the floor between two corners at height 0.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Orifice {
    /// Left corner's x.
    pub from: f64,
    /// Right corner's x.
    pub to: f64,
}

impl Orifice {
    /// `true` if a centre at `x` lies over the gap, edges included: the flat floor holds only
    /// centres strictly beside it (at an edge the corner gives the same vertical contact, and a
    /// disk leaving the floor there must not land on it again at once).
    #[inline]
    pub fn over_gap(&self, x: f64) -> bool {
        x >= self.from && x <= self.to
    }
}

/// A polynomial of degree at most 4, `c[0] + c[1] t + …`.
#[derive(Debug, Clone, Copy)]
struct Poly {
    c: [f64; 5],
    degree: usize,
}

impl Poly {
    #[inline]
    fn at(&self, t: f64) -> f64 {
        let mut v = 0.0;
        for k in (0..=self.degree).rev() {
            v = v * t + self.c[k];
        }
        v
    }

    fn derivative(&self) -> Poly {
        let mut c = [0.0; 5];
        for k in 1..=self.degree {
            c[k - 1] = k as f64 * self.c[k];
        }
        Poly {
            c,
            degree: self.degree.saturating_sub(1),
        }
    }
}

/// The points of `[t0, t1]` where `p` changes its direction (roots of its derivative, in
/// order), with `t0` and `t1` themselves: `p` is monotone between consecutive points. At most 6
/// points for degree ≤ 4.
fn monotone_pieces(p: &Poly, t0: f64, t1: f64) -> ([f64; 6], usize) {
    let mut pts = [t0; 6];
    let mut n = 1;
    if p.degree >= 2 {
        let d = p.derivative();
        let (inner, m) = monotone_pieces(&d, t0, t1);
        for w in inner[..m].windows(2) {
            let (a, b) = (w[0], w[1]);
            let (fa, fb) = (d.at(a), d.at(b));
            if (fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0) {
                pts[n] = bisect(&d, a, b, fa < 0.0);
                n += 1;
            }
        }
    }
    pts[n] = t1;
    (pts, n + 1)
}

/// The root of monotone `p` in `[a, b]` where it changes sign (`rising`: from − to +), to the
/// last bit: the last point on the side of `p(a)`.
fn bisect(p: &Poly, mut a: f64, mut b: f64, rising: bool) -> f64 {
    for _ in 0..2100 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let below = p.at(m) < 0.0;
        if below == rising {
            a = m;
        } else {
            b = m;
        }
    }
    a
}

/// The first time `t` in `[0, limit]` at which a disk of radius `a`, its centre at `(dx, dy)`
/// from a corner now with velocity `(vx, vy)` under gravity `g`, touches the corner while
/// approaching it. The disk is taken to touch from outside: a contact at `t = 0` counts only if
/// it approaches then. Returns the last time before the contact to round-off (the disk never
/// overlaps the corner at the returned time beyond round-off).
pub fn corner_contact(
    (dx, dy): (f64, f64),
    (vx, vy): (f64, f64),
    g: f64,
    a: f64,
    limit: f64,
) -> Option<f64> {
    // A cheap necessary condition first: within `limit` the centre must come within `a` of the
    // corner in x (linear) and in y (a parabola that is concave).
    let (t_lo, t_hi) = window_x(dx, vx, a, limit)?;
    let (t_lo, t_hi) = window_y(dy, vy, g, a, t_lo, t_hi)?;
    let f = Poly {
        c: [
            dx * dx + dy * dy - a * a,
            2.0 * (dx * vx + dy * vy),
            vx * vx + vy * vy - g * dy,
            -g * vy,
            0.25 * g * g,
        ],
        degree: if g != 0.0 { 4 } else { 2 },
    };
    let start = if t_lo > 0.0 { t_lo } else { 0.0 };
    // No root lies beyond Cauchy's bound of the quartic (under gravity the disk falls away).
    let t_hi = if g != 0.0 {
        let c4 = 0.25 * g * g;
        let bound = 1.0
            + [
                dx * dx + dy * dy - a * a,
                2.0 * (dx * vx + dy * vy),
                vx * vx + vy * vy - g * dy,
                g * vy,
            ]
            .iter()
            .fold(0.0f64, |m, c| m.max(c.abs() / c4));
        t_hi.min(bound)
    } else {
        t_hi
    };
    if !(t_hi.is_finite() && start <= t_hi) {
        return None;
    }
    let (pts, n) = monotone_pieces(&f, start, t_hi);
    for (k, w) in pts[..n].windows(2).enumerate() {
        let (p, q) = (w[0], w[1]);
        let (fp, fq) = (f.at(p), f.at(q));
        if fq < fp && fp <= 0.0 && k == 0 && start == 0.0 {
            // Touching (or a hair inside through round-off) and approaching: contact now.
            return Some(0.0);
        }
        // A window that starts inside its cheap bounds starts outside the contact.
        let outside = fp > 0.0 || (k == 0 && start > 0.0 && fp >= 0.0);
        if outside && fq <= 0.0 {
            return Some(bisect(&f, p, q, false));
        }
    }
    None
}

/// The times in `[0, limit]` at which `|dx + vx t| ≤ a`, if any.
fn window_x(dx: f64, vx: f64, a: f64, limit: f64) -> Option<(f64, f64)> {
    if vx == 0.0 {
        return (dx.abs() <= a).then_some((0.0, limit));
    }
    let (t1, t2) = ((-a - dx) / vx, (a - dx) / vx);
    let (lo, hi) = (t1.min(t2).max(0.0), t1.max(t2).min(limit));
    (lo <= hi).then_some((lo, hi))
}

/// The part of `[t0, t1]` from the first time at which `dy + vy t − ½ g t² ≤ a` on (the
/// parabola is concave, so the set is at most two rays; the first one that meets the window
/// starts it, and the window's end is kept).
fn window_y(dy: f64, vy: f64, g: f64, a: f64, t0: f64, t1: f64) -> Option<(f64, f64)> {
    let y = |t: f64| dy + vy * t - 0.5 * g * t * t;
    if y(t0) <= a {
        return Some((t0, t1));
    }
    // y(t0) > a: the first later time y = a is the larger root of the downward crossing.
    let disc = vy * vy + 2.0 * g * (dy - a);
    if g <= 0.0 || disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    let down = if vy >= 0.0 {
        (vy + s) / g
    } else {
        2.0 * (dy - a) / (s - vy)
    };
    // Round-off can put the crossing a hair early: start the window a little before.
    let from = (down * (1.0 - 1e-12)).max(t0);
    (from <= t1).then_some((from, t1))
}

/// The time from now at which a disk at height `y` rising at `vy` under gravity `g` has its
/// centre at `−a` (wholly below the floor at 0), if it gets there (`g > 0`: it does).
pub fn time_below(y: f64, vy: f64, g: f64, a: f64) -> Option<f64> {
    let h = y + a;
    if h <= 0.0 {
        return Some(0.0);
    }
    if g <= 0.0 {
        return (vy < 0.0).then(|| h / -vy);
    }
    let s = (vy * vy + 2.0 * g * h).sqrt();
    Some(if vy >= 0.0 {
        (vy + s) / g
    } else {
        2.0 * h / (s - vy)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_disk_dropped_on_a_corner_touches_it_when_its_centre_is_a_above() {
        // Centre straight above the corner, at rest, 3 above it: contact at y = a.
        let (g, a) = (1.0, 0.5);
        let t = corner_contact((0.0, 3.0), (0.0, 0.0), g, a, f64::INFINITY).unwrap();
        let exact = (2.0f64 * (3.0 - a) / g).sqrt();
        assert!(
            (t - exact).abs() <= 4.0 * f64::EPSILON * exact,
            "{t} vs {exact}"
        );
    }

    #[test]
    fn an_oblique_fall_meets_the_corner_where_the_distance_is_the_radius() {
        // Centre 0.3 to the left of the corner and 2 above, drifting right: the contact is
        // where the parabola first comes within a of the corner; the distance there is a.
        let (g, a) = (2.0, 0.5);
        let (dx, dy, vx, vy) = (-0.3, 2.0, 0.1, 0.4);
        let t = corner_contact((dx, dy), (vx, vy), g, a, f64::INFINITY).unwrap();
        let at = |t: f64| {
            let (x, y) = (dx + vx * t, dy + vy * t - 0.5 * g * t * t);
            (x * x + y * y).sqrt()
        };
        assert!((at(t) - a).abs() < 1e-14, "distance {}", at(t));
        // Never closer before: sample the path.
        for k in 0..10_000 {
            let s = t * k as f64 / 10_000.0;
            assert!(at(s) >= a * (1.0 - 1e-14), "closer at {s}");
        }
    }

    #[test]
    fn a_disk_missing_the_corner_has_no_contact_and_one_leaving_it_none_at_once() {
        // Falls 0.6 to the right of the corner (a = 0.5): it passes.
        assert_eq!(
            corner_contact((0.6, 2.0), (0.0, 0.0), 1.0, 0.5, f64::INFINITY),
            None
        );
        // Touching and moving away (just bounced): no contact at t = 0; under gravity it comes
        // back down only if it is over the corner, which it is not after drifting right.
        let t = corner_contact((0.3, 0.4), (2.0, 1.0), 1.0, 0.5, f64::INFINITY);
        assert!(t.is_none_or(|t| t > 0.0), "{t:?}");
        // Touching and approaching: contact now.
        assert_eq!(
            corner_contact((0.3, 0.4), (-1.0, -1.0), 1.0, 0.5, f64::INFINITY),
            Some(0.0)
        );
    }

    #[test]
    fn a_bounce_straight_up_off_the_corner_comes_back_after_its_flight() {
        // On top of the corner moving up at 1: back down after 2 vy / g.
        let t = corner_contact((0.0, 0.5), (0.0, 1.0), 1.0, 0.5, f64::INFINITY).unwrap();
        assert!((t - 2.0).abs() < 1e-12, "{t}");
    }

    #[test]
    fn time_below_is_the_root_of_the_parabola() {
        let (y, vy, g, a) = (0.2, 0.3, 1.5, 0.5);
        let t = time_below(y, vy, g, a).unwrap();
        let at = y + vy * t - 0.5 * g * t * t;
        assert!((at + a).abs() < 1e-15, "{at}");
        assert_eq!(time_below(-0.6, 0.0, 1.0, 0.5), Some(0.0));
    }
}
