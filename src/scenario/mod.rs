//! The scenario file: a JSON description of one scene. It states only what the scene needs;
//! whatever it leaves out is not simulated (no `gravity` → no gravity, no `floor` → no floor).
//!
//! Loading goes: JSON text → `serde_json::Value` → `--set` overrides ([`overrides`]) → typed
//! [`Scenario`] (unknown fields rejected, errors name the dotted path) → [`Scenario::validate`]
//! (physical sense: positive radii, reachable packing fraction, …).

pub mod intervals;
pub mod json;
pub mod limits;
pub mod overrides;
pub mod phase_stops;
pub mod speeds;
pub mod work;

use crate::error::{excerpt, Error, Result};
use crate::physics::drive::Drive;
pub use crate::physics::drive::{FloorModel, Waveform};
use crate::physics::restitution::Restitution;
use crate::scenario::json::quotes_cut;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A whole scene: domain, forces, floor, disks, collision law, run length, output, engine knobs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Name shown in summaries and recordings.
    pub name: String,
    /// Seed of the random initial state (positions, velocities).
    #[serde(default)]
    pub seed: u64,
    /// The box.
    pub domain: Domain,
    /// Gravitational acceleration g > 0, pointing to −y. Absent: no gravity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<f64>,
    /// The floor at mean height y = 0. Absent: no floor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub floor: Option<Floor>,
    /// The disks.
    pub particles: Particles,
    /// Pair collision law.
    #[serde(default)]
    pub collisions: Collisions,
    /// How long to run.
    pub run: Run,
    /// What to measure and write.
    #[serde(default)]
    pub output: Output,
    /// Integration scheme and its knobs.
    #[serde(default)]
    pub engine: Engine,
    /// Sources of disks entering the scene while it runs.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inlets: Vec<Inlet>,
}

/// An interval `[from, to]` of one coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Span {
    /// Lower end.
    pub from: f64,
    /// Upper end (at least `from`).
    pub to: f64,
}

/// A source of disks: their centres enter uniformly in a box (a segment where `y.from = y.to`)
/// at a rate or a total count over a window, sized as `particles` sizes its disks, falling at
/// a speed and/or with a temperature; leaving disks may come back in through it (`recycle`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Inlet {
    /// Where centres enter across the width.
    pub x: Span,
    /// Where centres enter in height.
    pub y: Span,
    /// New disks per unit time, from `start` to `end`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate: Option<f64>,
    /// Or this many new disks, evenly spread over `[start, end)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<u64>,
    /// When the first new disk enters.
    #[serde(default)]
    pub start: f64,
    /// When new disks stop (absent: the end of the run).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end: Option<f64>,
    /// Downward speed of the disks entering.
    #[serde(default)]
    pub speed: f64,
    /// Granular temperature of the disks entering (Maxwellian velocities about the downward
    /// speed).
    #[serde(default)]
    pub temperature: f64,
    /// Disks leaving (through the floor's orifice or the exit height) come back in here
    /// (keeping their ids).
    #[serde(default)]
    pub recycle: bool,
    /// Radius of the new disks, in the forms of `particles.radius` (a species list's counts are
    /// the odds of each species). Absent: the particles' own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<Radius>,
    /// Mass of every new disk (absent: by `density`, else the particles' law).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<f64>,
    /// Areal mass density of the new disks: mass = density·π·radius². Alternative to `mass`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
}

/// The box: its width, what bounds it in x and y.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Domain {
    /// Extent in x, from 0 to `width`.
    pub width: f64,
    /// Height of the lid, or the period in y. Not used for an open top.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<f64>,
    /// `walls` (hard walls at x = 0 and x = width) or `periodic`.
    #[serde(default)]
    pub x_boundary: XBoundary,
    /// `open` (no ceiling), `lid` (a hard wall at y = height) or `periodic` (period `height`).
    #[serde(default)]
    pub y_boundary: YBoundary,
    /// Restitution of the side walls and the lid (1 = elastic).
    #[serde(default = "one")]
    pub wall_restitution: f64,
    /// Coulomb friction μ of the side walls and the lid (rough disks). Absent: smooth walls,
    /// unless `wall_tangential_restitution` is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_friction: Option<f64>,
    /// Tangential restitution β ∈ [−1, 1] of the side walls and the lid (rough disks).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_tangential_restitution: Option<f64>,
    /// Under an open top: a disk whose centre rises to this height leaves the scene (through
    /// the pool, as through the floor's orifice). Absent: no disk leaves by the top.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exit_height: Option<f64>,
}

