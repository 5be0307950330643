//! Neighbour lists: for each disk, the disks found in its mask at the last mapping, stored
//! compactly (one offset per disk, one flat array of disk numbers), or in rows with room when
//! single lists change (the local re-mapping).

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
    /// Room per disk when the lists are rows ([`in_rows`](Self::in_rows); 0: compressed rows):
    /// disk i's neighbours are then `slots[i·room .. i·room + len[i]]`, and single lists can
    /// change.
    room: usize,
    slots: Vec<u32>,
    len: Vec<u32>,
}

impl NeighbourLists {
    /// Rebuilds the lists of `n` disks from their candidate pairs: `half(i, out)` appends to
    /// `out` the candidates of disk i, each pair offered once (from one of its two disks, as a
    /// half mask does); those that `near(i, j)` accepts are filed in both disks' lists, so
    /// j ∈ list(i) ⇔ i ∈ list(j). The lists are compressed rows, fixed until the next build,
    /// unless [`in_rows`](Self::in_rows) asked for rows with room. Either way the half lists
    /// ([`half_of`](Self::half_of)) are kept until [`drop_half`](Self::drop_half).
    pub fn build(
        &mut self,
        n: usize,
        mut half: impl FnMut(usize, &mut Vec<u32>),
        near: impl Fn(usize, usize) -> bool,
    ) {
        self.half.clear();
        self.half_start.clear();
        self.half_start.push(0);
        // The half lists and each disk's degree first; then either layout.
        let mut degree = vec![0u32; n];
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
                degree[i] += 1;
                degree[j as usize] += 1;
            }
            self.half_start.push(self.half.len() as u32);
        }
        if self.room == 0 {
            self.compress(n, degree);
        } else {
            self.file_in_rows(n, self.room, degree);
        }
    }

    /// From the next [`build`](Self::build) on, each disk gets at least `room` slots (more if
    /// a disk has more neighbours, or once rows have widened), so that one disk's list can be
    /// rebuilt on its own with [`replace`](Self::replace).
    pub fn in_rows(&mut self, room: usize) {
        self.room = self.room.max(room).max(1);
    }

    /// Compressed rows from the half lists and the degrees.
    fn compress(&mut self, n: usize, degree: Vec<u32>) {
        self.slots = Vec::new();
        self.len = Vec::new();
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

    /// Rows of `room` slots (at least the largest degree) from the half lists, each row in the
    /// order compressed rows would have (so either layout examines pairs in the same order).
    fn file_in_rows(&mut self, n: usize, room: usize, degree: Vec<u32>) {
        let most = degree.iter().copied().max().unwrap_or(0) as usize;
        drop(degree);
        self.list = Vec::new();
        self.start = Vec::new();
        self.room = room.max(most);
        let room = self.room;
        self.slots.clear();
        self.slots.resize(n * room, 0);
        self.len.clear();
        self.len.resize(n, 0);
        for i in 0..n {
            for h in self.half_start[i] as usize..self.half_start[i + 1] as usize {
                let j = self.half[h] as usize;
                self.slots[i * room + self.len[i] as usize] = j as u32;
                self.len[i] += 1;
                self.slots[j * room + self.len[j] as usize] = i as u32;
                self.len[j] += 1;
            }
        }
        // Compressed rows are filled from the end.
        for i in 0..n {
            self.slots[i * room..i * room + self.len[i] as usize].reverse();
        }
    }

    /// Frees the half lists (they go stale once single lists change).
    pub fn drop_half(&mut self) {
        self.half = Vec::new();
        self.half_start = Vec::new();
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
        // In place (no second copy of the slots): the rows move up, the last one first.
        self.slots.reserve_exact(n * (room - old));
        self.slots.resize(n * room, 0);
        for i in (1..n).rev() {
            let l = self.len[i] as usize;
            self.slots.copy_within(i * old..i * old + l, i * room);
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Disks on a line, candidates the next three, near when less than 2.5 apart.
    fn line(lists: &mut NeighbourLists, x: &[f64], room: usize) {
        let n = x.len();
        if room > 0 {
            lists.in_rows(room);
        }
        let half =
            |i: usize, out: &mut Vec<u32>| out.extend((i + 1..n.min(i + 4)).map(|j| j as u32));
        lists.build(n, half, |i, j| (x[i] - x[j]).abs() < 2.5);
    }

    #[test]
    fn rows_with_room_list_pairs_in_the_order_of_compressed_rows() {
        let x = [0.0, 1.0, 1.5, 3.9, 4.2, 4.4, 9.0, 9.5];
        let (mut rows, mut compressed) = (NeighbourLists::default(), NeighbourLists::default());
        line(&mut rows, &x, 2);
        line(&mut compressed, &x, 0);
        assert_eq!(rows.room, 3, "room grows to the largest list");
        for i in 0..x.len() {
            assert_eq!(rows.of(i), compressed.of(i), "disk {i}");
            assert_eq!(rows.half_of(i), compressed.half_of(i), "disk {i}");
        }
        assert_eq!(rows.entries(), compressed.entries());
        rows.drop_half();
        assert_eq!(rows.of(4), compressed.of(4));
    }

    #[test]
    fn widening_in_place_keeps_every_list_and_their_symmetry() {
        let x = [0.0, 1.0, 1.5, 3.9, 4.2, 4.4, 9.0, 9.5];
        let mut lists = NeighbourLists::default();
        line(&mut lists, &x, 1);
        let before: Vec<Vec<u32>> = (0..x.len()).map(|i| lists.of(i).to_vec()).collect();
        // Disk 7 now sees everyone: rows must widen (several times) to hold it.
        let all: Vec<u32> = (0..7).collect();
        lists.replace(7, &all);
        assert!(lists.room >= 7);
        assert_eq!(lists.of(7), &all[..]);
        for (i, was) in before.iter().enumerate().take(7) {
            let mut want: Vec<u32> = was.iter().copied().filter(|&j| j != 7).collect();
            want.push(7);
            assert_eq!(lists.of(i), &want[..], "disk {i}");
        }
    }
}
