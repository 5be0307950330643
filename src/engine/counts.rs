//! What the engine counts: events by kind, and the energy exchanged and lost.

use serde::{Deserialize, Serialize};

/// Counts of events by kind.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EventCounts {
    /// Disk–disk collisions.
    pub pair: u64,
    /// Disk–side-wall collisions.
    pub wall: u64,
    /// Disk–lid collisions.
    pub lid: u64,
    /// Disk–floor impacts.
    pub floor: u64,
    /// Contact searches (floor or riding disk) that needed a second look (no velocity change).
    pub recheck: u64,
    /// Disks that came to rest: on the floor (riding it), or on disks at rest.
    pub rest: u64,
    /// Riding disks thrown off by the floor.
    pub takeoff: u64,
    /// Predicted pair events found stale (the partner moved on); the disk was re-predicted.
    pub stale: u64,
    /// Disks resting on disks that slid off a support (the supports moved apart).
    pub unmount: u64,
    /// Grid re-mappings (DUTC).
    pub rebuild: u64,
    /// Disks that left their shell and rebuilt their own list (local re-mapping).
    #[serde(default)]
    pub shell: u64,
    /// Flying disks stopped after more than `ZENO` events at one instant (caught in a closed
    /// wedge); the event that would have been one more is dropped.
    #[serde(default)]
    pub zeno: u64,
    /// Disks that stopped sliding on a rough floor and roll on.
    #[serde(default)]
    pub slide_end: u64,
}

impl std::ops::AddAssign for EventCounts {
    /// Adds another tally's counts, kind by kind (the strips of the space-time scheme).
    fn add_assign(&mut self, b: EventCounts) {
        self.pair += b.pair;
        self.wall += b.wall;
        self.lid += b.lid;
        self.floor += b.floor;
        self.recheck += b.recheck;
        self.rest += b.rest;
        self.takeoff += b.takeoff;
        self.stale += b.stale;
        self.unmount += b.unmount;
        self.rebuild += b.rebuild;
        self.shell += b.shell;
        self.zeno += b.zeno;
        self.slide_end += b.slide_end;
    }
}

impl EventCounts {
    /// Collisions of any kind: pair + wall + lid + floor.
    pub fn collisions(&self) -> u64 {
        self.pair + self.wall + self.lid + self.floor
    }

    /// Every event popped from the queue (collisions, stale events, rechecks, shell exits,
    /// events dropped by a Zeno stop).
    pub fn popped(&self) -> u64 {
        self.collisions()
            + self.recheck
            + self.stale
            + self.takeoff
            + self.unmount
            + self.shell
            + self.zeno
            + self.slide_end
    }

    /// What `run.max_events` and the stall guard count: every popped event, every disk coming
    /// to rest (which happen inside other events, sometimes many at once: a loop of disks
    /// coming to rest and being released again must meet the guard too), and every grid
    /// re-mapping (a disk so fast that the re-mappings follow each other without the clock
    /// advancing must meet it too).
    pub fn guarded(&self) -> u64 {
        self.popped() + self.rest + self.rebuild
    }
}

/// How often each rule that ends a jam engaged (see `engine::rest::jams`): what
/// the rules' own tests look at. Not in the summary, not kept across a resume.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct JamCounts {
    /// A flying disk stopped in a slot between supports that do not give.
    pub slot: u64,
    /// A flying disk stopped after a burst of events at one instant (a closed wedge).
    pub zeno: u64,
    /// A disk at rest in a pocket by a side wall.
    pub pocket: u64,
    /// A disk hitting a jammed row, which does not give.
    pub jammed_row: u64,
    /// A disk pushing one at rest too gently to move it.
    pub gentle_push: u64,
    /// A jammed cluster of slow flying disks come to rest together.
    pub cluster: u64,
    /// A row at rest on the floor pushed aside a hair to let a disk down onto the floor.
    pub floor_room: u64,
    /// A full row of flying disks seated on a row at rest.
    pub seated_row: u64,
    /// A full row on the floor stopped.
    pub floor_row: u64,
    /// A disk sliding on a rough floor, pressed gently into another, rolled at once.
    pub pressed_slider: u64,
}

/// Energy (and the floor's momentum) exchanged with the outside, and energy lost in collisions,
/// since the start.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyFlow {
    /// Work done by the floor on the disks (can be negative for a lossy static floor).
    pub injected: f64,
    /// Kinetic energy lost in pair, wall and lid collisions.
    pub dissipated: f64,
    /// Vertical momentum the floor has given the disks: its impacts, and the force
    /// `m (g + h'')` carrying the disks at rest on it. Its time average per unit width is the
    /// pressure on the floor.
    pub floor_impulse: f64,
}

impl EnergyFlow {
    /// The floor changes a disk's vertical velocity from `before` to `after` (an impact, a
    /// launch): the work it does and the momentum it gives, for a disk of mass `mass`.
    #[inline]
    pub fn floor_work(&mut self, mass: f64, before: f64, after: f64) {
        self.injected += 0.5 * mass * (after * after - before * before);
        self.floor_impulse += mass * (after - before);
    }

    /// The floor carries a disk of mass `mass` at rest on it, under gravity `g`, from height,
    /// vertical velocity and time `(y0, vy0, t0)` to `(y1, vy1, t1)`: the work it does (the
    /// disk's gain of potential and kinetic energy) and the momentum it gives (the weight it
    /// holds meanwhile and the change of the disk's momentum).
    #[inline]
    pub fn floor_carry(
        &mut self,
        mass: f64,
        g: f64,
        (y0, vy0, t0): (f64, f64, f64),
        (y1, vy1, t1): (f64, f64, f64),
    ) {
        self.injected += mass * (g * (y1 - y0) + 0.5 * (vy1 * vy1 - vy0 * vy0));
        self.floor_impulse += mass * (g * (t1 - t0) + (vy1 - vy0));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zeno_stops_count_as_popped() {
        let mut c = EventCounts {
            pair: 10,
            ..Default::default()
        };
        assert_eq!(c.popped(), 10);
        c.zeno = 3;
        assert_eq!(c.popped(), 13);
        assert_eq!(serde_json::to_value(c).unwrap()["zeno"], 3);
    }
}