/// What bounds the domain in x.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum XBoundary {
    /// Hard walls at x = 0 and x = width.
    #[default]
    Walls,
    /// Periodic with period `width`.
    Periodic,
}

/// What bounds the domain at the top (and, for `periodic`, at the bottom).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum YBoundary {
    /// No ceiling: the bed may expand without bound.
    #[default]
    Open,
    /// A hard wall at y = height.
    Lid,
    /// Periodic with period `height` (no floor allowed).
    Periodic,
}

/// The floor: static, or vibrating with `h(t) = A·w(2π f t + φ0)` for a waveform w.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Floor {
    /// Normal restitution of disk–floor impacts.
    #[serde(default = "one")]
    pub restitution: f64,
    /// Vibration amplitude A (0 or absent: static floor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude: Option<f64>,
    /// Dimensionless peak acceleration Γ = Aω²/g, an alternative to `amplitude` (needs gravity).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gamma: Option<f64>,
    /// Vibration frequency in cycles per unit time (ω = 2π·frequency).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequency: Option<f64>,
    /// Initial phase φ0 in radians.
    #[serde(default)]
    pub phase: f64,
    /// Shape of the vibration.
    #[serde(default)]
    pub waveform: Waveform,
    /// How impacts are found: `exact` (the moving floor) or `fixed-position` (the floor stays at
    /// y = 0 for finding impacts, which use the moving floor's velocity).
    #[serde(default)]
    pub model: FloorModel,
    /// Coulomb friction μ of disk–floor impacts (rough disks). Absent: a smooth floor, unless
    /// `tangential_restitution` is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// Tangential restitution β ∈ [−1, 1] of disk–floor impacts (rough disks).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangential_restitution: Option<f64>,
    /// A gap in a static floor from x = `from` to x = `to`: disks fall through it and leave.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orifice: Option<Orifice>,
}

impl Floor {
    /// Whether the file asks this floor to vibrate: an amplitude above 0, or a peak
    /// acceleration Γ (a static floor gives neither).
    pub fn vibrates(&self) -> bool {
        self.amplitude.is_some_and(|a| a > 0.0) || self.gamma.is_some_and(|gamma| gamma > 0.0)
    }

    /// The drive this floor asks for under gravity `gravity`: its waveform and model, with
    /// `amplitude` at `frequency` or the amplitude of peak acceleration `gamma` (which needs
    /// gravity); static without either.
    pub fn drive(&self, gravity: Option<f64>) -> Drive {
        let f = self.frequency.unwrap_or(0.0);
        let drive = match (self.amplitude, self.gamma, gravity) {
            (Some(a), _, _) => Drive::new(a, f),
            (None, Some(gamma), Some(g)) if self.frequency.is_some() => {
                Drive::of_gamma(gamma, f, g)
            }
            _ => Drive::new(0.0, f),
        };
        drive.shaped(self.waveform, self.model)
    }
}

/// A gap in the floor whose two edges are corners (points) the disks collide with; a disk that
/// falls through it wholly below the floor leaves the scene.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Orifice {
    /// Left edge x0.
    pub from: f64,
    /// Right edge x1 > x0.
    pub to: f64,
}

/// The disks: how many, their sizes and masses, where they start and how fast.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Particles {
    /// Number of disks (ignored when `radius` lists species with counts).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<usize>,
    /// Radius: a number, a uniform distribution, or a list of species.
    pub radius: Radius,
    /// Mass of every disk (default: 1 for a single size, else set by `density`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<f64>,
    /// Areal mass density: mass = density·π·radius². Alternative to `mass`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// Packing fraction of the initial placement: for a closed box without `domain.height`, sets
    /// the height; for an open top, the packing fraction of the initial bed (default 0.5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub packing_fraction: Option<f64>,
    /// Where the disks start.
    #[serde(default)]
    pub placement: Placement,
    /// Initial granular temperature (kT per degree of freedom, mass-weighted); total momentum is
    /// set to zero unless there is a single disk.
    #[serde(default = "one")]
    pub temperature: f64,
    /// `q` in the moment of inertia `I = q m a²` of rough disks (½: a uniform disk).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia_factor: Option<f64>,
    /// Initial rotational temperature `Σ I ω² / N` of rough disks (default 0: no spin).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotational_temperature: Option<f64>,
}

