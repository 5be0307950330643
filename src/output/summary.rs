//! The run summary (JSON): what users, their scripts and the regression suite read.

use crate::engine::EventCounts;
use crate::measure::{Observables, ProfileTable};
use serde::Serialize;

/// How the run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Ending {
    /// Reached `run.duration`.
    Completed,
    /// Stopped by Ctrl-C; the summary covers the time simulated so far.
    Interrupted,
    /// Stopped by `run.max_events`.
    EventLimit,
    /// Stopped by `run.max_wall_seconds` (or `sweep run --max-run-seconds`): the wall-clock
    /// time allowed for the run was spent; the summary covers the time simulated so far.
    WallLimit,
    /// Simulated time stopped advancing (a bug of the engine's rules, reported on standard
    /// error with the disks and rules involved); the summary covers the time simulated so far.
    Stalled,
}

/// Exit code of a run stopped by `run.max_events`.
pub const EXIT_EVENT_LIMIT: i32 = 4;
/// Exit code of a run stopped by `run.max_wall_seconds`.
pub const EXIT_WALL_LIMIT: i32 = 5;
/// Exit code of a run whose simulated time stopped advancing (`"ending": "stalled"`): its own,
/// apart from 1 (a failure with no summary), so that a script or a batch system can tell them
/// apart.
pub const EXIT_STALLED: i32 = 6;

impl Ending {
    /// How the run ended, in words (progress lines, sweep logs, the recording's last note).
    pub fn words(self) -> &'static str {
        match self {
            Ending::Completed => "completed",
            Ending::Interrupted => "interrupted",
            Ending::EventLimit => "stopped by the event limit (run.max_events)",
            Ending::WallLimit => "stopped by the wall-clock limit (run.max_wall_seconds)",
            Ending::Stalled => "stopped: simulated time stalled",
        }
    }

    /// The exit code of a run that ended so (before any output failure): 0 completed,
    /// 128 + the signal's number interrupted, [`EXIT_EVENT_LIMIT`], [`EXIT_WALL_LIMIT`],
    /// [`EXIT_STALLED`]: each ending but `completed` its own, none 0.
    pub fn exit_code(self) -> i32 {
        match self {
            Ending::Completed => 0,
            Ending::Interrupted => crate::platform::signals::exit_code(),
            Ending::EventLimit => EXIT_EVENT_LIMIT,
            Ending::WallLimit => EXIT_WALL_LIMIT,
            Ending::Stalled => EXIT_STALLED,
        }
    }
}

/// Kinetic and potential energy at one time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EnergyAt {
    /// Σ ½ m v².
    pub kinetic: f64,
    /// Σ m g y.
    pub potential: f64,
    /// Σ ½ I ω² (rough disks only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotational: Option<f64>,
    /// kinetic + potential (+ rotational).
    pub total: f64,
}

impl From<&Observables> for EnergyAt {
    fn from(o: &Observables) -> Self {
        EnergyAt {
            kinetic: o.kinetic,
            potential: o.potential,
            rotational: o.rotational,
            total: o.energy(),
        }
    }
}

/// The time-averaged normal force of the floor per unit width, beside the bed's weight per unit
/// width `M g / width`: in a steady state (or a bed at rest) the two agree, the difference being
/// the change of the disks' vertical momentum over the window divided by its length and width.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FloorPressure {
    /// Vertical momentum the floor gave the disks over the window (impacts, and the force
    /// carrying the disks at rest on it) per unit time and width.
    pub measured: f64,
    /// `M g / width`.
    pub weight: f64,
}

/// The energy budget: final = initial + injected − dissipated, to round-off.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EnergySummary {
    /// At the start.
    pub initial: EnergyAt,
    /// At the end.
    #[serde(rename = "final")]
    pub final_: EnergyAt,
    /// Work done by the floor.
    pub injected: f64,
    /// Lost in collisions.
    pub dissipated: f64,
    /// Carried out by disks that left (scenes where disks leave or enter).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub carried_out: Option<f64>,
    /// Brought in by disks that entered (scenes where disks leave or enter).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub carried_in: Option<f64>,
    /// |final − initial − injected + dissipated + carried out − carried in| relative to the
    /// largest term.
    pub balance_error: f64,
}

