//! Neighbour lists: for each disk, the disks found in its mask at the last mapping, stored
//! compactly (one offset per disk, one flat array of disk numbers), or in [`Rows`] with room
//! when single lists change (the local re-mapping).

use super::rows::Rows;
use crate::platform::cpu::Lanes;

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
    in_rows: bool,
    /// Rows with room keep the half lists of their build until
    /// [`drop_halves`](Self::drop_halves) (see [`in_rows`](Self::in_rows)).
    #[serde(skip)]
    rows_keep_halves: bool,
    rows: Rows,
}

impl NeighbourLists {
    /// Rebuilds the lists of `n` disks from their candidate pairs: `half(i, out)` appends to
    /// `out` the candidates of disk i, each pair offered once (from one of its two disks, as a
    /// half mask does); those that `near(i, j)` accepts are filed in both disks' lists, so
    /// j ∈ list(i) ⇔ i ∈ list(j). The lists are compressed rows, fixed until the next build,
    /// and the half lists ([`half_of`](Self::half_of)) are kept (their memory too, for the next
    /// build); or, if [`in_rows`](Self::in_rows) asked for them, rows
    /// with room, filed from the candidates (half lists only if asked for too: their memory
    /// adds to the rows' at the peak).
    pub fn build(
        &mut self,
        n: usize,
        half: impl FnMut(usize, &mut Vec<u32>),
        near: impl Fn(usize, usize) -> bool,
    ) {
        self.half.clear();
        self.half_start.clear();
        if self.in_rows && self.rows_keep_halves {
            let degree = self.half_lists(n, half, near);
            self.file_halves_in_rows(n, degree);
            return;
        }
        if self.in_rows {
            self.half = Vec::new();
            self.half_start = Vec::new();
            self.file_in_rows(n, half, near);
            return;
        }
        // The half lists and each disk's degree first; then the compressed rows.
        let degree = self.half_lists(n, half, near);
        self.compress(n, degree);
    }

    /// The half lists (`half`, `half_start`) from the candidates, and each disk's degree.
    fn half_lists(
        &mut self,
        n: usize,
        mut half: impl FnMut(usize, &mut Vec<u32>),
        near: impl Fn(usize, usize) -> bool,
    ) -> Vec<u32> {
        self.half_start.push(0);
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
        degree
    }

    /// Rows with room filed from the half lists and the degrees, as
    /// [`file_in_rows`](Self::file_in_rows) files them from the candidates.
    fn file_halves_in_rows(&mut self, n: usize, degree: Vec<u32>) {
        self.list = Vec::new();
        self.start = Vec::new();
        self.rows = Rows::default();
        // Degrees counted to 2¹⁶ − 1 at most, as `file_in_rows` counts them.
        self.rows = Rows::sized_for(n, |i| degree[i].min(u16::MAX as u32) as usize);
        drop(degree);
        for i in 0..n {
            for h in self.half_start[i] as usize..self.half_start[i + 1] as usize {
                let j = self.half[h];
                self.rows.push(i, j);
                self.rows.push(j as usize, i as u32);
            }
        }
        // Compressed rows are filled from the end.
        for i in 0..n {
            self.rows.of_mut(i).reverse();
        }
    }

    /// From the next [`build`](Self::build) on, the lists are rows with room, so that one
    /// disk's list can be rebuilt on its own with [`replace`](Self::replace); each build keeps
    /// the half lists it found if `keep_halves` (for the caller's use of
    /// [`half_of`](Self::half_of), until [`drop_halves`](Self::drop_halves)), so that the
    /// candidates are gathered once instead of again for each use.
    pub fn in_rows(&mut self, keep_halves: bool) {
        self.in_rows = true;
        self.rows_keep_halves = keep_halves;
    }

    /// Frees the half lists of rows with room (compressed rows keep theirs).
    pub fn drop_halves(&mut self) {
        if self.in_rows {
            self.half = Vec::new();
            self.half_start = Vec::new();
        }
    }

    /// Compressed rows from the half lists and the degrees.
    fn compress(&mut self, n: usize, degree: Vec<u32>) {
        self.rows = Rows::default();
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
        // Fresh rows (the old ones freed first, if `release` has not): every list is filed
        // anew, and growing them in place could hold the old rows and the new at once.
        self.rows = Rows::default();
        self.rows = Rows::sized_for(n, |i| degree[i] as usize);
        drop(degree);
        for i in 0..n {
            found.clear();
            half(i, &mut found);
            let kept = keep_near(&mut found, 0, |j| near(i, j));
            for &j in &found[..kept] {
                self.rows.push(i, j);
                self.rows.push(j as usize, i as u32);
            }
        }
        // Compressed rows are filled from the end.
        for i in 0..n {
            self.rows.of_mut(i).reverse();
        }
    }

    /// Frees every list (rows only: the next [`build`](Self::build) files each anew), so that a
    /// re-mapping's renumbering and build do not hold the old lists beside their own arrays.
    /// Compressed rows keep their memory for the next build (they are rebuilt at every one
    /// of Isobe's frequent re-mappings).
    pub fn release(&mut self) {
        if self.in_rows {
            self.rows = Rows::default();
        }
    }

