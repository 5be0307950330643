//! Initial states: radii and masses, non-overlapping positions, velocities from a temperature.
//!
//! Generated placements fill a rectangular region in rows (a triangular lattice for equal disks,
//! shuffled row-filling for mixtures), spread evenly to the requested packing fraction; `random`
//! then melts the lattice with hard-disk Monte Carlo sweeps (random trial moves rejected on
//! overlap), which reaches any packing fraction the lattice holds — up to 0.85 for equal disks —
//! in a few seconds for 10⁶ disks.

use crate::error::{Error, Result};
use crate::physics::walls::nearest_image;
use rand::Rng;
use rand_xoshiro::Xoshiro256PlusPlus;

use std::cell::Cell;
use std::sync::atomic::{AtomicBool, Ordering};

thread_local! {
    /// The flag that ends the Monte Carlo early (a run's stop flag, set by SIGINT): see
    /// [`interruptible`].
    static STOP: Cell<Option<&'static AtomicBool>> = const { Cell::new(None) };
}

/// Runs `f` (a scene's build) with the Monte Carlo that melts a `random` placement watching
/// `flag`: once it is set, the melt ends within `STOP_POLL` trial moves, its disks where they
/// are (every trial kept overlaps nothing, so they are placed, only less melted). A run asked
/// to stop while 2·10⁷ disks are being melted (two minutes on one core) stops at once instead.
pub fn interruptible<T>(flag: Option<&'static AtomicBool>, f: impl FnOnce() -> T) -> T {
    let before = STOP.with(|s| s.replace(flag));
    let out = f();
    STOP.with(|s| s.set(before));
    out
}

/// Runs `f` (a scene's build for `vibrobed check`) with `random` placements left unmelted, as
/// the lattice placed them: the Monte Carlo only moves disks to where they overlap nothing,
/// within the region the lattice fills, so it changes nothing a run's acceptance depends on,
/// while it is most of a check's time at 10⁶ disks.
pub fn unmelted<T>(f: impl FnOnce() -> T) -> T {
    static STOPPED: AtomicBool = AtomicBool::new(true);
    interruptible(Some(&STOPPED), f)
}

/// Trial moves between two looks at the stop flag.
const STOP_POLL: usize = 1 << 16;

/// Whether the flag [`interruptible`] gave is set.
fn stopped() -> bool {
    STOP.with(Cell::get)
        .is_some_and(|flag| flag.load(Ordering::Relaxed))
}

/// The map of the Monte Carlo's occupied cells over a sparse region.
type HashMap<K, V> = std::collections::HashMap<K, V, ahash::RandomState>;

/// The rectangle disk centres may occupy, and how it wraps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region {
    /// Left edge (disks touch it at most).
    pub x0: f64,
    /// Right edge.
    pub x1: f64,
    /// Bottom edge.
    pub y0: f64,
    /// Top edge.
    pub y1: f64,
    /// Periodic in x (then x1 − x0 is the period and disks may straddle the edges).
    pub x_periodic: bool,
    /// Periodic in y.
    pub y_periodic: bool,
}

/// Monte Carlo sweeps used to melt the lattice for `random` placement.
pub const MELT_SWEEPS: usize = 40;

/// Places disks of the given radii (in this order) in `region`, as a lattice spread evenly over
/// the region's height `fill_height` (≤ region height); `melt` runs MC sweeps afterwards.
pub fn place(
    radius: &[f64],
    region: Region,
    fill_height: f64,
    melt: bool,
    rng: &mut Xoshiro256PlusPlus,
) -> Result<Vec<[f64; 2]>> {
    let (a_min, a_max) = radius.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &a| {
        (lo.min(a), hi.max(a))
    });
    let mut pos = if a_max <= a_min * 1.0001 {
        triangular(radius.len(), a_max, region, fill_height)?
    } else {
        rows(radius, region, fill_height, rng)?
    };
    if melt && radius.len() > 1 {
        // The Monte Carlo region holds every disk the lattice placed.
        let highest = pos
            .iter()
            .zip(radius)
            .map(|(p, a)| p[1] + a)
            .fold(f64::NEG_INFINITY, f64::max);
        let top = (region.y0 + fill_height).max(highest);
        let confine = Region {
            y1: top.min(region.y1),
            ..region
        };
        melt_mc(&mut pos, radius, confine, MELT_SWEEPS, rng);
    }
    Ok(pos)
}

