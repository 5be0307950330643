//! The floor's drive: the shape of its vibration, its amplitude A and angular frequency
//! ω = 2π f, and what follows from them — the peak acceleration in units of gravity Γ = Aω²/g,
//! the period 2π/ω, the peak velocity Aω — and how impacts on it are located. One home for
//! these, read alike by the scenario (an amplitude given as Γ), the floor, the measurements, the
//! summary and the sweeps.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// Shape of the floor vibration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Waveform {
    /// `A sin(ωt + φ0)`.
    #[default]
    Sine,
    /// Piecewise-linear triangle wave with the same amplitude, period and phase convention.
    Triangle,
    /// Sawtooth: slow linear rise from −A to A over a period, then an instantaneous drop.
    Sawtooth,
}

/// How floor impacts are located.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum FloorModel {
    /// The moving floor, exactly.
    #[default]
    Exact,
    /// The floor stays at y = 0 for finding impacts; impacts use the moving floor's velocity.
    FixedPosition,
}

/// The floor's vibration: its shape, how impacts on it are located, how far and how fast.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drive {
    /// Shape of the vibration.
    pub waveform: Waveform,
    /// How impacts are located.
    pub model: FloorModel,
    /// Amplitude A (0 for a static floor).
    pub amplitude: f64,
    /// Angular frequency ω = 2π·frequency.
    pub omega: f64,
}

impl Drive {
    /// A sine of amplitude `amplitude` at `frequency` cycles per unit time, its impacts located
    /// exactly (see [`shaped`](Self::shaped) for the others).
    pub fn new(amplitude: f64, frequency: f64) -> Drive {
        Drive {
            waveform: Waveform::Sine,
            model: FloorModel::Exact,
            amplitude,
            omega: TAU * frequency,
        }
    }

    /// The sine whose peak acceleration is `gamma` times gravity `g` at `frequency`:
    /// A = Γ g/ω².
    pub fn of_gamma(gamma: f64, frequency: f64, g: f64) -> Drive {
        let omega = TAU * frequency;
        Drive::new(gamma * g / (omega * omega), frequency)
    }

    /// The same amplitude and frequency with the vibration's shape `waveform`, its impacts
    /// located by `model`.
    pub fn shaped(self, waveform: Waveform, model: FloorModel) -> Drive {
        Drive {
            waveform,
            model,
            ..self
        }
    }

    /// `true` when the floor does not move.
    #[inline]
    pub fn is_static(&self) -> bool {
        self.amplitude == 0.0 || self.omega == 0.0
    }

    /// Peak acceleration Aω² (of the sine).
    #[inline]
    pub fn peak_acceleration(&self) -> f64 {
        self.amplitude * self.omega * self.omega
    }

    /// Peak acceleration in units of gravity `g`, Γ = Aω²/g (0 for a static floor).
    pub fn gamma(&self, g: f64) -> f64 {
        if self.is_static() {
            0.0
        } else {
            self.peak_acceleration() / g
        }
    }

    /// The vibration period 2π/ω.
    pub fn period(&self) -> f64 {
        TAU / self.omega
    }

    /// Peak floor velocity Aω (of the sine): a bound on the floor's speed for every waveform.
    #[inline]
    pub fn peak_velocity(&self) -> f64 {
        self.amplitude * self.omega
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_and_amplitude_are_each_others_inverse() {
        let (f, g) = (2.5, 9.81);
        let d = Drive::of_gamma(3.0, f, g);
        assert!((d.gamma(g) - 3.0).abs() < 1e-15);
        assert!((d.period() - 0.4).abs() < 1e-15);
        assert_eq!(Drive::new(d.amplitude, f), d);
        assert_eq!(d.peak_velocity(), d.amplitude * TAU * f);
        assert_eq!(Drive::new(0.0, f).gamma(g), 0.0);
        assert!(Drive::new(0.1, 0.0).is_static());
    }
}
