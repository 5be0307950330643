//! Neighbour lists: for each disk, the disks found in its mask at the last mapping, stored
//! compactly (one offset per disk, one flat array of disk numbers), or in rows with room when
//! single lists change (the local re-mapping): rows wide enough for all but the longest
//! lists, which move whole into wider chunks of an overflow area while they are long.

/// Moves the entries `j` of `v[from..]` that `near(j)` accepts to the front of that range, in
/// order, and returns where they end: without a branch per candidate (most are turned down, at
/// random).
#[inline]
fn keep_near(v: &mut [u32], from: usize, near: impl Fn(usize) -> bool) -> usize {
    let mut kept = from;
    for k in from..v.len() {
        let j = v[k];
        v[kept] = j;
        kept += near(j as usize) as usize;
    }
    kept
}

/// `len` of a list in the overflow area.
const SPILLED: u8 = u8::MAX;

/// Neighbour lists, in compressed-row form (disk i's neighbours are
/// `list[start[i + 1] .. start[i + 2]]`, the layout the in-place fill leaves behind) or, for
/// the local re-mapping, in rows with room (see [`in_rows`](Self::in_rows)).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct NeighbourLists {
    start: Vec<u32>,
    list: Vec<u32>,
    /// The pairs found (each once), as a half list: `half[half_start[i] .. half_start[i+1]]`
    /// are the partners j of disk i found from the half mask.
    half_start: Vec<u32>,
    half: Vec<u32>,
    /// Rows with room ([`in_rows`](Self::in_rows); `false`: compressed rows), so that single
    /// lists can change.
    rows: bool,
    /// Slots per row (at most 254): disk i's neighbours are `slots[i·room .. i·room + len[i]]`
    /// while they fit; a longer list (`len[i] = SPILLED`) lives whole in chunk
    /// `c = slots[i·room]` of the overflow area, its length in `spill[c·wide]` and its entries
    /// after it. Set at each build so that about one list in fifty overflows (rows sized for
    /// the longest list would spend half their memory on room few lists use).
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

impl NeighbourLists {
    /// Rebuilds the lists of `n` disks from their candidate pairs: `half(i, out)` appends to
    /// `out` the candidates of disk i, each pair offered once (from one of its two disks, as a
    /// half mask does); those that `near(i, j)` accepts are filed in both disks' lists, so
    /// j ∈ list(i) ⇔ i ∈ list(j). The lists are compressed rows, fixed until the next build,
    /// and the half lists ([`half_of`](Self::half_of)) are kept (their memory too, for the next
    /// build); or, if [`in_rows`](Self::in_rows) asked for them, rows
    /// with room, filed straight from the candidates (no half lists: their memory would add to
    /// the rows' at the peak).
    pub fn build(
        &mut self,
        n: usize,
        mut half: impl FnMut(usize, &mut Vec<u32>),
        near: impl Fn(usize, usize) -> bool,
    ) {
        self.half.clear();
        self.half_start.clear();
        if self.rows {
            self.half = Vec::new();
            self.half_start = Vec::new();
            self.file_in_rows(n, half, near);
            return;
        }
        self.half_start.push(0);
        // The half lists and each disk's degree first; then the compressed rows.
        let mut degree = vec![0u32; n];
        for i in 0..n {
            let from = self.half.len();
            half(i, &mut self.half);
            let kept = keep_near(&mut self.half, from, |j| near(i, j));
            self.half.truncate(kept);
            for &j in &self.half[from..] {
                degree[i] += 1;
                degree[j as usize] += 1;
            }
            self.half_start.push(self.half.len() as u32);
        }
        self.compress(n, degree);
    }

    /// From the next [`build`](Self::build) on, the lists are rows with room, so that one
    /// disk's list can be rebuilt on its own with [`replace`](Self::replace).
    pub fn in_rows(&mut self) {
        self.rows = true;
    }

