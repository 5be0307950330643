//! Motion against the floor's phase: the centre of mass, the bed's lower edge and the floor's
//! impacts and impulse in bins over one vibration period, after the warm-up.
//!
//! The run stops at every bin edge `k/B` of the floor's phase (B stops per period, whatever the
//! sample interval: samples at a fixed interval alias with the period — a sample interval equal to
//! the period sees one phase only). At each edge the centre of mass and the lower edge are sampled,
//! and the floor's impacts and impulse since the previous edge are booked into the bin just left;
//! the pieces of bins cut by the window's start and the run's end are booked too, so the bins sum
//! to the whole window. The phase stops cost what samples cost (a pass over the disks): they are
//! kept no more frequent than the samples by resolving every `stride`-th period only (the bins
//! then sum to those periods).

use crate::measure::States;
use crate::physics::disks::Disks;
use crate::physics::floor::Floor;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// The lower edge of the bed is the height above the floor below which this fraction of the disks'
/// bottoms lie: a low percentile, not the lowest disk, so that a lone disk bouncing under a flying
/// bed (or a gas's fastest disks) does not hide the bed's flight; 5 % stays inside the bottom layer
/// of beds up to 20 layers deep.
pub const LOWER_EDGE_FRACTION: f64 = 0.05;

/// Where the bin edges of the floor's phase fall in time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PhaseClock {
    /// Bins per period.
    pub bins: usize,
    /// The vibration period 2π/ω.
    pub period: f64,
    /// The floor's phase at time 0 as a fraction of the period, in [0, 1).
    origin: f64,
    /// Index of the first bin edge at or after time 0 (counted from phase 0 of period 0).
    first: u64,
    /// Every `stride`-th period is resolved (1: all).
    pub stride: u64,
}

impl PhaseClock {
    /// The clock of a vibrating floor (`None` for a static one), `bins` bins per period, in a run
    /// sampled every `sample_dt`: every stride-th period is resolved so that the phase stops are
    /// no more frequent than the samples (the stride does not depend on the run's length, so a
    /// resumed run resolves the same periods as an uninterrupted one).
    pub fn of(floor: &Floor, bins: usize, sample_dt: f64) -> Option<PhaseClock> {
        if floor.is_static() || bins == 0 {
            return None;
        }
        let origin = (floor.phase_origin() / TAU).rem_euclid(1.0);
        let period = TAU / floor.omega;
        Some(PhaseClock {
            bins,
            period,
            origin,
            first: (origin * bins as f64).ceil() as u64,
            stride: (bins as f64 * sample_dt / period).ceil().max(1.0) as u64,
        })
    }

    /// The edge after edge `k` at which the run stops: the next one, or the first of the next
    /// resolved period.
    pub fn next_edge(&self, k: u64) -> u64 {
        let (b, next) = (self.bins as u64, self.first + k + 1);
        let period = next / b;
        if next % b != 0 || period % self.stride == 0 {
            return k + 1;
        }
        period.div_ceil(self.stride) * self.stride * b - self.first
    }

    /// Time of the `k`-th bin edge at or after time 0.
    pub fn edge_time(&self, k: u64) -> f64 {
        ((self.first + k) as f64 / self.bins as f64 - self.origin) * self.period
    }

    /// The bin that starts at the `k`-th edge.
    pub fn bin_from(&self, k: u64) -> usize {
        ((self.first + k) % self.bins as u64) as usize
    }

    /// The bin that ends at the `k`-th edge.
    pub fn bin_before(&self, k: u64) -> usize {
        let b = self.bins as u64;
        ((self.first + k + b - 1) % b) as usize
    }

    /// The first edge at or after time `t`.
    pub fn first_edge_from(&self, t: f64) -> u64 {
        let mut k = ((t / self.period + self.origin) * self.bins as f64 - self.first as f64)
            .floor()
            .max(0.0) as u64;
        while self.edge_time(k) < t {
            k += 1;
        }
        k
    }
}

/// The floor's count of impacts and the vertical momentum it had given at one time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FloorTally {
    /// Simulated time.
    pub time: f64,
    /// Floor impacts so far.
    pub impacts: u64,
    /// Vertical momentum the floor has given the disks so far.
    pub impulse: f64,
}

/// Sums per phase bin over the window.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhaseBins {
    clock: PhaseClock,
    samples: Vec<u64>,
    com: Vec<f64>,
    com_sq: Vec<f64>,
    lower: Vec<f64>,
    impacts: Vec<u64>,
    impulse: Vec<f64>,
    exposure: Vec<f64>,
    /// The floor's tally at the last booking, and the edge it was taken at (the edge before the
    /// first when the window opened between edges).
    mark: Option<(FloorTally, u64)>,
}