fn too_dense(n: usize) -> Error {
    Error::input(
        "particles.count",
        format!("{n} disks do not fit in the domain at this packing fraction"),
    )
}

/// A triangular lattice of `n` equal disks, as open as the region allows: the widest spacing
/// at which they fit, with the rows they need spread evenly over the fill height.
fn triangular(n: usize, a: f64, r: Region, fill_height: f64) -> Result<Vec<[f64; 2]>> {
    let width = r.x1 - r.x0;
    let lattice = Lattice {
        span_x: if r.x_periodic { width } else { width - 2.0 * a },
        span_y: if r.y_periodic {
            fill_height
        } else {
            fill_height - 2.0 * a
        },
        x_periodic: r.x_periodic,
        y_periodic: r.y_periodic,
    };
    let min_d = 2.0 * a * (1.0 + 1e-9);
    if lattice.capacity(min_d) < n {
        return Err(too_dense(n));
    }
    let lo = lattice.widest_spacing(n, min_d);
    let mut d = lo;
    let (even, odd, rows) = lattice.layout(d);
    if r.x_periodic {
        d = width / even as f64; // tile the period exactly
    }
    // Rows half a spacing apart sideways need only the pitch of the bisected spacing `lo ≤ d`
    // between them (d²/4 + 3 lo²/4 ≥ lo²): the rows then fit the height `capacity` assumed.
    let pitch_lo = row_pitch(lo);
    // Rows actually needed, spread evenly over the height.
    let mut needed = 0;
    let mut placed = 0;
    while placed < n {
        placed += if needed % 2 == 0 { even } else { odd };
        needed += 1;
    }
    let dy = if r.y_periodic {
        fill_height / rows as f64
    } else if needed > 1 {
        (lattice.span_y / (needed - 1) as f64)
            .min(2.0 * row_pitch(d))
            .max(pitch_lo)
    } else {
        pitch_lo
    };
    let x_start = if r.x_periodic {
        r.x0 + 0.25 * d
    } else {
        r.x0 + a
    };
    let y_start = if r.y_periodic {
        r.y0 + 0.25 * dy
    } else {
        r.y0 + a
    };
    let mut out = Vec::with_capacity(n);
    for row in 0..needed {
        let (cols, shift) = if row % 2 == 0 {
            (even, 0.0)
        } else {
            (odd, 0.5 * d)
        };
        for col in 0..cols {
            if out.len() < n {
                out.push([x_start + shift + col as f64 * d, y_start + row as f64 * dy]);
            }
        }
    }
    Ok(out)
}

/// Distance between the rows of a triangular lattice of spacing `d`: d·√3/2.
fn row_pitch(d: f64) -> f64 {
    d * 3f64.sqrt() / 2.0
}

/// Where the centres of a triangular lattice may lie: the spans in x and y (the width and the
/// fill height, less a radius at each hard edge) and how they wrap.
struct Lattice {
    span_x: f64,
    span_y: f64,
    x_periodic: bool,
    y_periodic: bool,
}

impl Lattice {
    /// Columns of even and odd (half-shifted) rows, and the number of rows, at spacing `d`.
    /// Periodic in x, even and odd rows hold the same columns; periodic in either direction,
    /// the rows come in pairs.
    fn layout(&self, d: f64) -> (usize, usize, usize) {
        if self.x_periodic {
            let cols = (self.span_x / d).floor() as usize;
            let rows = ((self.span_y / row_pitch(d)).floor() as usize) & !1;
            (cols, cols, rows)
        } else {
            let even = (self.span_x / d).floor() as usize + 1;
            let odd = if self.span_x >= 0.5 * d {
                ((self.span_x - 0.5 * d) / d).floor() as usize + 1
            } else {
                0
            };
            let rows = if self.y_periodic {
                ((self.span_y / row_pitch(d)).floor() as usize) & !1
            } else if self.span_y >= 0.0 {
                (self.span_y / row_pitch(d)).floor() as usize + 1
            } else {
                0
            };
            (even, odd, rows)
        }
    }

