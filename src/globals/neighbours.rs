//! Neighbour lists: for each disk, the disks found in its mask at the last mapping, stored
//! compactly (one offset per disk, one flat array of disk numbers).

/// Neighbour lists in compressed-row form: disk i's neighbours are
/// `list[start[i + 1] .. start[i + 2]]` (the layout the in-place fill leaves behind).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct NeighbourLists {
    start: Vec<u32>,
    list: Vec<u32>,
    /// The pairs found (each once), as a half list: `half[half_start[i] .. half_start[i+1]]`
    /// are the partners j of disk i found from the half mask.
    half_start: Vec<u32>,
    half: Vec<u32>,
    /// Room per disk once the lists are [`fixed`](Self::fix) (0: compressed rows): disk i's
    /// neighbours are then `slots[i·room .. i·room + len[i]]`, and single lists can change.
    room: usize,
    slots: Vec<u32>,
    len: Vec<u32>,
}

impl NeighbourLists {
    /// Rebuilds the lists of `n` disks from their candidate pairs: `half(i, out)` appends to
    /// `out` the candidates of disk i, each pair offered once (from one of its two disks, as a
    /// half mask does); those that `near(i, j)` accepts are filed in both disks' lists, so
    /// j ∈ list(i) ⇔ i ∈ list(j).
    pub fn build(
        &mut self,
        n: usize,
        mut half: impl FnMut(usize, &mut Vec<u32>),
        near: impl Fn(usize, usize) -> bool,
    ) {
        self.room = 0;
        self.half.clear();
        self.half_start.clear();
        self.half_start.push(0);
        // Degrees go to start[i + 1], so that after the prefix sum start[i + 1] is the end of
        // i's range; decrementing it while filling leaves it at the range's beginning, and the
        // end is then start[i + 2] (start[n + 1] holds the total).
        self.start.clear();
        self.start.resize(n + 2, 0);
        for i in 0..n {
            let from = self.half.len();
            half(i, &mut self.half);
            // Kept without a branch per candidate (most are turned down, at random).
            let mut kept = from;
            for k in from..self.half.len() {
                let j = self.half[k];
                self.half[kept] = j;
                kept += near(i, j as usize) as usize;
            }
            self.half.truncate(kept);
            for &j in &self.half[from..] {
                self.start[i + 1] += 1;
                self.start[j as usize + 1] += 1;
            }
            self.half_start.push(self.half.len() as u32);
        }
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

    /// Each listed pair once: the partners of disk `i` found from the half mask.
    #[inline]
    pub fn half_of(&self, i: usize) -> &[u32] {
        &self.half[self.half_start[i] as usize..self.half_start[i + 1] as usize]
    }

    /// The neighbours of disk `i`.
    #[inline(always)]
    pub fn of(&self, i: usize) -> &[u32] {
        if self.room != 0 {
            let s = i * self.room;
            &self.slots[s..s + self.len[i] as usize]
        } else {
            &self.list[self.start[i + 1] as usize..self.start[i + 2] as usize]
        }
    }

    /// After a [`build`](Self::build): copies the lists into `room` slots per disk (more if a
    /// disk has more neighbours), so that one disk's list can be rebuilt on its own with
    /// [`replace`](Self::replace). The half lists are dropped (they would go stale).
    pub fn fix(&mut self, n: usize, room: usize) {
        let most = (0..n)
            .map(|i| (self.start[i + 2] - self.start[i + 1]) as usize)
            .max()
            .unwrap_or(0);
        self.room = room.max(most).max(1);
        self.slots.clear();
        self.slots.resize(n * self.room, 0);
        self.len.clear();
        self.len.resize(n, 0);
        for i in 0..n {
            let row = &self.list[self.start[i + 1] as usize..self.start[i + 2] as usize];
            self.slots[i * self.room..i * self.room + row.len()].copy_from_slice(row);
            self.len[i] = row.len() as u32;
        }
        self.list = Vec::new();
        self.start = Vec::new();
        self.half = Vec::new();
        self.half_start = Vec::new();
    }

    /// Makes `new` disk `i`'s list (fixed lists only), keeping the lists symmetric: `i` leaves
    /// the lists of all its old neighbours and joins those of all its new ones (cheaper than
    /// sorting out which stay, for lists of a dozen).
    pub fn replace(&mut self, i: usize, new: &[u32]) {
        let room = self.room;
        for k in 0..self.len[i] as usize {
            let j = self.slots[i * room + k] as usize;
            let row = j * room;
            let last = row + self.len[j] as usize - 1;
            if let Some(e) = (row..=last).find(|&e| self.slots[e] == i as u32) {
                self.slots[e] = self.slots[last];
                self.len[j] -= 1;
            }
        }
        self.len[i] = 0;
        while new.len() > self.room
            || new
                .iter()
                .any(|&j| self.len[j as usize] as usize == self.room)
        {
            self.widen();
        }
        let room = self.room;
        for &j in new {
            let j = j as usize;
            self.slots[j * room + self.len[j] as usize] = i as u32;
            self.len[j] += 1;
        }
        self.slots[i * room..i * room + new.len()].copy_from_slice(new);
        self.len[i] = new.len() as u32;
    }

    /// Gives every list a quarter more room (at least one slot).
    fn widen(&mut self) {
        let (old, room) = (self.room, self.room + (self.room / 4).max(1));
        let n = self.len.len();
        let mut slots = vec![0; n * room];
        for i in 0..n {
            let l = self.len[i] as usize;
            slots[i * room..i * room + l].copy_from_slice(&self.slots[i * old..i * old + l]);
        }
        self.slots = slots;
        self.room = room;
    }

    /// Total entries (twice the number of listed pairs).
    pub fn entries(&self) -> usize {
        if self.room != 0 {
            self.len.iter().map(|&l| l as usize).sum()
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
            + self.len.capacity())
    }
}
