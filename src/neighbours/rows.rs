//! Rows with room: many short lists of disk numbers that change one entry at a time (the
//! local re-mapping's neighbour lists, one per disk, and its cells of anchors, one per cell).
//! Each list has a row of `room` slots; the few longer ones move whole into wider chunks of an
//! overflow area while they are long. Rows sized for the longest list would spend most of
//! their memory on room few lists use.

use crate::platform::cpu::Lanes;

/// `len` of a list in the overflow area.
const SPILLED: u8 = u8::MAX;

/// Slots copied at once by [`Rows::copy_into`], which may read up to `GROUP` past a row's start
/// (beyond a short row's end).
pub const GROUP: usize = 8;

/// Slots compared at once by [`Rows::remove`], which may read up to `LANES − 1` past a row's
/// end: one AVX2 comparison of 32-bit numbers.
const LANES: usize = 8;

/// Slots kept past the last row, for the reads past a row's end.
const PADDING: usize = if GROUP > LANES { GROUP } else { LANES };

/// The slots of `row` (whole groups of [`LANES`], at most 64 slots) that hold `j`, as bits
/// (bit k for slot k), one slot at a time.
#[inline(always)]
fn holding(row: &[u32], j: u32) -> u64 {
    let mut bits = 0u64;
    let mut g = 0;
    while g < row.len() {
        let found = row[g..g + LANES]
            .iter()
            .enumerate()
            .fold(0, |bits, (k, &x)| bits | (((x == j) as u64) << k));
        bits |= found << g;
        g += LANES;
    }
    bits
}

/// [`holding`], a group in one AVX2 comparison of 32-bit numbers.
///
/// # Safety
///
/// Only where the processor has AVX2.
#[cfg(target_arch = "x86_64")]
#[cfg_attr(target_feature = "avx2", inline(always))]
#[cfg_attr(not(target_feature = "avx2"), target_feature(enable = "avx2"), inline)]
unsafe fn holding_in_lanes(row: &[u32], j: u32) -> u64 {
    use std::arch::x86_64::*;
    let key = _mm256_set1_epi32(j as i32);
    let group = |g: usize| {
        let group: &[u32; LANES] = row[g..g + LANES].try_into().unwrap();
        // The load is unaligned, of a whole group.
        let slots = _mm256_loadu_si256(group.as_ptr().cast());
        let equal = _mm256_cmpeq_epi32(slots, key);
        (_mm256_movemask_ps(_mm256_castsi256_ps(equal)) as u32 as u64) << g
    };
    // Rows of one or two groups (the lists of most scenes) without a loop to set up.
    match row.len() {
        LANES => group(0),
        w if w == 2 * LANES => group(0) | group(LANES),
        w => (0..w).step_by(LANES).fold(0, |bits, g| bits | group(g)),
    }
}

/// Lists in rows with room and an overflow area: list `i` is `slots[i·room .. i·room +
/// len[i]]` while it fits; a longer list (`len[i] = SPILLED`) lives whole in chunk
/// `c = slots[i·room]` of the overflow area, its length in `spill[c·wide]` and its entries
/// after it.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct Rows {
    /// Slots per row (1 to 254).
    room: usize,
    slots: Vec<u32>,
    len: Vec<u8>,
    /// Slots per overflow chunk, its length included (more than `room + 1`; widened when a
    /// list outgrows it).
    wide: usize,
    spill: Vec<u32>,
    /// Overflow chunks no list holds.
    free: Vec<u32>,
}

impl Rows {
    /// `n` empty lists, in rows that leave at most one list in fifty to the overflow area if
    /// the lists are to be as long as `length(i)`; overflow chunks for the longest.
    pub fn sized_for(n: usize, length: impl Fn(usize) -> usize) -> Rows {
        let most = (0..n).map(&length).max().unwrap_or(0);
        let mut count = vec![0usize; most + 1];
        for i in 0..n {
            count[length(i)] += 1;
        }
        // The smallest room that leaves at most n/50 lists longer.
        let (mut room, mut longer) = (most, 0);
        while room > 1 && longer + count[room] <= n / 50 {
            longer += count[room];
            room -= 1;
        }
        let room = room.clamp(1, SPILLED as usize - 1);
        Rows {
            room,
            slots: vec![0; n * room + PADDING],
            len: vec![0; n],
            wide: (most + 1).max(room + 2),
            spill: Vec::new(),
            free: Vec::new(),
        }
    }

