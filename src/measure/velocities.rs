//! Distributions of the scaled velocities `c = (v − u) / √T` per axis, after the warm-up, with
//! their kurtosis `⟨c⁴⟩ / ⟨c²⟩²` (3 for a Gaussian; larger for the overpopulated tails of driven
//! inelastic beds).
//!
//! A vibrated bed's mean velocity and temperature change with height, and mixing Gaussians of
//! different temperatures alone makes tails: so `u` and `T` are those of the disk's height band
//! (the profiles' bins), averaged over the whole window like the profiles, and the bands'
//! scaled distributions are pooled into one for the bed. A scene without gravity is one band.
//! Number-weighted: `u` and `T` here are the mean and variance of the velocities in the band.
//!
//! Each band keeps, per axis, the exact power sums of its velocities (the kurtosis comes from
//! them, unbinned) and a histogram of the raw velocities that coarsens itself (merging
//! neighbours) to stay within `RAW_BINS` bins while the values spread: its resolution is
//! about a 300th of the range seen. At the end each raw bin is spread over the bins of `c`
//! it overlaps, with the band's final `u` and `T`.

use super::States;
use serde::{Deserialize, Serialize};

/// Most bins of a band's raw histogram.
const RAW_BINS: usize = 2048;
/// Bins of the scaled velocity `c`: `C_BINS` of width `C_WIDTH` centred on 0.
const C_BINS: usize = 60;
const C_WIDTH: f64 = 0.2;

/// A histogram of raw values over bins of width `width` anchored at 0 (bin k: `[k w, (k+1) w)`),
/// kept within [`RAW_BINS`] bins by doubling the width (merging pairs) when the values spread.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct RawHistogram {
    width: f64,
    /// Index of `counts[0]`.
    lo: i64,
    counts: Vec<f64>,
}

impl RawHistogram {
    fn new(width: f64) -> RawHistogram {
        RawHistogram {
            width,
            lo: 0,
            counts: Vec::new(),
        }
    }

    fn add(&mut self, v: f64) {
        loop {
            let k = (v / self.width).floor() as i64;
            if self.counts.is_empty() {
                self.lo = k;
                self.counts.push(0.0);
            }
            let lo = self.lo.min(k);
            let hi = (self.lo + self.counts.len() as i64 - 1).max(k);
            if hi - lo < RAW_BINS as i64 {
                if k < self.lo {
                    let more = (self.lo - k) as usize;
                    self.counts.splice(0..0, std::iter::repeat_n(0.0, more));
                    self.lo = k;
                } else if k >= self.lo + self.counts.len() as i64 {
                    self.counts.resize((k - self.lo + 1) as usize, 0.0);
                }
                self.counts[(k - self.lo) as usize] += 1.0;
                return;
            }
            self.coarsen();
        }
    }

    /// Doubles the width: bin k of the new width holds old bins 2k and 2k + 1.
    fn coarsen(&mut self) {
        let lo = self.lo.div_euclid(2);
        let mut counts =
            vec![0.0; ((self.lo + self.counts.len() as i64 - 1).div_euclid(2) - lo + 1) as usize];
        for (k, c) in self.counts.iter().enumerate() {
            counts[((self.lo + k as i64).div_euclid(2) - lo) as usize] += c;
        }
        self.width *= 2.0;
        self.lo = lo;
        self.counts = counts;
    }

    /// Adds the counts, spread over the bins of `c = (v − u)/s` each raw bin overlaps, to `out`.
    fn rebin_into(&self, u: f64, s: f64, out: &mut [f64]) {
        let half = 0.5 * C_BINS as f64 * C_WIDTH;
        for (k, &n) in self.counts.iter().enumerate() {
            if n == 0.0 {
                continue;
            }
            let v0 = (self.lo + k as i64) as f64 * self.width;
            let (a, b) = ((v0 - u) / s + half, (v0 + self.width - u) / s + half);
            let (first, last) = ((a / C_WIDTH).floor().max(0.0), (b / C_WIDTH).floor());
            let mut m = first;
            while m <= last.min(C_BINS as f64 - 1.0) {
                let (lo, hi) = (m * C_WIDTH, (m + 1.0) * C_WIDTH);
                out[m as usize] += n * (b.min(hi) - a.max(lo)).max(0.0) / (b - a);
                m += 1.0;
            }
        }
    }
}

/// Exact power sums `Σ (v − shift)^k`, k = 0…4, of one band's velocities on one axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Moments {
    /// Subtracted before summing (the first value seen), so that the sums keep their precision
    /// when the mean is large against the spread.
    shift: Option<f64>,
    sums: [f64; 5],
}

impl Moments {
    fn add(&mut self, v: f64) {
        let d = v - *self.shift.get_or_insert(v);
        let mut p = 1.0;
        for s in &mut self.sums {
            *s += p;
            p *= d;
        }
    }

    /// Mean, variance and the fourth central moment (`None` below two values or no spread).
    fn central(&self) -> Option<(f64, f64, f64)> {
        let [n, s1, s2, s3, s4] = self.sums;
        if n < 2.0 {
            return None;
        }
        let m = s1 / n;
        let var = s2 / n - m * m;
        let m4 = s4 / n - 4.0 * m * s3 / n + 6.0 * m * m * s2 / n - 3.0 * m.powi(4);
        (var > 0.0).then(|| (m + self.shift.unwrap_or(0.0), var, m4))
    }
}

/// One band, both axes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Band {
    moments: [Moments; 2],
    raw: [RawHistogram; 2],
}

