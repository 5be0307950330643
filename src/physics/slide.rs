//! A rough disk sliding on the floor it rests on, exactly in time.
//!
//! The contact point of a disk riding the floor slips at `s = v_x + a ω`. Coulomb friction,
//! `μ` times the floor's push `m (g + h'')`, acts against the slip: `m v_x' = −σ μ m (g + h'')`
//! with `σ = sign s`, and the torque `a F` turns the disk, `ω' = v_x'/(q a)`. With
//! `G(t) = g (t − t₀) + h'(t) − h'(t₀)`, the push's impulse per unit mass since `t₀`:
//!
//! - `v_x(t) = v_x(t₀) − κ G(t)` with `κ = σ μ`,
//! - `x(t) = x(t₀) + v_x(t₀) (t − t₀) − κ [½ g (t − t₀)² + h(t) − h(t₀) − h'(t₀) (t − t₀)]`,
//! - `ω(t) = ω(t₀) + (v_x(t) − v_x(t₀))/(q a)`, and the orientation likewise from `x`,
//! - `s(t) = s(t₀) − κ (1 + 1/q) G(t)`.
//!
//! While the disk rides, `g + h'' > 0` (the floor presses), so `G` grows and the slip ends,
//! once, when `G = |s₀| / (μ (1 + 1/q))`: the disk then rolls at `v_x(t₀) − s₀ q/(1 + q)`. No
//! time step: the path is closed-form, and the end is a root of a monotone function.

use crate::physics::pair::RiderContact;

/// The slide of a disk riding the floor: `κ = σ μ` (its horizontal deceleration per unit of the
/// floor's push, signed by the slip; 0: the disk does not slide) and the local time `end` at
/// which the slip vanishes (∞ when the ride ends first).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Slide {
    /// `σ μ`: the friction's deceleration per unit push, against the slip.
    pub kappa: f64,
    /// Local time at which the disk rolls.
    pub end: f64,
}

impl Slide {
    /// No slide.
    pub const NONE: Slide = Slide {
        kappa: 0.0,
        end: 0.0,
    };

    /// `true` while this is a slide (κ ≠ 0).
    #[inline(always)]
    pub fn is_on(&self) -> bool {
        self.kappa != 0.0
    }

    /// Change of `(x, v_x)` against the friction-free line over `[t₀, t]`, from the floor's
    /// `(h, h')` at `t₀` and at `t` (taken at `end` after it: the disk then rolls on straight).
    /// Returns `(δx, δv)`: `x = x₀ + v₀ (t − t₀) + δx`, `v_x = v₀ + δv`.
    #[inline]
    pub fn offsets(
        &self,
        g: f64,
        t0: f64,
        t: f64,
        (h0, hd0): (f64, f64),
        ride: impl Fn(f64) -> (f64, f64),
    ) -> (f64, f64) {
        let te = t.min(self.end).max(t0);
        let tau = te - t0;
        let (h, hd) = ride(te);
        let dv = -self.kappa * (g * tau + hd - hd0);
        let dx = -self.kappa * (0.5 * g * tau * tau + h - h0 - hd0 * tau);
        // Rolling on from the end at its velocity.
        (dx + dv * (t - te).max(0.0), dv)
    }
}

