//! Linked cells for the approximate schemes: a head-of-chain array and a linked list (the
//! neighour-list tutorial's cell list), cells at least a given side. Every pair of disks in the
//! same or adjacent cells is visited once (a half stencil).
//!
//! An open top has no height bound: the rows are folded modulo a row count of O(N / columns),
//! so memory stays O(N) however high a disk flies (disks folded into adjacent rows are rejected
//! by the callers' distance tests).

use super::cores::MIN_PIECE;
use crate::physics::walls::{SideBounds, Top};
use rayon::prelude::*;

const EMPTY: u32 = u32::MAX;

/// A cell list over the domain.
#[derive(Debug, Clone, Default)]
pub struct CellList {
    nx: usize,
    ny: usize,
    cw: f64,
    ch: f64,
    y0: f64,
    x_wrap: bool,
    y_wrap: bool,
    head: Vec<u32>,
    next: Vec<u32>,
    cell_of: Vec<u32>,
    stencil: Vec<(isize, isize)>,
}

impl CellList {
    /// Side of the cells in x.
    pub fn cell(&self) -> f64 {
        self.cw
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        4 * (self.head.capacity() + self.next.capacity() + self.cell_of.capacity())
    }

    /// The columns of cells [`build`](Self::build) makes for `n` disks and cells of side at
    /// least `size`: at most O(N) (a wide, sparse domain gets fewer, wider cells), and one
    /// rather than two in a periodic box (a cell would be its own neighbour twice).
    pub fn columns_for(n: usize, size: f64, sides: SideBounds) -> usize {
        let nx = ((sides.width() / size).floor().min(1e15) as usize).clamp(1, 2 * n + 3);
        if matches!(sides, SideBounds::Periodic { .. }) && nx < 3 {
            1
        } else {
            nx
        }
    }

    /// Maps `n` disks at positions `pos(i)` (wrapped into the box where periodic) into cells of
    /// side at least `size`.
    pub fn build(
        &mut self,
        n: usize,
        pos: impl Fn(usize) -> (f64, f64) + Sync,
        size: f64,
        sides: SideBounds,
        top: Top,
    ) {
        let width = sides.width();
        let x_periodic = matches!(sides, SideBounds::Periodic { .. });
        self.nx = Self::columns_for(n, size, sides);
        self.x_wrap = x_periodic;
        self.cw = width / self.nx as f64;
        match top {
            Top::Periodic { height } => {
                self.ny = ((height / size).floor().min(1e15) as usize)
                    .clamp(1, ((4 * n + 16) / self.nx).max(1));
                if self.ny < 3 {
                    self.ny = 1;
                }
                self.ch = height / self.ny as f64;
                self.y0 = 0.0;
                self.y_wrap = true;
            }
            _ => {
                let (lo, hi) = (0..n)
                    .into_par_iter()
                    .with_min_len(MIN_PIECE)
                    .map(|i| (pos(i).1, pos(i).1))
                    .reduce(
                        || (f64::INFINITY, f64::NEG_INFINITY),
                        |(lo_a, hi_a), (lo_b, hi_b)| (lo_a.min(lo_b), hi_a.max(hi_b)),
                    );
                let (lo, hi) = if n == 0 { (0.0, 0.0) } else { (lo, hi) };
                let rows = ((hi - lo) / size).floor() as usize + 1;
                let cap = (2 * n.div_ceil(self.nx) + 3).max(3);
                self.ch = size;
                self.y0 = lo;
                if rows <= cap {
                    self.ny = rows;
                    self.y_wrap = false;
                } else {
                    self.ny = cap;
                    self.y_wrap = true; // folded rows
                }
            }
        }
        self.stencil.clear();
        for (mut dx, mut dy) in [(1isize, 0isize), (-1, 1), (0, 1), (1, 1)] {
            if self.x_wrap && self.nx == 1 {
                dx = 0;
            }
            if self.y_wrap && self.ny == 1 {
                dy = 0;
            }
            if (dx, dy) == (0, 0)
                || self.stencil.contains(&(dx, dy))
                || self.stencil.contains(&(-dx, -dy))
            {
                continue;
            }
            self.stencil.push((dx, dy));
        }
        self.head.clear();
        self.head.resize(self.nx * self.ny, EMPTY);
        self.next.clear();
        self.next.resize(n, EMPTY);
        // The cells on the threads; the chains linked in the order of the disks, on one.
        let mut cell_of = std::mem::take(&mut self.cell_of);
        (0..n)
            .into_par_iter()
            .with_min_len(MIN_PIECE)
            .map(|i| {
                let (x, y) = pos(i);
                self.index(x, y) as u32
            })
            .collect_into_vec(&mut cell_of);
        for (i, &c) in cell_of.iter().enumerate() {
            self.next[i] = self.head[c as usize];
            self.head[c as usize] = i as u32;
        }
        self.cell_of = cell_of;
    }

