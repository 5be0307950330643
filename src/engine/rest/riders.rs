//! Disks at rest: riding the floor, or resting on disks that rest (a bed at rest).
//!
//! A disk *rides* when its vertical motion is the floor's, `y(t) = h(t) + lift`, and it slides
//! horizontally at constant speed. Disks that ride directly on the floor have `lift` = their
//! radius. A disk that lands gently on riding disks in a stable position (its weight carried by
//! supports on both sides of the vertical, or by one support straight below) rides too, with the
//! lift it had at landing and its supports' horizontal velocity: the stack moves rigidly with the
//! floor and costs no events. Each such disk records up to two supporting disks (or a side wall),
//! and each disk the disks it carries, so that a support that leaves the floor's grip (hit, thrown
//! off, kicked) releases everything resting on it at once.
//!
//! The carried lists are validated lazily: an entry counts only while the carried disk still
//! rides and still names the carrier among its supports.

use crate::physics::slide::Slide;

/// No disk (an empty support or carried slot, or "supported by the floor").
pub const NO_DISK: u32 = u32::MAX;
/// A support code: the left side wall.
pub const LEFT_WALL: u32 = u32::MAX - 1;
/// A support code: the right side wall.
pub const RIGHT_WALL: u32 = u32::MAX - 2;
/// How many disks of radius `a_min` can touch a disk of radius `a_max` at once (each pair of
/// them apart by at least `2 a_min`): the most disks one disk can carry, however they rest on it.
/// Six for equal disks, seven for radii 0.4–0.6.
pub fn carried_room(a_min: f64, a_max: f64) -> usize {
    let half_angle = (a_min / (a_min + a_max)).asin();
    // (A hair of slack: six equal disks fit exactly, and π/(π/6) rounds below 6.)
    (std::f64::consts::PI / half_angle + 1e-9).floor() as usize
}

/// Who rides the floor and what rests on what; empty for scenes without a floor.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Riders {
    riding: Vec<bool>,
    /// How many disks ride (kept with `riding`; recounted after a checkpoint is read).
    #[serde(skip)]
    riding_count: usize,
    lift: Vec<f64>,
    support: Vec<[u32; 2]>,
    /// Slots per disk in `carries`.
    room: usize,
    /// The disks each disk carries, `room` slots per disk.
    carries: Vec<u32>,
    /// Each disk's slide on a rough floor ([`Slide::NONE`] when it rolls or flies); empty
    /// unless the floor is rough.
    slides: Vec<Slide>,
    /// How many disks slide (kept with `slides`; recounted after a checkpoint is read).
    #[serde(skip)]
    sliding_count: usize,
    /// The (absolute) time the last disk came to rest while every disk is at rest: the end of
    /// the last motion. `None` while a disk moves.
    at_rest_since: Option<f64>,
    /// Disks released from a bed all at rest by the rules or a collision, not by the floor
    /// (a take-off or a kick) nor through an outlet.
    wakes: u64,
}

impl Riders {
    /// Number of disks tracked (0 without a floor).
    pub fn len(&self) -> usize {
        self.riding.len()
    }

    /// `true` when no disk is tracked (no floor).
    pub fn is_empty(&self) -> bool {
        self.riding.is_empty()
    }

    /// Room for `n` disks, none riding, each able to carry `room` disks (see [`carried_room`]).
    pub fn new(n: usize, room: usize) -> Riders {
        Riders {
            riding: vec![false; n],
            riding_count: 0,
            lift: vec![0.0; n],
            support: vec![[NO_DISK; 2]; n],
            room,
            carries: vec![NO_DISK; n * room],
            slides: Vec::new(),
            sliding_count: 0,
            at_rest_since: None,
            wakes: 0,
        }
    }

    /// Room for slides: the floor is rough.
    pub fn with_slides(mut self) -> Riders {
        self.slides = vec![Slide::NONE; self.riding.len()];
        self
    }

    /// Disk `i`'s slide on a rough floor, if it slides.
    #[inline(always)]
    pub fn slide(&self, i: usize) -> Option<Slide> {
        self.slides.get(i).copied().filter(Slide::is_on)
    }

    /// `true` when some disk slides.
    #[inline(always)]
    pub fn any_sliding(&self) -> bool {
        self.sliding_count > 0
    }

