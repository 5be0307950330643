//! The Verlet pairs' separations between steps, and the fastest approach among them, four pairs
//! at a time where the processor has AVX2: each lane does the scalar operations in the same
//! order (the square root and the division are exact per lane), so both paths give the same
//! separations and approach bit for bit (the tests compare them).

use super::super::min_image;
use crate::physics::disks::{Motion, PerDisk};
use crate::physics::walls::{SideBounds, Top};
use crate::platform::cpu::Lanes;

/// The scene's boundaries and the disks, as the measure needs them.
pub(super) struct Measure<'a> {
    pub sides: SideBounds,
    pub top: Top,
    pub motion: &'a [Motion],
    pub radius: &'a PerDisk<f64>,
    /// The longest step: a pair that can close within it is an approach.
    pub dt: f64,
    /// Whether to look for the fastest approach at all.
    pub adaptive: bool,
}

/// Each pair's separation `(dx, dy, |d|)` into `out`, in order; returns the fastest approach
/// speed of a pair that can close within `dt` on its velocities now (0: none, or not looked for).
pub(super) fn measure(
    lanes: Lanes,
    m: &Measure,
    pairs: &[(u32, u32)],
    out: &mut Vec<[f64; 3]>,
) -> f64 {
    out.clear();
    #[cfg(target_arch = "x86_64")]
    if lanes.avx2() {
        // SAFETY: the processor has AVX2 (the lanes say so); the pairs index the disks.
        return unsafe { measure_avx2(m, pairs, out) };
    }
    let _ = lanes;
    pairs
        .iter()
        .fold(0.0, |fastest, &p| one(m, p, fastest, out))
}

/// One pair's separation pushed to `out`, and `fastest` raised to its approach if it can close
/// within `dt`.
#[inline(always)]
fn one(m: &Measure, (i, j): (u32, u32), fastest: f64, out: &mut Vec<[f64; 3]>) -> f64 {
    let (mi, mj) = (m.motion[i as usize], m.motion[j as usize]);
    let (dx, dy) = min_image(m.sides, m.top, mi.x - mj.x, mi.y - mj.y);
    let dist = (dx * dx + dy * dy).sqrt();
    out.push([dx, dy, dist]);
    if m.adaptive {
        let gap = dist - m.radius[i as usize] - m.radius[j as usize];
        let u = ((mi.vx - mj.vx) * dx + (mi.vy - mj.vy) * dy) / dist;
        if gap + u * m.dt < 0.0 {
            return larger(-u, fastest);
        }
    }
    fastest
}