    /// Slots per row.
    pub fn room(&self) -> usize {
        self.room
    }

    /// Number of lists.
    pub fn lists(&self) -> usize {
        self.len.len()
    }

    /// List `i`.
    #[inline(always)]
    pub fn of(&self, i: usize) -> &[u32] {
        let (s, l) = (i * self.room, self.len[i]);
        if l != SPILLED {
            &self.slots[s..s + l as usize]
        } else {
            self.spilled(i)
        }
    }

    /// Copies list `i` to `out[at..]` and returns its length. A list of at most [`GROUP`]
    /// slots in its row (most are: a cell holds a few anchors) is copied as one whole group,
    /// whatever its length (no loop, no exit to mispredict, one bounds check each way); a
    /// longer or overflowing one out of line. `out` must have room for a group, or the list if
    /// longer, past `at`.
    #[inline(always)]
    pub fn copy_into(&self, i: usize, out: &mut [u32], at: usize) -> usize {
        let l = self.len[i] as usize;
        if l > GROUP {
            // `SPILLED` too.
            return self.copy_long_into(i, out, at);
        }
        let s = i * self.room;
        let from: &[u32; GROUP] = self.slots[s..s + GROUP].try_into().unwrap();
        out[at..at + GROUP].copy_from_slice(from);
        l
    }

    /// [`copy_into`](Self::copy_into) for a list longer than a group, in its row (group by
    /// group) or in the overflow area.
    #[cold]
    #[inline(never)]
    fn copy_long_into(&self, i: usize, out: &mut [u32], at: usize) -> usize {
        let list = if self.len[i] == SPILLED {
            self.spilled(i)
        } else {
            let s = i * self.room;
            &self.slots[s..s + self.len[i] as usize]
        };
        out[at..at + list.len()].copy_from_slice(list);
        list.len()
    }

    /// Hints that list `i` will be changed soon (its row and its length). Rows whose room is
    /// not a power of two may straddle two cache lines: their last slot is asked for too.
    #[inline(always)]
    pub fn prefetch(&self, i: usize) {
        crate::platform::prefetch::prefetch(&self.slots, i * self.room);
        if !self.room.is_power_of_two() {
            crate::platform::prefetch::prefetch(&self.slots, i * self.room + self.room - 1);
        }
        crate::platform::prefetch::prefetch(&self.len, i);
    }

    /// List `i` in the overflow area.
    #[cold]
    #[inline(never)]
    fn spilled(&self, i: usize) -> &[u32] {
        let c = self.slots[i * self.room] as usize * self.wide;
        let l = self.spill[c] as usize;
        &self.spill[c + 1..c + 1 + l]
    }

    /// The length of list `i`.
    #[inline]
    pub fn length(&self, i: usize) -> usize {
        match self.len[i] {
            SPILLED => self.spill[self.slots[i * self.room] as usize * self.wide] as usize,
            l => l as usize,
        }
    }

    /// List `i`, to change in place.
    #[inline]
    pub fn of_mut(&mut self, i: usize) -> &mut [u32] {
        let s = i * self.room;
        match self.len[i] {
            SPILLED => {
                let c = self.slots[s] as usize * self.wide;
                let l = self.spill[c] as usize;
                &mut self.spill[c + 1..c + 1 + l]
            }
            l => &mut self.slots[s..s + l as usize],
        }
    }

    /// Appends `j` to list `i`, moving the list to the overflow area when its row is full
    /// (and widening the overflow chunks when its chunk is).
    #[inline(always)]
    pub fn push(&mut self, i: usize, j: u32) {
        let l = self.len[i];
        // `SPILLED` is never below `room`.
        if (l as usize) < self.room {
            self.slots[i * self.room + l as usize] = j;
            self.len[i] = l + 1;
        } else {
            self.push_long(i, j);
        }
    }

    /// [`push`](Self::push) to a full row or an overflowing list.
    #[cold]
    #[inline(never)]
    fn push_long(&mut self, i: usize, j: u32) {
        let s = i * self.room;
        if self.len[i] == SPILLED {
            let c = self.slots[s] as usize;
            let l = self.spill[c * self.wide] as usize;
            if l + 1 == self.wide {
                self.widen_spill();
            }
            let at = c * self.wide;
            self.spill[at + 1 + l] = j;
            self.spill[at] += 1;
            return;
        }
        let l = self.room;
        let c = self.chunk();
        let at = c as usize * self.wide;
        self.spill[at] = (l + 1) as u32;
        self.spill[at + 1..at + 1 + l].copy_from_slice(&self.slots[s..s + l]);
        self.spill[at + 1 + l] = j;
        self.slots[s] = c;
        self.len[i] = SPILLED;
    }

