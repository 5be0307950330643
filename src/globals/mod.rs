//! Globals: structures over all disks that find who can meet whom — the EEPGM grid, Isobe's
//! masks, and the neighbour lists taken from the mask at each mapping.

pub mod grid;
pub mod masks;
pub mod neighbours;

pub use grid::{CellMap, DenseCells, GridGeometry, SparseCells};
pub use masks::Mask;
pub use neighbours::NeighbourLists;

use crate::error::Result;

/// The grid storage a scene uses: dense for closed domains, Isobe's compressed array for an
/// open top.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub enum Cells {
    /// One slot per cell.
    Dense(DenseCells),
    /// Occupied cells only (open top).
    Sparse(SparseCells),
}

impl Cells {
    /// The storage for `geometry` and `mask`: dense when the height is bounded (unless
    /// `hashed` is asked for), Isobe's compressed array otherwise.
    pub fn for_geometry(geometry: &GridGeometry, mask: &Mask, hashed: bool, slack: bool) -> Cells {
        if geometry.ny.is_some() && !hashed {
            Cells::Dense(DenseCells::with_pad(mask.half_width as u32))
        } else if slack {
            Cells::Sparse(SparseCells::with_slack())
        } else {
            Cells::Sparse(SparseCells::default())
        }
    }

    /// Moves disk `i` from cell `from` to cell `to`; `Ok(false)` if `to`'s storage is full
    /// (then `i` is in no cell: the caller re-maps).
    pub fn relocate(
        &mut self,
        geometry: &GridGeometry,
        from: (u32, u32),
        to: (u32, u32),
        i: u32,
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
        }
    }

    /// Calls `found` with every disk in `mask` around `cell`, and with the disk in `cell`.
    #[inline]
    pub fn gather(
        &self,
        geometry: &GridGeometry,
        mask: &Mask,
        cell: (u32, u32),
        mut found: impl FnMut(u32),
    ) {
        match self {
            Cells::Dense(d) => d.gather_rows(&mask.rows, cell, found),
            Cells::Sparse(s) => {
                if let Some(j) = s.disk_at(cell.0, cell.1) {
                    found(j);
                }
                s.gather(geometry, &mask.offsets, cell, found)
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
            Cells::Dense(d) => {
                d.map(geometry, n, cell)?;
                lists.build(geometry, mask, n, cell, d, near);
            }
            Cells::Sparse(s) => {
                s.map(geometry, n, cell)?;
                lists.build(geometry, mask, n, cell, s, near);
            }
        }
        Ok(())
    }

    /// Bytes held by the cell storage.
    pub fn bytes(&self) -> usize {
        match self {
            Cells::Dense(d) => d.bytes(),
            Cells::Sparse(s) => s.bytes(),
        }
    }
}
