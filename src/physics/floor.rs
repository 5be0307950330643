//! The floor at mean height y = 0: static, or vibrating as `h(t) = A·w(ωt + φ0)`.
//!
//! A disk of radius `a` hits the floor at the first root of `f(t) = y(t) − a − h(t)` after the
//! present. For the sine this is transcendental; since `|f''| ≤ g + Aω² = K`, the parabola
//! `f + f' s − ½ K s²` is a lower bound of `f` over the step `s`, and stepping to its first root
//! never passes the first root of `f` (a safe-step Newton iteration that converges from below).
//! Piecewise-linear waveforms make `f` a quadratic on each linear piece: exact roots.
//!
//! The phase `ωt + φ0` is kept reduced modulo 2π and re-based together with the engine's clock,
//! so long runs keep full precision.

use crate::physics::drive::{Drive, FloorModel, Waveform};
use crate::physics::flight::time_to_fall;
use crate::physics::restitution::CollisionLaw;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// The floor: its drive, its phase and its restitution.
#[derive(Debug, Clone, PartialEq)]
pub struct Floor {
    /// Normal restitution of impacts (relative to the floor).
    pub restitution: f64,
    /// How it vibrates: waveform, model, amplitude and angular frequency.
    drive: Drive,
    /// Phase at the engine's local time 0, in [0, 2π).
    phase0: f64,
}

/// What the floor predicts for one disk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FloorEvent {
    /// The disk hits the floor at this (local) time.
    Impact(f64),
    /// Look again at this time: the root search made progress but did not conclude within its
    /// iteration budget (a disk skimming the floor). Nothing happens to the disk then.
    Recheck(f64),
}

impl FloorEvent {
    /// The time of the event.
    pub fn time(&self) -> f64 {
        match *self {
            FloorEvent::Impact(t) | FloorEvent::Recheck(t) => t,
        }
    }
}

/// Iterations of the safe-step search before a [`FloorEvent::Recheck`] is returned.
const MAX_STEPS: usize = 200;

/// A disk comes to rest on the floor (rides it) when its rebound, relative to the floor, would
/// rise less than `REST_HEIGHT` radii under gravity. This ends the infinite sequence of ever
/// smaller bounces of an inelastic disk (Zeno) after finitely many impacts; bounces that small
/// change nothing measurable.
pub const REST_HEIGHT: f64 = 1e-9;

/// A disk landing on a disk that rides the floor rebounds at least so fast that it would rise
/// `PAIR_REST_HEIGHT` radii against the acceleration pressing the two together (see
/// `physics::pair::collide_rebounding`), unless it comes to rest on it (resting contacts,
/// `engine::rest::resting`): a landing gentler than that in a stable place ends at rest. Without
/// resting contacts a disk on a rider keeps bouncing, about 1/(2·√(2·10⁻⁶ a/g)) ≈ 500 bounces
/// per unit time for a = 0.5, g = 1.
pub const PAIR_REST_HEIGHT: f64 = 1e-6;

/// How a ride on the floor ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RideEnd {
    /// The floor accelerates downwards faster than g: the disk flies off with vertical speed
    /// `launch`.
    TakeOff {
        /// Vertical velocity at take-off.
        launch: f64,
    },
    /// A kink of a piecewise-linear floor turns upwards: the floor hits the riding disk, which
    /// moved with the floor's velocity `before`, and the floor now moves with `after`.
    Kick {
        /// Vertical velocity of the disk (the floor's, before the kink).
        before: f64,
        /// The floor's velocity after the kink.
        after: f64,
    },
}

impl Floor {
    /// A floor vibrating as `drive` from initial phase `phase`.
    pub fn new(restitution: f64, drive: Drive, phase: f64) -> Floor {
        Floor {
            restitution,
            drive,
            phase0: phase.rem_euclid(TAU),
        }
    }

    /// How it vibrates, with what follows (Γ, the period, the peak velocity).
    #[inline]
    pub fn drive(&self) -> &Drive {
        &self.drive
    }

    /// `true` when the floor does not move.
    #[inline]
    pub fn is_static(&self) -> bool {
        self.drive.is_static()
    }

    /// Lowest height the floor reaches (−A).
    pub fn lowest(&self) -> f64 {
        -self.drive.amplitude
    }