    /// Removes `j` from list `i` (the last entry takes its place), moving the list back into
    /// its row once it fits; the row searched on the path `lanes`.
    #[inline(always)]
    pub fn remove(&mut self, i: usize, j: u32, lanes: Lanes) {
        #[cfg(target_arch = "x86_64")]
        if lanes.avx2() {
            // SAFETY: the processor has AVX2 (`lanes` says so).
            return self.remove_by(i, j, |row, j| unsafe { holding_in_lanes(row, j) });
        }
        let _ = lanes;
        self.remove_by(i, j, holding)
    }

    /// [`remove`](Self::remove), the row's slots that hold `j` found by `holding`.
    #[inline(always)]
    fn remove_by(&mut self, i: usize, j: u32, holding: impl Fn(&[u32], u32) -> u64) {
        let l = self.len[i];
        if l == SPILLED {
            self.remove_long(i, j);
            return;
        }
        // Every slot of the row looked at, without a branch: a search that stops where it
        // finds `j` mispredicts that stop (rows are short, their lengths vary). The slots that
        // hold `j` as bits of a mask, [`LANES`] slots at a time (where a running "last found"
        // would chain every slot on the one before); the groups may read past the row, into
        // the next or the padding.
        let s = i * self.room;
        let width = self.room.next_multiple_of(LANES);
        let e = if width <= 64 && s + width <= self.slots.len() {
            let bits = holding(&self.slots[s..s + width], j);
            // The list's slots (none when it is empty); of several, the last (as the loop
            // below finds: a list holds a disk once).
            let listed = u64::MAX.checked_shr(64 - l as u32).unwrap_or(0);
            match (bits & listed).leading_zeros() {
                64 => usize::MAX,
                z => 63 - z as usize,
            }
        } else {
            let mut e = usize::MAX;
            for (k, &x) in self.slots[s..s + self.room].iter().enumerate() {
                e = if x == j && k < l as usize { k } else { e };
            }
            e
        };
        if e != usize::MAX {
            self.slots[s + e] = self.slots[s + l as usize - 1];
            self.len[i] = l - 1;
        }
    }

    /// Removes `i` from the list of each disk in list `i` (which stays as it is), the rows
    /// searched on the path `lanes`.
    #[inline]
    pub fn leave_all(&mut self, i: usize, lanes: Lanes) {
        #[cfg(target_arch = "x86_64")]
        if lanes.avx2() {
            // SAFETY: the processor has AVX2 (`lanes` says so).
            return self.leave_all_by(i, |row, j| unsafe { holding_in_lanes(row, j) });
        }
        let _ = lanes;
        self.leave_all_by(i, holding)
    }

    /// [`leave_all`](Self::leave_all), the rows' slots that hold `i` found by `holding`.
    #[inline(always)]
    fn leave_all_by(&mut self, i: usize, holding: impl Fn(&[u32], u32) -> u64 + Copy) {
        let l = self.len[i];
        if l == SPILLED {
            for k in 0..self.length(i) {
                let j = self.of(i)[k];
                self.remove_by(j as usize, i as u32, holding);
            }
            return;
        }
        // A list never holds its own disk: removing `i` elsewhere leaves row `i` as it is.
        let s = i * self.room;
        for k in s..s + l as usize {
            let j = self.slots[k];
            self.remove_by(j as usize, i as u32, holding);
        }
    }

    /// [`remove`](Self::remove) from an overflowing list.
    #[cold]
    #[inline(never)]
    fn remove_long(&mut self, i: usize, j: u32) {
        let list = self.of_mut(i);
        let Some(e) = list.iter().position(|&k| k == j) else {
            return;
        };
        let last = list.len() - 1;
        list[e] = list[last];
        self.spill[self.slots[i * self.room] as usize * self.wide] -= 1;
        if last == self.room {
            self.unspill(i, last);
        }
    }

