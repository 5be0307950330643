//! When the phase-resolved motion stops a run: `output.phase_bins` edges a floor period, in
//! groups of four consecutive periods, every `stride`-th group — fixed by the scene alone (its
//! bins, sample interval and floor period), so that the checks can tell how many periods a
//! window resolves before anything runs, and the measurement stops where they said.

/// Periods in a group: motion that repeats every period, every second or every fourth period
/// (a period-doubled bed whose shape swaps at each landing) is told apart.
pub const GROUP: usize = 4;

/// Every how many groups of periods of length `period` the phase stops resolve, `bins` a
/// period, in a run sampled every `sample_dt`: no more phase stops than samples.
pub fn stride(bins: usize, sample_dt: f64, period: f64) -> u64 {
    (bins as f64 * sample_dt / period).ceil().max(1.0) as u64
}