    /// Compressed rows from the half lists and the degrees.
    fn compress(&mut self, n: usize, degree: Vec<u32>) {
        self.slots = Vec::new();
        self.len = Vec::new();
        self.spill = Vec::new();
        self.free = Vec::new();
        // Degrees go to start[i + 1], so that after the prefix sum start[i + 1] is the end of
        // i's range; decrementing it while filling leaves it at the range's beginning, and the
        // end is then start[i + 2] (start[n + 1] holds the total).
        self.start.clear();
        self.start.resize(n + 2, 0);
        self.start[1..=n].copy_from_slice(&degree);
        drop(degree);
        for k in 1..=n {
            self.start[k] += self.start[k - 1];
        }
        self.start[n + 1] = self.start[n];
        self.list.clear();
        self.list.resize(self.start[n + 1] as usize, 0);
        for i in 0..n {
            for h in self.half_start[i] as usize..self.half_start[i + 1] as usize {
                let j = self.half[h] as usize;
                self.start[i + 1] -= 1;
                self.list[self.start[i + 1] as usize] = j as u32;
                self.start[j + 1] -= 1;
                self.list[self.start[j + 1] as usize] = i as u32;
            }
        }
    }

    /// Rows filed straight from the candidates, each list in the order compressed rows would
    /// have (so either layout examines pairs in the same order). A first pass counts each
    /// disk's neighbours to size the rows: `room` leaves one list in fifty (or fewer) to the
    /// overflow area.
    fn file_in_rows(
        &mut self,
        n: usize,
        mut half: impl FnMut(usize, &mut Vec<u32>),
        near: impl Fn(usize, usize) -> bool,
    ) {
        self.list = Vec::new();
        self.start = Vec::new();
        let mut found = Vec::new();
        let mut degree = vec![0u16; n];
        for i in 0..n {
            found.clear();
            half(i, &mut found);
            let kept = keep_near(&mut found, 0, |j| near(i, j));
            for &j in &found[..kept] {
                degree[i] = degree[i].saturating_add(1);
                degree[j as usize] = degree[j as usize].saturating_add(1);
            }
        }
        let most = degree.iter().copied().max().unwrap_or(0) as usize;
        let mut count = vec![0usize; most + 1];
        for &d in &degree {
            count[d as usize] += 1;
        }
        drop(degree);
        // The smallest room that leaves at most n/50 lists longer.
        let (mut room, mut longer) = (most, 0);
        while room > 1 && longer + count[room] <= n / 50 {
            longer += count[room];
            room -= 1;
        }
        self.room = room.clamp(1, SPILLED as usize - 1);
        self.wide = (most + 1).max(self.room + 2);
        // Fresh rows (the old ones freed first, if `release` has not): every list is filed
        // anew, and growing them in place could hold the old rows and the new at once.
        self.slots = Vec::new();
        self.slots = vec![0; n * self.room];
        self.len.clear();
        self.len.resize(n, 0);
        self.spill = Vec::new();
        self.free.clear();
        for i in 0..n {
            found.clear();
            half(i, &mut found);
            let kept = keep_near(&mut found, 0, |j| near(i, j));
            for &j in &found[..kept] {
                self.push(i, j);
                self.push(j as usize, i as u32);
            }
        }
        // Compressed rows are filled from the end.
        for i in 0..n {
            self.list_mut(i).reverse();
        }
    }

    /// Disk `i`'s list in the overflow area.
    #[cold]
    #[inline(never)]
    fn spilled(&self, i: usize) -> &[u32] {
        let c = self.slots[i * self.room] as usize * self.wide;
        let l = self.spill[c] as usize;
        &self.spill[c + 1..c + 1 + l]
    }

    /// The length of disk `i`'s list.
    #[inline]
    fn length(&self, i: usize) -> usize {
        match self.len[i] {
            SPILLED => self.spill[self.slots[i * self.room] as usize * self.wide] as usize,
            l => l as usize,
        }
    }

