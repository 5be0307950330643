//! Measurements (output plugins): energies, granular temperature, centre of mass, height
//! profiles, sampled at exact times and averaged after the warm-up.

pub mod coverage;
pub mod fields;
pub mod phase;
pub mod state;
pub mod velocities;

use crate::engine::{EnergyFlow, Snapshot};
use crate::physics::disks::Disks;
use coverage::area_below;
use serde::Serialize;

/// The disks' states at one instant, as a measurement reads them: from a snapshot, or from an
/// engine observed on the fly (no copy of every state).
pub trait States {
    /// Calls `f(i, [x, y, vx, vy])` for every disk `i` (the scenario's numbering), in an
    /// order of the source's choosing.
    fn each(&self, f: impl FnMut(usize, [f64; 4]));
    /// `Σ ½ I ω²` of rough disks at the same instant (spins are constant between events);
    /// `None` for smooth disks, or where the source does not know the spins.
    fn rotational_energy(&self) -> Option<f64> {
        None
    }
    /// Rough disks at the same instant: the inertia factor q and each disk's `(angle, ω)` in
    /// the scenario's numbering; `None` for smooth disks or a source that does not know them.
    fn spins(&self) -> Option<(f64, Vec<(f64, f64)>)> {
        None
    }
}

impl States for Snapshot {
    fn each(&self, mut f: impl FnMut(usize, [f64; 4])) {
        for i in 0..self.x.len() {
            f(i, [self.x[i], self.y[i], self.vx[i], self.vy[i]]);
        }
    }
}

/// Disks given as `[x, y, vx, vy]`: the states the measurements' unit tests read.
#[cfg(test)]
pub(crate) struct Given(pub(crate) Vec<[f64; 4]>);

#[cfg(test)]
impl States for Given {
    fn each(&self, mut f: impl FnMut(usize, [f64; 4])) {
        self.0.iter().enumerate().for_each(|(i, s)| f(i, *s));
    }
}

/// Instantaneous observables of the disks at one instant.
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
    /// Σ ½ I ω² of rough disks (`None` for smooth ones).
    pub rotational: Option<f64>,
}

impl Observables {
    /// Measures the states of `disks` under gravity `g` (two passes: the mean velocity, then
    /// the temperature about it).
    pub fn of(states: &impl States, disks: &Disks, g: f64) -> Observables {
        let n = disks.len() as f64;
        let (mut m_sum, mut px, mut py, mut ke, mut my) = (0.0, 0.0, 0.0, 0.0, 0.0);
        states.each(|i, [_, y, vx, vy]| {
            let m = disks.mass[i];
            m_sum += m;
            px += m * vx;
            py += m * vy;
            ke += 0.5 * m * (vx * vx + vy * vy);
            my += m * y;
        });
        let (ux, uy) = (px / m_sum, py / m_sum);
        let (mut tx, mut ty) = (0.0, 0.0);
        states.each(|i, [_, _, vx, vy]| {
            let m = disks.mass[i];
            tx += m * (vx - ux).powi(2);
            ty += m * (vy - uy).powi(2);
        });
        Observables {
            kinetic: ke,
            potential: g * my,
            temperature: [tx / n, ty / n],
            com_height: my / m_sum,
            rotational: states.rotational_energy(),
        }
    }

    /// Kinetic (translational and rotational) plus potential energy.
    pub fn energy(&self) -> f64 {
        match self.rotational {
            Some(r) => self.kinetic + self.potential + r,
            None => self.kinetic + self.potential,
        }
    }

