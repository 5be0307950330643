//! Time-averaged coarse-grained 2D fields on a grid over x and height: number density, packing
//! fraction, mean velocity, granular temperature per axis (and rotational, for rough disks).
//!
//! The fields are the height profiles' measurement cut into columns as well: the same samples
//! (after the warm-up), the same exact split of each disk's area over the cells it covers
//! ([`coverage`](super::coverage)), the same mass-weighted mean velocity and temperature about it.
//! Cell `(i, j)`: column `i` from the left wall (x = 0), row `j` from the grid's bottom.

use super::coverage::area_below_left;
use super::States;
use crate::physics::disks::Disks;
use serde::{Deserialize, Serialize};

/// The grid's geometry: `nx × ny` equal cells over `[0, width] × [bottom, top]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FieldGrid {
    /// Columns (across x).
    pub nx: usize,
    /// Rows (up the height).
    pub ny: usize,
    /// Width of the domain (the grid spans x from 0 to it).
    pub width: f64,
    /// Height of the grid's bottom (the floor's lowest point).
    pub bottom: f64,
    /// Height of the grid's top.
    pub top: f64,
    /// Periodic in x: a disk across x = 0 or x = width has its area split over both edges.
    pub periodic: bool,
}

impl FieldGrid {
    /// Cell sides `[dx, dy]`.
    pub fn cell(&self) -> [f64; 2] {
        [
            self.width / self.nx as f64,
            (self.top - self.bottom) / self.ny as f64,
        ]
    }

    /// Area of one cell.
    pub fn cell_area(&self) -> f64 {
        let [dx, dy] = self.cell();
        dx * dy
    }

    /// Centre `[x, y]` of cell `(i, j)`.
    pub fn centre(&self, i: usize, j: usize) -> [f64; 2] {
        let [dx, dy] = self.cell();
        [(i as f64 + 0.5) * dx, self.bottom + (j as f64 + 0.5) * dy]
    }

    /// Position of cell `(i, j)` in the flat arrays: x runs fastest (the order of VTK image data).
    pub fn index(&self, i: usize, j: usize) -> usize {
        j * self.nx + i
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// `true` for a grid without cells (never built by a run).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The cell holding point `(x, y)`, if it lies in the grid.
    fn cell_of(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        let [dx, dy] = self.cell();
        let (fi, fj) = ((x / dx).floor(), ((y - self.bottom) / dy).floor());
        let inside = fj >= 0.0 && fj < self.ny as f64 && fi.is_finite();
        // A centre on the right edge (x = width) belongs to the last column.
        inside.then(|| ((fi.max(0.0) as usize).min(self.nx - 1), fj as usize))
    }
}

/// Sums over the samples, per cell (flat, x fastest).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fields {
    grid: FieldGrid,
    /// Weight of the samples: their number (or a decaying count for a running average).
    samples: f64,
    count: Vec<f64>,
    area: Vec<f64>,
    mass: Vec<f64>,
    px: Vec<f64>,
    py: Vec<f64>,
    kx: Vec<f64>,
    ky: Vec<f64>,
    /// Σ I ω² per cell (rough disks; empty for smooth ones).
    krot: Vec<f64>,
    /// The quadrant areas at the corners of the cells one disk covers (reused).
    #[serde(skip)]
    corners: Vec<f64>,
}

impl Fields {
    /// Empty fields over `grid`.
    pub fn new(grid: FieldGrid) -> Fields {
        let z = vec![0.0; grid.len()];
        Fields {
            grid,
            samples: 0.0,
            count: z.clone(),
            area: z.clone(),
            mass: z.clone(),
            px: z.clone(),
            py: z.clone(),
            kx: z.clone(),
            ky: z,
            krot: Vec::new(),
            corners: Vec::new(),
        }
    }

    /// The grid's geometry.
    pub fn grid(&self) -> &FieldGrid {
        &self.grid
    }

    /// Number of instants added (rounded, for a running average).
    pub fn samples(&self) -> usize {
        self.samples.round() as usize
    }

    /// Adds the disks' states at one instant: each disk's centre counts in its cell (with its
    /// mass, momentum and kinetic energy), its area is split over the cells it covers.
    pub fn add(&mut self, states: &impl States, disks: &Disks) {
        self.samples += 1.0;
        let spins = states.spins();
        if spins.is_some() && self.krot.is_empty() {
            self.krot = vec![0.0; self.grid.len()];
        }
        states.each(|i, [x, y, vx, vy]| {
            let a = disks.radius[i];
            self.add_area(x, y, a);
            let m = disks.mass[i];
            let Some(k) = self.add_centre([x, y, vx, vy], m) else {
                return;
            };
            if let Some((q, spins)) = &spins {
                let w = spins[i].1;
                self.krot[k] += q * m * a * a * w * w;
            }
        });
    }

