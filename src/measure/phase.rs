//! Motion against the floor's phase: the centre of mass, the bed's lower edge and the floor's
//! impacts and impulse in bins over one vibration period, after the warm-up; and, split by the
//! period's place in a group of four, the centre of mass and the heights of the bed's columns
//! (period doubling, and undulations: standing waves whose crests and troughs swap every period or
//! every second period).
//!
//! The run stops at every bin edge `k/B` of the floor's phase (B stops per period, whatever the
//! sample interval: samples at a fixed interval alias with the period — a sample interval equal to
//! the period sees one phase only). At each edge the centre of mass and the lower edge are sampled,
//! and the floor's impacts and impulse since the previous edge are booked into the bin just left;
//! the pieces of bins cut by the window's start and the run's end are booked too, so the bins sum
//! to the whole window. The phase stops cost what samples cost (a pass over the disks): they are
//! kept no more frequent than the samples by resolving every `stride`-th period only (the bins
//! then sum to those periods). The resolved periods come in groups of four consecutive ones, so
//! that motion over two and four periods is seen whatever the stride.

use crate::measure::States;
use crate::physics::disks::Disks;
use crate::physics::floor::Floor;
use crate::scenario::phase_stops::{stride, GROUP};
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
    /// Every `stride`-th group of four periods is resolved (1: all periods).
    pub stride: u64,
}

impl PhaseClock {
    /// The clock of a vibrating floor (`None` for a static one), `bins` bins per period, in a run
    /// sampled every `sample_dt`: every stride-th group of four periods is resolved so that the
    /// phase stops are no more frequent than the samples (the stride does not depend on the run's
    /// length, so a resumed run resolves the same periods as an uninterrupted one).
    pub fn of(floor: &Floor, bins: usize, sample_dt: f64) -> Option<PhaseClock> {
        if floor.is_static() || bins == 0 {
            return None;
        }
        let origin = (floor.phase_origin() / TAU).rem_euclid(1.0);
        let period = floor.drive().period();
        Some(PhaseClock {
            bins,
            period,
            origin,
            first: (origin * bins as f64).ceil() as u64,
            stride: stride(bins, sample_dt, period),
        })
    }

    /// The edge after edge `k` at which the run stops: the next one, or the first of the next
    /// resolved group of periods.
    pub fn next_edge(&self, k: u64) -> u64 {
        let (b, next) = (self.bins as u64, self.first + k + 1);
        let group = next / b / GROUP as u64;
        if next % b != 0 || group.is_multiple_of(self.stride) {
            return k + 1;
        }
        group.div_ceil(self.stride) * self.stride * GROUP as u64 * b - self.first
    }

    /// The place, 0 to 3, in its group of four of the period the `k`-th edge starts a bin of.
    pub fn place(&self, k: u64) -> usize {
        ((self.first + k) / self.bins as u64 % GROUP as u64) as usize
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
    /// The same samples per bin and place of the period in its group of four.
    places: Places,
    /// A sample's disk bottoms and column sums, kept so that a sample allocates nothing.
    #[serde(skip)]
    scratch: (Vec<f64>, Vec<(f64, f64)>),
}

/// The three ways of halving a group of four periods that a shape can swap between: every period
/// (places 0, 2 against 1, 3), and every second period starting at an even or an odd place.
const SWAPS: [([usize; 2], [usize; 2]); 3] = [([0, 2], [1, 3]), ([0, 1], [2, 3]), ([1, 2], [3, 0])];

/// Sums per bin of the floor's phase and place of the period in its group (index
/// `GROUP·bin + place`): the centre of mass, and each column's height less the mean over the
/// columns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Places {
    /// Columns across the width.
    columns: usize,
    /// The domain's width.
    width: f64,
    samples: Vec<u64>,
    com: Vec<f64>,
    /// Index `(GROUP·bin + place)·columns + column`.
    column_height: Vec<f64>,
    /// Their squares, for the noise of the means.
    column_height_sq: Vec<f64>,
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
    /// Share of the centre of mass's variance (over all phase samples) explained by the phase,
    /// corrected for the bins' finite samples (see `locking`); 1 for a bed locked to the
    /// floor's period, near 0 for one whose height does not follow the floor. Absent with no
    /// more samples than bins.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub com_locking: Option<f64>,
    /// The same over two periods (bins of the phase and the parity of the period): 1 for a bed
    /// whose motion repeats every second period (period doubling) as well as every period.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub com_locking_two_periods: Option<f64>,
    /// The part of the bed's shape that swaps between periods: a column's height less the mean
    /// over the columns, averaged per bin over the periods of each place in their group of four;
    /// the root mean square, over the bins and the columns, of half the difference between two
    /// halves of the group — places 0, 2 against 1, 3 (a swap every period), or 0, 1 against
    /// 2, 3, or 1, 2 against 3, 0 (a swap every second period: a period-doubled bed whose arches
    /// swap at each landing) — the largest of the three (a length). A standing wave that swaps so
    /// gives its amplitude over √2; a static heap, noise or a wave that repeats every period
    /// gives about nothing.
    pub undulation: f64,
}