/// Disk radii.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum Radius {
    /// Every disk has this radius.
    Fixed(f64),
    /// Radii drawn uniformly in [min, max].
    Uniform(UniformRadius),
    /// Discrete species with counts (and optionally masses).
    Species(SpeciesList),
}

/// Radii drawn uniformly in [min, max].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct UniformRadius {
    /// Smallest radius.
    pub min: f64,
    /// Largest radius.
    pub max: f64,
}

/// A list of species.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpeciesList {
    /// The species, in order (disk numbers follow this order).
    pub species: Vec<Species>,
}

/// One species of disks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Species {
    /// How many disks of this species.
    pub count: usize,
    /// Their radius.
    pub radius: f64,
    /// Their mass (default: from `particles.density`, or `particles.mass`, or π r² relative to
    /// the smallest species having mass 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<f64>,
}

/// Initial positions (and possibly velocities).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum Placement {
    /// `random` (uniform, non-overlapping) or `lattice` (triangular lattice).
    Kind(PlacementKind),
    /// Explicit positions, optionally velocities.
    Explicit(ExplicitPlacement),
}

impl Default for Placement {
    fn default() -> Self {
        Placement::Kind(PlacementKind::Random)
    }
}

/// Generated placements.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum PlacementKind {
    /// Uniform random non-overlapping positions: the rows of the lattice placement, melted by
    /// hard-disk Monte Carlo sweeps.
    Random,
    /// A perfect triangular lattice.
    Lattice,
}

/// Explicit initial state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExplicitPlacement {
    /// One `[x, y]` per disk.
    pub positions: Vec<[f64; 2]>,
    /// One `[vx, vy]` per disk; absent: drawn from `particles.temperature`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocities: Option<Vec<[f64; 2]>>,
}

/// The pair collision law, with the optional cures of inelastic collapse.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Collisions {
    /// Normal restitution e (1 = elastic).
    #[serde(default = "one")]
    pub restitution: f64,
    /// TC model (Luding & McNamara 1998): a collision is elastic when either disk's previous
    /// collision was less than `tc` ago. Absent: off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tc: Option<f64>,
    /// A collision is elastic when the normal approach speed is below this. Absent: off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_cutoff: Option<f64>,
    /// A disk landing gently (rebound below 10⁻⁶ radii) in a stable place on disks at rest comes
    /// to rest too and moves with the floor: a bed at rest costs no events. Off: it keeps
    /// bouncing with that smallest rebound. Only matters with a floor and gravity.
    #[serde(default = "yes", skip_serializing_if = "is_yes")]
    pub resting_contacts: bool,
    /// Coulomb friction μ of pair collisions (rough disks): the tangential impulse is at most μ
    /// times the normal one. Absent: no cap (with `tangential_restitution`) or smooth disks.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// Tangential restitution β ∈ [−1, 1] of sticking pair contacts (rough disks; −1 is
    /// smooth). Absent with `friction` given: 0, contacts that stick stop slipping.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangential_restitution: Option<f64>,
}

impl Collisions {
    /// The restitution law the file's `restitution`, `tc` and `speed_cutoff` give: the one value
    /// the engine and every scheme take, and that the checks ask.
    pub fn law(&self) -> Restitution {
        Restitution {
            e: self.restitution,
            tc: self.tc,
            speed_cutoff: self.speed_cutoff,
        }
    }
}

fn yes() -> bool {
    true
}

fn is_yes(b: &bool) -> bool {
    *b
}

impl Default for Collisions {
    fn default() -> Self {
        Collisions {
            restitution: 1.0,
            tc: None,
            speed_cutoff: None,
            resting_contacts: true,
            friction: None,
            tangential_restitution: None,
        }
    }
}

