//! The guard that time advances: a run whose clock has not moved over [`STALL_EVENTS`] events
//! (re-mappings included) has stopped — a rule firing again and again at one instant, which
//! is a bug, or re-mappings following each other for a disk too fast for the clock — and ends
//! with a report naming the disks and the rules involved, instead of running on for ever.

use super::{EventCounts, JamCounts, Simulation};
use crate::error::Result;
use crate::physics::flight::Flight;

/// Events over which the clock must advance by more than [`STALL_SPAN`].
pub const STALL_EVENTS: u64 = 10_000_000;

/// The least advance of the clock over [`STALL_EVENTS`] events, in time units (relative to
/// the clock from 1 on): 10¹⁶ events per unit time is beyond any scene, while a clock that
/// moves by round-off, or not at all, is stuck.
pub const STALL_SPAN: f64 = 1e-9;

/// Events watched, once the clock has stalled, to tell who is involved.
const WATCHED: u64 = 100_000;

/// Disks named in the report.
const NAMED: usize = 6;

/// The clock and the event count when the clock was last seen to move.
#[derive(Debug, Clone, Copy, Default)]
pub struct ClockMark {
    time: f64,
    events: u64,
}

impl<F: Flight> Simulation<F> {
    /// Whether the clock still advances: `Ok(None)` if so, else the report of the stall.
    pub(super) fn stalled(&mut self) -> Result<Option<String>> {
        let time = self.time();
        let events = self.tally.counts.guarded();
        let mark = self.control.clock_mark;
        if time - mark.time > STALL_SPAN * time.abs().max(1.0) {
            self.control.clock_mark = ClockMark { time, events };
            return Ok(None);
        }
        if events.wrapping_sub(mark.events) < STALL_EVENTS {
            return Ok(None);
        }
        let head = format!(
            "simulated time has stopped advancing: {} events at t = {time} (the clock moved by {:e})",
            events.wrapping_sub(mark.events),
            time - mark.time
        );
        Ok(Some(format!("{head}; {}", self.watch_stall()?)))
    }

    /// Runs [`WATCHED`] more events and tells which disks had them and which rules engaged.
    fn watch_stall(&mut self) -> Result<String> {
        let jams = self.tally.jams;
        let counts = self.tally.counts;
        let mut per_disk = vec![0u64; self.disks.len()];
        for _ in 0..WATCHED {
            let i = self.events.queue.min();
            per_disk[i] += 1;
            self.step_events(1)?;
        }
        let mut busiest: Vec<(usize, u64)> = per_disk
            .into_iter()
            .enumerate()
            .filter(|&(_, k)| k > 0)
            .collect();
        busiest.sort_by_key(|&(i, k)| (std::cmp::Reverse(k), self.map.numbering.id(i)));
        let disks: Vec<String> = busiest
            .iter()
            .take(NAMED)
            .map(|&(i, k)| self.describe_disk(i, k))
            .collect();
        Ok(format!(
            "of the next {WATCHED} events, disks {}; rules engaged: {}; events: {}",
            disks.join(", "),
            self.tally.jams.engaged_since(&jams),
            self.tally.counts.kinds_since(&counts)
        ))
    }

    /// Disk `i` by the scenario's number, with its `k` events: where it is, and whether it is
    /// at rest.
    fn describe_disk(&self, i: usize, k: u64) -> String {
        let id = self.map.numbering.id(i);
        let (x, y, _, _) = self.state_at(i, self.now);
        let state = if self.is_riding(i) {
            "at rest"
        } else {
            "flying"
        };
        format!("{id} ({k} events, {state} at x = {x:.6}, y = {y:.6})")
    }
}

impl JamCounts {
    /// The rules that engaged since `before`, with how often: "none" if none did.
    pub fn engaged_since(&self, before: &JamCounts) -> String {
        let rules = [
            ("slot", self.slot - before.slot),
            ("zeno stop", self.zeno - before.zeno),
            ("pocket", self.pocket - before.pocket),
            ("jammed row", self.jammed_row - before.jammed_row),
            ("gentle push", self.gentle_push - before.gentle_push),
            ("jammed cluster", self.cluster - before.cluster),
            ("floor room", self.floor_room - before.floor_room),
            ("seated row", self.seated_row - before.seated_row),
            ("floor row", self.floor_row - before.floor_row),
            (
                "pressed slider",
                self.pressed_slider - before.pressed_slider,
            ),
        ];
        list(&rules)
    }
}

impl EventCounts {
    /// The kinds of event since `before`, with how many: "none" if none.
    pub fn kinds_since(&self, before: &EventCounts) -> String {
        let kinds = [
            ("pair", self.pair - before.pair),
            ("wall", self.wall - before.wall),
            ("lid", self.lid - before.lid),
            ("floor", self.floor - before.floor),
            ("rest", self.rest - before.rest),
            ("stale", self.stale - before.stale),
            ("re-check", self.recheck - before.recheck),
            ("unmount", self.unmount - before.unmount),
            ("zeno", self.zeno - before.zeno),
            ("re-mapping", self.rebuild - before.rebuild),
        ];
        list(&kinds)
    }
}

/// "name ×count" for the non-zero counts, or "none".
fn list(counts: &[(&str, u64)]) -> String {
    let named: Vec<String> = counts
        .iter()
        .filter(|(_, k)| *k > 0)
        .map(|(name, k)| format!("{name} ×{k}"))
        .collect();
    if named.is_empty() {
        "none".to_string()
    } else {
        named.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::Scene;
    use crate::physics::flight::Ballistic;
    use crate::scenario::Scenario;

    /// A bouncing bed, run to t = 1: the clock moves, so the guard says nothing; told that
    /// the clock last moved [`STALL_EVENTS`] events ago, it reports the stall and names the
    /// disks and the events it watched.
    #[test]
    fn a_clock_that_does_not_move_is_reported_with_the_disks_involved() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/hard/bouncing_bed_gamma_1.5.json");
        let scenario = Scenario::load(&path, &[]).expect("the hard case is valid");
        let (scene, disks) = Scene::build(&scenario).expect("scene builds");
        let g = scene.gravity.expect("gravity");
        let mut sim = Simulation::new(Ballistic { g }, &scene, disks).expect("engine starts");
        sim.advance_to(1.0).expect("runs");
        assert_eq!(sim.stalled().expect("no failure"), None);
        let (time, events) = (sim.time(), sim.tally.counts.guarded());
        sim.control.clock_mark = ClockMark {
            time,
            events: events.wrapping_sub(STALL_EVENTS),
        };
        let report = sim.stalled().expect("no failure").expect("a stall");
        assert!(
            report.starts_with("simulated time has stopped advancing"),
            "{report}"
        );
        assert!(
            report.contains("of the next 100000 events, disks "),
            "{report}"
        );
        assert!(report.contains("events: pair ×"), "{report}");
        eprintln!("{report}");
    }
}
