//! What a run averages over its window (after the warm-up): temperatures, centre of mass, height
//! profiles.

use crate::engine::Scene;
use crate::measure::phase::PhaseBins;
use crate::measure::{Observables, Profiles, States};
use crate::output::summary::Temperature;
use crate::physics::disks::Disks;
use crate::scenario::Scenario;
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
}

impl Averages {
    /// Adds one sample (after the warm-up only).
    pub(super) fn add(&mut self, states: &impl States, disks: &Disks, o: &Observables) {
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
    }

    pub(super) fn temperature(&self) -> Temperature {
        let n = self.samples.max(1) as f64;
        Temperature {
            x: self.temperature[0] / n,
            y: self.temperature[1] / n,
            mean: 0.5 * (self.temperature[0] + self.temperature[1]) / n,
            rotational: self.rotational.map(|t| t / n),
        }
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
    scene.gravity?;
    let bottom = scene.floor.as_ref().map_or(0.0, |f| f.lowest());
    let top = s.output.profile_height.unwrap_or_else(|| {
        let mut highest = 0.0f64;
        states.each(|i, [_, y, _, _]| highest = highest.max(y + disks.radius[i]));
        2.0 * highest.max(bottom + 1.0)
    });
    Some(Profiles::new(
        s.output.profile_bins,
        bottom,
        top,
        s.domain.width,
    ))
}
