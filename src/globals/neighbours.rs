//! Neighbour lists: for each disk, the disks found in its mask at the last mapping, stored
//! compactly (one offset per disk, one flat array of disk numbers).

use super::grid::{CellMap, GridGeometry};
use super::masks::Mask;

/// Neighbour lists in compressed-row form.
#[derive(Debug, Clone, Default)]
pub struct NeighbourLists {
    start: Vec<u32>,
    list: Vec<u32>,
}

impl NeighbourLists {
    /// Rebuilds from the mapped cells: disk i's list holds the disks in the cells of `mask`
    /// around its cell that `near(i, j)` accepts (a distance filter; it must be symmetric).
    /// Masks are point-symmetric, so j ∈ list(i) ⇔ i ∈ list(j).
    pub fn build<M: CellMap>(
        &mut self,
        geometry: &GridGeometry,
        mask: &Mask,
        cells: &[(u32, u32)],
        map: &M,
        near: impl Fn(usize, usize) -> bool,
    ) {
        self.start.clear();
        self.list.clear();
        self.start.push(0);
        for (i, &cell) in cells.iter().enumerate() {
            let list = &mut self.list;
            map.gather(geometry, &mask.offsets, cell, |j| {
                if near(i, j as usize) {
                    list.push(j);
                }
            });
            self.start.push(self.list.len() as u32);
        }
    }

    /// The neighbours of disk `i`.
    #[inline(always)]
    pub fn of(&self, i: usize) -> &[u32] {
        &self.list[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// Total entries (twice the number of listed pairs).
    pub fn entries(&self) -> usize {
        self.list.len()
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        4 * (self.start.capacity() + self.list.capacity())
    }
}
