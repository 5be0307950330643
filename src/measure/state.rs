//! The bed's state — solid, bouncing bed, undulations, Leidenfrost, convection or gas (the
//! states of vertically shaken beds named by Eshuis et al., PRL 95, 258001 (2005) and Phys.
//! Fluids 19, 123301 (2007)) — decided from indicators measured over the window, each against a
//! stated threshold.

use crate::measure::fields::Fields;
use crate::measure::ProfileTable;
use serde::Serialize;

/// Γ below which a floor never accelerates downwards faster than gravity: a bed resting on it
/// never takes off (the solid bed).
pub const SOLID_GAMMA: f64 = 1.0;
/// Mean fraction of the disks at rest (riding the floor or resting on disks at rest) above which
/// a bed on a floor with Γ < 1 is solid.
pub const SOLID_AT_REST: f64 = 0.5;
/// Share of the centre of mass's variance explained by the floor's phase above which the bed
/// moves with the floor's period as one body (the bouncing bed).
pub const BOUNCING_LOCKING: f64 = 0.5;
/// The packing fraction's minimum below its maximum, relative to the maximum, at or under which
/// the maximum floats on a distinctly more dilute layer (the Leidenfrost state): 20 % below,
/// well outside the few per cent the time-averaged profiles scatter by.
pub const LEIDENFROST_DIP: f64 = 0.8;
/// The packing fraction the floating maximum must reach to be a dense cluster, not a bump in a
/// gas: half the area covered (a time-averaged profile smears a moving cluster, so its crystal's
/// 0.8–0.9 is not asked for).
pub const LEIDENFROST_DENSE: f64 = 0.5;
/// Coherence of the vertical mean flow through the bed (see [`Indicators::circulation`]) above
/// which the bed convects: the same columns rise and sink through the bed.
pub const CONVECTION_CIRCULATION: f64 = 0.7;
/// Rows of cells apart that the circulation correlates.
pub const ROW_LAG: usize = 2;
/// The part of the bed's shape that swaps between periods (see [`Indicators::undulation`]), in
/// mean disk diameters, above which the bed undulates: 0.74–1.12 in the undulating beds we ran
/// (ten layers, arches 40 diameters apart swapping at each landing of a period-doubled bed),
/// 0–0.37 in 19 flat bouncing, period-doubled and convecting beds.
pub const UNDULATION_AMPLITUDE: f64 = 0.5;

/// Rows of the coarse fields whose mean packing fraction reaches this are part of the bed (for
/// the circulation): a dense gas, not the dilute layers above and below.
pub const BED_ROW_PACKING: f64 = 0.3;

/// The states a vibrated bed can be in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StateName {
    /// At rest on (and riding) a floor with Γ < 1.
    Solid,
    /// A compact bed thrown up and landing once per period, like one inelastic ball.
    BouncingBed,
    /// A bouncing bed whose height varies along x (standing waves).
    Undulations,
    /// A dense region floating on a dilute, hot layer next to the floor.
    Leidenfrost,
    /// A circulating mean flow (convection rolls).
    Convection,
    /// A fluidized bed whose density only falls with height.
    Gas,
}

