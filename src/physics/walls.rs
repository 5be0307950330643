//! What bounds the domain at the sides and the top, as a single disk meets it: the side walls
//! (or periodic sides) and the lid (or an open or periodic top). The floor is
//! [`floor`](super::floor)'s.

use crate::physics::disks::Motion;
use crate::physics::flight::time_to_rise;
use crate::physics::restitution::CollisionLaw;

/// What bounds the domain in x.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SideBounds {
    /// Hard walls at x = 0 and x = `width`, with restitution `e`.
    Walls {
        /// Distance between the walls.
        width: f64,
        /// Normal restitution of the walls.
        e: f64,
    },
    /// Periodic in x with period `width`.
    Periodic {
        /// The period.
        width: f64,
    },
}

/// `x` reduced into `[0, period)`. Within one period outside it (nearly always: positions
/// are brought back at events) by one addition or subtraction, which gives `rem_euclid`'s
/// result there (the remainder is exact, and so is `x − period` for `x` in `[period,
/// 2 period)`), but for the sign of a zero; farther by `rem_euclid`, a library remainder
/// several times as costly. Either can round up to `period` itself (`x + period` for the
/// smallest negative `x`), which becomes 0.
#[inline]
pub fn into_period(x: f64, period: f64) -> f64 {
    let r = if (0.0..period).contains(&x) {
        return x;
    } else if (-period..0.0).contains(&x) {
        x + period
    } else if (period..2.0 * period).contains(&x) {
        x - period
    } else {
        x.rem_euclid(period)
    };
    if r >= period {
        0.0
    } else {
        r
    }
}

/// `d − period · round(d / period)` (rounding half away from zero), the separation `d` brought
/// to its nearest periodic image: the same value, bit for bit, without a call to libm's `round`
/// when `|d|` is less than 1.5 periods (the common case: positions within one period).
#[inline(always)]
pub fn nearest_image(d: f64, period: f64) -> f64 {
    let q = d / period;
    if q.abs() < 0.5 {
        d
    } else if q.abs() < 1.5 {
        // round(q) = ±1, and d − period · (±1) is exactly d ∓ period.
        if q > 0.0 {
            d - period
        } else {
            d + period
        }
    } else {
        d - period * q.round()
    }
}

/// Which side wall a disk hits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The wall at x = 0.
    Left,
    /// The wall at x = width.
    Right,
}

impl SideBounds {
    /// Width of the domain.
    pub fn width(&self) -> f64 {
        match *self {
            SideBounds::Walls { width, .. } | SideBounds::Periodic { width } => width,
        }
    }

    /// The gap between a disk of radius `a` at `x` and the side wall that the direction `dir`
    /// points to (left for `dir < 0`, else right); `None` where the sides are periodic.
    pub fn gap_to_wall(&self, x: f64, a: f64, dir: f64) -> Option<f64> {
        match *self {
            SideBounds::Walls { width, .. } => Some(if dir < 0.0 { x - a } else { width - x - a }),
            SideBounds::Periodic { .. } => None,
        }
    }

    /// Time until a disk of radius `a` at `x` moving with `vx` hits a side wall, if any.
    #[inline(always)]
    pub fn impact(&self, x: f64, vx: f64, a: f64) -> Option<(f64, Side)> {
        match *self {
            SideBounds::Periodic { .. } => None,
            SideBounds::Walls { width, .. } => {
                if vx < 0.0 {
                    Some((((x - a) / -vx).max(0.0), Side::Left))
                } else if vx > 0.0 {
                    Some((((width - a - x) / vx).max(0.0), Side::Right))
                } else {
                    None
                }
            }
        }
    }

    /// Disk `i` (state `m` at `now`, mass `mass`) hits wall `side`: the collision law says
    /// whether a cure makes the impact elastic, `m.vx` is reflected, and the kinetic energy lost
    /// is returned — the one place every scheme handles a wall impact.
    #[inline]
    pub fn hit(
        &self,
        side: Side,
        law: &mut CollisionLaw,
        i: usize,
        now: f64,
        m: &mut Motion,
        mass: f64,
    ) -> f64 {
        let elastic = law.boundary_elastic(i, now, m.vx.abs());
        let after = self.bounce(m.vx, side, elastic);
        rebound(&mut m.vx, after, mass)
    }