    /// Phase at local time `t`.
    #[inline]
    pub fn phase(&self, t: f64) -> f64 {
        self.phase0 + self.drive.omega * t
    }

    /// Phase at local time 0 (in [0, 2π)): with the engine's clock, the floor's whole state.
    pub fn phase_origin(&self) -> f64 {
        self.phase0
    }

    /// Sets the phase at local time 0 (a checkpoint's floor).
    pub fn set_phase_origin(&mut self, phase: f64) {
        self.phase0 = phase;
    }

    /// Moves the local time origin forward by `dt` (the engine re-bases its clock).
    pub fn rebase(&mut self, dt: f64) {
        self.phase0 = (self.phase0 + self.drive.omega * dt).rem_euclid(TAU);
    }

    /// Floor height at local time `t`.
    #[inline]
    pub fn height(&self, t: f64) -> f64 {
        if self.is_static() {
            return 0.0;
        }
        let th = self.phase(t);
        self.drive.amplitude
            * match self.drive.waveform {
                Waveform::Sine => th.sin(),
                Waveform::Triangle => triangle(th),
                Waveform::Sawtooth => th.rem_euclid(TAU) / PI - 1.0,
            }
    }

    /// Floor velocity at local time `t` (at a kink, the slope of the piece that starts there).
    #[inline]
    pub fn velocity(&self, t: f64) -> f64 {
        if self.is_static() {
            return 0.0;
        }
        let th = self.phase(t);
        self.drive.amplitude
            * self.drive.omega
            * match self.drive.waveform {
                Waveform::Sine => th.cos(),
                Waveform::Triangle => triangle_slope(th),
                Waveform::Sawtooth => 1.0 / PI,
            }
    }

    /// Next impact of a disk (radius `a`, at height `y` moving with `vy` at local time `now`,
    /// gravity `g`) no later than `limit`; `None` if there is none by then.
    #[inline]
    pub fn next_event(
        &self,
        y: f64,
        vy: f64,
        a: f64,
        g: f64,
        now: f64,
        limit: f64,
    ) -> Option<FloorEvent> {
        // Most disks of a bed are above the floor's reach until after `limit` (the next
        // re-mapping or an earlier event of their own): their bottom's height above the top
        // of the floor's travel, h + v τ − ½ g τ², is concave in τ and so stays positive over
        // [0, w] if it is positive at both ends. The margin keeps this test from deciding
        // what only round-off separates; anything closer is left to the exact search.
        let h = y - a - self.drive.amplitude;
        let w = limit - now;
        let end = h + (vy - 0.5 * g * w) * w;
        if h > 0.0 && end > 1e-12 * (h + (vy * w).abs() + g * w * w) {
            return None;
        }
        self.next_event_within_reach(y, vy, a, g, now, limit)
    }

    /// [`next_event`](Self::next_event) for a disk that may reach the floor by `limit`.
    #[inline(never)]
    fn next_event_within_reach(
        &self,
        y: f64,
        vy: f64,
        a: f64,
        g: f64,
        now: f64,
        limit: f64,
    ) -> Option<FloorEvent> {
        if self.is_static() || self.drive.model == FloorModel::FixedPosition {
            let t = now + time_to_fall(y - a, vy, g)?;
            return (t <= limit).then_some(FloorEvent::Impact(t));
        }
        match self.drive.waveform {
            Waveform::Sine => self.sine_impact(y, vy, a, g, now, limit),
            Waveform::Triangle | Waveform::Sawtooth => {
                self.piecewise_impact(y, vy, a, g, now, limit)
            }
        }
    }

    /// Vertical velocity after an impact at local time `t`: `v' = h' − e (v − h')` when the disk
    /// approaches the floor. In the fixed-position model a floor receding faster than the disk
    /// reflects it like a static floor (the disk must not pass y = 0).
    #[inline]
    pub fn bounce(&self, vy: f64, t: f64) -> f64 {
        self.bounce_on(vy, self.velocity(t), false)
    }

    /// Disk `i` moving vertically with `vy` hits the floor, moving with `hd`, at local time
    /// `now`: the collision law says whether a cure makes the impact elastic, and the vertical
    /// velocity after is returned — the one place every scheme handles a floor impact, as
    /// [`SideBounds::hit`](crate::physics::walls::SideBounds::hit) a wall's.
    #[inline]
    pub fn hit(&self, law: &mut CollisionLaw, i: usize, now: f64, vy: f64, hd: f64) -> f64 {
        let elastic = law.boundary_elastic(i, now, (hd - vy).max(0.0));
        self.bounce_on(vy, hd, elastic)
    }

