//! The summary of a run: the engine's counts and energies at the end, and what the driver
//! measured over the window after the warm-up — temperatures, the compressibility factor, the
//! floor's impacts and pressure, profiles, the phase-resolved motion, and the bed's state.

use super::averages::{Averages, Window};
use super::driver::Driver;
use super::views::{floor_tally, StatesAt};
use crate::engine::{EnergyFlow, Scene};
use crate::measure::phase::PhaseTable;
use crate::measure::state::{BedState, Indicators, StateName};
use crate::measure::{balance_error, Observables, ProfileTable};
use crate::output::summary::{
    Ending, EnergyAt, EnergySummary, EngineSummary, FloorPressure, FlowSummary, Summary,
};
use crate::physics::walls::Top;
use crate::scenario::{checks::mean_disk_area, Scenario, YBoundary};
use crate::schemes::Integrator;

/// The window after the warm-up, as the summary reads it: how long it lasted up to the end, and
/// the engine's tallies when it opened (`None` for a run that ended before its warm-up did).
type Measured<'w> = Option<(f64, &'w Window)>;

impl<E: Integrator> Driver<'_, E> {
    /// The summary of a run that ended at `end_time`.
    pub(super) fn summarise(&self, ending: Ending, end_time: f64, wall: f64) -> Summary {
        let (s, scene, sim) = (self.s, self.scene, &self.sim);
        let n = sim.disks().len();
        let last = Observables::of(&StatesAt(sim, end_time), sim.disks(), self.g);
        let flow = sim.energy_flow_at(end_time);
        let avg = &self.averages;
        let measured = avg
            .window
            .as_ref()
            .map(|w| (end_time - w.time, w))
            .filter(|(dt, _)| *dt > 0.0);
        let box_area = match scene.top {
            Top::Lid { height, .. } | Top::Periodic { height } => Some(s.domain.width * height),
            Top::Open => None,
        };
        let counts = sim.counts();
        // The engine knows the end of the last motion to the event, up to the end of the run.
        let at_rest_since = sim
            .at_rest_since()
            .or(self.at_rest_since.filter(|_| sim.disks_at_rest() == n));
        // Profiles and fields only once measured: a run that ended before its warm-up has none.
        let profiles = avg
            .profiles
            .as_ref()
            .filter(|p| p.samples() > 0)
            .map(|p| p.table());
        let phase = self.phase_table(end_time);
        let state = bed_state(
            scene,
            mean_disk_area(s),
            avg,
            at_rest_since.is_some(),
            (profiles.as_ref(), phase.as_ref()),
        );
        Summary {
            scenario: s.name.clone(),
            seed: s.seed,
            particles: n,
            ending,
            sim_time: end_time,
            wall_seconds: self.wall_before + wall,
            events: counts,
            collisions_per_second: counts.collisions() as f64 / (self.wall_before + wall).max(1e-9),
            energy: self.energy(&last, &flow),
            temperature: avg.temperature(),
            compressibility_factor: self.compressibility_factor(&last, measured),
            packing_fraction: box_area.map(|a| n as f64 * mean_disk_area(s) / a),
            max_overlap: sim.max_overlap(),
            com_height: scene.gravity.and(avg.com_height()),
            impacts_per_unit_time: match (&scene.floor, measured) {
                (Some(_), Some((dt, w))) => Some((counts.floor - w.floor_impacts) as f64 / dt),
                _ => None,
            },
            floor_pressure: self.floor_pressure(flow.floor_impulse, measured),
            at_rest_since,
            rest_wakes: Some(sim.rest_wakes()).filter(|&w| w > 0),
            profiles,
            phase,
            state,
            fields: avg.fields.clone().filter(|f| f.samples() > 0),
            velocity_distribution: avg.velocities.as_ref().and_then(|v| v.distribution()),
            engine: self.engine_summary(),
            approximation: sim.approximation(),
            output_failures: self.failures.list(),
            stall: sim.stall_report().map(str::to_owned),
            flow: sim.flow().map(|f| {
                let top = s.domain.exit_height.is_some();
                FlowSummary::of(&f, sim.disks().len(), top)
            }),
        }
    }

    /// The energies at the start and the end (`last`), what the floor injected and collisions
    /// dissipated (`flow`), what disks carried out and in, and how well the budget closes.
    fn energy(&self, last: &Observables, flow: &EnergyFlow) -> EnergySummary {
        let pool = self.sim.flow();
        EnergySummary {
            initial: EnergyAt::from(&self.initial),
            final_: EnergyAt::from(last),
            injected: flow.injected,
            dissipated: flow.dissipated,
            carried_out: pool.map(|f| f.energy_out),
            carried_in: pool.map(|f| f.energy_in),
            balance_error: balance_error(
                &self.initial,
                last,
                flow,
                pool.map_or(0.0, |f| f.energy_out - f.energy_in),
            ),
        }
    }

    /// Z = PA/NkT from the virial over the window, in a closed elastic box (where kT, from the
    /// kinetic energy at the end, is conserved).
    fn compressibility_factor(&self, last: &Observables, measured: Measured) -> Option<f64> {
        let (s, scene, sim) = (self.s, self.scene, &self.sim);
        let n = sim.disks().len();
        match (closed_elastic(s, scene), measured) {
            (true, Some((dt, w))) if self.averages.samples > 0 => {
                let kt = last.kinetic / n as f64; // conserved in a closed elastic box
                Some(1.0 + (sim.virial() - w.virial) / (2.0 * dt * n as f64 * kt))
            }
            _ => None,
        }
    }

    /// The pressure on the floor over the window (the momentum it gave, `impulse` so far, per
    /// time and width) against the bed's weight per width.
    fn floor_pressure(&self, impulse: f64, measured: Measured) -> Option<FloorPressure> {
        let (s, scene) = (self.s, self.scene);
        match (&scene.floor, scene.gravity, measured) {
            (Some(_), Some(g), Some((dt, w))) => {
                let mass: f64 = self.sim.disks().mass.iter().sum();
                Some(FloorPressure {
                    measured: (impulse - w.floor_impulse) / (dt * s.domain.width),
                    weight: mass * g / s.domain.width,
                })
            }
            _ => None,
        }
    }

    /// The motion against the floor's phase over the window, the piece of a bin from the last
    /// edge to `end_time` booked.
    fn phase_table(&self, end_time: f64) -> Option<PhaseTable> {
        match (&self.scene.floor, &self.averages.phase) {
            (Some(floor), Some(bins)) => {
                let mut bins = bins.clone();
                bins.book(self.stops.k_phase, floor_tally(&self.sim, end_time));
                Some(bins.table(floor, self.s.domain.width))
            }
            _ => None,
        }
    }

    /// How the engine was set up: scheme, mask, cells, grid, queue, re-mapping, memory, threads.
    fn engine_summary(&self) -> EngineSummary {
        let setup = self.sim.setup();
        EngineSummary {
            scheme: setup.scheme.into(),
            mask: setup.mask,
            cell: setup.cell,
            grid: setup.grid,
            queue: setup.queue,
            remap: setup.remap,
            bytes_per_disk: setup.bytes as f64 / self.sim.disks().len() as f64,
            threads: setup.threads,
            samples: self.averages.samples,
        }
    }
}

