//! The engine's clock: a local time that restarts at every mapping, an epoch summed with
//! compensation, and phases and periodic coordinates kept reduced.

/// The absolute time of the engine's local clock zero, summed with compensation (Neumaier) so
/// that millions of re-basings add no drift: absolute = `hi + (lo + local)`.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub(super) struct Epoch {
    pub(super) hi: f64,
    pub(super) lo: f64,
}

impl Epoch {
    /// Moves the epoch forward by `dt`.
    pub(super) fn advance(&mut self, dt: f64) {
        let sum = self.hi + dt;
        let err = if self.hi.abs() >= dt.abs() {
            (self.hi - sum) + dt
        } else {
            (dt - sum) + self.hi
        };
        self.hi = sum;
        self.lo += err;
    }

    /// Absolute time of local time `local`.
    #[inline]
    pub(super) fn absolute(&self, local: f64) -> f64 {
        self.hi + (self.lo + local)
    }

    /// Local time of absolute time `t`.
    #[inline]
    pub(super) fn local(&self, t: f64) -> f64 {
        (t - self.hi) - self.lo
    }
}

/// `x` reduced into `[0, period)`. Within one period outside it (nearly always: positions
/// are brought back at events) by one addition or subtraction, which gives `rem_euclid`'s
/// result there (the remainder is exact, and so is `x − period` for `x` in `[period,
/// 2 period)`), but for the sign of a zero; farther by `rem_euclid`, a library remainder
/// several times as costly. Either can round up to `period` itself (`x + period` for the
/// smallest negative `x`), which becomes 0.
#[inline]
pub(super) fn into_period(x: f64, period: f64) -> f64 {
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

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

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