/// Granular temperature per axis, time-averaged over the samples after the warm-up.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Temperature {
    /// ⟨Σ m (vx − Vx)²⟩/N.
    pub x: f64,
    /// ⟨Σ m (vy − Vy)²⟩/N.
    pub y: f64,
    /// (x + y)/2.
    pub mean: f64,
    /// ⟨Σ I ω²⟩/N (rough disks only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotational: Option<f64>,
    /// The local temperature (gravity scenes): each height bin's temperature about its own
    /// mean velocity, averaged over the bins weighted by their density; `x`, `y` and `mean`
    /// are about the whole bed's mean velocity at each sample, so they also count the motion
    /// of one height against another.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub local: Option<f64>,
}

/// How the engine was set up.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EngineSummary {
    /// Integration scheme.
    pub scheme: String,
    /// Neighbour mask (Isobe's name).
    pub mask: String,
    /// Grid cell side.
    pub cell: f64,
    /// Grid storage: `dense` or `hashed` (open top).
    pub grid: String,
    /// Event queue of the exact engine: `calendar` or `tree`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub queue: Option<&'static str>,
    /// Re-mapping of the exact engine: `global` or `local`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub remap: Option<&'static str>,
    /// Bytes held by the engine per disk.
    pub bytes_per_disk: f64,
    /// Threads the approximate schemes ran on (`engine.threads`); absent for the exact engine,
    /// which runs on one core.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub threads: Option<usize>,
    /// Measurement samples averaged.
    pub samples: usize,
}

/// The whole summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Scenario name.
    pub scenario: String,
    /// Seed used.
    pub seed: u64,
    /// Number of disks.
    pub particles: usize,
    /// How the run ended.
    pub ending: Ending,
    /// Simulated time reached.
    pub sim_time: f64,
    /// Wall-clock seconds of the event loop (setup excluded).
    pub wall_seconds: f64,
    /// Events by kind.
    pub events: EventCounts,
    /// (pair + wall + lid + floor collisions) per wall-clock second.
    pub collisions_per_second: f64,
    /// Energy budget.
    pub energy: EnergySummary,
    /// Granular temperature (averaged after warm-up); absent when no sample was taken after it
    /// (a run that ended before its warm-up did).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub temperature: Option<Temperature>,
    /// Z = PA/(NkT) from the pair collision virial, for a closed elastic box without gravity.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compressibility_factor: Option<f64>,
    /// Packing fraction of a closed box.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub packing_fraction: Option<f64>,
    /// Largest overlap seen at a contact (distance units).
    pub max_overlap: f64,
    /// Mean centre-of-mass height (averaged after warm-up), gravity scenes; absent before the
    /// first sample after the warm-up.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub com_height: Option<f64>,
    /// Floor impacts per unit simulated time (after warm-up), scenes with a floor.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub impacts_per_unit_time: Option<f64>,
    /// Pressure on the floor (after warm-up), scenes with gravity and a floor.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub floor_pressure: Option<FloorPressure>,
    /// Time to rest: the time the last disk came to rest (riding the floor or resting on disks
    /// at rest, resting contacts), every disk at rest from then to the end of the run — exact
    /// to the event in the event-driven engine; absent if some disk still moved at the end.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub at_rest_since: Option<f64>,
    /// Disks released from a bed all at rest by the rest rules or a collision, not by the
    /// floor, an outlet or an arriving disk; absent when none was.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rest_wakes: Option<u64>,
    /// Height profiles (gravity scenes; absent before the first sample after the warm-up).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub profiles: Option<ProfileTable>,
    /// The motion against the floor's phase (after warm-up): a vibrating floor under gravity.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phase: Option<crate::measure::phase::PhaseTable>,
    /// The bed's state and the indicators that decided it: a floor under gravity.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub state: Option<crate::measure::state::BedState>,
    /// Distributions of the scaled velocities c = (v − u)/√T per axis, with their kurtosis
    /// (after the warm-up; `output.velocity_distribution` only, absent before any sample).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub velocity_distribution: Option<crate::measure::velocities::VelocityDistribution>,
    /// The 2D fields (`run --fields`), written to their own file, not into the summary.
    #[serde(skip)]
    pub fields: Option<crate::measure::fields::Fields>,
    /// Engine set-up.
    pub engine: EngineSummary,
    /// Steps and errors of an approximate scheme (`engine.scheme` `time-step` or `space-time`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub approximation: Option<crate::schemes::SchemeStats>,
    /// Outputs this run (or this resumed part) could not write; the run went on without them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub output_failures: Vec<OutputFailure>,
    /// Why simulated time stopped advancing (ending `stalled`): the disks and rules involved.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stall: Option<String>,
    /// Disks in and out, where they enter or leave (inlets, a floor orifice, an exit height).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flow: Option<FlowSummary>,
}