/// The velocities seen after the warm-up, by height band.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Velocities {
    /// The bands: `count` equal bins over `[bottom, top)`; `None`: one band, the whole box.
    bands: Option<(f64, f64, usize)>,
    per_band: Vec<Band>,
}

/// The pooled distribution of one axis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisDistribution {
    /// `⟨c⁴⟩`, with `⟨c²⟩ = 1` by construction: 3 for a Gaussian.
    pub kurtosis: f64,
    /// Probability density of c at the bin centres (the fraction of values in the bin divided
    /// by its width; values beyond ±6 count in the normalisation, not in a bin).
    pub density: Vec<f64>,
}

/// Distributions of the scaled velocities (the summary's `velocity_distribution`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VelocityDistribution {
    /// `height bands` (u and T of the disk's band of height, the profiles' bins) or `whole box`
    /// (a scene without gravity).
    pub scaling: &'static str,
    /// Number of velocities (disks × samples) per axis in the distributions.
    pub values: f64,
    /// Bin centres of c.
    pub c: Vec<f64>,
    /// Horizontal: c = (vx − ux)/√Tx.
    pub x: AxisDistribution,
    /// Vertical: c = (vy − uy)/√Ty.
    pub y: AxisDistribution,
}

impl Velocities {
    /// Empty distributions over the height bands `(bottom, top, count)`, or one band (`None`);
    /// `speed` sets the finest raw resolution (a typical speed of the scene).
    pub fn new(bands: Option<(f64, f64, usize)>, speed: f64) -> Velocities {
        let count = bands.map_or(1, |b| b.2);
        let width = speed.abs().max(f64::MIN_POSITIVE) * 2f64.powi(-30);
        let band = Band {
            moments: [
                Moments {
                    shift: None,
                    sums: [0.0; 5],
                },
                Moments {
                    shift: None,
                    sums: [0.0; 5],
                },
            ],
            raw: [RawHistogram::new(width), RawHistogram::new(width)],
        };
        Velocities {
            bands,
            per_band: vec![band; count],
        }
    }

    /// Adds the disks' velocities at one instant, each to its band.
    pub fn add(&mut self, states: &impl States) {
        states.each(|_, [_, y, vx, vy]| {
            let k = match self.bands {
                None => 0,
                Some((bottom, top, count)) => {
                    let k = ((y - bottom) / ((top - bottom) / count as f64)).floor();
                    if !(0.0..count as f64).contains(&k) {
                        return;
                    }
                    k as usize
                }
            };
            let band = &mut self.per_band[k];
            for (axis, v) in [vx, vy].into_iter().enumerate() {
                band.moments[axis].add(v);
                band.raw[axis].add(v);
            }
        });
    }

    /// The pooled distributions (`None` before any value).
    pub fn distribution(&self) -> Option<VelocityDistribution> {
        let axis = |a: usize| {
            let (mut hist, mut n, mut c4) = (vec![0.0; C_BINS], 0.0, 0.0);
            for band in &self.per_band {
                let Some((u, var, m4)) = band.moments[a].central() else {
                    continue;
                };
                let nb = band.moments[a].sums[0];
                band.raw[a].rebin_into(u, var.sqrt(), &mut hist);
                n += nb;
                c4 += nb * m4 / (var * var);
            }
            (n > 0.0).then(|| AxisDistribution {
                kurtosis: c4 / n,
                density: hist.iter().map(|h| h / (n * C_WIDTH)).collect(),
            })
        };
        let (x, y) = (axis(0)?, axis(1)?);
        let half = 0.5 * C_BINS as f64 * C_WIDTH;
        Some(VelocityDistribution {
            scaling: if self.bands.is_some() {
                "height bands"
            } else {
                "whole box"
            },
            values: self.per_band.iter().map(|b| b.moments[0].sums[0]).sum(),
            c: (0..C_BINS)
                .map(|m| -half + (m as f64 + 0.5) * C_WIDTH)
                .collect(),
            x,
            y,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_raw_histogram_coarsens_and_keeps_its_counts() {
        let mut h = RawHistogram::new(1e-9);
        for k in 0..10_000 {
            h.add((k as f64 * 0.618_034).fract() * 10.0 - 5.0);
        }
        assert!(h.counts.len() <= RAW_BINS);
        assert_eq!(h.counts.iter().sum::<f64>(), 10_000.0);
        assert!(h.width < 10.0 / 1000.0, "resolution {}", h.width);
        // Rebinned with u = 0, s = 1: uniform over [−5, 5) gives 1/10 per unit of c inside.
        let mut out = vec![0.0; C_BINS];
        h.rebin_into(0.0, 1.0, &mut out);
        assert!((out.iter().sum::<f64>() - 10_000.0).abs() < 1e-6);
        let inside = out[5..55].iter().map(|c| c / (10_000.0 * C_WIDTH));
        assert!(inside.clone().all(|d| (d - 0.1).abs() < 0.01), "{out:?}");
    }

    #[test]
    fn moments_give_the_kurtosis_of_a_known_set() {
        // ±1 and ±3 once each about a mean of 100: variance 5, fourth moment 41.
        let mut m = Moments {
            shift: None,
            sums: [0.0; 5],
        };
        for v in [99.0, 101.0, 97.0, 103.0] {
            m.add(v);
        }
        let (u, var, m4) = m.central().unwrap();
        assert!((u - 100.0).abs() < 1e-12 && (var - 5.0).abs() < 1e-12 && (m4 - 41.0).abs() < 1e-9);
    }
}