/// The phase-resolved motion (the summary's `phase`): one entry per bin of the floor's phase.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PhaseTable {
    /// The vibration period.
    pub period: f64,
    /// Start of each bin as a fraction of the period (phase 0: the floor at its mean height moving
    /// up, for the sine); the centre of mass and the lower edge are sampled there.
    pub phase: Vec<f64>,
    /// The floor's height at each bin's start.
    pub floor_height: Vec<f64>,
    /// Mean height of the centre of mass at each bin's start.
    pub com_height: Vec<f64>,
    /// Mean lower edge at each bin's start: the height above the floor below which 5 % of the
    /// disks' bottoms lie.
    pub lower_edge: Vec<f64>,
    /// Samples taken at each bin's start.
    pub samples: Vec<u64>,
    /// Floor impacts within each bin over the window (they sum to the window's impacts).
    pub impacts: Vec<u64>,
    /// Simulated time spent in each bin over the window (sums to the window's length).
    pub exposure: Vec<f64>,
    /// Pressure on the floor within each bin: the vertical momentum it gave per unit time and
    /// width while in that bin (their exposure-weighted mean is `floor_pressure.measured`).
    pub pressure: Vec<f64>,
    /// Share of the centre of mass's variance (over all phase samples) explained by the phase:
    /// the variance of the bins' means over the total variance; 1 for a bed locked to the
    /// floor's period, near 0 for one whose height does not follow the floor.
    pub com_locking: f64,
}

impl PhaseBins {
    /// Empty bins on `clock`.
    pub fn new(clock: PhaseClock) -> PhaseBins {
        let (u, f) = (vec![0; clock.bins], vec![0.0; clock.bins]);
        PhaseBins {
            clock,
            samples: u.clone(),
            com: f.clone(),
            com_sq: f.clone(),
            lower: f.clone(),
            impacts: u,
            impulse: f.clone(),
            exposure: f,
            mark: None,
        }
    }

    /// The clock the bins follow.
    pub fn clock(&self) -> &PhaseClock {
        &self.clock
    }

    /// The window opens with `next` the first edge to come: impacts count from this tally on.
    pub fn open(&mut self, at: FloorTally, next: u64) {
        self.mark = Some((at, next.wrapping_sub(1)));
    }

    /// The run is at edge `k` (or at its end, between edge `k − 1` and edge `k`): books the
    /// impacts, impulse and time since the last booking into the bin before edge `k`, if the
    /// last booking was at the edge before (not in a period skipped by the stride).
    pub fn book(&mut self, k: u64, now: FloorTally) {
        if let Some((m, at)) = self.mark {
            if at == k.wrapping_sub(1) {
                let bin = self.clock.bin_before(k);
                self.impacts[bin] += now.impacts - m.impacts;
                self.impulse[bin] += now.impulse - m.impulse;
                self.exposure[bin] += now.time - m.time;
            }
        }
        self.mark = Some((now, k));
    }

    /// Adds the centre-of-mass height and lower edge sampled at the start of `bin`.
    pub fn sample(&mut self, bin: usize, (com, lower): (f64, f64)) {
        self.samples[bin] += 1;
        self.com[bin] += com;
        self.com_sq[bin] += com * com;
        self.lower[bin] += lower;
    }

    /// The table, with the floor's height from `floor` and pressures per unit `width`.
    pub fn table(&self, floor: &Floor, width: f64) -> PhaseTable {
        let b = self.clock.bins;
        let per = |f: &dyn Fn(usize) -> f64| (0..b).map(f).collect::<Vec<f64>>();
        let mean = |v: &[f64], k: usize| v[k] / self.samples[k].max(1) as f64;
        let phase = per(&|k| k as f64 / b as f64);
        PhaseTable {
            period: self.clock.period,
            floor_height: phase
                .iter()
                .map(|p| floor.height((p * TAU - floor.phase_origin()) / floor.omega))
                .collect(),
            phase,
            com_height: per(&|k| mean(&self.com, k)),
            lower_edge: per(&|k| mean(&self.lower, k)),
            samples: self.samples.clone(),
            impacts: self.impacts.clone(),
            exposure: self.exposure.clone(),
            pressure: per(&|k| {
                if self.exposure[k] > 0.0 {
                    self.impulse[k] / (self.exposure[k] * width)
                } else {
                    0.0
                }
            }),
            com_locking: self.com_locking(),
        }
    }