/// What decided the state (absent: not measured in this run).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Indicators {
    /// Γ = Aω²/g of the floor (0 for a static floor).
    pub gamma: f64,
    /// Mean fraction of the disks at rest over the window's samples.
    pub at_rest: f64,
    /// Every disk at rest at every sample to the end (the summary's `at_rest_since` is set).
    pub at_rest_at_end: bool,
    /// The phase table's `com_locking` (a vibrating floor).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub com_locking: Option<f64>,
    /// The phase table's `com_locking_two_periods`: the bed's motion repeats every second period
    /// (period doubling) when it is well above `com_locking`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub com_locking_two_periods: Option<f64>,
    /// The phase table's `undulation` in mean disk diameters: the root mean square over the phase
    /// and the columns of the bed (about three diameters wide) of the part of the columns'
    /// heights that swaps every period or every second period.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub undulation: Option<f64>,
    /// The packing fraction's lowest value between the floor's highest point and the height of
    /// its maximum, over that maximum (1 when the maximum is next to the floor).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub density_dip: Option<f64>,
    /// The maximum of the time-averaged packing fraction above the floor's highest point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_packing: Option<f64>,
    /// The height of that maximum.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_packing_height: Option<f64>,
    /// How coherent the time-averaged vertical flow is through the bed: on a coarse grid (cells
    /// of about three diameters) the vertical mean velocity of each row of the bed, less the
    /// row's mean (a bed moving up and down as a whole does not circulate), correlated across x
    /// with the row's [`ROW_LAG`] rows up, averaged over such pairs. Rolls rise and sink in the
    /// same columns through the bed (near 1); noise does not (near 0; neighbouring cells' noise
    /// is correlated through collisions, hence rows two apart). In a steady state a
    /// time-averaged vertical flow that varies across x and carries no net mass is a
    /// circulation. Absent for beds of fewer than three rows of cells (about six layers).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub circulation: Option<f64>,
}

/// The summary's `state`: the name and the indicators that decided it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BedState {
    /// The state.
    pub name: StateName,
    /// What decided it.
    pub indicators: Indicators,
}

impl Indicators {
    /// The state, tried in this order: solid (Γ < 1, mostly at rest or all at rest at the end),
    /// undulations (a bed locked to two periods whose shape swaps between periods), convection (a circulating mean
    /// flow, in a bouncing bed or not), bouncing bed (locked to the period or to two periods),
    /// Leidenfrost (a dense region over a dilute layer), and gas otherwise. An indicator not
    /// measured decides nothing.
    pub fn state(&self) -> StateName {
        let above = |v: Option<f64>, t: f64| v.is_some_and(|v| v > t);
        let resting = self.at_rest >= SOLID_AT_REST || self.at_rest_at_end;
        if self.gamma < SOLID_GAMMA && resting {
            StateName::Solid
        } else if above(self.undulation, UNDULATION_AMPLITUDE)
            && above(self.com_locking_two_periods, BOUNCING_LOCKING)
        {
            StateName::Undulations
        } else if above(self.circulation, CONVECTION_CIRCULATION) {
            StateName::Convection
        } else if above(self.com_locking, BOUNCING_LOCKING)
            || above(self.com_locking_two_periods, BOUNCING_LOCKING)
        {
            StateName::BouncingBed
        } else if self.density_dip.is_some_and(|d| d <= LEIDENFROST_DIP)
            && self.max_packing.is_some_and(|m| m >= LEIDENFROST_DENSE)
        {
            StateName::Leidenfrost
        } else {
            StateName::Gas
        }
    }

    /// The indicators with the density dip read from the height profiles, above the floor's
    /// highest point `floor_top` (below it the floor takes up part of the bins).
    pub fn with_profiles(mut self, p: &ProfileTable, floor_top: f64) -> Indicators {
        let above: Vec<(f64, f64)> = p
            .height
            .iter()
            .zip(&p.packing_fraction)
            .filter(|(h, _)| **h >= floor_top)
            .map(|(h, f)| (*h, *f))
            .collect();
        let Some(top) = (0..above.len()).max_by(|&i, &j| above[i].1.total_cmp(&above[j].1)) else {
            return self;
        };
        let (height, max) = above[top];
        if max <= 0.0 {
            return self;
        }
        let below = above[..=top].iter().map(|a| a.1).fold(max, f64::min);
        self.density_dip = Some(below / max);
        self.max_packing = Some(max);
        self.max_packing_height = Some(height);
        self
    }
}