/// The bed's state (a floor under gravity, once samples were averaged), from the indicators of
/// the window: Γ, the disks at rest, the phase-resolved centre of mass, the height profiles.
fn bed_state(
    scene: &Scene,
    mean_area: f64,
    avg: &Averages,
    at_rest_at_end: bool,
    (profiles, phase): (Option<&ProfileTable>, Option<&PhaseTable>),
) -> Option<BedState> {
    let (floor, g) = (scene.floor.as_ref()?, scene.gravity?);
    if avg.samples == 0 {
        return None;
    }
    let indicators = Indicators {
        gamma: floor.drive().gamma(g),
        at_rest: avg.at_rest / avg.samples as f64,
        at_rest_at_end,
        com_locking: phase.and_then(|p| p.com_locking),
        com_locking_two_periods: phase.and_then(|p| p.com_locking_two_periods),
        undulation: phase.map(|p| p.undulation / (2.0 * (mean_area / std::f64::consts::PI).sqrt())),
        density_dip: None,
        max_packing: None,
        max_packing_height: None,
        circulation: None,
    };
    let indicators = match profiles {
        Some(p) => indicators.with_profiles(p, floor.drive().amplitude),
        None => indicators,
    };
    let state = BedState::of(match &avg.state_fields {
        Some(f) => indicators.with_fields(f, floor.drive().amplitude, mean_area),
        None => indicators,
    });
    // On a static floor the states of a shaken bed do not apply (a pour, a draining silo): no
    // state but a solid one; nor for a shaken bed whose motion against the floor's phase was not
    // resolved (too few periods in the window): bouncing or not, it cannot be told.
    let unresolved = floor.is_static()
        || state.indicators.com_locking.is_none()
        || state.indicators.com_locking_two_periods.is_none();
    (!unresolved || state.name == StateName::Solid).then_some(state)
}

/// `true` for a closed elastic box without gravity, where the compressibility factor is defined.
pub(super) fn closed_elastic(s: &Scenario, scene: &Scene) -> bool {
    scene.gravity.is_none()
        && s.domain.y_boundary != YBoundary::Open
        && !scene.restitution.inelastic()
        && s.domain.wall_restitution == 1.0
        && scene
            .floor
            .as_ref()
            .is_none_or(|f| f.is_static() && f.restitution == 1.0)
}
