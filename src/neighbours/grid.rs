//! EEPGM, Isobe's Extended Exclusive Particle Grid Method: square-ish cells small enough that a
//! cell holds at most one disk (`σ < l_g < √2 σ`, σ the smallest radius), stored as arrays of
//! disk numbers — no linked lists.
//!
//! Two storages share one geometry:
//! - [`DenseCells`]: one slot per cell, for closed domains (lid or periodic y).
//! - [`SparseCells`]: Isobe's compressed virtual array for an open top (his §6): the occupied
//!   cells only, as arrays `A` (disk numbers), `BX`, `BY` (their cell indices), grouped by the
//!   bucket `k = ⌊N_G / L⌋ mod M` of their serial number `N_G = n_x·j + i`, with `C(k)` where
//!   bucket k starts in A and `D(k)` how many entries it holds. Isobe's direct bucket index needs
//!   `N_Gmax/L` buckets, which grows with the height of the highest disk; folding it modulo
//!   `M` (a power of two ≈ N/2) keeps memory O(N) whatever the height, at the price of buckets
//!   that may mix far-apart rows (a look-up still checks BX and BY). A mapping whose disks all
//!   lie in few enough rows uses a [`DenseCells`] window over those rows instead (one disk per
//!   cell, so the scene's mask is read without branches), and falls back to the arrays when a
//!   disk is far above the rest: both give the same disks in the same order.

use crate::error::{Error, Result};

/// Cell side as a fraction of the smallest radius: `l_g ≤ 1.35 σ`, so the cell diagonal
/// (≤ 1.91 σ) is below the closest centre distance 2σ.
pub const CELL_PER_RADIUS: f64 = 1.35;

/// Cells per bucket in the open-top hashing (Isobe's L, 5–10).
pub const BUCKET_CELLS: u64 = 8;

/// Where the cells are and how they wrap.
#[derive(Debug, Clone, PartialEq)]
pub struct GridGeometry {
    /// Cell side in x.
    pub lx: f64,
    /// Cell side in y.
    pub ly: f64,
    /// Number of cells in x.
    pub nx: u32,
    /// Number of cells in y; `None` for an open top (unbounded).
    pub ny: Option<u32>,
    /// Bottom of the grid (the floor's lowest position, or 0).
    pub y0: f64,
    /// Periodic in x.
    pub x_periodic: bool,
    /// Periodic in y.
    pub y_periodic: bool,
}

impl GridGeometry {
    /// Cells for disks of smallest radius `a_min` in a domain of `width`, `x_periodic`; `y_span`
    /// is `Some((bottom, top))` for a closed domain, `None` for an open top above `bottom`.
    pub fn new(
        a_min: f64,
        width: f64,
        x_periodic: bool,
        bottom: f64,
        top: Option<f64>,
        y_periodic: bool,
    ) -> GridGeometry {
        Self::sized(
            CELL_PER_RADIUS * a_min,
            false,
            width,
            x_periodic,
            bottom,
            top,
            y_periodic,
        )
    }

    /// As [`new`](Self::new), with cells of side at least `target` (linked cells, whose 3 × 3
    /// block must hold every pair closer than `target`).
    pub fn with_cell_at_least(
        target: f64,
        width: f64,
        x_periodic: bool,
        bottom: f64,
        top: Option<f64>,
        y_periodic: bool,
    ) -> GridGeometry {
        Self::sized(target, true, width, x_periodic, bottom, top, y_periodic)
    }

    /// Cells of side `target`, or where periodic the nearest that divides the period: at most
    /// `target` (`wider` false) or at least (`wider` true).
    fn sized(
        target: f64,
        wider: bool,
        width: f64,
        x_periodic: bool,
        bottom: f64,
        top: Option<f64>,
        y_periodic: bool,
    ) -> GridGeometry {
        let count = |span: f64, periodic: bool| {
            let n = if periodic && wider {
                (span / target).floor()
            } else {
                (span / target).ceil()
            };
            n.max(1.0) as u32
        };
        let side = |span: f64, n: u32, periodic: bool| {
            if periodic {
                span / n as f64
            } else {
                target
            }
        };
        let nx = count(width, x_periodic);
        let lx = side(width, nx, x_periodic);
        let (ny, ly) = match top {
            Some(top) => {
                let n = count(top - bottom, y_periodic);
                (Some(n), side(top - bottom, n, y_periodic))
            }
            None => (None, target),
        };
        GridGeometry {
            lx,
            ly,
            nx,
            ny,
            y0: bottom,
            x_periodic,
            y_periodic,
        }
    }