    /// [`bounce`](Self::bounce) on a floor moving with vertical velocity `hd`; `elastic` when a
    /// cure of inelastic collapse overrides the floor's restitution.
    #[inline]
    pub fn bounce_on(&self, vy: f64, hd: f64, elastic: bool) -> f64 {
        let e = if elastic { 1.0 } else { self.restitution };
        let moving = hd - e * (vy - hd).min(0.0);
        match self.drive.model {
            FloorModel::Exact => moving,
            FloorModel::FixedPosition => moving.max(-e * vy).max(0.0),
        }
    }

    /// The vibration period (1 for a static floor): a time scale for round-off guards.
    pub fn period_or_one(&self) -> f64 {
        if self.is_static() {
            1.0
        } else {
            self.drive.period()
        }
    }

    /// Floor acceleration at local time `t` (0 on the pieces of a piecewise-linear floor).
    #[inline]
    pub fn acceleration(&self, t: f64) -> f64 {
        match self.drive.waveform {
            Waveform::Sine if !self.is_static() => {
                -self.drive.peak_acceleration() * self.phase(t).sin()
            }
            _ => 0.0,
        }
    }

    /// How far a disk riding the floor can move up or down with it, at most (0 in the
    /// fixed-position model), and its largest vertical speed doing so.
    pub fn ride_bounds(&self) -> (f64, f64) {
        match self.drive.model {
            FloorModel::Exact if !self.is_static() => {
                (2.0 * self.drive.amplitude, self.drive.peak_velocity())
            }
            _ => (0.0, 0.0),
        }
    }

    /// Bound on |h''| over a piece of the motion (the sine's Aω²; 0 on linear pieces).
    pub fn max_acceleration(&self) -> f64 {
        match (self.drive.model, self.drive.waveform) {
            (FloorModel::Exact, Waveform::Sine) => self.drive.peak_acceleration(),
            _ => 0.0,
        }
    }

    /// Whether the floor can throw a disk resting on it: somewhere it accelerates downwards
    /// faster than `g` (a sine above Γ = 1, past round-off; a triangle's or sawtooth's corners
    /// always).
    pub fn throws(&self, g: f64) -> bool {
        !self.is_static()
            && match self.drive.waveform {
                Waveform::Sine => self.max_acceleration() > g * (1.0 + 1e-12),
                Waveform::Triangle | Waveform::Sawtooth => true,
            }
    }

    /// End of the phase interval in which the sine floor accelerates downwards faster than g
    /// (`sin θ > g/(Aω²)`), for a time `t` inside it.
    fn leaves_throw_zone(&self, t: f64, g: f64) -> f64 {
        let peak = self.drive.peak_acceleration();
        let crit = (g / peak).min(1.0).asin();
        let th = self.phase(t).rem_euclid(TAU);
        let end = PI - crit;
        let dth = if th <= end { end - th } else { TAU + end - th };
        // Step at least a few ulps so that time moves on.
        t + (dth / self.drive.omega).max(4.0 * f64::EPSILON * t.abs().max(1.0))
    }

    /// Rebound speed (relative to the floor) below which a disk of radius `a` comes to rest.
    pub fn rest_speed(a: f64, g: f64) -> f64 {
        (2.0 * g * REST_HEIGHT * a).sqrt()
    }

    /// Smallest rebound of a disk of radius `a` landing on a rider, pressed onto it with
    /// acceleration `press`.
    pub fn pair_rest_speed(a: f64, press: f64) -> f64 {
        (2.0 * press * PAIR_REST_HEIGHT * a).sqrt()
    }

    /// Whether a disk just bounced at local time `t` with relative rebound speed `rel` comes to
    /// rest on the floor: the floor presses the disk (its acceleration is above −g, so a disk
    /// moving with it stays in contact) and the rebound would rise less than [`REST_HEIGHT`]
    /// radii against that pressing acceleration.
    pub fn comes_to_rest(&self, rel: f64, a: f64, g: f64, t: f64) -> bool {
        self.presses(t, g) && rel < Self::rest_speed(a, self.press(t, g))
    }