impl PhaseBins {
    /// Empty bins on `clock`, the bed's shape in `columns` columns across `width`.
    pub fn new(clock: PhaseClock, columns: usize, width: f64) -> PhaseBins {
        let (u, f) = (vec![0; clock.bins], vec![0.0; clock.bins]);
        let columns = columns.max(1);
        PhaseBins {
            scratch: Default::default(),
            places: Places {
                columns,
                width,
                samples: vec![0; GROUP * clock.bins],
                com: vec![0.0; GROUP * clock.bins],
                column_height: vec![0.0; GROUP * clock.bins * columns],
                column_height_sq: vec![0.0; GROUP * clock.bins * columns],
            },
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

    /// Samples the bed at the `k`-th edge, the floor at height `floor`: the centre of mass, the
    /// lower edge and the columns' heights.
    pub fn sample(&mut self, k: u64, states: &impl States, disks: &Disks, floor: f64) {
        let t = &self.places;
        let (mut m_sum, mut my) = (0.0, 0.0);
        let (mut bottoms, mut columns) = std::mem::take(&mut self.scratch);
        bottoms.clear();
        columns.clear();
        columns.resize(t.columns, (0.0, 0.0));
        let per_column = t.columns as f64 / t.width;
        states.each(|i, [x, y, _, _]| {
            let m = disks.mass[i];
            m_sum += m;
            my += m * y;
            bottoms.push(y - disks.radius[i] - floor);
            let c = ((x * per_column) as usize).min(t.columns - 1);
            columns[c].0 += m * y;
            columns[c].1 += m;
        });
        let filled = columns.iter().filter(|c| c.1 > 0.0);
        let mean = filled.clone().map(|c| c.0 / c.1).sum::<f64>() / filled.count().max(1) as f64;
        let deviations = columns
            .iter()
            .map(|c| if c.1 > 0.0 { c.0 / c.1 - mean } else { 0.0 });
        let lower = lower_edge(&mut bottoms);
        self.add(k, my / m_sum, lower, deviations);
        self.scratch = (bottoms, columns);
    }

    /// Adds the centre-of-mass height, lower edge and columns' height deviations sampled at
    /// the `k`-th edge.
    fn add(&mut self, k: u64, com: f64, lower: f64, deviations: impl Iterator<Item = f64>) {
        let bin = self.clock.bin_from(k);
        self.samples[bin] += 1;
        self.com[bin] += com;
        self.com_sq[bin] += com * com;
        self.lower[bin] += lower;
        let t = &mut self.places;
        let at = GROUP * bin + self.clock.place(k);
        t.samples[at] += 1;
        t.com[at] += com;
        let row = at * t.columns..(at + 1) * t.columns;
        let sums = t.column_height[row.clone()].iter_mut();
        let squares = t.column_height_sq[row].iter_mut();
        for ((h, h_sq), d) in sums.zip(squares).zip(deviations) {
            *h += d;
            *h_sq += d * d;
        }
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
                .map(|p| floor.height((p * TAU - floor.phase_origin()) / floor.drive().omega))
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
            com_locking_two_periods: self.com_locking_two_periods(),
            undulation: self.undulation(),
        }
    }

    /// The share of the centre of mass's variance the bins explain (see [`locking`]).
    fn com_locking(&self) -> Option<f64> {
        locking(&self.samples, &self.com, &self.com_sq)
    }

    /// The same with the bins over two periods (the places of a group merged by parity).
    fn com_locking_two_periods(&self) -> Option<f64> {
        let t = &self.places;
        let by_parity = |bin: usize, parity: usize| {
            let (a, b) = (GROUP * bin + parity, GROUP * bin + parity + 2);
            (t.samples[a] + t.samples[b], t.com[a] + t.com[b])
        };
        let (samples, com): (Vec<u64>, Vec<f64>) = (0..self.clock.bins)
            .flat_map(|bin| [by_parity(bin, 0), by_parity(bin, 1)])
            .unzip();
        locking(&samples, &com, &self.com_sq)
    }

    /// See [`PhaseTable::undulation`]: the largest of the three ways a shape can swap within a
    /// group of four periods, over the bins sampled in every place.
    fn undulation(&self) -> f64 {
        SWAPS
            .iter()
            .map(|&swap| self.swapping_shape(swap))
            .fold(0.0, f64::max)
    }

    /// The root mean square, over the bins sampled in every place and the columns, of half the
    /// difference between a column's mean height deviation in places `a` and in places `b`, less
    /// the part the samples' own scatter puts in it (the squared standard error of that half
    /// difference): noise, a gas's busy columns included, gives about nothing on average.
    fn swapping_shape(&self, (a, b): ([usize; 2], [usize; 2])) -> f64 {
        let t = &self.places;
        let (mut sum, mut n) = (0.0, 0);
        for bin in 0..self.clock.bins {
            let at = |place: usize| GROUP * bin + place;
            if (0..GROUP).any(|place| t.samples[at(place)] == 0) {
                continue;
            }
            // Mean and squared standard error of column `c`'s deviation over `places`.
            let half = |places: [usize; 2], c: usize| {
                let of = |v: &[f64]| {
                    places
                        .iter()
                        .map(|&p| v[at(p) * t.columns + c])
                        .sum::<f64>()
                };
                let m = places.iter().map(|&p| t.samples[at(p)]).sum::<u64>() as f64;
                let mean = of(&t.column_height) / m;
                let var = (of(&t.column_height_sq) - m * mean * mean).max(0.0) / (m - 1.0);
                (mean, var / m)
            };
            for c in 0..t.columns {
                let ((mean_a, err_a), (mean_b, err_b)) = (half(a, c), half(b, c));
                sum += ((mean_a - mean_b) / 2.0).powi(2) - (err_a + err_b) / 4.0;
                n += 1;
            }
        }
        if n > 0 {
            (sum / n as f64).max(0.0).sqrt()
        } else {
            0.0
        }
    }
}

/// The share of the samples' variance that their bins explain, corrected for the bins' finite
/// samples: ω² = (SS_b − (k − 1)·MS_w) / (SS_t + MS_w) of a one-way analysis of variance (k bins
/// sampled, SS_b the bins' means' sum of squares, MS_w the mean square within bins), clamped to
/// [0, 1]. Uncorrected, bins of one or two samples each would explain most of any noise. `None`
/// with no more samples than bins. `samples` and `sum` per bin, `sum_sq` the squares summed in
/// any bins.
fn locking(samples: &[u64], sum: &[f64], sum_sq: &[f64]) -> Option<f64> {
    let n: u64 = samples.iter().sum();
    let k = samples.iter().filter(|&&m| m > 0).count() as u64;
    if n <= k {
        return None;
    }
    let all = sum.iter().sum::<f64>() / n as f64;
    let total = (sum_sq.iter().sum::<f64>() - n as f64 * all * all).max(0.0);
    let between = samples
        .iter()
        .zip(sum)
        .filter(|(&m, _)| m > 0)
        .map(|(&m, &s)| m as f64 * (s / m as f64 - all).powi(2))
        .sum::<f64>();
    let within = (total - between).max(0.0) / (n - k) as f64;
    if total + within > 0.0 {
        Some(((between - (k - 1) as f64 * within) / (total + within)).clamp(0.0, 1.0))
    } else {
        Some(0.0)
    }
}

/// The lower edge (see [`LOWER_EDGE_FRACTION`]) of the disks whose bottoms lie at `bottoms`
/// above the floor (reordered).
fn lower_edge(bottoms: &mut [f64]) -> f64 {
    if bottoms.is_empty() {
        return 0.0;
    }
    let k = ((LOWER_EDGE_FRACTION * bottoms.len() as f64) as usize).min(bottoms.len() - 1);
    *bottoms.select_nth_unstable_by(k, f64::total_cmp).1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::drive::Drive;

    fn floor(phase: f64) -> Floor {
        Floor::new(1.0, Drive::new(0.5, 0.5), phase)
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
        let mut p = PhaseBins::new(c, 1, 1.0);
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
            p.add(
                k,
                [1.0, 2.0, 3.0, 2.0][c.bin_from(k)],
                0.0,
                std::iter::empty(),
            );
        }
        let t = p.table(&floor(0.0), 1.0);
        assert_eq!(t.impacts.iter().sum::<u64>(), 40 - 1);
        assert!((t.exposure.iter().sum::<f64>() - (4.0 - 0.1)).abs() < 1e-12);
        assert!((t.com_locking.unwrap() - 1.0).abs() < 1e-12);
        // One sample in each bin over two periods: nothing to tell locking from noise.
        assert_eq!(t.com_locking_two_periods, None);
        assert_eq!(t.samples, vec![2, 2, 2, 2]);
    }