    /// How many disks the lattice of spacing `d` holds.
    fn capacity(&self, d: f64) -> usize {
        let (even, odd, rows) = self.layout(d);
        rows.div_ceil(2) * even + (rows / 2) * odd
    }

    /// The widest spacing, from `min_d` up, at which `n` disks still fit (100 bisections).
    fn widest_spacing(&self, n: usize, min_d: f64) -> f64 {
        let (mut lo, mut hi) = (min_d, min_d + 2.0 * (self.span_x + self.span_y));
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if self.capacity(mid) >= n {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }
}

/// Shuffled disks filled into rows left to right, each row as tall as its largest disk.
fn rows(
    radius: &[f64],
    r: Region,
    fill_height: f64,
    rng: &mut Xoshiro256PlusPlus,
) -> Result<Vec<[f64; 2]>> {
    let n = radius.len();
    let width = r.x1 - r.x0;
    let mut order: Vec<usize> = (0..n).collect();
    for k in (1..n).rev() {
        order.swap(k, rng.random_range(0..=k));
    }
    // Fill rows.
    let mut rows: Vec<Vec<usize>> = vec![Vec::new()];
    let mut used = 0.0;
    for &i in &order {
        let w = 2.0 * radius[i] * (1.0 + 1e-9);
        if used + w > width && !rows.last().unwrap().is_empty() {
            rows.push(Vec::new());
            used = 0.0;
        }
        if w > width {
            return Err(too_dense(n));
        }
        rows.last_mut().unwrap().push(i);
        used += w;
    }
    let heights: Vec<f64> = rows
        .iter()
        .map(|row| row.iter().map(|&i| 2.0 * radius[i]).fold(0.0, f64::max) * (1.0 + 1e-9))
        .collect();
    let total: f64 = heights.iter().sum();
    if total > fill_height {
        return Err(too_dense(n));
    }
    let gap_y = (fill_height - total) / rows.len() as f64;
    let mut out = vec![[0.0; 2]; n];
    let mut y = r.y0 + 0.5 * gap_y;
    for (row, h) in rows.iter().zip(&heights) {
        let row_width: f64 = row.iter().map(|&i| 2.0 * radius[i] * (1.0 + 1e-9)).sum();
        let gap_x = (width - row_width) / row.len() as f64;
        let mut x = r.x0 + 0.5 * gap_x;
        for &i in row {
            out[i] = [x + radius[i], y + 0.5 * h];
            x += 2.0 * radius[i] * (1.0 + 1e-9) + gap_x;
        }
        y += h + gap_y;
    }
    Ok(out)
}

/// Hard-disk Monte Carlo: each sweep tries one random move per disk (in storage order, which
/// follows the lattice rows and keeps memory access local) and rejects any move that overlaps
/// another disk or leaves the region. The step adapts towards half acceptance. Cells of side
/// ≥ 2 a_max hold their disks in fixed-size slots of one flat array (or, over a region too
/// sparse for that, a list per occupied cell).
pub fn melt_mc(
    pos: &mut [[f64; 2]],
    radius: &[f64],
    r: Region,
    sweeps: usize,
    rng: &mut Xoshiro256PlusPlus,
) {
    let n = pos.len();
    let a_max = radius.iter().fold(0.0f64, |hi, &a| hi.max(a));
    let mut grid = McGrid::new(pos, radius, r);
    let mut step = 0.5 * a_max;
    for _ in 0..sweeps {
        let Some(accepted) = mc_sweep(pos, radius, &mut grid, step, rng) else {
            return;
        };
        let rate = accepted as f64 / n as f64;
        step = (step * if rate > 0.5 { 1.2 } else { 0.8 }).clamp(1e-3 * a_max, 0.9 * grid.cell);
    }
}

/// One Monte Carlo sweep: a trial move per disk, in storage order, kept when the disk stays
/// in the region and overlaps no other; returns how many were kept. Each trial draws two
/// uniform numbers (x, then y) whether or not it is kept. `None`: stopped on the way by the
/// flag of [`interruptible`].
fn mc_sweep(
    pos: &mut [[f64; 2]],
    radius: &[f64],
    grid: &mut McGrid,
    step: f64,
    rng: &mut Xoshiro256PlusPlus,
) -> Option<usize> {
    let mut accepted = 0usize;
    for i in 0..pos.len() {
        if i % STOP_POLL == 0 && stopped() {
            return None;
        }
        let Some(p) = grid.trial_position(pos[i], radius[i], step, rng) else {
            continue;
        };
        let c = grid.cell_of(p);
        if !grid.overlaps(pos, radius, i, p, c) {
            accepted += 1;
            pos[i] = p;
            grid.move_disk(i, c);
        }
    }
    Some(accepted)
}

/// The Monte Carlo's cell grid over the region, and the cell each disk is filed in.
struct McGrid {
    /// The region the disks stay in.
    r: Region,
    /// Its width and height.
    width: f64,
    height: f64,
    /// Side of the cells before fitting them to the region, 2 a_max.
    cell: f64,
    /// Cells across and up, and their width and height.
    ncx: usize,
    ncy: usize,
    cw: f64,
    ch: f64,
    /// The disks of each cell.
    cells: CellSlots,
    /// The cell of each disk.
    home: Vec<usize>,
}

impl McGrid {
    /// Cells of side ≥ 2 a_max over the region, so that a disk can only overlap disks in its
    /// own and the eight neighbouring cells, with every disk filed in its cell. When fixed
    /// slots for every cell would take more than [`MAX_FLAT_SLOTS`] (a sparse region), only
    /// the occupied cells hold a list, in a map: memory follows the disks, and a trial move
    /// still looks at the disks within 2 a_max of it only. (Cells once merged until there were
    /// about 4 per disk: disks in rows at one end of a wide region, as a bed 10⁶ times wider
    /// than deep, then shared a few coarse cells, and each trial looked at thousands of them —
    /// minutes of Monte Carlo.)
    fn new(pos: &[[f64; 2]], radius: &[f64], r: Region) -> McGrid {
        let n = pos.len();
        let (a_min, a_max) = radius.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &a| {
            (lo.min(a), hi.max(a))
        });
        let width = r.x1 - r.x0;
        let height = r.y1 - r.y0;
        let cell = 2.0 * a_max;
        // Lengths are at most `MAX_LENGTH_RATIO` smallest radii (the scenario's checks): the
        // cells number at most 10¹⁸ and are indexed in a usize.
        let ncx = (width / cell).floor().clamp(1.0, 1e9) as usize;
        let ncy = (height / cell).floor().clamp(1.0, 1e9) as usize;
        // Centres in one cell are ≥ 2 a_min apart: at most (⌊side/(2 a_min)⌋ + 1)² of them.
        let per_side = |ncx: usize, ncy: usize| {
            let side = (width / ncx as f64).max(height / ncy as f64);
            (side / (2.0 * a_min)).floor() as usize + 1
        };
        let p = per_side(ncx, ncy);
        let flat = ncx
            .saturating_mul(ncy)
            .saturating_mul(p.saturating_mul(p) + 1)
            <= MAX_FLAT_SLOTS;
        let cap = if flat { p * p } else { 0 };
        let mut grid = McGrid {
            r,
            width,
            height,
            cell,
            ncx,
            ncy,
            cw: width / ncx as f64,
            ch: height / ncy as f64,
            cells: CellSlots::new(ncx * ncy, cap, flat),
            home: Vec::with_capacity(n),
        };
        for (i, &p) in pos.iter().enumerate() {
            let c = grid.cell_of(p);
            grid.cells.insert(c, i as u32);
            grid.home.push(c);
        }
        grid
    }