    /// How hard the floor presses a disk that moves with it: `g + h''(t)`.
    fn press(&self, t: f64, g: f64) -> f64 {
        match self.drive.model {
            FloorModel::Exact => g + self.acceleration(t),
            FloorModel::FixedPosition => g,
        }
    }

    /// Whether the floor presses a disk moving with it (`g + h'' > 0`, with a relative margin
    /// of 10⁻⁹ so that a disk thrown off exactly at `g + h'' = 0` is not caught again).
    pub fn presses(&self, t: f64, g: f64) -> bool {
        self.press(t, g) > 1e-9 * (g + self.max_acceleration())
    }

    /// Height and vertical velocity of a disk's contact point while it rides the floor: the
    /// floor's in the exact model, (0, 0) in the fixed-position model (the floor stays put).
    #[inline]
    pub fn ride(&self, t: f64) -> (f64, f64) {
        match self.drive.model {
            FloorModel::Exact => (self.height(t), self.velocity(t)),
            FloorModel::FixedPosition => (0.0, 0.0),
        }
    }

    /// Vertical acceleration of a disk riding the floor at local time `t`: the floor's in the
    /// exact model, 0 in the fixed-position model.
    #[inline]
    pub fn ride_acceleration(&self, t: f64) -> f64 {
        match self.drive.model {
            FloorModel::Exact => self.acceleration(t),
            FloorModel::FixedPosition => 0.0,
        }
    }

    /// When and how a ride that is under way at local time `now` ends (`None`: never, e.g. a
    /// static floor or Γ ≤ 1). The sine floor throws the disk off when `h'' < −g`, i.e. at
    /// `sin(ωt + φ0) = 1/Γ`; a triangle floor at its peaks (and kicks it at its troughs); a
    /// sawtooth at its drops.
    pub fn ride_end(&self, now: f64, g: f64) -> Option<(f64, RideEnd)> {
        if self.is_static() {
            return None;
        }
        let w = self.drive.omega;
        let th = self.phase(now).rem_euclid(TAU);
        let slope = |k: f64| self.drive.amplitude * w * k;
        match self.drive.waveform {
            Waveform::Sine => {
                let peak = self.drive.peak_acceleration();
                if peak <= g {
                    return None;
                }
                // sin θ = 1/Γ, θ in (0, π/2).
                let crit = (g / peak).asin();
                // The fixed-position floor cannot launch a disk while it moves down (the launch
                // would be 0 and the disk land again at once, for ever): a disk that comes to
                // rest there rides on to the next take-off.
                let falling =
                    self.drive.model == FloorModel::FixedPosition && self.velocity(now) <= 0.0;
                let dth = if th < crit {
                    crit - th
                } else if th < PI - crit && !falling {
                    0.0
                } else {
                    TAU + crit - th
                };
                let t = now + dth / w;
                let launch = match self.drive.model {
                    FloorModel::Exact => self.velocity(t),
                    FloorModel::FixedPosition => self.velocity(t).max(0.0),
                };
                Some((t, RideEnd::TakeOff { launch }))
            }
            Waveform::Triangle => {
                // Measured from the trough at −π/2: rising on [0, π), falling on [π, 2π).
                let p = (th + FRAC_PI_2).rem_euclid(TAU);
                let up = slope(2.0 / PI);
                if p < PI {
                    Some((now + (PI - p) / w, RideEnd::TakeOff { launch: up }))
                } else if self.drive.model == FloorModel::Exact {
                    Some((
                        now + (TAU - p) / w,
                        RideEnd::Kick {
                            before: -up,
                            after: up,
                        },
                    ))
                } else {
                    Some((now + (TAU - p + PI) / w, RideEnd::TakeOff { launch: up }))
                }
            }
            Waveform::Sawtooth => Some((
                now + (TAU - th) / w,
                RideEnd::TakeOff {
                    launch: slope(1.0 / PI),
                },
            )),
        }
    }

    fn tolerance(&self, a: f64, y: f64) -> f64 {
        1e-13 * (a + self.drive.amplitude + y.abs())
    }