    #[test]
    fn sparse_samples_resolve_every_stride_th_period() {
        // Periods of length 2 with 4 bins sampled every 5: every 10th group of four periods, all
        // their edges (16 phase stops per 80 time units, as many as the samples); sampled every
        // 0.5, every period.
        let c = PhaseClock::of(&floor(0.3), 4, 5.0).unwrap();
        assert_eq!(c.stride, 10);
        assert_eq!(PhaseClock::of(&floor(0.3), 4, 0.5).unwrap().stride, 1);
        let mut k = c.first_edge_from(0.0);
        let mut edges = Vec::new();
        for _ in 0..20 {
            edges.push(c.edge_time(k) / c.period);
            k = c.next_edge(k);
        }
        // Periods 0 (from its first edge after t = 0) to 3, then 40 (edges at 1/4 turn).
        let turns: Vec<f64> = edges.iter().map(|e| e + 0.3 / TAU).collect();
        let want = [
            0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5, 2.75, 3.0, 3.25, 3.5, 3.75,
            40.0, 40.25, 40.5, 40.75, 41.0,
        ];
        for (t, w) in turns.iter().zip(want) {
            assert!((t - w).abs() < 1e-9, "{turns:?}");
        }
        // A booking across skipped periods books nothing.
        let mut p = PhaseBins::new(c, 1, 1.0);
        let tally = |time: f64| FloorTally {
            time,
            impacts: 1,
            impulse: 0.0,
        };
        p.book(2, tally(1.0));
        p.book(4, tally(20.0));
        assert_eq!(p.exposure.iter().sum::<f64>(), 0.0);
    }

