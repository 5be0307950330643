//! The prediction's pair loop four at a time (AVX2): every listed neighbour's contact time with
//! packed square roots and divisions, the earliest taken by selection in list order, across the
//! periodic images as [`images::lanes`](crate::engine::images) wraps them.
//!
//! Each lane does exactly the scalar operations, in the same order, of
//! [`paths_meet`](crate::physics::pair::paths_meet),
//! [`paths_meet_within`](crate::physics::pair::paths_meet_within) and
//! [`meeting_time`](crate::physics::pair::meeting_time) on the state the disk's
//! [`Flight`](crate::physics::flight::Flight) gives (IEEE arithmetic is exact per lane, and Rust
//! never contracts a product and a sum): the same results bit for bit as the scalar loop, which
//! stays for other processors (tests compare the two). Run only where the processor has AVX2
//! ([`Lanes`](crate::platform::cpu::Lanes) says so); where `Lanes` takes AVX-512 (an Intel
//! processor that has it, or when asked), the same source compiled with its 32 registers and
//! mask registers runs.

use crate::engine::event::code;
use crate::engine::images::lanes::nearest_image;
use crate::physics::disks::Motion;
use crate::platform::cpu::Lanes;
use crate::platform::masks::{Masks, Vectors};
use std::arch::x86_64::*;

/// What the four-lane search needs to know of the disk that predicts and of the domain.
#[derive(Debug, Clone, Copy)]
pub(in crate::engine) struct Probe {
    /// The disk (its own list's padding: a disk never meets itself).
    pub i: u32,
    /// The present (engine clock).
    pub now: f64,
    /// The disk's state now.
    pub x: f64,
    /// See `x`.
    pub y: f64,
    /// See `x`.
    pub vx: f64,
    /// See `x`.
    pub vy: f64,
    /// `|vx| + |vy|`.
    pub speed: f64,
    /// Its radius.
    pub a: f64,
    /// Gravity: 0 for straight flight (`Straight::advance`), else the fall of
    /// `Ballistic::advance`.
    pub g: f64,
    /// The periodic images: half periods (∞ where not periodic) and periods.
    pub half: [f64; 2],
    /// See `half`.
    pub period: [f64; 2],
}

/// The neighbours a search runs over, and what it reads of them.
#[derive(Debug, Clone, Copy)]
pub(in crate::engine) struct Neighbours<'a> {
    /// The disk's list, in its order.
    pub list: &'a [u32],
    /// Every disk's state (`repr(C)`; every entry of `list` indexes it).
    pub motion: &'a [Motion],
    /// The radius every disk has, where they share one; else `each_radius` holds them.
    pub common_radius: Option<f64>,
    /// See `common_radius`.
    pub each_radius: &'a [f64],
    /// The collision counters, asked for (prefetched) for each neighbour if `prefetch`.
    pub counter: &'a [u32],
    /// See `counter`.
    pub prefetch: bool,
}

/// [`earliest_contact`] on the path `lanes` names: as written (AVX2's 16 registers), or compiled
/// with AVX-512's 32 and its mask registers where `lanes` says the processor has them — the
/// same operations lane by lane, fewer values spilled to the stack and reloaded.
///
/// # Safety
///
/// As [`earliest_contact`]; `lanes` is the AVX2 path or wider.
#[inline(always)]
pub(in crate::engine) unsafe fn earliest_contact_on<const WITHIN: bool>(
    lanes: Lanes,
    p: &Probe,
    n: &Neighbours,
    horizon: f64,
) -> (f64, u32) {
    if lanes.avx512() {
        wide::<WITHIN>(p, n, horizon)
    } else {
        earliest_contact::<Vectors, WITHIN>(p, n, horizon)
    }
}