impl Indicators {
    /// The indicators with the circulation read from the coarse 2D
    /// fields of the disks' centres `f`, above the floor's highest point `floor_top`, for disks of
    /// mean area `area` (a cell's packing fraction is taken as its number density × `area`).
    pub fn with_fields(mut self, f: &Fields, floor_top: f64, area: f64) -> Indicators {
        let g = *f.grid();
        if f.samples() == 0 {
            return self;
        }
        let inner: Vec<usize> = if g.periodic || g.nx < 3 {
            (0..g.nx).collect()
        } else {
            (1..g.nx - 1).collect()
        };
        // The bed's rows, bottom to top: each row's vertical mean velocity less its mean across x.
        let mut flows: Vec<Vec<f64>> = Vec::new();
        for j in (0..g.ny).filter(|&j| g.centre(0, j)[1] >= floor_top) {
            let phi: Vec<f64> = inner
                .iter()
                .map(|&i| f.number_density(i, j) * area)
                .collect();
            let mean = phi.iter().sum::<f64>() / phi.len() as f64;
            if mean < BED_ROW_PACKING {
                continue;
            }
            let uy: Vec<f64> = (0..g.nx)
                .map(|i| f.mean_velocity(i, j).map_or(0.0, |u| u[1]))
                .collect();
            let mean = uy.iter().sum::<f64>() / uy.len() as f64;
            flows.push(uy.iter().map(|u| u - mean).collect());
        }
        let pairs: Vec<f64> = flows
            .windows(ROW_LAG + 1)
            .filter_map(|w| correlation(&w[0], &w[ROW_LAG]))
            .collect();
        if !pairs.is_empty() {
            self.circulation = Some(pairs.iter().sum::<f64>() / pairs.len() as f64);
        }
        self
    }
}

/// Pearson correlation of `a` and `b` (about zero means: they are deviations from their rows'
/// means); `None` when either is flat.
fn correlation(a: &[f64], b: &[f64]) -> Option<f64> {
    let dot = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(x, y)| x * y).sum::<f64>();
    let norm = (dot(a, a) * dot(b, b)).sqrt();
    (norm > 0.0).then(|| dot(a, b) / norm)
}

