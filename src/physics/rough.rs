//! Rough disks: rotation, tangential restitution and Coulomb friction (Walton's model).
//!
//! Each disk has an angular velocity ω and a moment of inertia `I = q m a²` (q = ½ for a
//! uniform disk). At a contact with normal `n` (from the other body to the disk) and tangent
//! `t = (−n_y, n_x)`, the contact points' relative tangential velocity is
//! `g_t = Δv·t − (a_i ω_i + a_j ω_j)`. The normal impulse `p_n` is today's (restitution and its
//! cures); the tangential impulse `J` (along `t` on disk i) makes `g_t' = −β g_t` for a sticking
//! contact, `J = −(1 + β) m_t g_t` with `1/m_t = (1 + 1/q_i)/m_i + (1 + 1/q_j)/m_j`, and is
//! capped at `μ p_n` (a sliding contact: `J = −sign(g_t) μ p_n`). The disks' velocities change
//! by `±J t/m` and their spins by `Δω = −a J / I`. Energy lost to the tangential part:
//! `−(J g_t + J²/(2 m_t))`, `½ m_t (1 − β²) g_t²` when sticking. A wall, the lid or the floor
//! is a body of infinite mass that does not turn (`1/m_j = 0`, `a_j = 0`).
//!
//! One home for the rule, for pair collisions and boundary impacts alike, in the exact engine
//! and the approximate schemes; the rotational state it acts on is the disks'
//! ([`Spins`](crate::physics::disks::Spins)).

use crate::physics::disks::Disks;
use crate::physics::walls::Side;

/// The tangential part of a contact law: tangential restitution β ∈ [−1, 1] of sticking
/// contacts, capped by Coulomb friction μ ≥ 0 (∞: no cap). β = −1 or μ = 0 is a smooth contact.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Friction {
    /// Tangential restitution of a sticking contact.
    pub beta: f64,
    /// Coulomb friction coefficient (∞ when not capped).
    pub mu: f64,
}

impl Friction {
    /// A smooth contact: no tangential impulse.
    pub const SMOOTH: Friction = Friction {
        beta: -1.0,
        mu: 0.0,
    };

    /// The law a scenario's pair of fields names: β alone is a constant tangential
    /// restitution; μ alone is Coulomb friction up to a contact that stops slipping (β = 0,
    /// the disks leave rolling on each other); neither is smooth.
    pub fn of(beta: Option<f64>, mu: Option<f64>) -> Friction {
        match (beta, mu) {
            (None, None) => Friction::SMOOTH,
            (b, m) => Friction {
                beta: b.unwrap_or(0.0),
                mu: m.unwrap_or(f64::INFINITY),
            },
        }
    }

    /// `true` when the contact exchanges no tangential impulse.
    pub fn is_smooth(&self) -> bool {
        self.beta == -1.0 || self.mu == 0.0
    }

    /// The tangential impulse on the disk along `t`, for a tangential velocity `g_t` of the
    /// contact points, a normal impulse `p_n ≥ 0` and the tangential effective mass `m_t`. A
    /// contact that does not press (`p_n = 0`: a pair not approaching, by round-off) exchanges
    /// nothing.
    #[inline]
    pub fn impulse(&self, g_t: f64, p_n: f64, m_t: f64) -> f64 {
        if self.is_smooth() || g_t == 0.0 || p_n <= 0.0 {
            return 0.0;
        }
        let stick = -(1.0 + self.beta) * m_t * g_t;
        let cap = self.mu * p_n;
        if stick.abs() <= cap {
            stick
        } else {
            -cap.copysign(g_t)
        }
    }
}

/// The tangential laws of a rough scene: of pair collisions, of the floor, of the side walls
/// and the lid.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Roughness {
    /// Pair collisions.
    pub pair: Friction,
    /// Disk–floor impacts.
    pub floor: Friction,
    /// Side walls and lid.
    pub walls: Friction,
    /// `q` in `I = q m a²`.
    pub inertia_factor: f64,
}