/// How long to run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Run {
    /// Simulated time to run (after which the run stops).
    pub duration: f64,
    /// Simulated time before measurements start being averaged.
    #[serde(default)]
    pub warmup: f64,
    /// Stop after this many events (a safety net; absent: no limit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_events: Option<u64>,
    /// Stop after this many wall-clock seconds of running (absent: no limit); the run ends
    /// `wall-limit` with its summary, checkpoint and recording kept. A resumed run's part
    /// counts from its resume.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_wall_seconds: Option<f64>,
}

/// What to measure and write.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Output {
    /// Simulated time between recorded frames (default: duration/200).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame_interval: Option<f64>,
    /// Simulated time between measurement samples (default: frame interval).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_interval: Option<f64>,
    /// Number of height bins of the profiles (gravity scenes).
    #[serde(default = "default_bins")]
    pub profile_bins: usize,
    /// Height of the top of the profiles (default: chosen from the initial bed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile_height: Option<f64>,
    /// Bins per period of the phase-resolved motion (a vibrating floor under gravity).
    #[serde(default = "default_phase_bins")]
    pub phase_bins: usize,
    /// Cells `[nx, ny]` of the 2D fields (`run --fields`) across x and up the height (default:
    /// square-ish cells about two mean disk diameters wide, at most 200 a side).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field_bins: Option<[usize; 2]>,
    /// Height of the top of the 2D fields' grid (default: the profiles' top).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field_height: Option<f64>,
    /// Give the distributions of the scaled velocities c = (v − u)/√T and their kurtosis in the
    /// summary (`velocity_distribution`; off by default: it costs a few per cent of a run with
    /// dense samples).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub velocity_distribution: bool,
    /// Draw the live 2D fields in the recording beside the disks: packing fraction as a heat map,
    /// mean velocity as arrows, a running average over one floor period (gravity scenes).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub record_fields: bool,
    /// Record frames to this Rerun file (.rrd). Absent: nothing recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rrd: Option<String>,
    /// Colour disks in the recording by `speed`, `species` or `spin` (rough disks).
    #[serde(default)]
    pub color_by: ColorChoice,
    /// Speed drawn full red when the recording colours disks by speed (default: three times the
    /// floor's peak speed, else three times the initial root-mean-square speed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_scale: Option<f64>,
    /// Rim speed ω a drawn full colour when the recording colours rough disks by spin
    /// (default: a third of the speed scale, the floor's peak speed Aω when that is the default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spin_scale: Option<f64>,
    /// Write a trajectory (extended XYZ) to this file. Absent: no trajectory.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trajectory: Option<String>,
    /// Simulated time between trajectory frames (default: the frame interval).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trajectory_interval: Option<f64>,
}

impl Default for Output {
    fn default() -> Self {
        Output {
            frame_interval: None,
            sample_interval: None,
            profile_bins: default_bins(),
            profile_height: None,
            phase_bins: default_phase_bins(),
            field_bins: None,
            field_height: None,
            record_fields: false,
            velocity_distribution: false,
            rrd: None,
            color_by: ColorChoice::Speed,
            speed_scale: None,
            spin_scale: None,
            trajectory: None,
            trajectory_interval: None,
        }
    }
}

/// Colouring of disks in recordings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum ColorChoice {
    /// By speed.
    #[default]
    Speed,
    /// By species.
    Species,
    /// By spin (rough disks): the rim speed ω a on a diverging scale.
    Spin,
}