    /// Disk `i` (riding the floor itself) slides with `slide`, or stops sliding (`None`).
    pub fn set_slide(&mut self, i: usize, slide: Option<Slide>) {
        let Some(old) = self.slides.get_mut(i) else {
            return;
        };
        let new = slide.unwrap_or(Slide::NONE);
        self.sliding_count = self.sliding_count + new.is_on() as usize - old.is_on() as usize;
        *old = new;
    }

    /// The clock's origin moved forward by `dt`: slides end `dt` earlier in local time.
    pub fn rebase(&mut self, dt: f64) {
        for s in self.slides.iter_mut().filter(|s| s.is_on()) {
            s.end -= dt;
        }
    }

    /// Where the carried slots of disk `s` lie in `carries`.
    #[inline]
    fn span(&self, s: usize) -> std::ops::Range<usize> {
        s * self.room..(s + 1) * self.room
    }

    /// The carried slots of disk `s`.
    #[inline]
    fn slots(&self, s: usize) -> &[u32] {
        &self.carries[self.span(s)]
    }

    /// `true` when disk `i` rides (on the floor or on riding disks).
    #[inline(always)]
    pub fn is_riding(&self, i: usize) -> bool {
        self.riding.get(i).copied().unwrap_or(false)
    }

    /// Height of riding disk `i` above the floor's surface: `y = h(t) + lift`.
    #[inline(always)]
    pub fn lift(&self, i: usize) -> f64 {
        self.lift[i]
    }

    /// `true` when riding disk `i` rests on the floor itself (not on other disks).
    #[inline]
    pub fn on_floor(&self, i: usize) -> bool {
        self.support[i] == [NO_DISK; 2]
    }

    /// What disk `i` rests on: disk numbers, wall codes or [`NO_DISK`].
    #[inline]
    pub fn supports(&self, i: usize) -> [u32; 2] {
        self.support[i]
    }

    /// Disk `i` starts riding the floor directly at (absolute) time `now`, its centre `lift`
    /// above the floor's surface.
    pub fn mount_on_floor(&mut self, i: usize, lift: f64, now: f64) {
        self.set_riding(i, true);
        self.note_rest(now);
        self.set_slide(i, None);
        self.lift[i] = lift;
        self.support[i] = [NO_DISK; 2];
    }

    /// Disk `k` starts resting on `supports` (disks or walls) at (absolute) time `now`, `lift`
    /// above the floor's surface. Refused (returns `false`, nothing changes) when a supporting
    /// disk's slots are full (which the geometry forbids when the room comes from
    /// [`carried_room`]).
    pub fn mount_on_disks(&mut self, k: usize, lift: f64, supports: [u32; 2], now: f64) -> bool {
        let disks = || supports.into_iter().filter(|&s| s < RIGHT_WALL);
        for s in disks() {
            self.purge(s as usize);
            if !self.slots(s as usize).contains(&NO_DISK) {
                return false;
            }
        }
        self.set_riding(k, true);
        self.note_rest(now);
        self.set_slide(k, None);
        self.lift[k] = lift;
        self.support[k] = supports;
        for s in disks() {
            let s = s as usize;
            let span = self.span(s);
            let slots = &mut self.carries[span];
            if !slots.contains(&(k as u32)) {
                let free = slots
                    .iter()
                    .position(|&c| c == NO_DISK)
                    .expect("room checked");
                slots[free] = k as u32;
            }
        }
        true
    }

    /// Drops the carried entries of `s` that are no longer valid.
    fn purge(&mut self, s: usize) {
        for slot in self.span(s) {
            let c = self.carries[slot];
            if c != NO_DISK && !self.rests_on(c as usize, s) {
                self.carries[slot] = NO_DISK;
            }
        }
    }

    /// `true` when disk `k` rides resting on disk `s`.
    #[inline]
    fn rests_on(&self, k: usize, s: usize) -> bool {
        self.riding[k] && self.support[k].contains(&(s as u32))
    }

    /// Disk `i` stops riding, released by a rule or a collision: counted as a wake when every
    /// disk was at rest.
    #[inline]
    pub fn dismount(&mut self, i: usize) {
        if self.riding[i] && self.riding_count == self.riding.len() {
            self.wakes += 1;
        }
        self.set_riding(i, false);
    }