    /// Adds the disks' centres at one instant (count, mass, momentum, kinetic energy) without
    /// splitting their areas or reading their spins: the cheap coarse fields the bed's state
    /// reads (their packing fraction stays zero: read the number density).
    pub fn add_centres(&mut self, states: &impl States, disks: &Disks) {
        self.samples += 1.0;
        states.each(|i, s| {
            self.add_centre(s, disks.mass[i]);
        });
    }

    /// Counts a disk of mass `m` with state `[x, y, vx, vy]` in the cell of its centre (the
    /// cell's flat index; `None` outside the grid).
    fn add_centre(&mut self, [x, y, vx, vy]: [f64; 4], m: f64) -> Option<usize> {
        let (ci, cj) = self.grid.cell_of(x, y)?;
        let k = self.grid.index(ci, cj);
        self.count[k] += 1.0;
        self.mass[k] += m;
        self.px[k] += m * vx;
        self.py[k] += m * vy;
        self.kx[k] += m * vx * vx;
        self.ky[k] += m * vy * vy;
        Some(k)
    }

    /// Splits the area of a disk of radius `a` centred at `(x, y)` over the cells it covers
    /// (wrapped across x in a periodic domain; the parts outside the grid are not counted): a
    /// cell's part is the inclusion-exclusion of the disk's areas in the quadrants below-left
    /// of its four corners, each corner computed once for the cells sharing it.
    fn add_area(&mut self, x: f64, y: f64, a: f64) {
        let g = self.grid;
        let [dx, dy] = g.cell();
        let j_lo = ((y - a - g.bottom) / dy).floor().max(0.0);
        let j_hi = ((y + a - g.bottom) / dy).floor().min(g.ny as f64 - 1.0);
        let (i_lo, i_hi) = (((x - a) / dx).floor(), ((x + a) / dx).floor());
        if !(j_lo <= j_hi && i_lo <= i_hi) {
            return; // Wholly below or above the grid (or not a number).
        }
        let (j_lo, j_hi, i_lo, i_hi) = (j_lo as i64, j_hi as i64, i_lo as i64, i_hi as i64);
        let columns = (i_hi - i_lo + 2) as usize;
        self.corners.clear();
        for fj in j_lo..=j_hi + 1 {
            let cy = g.bottom + fj as f64 * dy - y;
            for fi in i_lo..=i_hi + 1 {
                self.corners
                    .push(area_below_left(fi as f64 * dx - x, cy, a));
            }
        }
        let corner = |fi: i64, fj: i64| ((fj - j_lo) as usize) * columns + (fi - i_lo) as usize;
        for fj in j_lo..=j_hi {
            for fi in i_lo..=i_hi {
                let column = if g.periodic {
                    fi.rem_euclid(g.nx as i64)
                } else {
                    fi
                };
                if !(0..g.nx as i64).contains(&column) {
                    continue;
                }
                let f = &self.corners;
                let part =
                    f[corner(fi + 1, fj + 1)] - f[corner(fi, fj + 1)] - f[corner(fi + 1, fj)]
                        + f[corner(fi, fj)];
                self.area[g.index(column as usize, fj as usize)] += part.max(0.0);
            }
        }
        self.corners.clear(); // Empty between disks: two equal fields compare equal.
    }

    /// The fields of one instant alone over the same grid; `self` is left as it is.
    pub fn of_instant(&self, states: &impl States, disks: &Disks) -> Fields {
        let mut one = Fields::new(self.grid);
        one.add(states, disks);
        one
    }

    /// Scales every sum (and the samples' weight) by `factor`: an exponential running average
    /// forgets its past by `factor` before the next instant is added.
    pub fn decay(&mut self, factor: f64) {
        self.samples *= factor;
        for v in [
            &mut self.count,
            &mut self.area,
            &mut self.mass,
            &mut self.px,
            &mut self.py,
            &mut self.kx,
            &mut self.ky,
            &mut self.krot,
        ] {
            v.iter_mut().for_each(|s| *s *= factor);
        }
    }

    /// Mean number of disk centres in cell `(i, j)`.
    pub fn mean_count(&self, i: usize, j: usize) -> f64 {
        self.count[self.grid.index(i, j)] / self.samples.max(f64::MIN_POSITIVE)
    }