    /// Variance of the bins' mean centre of mass (weighted by their samples) over the variance
    /// of all the samples.
    fn com_locking(&self) -> f64 {
        let n: u64 = self.samples.iter().sum();
        if n < 2 {
            return 0.0;
        }
        let n = n as f64;
        let all = self.com.iter().sum::<f64>() / n;
        let total = self.com_sq.iter().sum::<f64>() / n - all * all;
        let between = (0..self.clock.bins)
            .filter(|&k| self.samples[k] > 0)
            .map(|k| {
                let m = self.com[k] / self.samples[k] as f64;
                self.samples[k] as f64 * (m - all).powi(2)
            })
            .sum::<f64>()
            / n;
        if total > 0.0 {
            (between / total).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }
}

/// The centre of mass's height and the bed's lower edge (see [`LOWER_EDGE_FRACTION`]) above
/// the floor at height `floor` at one instant.
pub fn com_and_lower_edge(states: &impl States, disks: &Disks, floor: f64) -> (f64, f64) {
    let (mut m_sum, mut my) = (0.0, 0.0);
    let mut bottoms = Vec::with_capacity(disks.len());
    states.each(|i, [_, y, _, _]| {
        m_sum += disks.mass[i];
        my += disks.mass[i] * y;
        bottoms.push(y - disks.radius[i] - floor);
    });
    let k = ((LOWER_EDGE_FRACTION * bottoms.len() as f64) as usize).min(bottoms.len() - 1);
    let (_, lower, _) = bottoms.select_nth_unstable_by(k, f64::total_cmp);
    (my / m_sum, *lower)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{FloorModel, Waveform};

    fn floor(phase: f64) -> Floor {
        Floor::new(
            1.0,
            0.5,
            TAU * 0.5,
            phase,
            Waveform::Sine,
            FloorModel::Exact,
        )
    }

    #[test]
    fn edges_fall_on_the_floor_phase() {
        let f = floor(1.0);
        let c = PhaseClock::of(&f, 8, 0.1).unwrap();
        assert_eq!(c.stride, 1);
        assert_eq!(c.period, 2.0);
        for k in 0..20 {
            let t = c.edge_time(k);
            assert!(t >= 0.0);
            // The floor's phase at an edge is a multiple of 1/8 of a turn: bin_from says which.
            let turns = (f.phase(t) / TAU).rem_euclid(1.0) * 8.0;
            let bin = turns.round() as usize % 8;
            assert!((turns - turns.round()).abs() < 1e-9, "{turns}");
            assert_eq!(bin, c.bin_from(k));
            assert!(k == 0 || c.edge_time(k) > c.edge_time(k - 1));
        }
        for t in [0.0, 0.3, 1.7, 2.0, 33.3] {
            let k = c.first_edge_from(t);
            assert!(c.edge_time(k) >= t && (k == 0 || c.edge_time(k - 1) < t));
        }
    }

    #[test]
    fn bookings_sum_to_the_whole_and_locking_sees_a_locked_height() {
        let c = PhaseClock::of(&floor(0.0), 4, 0.1).unwrap();
        let mut p = PhaseBins::new(c);
        let tally = |time: f64| FloorTally {
            time,
            impacts: (10.0 * time) as u64,
            impulse: 3.0 * time,
        };
        p.open(tally(0.1), 1);
        for k in 1..9 {
            let t = c.edge_time(k);
            p.book(k, tally(t));
            // A height that repeats every period: fully locked.
            p.sample(c.bin_from(k), ([1.0, 2.0, 3.0, 2.0][c.bin_from(k)], 0.0));
        }
        let t = p.table(&floor(0.0), 1.0);
        assert_eq!(t.impacts.iter().sum::<u64>(), 40 - 1);
        assert!((t.exposure.iter().sum::<f64>() - (4.0 - 0.1)).abs() < 1e-12);
        assert!((t.com_locking - 1.0).abs() < 1e-12);
        assert_eq!(t.samples, vec![2, 2, 2, 2]);
    }

    #[test]
    fn sparse_samples_resolve_every_stride_th_period() {
        // Periods of length 2 with 4 bins sampled every 5: every 10th period, all four of its
        // edges (4 phase stops per 20 time units, as many as the samples); sampled every 0.5,
        // every period.
        let c = PhaseClock::of(&floor(0.3), 4, 5.0).unwrap();
        assert_eq!(c.stride, 10);
        assert_eq!(PhaseClock::of(&floor(0.3), 4, 0.5).unwrap().stride, 1);
        let mut k = c.first_edge_from(0.0);
        let mut edges = Vec::new();
        for _ in 0..12 {
            edges.push(c.edge_time(k) / c.period);
            k = c.next_edge(k);
        }
        // Period 0 from its first edge after t = 0, then periods 10 and 20 (edges at 1/4 turn).
        let turns: Vec<f64> = edges.iter().map(|e| e + 0.3 / TAU).collect();
        let want = [
            0.25, 0.5, 0.75, 10.0, 10.25, 10.5, 10.75, 20.0, 20.25, 20.5, 20.75, 30.0,
        ];
        for (t, w) in turns.iter().zip(want) {
            assert!((t - w).abs() < 1e-9, "{turns:?}");
        }
        // A booking across skipped periods books nothing.
        let mut p = PhaseBins::new(c);
        let tally = |time: f64| FloorTally {
            time,
            impacts: 1,
            impulse: 0.0,
        };
        p.book(2, tally(1.0));
        p.book(4, tally(20.0));
        assert_eq!(p.exposure.iter().sum::<f64>(), 0.0);
    }
}