    /// The cell holding point `p` (points on or past an edge go to the edge's cells).
    #[inline]
    fn cell_of(&self, p: [f64; 2]) -> usize {
        let r = &self.r;
        let cx = (((p[0] - r.x0) / self.cw).max(0.0) as usize).min(self.ncx - 1);
        let cy = (((p[1] - r.y0) / self.ch).max(0.0) as usize).min(self.ncy - 1);
        cy * self.ncx + cx
    }

    /// A trial position for a disk of radius `a` at `from`, uniform in a square of half-side
    /// `step`: wrapped into a periodic region, or `None` where it would cross a hard edge.
    #[inline]
    fn trial_position(
        &self,
        from: [f64; 2],
        a: f64,
        step: f64,
        rng: &mut Xoshiro256PlusPlus,
    ) -> Option<[f64; 2]> {
        let r = &self.r;
        let mut p = [
            from[0] + step * (2.0 * rng.random::<f64>() - 1.0),
            from[1] + step * (2.0 * rng.random::<f64>() - 1.0),
        ];
        if r.x_periodic {
            p[0] = r.x0 + (p[0] - r.x0).rem_euclid(self.width);
        } else if p[0] < r.x0 + a || p[0] > r.x1 - a {
            return None;
        }
        if r.y_periodic {
            p[1] = r.y0 + (p[1] - r.y0).rem_euclid(self.height);
        } else if p[1] < r.y0 + a || p[1] > r.y1 - a {
            return None;
        }
        Some(p)
    }