    /// Exact impact on the sine floor by safe stepping from below.
    fn sine_impact(
        &self,
        y: f64,
        vy: f64,
        a: f64,
        g: f64,
        now: f64,
        limit: f64,
    ) -> Option<FloorEvent> {
        let amp = self.drive.amplitude;
        let k = g + self.drive.peak_acceleration();
        // Above the floor's reach, fall exactly into the envelope y − a ≤ A first.
        let mut tau = if y - a > amp {
            time_to_fall(y - a - amp, vy, g)?
        } else {
            0.0
        };
        for _ in 0..MAX_STEPS {
            let t = now + tau;
            if t > limit {
                return None;
            }
            let yy = y + (vy - 0.5 * g * tau) * tau;
            let vv = vy - g * tau;
            let th = self.phase(t);
            let (s, c) = th.sin_cos();
            let f = yy - a - amp * s;
            let fd = vv - amp * self.drive.omega * c;
            if f <= self.tolerance(a, yy) {
                if !self.presses(t, g) && fd >= 0.0 {
                    // Touching and not approaching while the floor accelerates down faster than
                    // g: f'' > 0, so f grows until the floor's downward acceleration drops below
                    // g again. (Approaching, however slowly, is an impact.)
                    tau = self.leaves_throw_zone(t, g) - now;
                    continue;
                }
                if fd > 0.0 {
                    // Touching but separating: the lower bound stays ≥ f for 2 f'/K.
                    tau += 2.0 * fd / k;
                    continue;
                }
                return Some(FloorEvent::Impact(t));
            }
            if yy - a > amp && vv > 0.0 {
                // Left the envelope upwards: come back into it exactly.
                tau += time_to_fall(yy - a - amp, vv, g)?;
                continue;
            }
            let root = (fd * fd + 2.0 * k * f).sqrt();
            tau += if fd >= 0.0 {
                (fd + root) / k
            } else {
                2.0 * f / (root - fd)
            };
        }
        let t = now + tau;
        (t <= limit).then_some(FloorEvent::Recheck(t))
    }

    /// Exact impact on a piecewise-linear floor: a quadratic on each piece.
    fn piecewise_impact(
        &self,
        y: f64,
        vy: f64,
        a: f64,
        g: f64,
        now: f64,
        limit: f64,
    ) -> Option<FloorEvent> {
        let amp = self.drive.amplitude;
        let w = self.drive.omega;
        let mut tau = if y - a > amp {
            time_to_fall(y - a - amp, vy, g)?
        } else {
            0.0
        };
        for _ in 0..MAX_STEPS {
            let t = now + tau;
            if t > limit {
                return None;
            }
            let th = self.phase(t);
            // End of the current linear piece, in phase and then in time.
            // (The same phase decomposition as `triangle` and `triangle_slope`, so that piece
            // and slope always agree at the kinks.)
            let piece_end = match self.drive.waveform {
                Waveform::Triangle => {
                    let p = (th + FRAC_PI_2).rem_euclid(TAU);
                    th + if p < PI { PI - p } else { TAU - p }
                }
                _ => th + (TAU - th.rem_euclid(TAU)),
            };
            let tau_end = tau + (piece_end - th) / w;
            let yy = y + (vy - 0.5 * g * tau) * tau;
            let vv = vy - g * tau;
            let f = yy - a - self.height(t);
            let fd = vv - self.velocity(t);
            if f <= self.tolerance(a, yy) && fd <= 0.0 {
                return Some(FloorEvent::Impact(t));
            }
            if yy - a > amp && vv > 0.0 {
                tau += time_to_fall(yy - a - amp, vv, g)?;
                continue;
            }
            // On this piece f(s) = f + f' s − ½ g s² exactly.
            match time_to_fall(f.max(0.0), fd, g) {
                Some(s) if tau + s <= tau_end => {
                    let t_hit = now + tau + s;
                    return (t_hit <= limit).then_some(FloorEvent::Impact(t_hit));
                }
                _ => tau = tau_end.max(tau + f64::EPSILON * tau.abs().max(1.0)),
            }
        }
        let t = now + tau;
        (t <= limit).then_some(FloorEvent::Recheck(t))
    }
}

/// Triangle wave with the sine's peaks: `(2/π) asin(sin θ)`.
#[inline]
fn triangle(th: f64) -> f64 {
    // Phase measured from the trough at −π/2, in [0, 2π).
    let p = (th + FRAC_PI_2).rem_euclid(TAU);
    if p < PI {
        -1.0 + 2.0 * p / PI
    } else {
        3.0 - 2.0 * p / PI
    }
}