    /// Periods of 4 bins each, every period sampled, 12 periods (3 groups): the centre of mass
    /// at `com(k)` and the columns' deviations `shape(k, column)` at edge `k`.
    fn periods(com: impl Fn(u64) -> f64, shape: impl Fn(u64, usize) -> f64) -> PhaseTable {
        let c = PhaseClock::of(&floor(0.0), 4, 0.1).unwrap();
        let mut p = PhaseBins::new(c, 4, 8.0);
        for k in 0..48 {
            p.add(k, com(k), 0.0, (0..4).map(|column| shape(k, column)));
        }
        p.table(&floor(0.0), 1.0)
    }

    #[test]
    fn a_period_doubled_bed_locks_over_two_periods_only() {
        let c = PhaseClock::of(&floor(0.0), 4, 0.1).unwrap();
        // Up by one every other period at the same phase: the phase alone explains nothing.
        let t = periods(|k| (c.place(k) % 2) as f64, |_, _| 0.0);
        assert_eq!(t.com_locking, Some(0.0));
        assert!((t.com_locking_two_periods.unwrap() - 1.0).abs() < 1e-12);
        assert_eq!(t.undulation, 0.0);
    }

    #[test]
    fn noise_is_not_locked_however_few_samples_a_bin_holds() {
        // Heights drawn at random (a fixed linear congruential sequence), 3 per bin in 20 bins:
        // the bins' raw means explain about a third of the variance; corrected, nothing on
        // average (over 200 such sets).
        let mut x = 12345u64;
        let mut draw = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut mean = 0.0;
        for _ in 0..200 {
            let (mut samples, mut sum, mut sum_sq) = (vec![0; 20], vec![0.0; 20], vec![0.0; 20]);
            for k in 0..60 {
                let h = draw();
                samples[k % 20] += 1;
                sum[k % 20] += h;
                sum_sq[k % 20] += h * h;
            }
            mean += locking(&samples, &sum, &sum_sq).unwrap() / 200.0;
        }
        assert!(mean < 0.06, "{mean}");
    }