    /// Number of disk centres per unit area in cell `(i, j)` (time-averaged).
    pub fn number_density(&self, i: usize, j: usize) -> f64 {
        self.mean_count(i, j) / self.grid.cell_area()
    }

    /// Fraction of cell `(i, j)` covered by disks (time-averaged).
    pub fn packing_fraction(&self, i: usize, j: usize) -> f64 {
        let k = self.grid.index(i, j);
        self.area[k] / (self.samples.max(f64::MIN_POSITIVE) * self.grid.cell_area())
    }

    /// Mass-weighted mean velocity `[ux, uy] = Σ m v / Σ m` over the disks seen in cell
    /// `(i, j)`; `None` where no disk was ever seen.
    pub fn mean_velocity(&self, i: usize, j: usize) -> Option<[f64; 2]> {
        let k = self.grid.index(i, j);
        let m = self.mass[k];
        (m > 0.0).then(|| [self.px[k] / m, self.py[k] / m])
    }

    /// Granular temperature per axis `Σ m (v − u)² / N` about the cell's mean velocity `u`;
    /// `None` where no disk was ever seen.
    pub fn temperature(&self, i: usize, j: usize) -> Option<[f64; 2]> {
        let k = self.grid.index(i, j);
        let (m, n) = (self.mass[k], self.count[k]);
        let t = |p: f64, kk: f64| ((kk - p * p / m) / n).max(0.0);
        (m > 0.0).then(|| [t(self.px[k], self.kx[k]), t(self.py[k], self.ky[k])])
    }

    /// Rotational temperature `Σ I ω² / N` of rough disks in cell `(i, j)`; `None` for smooth
    /// disks or where no disk was ever seen.
    pub fn rotational_temperature(&self, i: usize, j: usize) -> Option<f64> {
        let k = self.grid.index(i, j);
        (!self.krot.is_empty() && self.count[k] > 0.0).then(|| self.krot[k] / self.count[k])
    }

    /// `true` when the disks are rough (the fields carry a rotational temperature).
    pub fn rough(&self) -> bool {
        !self.krot.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    use crate::measure::Given;

    fn disks(n: usize) -> Disks {
        Disks::new(&vec![[0.0; 2]; n], vec![0.5; n], vec![1.0; n], vec![0; n])
    }

    fn grid(periodic: bool) -> FieldGrid {
        FieldGrid {
            nx: 4,
            ny: 3,
            width: 4.0,
            bottom: 0.0,
            top: 3.0,
            periodic,
        }
    }

    #[test]
    fn counts_area_velocity_and_temperature_per_cell() {
        let d = disks(3);
        let mut f = Fields::new(grid(true));
        // Two disks in cell (1, 1), moving apart in x; one across the periodic edge x = 0.
        f.add(
            &Given(vec![
                [1.5, 1.5, 1.0, 0.0],
                [1.5, 1.5, -1.0, 2.0],
                [0.1, 0.5, 0.0, 0.0],
            ]),
            &d,
        );
        assert_eq!(f.mean_count(1, 1), 2.0);
        assert_eq!(f.mean_velocity(1, 1), Some([0.0, 1.0]));
        assert_eq!(f.temperature(1, 1), Some([1.0, 1.0]));
        assert_eq!(f.mean_velocity(2, 2), None);
        // The disk at x = 0.1 has part of its area in the last column (wrapped).
        assert!(f.packing_fraction(3, 0) > 0.0);
        let total: f64 = (0..4)
            .flat_map(|i| (0..3).map(move |j| (i, j)))
            .map(|(i, j)| f.packing_fraction(i, j))
            .sum();
        assert!((total - 3.0 * PI * 0.25).abs() < 1e-13, "{total}");
        // With walls the part left of x = 0 is not counted.
        let mut w = Fields::new(grid(false));
        w.add(&Given(vec![[0.1, 0.5, 0.0, 0.0]]), &disks(1));
        assert_eq!(w.packing_fraction(3, 0), 0.0);
    }

    #[test]
    fn a_running_average_forgets_by_its_factor() {
        let d = disks(1);
        let mut f = Fields::new(grid(false));
        f.add(&Given(vec![[0.5, 0.5, 1.0, 0.0]]), &d);
        f.decay(0.5);
        f.add(&Given(vec![[0.5, 0.5, 3.0, 0.0]]), &d);
        // Weights ½ and 1: mean velocity (½·1 + 3)/1.5.
        let u = f.mean_velocity(0, 0).unwrap()[0];
        assert!((u - 3.5 / 1.5).abs() < 1e-15);
        assert!((f.mean_count(0, 0) - 1.0).abs() < 1e-15);
    }
}