impl BedState {
    /// The state the indicators decide.
    pub fn of(indicators: Indicators) -> BedState {
        BedState {
            name: indicators.state(),
            indicators,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::fields::FieldGrid;
    use crate::physics::disks::Disks;

    use crate::measure::Given;

    /// A disk at the centre of every cell of a 4 × 6 grid of unit cells between walls, moving
    /// up with `vy(column, row)`.
    fn fields_of(vy: impl Fn(usize, usize) -> f64) -> Fields {
        let grid = FieldGrid {
            nx: 4,
            ny: 6,
            width: 4.0,
            bottom: 0.0,
            top: 6.0,
            periodic: false,
        };
        let states: Vec<[f64; 4]> = (0..24)
            .map(|k| {
                let (i, j) = (k % 4, k / 4);
                [i as f64 + 0.5, j as f64 + 0.5, 0.0, vy(i, j)]
            })
            .collect();
        let disks = Disks::new(
            &vec![[0.0; 2]; 24],
            vec![0.5; 24],
            vec![1.0; 24],
            vec![0; 24],
        );
        let mut f = Fields::new(grid);
        f.add_centres(&Given(states), &disks);
        f
    }

    #[test]
    fn rolls_circulate_and_a_rising_bed_does_not() {
        // Up on the left, down on the right, through the whole bed: two rolls' worth of flow.
        let rolls = base().with_fields(
            &fields_of(|i, _| if i < 2 { 1.0 } else { -1.0 }),
            0.0,
            0.785,
        );
        assert_eq!(rolls.circulation, Some(1.0));
        assert_eq!(rolls.state(), StateName::Convection);
        // The whole bed rising: no flow left once each row's mean is taken off.
        let rising = base().with_fields(&fields_of(|_, _| 1.0), 0.0, 0.785);
        assert_eq!(rising.circulation, None);
        // Up and down in columns that change from row to row (noise): no coherence two rows up.
        let noise = base().with_fields(
            &fields_of(|i, j| if (i + j / 2) % 2 == 0 { 1.0 } else { -1.0 }),
            0.0,
            0.785,
        );
        assert_eq!(noise.circulation, Some(-1.0));
    }

    fn base() -> Indicators {
        Indicators {
            gamma: 3.0,
            at_rest: 0.0,
            at_rest_at_end: false,
            com_locking: Some(0.1),
            com_locking_two_periods: Some(0.2),
            undulation: Some(0.1),
            density_dip: Some(1.0),
            max_packing: None,
            max_packing_height: None,
            circulation: None,
        }
    }

    #[test]
    fn each_indicator_decides_in_its_order() {
        assert_eq!(base().state(), StateName::Gas);
        let solid = Indicators {
            gamma: 0.5,
            at_rest: 0.9,
            ..base()
        };
        assert_eq!(solid.state(), StateName::Solid);
        let settled = Indicators {
            gamma: 0.5,
            at_rest: 0.2,
            at_rest_at_end: true,
            ..base()
        };
        assert_eq!(settled.state(), StateName::Solid);
        // Γ > 1: a bed at rest most of the time bounces.
        let riding = Indicators {
            gamma: 1.5,
            at_rest: 0.9,
            com_locking: Some(0.9),
            ..base()
        };
        assert_eq!(riding.state(), StateName::BouncingBed);
        // Landing every second period: a bouncing bed too.
        let doubled = Indicators {
            com_locking_two_periods: Some(0.9),
            ..base()
        };
        assert_eq!(doubled.state(), StateName::BouncingBed);
        let floating = Indicators {
            density_dip: Some(0.2),
            max_packing: Some(0.8),
            ..base()
        };
        assert_eq!(floating.state(), StateName::Leidenfrost);
        // A bump in a dilute gas is no floating cluster.
        let bump = Indicators {
            max_packing: Some(0.1),
            ..floating
        };
        assert_eq!(bump.state(), StateName::Gas);
        let rolls = Indicators {
            circulation: Some(0.9),
            ..floating
        };
        assert_eq!(rolls.state(), StateName::Convection);
        // Rolls in a bed that lands every second period: the rolls name it.
        let bouncing_rolls = Indicators {
            com_locking_two_periods: Some(0.9),
            ..rolls
        };
        assert_eq!(bouncing_rolls.state(), StateName::Convection);
        let waves = Indicators {
            undulation: Some(1.5),
            com_locking_two_periods: Some(0.9),
            ..base()
        };
        assert_eq!(waves.state(), StateName::Undulations);
        // Busy columns in a bed not locked to two periods (a gas): no undulations.
        let busy = Indicators {
            undulation: Some(1.5),
            com_locking_two_periods: Some(0.0),
            ..base()
        };
        assert_eq!(busy.state(), StateName::Gas);
    }

    #[test]
    fn the_dip_is_read_above_the_floor() {
        let p = |phi: Vec<f64>| ProfileTable {
            height: (0..phi.len()).map(|k| k as f64 + 0.5).collect(),
            density: phi.clone(),
            temperature_x: phi.clone(),
            temperature_y: phi.clone(),
            velocity_x: phi.clone(),
            velocity_y: phi.clone(),
            packing_fraction: phi,
            temperature_rotational: None,
            above_top: 0.0,
        };
        // Dense at the bottom, falling with height: no dip.
        let gas = base().with_profiles(&p(vec![0.5, 0.4, 0.2, 0.1]), 0.0);
        assert_eq!(gas.density_dip, Some(1.0));
        // A cluster at height 3.5 over a dilute layer (0.1 at 1.5); the bin under the floor's
        // top (0.05 at 0.5) does not count.
        let lf = base().with_profiles(&p(vec![0.05, 0.1, 0.4, 0.8, 0.2]), 1.0);
        assert_eq!(lf.density_dip, Some(0.125));
        assert_eq!(lf.max_packing_height, Some(3.5));
        assert_eq!(lf.state(), StateName::Leidenfrost);
    }
}
