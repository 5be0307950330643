//! Linked cells (the cell-list method): a dense grid whose cells hold any number of disks,
//! stored as one row with room per cell (not as a chain of links, whose walk waits on each
//! link and mispredicts each chain's end). The local re-mapping files its anchors here: its
//! shells are wider than a disk, so anchors may lie closer than EEPGM's one-per-cell grid
//! allows, and a cell at least as wide as the longest listed pair makes the 3 × 3 block around
//! a disk's cell hold every anchor it can list (the peer codes' cell list).

use super::grid::{GridGeometry, SeveralPerCell};
use super::rows::{Rows, GROUP};
use crate::platform::cpu::Lanes;

/// Disks by cell, several per cell: one list per cell, in [`Rows`] with room (about two disks
/// per cell on average, four slots per cell cover nearly all of them). Reading a cell copies
/// its row a group of slots at a time: no chain of links to follow (one dependent load and one
/// unpredictable loop exit per disk).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct LinkedCells {
    nx: usize,
    cells: Rows,
}

impl LinkedCells {
    #[inline(always)]
    fn index(&self, (ix, iy): (u32, u32)) -> usize {
        iy as usize * self.nx + ix as usize
    }

    /// Files `n` disks, disk i in cell `cell(i)` (a bounded grid), each cell's in increasing
    /// disk number.
    pub fn map(&mut self, geometry: &GridGeometry, n: usize, cell: impl Fn(usize) -> (u32, u32)) {
        let ny = geometry.ny.expect("linked cells need a bounded height") as usize;
        self.nx = geometry.nx as usize;
        let mut count = vec![0u32; self.nx * ny];
        for i in 0..n {
            count[self.index(cell(i))] += 1;
        }
        self.cells = Rows::default();
        self.cells = Rows::sized_for(count.len(), |c| count[c] as usize);
        drop(count);
        for i in 0..n {
            self.cells.push(self.index(cell(i)), i as u32);
        }
    }

    /// Puts disk `i` in cell `cell`.
    pub fn insert(&mut self, cell: (u32, u32), i: u32) {
        self.cells.push(self.index(cell), i);
    }

    /// Takes disk `i` out of cell `cell` (nothing if it is not there), searching the cell's
    /// row on the path `lanes`.
    pub fn remove(&mut self, cell: (u32, u32), i: u32, lanes: Lanes) {
        self.cells.remove(self.index(cell), i, lanes);
    }

    /// Writes to `out` from its start every disk in `cell` and in the cells at `offsets`
    /// around it (none farther than `reach` cells in x or y), and returns how many; `out` is
    /// scratch room (lengthened if it is too short for the copies' whole groups, never
    /// shortened).
    #[inline]
    pub fn gather_into(
        &self,
        geometry: &GridGeometry,
        offsets: &[(i32, i32)],
        reach: u32,
        cell: (u32, u32),
        out: &mut Vec<u32>,
    ) -> usize {
        // Each cell's row or overflowing list, and a group past it.
        let need = (offsets.len() + 1) * (self.cells.room().max(self.cells.wide()) + GROUP);
        if out.len() < need {
            out.resize(need, 0);
        }
        let mut n = self.cells.copy_into(self.index(cell), out, 0);
        let ny = geometry.ny.unwrap_or(0);
        let (ix, iy, h) = (cell.0, cell.1, reach);
        if ix >= h && ix + h < geometry.nx && iy >= h && iy + h < ny {
            // Away from the grid's edges no offset wraps nor leaves the grid: each cell is
            // a fixed step from the centre's.
            let centre = self.index(cell) as isize;
            for &(dx, dy) in offsets {
                let c = centre + dy as isize * self.nx as isize + dx as isize;
                n += self.cells.copy_into(c as usize, out, n);
            }
            return n;
        }
        for &(dx, dy) in offsets {
            if let Some(c) = geometry.offset(ix, iy, dx, dy) {
                n += self.cells.copy_into(self.index(c), out, n);
            }
        }
        n
    }

    /// Hints that the cells of a mask's `rows` (`(dy, dx_first, dx_last)`) around `cell` will
    /// be read soon: each row's first and last cell (the cells of a row are adjacent in memory).
    #[inline(always)]
    pub fn prefetch_rows(
        &self,
        geometry: &GridGeometry,
        rows: &[(i32, i32, i32)],
        cell: (u32, u32),
    ) {
        for &(dy, first, last) in rows {
            for dx in [first, last] {
                if let Some(c) = geometry.offset(cell.0, cell.1, dx, dy) {
                    self.cells.prefetch(self.index(c));
                }
            }
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.cells.bytes()
    }
}

impl SeveralPerCell for LinkedCells {
    #[inline(always)]
    fn each(&self, cell: (u32, u32), mut found: impl FnMut(u32)) {
        for &j in self.cells.of(self.index(cell)) {
            found(j);
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
        c.remove((0, 0), 1, Lanes::ONE_BY_ONE);
        c.insert((2, 2), 1);
        seen.clear();
        c.each((0, 0), |j| seen.push(j));
        assert_eq!(seen, [0, 3]);
        seen.clear();
        c.each((2, 2), |j| seen.push(j));
        assert_eq!(seen, [1]);
    }

    /// A cell fuller than its row's room (its list in the overflow area) and rows of every
    /// length: the group copies find what `each` finds, and nothing else.
    #[test]
    fn the_group_copies_find_every_disk_of_the_block() {
        // 10 × 6 cells, periodic in x: one list in fifty may overflow its row.
        let g = GridGeometry::with_cell_at_least(1.0, 10.0, true, 0.0, Some(6.0), false);
        // Cell (1, 1) holds nine disks, the others one or none: rows of room 1.
        let mut cells_of = vec![(1, 1); 9];
        cells_of.extend([(0, 0), (2, 2), (3, 1), (0, 2), (2, 0), (9, 1), (5, 5)]);
        let mut c = LinkedCells::default();
        c.map(&g, cells_of.len(), |i| cells_of[i]);
        assert_eq!(c.cells.room(), 1);
        let mask = super::super::Mask::circle("B1", 2);
        let mut scratch = Vec::new();
        let mut check = |c: &LinkedCells| {
            for iy in 0..6 {
                for ix in 0..10 {
                    let mut want = Vec::new();
                    c.gather_all(&g, &mask.offsets, (ix, iy), |j| want.push(j));
                    let n = c.gather_into(&g, &mask.offsets, 1, (ix, iy), &mut scratch);
                    let mut got = scratch[..n].to_vec();
                    // In the order of the mask's cells, the centre first, inside the grid and
                    // at its edges alike (the lists are built in this order).
                    let mut in_order = c.cells.of(c.index((ix, iy))).to_vec();
                    for &(dx, dy) in &mask.offsets {
                        if let Some(cell) = g.offset(ix, iy, dx, dy) {
                            in_order.extend_from_slice(c.cells.of(c.index(cell)));
                        }
                    }
                    assert_eq!(got, in_order, "the mask's order around ({ix}, {iy})");
                    want.sort_unstable();
                    got.sort_unstable();
                    assert_eq!(got, want, "around ({ix}, {iy})");
                }
            }
        };
        check(&c);
        // Moving disks in and out keeps it so (the full cell back into its row, another
        // overflowing).
        for i in 0..8 {
            let lanes = [Lanes::ONE_BY_ONE, Lanes::widest()][i as usize % 2];
            c.remove((1, 1), i, lanes);
            c.insert((3, 2), i);
        }
        check(&c);
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
