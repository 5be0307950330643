//! Every kind of event a disk can have next, and how it is filed: one `u32` per disk beside its
//! event time, a disk number for a pair collision and one of the highest values for the rest
//! ([`code`]). The event loop reads the code back as an [`Event`] to fire it.

use super::log::Partner;
use crate::physics::walls::Side;

/// A disk's next event.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Event {
    /// A collision with this disk (still due if the partner's collision counter is the one
    /// filed with the event: the partner has not moved since).
    Pair(u32),
    /// An impact on a side wall.
    Wall(Side),
    /// An impact on the lid.
    Lid,
    /// An impact on the floor.
    Floor,
    /// The end of a ride on the floor: the floor pulls away faster than gravity (take-off) or
    /// turns up into the disk (a kick).
    RideEnd,
    /// A disk resting on disks loses a support (they slide apart).
    Unmount,
    /// A disk sliding on a rough floor rolls.
    SlideEnd,
    /// The disk leaves its shell (local re-mapping): its neighbour list is rebuilt.
    ShellExit,
    /// The prediction is made again: the floor search looked only so far ahead.
    Recheck,
    /// An impact on a corner of the floor's orifice (`true`: the right one).
    Corner(bool),
    /// The disk is wholly below the floor in the orifice: it leaves.
    Exit,
    /// The disk's centre rises to the exit height of an open top: it leaves.
    ExitTop,
    /// A disk at rest on the floor slides over an edge of the orifice.
    Edge,
    /// No event: the disk's time is infinite, it is never the earliest.
    None,
}

/// The `u32` codes events are filed under: disk numbers for pairs, these for the rest.
pub(crate) mod code {
    pub const NONE: u32 = u32::MAX;
    pub const LEFT: u32 = u32::MAX - 1;
    pub const RIGHT: u32 = u32::MAX - 2;
    pub const LID: u32 = u32::MAX - 3;
    pub const FLOOR: u32 = u32::MAX - 4;
    pub const RIDE_END: u32 = u32::MAX - 5;
    pub const UNMOUNT: u32 = u32::MAX - 6;
    pub const SHELL: u32 = u32::MAX - 7;
    pub const RECHECK: u32 = u32::MAX - 8;
    pub const SLIDE_END: u32 = u32::MAX - 9;
    pub const CORNER_LEFT: u32 = u32::MAX - 10;
    pub const CORNER_RIGHT: u32 = u32::MAX - 11;
    pub const EXIT: u32 = u32::MAX - 12;
    pub const EDGE: u32 = u32::MAX - 13;
    pub const EXIT_TOP: u32 = u32::MAX - 14;
    /// The lowest code that is not a disk: no scene may have this many disks.
    pub const FIRST_NOT_A_DISK: u32 = EXIT_TOP;
}

impl Event {
    /// The event filed under `code`.
    #[inline(always)]
    pub fn of(c: u32) -> Event {
        match c {
            code::NONE => Event::None,
            code::LEFT => Event::Wall(Side::Left),
            code::RIGHT => Event::Wall(Side::Right),
            code::LID => Event::Lid,
            code::FLOOR => Event::Floor,
            code::RIDE_END => Event::RideEnd,
            code::UNMOUNT => Event::Unmount,
            code::SHELL => Event::ShellExit,
            code::RECHECK => Event::Recheck,
            code::SLIDE_END => Event::SlideEnd,
            code::CORNER_LEFT => Event::Corner(false),
            code::CORNER_RIGHT => Event::Corner(true),
            code::EXIT => Event::Exit,
            code::EDGE => Event::Edge,
            code::EXIT_TOP => Event::ExitTop,
            j => Event::Pair(j),
        }
    }

    /// The code this event is filed under.
    #[inline(always)]
    pub fn code(self) -> u32 {
        match self {
            Event::Pair(j) => j,
            Event::Wall(Side::Left) => code::LEFT,
            Event::Wall(Side::Right) => code::RIGHT,
            Event::Lid => code::LID,
            Event::Floor => code::FLOOR,
            Event::RideEnd => code::RIDE_END,
            Event::Unmount => code::UNMOUNT,
            Event::ShellExit => code::SHELL,
            Event::Recheck => code::RECHECK,
            Event::SlideEnd => code::SLIDE_END,
            Event::Corner(false) => code::CORNER_LEFT,
            Event::Corner(true) => code::CORNER_RIGHT,
            Event::Exit => code::EXIT,
            Event::Edge => code::EDGE,
            Event::ExitTop => code::EXIT_TOP,
            Event::None => code::NONE,
        }
    }

    /// What the collision log records of this event: the wall, lid, floor or partner disk hit;
    /// nothing for the events that are not impacts.
    pub fn partner(self) -> Option<Partner> {
        match self {
            Event::Pair(j) => Some(Partner::Disk(j)),
            Event::Wall(Side::Left) => Some(Partner::Left),
            Event::Wall(Side::Right) => Some(Partner::Right),
            Event::Lid => Some(Partner::Lid),
            Event::Floor | Event::Corner(_) => Some(Partner::Floor),
            Event::RideEnd
            | Event::Exit
            | Event::ExitTop
            | Event::Edge
            | Event::Unmount
            | Event::SlideEnd
            | Event::ShellExit
            | Event::Recheck
            | Event::None => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_event_reads_back_from_its_code() {
        let events = [
            Event::Pair(0),
            Event::Pair(code::FIRST_NOT_A_DISK - 1),
            Event::Wall(Side::Left),
            Event::Wall(Side::Right),
            Event::Lid,
            Event::Floor,
            Event::RideEnd,
            Event::Unmount,
            Event::ShellExit,
            Event::Recheck,
            Event::SlideEnd,
            Event::Corner(false),
            Event::Corner(true),
            Event::Exit,
            Event::Edge,
            Event::ExitTop,
            Event::None,
        ];
        for e in events {
            assert_eq!(Event::of(e.code()), e, "{e:?}");
        }
        let codes: std::collections::BTreeSet<u32> = events[2..].iter().map(|e| e.code()).collect();
        assert_eq!(codes.len(), events.len() - 2, "distinct codes");
        assert!(codes.iter().all(|&c| c >= code::FIRST_NOT_A_DISK));
    }

    #[test]
    fn only_impacts_are_logged() {
        assert_eq!(Event::Pair(7).partner(), Some(Partner::Disk(7)));
        assert_eq!(Event::Floor.partner(), Some(Partner::Floor));
        assert_eq!(Event::Recheck.partner(), None);
        assert_eq!(Event::ShellExit.partner(), None);
    }
}