    /// Disk `i` stops riding, thrown off by the floor or leaving through an outlet: something
    /// acts on it, no wake.
    #[inline]
    pub fn leave(&mut self, i: usize) {
        self.set_riding(i, false);
    }

    /// A disk came to rest at `now`: if every disk now rests, the bed has been at rest since.
    #[inline]
    fn note_rest(&mut self, now: f64) {
        if self.riding_count == self.riding.len() {
            self.at_rest_since = Some(now);
        }
    }

    /// The time since which every disk has been at rest (`None` while a disk moves, or when the
    /// last motion ended as a disk left the scene).
    pub fn at_rest_since(&self) -> Option<f64> {
        self.at_rest_since
            .filter(|_| !self.riding.is_empty() && self.riding_count == self.riding.len())
    }

    /// Disks released from a bed all at rest by the rules or a collision.
    pub fn wakes(&self) -> u64 {
        self.wakes
    }

    /// Marks disk `i` riding or not, keeping the count.
    #[inline]
    fn set_riding(&mut self, i: usize, riding: bool) {
        if !riding {
            self.set_slide(i, None);
        }
        if self.riding[i] != riding {
            self.riding[i] = riding;
            if riding {
                self.riding_count += 1;
            } else {
                self.riding_count -= 1;
                self.at_rest_since = None;
            }
        }
    }

    /// Counts the riding disks anew (after the flags were read from a checkpoint).
    pub fn recount(&mut self) {
        self.riding_count = self.riding.iter().filter(|&&r| r).count();
        self.sliding_count = self.slides.iter().filter(|s| s.is_on()).count();
    }

    /// Appends the disks resting on `s` now to `out` (clears its carried list).
    pub fn take_carried(&mut self, s: usize, out: &mut Vec<u32>) {
        for slot in self.span(s) {
            let c = std::mem::replace(&mut self.carries[slot], NO_DISK);
            if c != NO_DISK && self.rests_on(c as usize, s) {
                out.push(c);
            }
        }
    }

    /// `true` when disk `s` carries any resting disk (without clearing anything).
    #[inline]
    pub fn carries_any(&self, s: usize) -> bool {
        s < self.riding.len()
            && self
                .slots(s)
                .iter()
                .any(|&c| c != NO_DISK && self.rests_on(c as usize, s))
    }

    /// Number of riding disks.
    #[inline]
    pub fn count(&self) -> usize {
        self.riding_count
    }

    /// Number of riding disks that rest on other disks.
    pub fn stacked(&self) -> usize {
        (0..self.riding.len())
            .filter(|&i| self.riding[i] && !self.on_floor(i))
            .count()
    }

    /// `true` when any disk rides.
    #[inline]
    pub fn any(&self) -> bool {
        self.riding_count > 0
    }