/// Integration scheme and its knobs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Engine {
    /// `auto` (the default: `hybrid` for an inelastic bed on a vibrating floor, or on a static
    /// one with no cure of inelastic collapse, else `event-driven`), `event-driven` (exact),
    /// `time-step` or `space-time` (approximate, for comparison), `contact` (contact dynamics,
    /// for dense beds) or `hybrid` (the exact engine while the bed is a gas, contact dynamics
    /// while it is dense).
    #[serde(default)]
    pub scheme: Scheme,
    /// Neighbour mask: `auto`, `min`, `r3` … `r10`.
    #[serde(default)]
    pub mask: MaskChoice,
    /// Neighbour-list skin: the DUTC margin `r_NL − 2 a_max`, in units of the smallest radius
    /// (absent: the most the mask allows). Lists keep pairs closer than contact + skin. With the
    /// local re-mapping, twice the shell radius (absent: sized for six to eight neighbours beyond
    /// contact by the scene's packing and size, see `engine::remap::shells::local_margin`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skin: Option<f64>,
    /// Grid storage: `auto` (dense for closed domains, hashed for an open top), `dense`, or
    /// `hashed` (Isobe's compressed array, also for closed domains).
    #[serde(default)]
    pub grid: GridChoice,
    /// When neighbour lists are rebuilt: `local` (each disk's own list when it leaves its
    /// shell), `global` (Isobe 1999 as published: every list at the DUTC deadline), or `auto`
    /// (the default: local, but global under an open top with gravity).
    #[serde(default)]
    pub remap: RemapChoice,
    /// Event queue of the event-driven engine: `calendar` (Paul's calendar of linked lists with
    /// a small heap; faster) or `tree` (Isobe's complete binary tree; a little less memory).
    /// Both pop the same events in the same order; only speed and memory differ.
    #[serde(default)]
    pub queue: QueueChoice,
    /// Disk numbering inside the engine: `auto` (from 8192 disks, renumbered along a Z-order
    /// curve of the grid at re-mappings, so that neighbours lie close in memory), `on` (at any
    /// size) or `off`. Outputs keep the scenario's numbering either way.
    #[serde(default)]
    pub renumber: RenumberChoice,
    /// Switch on the invariant checks (no overlap, no event in the past, energy balance).
    #[serde(default)]
    pub check_invariants: bool,
    // --- Knobs of the approximate schemes (src/schemes); each belongs to one scheme. ---
    /// `time-step`: the fixed global step (absent: 0.1 × smallest radius / largest speed at the
    /// start, the speed being at least √(g·radius) and the floor's peak speed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dt: Option<f64>,
    /// `time-step`: Verlet-list skin in units of the smallest radius (absent: 1). Lists keep
    /// pairs closer than 2 a_max + skin and are rebuilt when a disk has moved half the skin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verlet_skin: Option<f64>,
    /// `space-time`: the synchronisation distance D in units of the smallest radius (absent: 6,
    /// three diameters); the synchronisation step is D / (largest speed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sync_distance: Option<f64>,
    /// `time-step` and `space-time`: side of the linked cells in units of the smallest radius
    /// (absent: the Verlet radius for `time-step`; 2 a_max + 3 a_min for `space-time`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cell_size: Option<f64>,
    /// `space-time`: vertical strips of cells whose event loops run apart within a
    /// synchronisation step, on the threads (absent: 1, the whole scene one loop). Pairs across
    /// a strip's border are left to the next synchronisation. Results do not depend on the
    /// threads.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub strips: Option<u64>,
    /// `time-step` and `space-time`: threads their loops run on (absent: every core this
    /// process may use). Results are the same bit for bit whatever the count.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threads: Option<u64>,
}

impl Default for Engine {
    fn default() -> Self {
        Engine {
            scheme: Scheme::Auto,
            mask: MaskChoice::Auto,
            skin: None,
            grid: GridChoice::Auto,
            remap: RemapChoice::default(),
            queue: QueueChoice::Calendar,
            renumber: RenumberChoice::Auto,
            check_invariants: false,
            dt: None,
            verlet_skin: None,
            sync_distance: None,
            cell_size: None,
            strips: None,
            threads: None,
        }
    }
}

/// Integration scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Scheme {
    /// The hybrid scheme for an inelastic bed (smooth or rough) on a vibrating floor whose disks
    /// neither enter nor leave (see [`Scenario::scheme`]); the exact engine for every other scene.
    #[default]
    Auto,
    /// Exact event-driven dynamics (Isobe 1999).
    EventDriven,
    /// Fixed global time step, overlaps found with cell and Verlet lists, resolved when found.
    TimeStep,
    /// Per-disk times moved straight to their next predicted collision, candidates from linked
    /// cells, with a global synchronisation step D/v (ReMoDy's space-time scheme).
    SpaceTime,
    /// Contact dynamics (Moreau–Jean): a global step dt, every contact of a step resolved
    /// together as one simultaneous impact (projected Gauss–Seidel), for dense beds.
    Contact,
    /// The exact engine while the bed is a gas, contact dynamics while it is dense, the run
    /// handed from one to the other as it turns.
    Hybrid,
}