/// Disks in and out of a scene with a pool (inlets, a floor orifice, an exit height), and the
/// discharge rate after the warm-up.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FlowSummary {
    /// Disks at the start.
    pub initial: u64,
    /// Disks that entered.
    #[serde(rename = "in")]
    pub in_: u64,
    /// Disks that left.
    pub out: u64,
    /// Of them, those that left at the top (scenes with `domain.exit_height` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub out_top: Option<u64>,
    /// Disks in the scene at the end (initial + in − out).
    pub live: u64,
    /// Mass that left.
    pub mass_out: f64,
    /// Energy the leaving disks carried out (kinetic and potential as they left).
    pub energy_out: f64,
    /// Disks out after the warm-up.
    pub exits_measured: u64,
    /// Disks per unit time out after the warm-up: one over the mean interval between exits
    /// (absent before two exits).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate: Option<f64>,
    /// Its standard error, from the spread of the intervals (taken as independent).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_error: Option<f64>,
    /// Mass per unit time out after the warm-up: the rate times the mean mass of the exits.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_rate: Option<f64>,
    /// Impacts on the orifice's corners.
    pub corner_impacts: u64,
    /// Disks at rest on the floor that slid over an edge of the orifice.
    pub slid_over_edge: u64,
    /// Energy the entering disks brought in.
    pub energy_in: f64,
    /// Entries that found no free place in their inlet and waited.
    pub waits: u64,
}

impl FlowSummary {
    /// The summary of `flow` with `live` disks at the end (`top`: the scene has an exit
    /// height).
    pub fn of(flow: &crate::engine::pool::Flow, live: usize, top: bool) -> FlowSummary {
        let rate = flow.rate();
        FlowSummary {
            initial: flow.initial,
            in_: flow.entered,
            out: flow.left,
            out_top: top.then_some(flow.top),
            live: live as u64,
            mass_out: flow.mass_out,
            energy_out: flow.energy_out,
            exits_measured: flow.exits,
            rate: rate.map(|r| r.0),
            rate_error: rate.map(|r| r.1),
            mass_rate: rate.map(|r| r.0 * flow.exit_mass / flow.exits as f64),
            corner_impacts: flow.corner,
            slid_over_edge: flow.edge,
            energy_in: flow.energy_in,
            waits: flow.waits,
        }
    }
}

/// An output the run could not write: a recording or trajectory (dropped from then on) or a
/// checkpoint (tried again at the next interval and at the end).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OutputFailure {
    /// `recording`, `trajectory` or `checkpoint`.
    pub output: &'static str,
    /// The file that could not be written.
    pub path: String,
    /// Simulated time at which the run noticed the first failure.
    pub time: f64,
    /// The first failure, with the operating system's reason.
    pub error: String,
    /// How many times writing it failed (a checkpoint is tried again).
    pub failures: u64,
}

impl Summary {
    /// Pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("summary serialises") + "\n"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::{Error, EXIT_OUTPUT_FAILED};

    /// Each ending but `completed` exits with a code of its own: none 0, no two alike, and none
    /// that of a failure (1), of bad input (2) or of a lost output (3), so that a script tells a
    /// stalled run from a crashed one and an event limit from a wall-clock limit.
    #[test]
    fn every_ending_but_completed_has_its_own_nonzero_exit_code() {
        let endings = [
            Ending::Interrupted,
            Ending::EventLimit,
            Ending::WallLimit,
            Ending::Stalled,
        ];
        assert_eq!(Ending::Completed.exit_code(), 0);
        let taken = [
            0,
            Error::Runtime(String::new()).exit_code(),
            Error::input("x", "y").exit_code(),
            EXIT_OUTPUT_FAILED,
        ];
        let mut seen = Vec::new();
        for e in endings {
            let code = e.exit_code();
            assert!(!taken.contains(&code), "{e:?} exits {code}, a code taken");
            assert!(
                !seen.contains(&code),
                "{e:?} exits {code}, as another ending"
            );
            seen.push(code);
        }
        assert_eq!(Ending::Stalled.exit_code(), EXIT_STALLED);
    }
}
