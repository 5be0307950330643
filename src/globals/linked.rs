//! Linked cells: a dense grid whose cells hold any number of disks, as a head per cell and a
//! link per disk. The local re-mapping files its anchors here: its shells are wider than a
//! disk, so anchors may lie closer than EEPGM's one-per-cell grid allows, and a cell at least
//! as wide as the longest listed pair makes the 3 × 3 block around a disk's cell hold every
//! anchor it can list (the peer codes' cell list).

use super::grid::{GridGeometry, SeveralPerCell};

/// End of a cell's chain (and an empty cell).
const END: u32 = u32::MAX;

/// Disks by cell, several per cell: `head[c]` is the first disk of cell `c`, `next[i]` the one
/// after disk `i`, `END` (`u32::MAX`) closes a chain.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct LinkedCells {
    nx: usize,
    head: Vec<u32>,
    next: Vec<u32>,
}

impl LinkedCells {
    #[inline(always)]
    fn index(&self, (ix, iy): (u32, u32)) -> usize {
        iy as usize * self.nx + ix as usize
    }

    /// Files `n` disks, disk i in cell `cell(i)` (a bounded grid).
    pub fn map(&mut self, geometry: &GridGeometry, n: usize, cell: impl Fn(usize) -> (u32, u32)) {
        let ny = geometry.ny.expect("linked cells need a bounded height") as usize;
        self.nx = geometry.nx as usize;
        self.head.clear();
        self.head.resize(self.nx * ny, END);
        self.next.clear();
        self.next.resize(n, END);
        // Filed from the last disk down, so that each chain runs in increasing disk number.
        for i in (0..n).rev() {
            let c = self.index(cell(i));
            self.next[i] = self.head[c];
            self.head[c] = i as u32;
        }
    }

    /// Puts disk `i` in cell `cell`.
    pub fn insert(&mut self, cell: (u32, u32), i: u32) {
        let c = self.index(cell);
        self.next[i as usize] = self.head[c];
        self.head[c] = i;
    }

    /// Takes disk `i` out of cell `cell` (nothing if it is not there).
    pub fn remove(&mut self, cell: (u32, u32), i: u32) {
        let c = self.index(cell);
        if self.head[c] == i {
            self.head[c] = self.next[i as usize];
            return;
        }
        let mut k = self.head[c];
        while k != END {
            let after = self.next[k as usize];
            if after == i {
                self.next[k as usize] = self.next[i as usize];
                return;
            }
            k = after;
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        4 * (self.head.capacity() + self.next.capacity())
    }
}

impl SeveralPerCell for LinkedCells {
    #[inline(always)]
    fn each(&self, cell: (u32, u32), mut found: impl FnMut(u32)) {
        let mut k = self.head[self.index(cell)];
        while k != END {
            found(k);
            k = self.next[k as usize];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geometry() -> GridGeometry {
        GridGeometry::with_cell_at_least(1.0, 4.0, true, 0.0, Some(3.0), false)
    }

    #[test]
    fn cells_hold_several_disks_and_let_them_go() {
        let g = geometry();
        let cells_of = [(0, 0), (0, 0), (3, 2), (0, 0), (1, 1)];
        let mut c = LinkedCells::default();
        c.map(&g, cells_of.len(), |i| cells_of[i]);
        let mut seen = Vec::new();
        c.each((0, 0), |j| seen.push(j));
        assert_eq!(seen, [0, 1, 3]);
        c.remove((0, 0), 1);
        c.insert((2, 2), 1);
        seen.clear();
        c.each((0, 0), |j| seen.push(j));
        assert_eq!(seen, [0, 3]);
        seen.clear();
        c.each((2, 2), |j| seen.push(j));
        assert_eq!(seen, [1]);
    }

    #[test]
    fn the_half_scan_finds_each_pair_once() {
        // 4 × 3 cells, periodic in x only; every disk within the 3 × 3 block of another.
        let g = geometry();
        let cells_of = [(0, 0), (0, 0), (3, 0), (1, 1), (2, 2), (3, 1), (0, 2)];
        let n = cells_of.len();
        let mut c = LinkedCells::default();
        c.map(&g, n, |i| cells_of[i]);
        let mask = super::super::Mask::circle("B1", 2);
        let mut half = Vec::new();
        for (i, &cell) in cells_of.iter().enumerate() {
            c.gather_half_of(&g, &mask.half, i as u32, cell, |j| {
                half.push((i.min(j as usize), i.max(j as usize)))
            });
        }
        let mut full = Vec::new();
        for (i, &cell) in cells_of.iter().enumerate() {
            c.gather_all(&g, &mask.offsets, cell, |j| {
                if j as usize > i {
                    full.push((i, j as usize))
                }
            });
        }
        let before = half.len();
        half.sort_unstable();
        half.dedup();
        assert_eq!(half.len(), before, "a pair found twice");
        full.sort_unstable();
        assert_eq!(half, full);
    }
}