/// How the grid is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum GridChoice {
    /// Dense for closed domains, hashed for an open top.
    #[default]
    Auto,
    /// One slot per cell (closed domains only).
    Dense,
    /// Isobe's compressed virtual array with bucketed hashing.
    Hashed,
}

/// When neighbour lists are rebuilt.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum RemapChoice {
    /// `local`, except under an open top with gravity (`global` there): a disk thrown far
    /// above such a bed would leave its shell at every few tenths of a diameter of its fall,
    /// where the global re-mapping gives it a DUTC deadline of its own.
    #[default]
    Auto,
    /// Isobe 1999 as published: the grid is re-mapped and every list rebuilt at the DUTC
    /// deadline, set by the fastest disk.
    Global,
    /// Each disk keeps a shell around the place its list was built at and rebuilds its own list
    /// when it leaves it (a per-disk displacement budget; anchors in linked cells): faster than
    /// the global re-mapping on every benchmark (the book's Performance page).
    Local,
}

impl RemapChoice {
    /// `global` or `local`: what `auto` means for a scene with (`open_fall`) or without an open
    /// top and gravity.
    pub fn resolve(self, open_fall: bool) -> RemapChoice {
        match self {
            RemapChoice::Auto if open_fall => RemapChoice::Global,
            RemapChoice::Auto => RemapChoice::Local,
            chosen => chosen,
        }
    }
}

/// Whether the event-driven engine renumbers its disks along a space-filling curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum RenumberChoice {
    /// From [`RENUMBER_FROM`] disks on: below, the engine's arrays fit in the caches anyway.
    #[default]
    Auto,
    /// At any size.
    On,
    /// Never: disks keep the scenario's numbering inside the engine too.
    Off,
}

/// Smallest number of disks that `renumber = "auto"` renumbers.
pub const RENUMBER_FROM: usize = 8192;

/// The event-driven engine's event queue.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum QueueChoice {
    /// Calendar of linked lists plus a small heap for the current bucket (Paul 2007): O(1)
    /// per event on average.
    #[default]
    Calendar,
    /// Complete binary tree over the disks (Isobe 1999): O(log N) per event, 8 bytes per disk.
    Tree,
}

/// Which Isobe mask to search for neighbours.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum MaskChoice {
    /// The smallest mask that reaches comfortably beyond contact.
    #[default]
    Auto,
    /// 5×5 square less its centre (24 cells).
    Min,
    /// Circle of radius 3 cells (36 cells).
    R3,
    /// 68 cells.
    R4,
    /// 96 cells.
    R5,
    /// 136 cells.
    R6,
    /// 176 cells.
    R7,
    /// 224 cells.
    R8,
    /// 292 cells.
    R9,
    /// 348 cells.
    R10,
}

/// The mass a disk of radius `a` is given: its species' own, else `density`·π a², else `mass`
/// (`None`: none of them is given).
fn disk_mass(
    a: f64,
    species_mass: Option<f64>,
    mass: Option<f64>,
    density: Option<f64>,
) -> Option<f64> {
    species_mass
        .or_else(|| density.map(|rho| rho * std::f64::consts::PI * a * a))
        .or(mass)
}

impl Radius {
    /// The smallest and largest radius of the law.
    pub fn range(&self) -> (f64, f64) {
        match self {
            Radius::Fixed(r) => (*r, *r),
            Radius::Uniform(u) => (u.min, u.max),
            Radius::Species(list) => list.species.iter().fold((f64::INFINITY, 0.0), |acc, s| {
                (acc.0.min(s.radius), acc.1.max(s.radius))
            }),
        }
    }
}

fn one() -> f64 {
    1.0
}

fn default_bins() -> usize {
    40
}

fn default_phase_bins() -> usize {
    20
}

/// Frames (and samples, and trajectory frames) a run takes when no interval is given: one every
/// `run.duration / DEFAULT_FRAMES`.
const DEFAULT_FRAMES: f64 = 200.0;

impl Scenario {
    /// The interval between frames: `output.frame_interval`, else a 200th of the duration.
    pub fn frame_interval(&self) -> f64 {
        self.output
            .frame_interval
            .unwrap_or(self.run.duration / DEFAULT_FRAMES)
    }

