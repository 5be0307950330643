//! Who can meet whom: structures over all disks — the EEPGM grid, Isobe's
//! masks, and the neighbour lists taken from the mask at each mapping.

pub mod grid;
pub mod linked;
pub mod lists;
pub mod masks;
pub mod rows;

pub use grid::{CellMap, DenseCells, GridGeometry, SeveralPerCell, SparseCells};
pub use linked::LinkedCells;
pub use lists::NeighbourLists;
pub use masks::Mask;

use crate::error::Result;
use crate::platform::cpu::Lanes;

/// The grid storage a scene uses: dense for closed domains, Isobe's compressed array for an
/// open top; linked cells (several disks per cell) for the local re-mapping's anchors.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub enum Cells {
    /// One slot per cell.
    Dense(DenseCells),
    /// Occupied cells only (open top); several disks per cell for the local re-mapping.
    Sparse(SparseCells),
    /// Several disks per cell, a head per cell (closed domains, local re-mapping).
    Linked(LinkedCells),
}

impl Cells {
    /// The storage for `geometry` and `mask`: dense when the height is bounded (unless
    /// `hashed` is asked for), Isobe's compressed array otherwise. `anchors`: the local
    /// re-mapping's cells, which hold several anchors each (linked cells where dense).
    pub fn for_geometry(
        geometry: &GridGeometry,
        mask: &Mask,
        hashed: bool,
        anchors: bool,
    ) -> Cells {
        match (geometry.ny.is_some() && !hashed, anchors) {
            (true, false) => Cells::Dense(DenseCells::with_pad(mask.half_width as u32)),
            (true, true) => Cells::Linked(LinkedCells::default()),
            (false, false) => Cells::Sparse(SparseCells::with_window(mask.half_width as u32)),
            (false, true) => Cells::Sparse(SparseCells::for_anchors()),
        }
    }

    /// Moves disk `i` from cell `from` to cell `to`; `Ok(false)` if `to`'s storage is full
    /// (then `i` is in no cell: the caller re-maps). Linked cells search `from`'s row on the
    /// path `lanes`.
    pub fn relocate(
        &mut self,
        geometry: &GridGeometry,
        from: (u32, u32),
        to: (u32, u32),
        i: u32,
        lanes: Lanes,
    ) -> Result<bool> {
        match self {
            Cells::Dense(d) => {
                d.remove(geometry, from, i);
                d.insert(geometry, to, i)
            }
            Cells::Sparse(s) => {
                s.remove(geometry, from, i);
                s.insert(geometry, to, i)
            }
            Cells::Linked(l) => {
                l.remove(from, i, lanes);
                l.insert(to, i);
                Ok(true)
            }
        }
    }

    /// Hints that the cells in `mask` around `cell` will be read soon (linked cells only: the
    /// local re-mapping's, read at each shell exit).
    #[inline(always)]
    pub fn prefetch_around(&self, geometry: &GridGeometry, mask: &Mask, cell: (u32, u32)) {
        if let Cells::Linked(l) = self {
            l.prefetch_rows(geometry, &mask.rows, cell);
        }
    }

    /// Calls `found` with every disk in `mask` around `cell`, and with the disk in `cell`.
    #[inline]
    pub fn gather(
        &self,
        geometry: &GridGeometry,
        mask: &Mask,
        cell: (u32, u32),
        found: impl FnMut(u32),
    ) {
        match self {
            Cells::Dense(d) => d.gather_rows(&mask.rows, cell, found),
            Cells::Sparse(s) => s.gather_all(geometry, &mask.offsets, cell, found),
            Cells::Linked(l) => l.gather_all(geometry, &mask.offsets, cell, found),
        }
    }

    /// Writes to `out` from its start every disk in `mask` around `cell` and the disks in
    /// `cell` (as [`gather`](Self::gather)), and returns how many; `out` is scratch room,
    /// which may be left longer.
    #[inline]
    pub fn gather_into(
        &self,
        geometry: &GridGeometry,
        mask: &Mask,
        cell: (u32, u32),
        out: &mut Vec<u32>,
    ) -> usize {
        match self {
            Cells::Linked(l) => {
                l.gather_into(geometry, &mask.offsets, mask.half_width as u32, cell, out)
            }
            _ => {
                out.clear();
                self.gather(geometry, mask, cell, |j| out.push(j));
                out.len()
            }
        }
    }