    /// Velocity after hitting a side wall (never pointing into the wall); `elastic` when a cure
    /// of inelastic collapse overrides the wall's restitution.
    #[inline]
    pub fn bounce(&self, vx: f64, side: Side, elastic: bool) -> f64 {
        let e = match *self {
            SideBounds::Walls { e, .. } if !elastic => e,
            _ => 1.0,
        };
        match side {
            Side::Left => (-e * vx).max(0.0),
            Side::Right => (-e * vx).min(0.0),
        }
    }
}

/// What bounds the domain at the top.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Top {
    /// No ceiling.
    Open,
    /// A hard wall at y = `height` with restitution `e`.
    Lid {
        /// Height of the lid.
        height: f64,
        /// Normal restitution of the lid.
        e: f64,
    },
    /// Periodic in y with period `height` (no floor).
    Periodic {
        /// The period.
        height: f64,
    },
}

impl Top {
    /// Time until a disk of radius `a` at height `y`, vertical speed `vy`, gravity `g`, hits the
    /// lid, if there is one and it gets there.
    #[inline(always)]
    pub fn impact(&self, y: f64, vy: f64, a: f64, g: f64) -> Option<f64> {
        match *self {
            Top::Lid { height, .. } => time_to_rise(height - a - y, vy, g),
            _ => None,
        }
    }

    /// Disk `i` (state `m` at `now`, mass `mass`) hits the lid: as [`SideBounds::hit`], for
    /// `m.vy`.
    #[inline]
    pub fn hit(
        &self,
        law: &mut CollisionLaw,
        i: usize,
        now: f64,
        m: &mut Motion,
        mass: f64,
    ) -> f64 {
        let elastic = law.boundary_elastic(i, now, m.vy);
        let after = self.bounce(m.vy, elastic);
        rebound(&mut m.vy, after, mass)
    }

    /// Vertical velocity after hitting the lid; `elastic` when a cure of inelastic collapse
    /// overrides the lid's restitution.
    #[inline]
    pub fn bounce(&self, vy: f64, elastic: bool) -> f64 {
        match *self {
            Top::Lid { e, .. } => (-if elastic { 1.0 } else { e } * vy).min(0.0),
            _ => vy,
        }
    }
}

/// Sets the velocity component `v` of a disk of mass `m` to `after` (a wall or lid rebound) and
/// returns the kinetic energy that lost.
#[inline]
fn rebound(v: &mut f64, after: f64, m: f64) -> f64 {
    let lost = 0.5 * m * (*v * *v - after * after);
    *v = after;
    lost
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn nearest_image_is_the_rounding_form_bit_for_bit() {
        let period = 7.3;
        let mut d = -30.0f64;
        while d < 30.0 {
            for x in [
                d,
                d.next_up(),
                d.next_down(),
                0.5 * period,
                -0.5 * period,
                1.5 * period,
                -1.5 * period,
            ] {
                let expected = x - period * (x / period).round();
                assert_eq!(
                    nearest_image(x, period).to_bits(),
                    expected.to_bits(),
                    "{x}"
                );
            }
            d += 0.0137;
        }
    }

    #[test]
    fn a_point_outside_the_period_comes_back_into_it() {
        assert_eq!(into_period(-0.25, 10.0), 9.75);
        assert_eq!(into_period(10.25, 10.0), 0.25);
        assert_eq!(into_period(3.0, 10.0), 3.0);
        assert_eq!(into_period(10.0, 10.0), 0.0);
        assert_eq!(into_period(-37.5, 10.0), 2.5);
        // The smallest negative x: x + period rounds to the period itself.
        let x = into_period(-1e-17, 10.0);
        assert!((0.0..10.0).contains(&x), "{x}");
    }

    /// The shortcut within one period outside gives `rem_euclid`'s result, bit for bit (but
    /// for the sign of a zero), near the period's ends and anywhere within three periods.
    #[test]
    fn the_shortcut_is_the_remainder() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        for _ in 0..200_000 {
            let period: f64 = rng.random_range(0.5..1e4);
            let x = match rng.random_range(0..4) {
                0 => rng.random_range(-3.0..3.0) * period,
                1 => -period * (1.0 - rng.random_range(0.0..1e-12)),
                2 => period * (2.0 - rng.random_range(0.0..1e-12)),
                _ => rng.random_range(-1e-12..1e-12) * period,
            };
            let r = x.rem_euclid(period);
            let want = if r >= period { 0.0 } else { r };
            let got = into_period(x, period);
            assert!(
                got == want,
                "x = {x:e}, period {period}: {got:e} against {want:e}"
            );
            assert!((0.0..period).contains(&got));
        }
    }
}
