//! A power law y = c·x^δ fitted to a sweep's point means by least squares on (ln x, ln y).

use serde::Serialize;

/// The fitted power law and the standard error of its exponent.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PowerFit {
    /// Exponent δ (the slope on log–log axes).
    pub exponent: f64,
    /// Standard error of δ from the scatter of the points about the line,
    /// √(Σ r² / (n − 2) / Σ (ln x − mean)²); absent with two points.
    pub exponent_se: Option<f64>,
    /// Prefactor c.
    pub prefactor: f64,
    /// Number of points fitted.
    pub points: usize,
}

impl PowerFit {
    /// y = c·x^δ at x.
    pub fn at(&self, x: f64) -> f64 {
        self.prefactor * x.powf(self.exponent)
    }
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
