//! The minimum image and the shells' filter four lanes at a time (AVX2), for the engine's short
//! hot loops: the pair search's kernel ([`pair::lanes`](crate::engine::pair)) and the filter of a
//! disk's new neighbours when it leaves its shell. Each lane does exactly the scalar operations
//! of [`Images::wrap`] and [`within_reach`](super::within_reach), in the same order: the same
//! results bit for bit (a test compares the two). Run only where the processor has AVX2
//! ([`Lanes`](crate::platform::cpu::Lanes) says so).

use super::Images;
use crate::physics::disks::PerDisk;
use std::arch::x86_64::*;

/// Minimum image of separations `d` along one direction, lane by lane, as `Images::wrap`: one
/// period off where beyond half of it (`half` = ∞ where the direction is not periodic).
///
/// # Safety
///
/// Only inside a function that runs with AVX2 enabled (inlined there).
#[inline(always)]
pub(in crate::engine) unsafe fn nearest_image(
    d: __m256d,
    half: __m256d,
    neg_half: __m256d,
    period: __m256d,
) -> __m256d {
    let above = _mm256_cmp_pd::<_CMP_GT_OQ>(d, half);
    let below = _mm256_cmp_pd::<_CMP_LT_OQ>(d, neg_half);
    let d_up = _mm256_blendv_pd(d, _mm256_add_pd(d, period), below);
    _mm256_blendv_pd(d_up, _mm256_sub_pd(d, period), above)
}

/// [`within_reach`](super::within_reach) four candidates at a time: the same
/// candidates kept in the same order, each lane doing the scalar filter's operations in its
/// order (the two share their parameters: one interface, two ways).
///
/// # Safety
///
/// Only where the processor has AVX2; every candidate and `i` index `anchor` (indexing is
/// checked).
#[cfg_attr(target_feature = "avx2", inline(always))]
#[cfg_attr(not(target_feature = "avx2"), target_feature(enable = "avx2"), inline)]
pub(in crate::engine) unsafe fn within_reach(
    found: &mut [u32],
    n: usize,
    i: usize,
    reach: f64,
    anchor: &[[f64; 2]],
    radius: &PerDisk<f64>,
    images: &Images,
) -> usize {
    let set1 = |v: f64| _mm256_set1_pd(v);
    let [x, y] = anchor[i];
    let (half, period) = (images.half(), images.period());
    let (xi, yi) = (set1(x), set1(y));
    let (half_x, half_y) = (set1(half[0]), set1(half[1]));
    let (neg_half_x, neg_half_y) = (set1(-half[0]), set1(-half[1]));
    let (period_x, period_y) = (set1(period[0]), set1(period[1]));
    let reach_v = set1(reach);
    let common = radius.common().map(|r| {
        let s = reach + r;
        set1(s * s)
    });
    let each = radius.each();
    let me = i as u32;
    let mut kept = 0;
    let mut k = 0;
    while k < n {
        let js = [0, 1, 2, 3].map(|l| if k + l < n { found[k + l] } else { me });
        let a = js.map(|j| _mm_loadu_pd(anchor[j as usize].as_ptr()));
        // Lanes in the order 0, 2, 1, 3 (what the unpacking gives).
        let a01 = _mm256_set_m128d(a[1], a[0]);
        let a23 = _mm256_set_m128d(a[3], a[2]);
        let xs = _mm256_unpacklo_pd(a01, a23);
        let ys = _mm256_unpackhi_pd(a01, a23);
        let dx = nearest_image(_mm256_sub_pd(xi, xs), half_x, neg_half_x, period_x);
        let dy = nearest_image(_mm256_sub_pd(yi, ys), half_y, neg_half_y, period_y);
        let d2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
        let limit = match common {
            Some(s2) => s2,
            None => {
                let r = |l: usize| each[js[l] as usize];
                let s = _mm256_add_pd(reach_v, _mm256_set_pd(r(3), r(1), r(2), r(0)));
                _mm256_mul_pd(s, s)
            }
        };
        let bits = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LE_OQ>(d2, limit)) as u32;
        // Kept entries never overtake the candidates read (kept ≤ k + l); the padding lanes
        // (beyond n) are never kept and write nothing.
        for (l, lane) in [0, 2, 1, 3].into_iter().enumerate().take(n - k) {
            found[kept] = js[l];
            kept += ((bits >> lane) & 1 & (js[l] != me) as u32) as usize;
        }
        k += 4;
    }
    kept
}

#[cfg(test)]
mod tests {
    /// The shell filter, four lanes against one by one: the same candidates kept in the same
    /// order, with equal and with mixed radii, periodic and closed boxes, candidate counts
    /// that fill whole groups and that do not, the disk itself among its candidates, and
    /// anchors at the reach's edge.
    #[test]
    fn four_lanes_keep_what_the_scalar_filter_keeps() {
        if !crate::platform::cpu::Lanes::widest().avx2() {
            eprintln!("no AVX2 on this processor: the four lanes are not compared");
            return;
        }
        use crate::engine::images::Images;
        use crate::physics::disks::PerDisk;
        use crate::physics::walls::{SideBounds, Top};
        use rand::{Rng, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(11);
        let n_disks = 200;
        let width = 12.0;
        let boxes = [
            Images::of(
                SideBounds::Periodic { width },
                Top::Periodic { height: width },
            ),
            Images::of(SideBounds::Walls { width, e: 1.0 }, Top::Open),
        ];
        let mut kept_total = 0;
        for images in boxes {
            for mixed in [false, true] {
                let radius = PerDisk::new(
                    (0..n_disks)
                        .map(|_| {
                            if mixed {
                                rng.random_range(0.3..0.7)
                            } else {
                                0.5
                            }
                        })
                        .collect(),
                );
                for _ in 0..300 {
                    let mut anchor: Vec<[f64; 2]> = (0..n_disks)
                        .map(|_| [rng.random_range(0.0..width), rng.random_range(0.0..width)])
                        .collect();
                    let i = rng.random_range(0..n_disks);
                    let reach = radius[i] + 1.5;
                    // One candidate exactly at its reach along x (both filters keep it).
                    let edge = (i + 1) % n_disks;
                    anchor[edge] = [anchor[i][0] + (reach + radius[edge]), anchor[i][1]];
                    let n = rng.random_range(0..40);
                    let mut candidates: Vec<u32> = (0..n)
                        .map(|_| rng.random_range(0..n_disks) as u32)
                        .collect();
                    if n > 0 && rng.random::<bool>() {
                        candidates[rng.random_range(0..n)] = i as u32;
                    }
                    candidates.push(edge as u32);
                    let n = candidates.len();
                    let (mut a, mut b) = (candidates.clone(), candidates);
                    // SAFETY: the processor has AVX2 (checked above); the candidates are disks.
                    let ka = unsafe {
                        super::within_reach(&mut a, n, i, reach, &anchor, &radius, &images)
                    };
                    let kb = crate::engine::images::within_reach_one_by_one(
                        &mut b, n, i, reach, &anchor, &radius, &images,
                    );
                    assert_eq!(a[..ka], b[..kb], "disk {i}, mixed {mixed}");
                    kept_total += kb;
                }
            }
        }
        assert!(kept_total > 1000, "too few kept to compare: {kept_total}");
    }
}