/// [`earliest_contact`] compiled with AVX-512F and AVX-512VL, its lanes' flags in mask
/// registers. (In a build for baseline x86-64 the loop is a function of its own, compiled for
/// AVX2, and this only calls its AVX2 form: the shipped x86-64-v3 build inlines it here.)
///
/// # Safety
///
/// Only where the processor has AVX2, AVX-512F and AVX-512VL; as [`earliest_contact`].
#[target_feature(enable = "avx2,avx512f,avx512vl")]
unsafe fn wide<const WITHIN: bool>(p: &Probe, n: &Neighbours, horizon: f64) -> (f64, u32) {
    #[cfg(target_feature = "avx2")]
    return earliest_contact::<crate::platform::masks::Registers, WITHIN>(p, n, horizon);
    #[cfg(not(target_feature = "avx2"))]
    return earliest_contact::<Vectors, WITHIN>(p, n, horizon);
}

/// Earliest contact of `probe`'s disk with one of the neighbours `n` from now: (time from now,
/// partner), (∞, `code::NONE`) if none. `WITHIN`: pairs that cannot touch within `horizon` are left
/// out, as by `paths_meet_within`.
///
/// # Safety
///
/// Only where the processor has AVX2; `n.motion` holds a `repr(C)` [`Motion`] per disk, and
/// every entry of `n.list` indexes it (indexing is checked).
#[cfg_attr(target_feature = "avx2", inline(always))]
#[cfg_attr(not(target_feature = "avx2"), target_feature(enable = "avx2"), inline)]
unsafe fn earliest_contact<K: Masks, const WITHIN: bool>(
    p: &Probe,
    n: &Neighbours,
    horizon: f64,
) -> (f64, u32) {
    let Neighbours {
        list,
        motion,
        common_radius,
        each_radius,
        counter,
        prefetch,
    } = *n;
    let set1 = |v: f64| _mm256_set1_pd(v);
    let (now, xi, yi, vxi, vyi) = (set1(p.now), set1(p.x), set1(p.y), set1(p.vx), set1(p.vy));
    let speed_i = set1(p.speed);
    let (half_x, half_y) = (set1(p.half[0]), set1(p.half[1]));
    let (neg_half_x, neg_half_y) = (set1(-p.half[0]), set1(-p.half[1]));
    let (period_x, period_y) = (set1(p.period[0]), set1(p.period[1]));
    let (g, half_g) = (set1(p.g), set1(0.5 * p.g));
    let sign = set1(-0.0);
    let zero = _mm256_setzero_pd();
    let inf = set1(f64::INFINITY);
    let (t_shell, t_touch) = (set1(1e-12), set1(1e-26));
    let (minus_two, slack, reach) = (set1(-2.0), set1(1.0 + 1e-12), set1(horizon));
    let s_common = common_radius.map(|r| set1(p.a + r));
    let a = set1(p.a);
    // Per lane: the earliest time so far and (list position << 32 | partner) of it.
    let mut best = inf;
    let mut key = _mm256_set1_epi64x(i64::MAX);
    let mut position = _mm256_set_epi64x(3 << 32, 2 << 32, 1 << 32, 0);
    let step = _mm256_set1_epi64x(4 << 32);
    let state = |j: u32| -> (__m256d, f64) {
        let m = &motion[j as usize];
        (_mm256_loadu_pd(&m.x as *const f64), m.t)
    };
    for group in list.chunks(4) {
        let js = [
            group[0],
            *group.get(1).unwrap_or(&p.i),
            *group.get(2).unwrap_or(&p.i),
            *group.get(3).unwrap_or(&p.i),
        ];
        if prefetch {
            for &j in &js {
                crate::platform::prefetch::prefetch(counter, j as usize);
            }
        }
        let (r0, t0) = state(js[0]);
        let (r1, t1) = state(js[1]);
        let (r2, t2) = state(js[2]);
        let (r3, t3) = state(js[3]);
        // Rows (x, y, vx, vy) to columns.
        let lo01 = _mm256_unpacklo_pd(r0, r1); // x0 x1 vx0 vx1
        let hi01 = _mm256_unpackhi_pd(r0, r1); // y0 y1 vy0 vy1
        let lo23 = _mm256_unpacklo_pd(r2, r3);
        let hi23 = _mm256_unpackhi_pd(r2, r3);
        let x = _mm256_permute2f128_pd::<0x20>(lo01, lo23);
        let vx = _mm256_permute2f128_pd::<0x31>(lo01, lo23);
        let y = _mm256_permute2f128_pd::<0x20>(hi01, hi23);
        let vy = _mm256_permute2f128_pd::<0x31>(hi01, hi23);
        let dt = _mm256_sub_pd(now, _mm256_set_pd(t3, t2, t1, t0));
        // Flight to now: x + vx dt; y + vy dt, or y + (vy − ½ g dt) dt and vy − g dt.
        let xj = _mm256_add_pd(x, _mm256_mul_pd(vx, dt));
        let (yj, vyj) = if p.g != 0.0 {
            let fall = _mm256_sub_pd(vy, _mm256_mul_pd(half_g, dt));
            (
                _mm256_add_pd(y, _mm256_mul_pd(fall, dt)),
                _mm256_sub_pd(vy, _mm256_mul_pd(g, dt)),
            )
        } else {
            (_mm256_add_pd(y, _mm256_mul_pd(vy, dt)), vy)
        };
        let dx = nearest_image::<K>(_mm256_sub_pd(xi, xj), half_x, neg_half_x, period_x);
        let dy = nearest_image::<K>(_mm256_sub_pd(yi, yj), half_y, neg_half_y, period_y);
        let s = match s_common {
            Some(s) => s,
            None => _mm256_add_pd(
                a,
                _mm256_set_pd(
                    each_radius[js[3] as usize],
                    each_radius[js[2] as usize],
                    each_radius[js[1] as usize],
                    each_radius[js[0] as usize],
                ),
            ),
        };
        let dvx = _mm256_sub_pd(vxi, vx);
        let dvy = _mm256_sub_pd(vyi, vyj);
        let speed = _mm256_add_pd(
            _mm256_add_pd(speed_i, _mm256_andnot_pd(sign, vx)),
            _mm256_andnot_pd(sign, vyj),
        );
        // b = Δr·Δv, c = Δr² − s², |Δv|², the discriminant.
        let b = _mm256_add_pd(_mm256_mul_pd(dx, dvx), _mm256_mul_pd(dy, dvy));
        let ss = _mm256_mul_pd(s, s);
        let c = _mm256_sub_pd(
            _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)),
            ss,
        );
        let dv2 = _mm256_add_pd(_mm256_mul_pd(dvx, dvx), _mm256_mul_pd(dvy, dvy));
        let bb = _mm256_mul_pd(b, b);
        let disc = _mm256_sub_pd(bb, _mm256_mul_pd(dv2, c));
        let mut meet = K::and(
            K::cmp::<_CMP_LT_OQ>(b, zero),
            K::cmp::<_CMP_GE_OQ>(disc, zero),
        );
        if WITHIN {
            let limit = _mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(minus_two, b), reach), slack);
            let beyond = K::and(
                K::cmp::<_CMP_GT_OQ>(c, zero),
                K::cmp::<_CMP_GE_OQ>(c, limit),
            );
            meet = K::and_not(beyond, meet);
        }
        // In contact and approaching only within round-off: not a collision.
        let s_scale = _mm256_mul_pd(_mm256_mul_pd(t_shell, s), s);
        let v_scale = _mm256_mul_pd(
            _mm256_mul_pd(_mm256_mul_pd(t_touch, s), s),
            _mm256_max_pd(_mm256_mul_pd(speed, speed), dv2),
        );
        let touching = K::and(
            K::cmp::<_CMP_LE_OQ>(c, s_scale),
            K::cmp::<_CMP_LE_OQ>(bb, v_scale),
        );
        let root = _mm256_sub_pd(_mm256_sqrt_pd(disc), b);
        let t = _mm256_max_pd(_mm256_div_pd(c, root), zero);
        let t = K::select(K::and_not(touching, meet), t, inf);
        // Lane by lane, the earliest in list order.
        let earlier = K::cmp::<_CMP_LT_OQ>(t, best);
        best = K::select(earlier, t, best);
        let ids = _mm256_or_si256(
            position,
            _mm256_set_epi64x(js[3] as i64, js[2] as i64, js[1] as i64, js[0] as i64),
        );
        key = K::select_i64(earlier, ids, key);
        position = _mm256_add_epi64(position, step);
    }
    // The earliest of the lanes (of equal times the one earliest in the list): halves, then
    // pairs, in registers. Keys are positive (positions below 2³¹), so signed comparison orders
    // them.
    let pick = |best: __m256d, key: __m256i, other_t: __m256d, other_k: __m256i| {
        let earlier = K::or(
            K::cmp::<_CMP_LT_OQ>(other_t, best),
            K::and(K::cmp::<_CMP_EQ_OQ>(other_t, best), K::gt_i64(key, other_k)),
        );
        (
            K::select(earlier, other_t, best),
            K::select_i64(earlier, other_k, key),
        )
    };
    let (best, key) = pick(
        best,
        key,
        _mm256_permute2f128_pd::<0x01>(best, best),
        _mm256_permute2x128_si256::<0x01>(key, key),
    );
    let (best, key) = pick(
        best,
        key,
        _mm256_permute_pd::<0b0101>(best),
        _mm256_castpd_si256(_mm256_permute_pd::<0b0101>(_mm256_castsi256_pd(key))),
    );
    let t_best = _mm256_cvtsd_f64(best);
    let k_best = _mm256_extract_epi64::<0>(key) as u64;
    let who = if t_best < f64::INFINITY {
        k_best as u32
    } else {
        code::NONE
    };
    (t_best, who)
}