impl Roughness {
    /// The tangential part of the collision of disks `i` and `j` of `disks`: unit normal `n`
    /// from `j` to `i`, the centres' relative velocity `dv` before the normal impulse `p_n`.
    #[inline]
    pub fn pair_kick(
        &self,
        disks: &Disks,
        (i, j): (usize, usize),
        n: (f64, f64),
        dv: (f64, f64),
        p_n: f64,
    ) -> Kick {
        kick(
            &self.pair,
            n,
            dv,
            &Body::disk(disks, i),
            &Body::disk(disks, j),
            p_n,
        )
    }

    /// The tangential part of disk `i`'s impact on `boundary` moving with velocity `wall` (the
    /// floor's; 0 for the others), after the normal part changed the disk's velocity from
    /// `before` to what it is now: the normal impulse is the change along the normal.
    #[inline]
    pub fn boundary_kick(
        &self,
        disks: &Disks,
        i: usize,
        boundary: Boundary,
        wall: (f64, f64),
        before: (f64, f64),
    ) -> Kick {
        let law = boundary.law(self);
        fixed_kick(
            &law,
            disks,
            i,
            (boundary.normal(), wall, before),
            &Body::WALL,
        )
    }
}

/// The tangential part of disk `i`'s impact on a body `other` that does not give (a wall, the
/// lid, the floor, or a disk held at rest), with unit normal `n` from it to the disk, moving
/// with velocity `wall`, after the normal part changed the disk's velocity from `before` to
/// what it is now: the normal impulse is that change along the normal.
#[inline]
pub fn fixed_kick(
    law: &Friction,
    disks: &Disks,
    i: usize,
    (n, wall, before): ((f64, f64), (f64, f64), (f64, f64)),
    other: &Body,
) -> Kick {
    let m = &disks.motion[i];
    let p_n = disks.mass[i] * ((m.vx - before.0) * n.0 + (m.vy - before.1) * n.1);
    let dv = (m.vx - wall.0, m.vy - wall.1);
    kick(law, n, dv, &Body::disk(disks, i), other, p_n)
}

/// The boundary a disk hits, by the normal from it to the disk.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// The left side wall.
    Left,
    /// The right side wall.
    Right,
    /// The lid.
    Lid,
    /// The floor.
    Floor,
}

impl Boundary {
    /// The unit normal from the boundary to a disk that hits it.
    pub fn normal(self) -> (f64, f64) {
        match self {
            Boundary::Left => (1.0, 0.0),
            Boundary::Right => (-1.0, 0.0),
            Boundary::Lid => (0.0, -1.0),
            Boundary::Floor => (0.0, 1.0),
        }
    }

    /// Its tangential law: the floor's, or the side walls' and lid's.
    pub fn law(self, r: &Roughness) -> Friction {
        match self {
            Boundary::Floor => r.floor,
            _ => r.walls,
        }
    }

    /// The side wall `side`.
    pub fn side(side: Side) -> Boundary {
        match side {
            Side::Left => Boundary::Left,
            Side::Right => Boundary::Right,
        }
    }
}

/// What the tangential part of one contact does: disk i's velocity changes by `j·t/m_i` and
/// disk j's by `−j·t/m_j`; their spins by `dw_i`, `dw_j`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Kick {
    /// Tangential impulse on disk i along `t = (−n_y, n_x)`.
    pub j: f64,
    /// Velocity change of disk i.
    pub dv_i: (f64, f64),
    /// Velocity change of disk j.
    pub dv_j: (f64, f64),
    /// Spin change of disk i.
    pub dw_i: f64,
    /// Spin change of disk j.
    pub dw_j: f64,
    /// Kinetic energy (translational and rotational) lost, ≥ 0.
    pub energy_lost: f64,
}

impl Kick {
    /// Disk `i` of `disks` takes its side of the kick at time `now` (on the clock the spins'
    /// orientations refer to), and disk `j`, if the other body is a disk, takes the other.
    #[inline]
    pub fn apply(&self, disks: &mut Disks, i: usize, j: Option<usize>, now: f64) {
        take(disks, i, self.dv_i, self.dw_i, now);
        if let Some(j) = j {
            take(disks, j, self.dv_j, self.dw_j, now);
        }
    }
}

