//! Free flight between collisions: straight lines without gravity, parabolas with it.
//!
//! Each disk carries its own time stamp and is brought forward only when touched (lazy update).
//! Gravity is the same for all disks, so the *relative* motion of two disks is always straight:
//! pair collision times never see g. The engine is generic over [`Flight`], so a scene without
//! gravity pays nothing for it.

/// How a disk moves between collisions.
pub trait Flight: Copy + Send + Sync + std::fmt::Debug + 'static {
    /// Gravitational acceleration (pointing to −y); 0 for straight flight.
    fn g(&self) -> f64;

    /// State after flying for `dt`: `(x, y, vx, vy)`.
    fn advance(&self, x: f64, y: f64, vx: f64, vy: f64, dt: f64) -> (f64, f64, f64, f64);

    /// Position after flying for `dt`.
    #[inline(always)]
    fn position(&self, x: f64, y: f64, vx: f64, vy: f64, dt: f64) -> (f64, f64) {
        let (x, y, _, _) = self.advance(x, y, vx, vy, dt);
        (x, y)
    }
}

/// Straight flight: `r(t) = r0 + v0 t`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Straight;

impl Flight for Straight {
    #[inline(always)]
    fn g(&self) -> f64 {
        0.0
    }
    #[inline(always)]
    fn advance(&self, x: f64, y: f64, vx: f64, vy: f64, dt: f64) -> (f64, f64, f64, f64) {
        (x + vx * dt, y + vy * dt, vx, vy)
    }
}

/// Ballistic flight under gravity g along −y: `r(t) = r0 + v0 t + ½ g t²`, `v(t) = v0 + g t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ballistic {
    /// Gravitational acceleration (> 0).
    pub g: f64,
}

impl Flight for Ballistic {
    #[inline(always)]
    fn g(&self) -> f64 {
        self.g
    }
    #[inline(always)]
    fn advance(&self, x: f64, y: f64, vx: f64, vy: f64, dt: f64) -> (f64, f64, f64, f64) {
        (
            x + vx * dt,
            y + (vy - 0.5 * self.g * dt) * dt,
            vx,
            vy - self.g * dt,
        )
    }
}

/// Earliest `t ≥ 0` at which a body at height `h ≥ 0` above a plane, moving with vertical speed
/// `vy` under gravity `g ≥ 0` (towards the plane), reaches the plane: the root of
/// `h + vy t − ½ g t² = 0`. `None` if it never does. Round-off (h slightly negative while
/// approaching) gives 0, never a negative time.
#[inline]
pub fn time_to_fall(h: f64, vy: f64, g: f64) -> Option<f64> {
    if h <= 0.0 {
        // Touching or slightly past the plane: an impact now if moving towards it.
        if vy <= 0.0 {
            return Some(0.0);
        }
        if g <= 0.0 {
            return None;
        }
        // Moving away; comes back after (vy + √(vy² + 2 g h))/g.
        let d = (vy * vy + 2.0 * g * h).max(0.0);
        return Some((vy + d.sqrt()) / g);
    }
    if g <= 0.0 {
        return if vy < 0.0 { Some(h / -vy) } else { None };
    }
    let d = vy * vy + 2.0 * g * h;
    let sd = d.sqrt();
    Some(if vy > 0.0 {
        (vy + sd) / g
    } else {
        2.0 * h / (sd - vy)
    })
}

/// Earliest `t ≥ 0` at which a body `h ≥ 0` below a plane, moving up with `vy` under gravity `g`,
/// reaches it: the first root of `h − vy t + ½ g t² = 0`; `None` if it turns back before.
#[inline]
pub fn time_to_rise(h: f64, vy: f64, g: f64) -> Option<f64> {
    if vy <= 0.0 {
        return None;
    }
    if h <= 0.0 {
        return Some(0.0);
    }
    let d = vy * vy - 2.0 * g * h;
    if d < 0.0 {
        return None;
    }
    Some(2.0 * h / (vy + d.sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parabola_matches_closed_form() {
        let b = Ballistic { g: 9.81 };
        let (x, y, vx, vy) = b.advance(1.0, 2.0, 0.5, 3.0, 0.7);
        assert!((x - (1.0 + 0.5 * 0.7)).abs() < 1e-15);
        assert!((y - (2.0 + 3.0 * 0.7 - 0.5 * 9.81 * 0.49)).abs() < 1e-14);
        assert_eq!(vx, 0.5);
        assert!((vy - (3.0 - 9.81 * 0.7)).abs() < 1e-15);
    }

    #[test]
    fn fall_and_rise_times_solve_their_equations() {
        for &(h, vy, g) in &[
            (1.0, 0.0, 1.0),
            (2.0, 3.0, 1.0),
            (0.5, -2.0, 9.8),
            (3.0, -1.0, 0.0),
        ] {
            let t = time_to_fall(h, vy, g).unwrap();
            assert!(t >= 0.0);
            assert!((h + vy * t - 0.5 * g * t * t).abs() < 1e-12, "{h} {vy} {g}");
        }
        assert_eq!(time_to_fall(1.0, 1.0, 0.0), None);
        assert_eq!(time_to_fall(-1e-18, -1.0, 1.0), Some(0.0));
        let t = time_to_rise(1.0, 2.0, 1.0).unwrap();
        assert!((1.0 - 2.0 * t + 0.5 * t * t).abs() < 1e-12);
        assert_eq!(time_to_rise(3.0, 2.0, 1.0), None);
    }
}