    /// The rotational temperature `Σ I ω² / N` of rough disks (one degree of freedom each).
    pub fn rotational_temperature(&self, n: usize) -> Option<f64> {
        self.rotational.map(|r| 2.0 * r / n.max(1) as f64)
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
    /// Σ I ω² per bin (rough disks; empty for smooth ones).
    #[serde(default)]
    krot: Vec<f64>,
    above: f64,
}

/// Averaged profiles, one value per bin (the JSON and CSV form).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProfileTable {
    /// Bin centres (height).
    pub height: Vec<f64>,
    /// Number of disk centres per unit area.
    pub density: Vec<f64>,
    /// Fraction of the bin's area covered by disks: each disk's area is split exactly over
    /// the bins it covers, so the fraction never exceeds 1 (a bin thinner than a disk may exceed
    /// the densest packing, which bounds averages over several diameters only).
    pub packing_fraction: Vec<f64>,
    /// Granular temperature in x, relative to the bin's mean velocity (mass-weighted); this,
    /// the other temperatures and the velocities are NaN in a bin no disk centre entered
    /// (null in the summary, `NaN` in the CSV).
    pub temperature_x: Vec<f64>,
    /// Granular temperature in y, relative to the bin's mean velocity.
    pub temperature_y: Vec<f64>,
    /// Mean velocity x (mass-weighted).
    pub velocity_x: Vec<f64>,
    /// Mean velocity y (mass-weighted).
    pub velocity_y: Vec<f64>,
    /// Rotational temperature `Σ I ω² / N` of the bin's rough disks (absent for smooth ones).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub temperature_rotational: Option<Vec<f64>>,
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
            krot: Vec::new(),
            above: 0.0,
        }
    }

    /// Adds the disks' states at one instant.
    pub fn add(&mut self, states: &impl States, disks: &Disks) {
        let bins = self.count.len();
        let h = (self.top - self.bottom) / bins as f64;
        self.samples += 1;
        let spins = states.spins();
        if spins.is_some() && self.krot.is_empty() {
            self.krot = vec![0.0; bins];
        }
        states.each(|i, [_, y, vx, vy]| {
            self.add_area(y, disks.radius[i], h);
            let k = ((y - self.bottom) / h).floor();
            if k >= bins as f64 {
                self.above += 1.0;
                return;
            }
            let k = k.max(0.0) as usize;
            let m = disks.mass[i];
            self.count[k] += 1.0;
            self.mass[k] += m;
            self.px[k] += m * vx;
            self.py[k] += m * vy;
            self.kx[k] += m * vx * vx;
            self.ky[k] += m * vy * vy;
            if let Some((q, spins)) = &spins {
                let (a, w) = (disks.radius[i], spins[i].1);
                self.krot[k] += q * m * a * a * w * w;
            }
        });
    }

    /// Splits the area of a disk of radius `a` centred at height `y` over the bins of height
    /// `h` it covers (the parts below the bottom or above the top are not counted).
    fn add_area(&mut self, y: f64, a: f64, h: f64) {
        let bins = self.count.len();
        let lo = ((y - a - self.bottom) / h).floor().max(0.0);
        let hi = ((y + a - self.bottom) / h).floor().min(bins as f64 - 1.0);
        if lo.is_nan() || hi.is_nan() || lo > hi {
            return;
        }
        let (lo, hi) = (lo as usize, hi as usize);
        let mut below = area_below(self.bottom + lo as f64 * h - y, a);
        for k in lo..=hi {
            let next = area_below(self.bottom + (k + 1) as f64 * h - y, a);
            self.area[k] += next - below;
            below = next;
        }
    }

    /// The profiles of one instant alone over the same bins (the live profiles of a recorded
    /// frame); `self` is left as it is.
    pub fn of_instant(&self, states: &impl States, disks: &Disks) -> ProfileTable {
        let mut one = Profiles::new(self.count.len(), self.bottom, self.top, self.width);
        one.add(states, disks);
        one.table()
    }

    /// Number of instants added.
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
        // A bin no disk centre entered has no velocity or temperature: NaN (null in the
        // summary, `NaN` in the CSV), never a 0 that reads as a measurement.
        let temp = |k: usize, p: &[f64], kk: &[f64]| {
            if self.count[k] > 0.0 {
                (kk[k] - p[k] * p[k] / self.mass[k]) / self.count[k]
            } else {
                f64::NAN
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
                    f64::NAN
                }
            }),
            velocity_y: per(&|k| {
                if self.mass[k] > 0.0 {
                    self.py[k] / self.mass[k]
                } else {
                    f64::NAN
                }
            }),
            temperature_rotational: (!self.krot.is_empty()).then(|| {
                per(&|k| {
                    if self.count[k] > 0.0 {
                        self.krot[k] / self.count[k]
                    } else {
                        f64::NAN
                    }
                })
            }),
            above_top: self.above / s,
        }
    }
}