    /// Appends to `out` the candidates of disk `i` (in `cell`) from the half of `mask`, each
    /// pair of the grid offered from one of its two disks (the candidates the lists are built
    /// from, in the order they are built).
    #[inline]
    pub fn gather_half(
        &self,
        geometry: &GridGeometry,
        mask: &Mask,
        i: usize,
        cell: (u32, u32),
        out: &mut Vec<u32>,
    ) {
        match self {
            Cells::Dense(d) => d.gather_rows_into(&mask.half_rows, cell, out),
            Cells::Sparse(s) if s.several() => {
                s.gather_half_of(geometry, &mask.half, i as u32, cell, |j| out.push(j))
            }
            Cells::Sparse(s) => s.gather_half_into(geometry, mask, cell, out),
            Cells::Linked(l) => {
                l.gather_half_of(geometry, &mask.half, i as u32, cell, |j| out.push(j))
            }
        }
    }

    /// Re-maps the disks and rebuilds the neighbour lists from `mask`, keeping the pairs that
    /// `near` accepts.
    pub fn rebuild(
        &mut self,
        geometry: &GridGeometry,
        mask: &Mask,
        n: usize,
        cell: impl Fn(usize) -> (u32, u32) + Copy,
        lists: &mut NeighbourLists,
        near: impl Fn(usize, usize) -> bool,
    ) -> Result<()> {
        match self {
            Cells::Dense(d) => d.map(geometry, n, cell)?,
            Cells::Sparse(s) => s.map(geometry, n, cell)?,
            Cells::Linked(l) => l.map(geometry, n, cell),
        }
        let cells = &*self;
        lists.build(
            n,
            |i, out: &mut Vec<u32>| cells.gather_half(geometry, mask, i, cell(i), out),
            near,
        );
        Ok(())
    }

    /// Bytes held by the cell storage.
    pub fn bytes(&self) -> usize {
        match self {
            Cells::Dense(d) => d.bytes(),
            Cells::Sparse(s) => s.bytes(),
            Cells::Linked(l) => l.bytes(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// Linked cells (closed height) and Isobe's hashed array with several disks per cell (open
    /// top) list exactly the pairs closer than the cell side, as all pairs checked one by one.
    #[test]
    fn cells_of_several_anchors_list_every_close_pair() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let mask = Mask::circle("B1", 2);
        for trial in 0..8 {
            let (width, top, reach) = (17.3, 11.9, 2.6);
            let periodic = trial % 2 == 0;
            let n = 400;
            // Clumped: many points share cells.
            let pts: Vec<(f64, f64)> = (0..n)
                .map(|_| {
                    let (cx, cy) = (rng.random_range(0.0..width), rng.random_range(0.0..top));
                    let dx: f64 = rng.random_range(-0.3..0.3);
                    ((cx + dx).clamp(0.0, width - 1e-9), cy)
                })
                .collect();
            let wrap = |d: f64| {
                if periodic && d.abs() > 0.5 * width {
                    d - width * d.signum()
                } else {
                    d
                }
            };
            let near = |i: usize, j: usize| {
                let (dx, dy) = (wrap(pts[i].0 - pts[j].0), pts[i].1 - pts[j].1);
                dx * dx + dy * dy <= reach * reach
            };
            let expected: Vec<Vec<u32>> = (0..n)
                .map(|i| {
                    (0..n)
                        .filter(|&j| i != j && near(i, j))
                        .map(|j| j as u32)
                        .collect()
                })
                .collect();
            for open in [false, true] {
                let top_y = (!open).then_some(top);
                let g = GridGeometry::with_cell_at_least(reach, width, periodic, 0.0, top_y, false);
                assert!(g.lx >= reach && g.ly >= reach);
                let mut cells = Cells::for_geometry(&g, &mask, open, true);
                let mut lists = NeighbourLists::default();
                let cell = |i: usize| g.cell_of(pts[i].0, pts[i].1);
                cells.rebuild(&g, &mask, n, cell, &mut lists, near).unwrap();
                for (i, want) in expected.iter().enumerate() {
                    let mut got = lists.of(i).to_vec();
                    got.sort_unstable();
                    assert_eq!(&got, want, "trial {trial}, open {open}, disk {i}");
                }
                // One disk's gather finds its whole list.
                let mut around = Vec::new();
                cells.gather(&g, &mask, cell(7), |j| {
                    if j != 7 && near(7, j as usize) {
                        around.push(j)
                    }
                });
                around.sort_unstable();
                assert_eq!(around, expected[7], "trial {trial}, open {open}");
            }
        }
    }
}