    /// Each listed pair once: the partners of disk `i` found from the half mask, for
    /// compressed rows and for rows with room built to keep them (`None` for other rows with
    /// room, and after [`drop_halves`](Self::drop_halves)).
    #[inline]
    pub fn half_of(&self, i: usize) -> Option<&[u32]> {
        (!self.half_start.is_empty())
            .then(|| &self.half[self.half_start[i] as usize..self.half_start[i + 1] as usize])
    }

    /// The neighbours of disk `i`.
    #[inline(always)]
    pub fn of(&self, i: usize) -> &[u32] {
        if !self.in_rows {
            return &self.list[self.start[i + 1] as usize..self.start[i + 2] as usize];
        }
        self.rows.of(i)
    }

    /// Hints that disk `i`'s list will be read soon: its row, or the first and last lines of
    /// its stretch of the compressed lists (read from its bounds, which may themselves miss).
    #[inline]
    pub fn prefetch_list(&self, i: usize) {
        if self.in_rows {
            self.rows.prefetch(i);
        } else if let (Some(&a), Some(&b)) = (self.start.get(i + 1), self.start.get(i + 2)) {
            crate::platform::prefetch::prefetch(&self.list, a as usize);
            crate::platform::prefetch::prefetch(&self.list, (b as usize).saturating_sub(1));
        }
    }

    /// Hints that the lists of disk `i`'s neighbours will change soon (rows only): `i`
    /// leaves them at [`replace`](Self::replace).
    #[inline]
    pub fn prefetch_neighbours(&self, i: usize) {
        if self.in_rows {
            for &j in self.rows.of(i) {
                self.rows.prefetch(j as usize);
            }
        }
    }

    /// Makes `new` disk `i`'s list (rows only), keeping the lists symmetric: `i` leaves the
    /// lists of all its old neighbours and joins those of all its new ones (cheaper than
    /// sorting out which stay, for lists of a dozen). Rows are searched on the path `lanes`.
    pub fn replace(&mut self, i: usize, new: &[u32], lanes: Lanes) {
        self.rows.leave_all(i, lanes);
        self.rows.clear(i);
        for &j in new {
            self.rows.push(j as usize, i as u32);
        }
        self.rows.set(i, new);
    }

    /// Total entries (twice the number of listed pairs).
    pub fn entries(&self) -> usize {
        if self.in_rows {
            self.rows.entries()
        } else {
            self.list.len()
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        4 * (self.start.capacity()
            + self.list.capacity()
            + self.half_start.capacity()
            + self.half.capacity())
            + self.rows.bytes()
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
            lists.in_rows(false);
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
        assert_eq!(
            rows.rows.room(),
            3,
            "so few lists: rows as wide as the longest"
        );
        for i in 0..x.len() {
            assert_eq!(rows.of(i), compressed.of(i), "disk {i}");
            assert!(rows.half_of(i).is_none(), "rows keep no half lists");
            assert!(compressed.half_of(i).is_some());
        }
        assert_eq!(rows.entries(), compressed.entries());
    }

    /// Rows with room that keep their half lists: the same rows as without, and the half lists
    /// of compressed rows, until dropped.
    #[test]
    fn rows_keep_the_half_lists_of_compressed_rows_until_dropped() {
        let x: [f64; 10] = [0.0, 1.0, 1.5, 3.9, 4.2, 4.4, 9.0, 9.5, 9.7, 9.8];
        let (mut kept, mut rows, mut compressed) = Default::default();
        let build = |lists: &mut NeighbourLists| {
            let n = x.len();
            let half =
                |i: usize, out: &mut Vec<u32>| out.extend((i + 1..n.min(i + 4)).map(|j| j as u32));
            lists.build(n, half, |i, j| (x[i] - x[j]).abs() < 2.5);
        };
        NeighbourLists::in_rows(&mut kept, true);
        NeighbourLists::in_rows(&mut rows, false);
        for lists in [&mut kept, &mut rows, &mut compressed] {
            build(lists);
        }
        let (kept, rows, compressed): (NeighbourLists, NeighbourLists, NeighbourLists) =
            (kept, rows, compressed);
        let mut pairs = 0;
        for i in 0..x.len() {
            assert_eq!(kept.of(i), rows.of(i), "disk {i}");
            assert_eq!(kept.half_of(i), compressed.half_of(i), "disk {i}");
            pairs += kept.half_of(i).map_or(0, <[u32]>::len);
        }
        assert!(pairs > x.len() / 2, "too few pairs to compare");
        assert_eq!(kept.rows.room(), rows.rows.room());
        let mut kept = kept;
        kept.drop_halves();
        assert!((0..x.len()).all(|i| kept.half_of(i).is_none()));
        assert_eq!(
            kept.of(3),
            rows.of(3),
            "dropping the half lists keeps the rows"
        );
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
        assert!(
            rows.rows.room() < most,
            "rows narrower than the longest list"
        );
        assert!(
            (0..n)
                .filter(|&i| rows.of(i).len() > rows.rows.room())
                .count()
                <= n / 50,
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
            // Either path, by turns: each must keep the lists as the plain ones.
            rows.replace(i, &new, [Lanes::ONE_BY_ONE, Lanes::widest()][step % 2]);
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
            rows.rows.wide() > most,
            "overflow chunks widened for the longest lists"
        );
        assert_eq!(rows.entries(), plain.iter().map(Vec::len).sum::<usize>());
    }
}