/// Disk `i` takes its side of a tangential kick: velocity change `dv`, spin change `dw`.
fn take(disks: &mut Disks, i: usize, dv: (f64, f64), dw: f64, now: f64) {
    disks.motion[i].vx += dv.0;
    disks.motion[i].vy += dv.1;
    disks
        .spins
        .as_mut()
        .expect("rough disks have spins")
        .spin(i, now, dw);
}

/// One side of a contact: a disk's mass, radius, inertia factor q and spin; a wall is
/// [`Body::WALL`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Mass (∞ for a wall).
    pub m: f64,
    /// Radius (0 for a wall: its contact point is where it is hit).
    pub a: f64,
    /// `I = q m a²`.
    pub q: f64,
    /// Angular velocity.
    pub w: f64,
}

impl Body {
    /// Disk `i` of `disks` (with its spin; a disk without spins does not turn).
    pub fn disk(disks: &Disks, i: usize) -> Body {
        Body {
            m: disks.mass[i],
            a: disks.radius[i],
            q: disks.spins.as_ref().map_or(1.0, |s| s.q),
            w: disks.spins.as_ref().map_or(0.0, |s| s.omega[i]),
        }
    }

    /// A wall, the lid or the floor: infinite mass, no turning.
    pub const WALL: Body = Body {
        m: f64::INFINITY,
        a: 0.0,
        q: 1.0,
        w: 0.0,
    };

    /// `1/m + a²/I = (1 + 1/q)/m`, this body's part of the tangential inverse mass.
    fn inverse_mass(&self) -> f64 {
        (1.0 + 1.0 / self.q) / self.m
    }
}

/// The tangential part of a contact of disk `i` with `j` (a disk or [`Body::WALL`]): unit
/// normal `n` from `j` to `i`, relative velocity `dv = v_i − v_j` (of the centres; for a wall,
/// the disk's velocity less the wall's), and the normal impulse `p_n ≥ 0` the normal part gave.
#[inline]
pub fn kick(law: &Friction, n: (f64, f64), dv: (f64, f64), i: &Body, j: &Body, p_n: f64) -> Kick {
    if law.is_smooth() {
        return Kick::default();
    }
    let t = (-n.1, n.0);
    let g_t = dv.0 * t.0 + dv.1 * t.1 - (i.a * i.w + j.a * j.w);
    let m_t = 1.0 / (i.inverse_mass() + j.inverse_mass());
    let jt = law.impulse(g_t, p_n, m_t);
    if jt == 0.0 {
        return Kick::default();
    }
    let (di, dj) = (jt / i.m, -jt / j.m);
    Kick {
        j: jt,
        dv_i: (di * t.0, di * t.1),
        dv_j: (dj * t.0, dj * t.1),
        dw_i: -i.a * jt / (i.q * i.m * i.a * i.a),
        dw_j: if j.m.is_finite() {
            -j.a * jt / (j.q * j.m * j.a * j.a)
        } else {
            0.0
        },
        energy_lost: -(jt * g_t + 0.5 * jt * jt / m_t),
    }
}

