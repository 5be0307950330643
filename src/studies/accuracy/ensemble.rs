//! The seed ensembles of the accuracy report: what one run measured, the seed-averaged
//! observables of a variant, its errors against the reference's, and the reference's own
//! seed-to-seed spread (the noise floor of every comparison).

use super::Errors;
use crate::output::summary::Summary;
use crate::schemes::SchemeStats;

/// What one run measured.
#[derive(Debug, Clone, Default)]
pub(super) struct Measured {
    density: Option<Vec<f64>>,
    temperature_profile: Option<Vec<f64>>,
    com_height: Option<f64>,
    pub(super) temperature: f64,
    energy_input: Option<f64>,
    pub(super) collision_rate: f64,
    wall_per_time: f64,
    /// Wall-clock seconds of the run's event loop, and the simulated time it covered.
    pub(super) wall: f64,
    pub(super) sim_time: f64,
    /// Threads the run used.
    pub(super) threads: usize,
    pub(super) pair: f64,
    pub(super) events: u64,
    pub(super) max_overlap: f64,
    pub(super) stats: Option<SchemeStats>,
}

impl Measured {
    /// The observables of one run's summary (the energy input only where the scene has a floor).
    pub(super) fn of(s: &Summary, has_floor: bool) -> Measured {
        let t = s.sim_time.max(f64::MIN_POSITIVE);
        Measured {
            density: s.profiles.as_ref().map(|p| p.density.clone()),
            // A bin no disk entered (no temperature: NaN) weighs 0 by its density; as 0 it
            // keeps the seed averages and the weighted distances finite.
            temperature_profile: s.profiles.as_ref().map(|p| {
                p.temperature_x
                    .iter()
                    .zip(&p.temperature_y)
                    .map(|(x, y)| 0.5 * (x + y))
                    .map(|t| if t.is_nan() { 0.0 } else { t })
                    .collect()
            }),
            com_height: s.com_height,
            temperature: s.temperature.map_or(f64::NAN, |t| t.mean),
            energy_input: has_floor.then(|| s.energy.injected / t),
            collision_rate: s.events.pair as f64 / t,
            wall_per_time: s.wall_seconds / t,
            wall: s.wall_seconds,
            sim_time: s.sim_time,
            threads: s.engine.threads.unwrap_or(1),
            pair: s.events.pair as f64,
            events: s.events.popped(),
            max_overlap: s.max_overlap,
            stats: s.approximation,
        }
    }
}

/// Seed-averaged observables of one variant.
#[derive(Debug, Clone, Default)]
pub(super) struct Ensemble {
    /// One run per seed, in seed order.
    pub(super) runs: Vec<Measured>,
}

/// The mean (0 of nothing).
fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// The sample variance (NaN below two values).
fn variance(v: &[f64]) -> f64 {
    if v.len() < 2 {
        return f64::NAN;
    }
    let m = mean(v);
    v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (v.len() - 1) as f64
}

impl Ensemble {
    /// A scalar of every run, if every run has it.
    fn scalars(&self, f: impl Fn(&Measured) -> Option<f64>) -> Option<Vec<f64>> {
        self.runs.iter().map(f).collect()
    }
    /// The seed mean of a scalar, if every run has it.
    pub(super) fn scalar(&self, f: impl Fn(&Measured) -> Option<f64>) -> Option<f64> {
        self.scalars(f).map(|v| mean(&v))
    }
    /// A profile of every run, if every run has it.
    fn profiles(&self, f: impl Fn(&Measured) -> Option<&Vec<f64>>) -> Option<Vec<Vec<f64>>> {
        self.runs.iter().map(|m| f(m).cloned()).collect()
    }
    /// The bin-by-bin seed mean of a profile, if every run has it.
    fn profile(&self, f: impl Fn(&Measured) -> Option<&Vec<f64>>) -> Option<Vec<f64>> {
        let all = self.profiles(f)?;
        let bins = all.first()?.len();
        Some(
            (0..bins)
                .map(|k| mean(&all.iter().map(|p| p[k]).collect::<Vec<_>>()))
                .collect(),
        )
    }
    /// The seed-averaged density profile.
    fn density(&self) -> Option<Vec<f64>> {
        self.profile(|m| m.density.as_ref())
    }
    /// The seed-averaged temperature profile (mean of the two axes).
    fn temperature_profile(&self) -> Option<Vec<f64>> {
        self.profile(|m| m.temperature_profile.as_ref())
    }
    /// Wall-clock seconds per unit of simulated time, averaged over the seeds.
    pub(super) fn wall_per_time(&self) -> f64 {
        mean(
            &self
                .runs
                .iter()
                .map(|m| m.wall_per_time)
                .collect::<Vec<_>>(),
        )
    }

