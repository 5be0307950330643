//! What a run averages over its window (after the warm-up): temperatures, centre of mass, height
//! profiles.

use crate::engine::Scene;
use crate::measure::fields::{FieldGrid, Fields};
use crate::measure::phase::PhaseBins;
use crate::measure::velocities::Velocities;
use crate::measure::{Observables, Profiles, States};
use crate::output::summary::Temperature;
use crate::physics::disks::Disks;
use crate::scenario::{checks::mean_disk_area, Scenario, XBoundary};
use serde::{Deserialize, Serialize};

/// The window over which averages are taken (from the end of the warm-up).
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub(super) struct Window {
    pub(super) time: f64,
    pub(super) virial: f64,
    pub(super) floor_impacts: u64,
    /// Vertical momentum the floor had given the disks when the window opened.
    pub(super) floor_impulse: f64,
}

/// What is averaged over the window: temperatures, centre of mass, height profiles.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct Averages {
    pub(super) window: Option<Window>,
    pub(super) temperature: [f64; 2],
    /// Σ of the rotational temperature over the samples (rough disks).
    pub(super) rotational: Option<f64>,
    pub(super) com_height: f64,
    pub(super) samples: usize,
    pub(super) profiles: Option<Profiles>,
    /// The motion against the floor's phase (a vibrating floor under gravity), from the window's
    /// start.
    #[serde(default)]
    pub(super) phase: Option<PhaseBins>,
    /// Σ of the fraction of disks at rest over the samples.
    #[serde(default)]
    pub(super) at_rest: f64,
    /// Coarse 2D fields of the disks' centres for the bed's state (a floor under gravity):
    /// always measured, at every sample (no area split: cheap).
    #[serde(default)]
    pub(super) state_fields: Option<Fields>,
    /// The 2D fields, when asked (`run --fields`).
    pub(super) fields: Option<Fields>,
    /// The velocities by height band, for their scaled distributions
    /// (`output.velocity_distribution`).
    pub(super) velocities: Option<Velocities>,
}

impl Averages {
    /// Nothing averaged yet, in the bins, fields and bands the scene asks for (`fields`: the
    /// 2D fields of `run --fields`), laid out from the disks' states at the start.
    pub(super) fn new(
        s: &Scenario,
        scene: &Scene,
        states: &impl States,
        disks: &Disks,
        fields: bool,
    ) -> Averages {
        Averages {
            window: None,
            temperature: [0.0; 2],
            rotational: None,
            com_height: 0.0,
            samples: 0,
            profiles: empty_profiles(s, scene, states, disks),
            phase: None,
            at_rest: 0.0,
            state_fields: state_grid(s, scene, states, disks).map(Fields::new),
            fields: fields
                .then(|| field_grid(s, scene, states, disks))
                .flatten()
                .map(Fields::new),
            velocities: (s.output.velocity_distribution)
                .then(|| empty_velocities(s, scene, states, disks)),
        }
    }

    /// Measures one sample of `states` under gravity `g` and adds it (after the warm-up only).
    pub(super) fn add(&mut self, states: &impl States, disks: &Disks, g: f64) {
        let o = Observables::of(states, disks, g);
        self.temperature[0] += o.temperature[0];
        self.temperature[1] += o.temperature[1];
        if let Some(t) = o.rotational_temperature(disks.len()) {
            *self.rotational.get_or_insert(0.0) += t;
        }
        self.com_height += o.com_height;
        self.samples += 1;
        if let Some(p) = self.profiles.as_mut() {
            p.add(states, disks);
        }
        if let Some(f) = self.fields.as_mut() {
            f.add(states, disks);
        }
        if let Some(f) = self.state_fields.as_mut() {
            f.add_centres(states, disks);
        }
        if let Some(v) = self.velocities.as_mut() {
            v.add(states);
        }
    }

    /// The temperatures averaged over the samples; `None` before the first.
    pub(super) fn temperature(&self) -> Option<Temperature> {
        if self.samples == 0 {
            return None;
        }
        let n = self.samples as f64;
        Some(Temperature {
            x: self.temperature[0] / n,
            y: self.temperature[1] / n,
            mean: 0.5 * (self.temperature[0] + self.temperature[1]) / n,
            rotational: self.rotational.map(|t| t / n),
            local: self
                .profiles
                .as_ref()
                .and_then(|p| p.table().local_temperature()),
        })
    }

    /// The mean centre-of-mass height over the samples; `None` before the first.
    pub(super) fn com_height(&self) -> Option<f64> {
        (self.samples > 0).then(|| self.com_height / self.samples as f64)
    }
}