    #[inline]
    fn index(&self, x: f64, y: f64) -> usize {
        let cx = ((x / self.cw).floor().max(0.0) as usize).min(self.nx - 1);
        let ry = ((y - self.y0) / self.ch).floor().max(0.0) as usize;
        let cy = if self.y_wrap {
            ry % self.ny
        } else {
            ry.min(self.ny - 1)
        };
        cy * self.nx + cx
    }

    /// Number of columns of cells.
    pub fn columns(&self) -> usize {
        self.nx
    }

    /// Calls `f(i)` for every disk in the cells of `columns`, row by row, the columns in the
    /// order given.
    pub fn for_each_disk_in_columns(&self, columns: &[usize], mut f: impl FnMut(usize)) {
        for row in 0..self.ny {
            for &col in columns {
                let mut i = self.head[row * self.nx + col];
                while i != EMPTY {
                    f(i as usize);
                    i = self.next[i as usize];
                }
            }
        }
    }

    /// Calls `f(i, j, same)` for every pair [`for_each_pair`](Self::for_each_pair) visits from
    /// the cells of `columns` (row by row, the columns in the order given); `same` tells whether
    /// the other disk's column has the same `group` as the first's.
    pub fn for_each_pair_in_columns(
        &self,
        columns: &[usize],
        group: &[u32],
        mut f: impl FnMut(usize, usize, bool),
    ) {
        for row in 0..self.ny {
            for &col in columns {
                let c = row * self.nx + col;
                self.for_each_pair_from_cell(c, |i, j, t| {
                    f(i, j, group[t % self.nx] == group[col])
                });
            }
        }
    }

    /// Calls `f(i, j)` once for every pair of disks in the same or adjacent cells, cell by cell
    /// in row-major order.
    pub fn for_each_pair(&self, mut f: impl FnMut(usize, usize)) {
        for c in 0..self.nx * self.ny {
            self.for_each_pair_from_cell(c, |i, j, _| f(i, j));
        }
    }

    /// `f(i, j)` of every pair [`for_each_pair`](Self::for_each_pair) visits, where it is
    /// `Some`, in the order it visits them. The cells are shared among the threads of the
    /// current pool in runs of about [`MIN_PIECE`] disks (not rows: a bed's few rows hold very
    /// different numbers of disks, and two threads split a dozen rows unevenly); the order is
    /// not shared out.
    pub fn pairs_where<T: Send>(&self, f: impl Fn(usize, usize) -> Option<T> + Sync) -> Vec<T> {
        let mut found = Vec::new();
        self.pairs_where_into(&mut found, f);
        found
    }

    /// [`pairs_where`](Self::pairs_where) into `out`, whose memory is kept (a list rebuilt at
    /// every few steps then costs no fresh pages).
    pub fn pairs_where_into<T: Send>(
        &self,
        out: &mut Vec<T>,
        f: impl Fn(usize, usize) -> Option<T> + Sync,
    ) {
        let cells = self.nx * self.ny;
        let disks_per_cell = (self.next.len() / cells.max(1)).max(1);
        let pieces: Vec<Vec<T>> = (0..cells)
            .into_par_iter()
            .with_min_len((MIN_PIECE / disks_per_cell).max(1))
            .fold(Vec::new, |mut found, c| {
                self.for_each_pair_from_cell(c, |i, j, _| found.extend(f(i, j)));
                found
            })
            .collect();
        out.clear();
        out.reserve(pieces.iter().map(Vec::len).sum());
        for piece in pieces {
            out.extend(piece);
        }
    }