/// Whether static friction lets two contacts hold a disk still under its weight: unit normals
/// `n1`, `n2` from the supports to the disk (both contacts on its rim), Coulomb coefficients
/// `mu1`, `mu2` (∞: no cap). The contact forces `N_i n_i + f_i t_i` (with `t = (−n_y, n_x)`)
/// must sum to the weight's opposite, their torques about the centre cancel (`f_1 + f_2 = 0`),
/// and each stays in its friction cone (`N_i ≥ 0`, `|f_i| ≤ μ_i N_i`). For a given `f = f_1`
/// the forces balance with `N_i` linear in `f`; the constraints cut an interval of `f`, which
/// must not be empty. Frictionless (`μ = 0`) this is the normals bracketing the vertical.
pub fn friction_holds(n1: (f64, f64), n2: (f64, f64), mu1: f64, mu2: f64) -> bool {
    let det = n1.0 * n2.1 - n1.1 * n2.0;
    if det.abs() < 1e-12 {
        return false;
    }
    // N(f) = N(0) + f N': weight (0, 1) less f (t1 − t2), solved by Cramer's rule.
    let (t1, t2) = ((-n1.1, n1.0), (-n2.1, n2.0));
    let d = (t1.0 - t2.0, t1.1 - t2.1);
    let cramer = |b: (f64, f64)| {
        (
            (b.0 * n2.1 - b.1 * n2.0) / det,
            (n1.0 * b.1 - n1.1 * b.0) / det,
        )
    };
    let (n1_0, n2_0) = cramer((0.0, 1.0));
    let (n1_d, n2_d) = cramer((-d.0, -d.1));
    // Each constraint c + a f ≥ 0 narrows [lo, hi].
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    let mut keep = |c: f64, a: f64| {
        if a > 0.0 {
            lo = lo.max(-c / a);
        } else if a < 0.0 {
            hi = hi.min(-c / a);
        } else if c < 0.0 {
            hi = f64::NEG_INFINITY;
        }
    };
    for (c, a, mu) in [(n1_0, n1_d, mu1), (n2_0, n2_d, mu2)] {
        keep(c, a); // N ≥ 0
        if mu.is_finite() {
            keep(mu * c, mu * a - 1.0); // μN − f ≥ 0
            keep(mu * c, mu * a + 1.0); // μN + f ≥ 0
        }
    }
    lo <= hi
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::disks::Spins;
    use crate::physics::pair::collide;

    /// Two disks in contact and what a collision with the normal impulse of today and the
    /// tangential kick does to them: positions, velocities, spins before and after.
    struct Pair {
        r: [(f64, f64); 2],
        v: [(f64, f64); 2],
        w: [f64; 2],
        m: [f64; 2],
        a: [f64; 2],
        q: f64,
    }

    impl Pair {
        fn new(angle: f64, v: [(f64, f64); 2], w: [f64; 2]) -> Pair {
            let (m, a) = ([1.0, 2.7], [0.5, 0.8]);
            let s = a[0] + a[1];
            Pair {
                r: [(0.3 + s * angle.cos(), -0.2 + s * angle.sin()), (0.3, -0.2)],
                v,
                w,
                m,
                a,
                q: 0.5,
            }
        }

        /// Collides the pair with restitution `e` and `law`: the new velocities and spins,
        /// and the energy the rule says was lost.
        fn collide(&self, e: f64, law: &Friction) -> ([(f64, f64); 2], [f64; 2], f64) {
            let (dx, dy) = (self.r[0].0 - self.r[1].0, self.r[0].1 - self.r[1].1);
            let dv = (self.v[0].0 - self.v[1].0, self.v[0].1 - self.v[1].1);
            let imp = collide(dx, dy, dv.0, dv.1, self.m[0], self.m[1], e);
            let d = (dx * dx + dy * dy).sqrt();
            let body = |k: usize| Body {
                m: self.m[k],
                a: self.a[k],
                q: self.q,
                w: self.w[k],
            };
            let k = kick(law, (dx / d, dy / d), dv, &body(0), &body(1), imp.momentum);
            let v = [
                (
                    self.v[0].0 + imp.dvx_i + k.dv_i.0,
                    self.v[0].1 + imp.dvy_i + k.dv_i.1,
                ),
                (
                    self.v[1].0 + imp.dvx_j + k.dv_j.0,
                    self.v[1].1 + imp.dvy_j + k.dv_j.1,
                ),
            ];
            let w = [self.w[0] + k.dw_i, self.w[1] + k.dw_j];
            (v, w, imp.energy_lost + k.energy_lost)
        }

        fn energy(&self, v: &[(f64, f64); 2], w: &[f64; 2]) -> f64 {
            (0..2)
                .map(|k| {
                    0.5 * self.m[k] * (v[k].0 * v[k].0 + v[k].1 * v[k].1)
                        + 0.5 * self.q * self.m[k] * self.a[k] * self.a[k] * w[k] * w[k]
                })
                .sum()
        }

        /// Angular momentum about `p`, orbital plus spin.
        fn angular_momentum(&self, v: &[(f64, f64); 2], w: &[f64; 2], p: (f64, f64)) -> f64 {
            (0..2)
                .map(|k| {
                    let (x, y) = (self.r[k].0 - p.0, self.r[k].1 - p.1);
                    self.m[k] * (x * v[k].1 - y * v[k].0)
                        + self.q * self.m[k] * self.a[k] * self.a[k] * w[k]
                })
                .sum()
        }
    }

    proptest::proptest! {
        /// Every collision conserves momentum and angular momentum about any point, loses the
        /// energy the rule states (never gains), and is smooth for β = −1 or μ = 0.
        #[test]
        fn a_rough_collision_conserves_momenta_and_loses_the_stated_energy(
            angle in 0.0f64..6.3,
            v0 in proptest::array::uniform4(-2.0f64..2.0),
            w in proptest::array::uniform2(-4.0f64..4.0),
            e in 0.0f64..=1.0,
            beta in -1.0f64..=1.0,
            mu in 0.0f64..2.0,
            capped in proptest::bool::ANY,
            p in proptest::array::uniform2(-50.0f64..50.0),
        ) {
            let pair = Pair::new(angle, [(v0[0], v0[1]), (v0[2], v0[3])], w);
            let law = Friction { beta, mu: if capped { mu } else { f64::INFINITY } };
            let (v, w2, lost) = pair.collide(e, &law);
            let before = pair.energy(&pair.v, &pair.w);
            let after = pair.energy(&v, &w2);
            let scale = before.max(1.0);
            proptest::prop_assert!((before - after - lost).abs() <= 1e-13 * scale,
                "lost {} stated {}", before - after, lost);
            proptest::prop_assert!(lost >= -1e-14 * scale);
            for k in 0..2 {
                let p0 = pair.m[0] * [pair.v[0].0, pair.v[0].1][k] + pair.m[1] * [pair.v[1].0, pair.v[1].1][k];
                let p1 = pair.m[0] * [v[0].0, v[0].1][k] + pair.m[1] * [v[1].0, v[1].1][k];
                proptest::prop_assert!((p0 - p1).abs() <= 1e-13 * scale);
            }
            let (l0, l1) = (pair.angular_momentum(&pair.v, &pair.w, (p[0], p[1])),
                            pair.angular_momentum(&v, &w2, (p[0], p[1])));
            proptest::prop_assert!((l0 - l1).abs() <= 1e-12 * scale * 100.0, "{} {}", l0, l1);
        }

        /// β = −1 or μ = 0 is exactly today's smooth collision, and the spins do not change.
        #[test]
        fn beta_minus_one_or_no_friction_is_the_smooth_collision_bit_for_bit(
            angle in 0.0f64..6.3,
            v0 in proptest::array::uniform4(-2.0f64..2.0),
            w in proptest::array::uniform2(-4.0f64..4.0),
            e in 0.0f64..=1.0,
            x in -1.0f64..=1.0,
        ) {
            let pair = Pair::new(angle, [(v0[0], v0[1]), (v0[2], v0[3])], w);
            let smooth = pair.collide(e, &Friction::SMOOTH);
            for law in [Friction { beta: -1.0, mu: 1.0 + x }, Friction { beta: x, mu: 0.0 }] {
                let rough = pair.collide(e, &law);
                proptest::prop_assert_eq!(rough.0, smooth.0);
                proptest::prop_assert_eq!(rough.1, pair.w);
            }
        }

        /// e = 1 with β = ±1 (no cap) keeps the kinetic energy, rotation included.
        #[test]
        fn perfectly_rough_and_smooth_elastic_collisions_keep_the_energy(
            angle in 0.0f64..6.3,
            v0 in proptest::array::uniform4(-2.0f64..2.0),
            w in proptest::array::uniform2(-4.0f64..4.0),
            rough in proptest::bool::ANY,
        ) {
            let pair = Pair::new(angle, [(v0[0], v0[1]), (v0[2], v0[3])], w);
            let beta = if rough { 1.0 } else { -1.0 };
            let (v, w2, lost) = pair.collide(1.0, &Friction { beta, mu: f64::INFINITY });
            let before = pair.energy(&pair.v, &pair.w);
            proptest::prop_assert!((before - pair.energy(&v, &w2)).abs() <= 1e-13 * before.max(1.0));
            proptest::prop_assert!(lost.abs() <= 1e-13 * before.max(1.0));
        }
    }

    #[test]
    fn a_sticking_contact_reverses_the_tangential_velocity_times_beta() {
        // Equal disks side by side, i right of j; i moves up, j down, no spins: g_t = 2.
        let pair = Pair {
            r: [(1.0, 0.0), (0.0, 0.0)],
            v: [(-0.1, 1.0), (0.1, -1.0)],
            w: [0.0, 0.0],
            m: [1.0, 1.0],
            a: [0.5, 0.5],
            q: 0.5,
        };
        let law = Friction {
            beta: 0.4,
            mu: f64::INFINITY,
        };
        let (v, w, lost) = pair.collide(1.0, &law);
        let g_t = |v: &[(f64, f64); 2], w: &[f64; 2]| (v[0].1 - v[1].1) - 0.5 * (w[0] + w[1]);
        assert!((g_t(&v, &w) + 0.4 * 2.0).abs() < 1e-15);
        // m_t = 1/(2·3) = 1/6: lost ½·(1/6)·(1 − 0.16)·4.
        assert!((lost - 0.5 / 6.0 * 0.84 * 4.0).abs() < 1e-15);
        // Capped: the impulse is μ p_n = 0.1·(2·½·0.2) = 0.02, against the slip.
        let (v, w, _) = pair.collide(1.0, &Friction { beta: 0.4, mu: 0.1 });
        assert!((v[0].1 - (1.0 - 0.02)).abs() < 1e-15);
        // Δω_i = −a J / I = −0.5·(−0.02)/(0.5·0.25) = 0.08.
        assert!((w[0] - 0.08).abs() < 1e-15 && (w[1] - 0.08).abs() < 1e-15);
    }

    #[test]
    fn a_disk_rolling_on_a_wall_feels_no_friction_and_a_sliding_one_starts_rolling() {
        // Floor normal (0, 1); the disk rolls right: v_x = 1, ω = −v_x/a.
        let disk = |w: f64| Body {
            m: 1.0,
            a: 0.5,
            q: 0.5,
            w,
        };
        let law = Friction::of(None, Some(10.0));
        let k = kick(&law, (0.0, 1.0), (1.0, -1.0), &disk(-2.0), &Body::WALL, 1.0);
        assert_eq!(k, Kick::default());
        // Sliding without spin, β = 0, no cap reached: J = −m_t g_t with m_t = m q/(1 + q) and
        // g_t = −v_x, so it rolls at v_x' = v_x/(1 + q) = 2/3, ω' = −v_x'/a.
        let k = kick(&law, (0.0, 1.0), (1.0, -1.0), &disk(0.0), &Body::WALL, 1.0);
        let (vx, w) = (1.0 + k.dv_i.0, k.dw_i);
        assert!((vx - 2.0 / 3.0).abs() < 1e-15 && (w + vx / 0.5).abs() < 1e-15);
        assert_eq!(k.dv_j, (0.0, 0.0));
    }

    #[test]
    fn a_disk_rubbing_a_wall_takes_the_kick_of_the_normal_impulse_it_got() {
        // A disk (m = 2, a = 0.25) hits the left wall at v = (−1, 0.5) with ω = 1 and leaves
        // at v_x = 0.9: p_n = 2·1.9. The wall's tangent is (0, 1): g_t = 0.5 − 0.25·1 = 0.25;
        // β = 0 without a cap: J = −m_t g_t, m_t = m q/(1 + q).
        let mut disks = Disks::new(&[[0.25, 3.0]], vec![0.25], vec![2.0], vec![0]);
        disks.spins = Some(Spins::new(0.5, vec![1.0]));
        (disks.motion[0].vx, disks.motion[0].vy) = (0.9, 0.5);
        let laws = Roughness {
            pair: Friction::SMOOTH,
            floor: Friction::SMOOTH,
            walls: Friction::of(Some(0.0), None),
            inertia_factor: 0.5,
        };
        let k = laws.boundary_kick(
            &disks,
            0,
            Boundary::side(Side::Left),
            (0.0, 0.0),
            (-1.0, 0.5),
        );
        let m_t = 2.0 * 0.5 / 1.5;
        assert!((k.j + m_t * 0.25).abs() < 1e-15, "{}", k.j);
        k.apply(&mut disks, 0, None, 2.0);
        // It leaves rolling on the wall (g_t = 0), its orientation carrying on from time 2.
        let (vy, w) = (disks.motion[0].vy, disks.spins.as_ref().unwrap().omega[0]);
        assert!((vy - 0.25 * w).abs() < 1e-15, "{vy} {w}");
        assert_eq!(disks.motion[0].vx, 0.9);
        assert!((disks.spins.as_ref().unwrap().angle(0, 2.0) - 2.0).abs() < 1e-15);
        // Capped at μ = 0.02: |J| = μ p_n, from the velocity change along the normal.
        let capped = Roughness {
            walls: Friction::of(Some(0.0), Some(0.02)),
            ..laws
        };
        (disks.motion[0].vy, disks.spins.as_mut().unwrap().omega[0]) = (0.5, 1.0);
        let k = capped.boundary_kick(&disks, 0, Boundary::Left, (0.0, 0.0), (-1.0, 0.5));
        assert!((k.j + 0.02 * 2.0 * 1.9).abs() < 1e-15, "{}", k.j);
        // The lid and the floor have the other law: smooth here.
        let k = laws.boundary_kick(&disks, 0, Boundary::Floor, (0.0, 0.0), (0.9, -1.0));
        assert_eq!(k, Kick::default());
    }

    /// A disk on two supports: held without friction only when the normals bracket the
    /// vertical; with friction the interval of `f` found agrees with a scan of `f` over a fine
    /// grid, for random normals and coefficients.
    #[test]
    fn friction_holds_as_a_scan_of_the_tangential_force_finds() {
        use rand::{Rng, SeedableRng};
        let at = |deg: f64| {
            let r = deg.to_radians();
            (r.sin(), r.cos())
        };
        assert!(friction_holds(at(-30.0), at(30.0), 0.0, 0.0));
        assert!(!friction_holds(at(10.0), at(70.0), 0.0, 0.0));
        assert!(friction_holds(
            at(20.0),
            at(80.0),
            f64::INFINITY,
            f64::INFINITY
        ));
        let scan = |n1: (f64, f64), n2: (f64, f64), mu1: f64, mu2: f64| {
            let det = n1.0 * n2.1 - n1.1 * n2.0;
            let (t1, t2) = ((-n1.1, n1.0), (-n2.1, n2.0));
            (-40_000..=40_000).any(|k| {
                let f = k as f64 * 1e-4;
                let b = (-f * (t1.0 - t2.0), 1.0 - f * (t1.1 - t2.1));
                let big1 = (b.0 * n2.1 - b.1 * n2.0) / det;
                let big2 = (n1.0 * b.1 - n1.1 * b.0) / det;
                big1 >= 0.0 && big2 >= 0.0 && f.abs() <= mu1 * big1 && f.abs() <= mu2 * big2
            })
        };
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(5);
        let (mut held, mut agree) = (0, 0);
        for _ in 0..400 {
            let (a1, a2) = (rng.random_range(-89.0..89.0), rng.random_range(-89.0..89.0));
            let (m1, m2) = (rng.random_range(0.0..1.5), rng.random_range(0.0..1.5));
            let (n1, n2) = (at(a1), at(a2));
            let exact = friction_holds(n1, n2, m1, m2);
            // The grid misses only holds within its step of the cone's edge: skip those.
            let near = friction_holds(n1, n2, 0.99 * m1, 0.99 * m2) != exact
                || friction_holds(n1, n2, 1.01 * m1, 1.01 * m2) != exact;
            if !near {
                assert_eq!(exact, scan(n1, n2, m1, m2), "{a1} {a2} {m1} {m2}");
                agree += 1;
                held += exact as usize;
            }
        }
        assert!(
            agree > 300 && held > 50 && held < agree - 50,
            "{agree} {held}"
        );
    }
}