    /// Cores each run used (the most any run used).
    pub(super) fn cores(&self) -> usize {
        self.runs.iter().map(|m| m.threads).max().unwrap_or(1)
    }

    /// Wall-clock seconds per unit of simulated time of runs that ran all at once: the longest
    /// run's wall time over the simulated time of all of them (the ensemble's throughput).
    pub(super) fn wall_per_time_at_once(&self) -> f64 {
        let wall = self.runs.iter().map(|m| m.wall).fold(0.0, f64::max);
        wall / self.runs.iter().map(|m| m.sim_time).sum::<f64>()
    }

    /// Errors of this ensemble's means against `reference`'s.
    pub(super) fn errors_against(&self, reference: &Ensemble) -> Errors {
        self.compare(reference, |a, b| (a - b).abs() / b.abs())
    }

    /// What changed from `other`'s means to this ensemble's: the profiles' distances as in
    /// [`errors_against`](Self::errors_against), the scalars' relative changes with their sign.
    pub(super) fn changes_from(&self, other: &Ensemble) -> Errors {
        self.compare(other, |a, b| (a - b) / b.abs())
    }

    /// The profiles' relative L2 distances from `reference`'s, and `relative(a, b)` of each
    /// scalar (`b` the reference's).
    fn compare(&self, reference: &Ensemble, relative: impl Fn(f64, f64) -> f64) -> Errors {
        let rel = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(a), Some(b)) if b != 0.0 => Some(relative(a, b)),
            _ => None,
        };
        let density = match (self.density(), reference.density()) {
            (Some(a), Some(b)) => l2_rel(&a, &b, None),
            _ => None,
        };
        let temperature_profile = match (
            self.temperature_profile(),
            reference.temperature_profile(),
            reference.density(),
        ) {
            (Some(a), Some(b), Some(w)) => l2_rel(&a, &b, Some(&w)),
            _ => None,
        };
        Errors {
            density_profile: density,
            temperature_profile,
            com_height: rel(
                self.scalar(|m| m.com_height),
                reference.scalar(|m| m.com_height),
            ),
            temperature: rel(
                self.scalar(|m| Some(m.temperature)),
                reference.scalar(|m| Some(m.temperature)),
            ),
            energy_input: rel(
                self.scalar(|m| m.energy_input),
                reference.scalar(|m| m.energy_input),
            ),
            collision_rate: rel(
                self.scalar(|m| Some(m.collision_rate)),
                reference.scalar(|m| Some(m.collision_rate)),
            ),
        }
    }

    /// The error expected between two independent K-seed ensembles: `√(2/K)·σ/|mean|`.
    pub(super) fn spread(&self) -> Errors {
        let k = self.runs.len() as f64;
        let factor = (2.0 / k).sqrt();
        let scalar = |f: &dyn Fn(&Measured) -> Option<f64>| {
            let v = self.scalars(f)?;
            let m = mean(&v);
            (m != 0.0 && v.len() > 1).then(|| factor * variance(&v).sqrt() / m.abs())
        };
        let profile = |all: Option<Vec<Vec<f64>>>, weights: Option<&[f64]>| {
            let all = all?;
            if all.len() < 2 {
                return None;
            }
            let bins = all[0].len();
            let (mut num, mut den) = (0.0, 0.0);
            for b in 0..bins {
                let col: Vec<f64> = all.iter().map(|p| p[b]).collect();
                let w = weights.map_or(1.0, |w| w[b]);
                num += w * variance(&col);
                den += w * mean(&col).powi(2);
            }
            (den > 0.0).then(|| factor * (num / den).sqrt())
        };
        let density = self.density();
        Errors {
            density_profile: profile(self.profiles(|m| m.density.as_ref()), None),
            temperature_profile: profile(
                self.profiles(|m| m.temperature_profile.as_ref()),
                density.as_deref(),
            ),
            com_height: scalar(&|m| m.com_height),
            temperature: scalar(&|m| Some(m.temperature)),
            energy_input: scalar(&|m| m.energy_input),
            collision_rate: scalar(&|m| Some(m.collision_rate)),
        }
    }
}

/// `‖a − b‖ / ‖b‖`, optionally weighted per bin.
fn l2_rel(a: &[f64], b: &[f64], w: Option<&[f64]>) -> Option<f64> {
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0..a.len().min(b.len()) {
        let wk = w.map_or(1.0, |w| w[k]);
        num += wk * (a[k] - b[k]).powi(2);
        den += wk * b[k] * b[k];
    }
    (den > 0.0).then(|| (num / den).sqrt())
}
