//! Pair interactions of smooth hard disks: when two disks touch, and what a collision does.
//!
//! Gravity acts equally on both disks, so their relative motion is straight:
//! `Δr(t) = Δr + Δv t`. With `b = Δr·Δv < 0`, `disc = b² − Δv²(Δr² − s²)` and `s = a_i + a_j`,
//! the contact time is `t = (Δr² − s²)/(−b + √disc)`, a form that keeps full precision for grazing
//! and near-contact pairs (no cancellation between `−b` and `√disc`).

/// Earliest `t ≥ 0` at which two disks at separation `(dx, dy)` with relative velocity
/// `(dvx, dvy)` reach centre distance `s`; `None` if they recede or miss. `speed` is the scale
/// of the two velocities themselves (e.g. the sum of their components' magnitudes; 0 if
/// unknown): a pair in contact approaching slower than their round-off is not a collision.
///
/// Receding pairs (`b ≥ 0`) are rejected before any square root. A pair that already overlaps
/// by round-off while approaching collides now (`Some(0)`), never in the past.
#[inline(always)]
pub fn contact_time(dx: f64, dy: f64, dvx: f64, dvy: f64, s: f64, speed: f64) -> Option<f64> {
    contact_time_within(dx, dy, dvx, dvy, s, speed, f64::INFINITY)
}

/// [`contact_time`], for a caller that only wants a contact earlier than `horizon` (time from
/// now): a pair that cannot touch before it is rejected without a square root (the contact time
/// is at least `c / (−2b)` for disks apart). A contact at `horizon` or later may come back as
/// `None` or as its time; an earlier one always comes back, the same as from `contact_time`.
#[inline(always)]
pub fn contact_time_within(
    dx: f64,
    dy: f64,
    dvx: f64,
    dvy: f64,
    s: f64,
    speed: f64,
    horizon: f64,
) -> Option<f64> {
    let b = dx * dvx + dy * dvy;
    if b >= 0.0 {
        return None;
    }
    let c = dx * dx + dy * dy - s * s;
    if beyond(b, c, horizon) {
        return None;
    }
    let dv2 = dvx * dvx + dvy * dvy;
    if b * b - dv2 * c < 0.0 {
        return None;
    }
    let t = meeting_time(dx, dy, dvx, dvy, s, speed);
    (t < f64::INFINITY).then_some(t)
}

/// The contact time of a pair whose paths meet ([`paths_meet`] is `true`), without a branch
/// (the one home of the formula: [`contact_time_within`] rejects pairs first, then asks here);
/// ∞ for a pair in contact that approaches only within round-off. For a horizon h, a pair
/// that `contact_time_within` turns down as unable to touch before h has a time here of more
/// than h: its least time, c / (−2b), is at least h (1 + 10⁻¹²), and the round-off of the
/// formula is a few units in the last place.
#[inline(always)]
pub fn meeting_time(dx: f64, dy: f64, dvx: f64, dvy: f64, s: f64, speed: f64) -> f64 {
    let b = dx * dvx + dy * dvy;
    let c = dx * dx + dy * dy - s * s;
    let dv2 = dvx * dvx + dvy * dvy;
    // In contact, approaching only within the round-off of b (a pair that just collided with
    // e = 0, or slides tangentially), or of the velocities (two disks of a column moving
    // together): not a collision. Colliding would change the velocities by less than an ulp and
    // repeat forever.
    let touching = (c <= 1e-12 * s * s) & (b * b <= 1e-26 * s * s * dv2.max(speed * speed));
    let disc = b * b - dv2 * c;
    let t = (c / (-b + disc.sqrt())).max(0.0);
    if touching {
        f64::INFINITY
    } else {
        t
    }
}

/// `false` only for pairs that [`contact_time_within`] turns down whatever its horizon: receding
/// (`b ≥ 0`) or passing each other by (`b² < |Δv|² c`). Branch-free, for a first pass over a
/// neighbour list.
#[inline(always)]
pub fn paths_meet(dx: f64, dy: f64, dvx: f64, dvy: f64, s: f64) -> bool {
    let b = dx * dvx + dy * dvy;
    let c = dx * dx + dy * dy - s * s;
    let dv2 = dvx * dvx + dvy * dvy;
    (b < 0.0) & (b * b - dv2 * c >= 0.0)
}

/// `true` for an approaching pair apart (`b = Δr·Δv < 0`, `c = Δr² − s² > 0`) that cannot
/// touch within `horizon`: its contact time is at least `c / (−2b)`. The factor keeps the test
/// clear of the round-off of the contact time's division.
#[inline(always)]
fn beyond(b: f64, c: f64, horizon: f64) -> bool {
    (c > 0.0) & (c >= -2.0 * b * horizon * (1.0 + 1e-12))
}