/// dw/dθ of [`triangle`]: +2/π on the rising piece, −2/π on the falling one.
#[inline]
fn triangle_slope(th: f64) -> f64 {
    let p = (th + FRAC_PI_2).rem_euclid(TAU);
    if p < PI {
        2.0 / PI
    } else {
        -2.0 / PI
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A drive of amplitude 0.2 and ω = 2, of the given shape.
    fn shaped(waveform: Waveform, model: FloorModel) -> Drive {
        Drive {
            waveform,
            model,
            amplitude: 0.2,
            omega: 2.0,
        }
    }

    fn sine(a: f64, f: f64, e: f64) -> Floor {
        Floor::new(e, Drive::new(a, f), 0.0)
    }

    #[test]
    fn triangle_matches_sine_at_peaks_and_is_continuous() {
        for k in -3..4 {
            let th = FRAC_PI_2 + k as f64 * PI;
            assert!((triangle(th) - th.sin()).abs() < 1e-12);
        }
        let mut prev = triangle(-10.0);
        for i in 1..20_000 {
            let th = -10.0 + i as f64 * 1e-3;
            let v = triangle(th);
            assert!((v - prev).abs() < 1e-3 * 2.0 / PI + 1e-12);
            prev = v;
        }
    }

    #[test]
    fn static_floor_impact_is_the_parabola_root() {
        let fl = sine(0.0, 1.0, 1.0);
        let ev = fl
            .next_event(5.5, 0.0, 0.5, 2.0, 1.0, f64::INFINITY)
            .unwrap();
        // Falls 5 under g = 2: t = √5.
        assert!((ev.time() - 1.0 - 5f64.sqrt()).abs() < 1e-14);
    }

    #[test]
    fn sine_impact_is_a_root_and_the_floor_is_not_crossed_before() {
        let fl = sine(0.1, 2.0, 0.9);
        let (y, vy, a, g) = (3.0, 1.0, 0.5, 1.0);
        let FloorEvent::Impact(t) = fl.next_event(y, vy, a, g, 0.0, f64::INFINITY).unwrap() else {
            panic!("expected an impact")
        };
        let f = |t: f64| y + vy * t - 0.5 * g * t * t - a - fl.height(t);
        assert!(f(t).abs() < 1e-12, "f(t) = {}", f(t));
        let n = 100_000;
        for i in 0..n {
            assert!(f(t * i as f64 / n as f64) > -1e-12);
        }
    }

    #[test]
    fn the_out_of_reach_shortcut_never_changes_the_answer() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
        let floors = [
            sine(0.3, 0.5, 0.9),
            sine(0.0, 1.0, 0.5),
            Floor::new(0.9, shaped(Waveform::Triangle, FloorModel::Exact), 1.0),
            Floor::new(
                0.9,
                shaped(Waveform::Sawtooth, FloorModel::FixedPosition),
                0.3,
            ),
        ];
        let mut shortcuts = 0;
        for k in 0..200_000 {
            let fl = &floors[k % floors.len()];
            let (a, g) = (0.5, if k % 7 == 0 { 0.0 } else { 1.0 });
            let y = rng.random_range(-0.2..3.0);
            let vy = rng.random_range(-2.0..2.0);
            let now = rng.random_range(0.0..10.0);
            // Limits around the fall to the floor's reach, where the shortcut decides.
            let h = y - a - fl.drive.amplitude;
            let fall = time_to_fall(h, vy, g).unwrap_or(1.0);
            let limit = now
                + fall * rng.random_range(0.0..2.0)
                + if k % 11 == 0 { f64::INFINITY } else { 0.0 };
            let full = fl.next_event_within_reach(y, vy, a, g, now, limit);
            assert_eq!(
                fl.next_event(y, vy, a, g, now, limit),
                full,
                "y {y} vy {vy} limit {limit}"
            );
            shortcuts += (full.is_none() && h > 0.0) as usize;
        }
        assert!(shortcuts > 10_000, "only {shortcuts} cases out of reach");
    }

    #[test]
    fn rebase_keeps_the_floor_where_it_was() {
        let mut fl = sine(0.3, 1.7, 1.0);
        let h = fl.height(123.456);
        fl.rebase(123.0);
        assert!((fl.height(0.456) - h).abs() < 1e-12);
    }
}
