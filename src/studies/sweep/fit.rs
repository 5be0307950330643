//! A power law y = c·x^δ (or y − y₀ = c·x^δ) fitted to a sweep's point means by least squares
//! on (ln x, ln (y − y₀)), over an x range if asked, with the exponent's error from the scatter
//! about the line and from the seeds (a bootstrap over each point's runs).

use rand::{Rng, SeedableRng};
use serde::Serialize;

/// The fitted power law and the standard error of its exponent.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PowerFit {
    /// Exponent δ (the slope on log–log axes).
    pub exponent: f64,
    /// Standard error of δ from the scatter of the points about the line,
    /// √(Σ r² / (n − p) / Σ (ln x − mean)²) for p fitted parameters (2; 3 with a fitted
    /// offset, the error then taken at that offset); absent with p points or fewer.
    pub exponent_se: Option<f64>,
    /// Prefactor c.
    pub prefactor: f64,
    /// Number of points fitted.
    pub points: usize,
    /// The offset y₀ taken off y before the fit (given, or fitted), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset: Option<f64>,
    /// Standard error of δ from the seeds: the spread of δ over fits to bootstrap resamples of
    /// each point's runs, a fitted offset fitted again to each (absent without two runs at some
    /// point).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exponent_seed_se: Option<f64>,
}

impl PowerFit {
    /// y = y₀ + c·x^δ at x.
    pub fn at(&self, x: f64) -> f64 {
        self.offset.unwrap_or(0.0) + self.prefactor * x.powf(self.exponent)
    }
}

/// The offset y₀ of a fit of y − y₀ = c·x^δ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Offset {
    /// A value given (e.g. the bed's height at rest, for the centre of mass's rise).
    Given(f64),
    /// Fitted: the y₀ below every point that leaves the least squares of y about the curve.
    Fitted,
}

/// How to fit: the x range kept and the offset.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FitOptions {
    /// Only points with x in [lo, hi].
    pub range: Option<(f64, f64)>,
    /// The offset taken off y (none: y itself).
    pub offset: Option<Offset>,
}

/// Resamples of the seeds for the exponent's error, and the generator's seed (fixed: the same
/// sweep gives the same error).
const BOOTSTRAP: usize = 1000;
const BOOTSTRAP_SEED: u64 = 0x05ee_df17;

/// Fits y − y₀ = c·x^δ to points given as (x, the values of each of the point's runs), their
/// means fitted; the exponent's seed error by a bootstrap over each point's runs (a fitted
/// offset fitted again to each resample). None as for [`power_law`].
pub fn fit(points: &[(f64, Vec<f64>)], options: FitOptions) -> Option<PowerFit> {
    let kept: Vec<&(f64, Vec<f64>)> = points
        .iter()
        .filter(|(x, v)| {
            !v.is_empty() && options.range.is_none_or(|(lo, hi)| (lo..=hi).contains(x))
        })
        .collect();
    let means: Vec<(f64, f64)> = kept.iter().map(|(x, v)| (*x, mean(v))).collect();
    // The power law of means less the offset, the offset fitted to them if asked.
    let fitted = |m: &[(f64, f64)]| -> Option<PowerFit> {
        let y0 = match options.offset {
            None => None,
            Some(Offset::Given(y0)) => Some(y0),
            Some(Offset::Fitted) => Some(fitted_offset(m)?),
        };
        let shifted: Vec<(f64, f64)> = m.iter().map(|(x, y)| (*x, y - y0.unwrap_or(0.0))).collect();
        let mut f = power_law(&shifted)?;
        f.offset = y0;
        Some(f)
    };
    let mut f = fitted(&means)?;
    if options.offset == Some(Offset::Fitted) {
        // One more parameter: n − 3 degrees of freedom for the scatter (none with 3 points).
        let n = f.points as f64;
        f.exponent_se = f
            .exponent_se
            .filter(|_| f.points > 3)
            .map(|se| se * ((n - 2.0) / (n - 3.0)).sqrt());
    }
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(BOOTSTRAP_SEED);
    let several = kept.iter().any(|(_, v)| v.len() > 1);
    let exponents: Vec<f64> = (0..if several { BOOTSTRAP } else { 0 })
        .filter_map(|_| {
            let resampled: Vec<(f64, f64)> = kept
                .iter()
                .map(|(x, v)| {
                    let sum: f64 = (0..v.len()).map(|_| v[rng.random_range(0..v.len())]).sum();
                    (*x, sum / v.len() as f64)
                })
                .collect();
            Some(fitted(&resampled)?.exponent)
        })
        .collect();
    f.exponent_seed_se = (exponents.len() > 1).then(|| {
        let m = mean(&exponents);
        let var = exponents.iter().map(|e| (e - m).powi(2)).sum::<f64>();
        (var / (exponents.len() - 1) as f64).sqrt()
    });
    Some(f)
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// The offset y₀ < min y that leaves the least sum of squares of y about y₀ + c·x^δ (c and δ
/// fitted on log–log axes for each y₀), searched by golden section over y₀ from ten spans of y
/// below its least value up to it. None with fewer than three points.
fn fitted_offset(points: &[(f64, f64)]) -> Option<f64> {
    if points.len() < 3 {
        return None;
    }
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.1), b.max(p.1))
        });
    let span = (hi - lo).max(lo.abs() * 1e-9).max(f64::MIN_POSITIVE);
    let squares = |y0: f64| -> f64 {
        let shifted: Vec<(f64, f64)> = points.iter().map(|(x, y)| (*x, y - y0)).collect();
        match power_law(&shifted) {
            Some(f) => points
                .iter()
                .map(|(x, y)| (y - y0 - f.prefactor * x.powf(f.exponent)).powi(2))
                .sum(),
            None => f64::INFINITY,
        }
    };
    let (mut a, mut b) = (lo - 10.0 * span, lo - 1e-6 * span);
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..200 {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if squares(c) < squares(d) {
            b = d;
        } else {
            a = c;
        }
    }
    Some(0.5 * (a + b))
}