/// [`paths_meet`], and `false` too for pairs that [`contact_time_within`] turns down for a
/// `horizon` from now (apart, and unable to touch before it). Branch-free.
#[inline(always)]
pub fn paths_meet_within(dx: f64, dy: f64, dvx: f64, dvy: f64, s: f64, horizon: f64) -> bool {
    let b = dx * dvx + dy * dvy;
    let c = dx * dx + dy * dy - s * s;
    paths_meet(dx, dy, dvx, dvy, s) & !beyond(b, c, horizon)
}

/// Outcome of one pair collision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impulse {
    /// Velocity change of disk i; disk j changes by `−Δv_i·m_i/m_j`.
    pub dvx_i: f64,
    /// See `dvx_i`.
    pub dvy_i: f64,
    /// Velocity change of disk j.
    pub dvx_j: f64,
    /// See `dvx_j`.
    pub dvy_j: f64,
    /// Kinetic energy lost, `½ μ (1 − e²) u²`.
    pub energy_lost: f64,
    /// Magnitude of the momentum exchanged, `(1 + e) μ |u|`.
    pub momentum: f64,
    /// Normal approach speed `|u|` before the collision.
    pub normal_speed: f64,
    /// Centre distance at contact.
    pub distance: f64,
}

impl Impulse {
    /// Changes the velocities of disks `i` and `j` in `motion` by this impulse (one home for
    /// every scheme's pair collision).
    #[inline]
    pub fn apply(&self, motion: &mut [crate::physics::disks::Motion], i: usize, j: usize) {
        motion[i].vx += self.dvx_i;
        motion[i].vy += self.dvy_i;
        motion[j].vx += self.dvx_j;
        motion[j].vy += self.dvy_j;
    }
}

/// Collides smooth disks i and j with normal restitution `e`, and a normal rebound speed of at
/// least `min_rebound` (0 for a plain collision). The floor of the rebound is used for a disk
/// landing on a disk that rides the floor: they are pressed together, and without it a contact
/// at zero normal speed would exchange nothing and repeat (Zeno); `min_rebound` is the speed that
/// lifts the pair apart by a negligible height (see `Floor::rest_speed`); a pressed pair found in
/// contact while receding slower than that (round-off) gets it too. The energy lost is then
/// whatever the velocities lost (slightly negative when the floor of the rebound acts).
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn collide_rebounding(
    dx: f64,
    dy: f64,
    dvx: f64,
    dvy: f64,
    m_i: f64,
    m_j: f64,
    e: f64,
    min_rebound: f64,
) -> Impulse {
    let distance = (dx * dx + dy * dy).sqrt();
    let (nx, ny) = (dx / distance, dy / distance);
    let u = dvx * nx + dvy * ny;
    if u >= min_rebound || (u == 0.0 && min_rebound == 0.0) {
        return collide(dx, dy, dvx, dvy, m_i, m_j, e);
    }
    let mu = m_i * m_j / (m_i + m_j);
    // Normal speed after, ≥ 0. A pressed pair that touches while receding slower than the
    // floor of the rebound (a contact found by round-off) is also lifted apart by it.
    let after = (-e * u).max(u).max(min_rebound);
    let p = mu * (after - u);
    Impulse {
        dvx_i: p * nx / m_i,
        dvy_i: p * ny / m_i,
        dvx_j: -p * nx / m_j,
        dvy_j: -p * ny / m_j,
        energy_lost: 0.5 * mu * (u * u - after * after),
        momentum: p,
        normal_speed: (-u).max(0.0),
        distance,
    }
}