    /// Makes `new` list `i`.
    pub fn set(&mut self, i: usize, new: &[u32]) {
        self.clear(i);
        let s = i * self.room;
        if new.len() <= self.room {
            self.slots[s..s + new.len()].copy_from_slice(new);
            self.len[i] = new.len() as u8;
        } else {
            for &j in new {
                self.push(i, j);
            }
        }
    }

    /// Empties list `i`.
    pub fn clear(&mut self, i: usize) {
        if self.len[i] == SPILLED {
            self.unspill(i, 0);
        }
        self.len[i] = 0;
    }

    /// Moves list `i` of `l ≤ room` entries from its overflow chunk back to its row.
    fn unspill(&mut self, i: usize, l: usize) {
        let s = i * self.room;
        let c = self.slots[s];
        let at = c as usize * self.wide;
        self.slots[s..s + l].copy_from_slice(&self.spill[at + 1..at + 1 + l]);
        self.free.push(c);
        self.len[i] = l as u8;
    }

    /// A free overflow chunk (a new one if none is free).
    fn chunk(&mut self) -> u32 {
        self.free.pop().unwrap_or_else(|| {
            let c = self.spill.len() / self.wide;
            self.spill.resize((c + 1) * self.wide, 0);
            c as u32
        })
    }

    /// Gives every overflow chunk a quarter more slots (at least one), in place.
    fn widen_spill(&mut self) {
        let (old, wide) = (self.wide, self.wide + (self.wide / 4).max(1));
        let chunks = self.spill.len() / old;
        self.spill.resize(chunks * wide, 0);
        for c in (1..chunks).rev() {
            self.spill.copy_within(c * old..c * old + old, c * wide);
        }
        self.wide = wide;
    }

    /// Slots per overflow chunk (more than any list holds).
    pub fn wide(&self) -> usize {
        self.wide
    }

    /// Total entries.
    pub fn entries(&self) -> usize {
        (0..self.len.len()).map(|i| self.length(i)).sum()
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        4 * (self.slots.capacity() + self.spill.capacity() + self.free.capacity())
            + self.len.capacity()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The slot search one slot at a time and in AVX2 lanes: the same bits for rows of one to
    /// eight groups, the number sought nowhere, once or in several slots, in every group.
    #[test]
    fn lanes_find_the_slots_one_by_one_finds() {
        if !Lanes::widest().avx2() {
            eprintln!("no AVX2 on this processor: the lanes are not compared");
            return;
        }
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(5);
        let mut found = 0;
        for _ in 0..5000 {
            let groups = rng.random_range(1..=64 / LANES);
            let row: Vec<u32> = (0..groups * LANES)
                .map(|_| rng.random_range(0..12))
                .collect();
            let j = rng.random_range(0..14);
            let one = holding(&row, j);
            #[cfg(target_arch = "x86_64")]
            // SAFETY: the processor has AVX2 (checked above).
            assert_eq!(unsafe { holding_in_lanes(&row, j) }, one, "{row:?} {j}");
            found += one.count_ones();
        }
        assert!(found > 5000, "too few found to compare: {found}");
    }

    /// Copies as a gather makes them, one after another into one buffer sized as
    /// [`Rows::copy_into`] asks: lists of every length up to a row wider than a group, and
    /// overflowing ones, come out whole and in order, each after the one before.
    #[test]
    fn copies_give_every_list_whole_and_in_order() {
        let room = GROUP + 4;
        let n = 3 * room;
        // List i holds i mod (room + 3) entries: empty, within a group, beyond a group in its
        // row, and (beyond its room) in the overflow area.
        let length = |i: usize| i % (room + 3);
        let mut rows = Rows::sized_for(n, |_| room);
        assert_eq!(rows.room(), room);
        for i in 0..n {
            for k in 0..length(i) {
                rows.push(i, (1000 * i + k) as u32);
            }
        }
        let mut out = vec![u32::MAX; n * (room + 3 + GROUP)];
        let mut at = 0;
        for i in 0..n {
            let l = rows.copy_into(i, &mut out, at);
            assert_eq!(l, length(i), "list {i}'s length");
            assert_eq!(&out[at..at + l], rows.of(i), "list {i}");
            at += l;
        }
        let want: Vec<u32> = (0..n).flat_map(|i| rows.of(i).to_vec()).collect();
        assert_eq!(&out[..at], &want[..], "the lists one after another");
    }
}
