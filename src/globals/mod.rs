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
    pub fn for_geometry(geometry: &GridGeometry, mask: &Mask, hashed: bool) -> Cells {
        if geometry.ny.is_some() && !hashed {
            Cells::Dense(DenseCells::with_pad(mask.half_width as u32))
        } else {
            Cells::Sparse(SparseCells::default())
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