/// Collides smooth disks i and j with normal restitution `e`.
///
/// `(dx, dy) = r_i − r_j` and `(dvx, dvy) = v_i − v_j` at contact; `n = Δr/|Δr|`, `u = Δv·n`,
/// `v_i += −(1+e) μ u n / m_i`, `v_j −= −(1+e) μ u n / m_j` with `μ = m_i m_j/(m_i + m_j)`.
/// A pair that is not approaching (`u ≥ 0`, possible only by round-off) exchanges nothing.
#[inline(always)]
pub fn collide(dx: f64, dy: f64, dvx: f64, dvy: f64, m_i: f64, m_j: f64, e: f64) -> Impulse {
    let distance = (dx * dx + dy * dy).sqrt();
    let (nx, ny) = (dx / distance, dy / distance);
    let u = dvx * nx + dvy * ny;
    let mu = m_i * m_j / (m_i + m_j);
    if u >= 0.0 {
        return Impulse {
            dvx_i: 0.0,
            dvy_i: 0.0,
            dvx_j: 0.0,
            dvy_j: 0.0,
            energy_lost: 0.0,
            momentum: 0.0,
            normal_speed: 0.0,
            distance,
        };
    }
    let p = -(1.0 + e) * mu * u; // > 0: impulse on i along +n
    Impulse {
        dvx_i: p * nx / m_i,
        dvy_i: p * ny / m_i,
        dvx_j: -p * nx / m_j,
        dvy_j: -p * ny / m_j,
        energy_lost: 0.5 * mu * (1.0 - e * e) * u * u,
        momentum: p,
        normal_speed: -u,
        distance,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn head_on_contact_time() {
        // Two unit-radius disks 10 apart closing at speed 2: contact after (10 − 2)/2 = 4.
        let t = contact_time(-10.0, 0.0, 2.0, 0.0, 2.0, 0.0).unwrap();
        assert!((t - 4.0).abs() < 1e-15);
        assert_eq!(
            contact_time(10.0, 0.0, 2.0, 0.0, 2.0, 0.0),
            None,
            "receding"
        );
        assert_eq!(contact_time(-10.0, 5.0, 2.0, 0.0, 2.0, 0.0), None, "miss");
        assert_eq!(
            contact_time(-1.999, 0.0, 1.0, 0.0, 2.0, 0.0),
            Some(0.0),
            "overlap"
        );
    }

    #[test]
    fn elastic_collision_conserves_momentum_and_energy() {
        let (mi, mj) = (1.0, 3.0);
        let (vi, vj) = ((1.0, 0.3), (-0.5, 0.2));
        let imp = collide(-0.8, -0.6, vi.0 - vj.0, vi.1 - vj.1, mi, mj, 1.0);
        let vi2 = (vi.0 + imp.dvx_i, vi.1 + imp.dvy_i);
        let vj2 = (vj.0 + imp.dvx_j, vj.1 + imp.dvy_j);
        let p0 = (mi * vi.0 + mj * vj.0, mi * vi.1 + mj * vj.1);
        let p1 = (mi * vi2.0 + mj * vj2.0, mi * vi2.1 + mj * vj2.1);
        assert!((p0.0 - p1.0).abs() < 1e-15 && (p0.1 - p1.1).abs() < 1e-15);
        let ke = |a: (f64, f64), b: (f64, f64)| {
            0.5 * mi * (a.0 * a.0 + a.1 * a.1) + 0.5 * mj * (b.0 * b.0 + b.1 * b.1)
        };
        assert!((ke(vi, vj) - ke(vi2, vj2)).abs() < 1e-15);
        assert_eq!(imp.energy_lost, 0.0);
    }

    #[test]
    fn inelastic_collision_loses_the_stated_energy() {
        let imp = collide(-1.0, 0.0, 2.0, 0.0, 1.0, 1.0, 0.5);
        // u = −2, μ = ½: lost ½·½·(1 − ¼)·4 = 0.75; relative normal speed after = e·2 = 1.
        assert!((imp.energy_lost - 0.75).abs() < 1e-15);
        let u_after = -(2.0 + imp.dvx_i - imp.dvx_j);
        assert!((u_after - 1.0).abs() < 1e-15);
    }

    #[test]
    fn touching_disks_approaching_below_their_velocities_round_off_do_not_collide() {
        // Two disks of a column flying together at 5e-4 (bed_at_rest with TC, seed 1): one
        // centre 7e-11 off the vertical, horizontal velocities 1.3e-12 apart. An impulse of
        // ~1e-22 is below ulp(5e-4) ≈ 1e-19: colliding would change nothing and repeat.
        let (dx, dy, dvx) = (7e-11, -1.0, -1.27e-12);
        assert_eq!(contact_time(dx, dy, dvx, 0.0, 1.0, 2e-3), None);
        // Without the velocities' scale it would be a contact now.
        assert_eq!(contact_time(dx, dy, dvx, 0.0, 1.0, 0.0), Some(0.0));
        // A real approach of the same pair is still found.
        assert_eq!(contact_time(dx, dy, 0.0, 1e-9, 1.0, 2e-3), Some(0.0));
    }

    proptest::proptest! {
        /// The branch-free time of a pair apart is the root of the contact equation, and where
        /// `contact_time_within` turns the pair down for a finite horizon, the time is later
        /// than the horizon: the earliest of several pairs is the same either way.
        #[test]
        fn meeting_time_is_the_contact_time(
            dx in -3.0f64..3.0,
            dy in -3.0f64..3.0,
            dvx in -2.0f64..2.0,
            dvy in -2.0f64..2.0,
            s in 0.5f64..1.5,
            horizon in 0.0f64..4.0,
            mode in 0u8..3,
            grazing in -1e-12f64..1e-12,
        ) {
            // Apart (mode 0), in contact up to round-off (1), or in contact and approaching
            // only within round-off of the velocities (2): the hard cases.
            let r = (dx * dx + dy * dy).sqrt().max(1e-3);
            let (dx, dy) = if mode == 0 { (dx, dy) } else { (dx * s / r, dy * s / r) };
            let (dvx, dvy) = if mode == 2 {
                // Tangential, with a tiny approach along the normal.
                let v = (dvx * dvx + dvy * dvy).sqrt();
                let (nx, ny) = (dx / s, dy / s);
                (-ny * v - nx * grazing.abs(), nx * v - ny * grazing.abs())
            } else {
                (dvx, dvy)
            };
            let speed = dvx.abs() + dvy.abs();
            proptest::prop_assume!(paths_meet(dx, dy, dvx, dvy, s));
            let t = meeting_time(dx, dy, dvx, dvy, s, speed);
            // Apart, the time is the smaller root of |Δr + Δv t| = s, here in the other form
            // of the quadratic's solution.
            let (b, c) = (dx * dvx + dy * dvy, dx * dx + dy * dy - s * s);
            let dv2 = dvx * dvx + dvy * dvy;
            if mode == 0 && c > 1e-6 && dv2 > 1e-6 {
                let root = (-b - (b * b - dv2 * c).sqrt()) / dv2;
                proptest::prop_assert!((t - root).abs() <= 1e-9 * root.max(1.0), "{} {}", t, root);
            }
            if contact_time_within(dx, dy, dvx, dvy, s, speed, horizon).is_none() {
                proptest::prop_assert!(t > horizon, "{} <= {}", t, horizon);
            }
        }
    }

    #[test]
    fn a_pressed_pair_receding_by_round_off_is_lifted_apart() {
        // Disk i above j, receding at 1e-15 while the floor of the rebound is 1e-3.
        let imp = collide_rebounding(0.0, 1.0, 0.0, 1e-15, 1.0, 1.0, 1.0, 1e-3);
        let after = 1e-15 + imp.dvy_i - imp.dvy_j;
        assert!((after - 1e-3).abs() < 1e-15, "{after}");
        assert_eq!(imp.normal_speed, 0.0);
        // Receding faster than the floor: nothing happens.
        let imp = collide_rebounding(0.0, 1.0, 0.0, 2e-3, 1.0, 1.0, 1.0, 1e-3);
        assert_eq!((imp.dvy_i, imp.dvy_j, imp.momentum), (0.0, 0.0, 0.0));
    }
}

/// Outcome of the contact search between a disk riding the floor and a flying disk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RiderContact {
    /// They touch at this time.
    At(f64),
    /// The search did not conclude within its budget (a grazing pair): look again then.
    Recheck(f64),
}

