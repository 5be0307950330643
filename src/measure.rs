//! Measurements (output plugins): energies, granular temperature, centre of mass, height
//! profiles, sampled at exact times from snapshots and averaged after the warm-up.

use crate::disks::Disks;
use crate::simulation::Snapshot;
use serde::Serialize;

/// Instantaneous observables of one snapshot.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct Observables {
    /// Σ ½ m v².
    pub kinetic: f64,
    /// Σ m g y (zero without gravity).
    pub potential: f64,
    /// Granular temperature per axis: Σ m (v − V)² / N with V the mass-weighted mean velocity.
    pub temperature: [f64; 2],
    /// Mean height of the disks' centres (mass-weighted).
    pub com_height: f64,
}

impl Observables {
    /// Measures a snapshot of `disks` under gravity `g`.
    pub fn of(snap: &Snapshot, disks: &Disks, g: f64) -> Observables {
        let n = disks.len() as f64;
        let (mut m_sum, mut px, mut py, mut ke, mut my) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for i in 0..disks.len() {
            let m = disks.mass[i];
            let (vx, vy) = (snap.vx[i], snap.vy[i]);
            m_sum += m;
            px += m * vx;
            py += m * vy;
            ke += 0.5 * m * (vx * vx + vy * vy);
            my += m * snap.y[i];
        }
        let (ux, uy) = (px / m_sum, py / m_sum);
        let (mut tx, mut ty) = (0.0, 0.0);
        for i in 0..disks.len() {
            let m = disks.mass[i];
            tx += m * (snap.vx[i] - ux).powi(2);
            ty += m * (snap.vy[i] - uy).powi(2);
        }
        Observables {
            kinetic: ke,
            potential: g * my,
            temperature: [tx / n, ty / n],
            com_height: my / m_sum,
        }
    }

    /// Kinetic plus potential energy.
    pub fn energy(&self) -> f64 {
        self.kinetic + self.potential
    }
}

/// Time-averaged height profiles in equal bins between `bottom` and `top`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Profiles {
    bottom: f64,
    top: f64,
    width: f64,
    samples: usize,
    count: Vec<f64>,
    area: Vec<f64>,
    mass: Vec<f64>,
    px: Vec<f64>,
    py: Vec<f64>,
    kx: Vec<f64>,
    ky: Vec<f64>,
    above: f64,
}

/// Averaged profiles, one value per bin (the JSON and CSV form).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProfileTable {
    /// Bin centres (height).
    pub height: Vec<f64>,
    /// Number of disk centres per unit area.
    pub density: Vec<f64>,
    /// Fraction of the bin's area covered by disks (centres counted: a disk's whole area goes
    /// to the bin of its centre).
    pub packing_fraction: Vec<f64>,
    /// Granular temperature in x, relative to the bin's mean velocity (mass-weighted).
    pub temperature_x: Vec<f64>,
    /// Granular temperature in y, relative to the bin's mean velocity.
    pub temperature_y: Vec<f64>,
    /// Mean velocity x (mass-weighted).
    pub velocity_x: Vec<f64>,
    /// Mean velocity y (mass-weighted).
    pub velocity_y: Vec<f64>,
    /// Mean number of disks above the top bin.
    pub above_top: f64,
}

impl Profiles {
    /// Empty profiles with `bins` bins over `[bottom, top]` across a domain of `width`.
    pub fn new(bins: usize, bottom: f64, top: f64, width: f64) -> Profiles {
        let z = vec![0.0; bins];
        Profiles {
            bottom,
            top,
            width,
            samples: 0,
            count: z.clone(),
            area: z.clone(),
            mass: z.clone(),
            px: z.clone(),
            py: z.clone(),
            kx: z.clone(),
            ky: z,
            above: 0.0,
        }
    }

    /// Adds one snapshot.
    pub fn add(&mut self, snap: &Snapshot, disks: &Disks) {
        let bins = self.count.len();
        let h = (self.top - self.bottom) / bins as f64;
        self.samples += 1;
        for i in 0..disks.len() {
            let k = ((snap.y[i] - self.bottom) / h).floor();
            if k >= bins as f64 {
                self.above += 1.0;
                continue;
            }
            let k = k.max(0.0) as usize;
            let m = disks.mass[i];
            let a = disks.radius[i];
            self.count[k] += 1.0;
            self.area[k] += std::f64::consts::PI * a * a;
            self.mass[k] += m;
            self.px[k] += m * snap.vx[i];
            self.py[k] += m * snap.vy[i];
            self.kx[k] += m * snap.vx[i] * snap.vx[i];
            self.ky[k] += m * snap.vy[i] * snap.vy[i];
        }
    }

    /// The profiles of `snap` alone over the same bins (the live profiles of a recorded frame);
    /// `self` is left as it is.
    pub fn of_snapshot(&self, snap: &Snapshot, disks: &Disks) -> ProfileTable {
        let mut one = Profiles::new(self.count.len(), self.bottom, self.top, self.width);
        one.add(snap, disks);
        one.table()
    }

    /// Number of snapshots added.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// The averaged profiles.
    pub fn table(&self) -> ProfileTable {
        let bins = self.count.len();
        let h = (self.top - self.bottom) / bins as f64;
        let s = self.samples.max(1) as f64;
        let bin_area = h * self.width;
        let per = |f: &dyn Fn(usize) -> f64| (0..bins).map(f).collect::<Vec<f64>>();
        let temp = |k: usize, p: &[f64], kk: &[f64]| {
            if self.count[k] > 0.0 {
                (kk[k] - p[k] * p[k] / self.mass[k]) / self.count[k]
            } else {
                0.0
            }
        };
        ProfileTable {
            height: per(&|k| self.bottom + (k as f64 + 0.5) * h),
            density: per(&|k| self.count[k] / (s * bin_area)),
            packing_fraction: per(&|k| self.area[k] / (s * bin_area)),
            temperature_x: per(&|k| temp(k, &self.px, &self.kx)),
            temperature_y: per(&|k| temp(k, &self.py, &self.ky)),
            velocity_x: per(&|k| {
                if self.mass[k] > 0.0 {
                    self.px[k] / self.mass[k]
                } else {
                    0.0
                }
            }),
            velocity_y: per(&|k| {
                if self.mass[k] > 0.0 {
                    self.py[k] / self.mass[k]
                } else {
                    0.0
                }
            }),
            above_top: self.above / s,
        }
    }
}

impl ProfileTable {
    /// The profiles as CSV, one row per bin.
    pub fn to_csv(&self) -> String {
        let mut out = String::from(
            "height,density,packing_fraction,temperature_x,temperature_y,velocity_x,velocity_y\n",
        );
        for k in 0..self.height.len() {
            out.push_str(&format!(
                "{},{},{},{},{},{},{}\n",
                self.height[k],
                self.density[k],
                self.packing_fraction[k],
                self.temperature_x[k],
                self.temperature_y[k],
                self.velocity_x[k],
                self.velocity_y[k]
            ));
        }
        out
    }
}

/// Henderson's equation of state for hard disks, `Z = (1 + φ²/8)/(1 − φ)²`.
pub fn henderson_z(phi: f64) -> f64 {
    (1.0 + phi * phi / 8.0) / ((1.0 - phi) * (1.0 - phi))
}