#[cfg(test)]
mod tests {
    use crate::engine::{Scene, Simulation};
    use crate::physics::flight::{Ballistic, Flight, Straight};
    use crate::platform::cpu::Lanes;
    use crate::Scenario;

    fn engine<F: Flight>(json: &str, flight: impl Fn(&Scene) -> F) -> Simulation<F> {
        let scenario = Scenario::from_json(json).expect("test scenario is valid");
        let (scene, disks) = Scene::build(&scenario).expect("scene builds");
        Simulation::new(flight(&scene), &scene, disks).expect("engine starts")
    }

    /// Every disk's earliest contact, four lanes (on each of the processor's wider paths) against
    /// one by one, with and without horizons: bit for bit the same time and partner. Returns
    /// how many disks had a contact.
    fn compare<F: Flight>(sim: &mut Simulation<F>, what: &str) -> usize {
        let mut found = 0;
        for path in Lanes::all_here().into_iter().skip(1) {
            sim.control.lanes = path;
            for i in 0..sim.disks.len() {
                for horizon in [f64::INFINITY, 0.05, 1.0] {
                    let list = sim.map.lists.of(i);
                    let (lanes, one) = if horizon.is_finite() {
                        (
                            sim.pair_event_in_flight::<true>(i, list, horizon),
                            sim.pair_event_one_by_one::<true>(i, list, horizon),
                        )
                    } else {
                        (
                            sim.pair_event_in_flight::<false>(i, list, horizon),
                            sim.pair_event_one_by_one::<false>(i, list, horizon),
                        )
                    };
                    assert_eq!(
                        (lanes.0.to_bits(), lanes.1),
                        (one.0.to_bits(), one.1),
                        "{what}: disk {i}, horizon {horizon}: {lanes:?} against {one:?}"
                    );
                    found += (one.0 < f64::INFINITY) as usize;
                }
            }
        }
        found
    }