    /// Disk `i`'s list, to change in place.
    #[inline]
    fn list_mut(&mut self, i: usize) -> &mut [u32] {
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

    /// Appends `j` to disk `i`'s list, moving the list to the overflow area when its row is
    /// full (and widening the overflow chunks when its chunk is).
    #[inline(always)]
    fn push(&mut self, i: usize, j: u32) {
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

    /// Removes `j` from disk `i`'s list (the last entry takes its place), moving the list back
    /// into its row once it fits.
    #[inline(always)]
    fn remove(&mut self, i: usize, j: u32) {
        let l = self.len[i];
        if l == SPILLED {
            self.remove_long(i, j);
            return;
        }
        let s = i * self.room;
        let row = &mut self.slots[s..s + l as usize];
        if let Some(e) = row.iter().position(|&k| k == j) {
            row[e] = row[l as usize - 1];
            self.len[i] = l - 1;
        }
    }

    /// [`remove`](Self::remove) from an overflowing list.
    #[cold]
    #[inline(never)]
    fn remove_long(&mut self, i: usize, j: u32) {
        let list = self.list_mut(i);
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

    /// Moves disk `i`'s list of `l ≤ room` entries from its overflow chunk back to its row.
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

    /// Frees every list (rows only: the next [`build`](Self::build) files each anew), so that a
    /// re-mapping's renumbering and build do not hold the old lists beside their own arrays.
    /// Compressed rows keep their memory for the next build (they are rebuilt at every one
    /// of Isobe's frequent re-mappings).
    pub fn release(&mut self) {
        if self.rows {
            self.slots = Vec::new();
            self.len = Vec::new();
            self.spill = Vec::new();
            self.free = Vec::new();
        }
    }

    /// Each listed pair once: the partners of disk `i` found from the half mask, for
    /// compressed rows (`None` for rows with room, which keep no half lists).
    #[inline]
    pub fn half_of(&self, i: usize) -> Option<&[u32]> {
        (!self.half_start.is_empty())
            .then(|| &self.half[self.half_start[i] as usize..self.half_start[i + 1] as usize])
    }

    /// The neighbours of disk `i`.
    #[inline(always)]
    pub fn of(&self, i: usize) -> &[u32] {
        if !self.rows {
            return &self.list[self.start[i + 1] as usize..self.start[i + 2] as usize];
        }
        let (s, l) = (i * self.room, self.len[i]);
        if l != SPILLED {
            &self.slots[s..s + l as usize]
        } else {
            self.spilled(i)
        }
    }

    /// Makes `new` disk `i`'s list (rows only), keeping the lists symmetric: `i` leaves the
    /// lists of all its old neighbours and joins those of all its new ones (cheaper than
    /// sorting out which stay, for lists of a dozen).
    pub fn replace(&mut self, i: usize, new: &[u32]) {
        let (s, l) = (i * self.room, self.len[i]);
        if l != SPILLED {
            for k in 0..l as usize {
                let j = self.slots[s + k];
                self.remove(j as usize, i as u32);
            }
        } else {
            for k in 0..self.length(i) {
                let j = self.of(i)[k];
                self.remove(j as usize, i as u32);
            }
            self.unspill(i, 0);
        }
        self.len[i] = 0;
        for &j in new {
            self.push(j as usize, i as u32);
        }
        if new.len() <= self.room {
            self.slots[s..s + new.len()].copy_from_slice(new);
            self.len[i] = new.len() as u8;
        } else {
            for &j in new {
                self.push(i, j);
            }
        }
    }

    /// Total entries (twice the number of listed pairs).
    pub fn entries(&self) -> usize {
        if self.rows {
            (0..self.len.len()).map(|i| self.length(i)).sum()
        } else {
            self.list.len()
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        4 * (self.start.capacity()
            + self.list.capacity()
            + self.half_start.capacity()
            + self.half.capacity()
            + self.slots.capacity()
            + self.spill.capacity()
            + self.free.capacity())
            + self.len.capacity()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Disks on a line, candidates the next `ahead`, near when less than `reach` apart.
    fn line(lists: &mut NeighbourLists, x: &[f64], rows: bool, ahead: usize, reach: f64) {
        let n = x.len();
        if rows {
            lists.in_rows();
        }
        let half = |i: usize, out: &mut Vec<u32>| {
            out.extend((i + 1..n.min(i + 1 + ahead)).map(|j| j as u32))
        };
        lists.build(n, half, |i, j| (x[i] - x[j]).abs() < reach);
    }

    #[test]
    fn rows_with_room_list_pairs_in_the_order_of_compressed_rows() {
        let x = [0.0, 1.0, 1.5, 3.9, 4.2, 4.4, 9.0, 9.5];
        let (mut rows, mut compressed) = (NeighbourLists::default(), NeighbourLists::default());
        line(&mut rows, &x, true, 3, 2.5);
        line(&mut compressed, &x, false, 3, 2.5);
        assert_eq!(rows.room, 3, "so few lists: rows as wide as the longest");
        for i in 0..x.len() {
            assert_eq!(rows.of(i), compressed.of(i), "disk {i}");
            assert!(rows.half_of(i).is_none(), "rows keep no half lists");
            assert!(compressed.half_of(i).is_some());
        }
        assert_eq!(rows.entries(), compressed.entries());
    }

    /// Rows sized for all but one list in fifty, the longer ones in the overflow area: the
    /// same lists as compressed rows, and through many single-list changes (lists moving into
    /// the overflow area and back, chunks widening) the same lists as plain vectors changed the
    /// same way.
    #[test]
    fn long_lists_overflow_and_come_back_as_plain_lists_would() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
        let n = 400;
        let x: Vec<f64> = (0..n).map(|_| rng.random::<f64>() * 100.0).collect();
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
        let x: Vec<f64> = order.iter().map(|&k| x[k]).collect();
        let (mut rows, mut compressed) = (NeighbourLists::default(), NeighbourLists::default());
        line(&mut rows, &x, true, 30, 1.5);
        line(&mut compressed, &x, false, 30, 1.5);
        let most = (0..n).map(|i| compressed.of(i).len()).max().unwrap();
        assert!(rows.room < most, "rows narrower than the longest list");
        assert!(
            (0..n).filter(|&i| rows.of(i).len() > rows.room).count() <= n / 50,
            "at most one list in fifty overflows"
        );
        let mut plain: Vec<Vec<u32>> = (0..n).map(|i| compressed.of(i).to_vec()).collect();
        for (i, list) in plain.iter().enumerate() {
            assert_eq!(rows.of(i), &list[..], "disk {i} after the build");
        }
        for step in 0..3000 {
            let i = rng.random_range(0..n);
            let size = rng.random_range(0..(if step % 10 == 0 { 3 * most } else { most }));
            let mut new: Vec<u32> = Vec::new();
            while new.len() < size {
                let j = rng.random_range(0..n) as u32;
                if j as usize != i && !new.contains(&j) {
                    new.push(j);
                }
            }
            rows.replace(i, &new);
            for j in std::mem::take(&mut plain[i]) {
                let l = &mut plain[j as usize];
                let e = l.iter().position(|&k| k == i as u32).unwrap();
                l.swap_remove(e);
            }
            for &j in &new {
                plain[j as usize].push(i as u32);
            }
            plain[i] = new;
            for (k, list) in plain.iter().enumerate() {
                assert_eq!(rows.of(k), &list[..], "disk {k} after step {step}");
            }
        }
        assert!(
            rows.wide > most,
            "overflow chunks widened for the longest lists"
        );
        assert_eq!(rows.entries(), plain.iter().map(Vec::len).sum::<usize>());
    }
}