    /// The interval between samples: `output.sample_interval`, else the frame interval.
    pub fn sample_interval(&self) -> f64 {
        self.output
            .sample_interval
            .unwrap_or_else(|| self.frame_interval())
    }

    /// The interval between trajectory frames: `output.trajectory_interval`, else the frame
    /// interval.
    pub fn trajectory_interval(&self) -> f64 {
        self.output
            .trajectory_interval
            .unwrap_or_else(|| self.frame_interval())
    }

    /// Parses scenario JSON text, applying `--set` overrides (`KEY=VALUE`) first, then validates.
    pub fn from_json_with_overrides(text: &str, sets: &[String]) -> Result<Scenario> {
        let mut value = json::parse(text)?;
        for set in sets {
            overrides::apply(&mut value, set)?;
        }
        json::lists_only_where_lists_belong(&value)?;
        let scenario = Scenario::from_value(value)?;
        scenario
            .validate()
            .map_err(|e| checks::blame_what_was_set(e, &scenario, sets))?;
        Ok(scenario)
    }

    /// Parses and validates scenario JSON text.
    pub fn from_json(text: &str) -> Result<Scenario> {
        Scenario::from_json_with_overrides(text, &[])
    }

    /// Reads, overrides and validates a scenario file.
    pub fn load(path: &std::path::Path, sets: &[String]) -> Result<Scenario> {
        Scenario::from_json_with_overrides(&Scenario::read_text(path)?, sets)
    }

    /// The text of a scenario file; one that cannot be read is bad input (`SCENARIO`).
    pub fn read_text(path: &std::path::Path) -> Result<String> {
        std::fs::read_to_string(path)
            .map_err(|e| Error::input("SCENARIO", format!("cannot read {}: {e}", path.display())))
    }