    #[test]
    fn four_lanes_find_what_the_scalar_loop_finds() {
        if !crate::platform::cpu::Lanes::found().avx2() {
            eprintln!("the engine's lanes are not AVX2's here: nothing to compare");
            return;
        }
        let scenes = [
            (
                "gas_periodic_phi07",
                include_str!("../../../scenarios/gas_periodic_phi07.json"),
            ),
            (
                "polydisperse",
                include_str!("../../../scenarios/polydisperse.json"),
            ),
            (
                "box_walls",
                include_str!("../../../scenarios/box_walls.json"),
            ),
        ];
        for (what, json) in scenes {
            for remap in ["local", "global"] {
                let json = json.replacen(
                    "\"run\"",
                    &format!("\"engine\": {{\"remap\": \"{remap}\"}}, \"run\""),
                    1,
                );
                let mut sim = engine(&json, |_| Straight);
                let mut found = 0;
                for t in [0.0, 0.5, 2.0] {
                    sim.advance_to(t).expect("runs");
                    found += compare(&mut sim, what);
                }
                assert!(
                    found > sim.disks.len(),
                    "{what}: too few contacts to compare"
                );
            }
        }
        let bed = include_str!("../../../scenarios/vibrated_bed.json");
        let mut sim = engine(bed, |s| Ballistic {
            g: s.gravity.expect("the bed has gravity"),
        });
        for t in [0.0, 1.0, 3.0] {
            sim.advance_to(t).expect("runs");
            assert!(compare(&mut sim, "vibrated_bed") > 0);
        }
    }