    /// The smaller cell side (what mask reaches are measured in).
    pub fn cell(&self) -> f64 {
        self.lx.min(self.ly)
    }

    /// Cell indices of a point (clamped into the grid: round-off never maps outside).
    #[inline]
    pub fn cell_of(&self, x: f64, y: f64) -> (u32, u32) {
        // Truncation equals floor for non-negative values, and anything below 0 clamps to 0
        // either way (and `as` saturates): no libm call on the re-mapping path.
        let ix = ((x / self.lx) as i64).clamp(0, self.nx as i64 - 1) as u32;
        let fy = ((y - self.y0) / self.ly) as i64;
        let iy = match self.ny {
            Some(ny) => fy.clamp(0, ny as i64 - 1) as u32,
            None => fy.clamp(0, u32::MAX as i64 - 1) as u32,
        };
        (ix, iy)
    }

    /// The cell at offset `(dx, dy)` from `(ix, iy)`, wrapped where periodic; `None` if it falls
    /// outside the grid.
    #[inline(always)]
    pub fn offset(&self, ix: u32, iy: u32, dx: i32, dy: i32) -> Option<(u32, u32)> {
        let mut x = ix as i64 + dx as i64;
        let nx = self.nx as i64;
        if x < 0 || x >= nx {
            if !self.x_periodic {
                return None;
            }
            x = into_grid(x, nx);
        }
        let mut y = iy as i64 + dy as i64;
        if y < 0 {
            if !self.y_periodic {
                return None;
            }
            y = into_grid(y, self.ny.unwrap_or(1) as i64);
        }
        if let Some(ny) = self.ny {
            if y >= ny as i64 {
                if !self.y_periodic {
                    return None;
                }
                y = into_grid(y, ny as i64);
            }
        }
        Some((x as u32, y as u32))
    }