/// The slide of a disk whose contact point slips at `slip` on a floor of friction `mu`
/// (inertia factor `q`), from local time `t0`: the time its slip vanishes, the root of the
/// push's impulse `G(t) = g (t − t₀) + h'(t) − h'(t₀) = |s|/(μ (1 + 1/q))`, found by bisection
/// (`G` grows while the floor presses). `ride_end`: when the ride ends, if it does (the slide
/// then lasts past it: `end` = ∞); `max_speed` bounds `|h'|`. `None` when the disk does not
/// slide (no slip, or no cap on friction: it rolls at once).
#[allow(clippy::too_many_arguments)]
pub fn slide_from(
    slip: f64,
    mu: f64,
    q: f64,
    g: f64,
    t0: f64,
    ride_end: Option<f64>,
    max_speed: f64,
    velocity: impl Fn(f64) -> f64,
) -> Option<Slide> {
    if slip == 0.0 || !mu.is_finite() || mu <= 0.0 || g <= 0.0 {
        return None;
    }
    let target = slip.abs() / (mu * (1.0 + 1.0 / q));
    let hd0 = velocity(t0);
    let push = |t: f64| g * (t - t0) + velocity(t) - hd0;
    // G ≥ g τ − 2 max|h'|: the root lies before this.
    let mut hi = t0 + (target + 2.0 * max_speed) / g;
    if let Some(t_end) = ride_end {
        if t_end < hi {
            if push(t_end) < target {
                return Some(Slide {
                    kappa: slip.signum() * mu,
                    end: f64::INFINITY,
                });
            }
            hi = t_end;
        }
    }
    let mut lo = t0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if push(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(Slide {
        kappa: slip.signum() * mu,
        end: hi,
    })
}

/// First time in `[now, limit]` at which two disks riding the floor side by side touch while
/// one or both slide: `dx`, `dvx` the first's x and v_x minus the second's now, `dy` their
/// (constant) height difference, `kappa` the first's κ minus the second's, `s` the contact
/// distance, `k_floor` a bound on |h''|. Their separation is `Δx(τ) = dx + dvx τ − κ Q(τ)` with
/// `|Q''| = |g + h''| ≤ g + k_floor`: stepping to the first root of the parabola that bounds
/// `|Δx| − c` from below (`c² = s² − dy²`) never passes its first root.
#[allow(clippy::too_many_arguments)]
pub fn riders_contact(
    (dx, dvx, dy): (f64, f64, f64),
    kappa: f64,
    s: f64,
    g: f64,
    k_floor: f64,
    now: f64,
    limit: f64,
    ride: impl Fn(f64) -> (f64, f64),
) -> Option<RiderContact> {
    let c2 = s * s - dy * dy;
    if c2 <= 0.0 {
        return None;
    }
    let c = c2.sqrt();
    let side = if dx >= 0.0 { 1.0 } else { -1.0 };
    let m = kappa.abs() * (g + k_floor);
    let tol = 1e-13 * s;
    let (h0, hd0) = ride(now);
    let mut tau = 0.0f64;
    for _ in 0..SLIDE_STEPS {
        let t = now + tau;
        if t > limit {
            return None;
        }
        let (h, hd) = ride(t);
        let q = 0.5 * g * tau * tau + h - h0 - hd0 * tau;
        let push = g * tau + hd - hd0;
        // The gap along x beyond contact, and its rate.
        let u = side * (dx + dvx * tau - kappa * q) - c;
        let ud = side * (dvx - kappa * push);
        if u <= tol {
            if ud < 0.0 {
                return Some(RiderContact::At(t));
            }
            if ud == 0.0 {
                // Touching without approach: look again once the friction could have closed
                // the gap by round-off.
                let wait = (2.0 * tol / m.max(f64::MIN_POSITIVE)).sqrt();
                return (t + wait <= limit).then_some(RiderContact::Recheck(t + wait));
            }
        }
        let u = u.max(0.0);
        let step = if m == 0.0 {
            if ud >= 0.0 {
                return None;
            }
            u / -ud
        } else {
            let root = (ud * ud + 2.0 * m * u).sqrt();
            if ud >= 0.0 {
                (ud + root) / m
            } else {
                2.0 * u / (root - ud)
            }
        };
        tau += step.max(f64::EPSILON * t.abs().max(1.0));
    }
    let t = now + tau;
    (t <= limit).then_some(RiderContact::Recheck(t))
}

/// Steps of [`riders_contact`] before it asks to be run again.
const SLIDE_STEPS: usize = 200;

#[cfg(test)]
mod tests {
    use super::*;

    /// On a still floor the slide lasts `|s|/(μ g (1 + 1/q))` and the disk decelerates
    /// uniformly: `x = v₀ τ − ½ κ g τ²`.
    #[test]
    fn on_a_still_floor_the_slide_is_uniform_deceleration() {
        let (g, mu, q) = (1.0, 0.5, 0.5);
        let slide = slide_from(1.5, mu, q, g, 2.0, None, 0.0, |_| 0.0).unwrap();
        let expected = 1.5 / (mu * g * 3.0);
        assert!((slide.end - 2.0 - expected).abs() < 1e-14, "{}", slide.end);
        let still = |_| (0.0, 0.0);
        let (dx, dv) = slide.offsets(g, 2.0, 2.5, (0.0, 0.0), still);
        assert!((dv + 0.5 * 0.5).abs() < 1e-15 && (dx + 0.5 * 0.5 * 0.25).abs() < 1e-15);
        // After the end it rolls on at the end's velocity.
        let (dx_end, dv_end) = slide.offsets(g, 2.0, slide.end, (0.0, 0.0), still);
        let (dx, dv) = slide.offsets(g, 2.0, slide.end + 1.0, (0.0, 0.0), still);
        assert_eq!(dv, dv_end);
        assert!((dx - dx_end - dv_end).abs() < 1e-14);
    }

    /// On a sine floor the end is where the push's impulse reaches its target, and the
    /// offsets agree with a fine numerical integration of `v_x' = −κ (g + h'')`.
    #[test]
    fn on_a_sine_floor_the_path_integrates_the_push() {
        let (g, mu, q, amp, w) = (1.0, 0.3, 0.5, 0.02, 5.0); // Γ = 0.5: it never takes off
        let h = |t: f64| amp * (w * t).sin();
        let hd = |t: f64| amp * w * (w * t).cos();
        let ride = |t: f64| (h(t), hd(t));
        let slide = slide_from(-0.8, mu, q, g, 0.3, None, amp * w, hd).unwrap();
        let push = g * (slide.end - 0.3) + hd(slide.end) - hd(0.3);
        assert!((push - 0.8 / (mu * 3.0)).abs() < 1e-13, "{push}");
        // Integrate x'' = −κ (g + h'') with a fine midpoint rule.
        let (mut x, mut v, steps) = (0.0, 0.0, 200_000);
        let dt = (slide.end - 0.3) / steps as f64;
        for k in 0..steps {
            let t = 0.3 + (k as f64 + 0.5) * dt;
            let acc = -slide.kappa * (g - amp * w * w * (w * t).sin());
            x += v * dt + 0.5 * acc * dt * dt;
            v += acc * dt;
        }
        let (dx, dv) = slide.offsets(g, 0.3, slide.end, ride(0.3), ride);
        assert!(
            (dv - v).abs() < 1e-9 && (dx - x).abs() < 1e-9,
            "{dx} {x} {dv} {v}"
        );
        assert!(slide.kappa < 0.0, "friction acts against the slip");
    }

    /// Two riders side by side, one sliding into the other on a sine floor: the contact found
    /// is the first root of the gap, against a fine scan.
    #[test]
    fn sliding_riders_meet_at_the_first_root() {
        let (g, amp, w) = (1.0, 0.03, 4.0);
        let ride = |t: f64| (amp * (w * t).sin(), amp * w * (w * t).cos());
        for &(dx, dvx, dy, kappa) in &[
            (-2.0, 1.5, 0.1, 0.5),
            (-2.0, 0.6, 0.0, -0.4), // sped up by its slide
            (3.0, -0.3, 0.2, -0.5),
            (-1.5, 1.2, 0.0, 1.0), // stopped short of the other
        ] {
            let (s, now) = (1.0, 0.7);
            let gap = |t: f64| {
                let tau = t - now;
                let (h0, hd0) = ride(now);
                let (h, _) = ride(t);
                let x = dx + dvx * tau - kappa * (0.5 * g * tau * tau + h - h0 - hd0 * tau);
                x * x + dy * dy - s * s
            };
            let found = riders_contact((dx, dvx, dy), kappa, s, g, amp * w * w, now, 5.0, ride);
            let scan = (1..=400_000)
                .map(|k| now + k as f64 * 1e-5)
                .find(|&t| gap(t) <= 0.0);
            match (found, scan) {
                (Some(RiderContact::At(t)), Some(ts)) => {
                    assert!((t - ts).abs() < 2e-5, "{t} vs {ts}");
                    assert!(gap(t).abs() < 1e-9, "{}", gap(t));
                }
                (None, None) => {}
                other => panic!("{dx} {dvx} {dy} {kappa}: {other:?}"),
            }
        }
    }

    #[test]
    fn no_slip_or_no_cap_is_no_slide() {
        assert!(slide_from(0.0, 0.5, 0.5, 1.0, 0.0, None, 0.0, |_| 0.0).is_none());
        assert!(slide_from(1.0, f64::INFINITY, 0.5, 1.0, 0.0, None, 0.0, |_| 0.0).is_none());
        // A ride that ends before the slip does: the slide lasts past it.
        let s = slide_from(10.0, 0.1, 0.5, 1.0, 0.0, Some(1.0), 0.0, |_| 0.0).unwrap();
        assert_eq!(s.end, f64::INFINITY);
    }
}
