//! The speeds a scene starts its disks with (explicit velocities, temperatures, spins, inlets,
//! the floor's peak speed): each finite, with finite energies, and sending no disk farther over
//! the run than [`MAX_TRAVEL`] smallest radii. Beyond that the run would need more events than
//! any computer gives it, and a disk crossing a radius faster than the clock resolves would
//! leave the clock standing still.

use super::limits::{MAX_TRAVEL, MIN_MAGNITUDE};
use super::{Inlet, Placement, Radius, Scenario};
use crate::error::{Error, Result};

/// Largest speed accepted: its square times the heaviest mass stays finite.
const MAX_SPEED: f64 = 1e100;

/// Checks every speed the scene gives its disks, naming the field that sets it.
pub fn validate_speeds(s: &Scenario) -> Result<()> {
    let bound = Travel::of(s);
    given_speeds(s)
        .iter()
        .try_for_each(|g| bound.check(&g.field, g.what, g.speed))
}

/// The scene's own speed and the field that sets it: the fastest speed it gives a disk
/// (`given_speeds`), or √(g a_min), the speed of a disk that fell its smallest radius, when
/// that is faster (no field then; 0 when nothing moves: no speed, no gravity, no moving
/// floor). The time-step scheme's default step is a tenth of the time a disk takes to cross
/// its smallest radius at this speed.
pub fn natural_speed(s: &Scenario) -> (f64, Option<String>) {
    let fall = (s.gravity.unwrap_or(0.0) * s.all_radius_range().0).sqrt();
    given_speeds(s)
        .into_iter()
        .filter(|g| g.speed > fall)
        .max_by(|a, b| a.speed.total_cmp(&b.speed))
        .map_or((fall, None), |g| (g.speed, Some(g.field)))
}

/// A speed the scene gives its disks: the field that sets it, what it is, and its value.
struct Given {
    field: String,
    what: &'static str,
    speed: f64,
}

/// Every speed the scene starts or brings disks with, and the floor's peak speed, in the
/// file's order (so the first that breaks a bound is always the same one).
fn given_speeds(s: &Scenario) -> Vec<Given> {
    let given = |field: &str, what, speed| Given {
        field: field.to_string(),
        what,
        speed,
    };
    let mut out = Vec::new();
    if let Placement::Explicit(e) = &s.particles.placement {
        let fastest = e
            .velocities
            .iter()
            .flatten()
            .map(|[vx, vy]| vx.hypot(*vy))
            .map(|v| if v.is_nan() { f64::INFINITY } else { v })
            .fold(0.0, f64::max);
        out.push(given(
            "particles.placement.velocities",
            "a velocity",
            fastest,
        ));
    }
    let lightest = lightest(s);
    let p = &s.particles;
    out.push(given(
        "particles.temperature",
        "a thermal speed √(T/m)",
        (p.temperature / lightest).sqrt(),
    ));
    if let Some(t) = p.rotational_temperature {
        let q = p.inertia_factor.unwrap_or(0.5);
        out.push(given(
            "particles.rotational_temperature",
            "a rim speed √(T_rot/(q m))",
            (t / (q * lightest)).sqrt(),
        ));
    }
    for (k, inlet) in s.inlets.iter().enumerate() {
        out.push(given(&format!("inlets.{k}.speed"), "a speed", inlet.speed));
        let thermal = (inlet.temperature / lightest_entering(s, inlet)).sqrt();
        out.push(given(
            &format!("inlets.{k}.temperature"),
            "a thermal speed √(T/m)",
            thermal,
        ));
    }
    if let Some(floor) = s.floor.as_ref().filter(|f| f.frequency.is_some()) {
        let peak = floor.drive(s.gravity).peak_velocity();
        let field = match floor.gamma {
            Some(_) => "floor.gamma",
            None => "floor.frequency",
        };
        out.push(given(field, "a floor peak speed Aω", peak));
    }
    out
}

/// The farthest a disk may travel over the run, and the run it is measured on.
struct Travel {
    /// The run's duration.
    duration: f64,
    /// The smallest radius of any disk of the scene.
    a_min: f64,
}

impl Travel {
    fn of(s: &Scenario) -> Travel {
        Travel {
            duration: s.run.duration,
            a_min: s.all_radius_range().0,
        }
    }

    /// `speed` (what it is: `what`, set by `field`) is finite, at most [`MAX_SPEED`], and
    /// carries a disk at most [`MAX_TRAVEL`] smallest radii over the run.
    fn check(&self, field: &str, what: &str, speed: f64) -> Result<()> {
        let radii = speed * self.duration / self.a_min;
        if speed.is_finite() && speed <= MAX_SPEED && radii <= MAX_TRAVEL {
            return Ok(());
        }
        Err(Error::input(
            field,
            format!(
                "gives {what} of {speed:e}, which carries a disk {radii:.3e} smallest radii in \
                 run.duration = {}: at most {MAX_TRAVEL:e} can be simulated (and speeds up to \
                 {MAX_SPEED:e})",
                self.duration
            ),
        ))
    }
}

/// The lightest disk at the start (a species' own mass included), at least [`MIN_MAGNITUDE`].
fn lightest(s: &Scenario) -> f64 {
    let (lo, hi) = s.radius_range();
    let mut m = s.particle_mass(lo, None).min(s.particle_mass(hi, None));
    if let Radius::Species(list) = &s.particles.radius {
        for sp in &list.species {
            m = m.min(s.particle_mass(sp.radius, sp.mass));
        }
    }
    m.max(MIN_MAGNITUDE)
}

/// The lightest disk `inlet` brings, at least [`MIN_MAGNITUDE`].
fn lightest_entering(s: &Scenario, inlet: &Inlet) -> f64 {
    let (lo, hi) = s.inlet_radius_range(inlet);
    let mut m = s
        .inlet_mass(inlet, lo, None)
        .min(s.inlet_mass(inlet, hi, None));
    if let Radius::Species(list) = s.inlet_radius(inlet) {
        for sp in &list.species {
            m = m.min(s.inlet_mass(inlet, sp.radius, sp.mass));
        }
    }
    m.max(MIN_MAGNITUDE)
}