/// Fits y = c·x^δ by ordinary least squares of ln y on ln x, every point weighted equally
/// (points with x ≤ 0 or y ≤ 0 are left out). None with fewer than two usable points or a
/// single x value.
pub fn power_law(points: &[(f64, f64)]) -> Option<PowerFit> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = logs.len();
    if n < 2 {
        return None;
    }
    let nf = n as f64;
    let mx = logs.iter().map(|p| p.0).sum::<f64>() / nf;
    let my = logs.iter().map(|p| p.1).sum::<f64>() / nf;
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let exponent_se = (n > 2).then(|| {
        let ssr: f64 = logs
            .iter()
            .map(|p| (p.1 - intercept - slope * p.0).powi(2))
            .sum();
        (ssr / (nf - 2.0) / sxx).sqrt()
    });
    Some(PowerFit {
        exponent: slope,
        exponent_se,
        prefactor: intercept.exp(),
        points: n,
        offset: None,
        exponent_seed_se: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_an_exact_power_law() {
        let pts: Vec<(f64, f64)> = [0.5, 1.0, 2.0, 4.0]
            .iter()
            .map(|&x| (x, 3.0 * x * x))
            .collect();
        let f = power_law(&pts).unwrap();
        assert!((f.exponent - 2.0).abs() < 1e-12);
        assert!((f.prefactor - 3.0).abs() < 1e-12);
        assert!(f.exponent_se.unwrap() < 1e-12);
        assert_eq!(f.points, 4);
    }

    #[test]
    fn slope_error_matches_the_textbook_formula() {
        // ln y = x' exactly but for ±0.1 alternating: residuals known in closed form.
        let pts: Vec<(f64, f64)> = (1..=4)
            .map(|k| {
                let lx = k as f64;
                let ly = lx + if k % 2 == 0 { 0.1 } else { -0.1 };
                (lx.exp(), ly.exp())
            })
            .collect();
        let f = power_law(&pts).unwrap();
        // x' = 1..4: mean 2.5, Sxx = 5; y' − mean = x' − 2.5 + (−.1, .1, −.1, .1)
        let slope = 1.0 + (-0.1 * -1.5 + 0.1 * -0.5 - 0.1 * 0.5 + 0.1 * 1.5) / 5.0;
        assert!((f.exponent - slope).abs() < 1e-12);
        let ssr: f64 = (1..=4)
            .map(|k| {
                let lx = k as f64;
                let ly = lx + if k % 2 == 0 { 0.1 } else { -0.1 };
                let icpt = 2.5 - slope * 2.5;
                (ly - icpt - slope * lx).powi(2)
            })
            .sum();
        assert!((f.exponent_se.unwrap() - (ssr / 2.0 / 5.0).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn fits_a_range_and_a_given_or_fitted_offset() {
        // y = 2 + 3 x^1.5 over x = 1..8, and a point far off outside the range [1, 8].
        let mut pts: Vec<(f64, Vec<f64>)> = (1..=8)
            .map(|k| {
                let x = k as f64;
                (x, vec![2.0 + 3.0 * x.powf(1.5)])
            })
            .collect();
        pts.push((100.0, vec![1.0]));
        let range = Some((1.0, 8.0));
        let given = FitOptions {
            range,
            offset: Some(Offset::Given(2.0)),
        };
        let f = fit(&pts, given).unwrap();
        assert!((f.exponent - 1.5).abs() < 1e-12, "{f:?}");
        assert_eq!((f.points, f.offset), (8, Some(2.0)));
        let fitted = fit(
            &pts,
            FitOptions {
                range,
                offset: Some(Offset::Fitted),
            },
        )
        .unwrap();
        assert!((fitted.offset.unwrap() - 2.0).abs() < 1e-3, "{fitted:?}");
        assert!((fitted.exponent - 1.5).abs() < 1e-3, "{fitted:?}");
        // Without the offset the same points give another exponent.
        let plain = fit(
            &pts,
            FitOptions {
                range,
                offset: None,
            },
        )
        .unwrap();
        assert!((plain.exponent - 1.5).abs() > 0.05, "{plain:?}");
    }

    #[test]
    fn a_fitted_offset_counts_as_a_parameter() {
        // y = 2 + 3 x^1.5 with two seeds a point, ±5 % apart: three points leave no scatter
        // error with the offset fitted (three parameters), four do.
        let pts = |xs: &[f64]| -> Vec<(f64, Vec<f64>)> {
            xs.iter()
                .map(|&x| {
                    let y = 2.0 + 3.0 * x.powf(1.5);
                    (x, vec![0.95 * y, 1.05 * y + 0.01 * x])
                })
                .collect()
        };
        let fitted = FitOptions {
            range: None,
            offset: Some(Offset::Fitted),
        };
        let three = fit(&pts(&[1.0, 2.0, 4.0]), fitted).unwrap();
        assert_eq!(three.exponent_se, None, "{three:?}");
        let five = pts(&[1.0, 2.0, 4.0, 8.0, 16.0]);
        let f = fit(&five, fitted).unwrap();
        assert!(f.exponent_se.is_some(), "{f:?}");
        // The seeds move the fitted offset too: δ then spreads more than at that offset held.
        let held = fit(
            &five,
            FitOptions {
                range: None,
                offset: Some(Offset::Given(f.offset.unwrap())),
            },
        )
        .unwrap();
        assert!(
            f.exponent_seed_se.unwrap() > 1.5 * held.exponent_seed_se.unwrap(),
            "{f:?} {held:?}"
        );
    }

    #[test]
    fn the_seed_error_is_the_spread_of_bootstrapped_exponents() {
        // Two seeds per point, y = 0.9 x² and 1.1 x²: means on the line, exponents apart.
        let pts: Vec<(f64, Vec<f64>)> = [1.0, 2.0, 4.0, 8.0]
            .iter()
            .map(|&x: &f64| (x, vec![0.9 * x * x, 1.1 * x * x]))
            .collect();
        let f = fit(&pts, FitOptions::default()).unwrap();
        assert!((f.exponent - 2.0).abs() < 1e-12);
        // The means lie on the line: no scatter, but the seeds could have tilted it.
        assert!(f.exponent_se.unwrap() < 1e-12);
        let seed_se = f.exponent_seed_se.unwrap();
        assert!(seed_se > 0.01 && seed_se < 0.2, "{seed_se}");
        // One run per point: no seed error.
        let single: Vec<(f64, Vec<f64>)> = pts.iter().map(|(x, v)| (*x, vec![v[0]])).collect();
        assert_eq!(
            fit(&single, FitOptions::default())
                .unwrap()
                .exponent_seed_se,
            None
        );
    }

    #[test]
    fn needs_two_distinct_positive_points() {
        assert!(power_law(&[(1.0, 1.0)]).is_none());
        assert!(power_law(&[(1.0, 1.0), (1.0, 2.0)]).is_none());
        assert!(power_law(&[(1.0, 1.0), (-2.0, 2.0)]).is_none());
        assert!(power_law(&[(1.0, 1.0), (2.0, 2.0)])
            .unwrap()
            .exponent_se
            .is_none());
    }
}