    #[test]
    fn undulations_are_the_shape_that_alternates_between_periods() {
        let c = PhaseClock::of(&floor(0.0), 4, 0.1).unwrap();
        let sign = |column: usize| if column.is_multiple_of(2) { 1.0 } else { -1.0 };
        // Arches of amplitude 0.7 (in half the bins) that swap every period, or every second
        // period from an even or an odd place; and a static heap.
        let arches = |flips: [f64; 4]| {
            move |k: u64, column: usize| {
                let on = if c.bin_from(k) < 2 { 0.7 } else { 0.0 };
                on * flips[c.place(k)] * sign(column)
            }
        };
        for flips in [
            [1.0, -1.0, 1.0, -1.0],
            [1.0, 1.0, -1.0, -1.0],
            [-1.0, 1.0, 1.0, -1.0],
        ] {
            let t = periods(|_| 0.0, arches(flips));
            assert!(
                (t.undulation - 0.7 / 2f64.sqrt()).abs() < 1e-12,
                "{}",
                t.undulation
            );
        }
        let heap = periods(|_| 0.0, |_, column| 0.7 * sign(column));
        assert!(heap.undulation < 1e-12);
    }

    #[test]
    fn a_sample_splits_the_bed_into_columns() {
        use crate::measure::Given;
        let c = PhaseClock::of(&floor(0.0), 4, 0.1).unwrap();
        let mut p = PhaseBins::new(c, 2, 4.0);
        // Two disks in the left column at heights 1 and 3, one in the right at 5.
        let states = Given(vec![
            [0.5, 1.0, 0.0, 0.0],
            [1.5, 3.0, 0.0, 0.0],
            [3.0, 5.0, 0.0, 0.0],
        ]);
        let disks = Disks::new(&[[0.0; 2]; 3], vec![0.5; 3], vec![1.0; 3], vec![0; 3]);
        p.sample(0, &states, &disks, 0.0);
        assert_eq!(p.places.column_height[..2], [-1.5, 1.5]);
        assert_eq!(p.com[0], 3.0);
        assert_eq!(p.lower[0], 0.5);
    }
}