/// `a` if it is the larger, else `b` (so `b` where either is a NaN): the vector `max`'s rule.
#[inline(always)]
fn larger(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// [`measure`] four pairs at a time; a group with a pair more than one and a half periods apart
/// (the nearest image not one period away), and the last pairs, one at a time.
///
/// # Safety
///
/// Only where the processor has AVX2; every pair indexes `motion` and `radius` (checked).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn measure_avx2(m: &Measure, pairs: &[(u32, u32)], out: &mut Vec<[f64; 3]>) -> f64 {
    use crate::platform::transpose::transpose;
    use std::arch::x86_64::*;
    let set1 = |v: f64| _mm256_set1_pd(v);
    let period = |p: Option<f64>| p.map(|p| (set1(p), set1(0.5), set1(1.5)));
    let x_period = period(match m.sides {
        SideBounds::Periodic { width } => Some(width),
        SideBounds::Walls { .. } => None,
    });
    let y_period = period(match m.top {
        Top::Periodic { height } => Some(height),
        _ => None,
    });
    let (zero, sign, dt) = (_mm256_setzero_pd(), set1(-0.0), set1(m.dt));
    // Nearest image per lane as `nearest_image` for |d/period| < 1.5; None where a lane is not.
    let nearest = |d: __m256d, p: Option<(__m256d, __m256d, __m256d)>| -> Option<__m256d> {
        let Some((period, half, one_half)) = p else {
            return Some(d);
        };
        let q = _mm256_div_pd(d, period);
        let a = _mm256_andnot_pd(sign, q);
        if _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(a, one_half)) != 0b1111 {
            return None;
        }
        let shifted = _mm256_blendv_pd(
            _mm256_add_pd(d, period),
            _mm256_sub_pd(d, period),
            _mm256_cmp_pd::<_CMP_GT_OQ>(q, zero),
        );
        Some(_mm256_blendv_pd(
            shifted,
            d,
            _mm256_cmp_pd::<_CMP_LT_OQ>(a, half),
        ))
    };
    let state = |k: u32| _mm256_loadu_pd(&m.motion[k as usize].x as *const f64);
    let mut fastest_lanes = zero;
    let mut fastest = 0.0;
    let groups = pairs.chunks_exact(4);
    let rest = groups.remainder();
    for group in groups {
        let is = [0, 1, 2, 3].map(|k| group[k].0);
        let js = [0, 1, 2, 3].map(|k| group[k].1);
        // Rows (x, y, vx, vy) of four disks to columns.
        let si = transpose(is.map(state));
        let sj = transpose(js.map(state));
        let dx = nearest(_mm256_sub_pd(si[0], sj[0]), x_period);
        let dy = nearest(_mm256_sub_pd(si[1], sj[1]), y_period);
        let (Some(dx), Some(dy)) = (dx, dy) else {
            fastest = group.iter().fold(fastest, |f, &p| one(m, p, f, out));
            continue;
        };
        let dist = _mm256_sqrt_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)));
        let mut lanes = [[0.0; 4]; 3];
        _mm256_storeu_pd(lanes[0].as_mut_ptr(), dx);
        _mm256_storeu_pd(lanes[1].as_mut_ptr(), dy);
        _mm256_storeu_pd(lanes[2].as_mut_ptr(), dist);
        out.extend((0..4).map(|k| [lanes[0][k], lanes[1][k], lanes[2][k]]));
        if m.adaptive {
            let r = |ks: [u32; 4]| {
                let a = ks.map(|k| m.radius[k as usize]);
                _mm256_set_pd(a[3], a[2], a[1], a[0])
            };
            let gap = _mm256_sub_pd(_mm256_sub_pd(dist, r(is)), r(js));
            let dvx = _mm256_sub_pd(si[2], sj[2]);
            let dvy = _mm256_sub_pd(si[3], sj[3]);
            let u = _mm256_div_pd(
                _mm256_add_pd(_mm256_mul_pd(dvx, dx), _mm256_mul_pd(dvy, dy)),
                dist,
            );
            let closes =
                _mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_add_pd(gap, _mm256_mul_pd(u, dt)), zero);
            let approach = _mm256_and_pd(closes, _mm256_xor_pd(u, sign));
            fastest_lanes = _mm256_max_pd(approach, fastest_lanes);
        }
    }
    fastest = rest.iter().fold(fastest, |f, &p| one(m, p, f, out));
    let mut lanes = [0.0; 4];
    _mm256_storeu_pd(lanes.as_mut_ptr(), fastest_lanes);
    lanes.into_iter().fold(fastest, |f, x| larger(x, f))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Random disks in a box periodic in x or walled, periodic in y or open, some pairs across the
    /// period and some more than one and a half periods apart: four lanes give each pair's separation and the
    /// fastest approach of one at a time bit for bit.
    #[test]
    fn four_lanes_measure_what_one_at_a_time_does() {
        if !Lanes::found().avx2() {
            eprintln!("no AVX2 here: nothing to compare");
            return;
        }
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        let mut found = 0;
        for case in 0..30 {
            let n = rng.random_range(2..80);
            let (width, height) = (20.0, 30.0);
            let motion: Vec<Motion> = (0..n)
                .map(|_| Motion {
                    x: rng.random_range(-5.0..45.0),
                    y: rng.random_range(0.0..height),
                    vx: rng.random_range(-1.0..1.0),
                    vy: rng.random_range(-1.0..1.0),
                    t: 0.0,
                })
                .collect();
            let radius = PerDisk::new((0..n).map(|_| rng.random_range(0.3..0.7)).collect());
            let pairs: Vec<(u32, u32)> = (0..rng.random_range(0..200))
                .map(|_| {
                    let i = rng.random_range(0..n);
                    (i, (i + rng.random_range(1..n)) % n)
                })
                .collect();
            let top = if case % 2 == 0 {
                Top::Periodic { height }
            } else {
                Top::Open
            };
            for adaptive in [false, true] {
                let m = Measure {
                    sides: if case % 3 == 0 {
                        SideBounds::Walls { width, e: 1.0 }
                    } else {
                        SideBounds::Periodic { width }
                    },
                    top,
                    motion: &motion,
                    radius: &radius,
                    dt: rng.random_range(0.01..3.0),
                    adaptive,
                };
                let (mut one, mut four) = (Vec::new(), Vec::new());
                let slow = measure(Lanes::ONE_BY_ONE, &m, &pairs, &mut one);
                let fast = measure(Lanes::found(), &m, &pairs, &mut four);
                assert_eq!(slow.to_bits(), fast.to_bits(), "case {case}: the fastest");
                let bits = |v: &[[f64; 3]]| -> Vec<[u64; 3]> {
                    v.iter().map(|s| s.map(f64::to_bits)).collect()
                };
                assert_eq!(bits(&one), bits(&four), "case {case}: the separations");
                found += (slow > 0.0) as usize;
            }
        }
        assert!(found > 5, "too few approaches to compare: {found}");
    }
}