    /// The pairs within cell `c` and between it and the cells its half stencil reaches, with
    /// the other disk's cell.
    fn for_each_pair_from_cell(&self, c: usize, mut f: impl FnMut(usize, usize, usize)) {
        let (nx, ny) = (self.nx as isize, self.ny as isize);
        let (cx, cy) = ((c % self.nx) as isize, (c / self.nx) as isize);
        let mut i = self.head[c];
        while i != EMPTY {
            let mut j = self.next[i as usize];
            while j != EMPTY {
                f(i as usize, j as usize, c);
                j = self.next[j as usize];
            }
            i = self.next[i as usize];
        }
        for &(dx, dy) in &self.stencil {
            let (mut tx, mut ty) = (cx + dx, cy + dy);
            if self.x_wrap {
                tx = tx.rem_euclid(nx);
            } else if !(0..nx).contains(&tx) {
                continue;
            }
            if self.y_wrap {
                ty = ty.rem_euclid(ny);
            } else if !(0..ny).contains(&ty) {
                continue;
            }
            let t = (ty * nx + tx) as usize;
            let mut i = self.head[c];
            while i != EMPTY {
                let mut j = self.head[t];
                while j != EMPTY {
                    f(i as usize, j as usize, t);
                    j = self.next[j as usize];
                }
                i = self.next[i as usize];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Every pair closer than the cell side is visited exactly once, in periodic, walled and
    /// open (folded) domains, including boxes only one or two cells wide.
    #[test]
    fn visits_every_close_pair_once() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        for &(width, periodic_y, spread) in &[
            (10.0, true, 10.0),
            (2.5, true, 2.5),
            (10.0, false, 1e6),
            (1.5, false, 30.0),
        ] {
            for x_periodic in [true, false] {
                let sides = if x_periodic {
                    SideBounds::Periodic { width }
                } else {
                    SideBounds::Walls { width, e: 1.0 }
                };
                let top = if periodic_y {
                    Top::Periodic { height: spread }
                } else {
                    Top::Open
                };
                let n = 300;
                let mut p: Vec<(f64, f64)> = (0..n)
                    .map(|_| (rng.random::<f64>() * width, rng.random::<f64>() * 20.0))
                    .collect();
                if !periodic_y {
                    p[0].1 = spread; // far above the rest
                } else {
                    for q in &mut p {
                        q.1 = q.1.rem_euclid(spread);
                    }
                }
                let size = 1.0;
                let mut cl = CellList::default();
                cl.build(n, |i| p[i], size, sides, top);
                let mut seen = std::collections::HashMap::new();
                cl.for_each_pair(|i, j| {
                    *seen.entry((i.min(j), i.max(j))).or_insert(0) += 1;
                });
                assert!(seen.values().all(|&k| k == 1), "a pair visited twice");
                let mut in_order = Vec::new();
                cl.for_each_pair(|i, j| in_order.push((i, j)));
                let threads = rayon::ThreadPoolBuilder::new()
                    .num_threads(3)
                    .build()
                    .unwrap();
                let shared = threads.install(|| cl.pairs_where(|i, j| Some((i, j))));
                assert_eq!(
                    shared, in_order,
                    "the threads changed the order of the pairs"
                );
                for i in 0..n {
                    for j in i + 1..n {
                        let (dx, dy) =
                            crate::schemes::min_image(sides, top, p[i].0 - p[j].0, p[i].1 - p[j].1);
                        if dx * dx + dy * dy < size * size {
                            assert!(seen.contains_key(&(i, j)), "missed {i} {j}");
                        }
                    }
                }
            }
        }
    }
}
