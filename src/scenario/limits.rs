//! The limits a scene may ask for: magnitudes double precision computes with, and how much of
//! anything (disks, bins, frames, travel, work) a run can be given, and the two checks of a
//! number against them that the scene's checks and the intervals beside it share. The checks,
//! the speeds' checks and the work's check read them alike.

use crate::error::{Error, Result};

/// Densest packing of equal disks in the plane (triangular lattice), π/(2√3).
pub const MAX_PACKING: f64 = 0.906_899_682_117_108_9;

/// Smallest magnitude accepted for any positive quantity: below it squares and products of
/// scene quantities underflow to zero in double precision.
pub const MIN_MAGNITUDE: f64 = 1e-100;
/// Largest magnitude accepted for any quantity: above it squares and products overflow.
pub const MAX_MAGNITUDE: f64 = 1e100;
/// Most disks a scene may hold (the engine keeps a few hundred bytes per disk).
pub const MAX_DISKS: usize = 20_000_000;
/// Largest ratio of a length of the scene (width, height, floor amplitude) to the smallest
/// radius: positions are then resolved to about 10⁻⁷ of a radius in double precision.
pub const MAX_LENGTH_RATIO: f64 = 1e9;
/// Most profile bins.
pub const MAX_PROFILE_BINS: usize = 1_000_000;
/// Most bins per period of the phase-resolved motion (each is a stop of the run).
pub const MAX_PHASE_BINS: usize = 1000;
/// Most cells of the 2D fields along either axis.
pub const MAX_FIELD_BINS: usize = 100_000;
/// Most cells of the 2D fields in all (nine running sums of 8 bytes each, kept twice with
/// `record_fields`: about 0.6 GB at the bound).
pub const MAX_FIELD_CELLS: usize = 4_000_000;
/// Most disk frames (disks × frames) a recording or a trajectory may hold: some 10¹¹ bytes.
pub const MAX_RECORDED_DISKS: f64 = 1e10;
/// Most disk visits the frames and samples of a run may cost (disks × (frames + samples)):
/// each visits every disk, some nanoseconds a disk (8 on a Zen 4 core): hours at the bound.
pub const MAX_OUTPUT_VISITS: f64 = 1e12;
/// Longest wall-clock limit of a run (`run.max_wall_seconds`, `sweep run --max-run-seconds`),
/// about 32 years: a deadline the clock can hold (a limit past 1.8·10¹⁹ s overflowed it).
pub const MAX_WALL_SECONDS: f64 = 1e9;
/// Shortest wall-clock limit of a run (and of a sweep plan's trial runs): a millisecond, less
/// than the start of any run, so a shorter limit only ends it before it begins.
pub const MIN_WALL_SECONDS: f64 = 1e-3;
/// Shortest wall time between progress lines (`--progress-every`): more than ten lines a second
/// fill a log without telling more.
pub const MIN_PROGRESS_SECONDS: f64 = 0.1;
/// Most checkpoints a run may ask for (`--checkpoint-every`); each writes the whole state.
pub const MAX_CHECKPOINTS: f64 = 1e5;
/// Farthest any disk may be sent over the run at its initial or entering speed, in smallest
/// radii: about as many events as it would have (10¹² events are days of computing), and a
/// speed at which the clock still advances by what double precision resolves.
pub const MAX_TRAVEL: f64 = 1e12;
/// Most disk crossings a run may be asked for without a budget of its own (every disk the
/// scene may hold crossing its smallest radius at the scene's speed, over the run: see
/// [`crate::scenario::work`]): 2 to 15 events each in the shipped beds, at a few million events
/// a second on a Zen 4 core, weeks of computing at the bound.
pub const MAX_WORK: f64 = 1e12;
/// Largest `run.max_events` that lets a run ask for more than [`MAX_WORK`]: some ten years of
/// a core at a few million events a second, of the order of the longest wall-clock limit.
pub const MAX_EVENT_BUDGET: f64 = 1e15;
/// Smallest inertia factor `q` of rough disks: spins and their energies stay finite.
pub const MIN_INERTIA_FACTOR: f64 = 1e-6;
/// Deepest a scenario field is nested (`inlets.0.radius.species.0.mass` is six deep).
pub const MAX_FIELD_DEPTH: usize = 8;
/// Most frames, samples or trajectory frames a run may ask for.
pub const MAX_OUTPUT_TIMES: f64 = 1e7;
/// Largest ratio of the largest radius to the smallest that the neighbour masks support.
pub const MAX_RADIUS_RATIO: f64 = 6.0;
/// Most global steps the time-step scheme may be asked for (`run.duration / engine.dt`).
pub const MAX_STEPS: f64 = 1e12;

/// A positive finite number, within [`MIN_MAGNITUDE`, `MAX_MAGNITUDE`].
pub(crate) fn positive(field: &str, v: f64) -> Result<()> {
    if v.is_finite() && (MIN_MAGNITUDE..=MAX_MAGNITUDE).contains(&v) {
        Ok(())
    } else if v.is_finite() && v > 0.0 {
        Err(Error::input(
            field,
            format!(
                "{v:e} is outside the range [{MIN_MAGNITUDE:e}, {MAX_MAGNITUDE:e}] that double precision computes with (choose units closer to the scene)"
            ),
        ))
    } else {
        Err(Error::input(
            field,
            format!("must be a positive finite number (got {v})"),
        ))
    }
}

/// At most `limit` of something asked for by `count = span / interval`.
pub(crate) fn at_most(field: &str, what: &str, count: f64, limit: f64) -> Result<()> {
    if count <= limit {
        Ok(())
    } else {
        Err(Error::input(
            field,
            format!("asks for {count:.3e} {what} in the run; at most {limit:e} are supported"),
        ))
    }
}
