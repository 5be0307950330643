//! Every kind of event a disk can have next, and how it is filed: one `u32` per disk beside its
//! event time, a disk number for a pair collision and one of the highest values for the rest
//! ([`code`]). The event loop reads the code back as an [`Event`] to fire it.
//!
//! The kinds are one table (`events!`, below): a new kind is a row of it, with the codes it is
//! filed under and what the collision log records of it; the enum, the codes and the
//! conversions both ways are made from it.

use super::log::Partner;
use crate::physics::walls::Side;

/// Makes [`Event`], the [`code`]s and the conversions from the table of kinds below. Each
/// kind is a variant (with its payload type, if any) and the codes it is filed under: a name,
/// its offset below `u32::MAX`, the payload it stands for, and `=> P` if the collision log
/// records the impact as `Partner::P`.
macro_rules! events {
    (@partner) => { None };
    (@partner $p:ident) => { Some(Partner::$p) };
    ($(
        $(#[$doc:meta])*
        $kind:ident $(($payload:ty))? {
            $($code:ident = $offset:literal $(($($arg:tt)*))? $(=> $partner:ident)?),+ $(,)?
        }
    )*) => {
        /// A disk's next event.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum Event {
            /// A collision with this disk (still due if the partner's collision counter is the
            /// one filed with the event: the partner has not moved since).
            Pair(u32),
            $($(#[$doc])* $kind $(($payload))?,)*
        }

        /// The `u32` codes events are filed under: disk numbers for pairs, these for the rest.
        pub(crate) mod code {
            $($(pub const $code: u32 = u32::MAX - $offset;)+)*
            /// Every code that is not a disk.
            const ALL: &[u32] = &[$($($code),+),*];
            /// The lowest code that is not a disk: no scene may have this many disks.
            pub const FIRST_NOT_A_DISK: u32 = super::lowest(ALL);
            const _: () = assert!(super::distinct(ALL), "two kinds of event share a code");
        }

        impl Event {
            /// The event filed under `code`.
            #[inline(always)]
            pub fn of(c: u32) -> Event {
                match c {
                    $($(code::$code => Event::$kind $(($($arg)*))?,)+)*
                    j => Event::Pair(j),
                }
            }

            /// The code this event is filed under.
            #[inline(always)]
            pub fn code(self) -> u32 {
                match self {
                    Event::Pair(j) => j,
                    $($(Event::$kind $(($($arg)*))? => code::$code,)+)*
                }
            }

            /// What the collision log records of this event: the wall, lid, floor or partner
            /// disk hit; nothing for the events that are not impacts.
            pub fn partner(self) -> Option<Partner> {
                match self {
                    Event::Pair(j) => Some(Partner::Disk(j)),
                    $($(Event::$kind $(($($arg)*))? => events!(@partner $($partner)?),)+)*
                }
            }
        }

        /// Every event but a pair collision, one per code.
        #[cfg(test)]
        const EVERY: &[Event] = &[$($(Event::$kind $(($($arg)*))?),+),*];
    };
}

events! {
    /// An impact on a side wall.
    Wall(Side) {
        LEFT = 1 (Side::Left) => Left,
        RIGHT = 2 (Side::Right) => Right,
    }
    /// An impact on the lid.
    Lid { LID = 3 => Lid }
    /// An impact on the floor.
    Floor { FLOOR = 4 => Floor }
    /// The end of a ride on the floor: the floor pulls away faster than gravity (take-off) or
    /// turns up into the disk (a kick).
    RideEnd { RIDE_END = 5 }
    /// A disk resting on disks loses a support (they slide apart).
    Unmount { UNMOUNT = 6 }
    /// A disk sliding on a rough floor rolls.
    SlideEnd { SLIDE_END = 9 }
    /// The disk leaves its shell (local re-mapping): its neighbour list is rebuilt.
    ShellExit { SHELL = 7 }
    /// The prediction is made again: the floor search looked only so far ahead.
    Recheck { RECHECK = 8 }
    /// An impact on a corner of the floor's orifice (`true`: the right one).
    Corner(bool) {
        CORNER_LEFT = 10 (false) => Floor,
        CORNER_RIGHT = 11 (true) => Floor,
    }
    /// The disk is wholly below the floor in the orifice: it leaves.
    Exit { EXIT = 12 }
    /// The disk's centre rises to the exit height of an open top: it leaves.
    ExitTop { EXIT_TOP = 14 }
    /// A disk at rest on the floor slides over an edge of the orifice.
    Edge { EDGE = 13 }
    /// No event: the disk's time is infinite, it is never the earliest.
    None { NONE = 0 }
}

/// The lowest of `codes`.
const fn lowest(codes: &[u32]) -> u32 {
    let (mut low, mut k) = (u32::MAX, 0);
    while k < codes.len() {
        if codes[k] < low {
            low = codes[k];
        }
        k += 1;
    }
    low
}

/// Whether no two of `codes` are the same.
const fn distinct(codes: &[u32]) -> bool {
    let mut k = 0;
    while k < codes.len() {
        let mut l = k + 1;
        while l < codes.len() {
            if codes[k] == codes[l] {
                return false;
            }
            l += 1;
        }
        k += 1;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_event_reads_back_from_its_code() {
        let pairs = [Event::Pair(0), Event::Pair(code::FIRST_NOT_A_DISK - 1)];
        for e in pairs.iter().chain(EVERY) {
            assert_eq!(Event::of(e.code()), *e, "{e:?}");
        }
        assert!(EVERY.iter().all(|e| e.code() >= code::FIRST_NOT_A_DISK));
        assert!(EVERY.contains(&Event::Wall(Side::Right)) && EVERY.contains(&Event::None));
    }

    #[test]
    fn distinct_tells_a_shared_code() {
        assert!(distinct(&[1, 2, 3]));
        assert!(!distinct(&[1, 2, 1]));
        assert_eq!(lowest(&[7, 3, 9]), 3);
    }

    #[test]
    fn only_impacts_are_logged() {
        assert_eq!(Event::Pair(7).partner(), Some(Partner::Disk(7)));
        assert_eq!(Event::Floor.partner(), Some(Partner::Floor));
        assert_eq!(Event::Corner(true).partner(), Some(Partner::Floor));
        assert_eq!(Event::Wall(Side::Left).partner(), Some(Partner::Left));
        assert_eq!(Event::Recheck.partner(), None);
        assert_eq!(Event::ShellExit.partner(), None);
    }
}