    /// Disks on the axes around a centre one, approaching it at the same speed: contact times
    /// equal to the last bit, of which the scalar loop keeps the first in the list; so must the
    /// lanes (whichever lanes and groups the list puts them in). Receding disks on the
    /// diagonals fill the list.
    #[test]
    fn of_equal_times_the_first_in_the_list_is_kept() {
        if !crate::platform::cpu::Lanes::found().avx2() {
            eprintln!("the engine's lanes are not AVX2's here: nothing to compare");
            return;
        }
        let axes = [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)];
        let diagonals = [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)];
        for subset in 1..16 {
            for fill in [false, true] {
                let mut positions = vec![[10.0, 10.0]];
                let mut velocities = vec![[0.0, 0.0]];
                for (k, &(ux, uy)) in axes.iter().enumerate() {
                    if subset & (1 << k) != 0 {
                        positions.push([10.0 + 1.5 * ux, 10.0 + 1.5 * uy]);
                        velocities.push([-ux, -uy]);
                    }
                }
                for &(ux, uy) in diagonals.iter().filter(|_| fill) {
                    positions.push([10.0 + 1.25 * ux, 10.0 + 1.25 * uy]);
                    velocities.push([ux, uy]);
                }
                let json = format!(
                    r#"{{"name": "cross", "domain": {{"width": 20.0, "height": 20.0, "x_boundary": "periodic", "y_boundary": "periodic"}},
                    "particles": {{"count": {}, "radius": 0.5, "placement": {{"positions": {positions:?}, "velocities": {velocities:?}}}}},
                    "run": {{"duration": 1.0}}}}"#,
                    positions.len()
                );
                let mut sim = engine(&json, |_| Straight);
                let centre = (0..sim.disks.len())
                    .find(|&i| (sim.disks.motion[i].x, sim.disks.motion[i].y) == (10.0, 10.0))
                    .expect("the centre disk is where it was put");
                let (t, _) = sim.pair_event_one_by_one::<false>(
                    centre,
                    sim.map.lists.of(centre),
                    f64::INFINITY,
                );
                assert_eq!(
                    t, 0.5,
                    "subset {subset}: the axes' disks touch the centre at 0.5"
                );
                compare(&mut sim, &format!("subset {subset}, fill {fill}"));
            }
        }
    }
}