    /// Whether disk `i`, moved to `p` in cell `c`, would overlap another disk: any in cell `c`
    /// or its eight neighbours (wrapped where the region is periodic), nearest images compared.
    #[inline]
    fn overlaps(&self, pos: &[[f64; 2]], radius: &[f64], i: usize, p: [f64; 2], c: usize) -> bool {
        let r = &self.r;
        let (cx, cy) = ((c % self.ncx) as i64, (c / self.ncx) as i64);
        for ddy in -1..=1i64 {
            for ddx in -1..=1i64 {
                let Some(k) = self.neighbour(cx + ddx, cy + ddy) else {
                    continue;
                };
                for &j in self.cells.members(k) {
                    let j = j as usize;
                    if j == i {
                        continue;
                    }
                    let mut dx = p[0] - pos[j][0];
                    let mut dy = p[1] - pos[j][1];
                    if r.x_periodic {
                        dx = nearest_image(dx, self.width);
                    }
                    if r.y_periodic {
                        dy = nearest_image(dy, self.height);
                    }
                    let s = (radius[i] + radius[j]) * (1.0 + 1e-9);
                    if dx * dx + dy * dy < s * s {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// The cell at column `x`, row `y`, wrapped in a periodic direction; `None` beyond a hard
    /// edge.
    #[inline]
    fn neighbour(&self, mut x: i64, mut y: i64) -> Option<usize> {
        if x < 0 || x >= self.ncx as i64 {
            if !self.r.x_periodic {
                return None;
            }
            x = x.rem_euclid(self.ncx as i64);
        }
        if y < 0 || y >= self.ncy as i64 {
            if !self.r.y_periodic {
                return None;
            }
            y = y.rem_euclid(self.ncy as i64);
        }
        Some(y as usize * self.ncx + x as usize)
    }

    /// Files disk `i` under cell `c` (where it has just moved).
    fn move_disk(&mut self, i: usize, c: usize) {
        let old = self.home[i];
        if c != old {
            self.cells.remove(old, i as u32);
            self.cells.insert(c, i as u32);
            self.home[i] = c;
        }
    }
}

/// Most words the Monte Carlo grid may hold as fixed-size slots (256 MiB); a sparser region
/// gets a list per occupied cell.
const MAX_FLAT_SLOTS: usize = 1 << 26;

/// The disks in each cell of the Monte Carlo grid.
enum CellSlots {
    /// `cap` slots per cell in one flat array, and the count of each cell (dense regions: fast).
    Flat {
        cap: usize,
        count: Vec<u32>,
        slots: Vec<u32>,
    },
    /// A list per occupied cell, by cell (sparse regions: memory follows the disks, not the
    /// area).
    Lists(HashMap<usize, Vec<u32>>),
}

impl CellSlots {
    fn new(cells: usize, cap: usize, flat: bool) -> CellSlots {
        if flat {
            CellSlots::Flat {
                cap,
                count: vec![0; cells],
                slots: vec![0; cells * cap],
            }
        } else {
            CellSlots::Lists(HashMap::default())
        }
    }

    #[inline]
    fn members(&self, c: usize) -> &[u32] {
        match self {
            CellSlots::Flat { cap, count, slots } => &slots[c * cap..c * cap + count[c] as usize],
            CellSlots::Lists(lists) => lists.get(&c).map_or(&[], Vec::as_slice),
        }
    }

    fn insert(&mut self, c: usize, i: u32) {
        match self {
            CellSlots::Flat { cap, count, slots } => {
                slots[c * *cap + count[c] as usize] = i;
                count[c] += 1;
            }
            CellSlots::Lists(lists) => lists.entry(c).or_default().push(i),
        }
    }

    fn remove(&mut self, c: usize, i: u32) {
        let members: &mut [u32] = match self {
            CellSlots::Flat { cap, count, slots } => {
                count[c] -= 1;
                &mut slots[c * *cap..c * *cap + count[c] as usize + 1]
            }
            CellSlots::Lists(lists) => lists.get_mut(&c).expect("disk in its cell"),
        };
        let k = members
            .iter()
            .position(|&m| m == i)
            .expect("disk in its cell");
        let last = members.len() - 1;
        members.swap(k, last);
        if let CellSlots::Lists(lists) = self {
            let list = lists.get_mut(&c).expect("disk in its cell");
            list.pop();
            if list.is_empty() {
                lists.remove(&c);
            }
        }
    }
}

/// Standard normal deviate (Box–Muller).
pub(crate) fn gaussian(rng: &mut Xoshiro256PlusPlus) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>(); // (0, 1]
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// Maxwellian velocities at granular temperature `temperature` (kT per degree of freedom):
/// zero total momentum when there are at least two disks, then rescaled so that the kinetic
/// energy is exactly `N·temperature` (2 degrees of freedom × ½kT each).
pub fn thermal_velocities(
    mass: &[f64],
    temperature: f64,
    rng: &mut Xoshiro256PlusPlus,
) -> Vec<[f64; 2]> {
    let n = mass.len();
    let mut v: Vec<[f64; 2]> = mass
        .iter()
        .map(|&m| {
            let s = (temperature / m).sqrt();
            [s * gaussian(rng), s * gaussian(rng)]
        })
        .collect();
    if temperature == 0.0 {
        return vec![[0.0; 2]; n];
    }
    if n > 1 {
        let total: f64 = mass.iter().sum();
        let px: f64 = mass.iter().zip(&v).map(|(m, v)| m * v[0]).sum::<f64>() / total;
        let py: f64 = mass.iter().zip(&v).map(|(m, v)| m * v[1]).sum::<f64>() / total;
        for vi in &mut v {
            vi[0] -= px;
            vi[1] -= py;
        }
    }
    let ke: f64 = mass
        .iter()
        .zip(&v)
        .map(|(m, v)| 0.5 * m * (v[0] * v[0] + v[1] * v[1]))
        .sum();
    if ke > 0.0 {
        let scale = (n as f64 * temperature / ke).sqrt();
        for vi in &mut v {
            vi[0] *= scale;
            vi[1] *= scale;
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn min_distance_ratio(pos: &[[f64; 2]], radius: &[f64], period: Option<(f64, f64)>) -> f64 {
        let mut worst = f64::INFINITY;
        for i in 0..pos.len() {
            for j in 0..i {
                let mut dx = pos[i][0] - pos[j][0];
                let mut dy = pos[i][1] - pos[j][1];
                if let Some((w, h)) = period {
                    dx = nearest_image(dx, w);
                    dy = nearest_image(dy, h);
                }
                worst = worst.min((dx * dx + dy * dy).sqrt() / (radius[i] + radius[j]));
            }
        }
        worst
    }

    #[test]
    fn dense_periodic_random_placement_has_no_overlap() {
        // φ = 0.7: 400 disks of radius 0.5 in a square of side √(400 π/4 / 0.7).
        let n = 400;
        let side = (n as f64 * std::f64::consts::PI * 0.25 / 0.7).sqrt();
        let region = Region {
            x0: 0.0,
            x1: side,
            y0: 0.0,
            y1: side,
            x_periodic: true,
            y_periodic: true,
        };
        let radius = vec![0.5; n];
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        let pos = place(&radius, region, side, true, &mut rng).unwrap();
        assert_eq!(pos.len(), n);
        assert!(min_distance_ratio(&pos, &radius, Some((side, side))) >= 1.0);
    }

    /// A stop flag already set leaves the lattice unmelted: the Monte Carlo looks at it before
    /// its first trial; unset, the same placement melts (the disks move). A check's placement
    /// ([`unmelted`]) is the lattice.
    #[test]
    fn a_set_stop_flag_ends_the_melt_before_it_moves_a_disk() {
        static SET: AtomicBool = AtomicBool::new(true);
        static UNSET: AtomicBool = AtomicBool::new(false);
        let radius = vec![0.5; 200];
        let region = Region {
            x0: 0.0,
            x1: 20.0,
            y0: 0.0,
            y1: 20.0,
            x_periodic: true,
            y_periodic: false,
        };
        let lattice = place(
            &radius,
            region,
            20.0,
            false,
            &mut Xoshiro256PlusPlus::seed_from_u64(1),
        );
        let placed = |flag: &'static AtomicBool| {
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
            interruptible(Some(flag), || place(&radius, region, 20.0, true, &mut rng))
        };
        assert_eq!(placed(&SET).unwrap(), lattice.as_ref().unwrap().clone());
        assert_ne!(placed(&UNSET).unwrap(), lattice.as_ref().unwrap().clone());
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
        let checked = unmelted(|| place(&radius, region, 20.0, true, &mut rng));
        assert_eq!(checked.unwrap(), lattice.unwrap(), "a check's placement");
    }

    /// A bed of 400 disks in rows at one end of a region 2·10⁸ radii wide (the Monte Carlo's
    /// sparse grid, a list per occupied cell) melts without overlap and within the region.
    #[test]
    fn a_row_in_a_very_wide_region_melts_without_overlap() {
        let radius = vec![0.5; 400];
        let region = Region {
            x0: 0.0,
            x1: 1e8,
            y0: 0.0,
            y1: f64::INFINITY,
            x_periodic: true,
            y_periodic: false,
        };
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(2);
        let pos = place(&radius, region, 3.0, true, &mut rng).unwrap();
        assert!(min_distance_ratio(&pos, &radius, Some((1e8, 1e300))) >= 1.0);
        assert!(pos.iter().all(|p| p[1] >= 0.5 && p[1] <= 3.0 - 0.5 + 1e-9));
    }

    #[test]
    fn mixtures_fill_rows_without_overlap() {
        let radius: Vec<f64> = (0..300)
            .map(|i| if i % 3 == 0 { 0.7 } else { 0.5 })
            .collect();
        let region = Region {
            x0: 0.0,
            x1: 30.0,
            y0: 0.0,
            y1: 30.0,
            x_periodic: false,
            y_periodic: false,
        };
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        let pos = place(&radius, region, 30.0, true, &mut rng).unwrap();
        assert!(min_distance_ratio(&pos, &radius, None) >= 1.0);
        for (p, a) in pos.iter().zip(&radius) {
            assert!(p[0] >= a - 1e-12 && p[0] <= 30.0 - a + 1e-12);
            assert!(p[1] >= a - 1e-12 && p[1] <= 30.0 - a + 1e-12);
        }
    }

    #[test]
    fn thermal_velocities_have_zero_momentum_and_exact_energy() {
        let mass = vec![1.0, 2.0, 3.0, 1.5];
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let v = thermal_velocities(&mass, 2.0, &mut rng);
        let px: f64 = mass.iter().zip(&v).map(|(m, v)| m * v[0]).sum();
        let ke: f64 = mass
            .iter()
            .zip(&v)
            .map(|(m, v)| 0.5 * m * (v[0] * v[0] + v[1] * v[1]))
            .sum();
        assert!(px.abs() < 1e-12);
        assert!((ke - 8.0).abs() < 1e-12);
    }
}