impl ProfileTable {
    /// The local granular temperature: each bin's temperature ((x + y)/2, about the bin's own
    /// mean velocity) averaged over the bins with their density as weight; unlike the whole
    /// bed's temperature it leaves out the flow between heights (the bed's rise and fall with
    /// the floor), as the literature's T(h) fits do. `None` when no bin held a disk.
    pub fn local_temperature(&self) -> Option<f64> {
        let (mut sum, mut weight) = (0.0, 0.0);
        for k in (0..self.height.len()).filter(|&k| self.density[k] > 0.0) {
            let t = 0.5 * (self.temperature_x[k] + self.temperature_y[k]);
            sum += self.density[k] * t;
            weight += self.density[k];
        }
        (weight > 0.0).then(|| sum / weight)
    }

    /// The profiles as CSV, one row per bin.
    /// Rough disks add a last column, `temperature_rotational`.
    pub fn to_csv(&self) -> String {
        let mut out = String::from(
            "height,density,packing_fraction,temperature_x,temperature_y,velocity_x,velocity_y",
        );
        out.push_str(match self.temperature_rotational {
            Some(_) => ",temperature_rotational\n",
            None => "\n",
        });
        for k in 0..self.height.len() {
            out.push_str(&format!(
                "{},{},{},{},{},{},{}",
                self.height[k],
                self.density[k],
                self.packing_fraction[k],
                self.temperature_x[k],
                self.temperature_y[k],
                self.velocity_x[k],
                self.velocity_y[k]
            ));
            if let Some(t) = &self.temperature_rotational {
                out.push_str(&format!(",{}", t[k]));
            }
            out.push('\n');
        }
        out
    }
}

/// |now − initial − injected + dissipated + carried out − carried in| relative to the largest
/// term of the energy budget (`out`: the energy disks that left carried out, less what entering
/// disks brought in).
pub fn balance_error(initial: &Observables, now: &Observables, flow: &EnergyFlow, out: f64) -> f64 {
    let balance = now.energy() - initial.energy() - flow.injected + flow.dissipated + out;
    let scale = initial
        .energy()
        .abs()
        .max(now.energy().abs())
        .max(flow.injected.abs())
        .max(flow.dissipated)
        .max(out.abs())
        .max(f64::MIN_POSITIVE);
    balance.abs() / scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_disk_is_split_over_the_bins_it_covers() {
        let pi = std::f64::consts::PI;
        assert_eq!(area_below(-2.0, 1.0), 0.0);
        assert!((area_below(0.0, 1.0) - 0.5 * pi).abs() < 1e-15);
        assert!((area_below(5.0, 1.0) - pi).abs() < 1e-15);
        // Radius 0.5 centred on the boundary of two bins of height 0.5: half in each.
        let mut p = Profiles::new(4, 0.0, 2.0, 1.0);
        p.add_area(1.0, 0.5, 0.5);
        let quarter = 0.125 * pi;
        assert!((p.area[1] - quarter).abs() < 1e-15 && (p.area[2] - quarter).abs() < 1e-15);
        assert_eq!((p.area[0], p.area[3]), (0.0, 0.0));
        // Radius 0.5 centred in a bin of height 0.25 covers parts of five bins, adding up.
        let mut p = Profiles::new(8, 0.0, 2.0, 1.0);
        p.add_area(0.875, 0.5, 0.25);
        let covered: Vec<usize> = (0..8).filter(|&k| p.area[k] > 0.0).collect();
        assert_eq!(covered, vec![1, 2, 3, 4, 5]);
        assert!((p.area.iter().sum::<f64>() - 0.25 * pi).abs() < 1e-14);
        // Only the part above the bottom counts.
        let mut p = Profiles::new(2, 0.0, 1.0, 1.0);
        p.add_area(0.0, 0.5, 0.5);
        assert!((p.area.iter().sum::<f64>() - 0.125 * pi).abs() < 1e-15);
    }

    #[test]
    fn a_dense_row_never_exceeds_full_coverage() {
        // A row of touching disks (radius 0.5, one per unit width) in bins of height 0.1: a bin
        // through the centres is covered by the chords, just under 1; counting each disk's
        // whole area in the bin of its centre gave π/4 / 0.1 = 7.85.
        let mut p = Profiles::new(20, 0.0, 2.0, 1.0);
        p.samples = 1;
        p.add_area(1.0, 0.5, 0.1);
        let phi = p.table().packing_fraction;
        assert!(phi.iter().all(|&f| f <= 1.0), "{phi:?}");
        let max = phi.iter().cloned().fold(0.0, f64::max);
        assert!(max > 0.95, "{phi:?}");
    }
}