    /// Checks that a mask of half-width `h` does not wrap onto itself in periodic directions.
    pub fn check_mask_fits(&self, h: i32) -> Result<()> {
        let need = 2 * h as u32 + 1;
        if self.x_periodic && self.nx < need {
            return Err(Error::input(
                "domain.width",
                format!(
                    "too narrow for a periodic grid: {} cells across, the neighbour mask needs {need}",
                    self.nx
                ),
            ));
        }
        if let (true, Some(ny)) = (self.y_periodic, self.ny) {
            if ny < need {
                return Err(Error::input(
                    "domain.height",
                    format!(
                        "too low for a periodic grid: {ny} cells high, the neighbour mask needs {need}"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Cells that hold any number of disks (the local re-mapping's anchors): what is in one cell,
/// and from it the scans of a mask around a cell.
pub trait SeveralPerCell {
    /// Calls `found` with every disk in `cell`.
    fn each(&self, cell: (u32, u32), found: impl FnMut(u32));

    /// Calls `found` with every disk in `cell` and in the cells at `offsets` around it.
    #[inline]
    fn gather_all(
        &self,
        geometry: &GridGeometry,
        offsets: &[(i32, i32)],
        cell: (u32, u32),
        mut found: impl FnMut(u32),
    ) {
        self.each(cell, &mut found);
        for &(dx, dy) in offsets {
            if let Some(c) = geometry.offset(cell.0, cell.1, dx, dy) {
                self.each(c, &mut found);
            }
        }
    }

    /// Calls `found` with each disk that pairs with disk `i` (in `cell`) once: the disks of its
    /// own cell numbered above it, and those in the cells at the half offsets `half`.
    #[inline]
    fn gather_half_of(
        &self,
        geometry: &GridGeometry,
        half: &[(i32, i32)],
        i: u32,
        cell: (u32, u32),
        mut found: impl FnMut(u32),
    ) {
        self.each(cell, |j| {
            if j > i {
                found(j)
            }
        });
        for &(dx, dy) in half {
            if let Some(c) = geometry.offset(cell.0, cell.1, dx, dy) {
                self.each(c, &mut found);
            }
        }
    }
}

/// Where disks are: a map from cell to the (at most one) disk in it.
pub trait CellMap {
    /// Re-maps `n` disks, disk i being in cell `cell(i)`. Fails if two disks share a cell
    /// (they overlap).
    fn map(
        &mut self,
        geometry: &GridGeometry,
        n: usize,
        cell: impl Fn(usize) -> (u32, u32),
    ) -> Result<()>;
    /// The disk in cell `(ix, iy)`, if any.
    fn disk_at(&self, ix: u32, iy: u32) -> Option<u32>;
    /// Puts disk `i` in the empty cell `cell`; `Ok(false)` if the storage has no room
    /// left there (the caller re-maps), an error if the cell holds another disk.
    fn insert(&mut self, geometry: &GridGeometry, cell: (u32, u32), i: u32) -> Result<bool>;
    /// Takes disk `i` out of cell `cell` (nothing if it is not there).
    fn remove(&mut self, geometry: &GridGeometry, cell: (u32, u32), i: u32);
    /// Calls `found` with every disk in the half of `mask` "after" `cell` (its `half`
    /// offsets, in their order).
    #[inline]
    fn gather_half(
        &self,
        geometry: &GridGeometry,
        mask: &super::Mask,
        cell: (u32, u32),
        found: impl FnMut(u32),
    ) {
        self.gather(geometry, &mask.half, cell, found)
    }

    /// Calls `found` with every disk in the cells at `offsets` around `(ix, iy)`.
    #[inline]
    fn gather(
        &self,
        geometry: &GridGeometry,
        offsets: &[(i32, i32)],
        (ix, iy): (u32, u32),
        mut found: impl FnMut(u32),
    ) {
        for &(dx, dy) in offsets {
            if let Some((cx, cy)) = geometry.offset(ix, iy, dx, dy) {
                if let Some(j) = self.disk_at(cx, cy) {
                    found(j);
                }
            }
        }
    }
    /// Bytes held.
    fn bytes(&self) -> usize;
}

fn shared_cell(i: u32, j: u32) -> Error {
    Error::Runtime(format!(
        "disks {i} and {j} share a grid cell: they overlap beyond the tolerance of the grid"
    ))
}

/// One slot per cell (0 = empty, else disk number + 1), with a halo of `pad` cells around the
/// grid: copies of the opposite edge where periodic, empty otherwise. A mask offset is then one
/// fixed index step, with no wrapping or bounds tests while neighbour lists are built.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct DenseCells {
    pad: u32,
    stride: usize,
    slots: Vec<u32>,
}

impl DenseCells {
    /// A dense map whose halo is wide enough for masks of half-width `pad`.
    pub fn with_pad(pad: u32) -> DenseCells {
        DenseCells {
            pad,
            ..DenseCells::default()
        }
    }

    #[inline(always)]
    fn index(&self, ix: u32, iy: u32) -> usize {
        (iy + self.pad) as usize * self.stride + (ix + self.pad) as usize
    }

    /// Width of the halo, in cells.
    pub fn pad(&self) -> u32 {
        self.pad
    }

    /// Calls `found` with every disk in the mask `rows` around `(ix, iy)`, reading each row
    /// as one run of slots (the halo makes every row contiguous).
    #[inline]
    pub fn gather_rows(
        &self,
        rows: &[(i32, i32, i32)],
        (ix, iy): (u32, u32),
        mut found: impl FnMut(u32),
    ) {
        let base = self.index(ix, iy) as isize;
        let stride = self.stride as isize;
        // Most cells are empty, at random: the occupied slots of a run are first packed without
        // a branch (a data-dependent branch per cell mispredicts often), then handed on.
        let mut packed = [0u32; 64];
        for &(dy, lo, hi) in rows {
            let start = (base + dy as isize * stride + lo as isize) as usize;
            let end = (base + dy as isize * stride + hi as isize) as usize;
            for run in self.slots[start..=end].chunks(packed.len()) {
                let mut k = 0;
                for &s in run {
                    packed[k] = s;
                    k += (s != 0) as usize;
                }
                for &s in &packed[..k] {
                    found(s - 1);
                }
            }
        }
    }

    /// [`gather_rows`](Self::gather_rows) appending to `out`: room for every cell of the mask
    /// is made in `out` at once, the occupied slots are packed into it without a branch, and
    /// the rest is cut off (no call or capacity check per disk).
    #[inline]
    pub fn gather_rows_into(
        &self,
        rows: &[(i32, i32, i32)],
        (ix, iy): (u32, u32),
        out: &mut Vec<u32>,
    ) {
        let base = self.index(ix, iy) as isize;
        let stride = self.stride as isize;
        let from = out.len();
        let cells: usize = rows.iter().map(|&(_, lo, hi)| (hi - lo + 1) as usize).sum();
        out.resize(from + cells, 0);
        let packed = &mut out[from..];
        let mut k = 0;
        for &(dy, lo, hi) in rows {
            let start = (base + dy as isize * stride + lo as isize) as usize;
            let end = (base + dy as isize * stride + hi as isize) as usize;
            for &s in &self.slots[start..=end] {
                packed[k] = s.wrapping_sub(1);
                k += (s != 0) as usize;
            }
        }
        out.truncate(from + k);
    }

    /// Writes one cell's slot and its images in the halo where periodic.
    fn write(&mut self, geometry: &GridGeometry, ix: u32, iy: u32, value: u32) {
        let (p, nx) = (self.pad as i64, geometry.nx as i64);
        let ny = geometry.ny.unwrap_or(1) as i64;
        let images = |i: i64, n: i64, periodic: bool| {
            let mut v = [i + p, i + p, i + p];
            if periodic && i < p {
                v[1] = i + p + n;
            }
            if periodic && i >= n - p {
                v[2] = i + p - n;
            }
            v
        };
        let xs = images(ix as i64, nx, geometry.x_periodic);
        let ys = images(iy as i64, ny, geometry.y_periodic);
        for y in ys {
            for x in xs {
                let k = y as usize * self.stride + x as usize;
                self.slots[k] = value;
            }
        }
    }
}

impl CellMap for DenseCells {
    fn map(
        &mut self,
        geometry: &GridGeometry,
        count: usize,
        cell: impl Fn(usize) -> (u32, u32),
    ) -> Result<()> {
        let ny = geometry.ny.expect("a dense grid needs a bounded height") as usize;
        let nx = geometry.nx as usize;
        let p = self.pad as usize;
        self.stride = nx + 2 * p;
        let n = self.stride * (ny + 2 * p);
        // Emptied in place: a window re-mapped over a changing number of rows keeps its room.
        self.slots.clear();
        self.slots.resize(n, 0);
        for i in 0..count {
            let (ix, iy) = cell(i);
            let k = self.index(ix, iy);
            let slot = &mut self.slots[k];
            if *slot != 0 {
                return Err(shared_cell(*slot - 1, i as u32));
            }
            *slot = i as u32 + 1;
        }
        let stride = self.stride;
        if geometry.x_periodic {
            for row in p..p + ny {
                let r = row * stride;
                for k in 0..p {
                    self.slots[r + k] = self.slots[r + nx + k];
                    self.slots[r + p + nx + k] = self.slots[r + p + k];
                }
            }
        }
        if geometry.y_periodic {
            for k in 0..p {
                let (below, from_top) = (k * stride, (ny + k) * stride);
                let (above, from_bottom) = ((p + ny + k) * stride, (p + k) * stride);
                self.slots.copy_within(from_top..from_top + stride, below);
                self.slots
                    .copy_within(from_bottom..from_bottom + stride, above);
            }
        }
        Ok(())
    }

    #[inline(always)]
    fn disk_at(&self, ix: u32, iy: u32) -> Option<u32> {
        let s = self.slots[self.index(ix, iy)];
        (s != 0).then(|| s - 1)
    }

    fn insert(&mut self, geometry: &GridGeometry, (ix, iy): (u32, u32), i: u32) -> Result<bool> {
        if let Some(j) = self.disk_at(ix, iy) {
            if j != i {
                return Err(shared_cell(j, i));
            }
        }
        self.write(geometry, ix, iy, i + 1);
        Ok(true)
    }

    fn remove(&mut self, geometry: &GridGeometry, (ix, iy): (u32, u32), i: u32) {
        if self.disk_at(ix, iy) == Some(i) {
            self.write(geometry, ix, iy, 0);
        }
    }

    #[inline]
    fn gather_half(
        &self,
        _geometry: &GridGeometry,
        mask: &super::Mask,
        cell: (u32, u32),
        found: impl FnMut(u32),
    ) {
        self.gather_rows(&mask.half_rows, cell, found)
    }

    #[inline]
    fn gather(
        &self,
        _geometry: &GridGeometry,
        offsets: &[(i32, i32)],
        (ix, iy): (u32, u32),
        mut found: impl FnMut(u32),
    ) {
        debug_assert!(offsets
            .iter()
            .all(|&(a, b)| a.unsigned_abs().max(b.unsigned_abs()) <= self.pad));
        let base = self.index(ix, iy) as isize;
        for &(dx, dy) in offsets {
            let s = self.slots[(base + dy as isize * self.stride as isize + dx as isize) as usize];
            if s != 0 {
                found(s - 1);
            }
        }
    }

    fn bytes(&self) -> usize {
        self.slots.capacity() * 4
    }
}

/// Isobe's compressed virtual array with bucketed hashing (arrays A, BX, BY, C, D).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct SparseCells {
    nx: u64,
    /// Buckets − 1 (a power of two minus one).
    fold: u64,
    /// Disk numbers grouped by bucket.
    a: Vec<u32>,
    /// Cell x index of each entry of A.
    bx: Vec<u32>,
    /// Cell y index of each entry of A.
    by: Vec<u32>,
    /// Where bucket k starts in A (and, at M, the end of A): bucket k may hold up to
    /// `C(k+1) − C(k)` entries.
    c: Vec<u32>,
    /// Room left in each bucket at a mapping, for disks that move in between (the local
    /// re-mapping): a bucket gets twice its entries plus two.
    slack: bool,
    /// Cells may hold several disks (the local re-mapping's anchors): no shared-cell check,
    /// and a look-up reads every entry of the cell.
    several: bool,
    /// How many entries bucket k holds.
    d: Vec<u32>,
    /// One disk per cell: at a mapping whose disks all lie in few enough rows (see
    /// [`WINDOW_CELLS_PER_DISK`]), they go into dense slots over those rows instead of A, BX,
    /// BY, C, D, and the mask is read row by row from the slots (branch-free, as on a closed
    /// domain's dense grid). Its halo is as wide as the scene's mask: a map made with
    /// [`Default`] has none and never uses it.
    window: DenseCells,
    /// The last mapping used the window, over this many rows (0: it did not).
    window_rows: u32,
}

/// Largest dense window, in cells per disk (plus [`WINDOW_CELLS_FLOOR`]): above it (a disk
/// far above the others, a dilute bed spread high) the mapping keeps Isobe's arrays, whose
/// size does not depend on where the disks are.
pub const WINDOW_CELLS_PER_DISK: u64 = 64;
/// Cells any window may have, whatever the number of disks.
pub const WINDOW_CELLS_FLOOR: u64 = 1 << 16;

impl SparseCells {
    /// A map of one disk per cell, with a dense window's halo wide enough for masks of
    /// half-width `pad`.
    pub fn with_window(pad: u32) -> SparseCells {
        SparseCells {
            window: DenseCells::with_pad(pad),
            ..SparseCells::default()
        }
    }

    #[inline(always)]
    fn bucket(&self, ix: u32, iy: u32) -> usize {
        let serial = self.nx * iy as u64 + ix as u64; // N_G − 1
        ((serial / BUCKET_CELLS) & self.fold) as usize
    }

    /// Number of buckets (M).
    pub fn buckets(&self) -> usize {
        self.d.len()
    }

    /// A map whose buckets keep room for disks moving in between mappings, and whose cells
    /// hold any number of disks (the local re-mapping's anchors).
    pub fn for_anchors() -> SparseCells {
        SparseCells {
            slack: true,
            several: true,
            ..SparseCells::default()
        }
    }

    /// [`gather_half`](CellMap::gather_half) appending to `out`; through the dense window
    /// (rows copied in runs, see [`DenseCells::gather_rows_into`]) where the mapping has one.
    #[inline]
    pub fn gather_half_into(
        &self,
        geometry: &GridGeometry,
        mask: &super::Mask,
        cell: (u32, u32),
        out: &mut Vec<u32>,
    ) {
        if self.window_rows > 0 && mask.half_width as u32 <= self.window.pad() {
            return self.window.gather_rows_into(&mask.half_rows, cell, out);
        }
        self.gather_half(geometry, mask, cell, |j| out.push(j))
    }

    /// `true` if cells may hold several disks.
    pub fn several(&self) -> bool {
        self.several
    }
}

impl SeveralPerCell for SparseCells {
    #[inline]
    fn each(&self, (ix, iy): (u32, u32), mut found: impl FnMut(u32)) {
        let k = self.bucket(ix, iy);
        let start = self.c[k] as usize;
        for e in start..start + self.d[k] as usize {
            if self.bx[e] == ix && self.by[e] == iy {
                found(self.a[e]);
            }
        }
    }
}

impl CellMap for SparseCells {
    fn map(
        &mut self,
        geometry: &GridGeometry,
        n: usize,
        cell: impl Fn(usize) -> (u32, u32),
    ) -> Result<()> {
        self.nx = geometry.nx as u64;
        self.window_rows = 0;
        // Not where y is periodic: the window's rows do not wrap (mask rows would miss the
        // pairs across the top and bottom edges).
        if !self.several && self.window.pad() > 0 && !geometry.y_periodic {
            let rows = (0..n).map(|i| cell(i).1 as u64 + 1).max().unwrap_or(1);
            let pad = 2 * self.window.pad() as u64;
            let cells = (self.nx + pad) * (rows + pad);
            if cells <= WINDOW_CELLS_PER_DISK * n as u64 + WINDOW_CELLS_FLOOR {
                let mut band = geometry.clone();
                band.ny = Some(rows as u32);
                band.y_periodic = false;
                self.window.map(&band, n, cell)?;
                self.window_rows = rows as u32;
                return Ok(());
            }
        }
        let m = (n / 2).max(1).next_power_of_two();
        self.fold = m as u64 - 1;
        self.d.clear();
        self.d.resize(m, 0);
        self.c.clear();
        self.c.resize(m + 1, 0);
        for i in 0..n {
            let (ix, iy) = cell(i);
            let k = self.bucket(ix, iy);
            self.d[k] += 1;
        }
        let mut start = 0u32;
        for k in 0..m {
            self.c[k] = start;
            start += if self.slack {
                2 * self.d[k] + 2
            } else {
                self.d[k]
            };
        }
        self.c[m] = start;
        let total = start as usize;
        self.a.resize(total, 0);
        self.bx.resize(total, 0);
        self.by.resize(total, 0);
        // Counting sort: D doubles as the fill cursor, then is restored.
        self.d.fill(0);
        for i in 0..n {
            let (ix, iy) = cell(i);
            let k = self.bucket(ix, iy);
            let at = (self.c[k] + self.d[k]) as usize;
            self.d[k] += 1;
            self.a[at] = i as u32;
            self.bx[at] = ix;
            self.by[at] = iy;
        }
        for i in (0..n).filter(|_| !self.several) {
            let (ix, iy) = cell(i);
            let found = self.disk_at(ix, iy).expect("a disk just mapped is found");
            if found != i as u32 {
                return Err(shared_cell(found, i as u32));
            }
        }
        Ok(())
    }

    #[inline(always)]
    fn disk_at(&self, ix: u32, iy: u32) -> Option<u32> {
        if self.window_rows > 0 {
            return if iy < self.window_rows {
                self.window.disk_at(ix, iy)
            } else {
                None
            };
        }
        let k = self.bucket(ix, iy);
        let start = self.c[k] as usize;
        let end = start + self.d[k] as usize;
        (start..end)
            .find(|&e| self.bx[e] == ix && self.by[e] == iy)
            .map(|e| self.a[e])
    }

    fn insert(&mut self, _: &GridGeometry, (ix, iy): (u32, u32), i: u32) -> Result<bool> {
        if self.window_rows > 0 {
            // The window is for whole mappings: one disk moving re-maps them all.
            return Ok(false);
        }
        if let Some(j) = self.disk_at(ix, iy).filter(|_| !self.several) {
            if j != i {
                return Err(shared_cell(j, i));
            }
            return Ok(true);
        }
        let k = self.bucket(ix, iy);
        if self.c[k] + self.d[k] == self.c[k + 1] {
            return Ok(false);
        }
        let at = (self.c[k] + self.d[k]) as usize;
        self.d[k] += 1;
        self.a[at] = i;
        self.bx[at] = ix;
        self.by[at] = iy;
        Ok(true)
    }

    fn remove(&mut self, _: &GridGeometry, (ix, iy): (u32, u32), i: u32) {
        if self.window_rows > 0 {
            return;
        }
        let k = self.bucket(ix, iy);
        let start = self.c[k] as usize;
        let last = start + self.d[k] as usize - 1;
        if let Some(e) =
            (start..=last).find(|&e| self.a[e] == i && self.bx[e] == ix && self.by[e] == iy)
        {
            self.a[e] = self.a[last];
            self.bx[e] = self.bx[last];
            self.by[e] = self.by[last];
            self.d[k] -= 1;
        }
    }

    /// Row by row: the cells of a row of the half mask lie in one to three buckets (a bucket
    /// holds [`BUCKET_CELLS`] consecutive cells of a row), and each of those is read once
    /// instead of once per cell; the disks found come out sorted along the row, in the order
    /// of the cell-by-cell scan. A row that wraps round the periodic sides or leaves the grid
    /// is scanned cell by cell.
    #[inline]
    fn gather_half(
        &self,
        geometry: &GridGeometry,
        mask: &super::Mask,
        (ix, iy): (u32, u32),
        mut found: impl FnMut(u32),
    ) {
        if self.window_rows > 0 {
            if mask.half_width as u32 <= self.window.pad() {
                return self.window.gather_rows(&mask.half_rows, (ix, iy), found);
            }
            // A mask wider than the halo: cell by cell (the window answers each cell).
            return self.gather(geometry, &mask.half, (ix, iy), found);
        }
        debug_assert!(
            !self.several,
            "one disk per cell (anchors use gather_half_of)"
        );
        /// Longest row read in one go, plus one (masks up to R10 have rows of 19 cells).
        const ROW: usize = 32;
        let cell_by_cell = |dy: i32, lo: i32, hi: i32, found: &mut dyn FnMut(u32)| {
            for dx in lo..=hi {
                if let Some((cx, cy)) = geometry.offset(ix, iy, dx, dy) {
                    if let Some(j) = self.disk_at(cx, cy) {
                        found(j);
                    }
                }
            }
        };
        for &(dy, lo, hi) in &mask.half_rows {
            let ends = (
                geometry.offset(ix, iy, lo, dy),
                geometry.offset(ix, iy, hi, dy),
            );
            let (Some((x0, y)), Some((x1, _))) = ends else {
                cell_by_cell(dy, lo, hi, &mut found);
                continue;
            };
            let first = (self.nx * y as u64 + x0 as u64) / BUCKET_CELLS;
            let last = (self.nx * y as u64 + x1 as u64) / BUCKET_CELLS;
            let straight = x1 >= x0 && (x1 - x0) as i64 == (hi - lo) as i64;
            // Room for every cell of the row and one more write (the last, unkept, entry).
            if !straight || (hi - lo) as usize + 1 >= ROW || last - first > self.fold {
                cell_by_cell(dy, lo, hi, &mut found);
                continue;
            }
            // (cell x, disk) of the row's disks, kept without a branch per entry.
            let mut got = [(0u32, 0u32); ROW];
            let mut n = 0;
            for b in first..=last {
                let k = (b & self.fold) as usize;
                let start = self.c[k] as usize;
                for e in start..start + self.d[k] as usize {
                    let bx = self.bx[e];
                    got[n] = (bx, self.a[e]);
                    n += (self.by[e] == y && bx >= x0 && bx <= x1) as usize;
                }
            }
            let got = &mut got[..n];
            // At most one disk per cell: sorting by cell is the scan's order.
            got.sort_unstable_by_key(|&(bx, _)| bx);
            for &(_, j) in got.iter() {
                found(j);
            }
        }
    }

    fn bytes(&self) -> usize {
        4 * (self.a.capacity()
            + self.bx.capacity()
            + self.by.capacity()
            + self.c.capacity()
            + self.d.capacity())
            + self.window.bytes()
    }
}

/// Cell index `k` brought into `0..n` on a periodic grid of `n` cells: `k.rem_euclid(n)`, by
/// one period's step where that suffices (a mask reaches less than a period: see
/// [`GridGeometry::check_mask_fits`]), without the division.
#[inline(always)]
fn into_grid(k: i64, n: i64) -> i64 {
    let stepped = if k < 0 { k + n } else { k - n };
    if (0..n).contains(&stepped) {
        stepped
    } else {
        k.rem_euclid(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighbours::Mask;
    use rand::seq::SliceRandom;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256StarStar;

    /// A cell index brought into the grid by a period's step is the remainder's, near the grid
    /// and far from it.
    #[test]
    fn cells_come_into_the_grid_as_by_the_remainder() {
        for n in 1..12i64 {
            for k in -5 * n..5 * n {
                assert_eq!(into_grid(k, n), k.rem_euclid(n), "k = {k}, n = {n}");
            }
        }
    }

    /// Disks in four cells of ten of the lowest twelve rows of `nx` columns, and in `extra`,
    /// numbered in no particular order of the cells.
    fn random_cells(
        rng: &mut Xoshiro256StarStar,
        nx: u32,
        extra: &[(u32, u32)],
    ) -> Vec<(u32, u32)> {
        let mut cells: Vec<(u32, u32)> = (0..nx)
            .flat_map(|ix| (0..12).map(move |iy| (ix, iy)))
            .filter(|_| rng.random::<f64>() < 0.4)
            .chain(extra.iter().copied())
            .collect();
        cells.shuffle(rng);
        cells
    }

    /// The row-by-row scan of the compressed array finds the disks of the half mask in exactly
    /// the order of the cell-by-cell scan: every mask, periodic sides and walls, disks on the
    /// seam, and one far above the others (cell rows near the top of the index range).
    #[test]
    fn sparse_rows_find_the_half_mask_in_cell_order() {
        let mut rng = Xoshiro256StarStar::seed_from_u64(7);
        for k in 0..9 {
            let mask = Mask::table(k);
            for periodic in [true, false] {
                let geometry = GridGeometry::new(0.5, 30.0, periodic, 0.0, None, false);
                let far = [(geometry.nx / 2, u32::MAX - 3), (0, u32::MAX - 2)];
                let cells = random_cells(&mut rng, geometry.nx, &far);
                let mut sparse = SparseCells::default();
                sparse.map(&geometry, cells.len(), |i| cells[i]).unwrap();
                for &cell in &cells {
                    let (mut rows, mut one_by_one) = (Vec::new(), Vec::new());
                    sparse.gather_half(&geometry, &mask, cell, |j| rows.push(j));
                    sparse.gather(&geometry, &mask.half, cell, |j| one_by_one.push(j));
                    assert_eq!(
                        rows, one_by_one,
                        "{} periodic {periodic} {cell:?}",
                        mask.name
                    );
                }
            }
        }
    }

    /// A mapping whose disks lie in few rows uses the dense window, and finds the half mask in
    /// the same order as Isobe's arrays (one disk at a time, or appended in runs); a disk far
    /// up sends it back to the arrays.
    #[test]
    fn the_dense_window_finds_what_the_arrays_find() {
        let mut rng = Xoshiro256StarStar::seed_from_u64(11);
        for k in 0..9 {
            let mask = Mask::table(k);
            for periodic in [true, false] {
                let geometry = GridGeometry::new(0.5, 30.0, periodic, 0.0, None, false);
                let mut cells = random_cells(&mut rng, geometry.nx, &[]);
                let mut window = SparseCells::with_window(mask.half_width as u32);
                window.map(&geometry, cells.len(), |i| cells[i]).unwrap();
                assert!(window.window_rows > 0, "{}: the window is used", mask.name);
                let mut arrays = SparseCells::default();
                arrays.map(&geometry, cells.len(), |i| cells[i]).unwrap();
                assert_eq!(arrays.window_rows, 0);
                for &cell in &cells {
                    let (mut w, mut a) = (Vec::new(), Vec::new());
                    window.gather_half(&geometry, &mask, cell, |j| w.push(j));
                    arrays.gather_half(&geometry, &mask, cell, |j| a.push(j));
                    assert_eq!(w, a, "{} periodic {periodic} {cell:?}", mask.name);
                    // Appended in runs (what the lists are built from), after what was there.
                    let mut into = vec![7, 8];
                    window.gather_half_into(&geometry, &mask, cell, &mut into);
                    assert_eq!(into[..2], [7, 8]);
                    assert_eq!(into[2..], w, "{} periodic {periodic} {cell:?}", mask.name);
                    for dy in 0..3 {
                        let up = (cell.0, cell.1 + dy);
                        assert_eq!(window.disk_at(up.0, up.1), arrays.disk_at(up.0, up.1));
                    }
                }
                cells.push((0, 1 << 30));
                window.map(&geometry, cells.len(), |i| cells[i]).unwrap();
                assert_eq!(window.window_rows, 0, "a disk far up: Isobe's arrays");
            }
        }
    }

    /// A closed box with periodic y on the compressed array (`engine.grid = "hashed"`): the
    /// mask wraps round the top and bottom, which a window over rows cannot; the arrays are
    /// kept and find the pairs across that edge.
    #[test]
    fn a_box_periodic_in_y_keeps_the_arrays() {
        let mask = Mask::table(2);
        let geometry = GridGeometry::new(0.5, 10.0, true, 0.0, Some(10.0), true);
        let ny = geometry.ny.unwrap();
        let cells = [(3, 0), (3, ny - 1), (7, 5)];
        let mut sparse = SparseCells::with_window(mask.half_width as u32);
        sparse.map(&geometry, cells.len(), |i| cells[i]).unwrap();
        assert_eq!(sparse.window_rows, 0);
        let mut found = Vec::new();
        sparse.gather_half(&geometry, &mask, cells[1], |j| found.push(j));
        assert_eq!(found, [0], "the disk across the periodic edge");
    }
}