    /// Indices of the riding disks.
    pub fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.riding.len()).filter(|&i| self.riding[i])
    }

    /// A flying disk enters as the last one.
    pub fn push(&mut self) {
        if self.riding.is_empty() && self.room == 0 {
            return;
        }
        self.at_rest_since = None;
        self.riding.push(false);
        self.lift.push(0.0);
        self.support.push([NO_DISK; 2]);
        if !self.slides.is_empty() {
            self.slides.push(Slide::NONE);
        }
        self.carries.extend(std::iter::repeat_n(NO_DISK, self.room));
    }

    /// Room for `cap` disks.
    pub fn reserve_to(&mut self, cap: usize) {
        let more = cap.saturating_sub(self.riding.len());
        self.riding.reserve_exact(more);
        self.lift.reserve_exact(more);
        self.support.reserve_exact(more);
        self.carries.reserve_exact(more * self.room);
        if !self.slides.is_empty() {
            self.slides.reserve_exact(more);
        }
    }

    /// Flying disk `k` leaves, the last disk taking its number (no allocation): references to
    /// the last disk follow it, any to `k` are cleared.
    pub fn swap_remove(&mut self, k: usize) {
        if self.riding.is_empty() {
            return;
        }
        self.set_riding(k, false);
        self.at_rest_since = None;
        let last = self.riding.len() - 1;
        let renamed = |d: u32| {
            if d == k as u32 {
                NO_DISK
            } else if d == last as u32 {
                k as u32
            } else {
                d
            }
        };
        for s in self.support.iter_mut() {
            *s = s.map(renamed);
        }
        for c in self.carries.iter_mut() {
            *c = renamed(*c);
        }
        self.riding.swap_remove(k);
        self.lift.swap_remove(k);
        self.support.swap_remove(k);
        if !self.slides.is_empty() {
            self.slides.swap_remove(k);
        }
        let room = self.room;
        for r in 0..room {
            self.carries[k * room + r] = self.carries[last * room + r];
        }
        self.carries.truncate(last * room);
    }

    /// Follows a renumbering of the disks: new disk k is old disk `from[k]`.
    pub fn permute(&mut self, from: &[u32]) {
        if self.riding.is_empty() {
            return;
        }
        // Old disk j is now place[j].
        let mut place = vec![0u32; from.len()];
        for (k, &f) in from.iter().enumerate() {
            place[f as usize] = k as u32;
        }
        let renamed = |d: u32| if d < RIGHT_WALL { place[d as usize] } else { d };
        let take = |k: &u32| *k as usize;
        self.riding = from.iter().map(|k| self.riding[take(k)]).collect();
        self.lift = from.iter().map(|k| self.lift[take(k)]).collect();
        if !self.slides.is_empty() {
            self.slides = from.iter().map(|k| self.slides[take(k)]).collect();
        }
        self.support = from
            .iter()
            .map(|k| self.support[take(k)].map(renamed))
            .collect();
        let mut carries = Vec::with_capacity(self.carries.len());
        for &k in from {
            carries.extend(self.slots(k as usize).iter().map(|&c| renamed(c)));
        }
        self.carries = carries;
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.riding.capacity()
            + 8 * self.lift.capacity()
            + 8 * self.support.capacity()
            + 4 * self.carries.capacity()
            + std::mem::size_of::<Slide>() * self.slides.capacity()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bed_is_at_rest_from_the_last_disk_that_came_to_rest() {
        let mut r = Riders::new(2, carried_room(0.5, 0.5));
        r.mount_on_floor(0, 0.5, 1.0);
        assert_eq!(r.at_rest_since(), None);
        assert!(r.mount_on_disks(1, 1.5, [0, NO_DISK], 2.0));
        assert_eq!(r.at_rest_since(), Some(2.0));
        // Released from a bed at rest by a rule: a wake, and the bed moves.
        r.dismount(1);
        assert_eq!((r.at_rest_since(), r.wakes()), (None, 1));
        assert!(r.mount_on_disks(1, 1.5, [0, NO_DISK], 3.0));
        assert_eq!(r.at_rest_since(), Some(3.0));
        // Thrown off by the floor: no wake.
        r.leave(0);
        assert_eq!((r.at_rest_since(), r.wakes()), (None, 1));
        // Released while a disk flies: no wake either.
        r.dismount(1);
        assert_eq!(r.wakes(), 1);
    }

    #[test]
    fn carried_lists_follow_the_supports() {
        let mut r = Riders::new(4, 4);
        r.mount_on_floor(0, 0.5, 0.0);
        assert!(r.mount_on_disks(1, 1.5, [0, NO_DISK], 0.0));
        assert!(r.carries_any(0));
        // Disk 1 leaves and lands elsewhere: 0 no longer carries it.
        r.dismount(1);
        assert!(!r.carries_any(0));
        r.mount_on_floor(2, 0.5, 0.0);
        assert!(r.mount_on_disks(1, 1.4, [2, LEFT_WALL], 0.0));
        let mut out = Vec::new();
        r.take_carried(0, &mut out);
        assert!(out.is_empty());
        r.take_carried(2, &mut out);
        assert_eq!(out, [1]);
        assert!(!r.carries_any(2));
    }

    #[test]
    fn a_full_carrier_refuses() {
        let room = carried_room(0.5, 0.5);
        assert_eq!(room, 6);
        assert_eq!(carried_room(0.4, 0.6), 7);
        let mut r = Riders::new(room + 2, room);
        r.mount_on_floor(0, 0.5, 0.0);
        for k in 1..=room {
            assert!(r.mount_on_disks(k, 1.5, [0, NO_DISK], 0.0));
        }
        assert!(!r.mount_on_disks(room + 1, 1.5, [0, NO_DISK], 0.0));
        assert!(!r.is_riding(room + 1));
        assert_eq!(r.count(), 1 + room);
        assert_eq!(r.stacked(), room);
    }
}