/// Empty height profiles for a gravity scene: from the floor's lowest point to
/// `output.profile_height` (default: twice the highest disk top at the start).
pub(super) fn empty_profiles(
    s: &Scenario,
    scene: &Scene,
    states: &impl States,
    disks: &Disks,
) -> Option<Profiles> {
    let (bottom, top) = profile_range(s, scene, states, disks)?;
    Some(Profiles::new(
        s.output.profile_bins,
        bottom,
        top,
        s.domain.width,
    ))
}

/// The heights the profiles span in a gravity scene: from the floor's lowest point to
/// `output.profile_height` (default: twice the highest disk top at the start).
fn profile_range(
    s: &Scenario,
    scene: &Scene,
    states: &impl States,
    disks: &Disks,
) -> Option<(f64, f64)> {
    scene.gravity?;
    let bottom = scene.floor.as_ref().map_or(0.0, |f| f.lowest());
    let top = s.output.profile_height.unwrap_or_else(|| {
        let mut highest = 0.0f64;
        states.each(|i, [_, y, _, _]| highest = highest.max(y + disks.radius[i]));
        2.0 * highest.max(bottom + 1.0)
    });
    Some((bottom, top))
}

/// Empty velocity distributions: by the profiles' height bins in a gravity scene, else one band
/// (the whole box); the finest raw resolution is set from the initial rms speed (or 1).
pub(super) fn empty_velocities(
    s: &Scenario,
    scene: &Scene,
    states: &impl States,
    disks: &Disks,
) -> Velocities {
    let bands = profile_range(s, scene, states, disks)
        .map(|(bottom, top)| (bottom, top, s.output.profile_bins));
    let (mut v2, mut n) = (0.0, 0.0f64);
    states.each(|_, [_, _, vx, vy]| {
        v2 += vx * vx + vy * vy;
        n += 1.0;
    });
    let rms = (v2 / n.max(1.0)).sqrt();
    Velocities::new(bands, if rms > 0.0 { rms } else { 1.0 })
}

/// Side of the cells of the state's coarse fields, in mean disk diameters, and most cells a side.
const STATE_CELL_DIAMETERS: f64 = 3.0;
const STATE_BINS_MAX: usize = 40;

/// The coarse grid of the fields the bed's state reads (a floor under gravity): over the
/// profiles' range, cells of about three mean diameters (at most 40 a side): coarse enough that
/// every cell of the bed holds several disks per sample, fine enough for rolls a few diameters
/// across.
pub(super) fn state_grid(
    s: &Scenario,
    scene: &Scene,
    states: &impl States,
    disks: &Disks,
) -> Option<FieldGrid> {
    scene.floor.as_ref()?;
    let (bottom, top) = profile_range(s, scene, states, disks)?;
    let cell = STATE_CELL_DIAMETERS * 2.0 * (mean_disk_area(s) / std::f64::consts::PI).sqrt();
    let bins = |length: f64| ((length / cell).round() as usize).clamp(1, STATE_BINS_MAX);
    Some(FieldGrid {
        nx: bins(s.domain.width),
        ny: bins(top - bottom),
        width: s.domain.width,
        bottom,
        top,
        periodic: s.domain.x_boundary == XBoundary::Periodic,
    })
}

/// Most cells a side of the default fields' grid.
const DEFAULT_FIELD_BINS_MAX: usize = 200;

/// The 2D fields' grid of a gravity scene: across the width, from the profiles' bottom to
/// `output.field_height` (default: the profiles' top), in `output.field_bins` cells (default:
/// square-ish cells about two mean disk diameters wide, at most 200 a side).
pub(super) fn field_grid(
    s: &Scenario,
    scene: &Scene,
    states: &impl States,
    disks: &Disks,
) -> Option<FieldGrid> {
    let (bottom, profile_top) = profile_range(s, scene, states, disks)?;
    let top = s.output.field_height.unwrap_or(profile_top);
    let [nx, ny] = s.output.field_bins.unwrap_or_else(|| {
        let cell = 4.0 * (mean_disk_area(s) / std::f64::consts::PI).sqrt();
        let bins =
            |length: f64| ((length / cell).round() as usize).clamp(1, DEFAULT_FIELD_BINS_MAX);
        [bins(s.domain.width), bins(top - bottom)]
    });
    Some(FieldGrid {
        nx,
        ny,
        width: s.domain.width,
        bottom,
        top,
        periodic: s.domain.x_boundary == XBoundary::Periodic,
    })
}
