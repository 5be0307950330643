//! The parts of the engine's state, each named for what it holds.

use super::event::code;
use super::images::Images;
use super::log::Collision;
use super::remap::dutc::Dutc;
use super::remap::numbering::Numbering;
use super::remap::shells::Shells;
use super::rest::riders::Riders;
use super::stall::ClockMark;
use super::Scene;
use super::{EnergyFlow, EventCounts, JamCounts};
use crate::neighbours::{Cells, GridGeometry, Mask, NeighbourLists};
use crate::physics::floor::Floor;
use crate::physics::walls::{SideBounds, Top};
use crate::platform::cpu::Lanes;
use crate::scenario::QueueChoice;
use crate::scheduler::{CalendarQueue, CompleteBinaryTree, EventQueue};
use std::sync::atomic::AtomicBool;

/// Each disk's next event (see [`event`](super::event)), and the queue that orders them.
#[derive(Debug)]
pub(super) struct Events {
    /// Absolute event times on the local clock, one per disk (and one more, infinite, that the
    /// tree uses as a sentinel).
    pub time: Vec<f64>,
    /// What each event is, as its [`code`](super::event::code).
    pub code: Vec<u32>,
    /// A pair event's partner's collision counter when it was filed (the event is stale if the
    /// partner has moved since); 1 for a ride end that is a kick.
    pub counter: Vec<u32>,
    pub queue: EventQueue,
}

impl Events {
    /// No events yet for `n` disks, in the queue the scene asks for (a calendar keeping events
    /// ahead for the event loop's pipeline of hints if `pipelining`).
    pub fn new(n: usize, queue: QueueChoice, pipelining: bool) -> Events {
        Events {
            time: vec![f64::INFINITY; n + 1],
            code: vec![code::NONE; n],
            counter: vec![0; n],
            queue: match queue {
                QueueChoice::Tree => EventQueue::Tree(CompleteBinaryTree::default()),
                QueueChoice::Calendar => {
                    EventQueue::Calendar(CalendarQueue::keeping_ahead(pipelining))
                }
            },
        }
    }
}

/// Who can meet whom: Isobe's grid and masks, the neighbour lists taken from them at a mapping,
/// and when they must be taken again.
#[derive(Debug)]
pub(super) struct Mapping {
    pub geometry: GridGeometry,
    pub mask: Mask,
    pub cells: Cells,
    pub lists: NeighbourLists,
    /// How far beyond contact a pair is listed.
    pub margin: f64,
    /// The Dynamical Upper Time Cut-off: when the lists may miss a pair (global re-mapping).
    pub dutc: Dutc,
    /// The local re-mapping's anchors (`engine.remap = "local"`); `None` for Isobe's global one.
    pub shells: Option<Shells>,
    /// The engine's numbering of the disks against the scenario's (`engine.renumber`).
    pub numbering: Numbering,
}

/// What bounds the disks: side walls or periodic images, the lid or an open top, the floor.
#[derive(Debug)]
pub(super) struct Bounds {
    pub sides: SideBounds,
    pub top: Top,
    /// The periodic images of `sides` and `top`, for minimum-image separations.
    pub images: Images,
    pub floor: Option<Floor>,
    /// The floor's orifice, if any (a static floor).
    pub orifice: Option<crate::physics::orifice::Orifice>,
    /// Under an open top, the height at which a rising disk's centre leaves, if any.
    pub exit_height: Option<f64>,
    /// An orifice or an exit height: flying disks may leave (one test in the prediction of
    /// scenes without either).
    pub outlets: bool,
}

/// Disks at rest: on (riding) the floor or on resting disks, and the memory of the rules that
/// end bursts of events at one instant (see [`rest`](super::rest)).
#[derive(Debug)]
pub(super) struct Rest {
    /// Disks at rest on the floor or on resting disks; empty without a floor.
    pub riders: Riders,
    /// Disks resting on disks that rest move with the floor (`collisions.resting_contacts`).
    pub resting_contacts: bool,
    /// Per disk: the first event of its latest burst at one instant and how many it has had
    /// since (scenes with a floor and resting contacts; see `stop_zeno`).
    pub same_instant: Vec<(f64, u32)>,
    /// Events of disk i within `√(zeno_instant2 · a_i)` of the first of a burst count as at one
    /// instant for `same_instant`: the square of `jams::INSTANT` time units per unit radius.
    pub zeno_instant2: f64,
    /// Scratch of the release cascade: the stack, and the disks one support carried.
    pub releasing: Vec<u32>,
    pub carried: Vec<u32>,
    /// Scratch of the settling of clusters: the candidates, and who is one.
    pub cluster: Vec<u32>,
    pub in_cluster: Vec<bool>,
}

impl Rest {
    /// No disk at rest yet (the riders are sized when the scene has a floor).
    pub fn new(resting_contacts: bool) -> Rest {
        Rest {
            riders: Riders::default(),
            resting_contacts,
            same_instant: Vec::new(),
            zeno_instant2: 0.0,
            releasing: Vec::new(),
            carried: Vec::new(),
            cluster: Vec::new(),
            in_cluster: Vec::new(),
        }
    }
}

/// What is counted and summed as the run goes: events by kind, the energy's flow, the virial,
/// the largest overlap seen, the jam rules that engaged.
#[derive(Debug, Default)]
pub(super) struct Tally {
    pub counts: EventCounts,
    pub flow: EnergyFlow,
    pub virial: f64,
    pub max_overlap: f64,
    pub jams: JamCounts,
}

/// What the caller asked of the run: invariant checks, an event limit, an interrupt flag, a
/// collision log; and the memory hints the engine gives at its size.
#[derive(Debug)]
pub(super) struct Control {
    pub check: bool,
    pub event_limit: u64,
    pub interrupt: Option<&'static AtomicBool>,
    pub log: Option<Vec<Collision>>,
    /// The event loop prefetches what it will read (from
    /// [`PREFETCH_FROM`](crate::platform::prefetch::PREFETCH_FROM) disks on).
    pub prefetching: bool,
    /// The prefetching runs as a pipeline over the next three events, the calendar keeping
    /// them ahead (under the local re-mapping from
    /// [`PIPELINE_FROM`](crate::platform::prefetch::PIPELINE_FROM) disks on; the calendar
    /// alone under the global one from
    /// [`KEEP_AHEAD_FROM`](crate::platform::prefetch::KEEP_AHEAD_FROM)).
    pub pipelining: bool,
    /// The vector path of the hot loops (the scene's).
    pub lanes: Lanes,
    /// Where the clock stood when last seen to move (see [`stall`](super::stall)), and the
    /// report once it has stalled.
    pub clock_mark: ClockMark,
    pub stall_report: Option<String>,
    /// Local time of the next disk entering through an inlet (∞: none).
    pub entry: f64,
    /// The run's time and collisions at this engine's start, added to what it publishes (not
    /// zero where the engine is a part of the hybrid scheme).
    pub published_origin: (f64, u64),
}

impl Control {
    /// What `scene` asks for, with the memory hints for `n` disks; no interrupt, no log.
    pub fn new(scene: &Scene, n: usize, pipelining: bool) -> Control {
        Control {
            check: scene.check_invariants,
            event_limit: scene.max_events.unwrap_or(u64::MAX),
            interrupt: None,
            log: None,
            prefetching: n >= crate::platform::prefetch::PREFETCH_FROM,
            pipelining,
            lanes: scene.lanes,
            clock_mark: ClockMark::default(),
            stall_report: None,
            entry: f64::INFINITY,
            published_origin: (0.0, 0),
        }
    }
}