    /// Typed view of a JSON value; errors name the dotted path of the offending field.
    pub fn from_value(value: serde_json::Value) -> Result<Scenario> {
        serde_path_to_error::deserialize(value).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner().to_string();
            let hint = if path.ends_with("radius") && inner.contains("untagged") {
                " (expected a number, {\"min\": .., \"max\": ..}, or {\"species\": [{\"count\": .., \"radius\": ..}]})"
            } else if path.ends_with("placement") && inner.contains("untagged") {
                " (expected \"random\", \"lattice\" or {\"positions\": [[x, y], ..]})"
            } else {
                ""
            };
            let field = if path == "." { String::new() } else { excerpt(&path) };
            Error::input(field, format!("{}{hint}", quotes_cut(&inner)))
        })
    }

    /// Checks that the scene makes physical sense; errors name the field.
    pub fn validate(&self) -> Result<()> {
        crate::scenario::checks::validate(self)
    }

    /// Whether the disks are rough (carry spins): any of the rough disks' fields is named.
    pub fn is_rough(&self) -> bool {
        let c = &self.collisions;
        let d = &self.domain;
        let p = &self.particles;
        c.friction.is_some()
            || c.tangential_restitution.is_some()
            || d.wall_friction.is_some()
            || d.wall_tangential_restitution.is_some()
            || p.inertia_factor.is_some()
            || p.rotational_temperature.is_some()
            || self
                .floor
                .as_ref()
                .is_some_and(|f| f.friction.is_some() || f.tangential_restitution.is_some())
    }

    /// The scheme the run uses: `engine.scheme`, with `auto` chosen from the scene. An inelastic
    /// bed on a vibrating floor, smooth or rough, may turn dense (bouncing, riding, at rest below
    /// Γ = 1), where the exact engine alone meets inelastic collapse at a cost without bound: so
    /// does one settling on a static floor with no cure of the collapse set (with TC or the
    /// speed cutoff it settles on the exact engine's rest rules). `auto` runs such a bed on the
    /// hybrid scheme, unless disks enter or leave or the floor is a cheaper model, which only the
    /// exact engine has. Every other scene runs on the exact engine.
    pub fn scheme(&self) -> Scheme {
        let law = self.collisions.law();
        let settles = self.floor.as_ref().is_some_and(|f| {
            f.orifice.is_none()
                && f.model == FloorModel::Exact
                && (!f.drive(self.gravity).is_static() || !law.cured())
        });
        let dense_bed = settles
            && self.gravity.is_some()
            && law.inelastic()
            && self.inlets.is_empty()
            && self.domain.exit_height.is_none();
        match self.engine.scheme {
            Scheme::Auto if dense_bed => Scheme::Hybrid,
            Scheme::Auto => Scheme::EventDriven,
            chosen => chosen,
        }
    }

    /// Number of disks the scene holds.
    pub fn disk_count(&self) -> usize {
        match &self.particles.radius {
            // Saturating: a sum past the largest count is refused by validation, never wrapped.
            Radius::Species(list) => list
                .species
                .iter()
                .fold(0usize, |n, s| n.saturating_add(s.count)),
            _ => self.particles.count.unwrap_or(0),
        }
    }

    /// The smallest and largest radius of the disks at the start.
    pub fn radius_range(&self) -> (f64, f64) {
        self.particles.radius.range()
    }

    /// The radius law of the disks `inlet` brings: its own, else the particles'.
    pub fn inlet_radius<'a>(&'a self, inlet: &'a Inlet) -> &'a Radius {
        inlet.radius.as_ref().unwrap_or(&self.particles.radius)
    }

    /// The smallest and largest radius of the disks `inlet` brings.
    pub fn inlet_radius_range(&self, inlet: &Inlet) -> (f64, f64) {
        self.inlet_radius(inlet).range()
    }

    /// The smallest and largest radius of every disk the scene may hold: at the start and
    /// through its inlets (what the grid, the masks and the orifice must allow for).
    pub fn all_radius_range(&self) -> (f64, f64) {
        self.inlets
            .iter()
            .map(|i| self.inlet_radius_range(i))
            .fold(self.radius_range(), |(lo, hi), (a, b)| {
                (lo.min(a), hi.max(b))
            })
    }

    /// The mass of a disk of radius `a` at the start: its species' mass if given, else by
    /// `particles.density`, else `particles.mass`, else of equal areal density, the smallest
    /// disk weighing 1.
    pub fn particle_mass(&self, a: f64, species_mass: Option<f64>) -> f64 {
        let p = &self.particles;
        let a_min = self.radius_range().0;
        disk_mass(a, species_mass, p.mass, p.density).unwrap_or_else(|| (a / a_min).powi(2))
    }

    /// The mass of a disk of radius `a` that `inlet` brings: its species' mass if given, else
    /// by the inlet's `density` or `mass`, else as a disk of that radius at the start.
    pub fn inlet_mass(&self, inlet: &Inlet, a: f64, species_mass: Option<f64>) -> f64 {
        disk_mass(a, species_mass, inlet.mass, inlet.density)
            .unwrap_or_else(|| self.particle_mass(a, None))
    }

    /// Notes on what this (valid) scenario asks for that is likely unintended; see
    /// [`checks::advisories`].
    pub fn advisories(&self) -> Vec<String> {
        checks::advisories(self)
    }

    /// The floor's drive, its amplitude given or from Γ (`None` without a floor).
    pub fn floor_drive(&self) -> Option<Drive> {
        self.floor.as_ref().map(|f| f.drive(self.gravity))
    }

    /// Vibration amplitude of the floor (0 for a static floor or no floor).
    pub fn floor_amplitude(&self) -> f64 {
        self.floor_drive().map_or(0.0, |d| d.amplitude)
    }
}

pub mod checks;

#[cfg(test)]
mod tests {
    use super::Floor;

    /// A floor vibrates with an amplitude above 0 or a Γ; without either, or at amplitude 0, it
    /// is static, whatever its frequency.
    #[test]
    fn a_floor_vibrates_only_with_an_amplitude_or_a_gamma() {
        let floor = |json: &str| serde_json::from_str::<Floor>(json).expect("a floor");
        assert!(!floor(r#"{}"#).vibrates());
        assert!(!floor(r#"{"amplitude": 0, "frequency": 1}"#).vibrates());
        assert!(!floor(r#"{"frequency": 1}"#).vibrates());
        assert!(floor(r#"{"amplitude": 0.1, "frequency": 1}"#).vibrates());
        assert!(floor(r#"{"gamma": 2, "frequency": 1}"#).vibrates());
    }
}