/// Iterations of the rider–flyer contact search before it asks to be re-run.
const RIDER_STEPS: usize = 200;

/// First time in `[now, limit]` at which a disk riding the floor touches a flying disk.
///
/// The rider moves with `x_r + vx_r τ − κ Q(τ)` and `y = h(t) + a_r` (`ride(t)` gives `(h, h')`;
/// `κ ≠ 0` while it slides on a rough floor, `Q(τ) = ½ g τ² + h(t) − h(now) − h'(now) τ`, see
/// [`slide`](crate::physics::slide)); the flyer
/// on its parabola under gravity `g` (`ride_acc(t)` is the rider's vertical acceleration). `dx` is
/// the flyer's x minus the rider's at `now` (minimum
/// image), `dy0` the flyer's y minus the rider's, `dvx` and `dvy0` likewise, `s` the contact
/// distance and `k_floor` a bound on |h''|. With `F(τ) = |Δr|² − s²`,
/// `|F''| ≤ 2(Δvx² + Δvy² + (|Δx| |κ| + |Δy|) (g + k_floor))`, bounded over a window from the values at its
/// start; stepping to the first root of the parabola `F + F' σ − ½ M σ²` never passes the first
/// root of F (the same safe-step scheme as the floor impacts).
#[allow(clippy::too_many_arguments)]
pub fn rider_contact(
    dx: f64,
    dvx: f64,
    flyer_y: f64,
    flyer_vy: f64,
    rider_a: f64,
    s: f64,
    g: f64,
    k_floor: f64,
    kappa: f64,
    now: f64,
    limit: f64,
    ride: impl Fn(f64) -> (f64, f64),
    ride_acc: impl Fn(f64) -> f64,
) -> Option<RiderContact> {
    let k = g + k_floor;
    let kx = kappa.abs() * k;
    let tol = 1e-13 * s * s;
    let (h0, hd0) = if kappa != 0.0 { ride(now) } else { (0.0, 0.0) };
    let mut tau = 0.0f64;
    let mut window = f64::NAN;
    for _ in 0..RIDER_STEPS {
        let t = now + tau;
        if t > limit {
            return None;
        }
        let (h, hd) = ride(t);
        // The rider's slide (nothing when κ = 0: the terms vanish exactly).
        let (q, push) = (0.5 * g * tau * tau + h - h0 - hd0 * tau, g * tau + hd - hd0);
        let ddx = dx + dvx * tau + kappa * q;
        let dvx_t = dvx + kappa * push;
        let ddy = flyer_y + (flyer_vy - 0.5 * g * tau) * tau - h - rider_a;
        let dvy = flyer_vy - g * tau - hd;
        let f = ddx * ddx + ddy * ddy - s * s;
        let fd = 2.0 * (ddx * dvx_t + ddy * dvy);
        let bound = |w: f64| {
            let v = dvy.abs() + k * w;
            let y = ddy.abs() + dvy.abs() * w + 0.5 * k * w * w;
            let u = dvx_t.abs() + kx * w;
            let x = ddx.abs() + dvx_t.abs() * w + 0.5 * kx * w * w;
            2.0 * (u * u + v * v + y * k + x * kx)
        };
        if f <= tol {
            // Touching. Half of F'' now: relative speed² + Δr·(relative acceleration).
            let press = g + ride_acc(t);
            let curvature = dvx_t * dvx_t + dvy * dvy - ddy * press + ddx * (kappa * press);
            if fd.abs() <= 1e-12 * s * (dvx_t.abs() + dvy.abs()) + tol / s && curvature >= 0.0 {
                // No normal approach, and nothing pressing the pair together: no collision now
                // (colliding would exchange nothing). Look again once the floor's motion could
                // have changed that: after the time to move by a rest height under g + h''.
                let wait = (2.0 * crate::physics::floor::PAIR_REST_HEIGHT * s
                    / k.max(f64::MIN_POSITIVE))
                .sqrt();
                let t_next = t + wait;
                return (t_next <= limit).then_some(RiderContact::Recheck(t_next));
            }
            if fd <= 0.0 {
                return Some(RiderContact::At(t));
            }
            // Touching but separating: F stays ≥ f + f'σ − ½Mσ² ≥ 0 for σ ≤ 2f'/M(σ), where
            // M(σ) bounds |F''| over the window σ. The widest such σ is the fixed point of
            // σ = 2f'/M(σ) (M grows with σ): approach it geometrically, then keep the step
            // inside the window its bound holds on.
            if bound(0.0) <= 0.0 {
                return None; // nothing will ever bend the separation back
            }
            let mut w = fd / bound(0.0);
            for _ in 0..8 {
                w = (w * 2.0 * fd / bound(w)).sqrt();
            }
            let step = w.min(2.0 * fd / bound(w));
            tau += step.max(f64::EPSILON * t.abs().max(1.0));
            continue;
        }
        if window.is_nan() {
            let m0 = bound(0.0);
            window = if m0 > 0.0 {
                (2.0 * f / m0).sqrt()
            } else if fd < 0.0 {
                f / -fd
            } else {
                return None;
            };
        }
        let w = window.min((limit - t).max(0.0)).max(f64::MIN_POSITIVE);
        let m = bound(w);
        let step = if m > 0.0 {
            let root = (fd * fd + 2.0 * m * f).sqrt();
            if fd >= 0.0 {
                (fd + root) / m
            } else {
                2.0 * f / (root - fd)
            }
        } else if fd < 0.0 {
            f / -fd
        } else {
            f64::INFINITY
        };
        if step >= w {
            if t + w >= limit {
                return None;
            }
            tau += w;
            window = 2.0 * w;
        } else {
            tau += step;
            window = step.max(f64::MIN_POSITIVE) * 2.0;
        }
    }
    let t = now + tau;
    (t <= limit).then_some(RiderContact::Recheck(t))
}
