//! The minimum image and the shells' filter four lanes at a time (AVX2), for the engine's short
//! hot loops: the pair search's kernel ([`pair::lanes`](crate::engine::pair)) and the filter of a
//! disk's new neighbours when it leaves its shell. Each lane does exactly the scalar operations
//! of [`Images::wrap`] and [`within_reach`](super::within_reach), in the same order: the same
//! results bit for bit (a test compares the two). Run only where the processor has AVX2
//! ([`Lanes`](crate::platform::cpu::Lanes) says so).

use super::Images;
use crate::physics::disks::PerDisk;
use crate::platform::masks::{Masks, Vectors};
use std::arch::x86_64::*;

/// Minimum image of separations `d` along one direction, lane by lane, as `Images::wrap`: one
/// period off where beyond half of it (`half` = ∞ where the direction is not periodic); the
/// lanes' flags kept as `K` keeps them.
///
/// # Safety
///
/// Only inside a function that runs with `K`'s instructions enabled (inlined there).
#[inline(always)]
pub(in crate::engine) unsafe fn nearest_image<K: Masks>(
    d: __m256d,
    half: __m256d,
    neg_half: __m256d,
    period: __m256d,
) -> __m256d {
    let above = K::cmp::<_CMP_GT_OQ>(d, half);
    let below = K::cmp::<_CMP_LT_OQ>(d, neg_half);
    let d_up = K::select(below, _mm256_add_pd(d, period), d);
    K::select(above, _mm256_sub_pd(d, period), d_up)
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
    let around = Around {
        x: set1(x),
        y: set1(y),
        half_x: set1(half[0]),
        half_y: set1(half[1]),
        neg_half_x: set1(-half[0]),
        neg_half_y: set1(-half[1]),
        period_x: set1(period[0]),
        period_y: set1(period[1]),
    };
    let me = i as u32;
    // One loop per kind of radii, so that neither tests which it is per group.
    match radius.common() {
        Some(r) => {
            let s = reach + r;
            let limit = set1(s * s);
            keep_near(found, n, me, anchor, &around, |_| limit)
        }
        None => {
            let (each, reach) = (radius.each(), set1(reach));
            keep_near(found, n, me, anchor, &around, |js| {
                let r = |l: usize| each[js[l] as usize];
                let s = _mm256_add_pd(reach, _mm256_set_pd(r(3), r(2), r(1), r(0)));
                _mm256_mul_pd(s, s)
            })
        }
    }
}

/// Disk `i`'s anchor and the images, one value in all four lanes.
struct Around {
    x: __m256d,
    y: __m256d,
    half_x: __m256d,
    half_y: __m256d,
    neg_half_x: __m256d,
    neg_half_y: __m256d,
    period_x: __m256d,
    period_y: __m256d,
}

/// For each set of lanes (bit l: lane l kept), the lanes to move to the front in order: the
/// control of `vpermilps` that packs the kept candidates of a group.
static PACK: [[u32; 4]; 16] = {
    let mut table = [[0u32; 4]; 16];
    let mut m = 0;
    while m < 16 {
        let mut to = 0;
        let mut l = 0;
        while l < 4 {
            if m >> l & 1 == 1 {
                table[m][to] = l as u32;
                to += 1;
            }
            l += 1;
        }
        m += 1;
    }
    table
};

/// The filter's loop: keeps at the front of `found[..n]`, in order, the candidates other than
/// `me` whose squared minimum-image distance from the anchor `around` is at most `limit` of
/// their lanes. Four candidates at a time: whole groups packed by one shuffle and one store,
/// the last few (padded with `me`, never kept) one by one.
///
/// # Safety
///
/// As [`within_reach`].
#[inline(always)]
unsafe fn keep_near(
    found: &mut [u32],
    n: usize,
    me: u32,
    anchor: &[[f64; 2]],
    around: &Around,
    limit: impl Fn([u32; 4]) -> __m256d,
) -> usize {
    let found = &mut found[..n];
    let me_v = _mm_set1_epi32(me as i32);
    let near = |js: [u32; 4]| {
        let a = js.map(|j| _mm_loadu_pd(anchor[j as usize].as_ptr()));
        // Lanes in the candidates' order: 0 and 2 in the halves of one register, 1 and 3 in
        // the other's, interleaved by the unpacking.
        let a02 = _mm256_set_m128d(a[2], a[0]);
        let a13 = _mm256_set_m128d(a[3], a[1]);
        let xs = _mm256_unpacklo_pd(a02, a13);
        let ys = _mm256_unpackhi_pd(a02, a13);
        let dx = nearest_image::<Vectors>(
            _mm256_sub_pd(around.x, xs),
            around.half_x,
            around.neg_half_x,
            around.period_x,
        );
        let dy = nearest_image::<Vectors>(
            _mm256_sub_pd(around.y, ys),
            around.half_y,
            around.neg_half_y,
            around.period_y,
        );
        let d2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
        let close = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LE_OQ>(d2, limit(js)));
        let ids = _mm_loadu_si128(js.as_ptr().cast());
        let itself = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(ids, me_v)));
        ((close & !itself) as usize, ids)
    };
    let mut kept = 0;
    let mut k = 0;
    while k + 4 <= n {
        let (keep, ids) = near(found[k..k + 4].try_into().unwrap());
        // Kept entries never overtake the candidates read (kept ≤ k): the group's store only
        // overwrites read candidates, and what lies past the kept ones is written again.
        let at = kept.min(k);
        let order = _mm_loadu_si128(PACK[keep].as_ptr().cast());
        let packed = _mm_permutevar_ps(_mm_castsi128_ps(ids), order);
        _mm_storeu_ps(found[at..at + 4].as_mut_ptr().cast(), packed);
        kept += keep.count_ones() as usize;
        k += 4;
    }
    if k < n {
        let js = [0, 1, 2, 3].map(|l| if k + l < n { found[k + l] } else { me });
        let (keep, _) = near(js);
        for (l, &j) in js.iter().enumerate().take(n - k) {
            found[kept] = j;
            kept += keep >> l & 1;
        }
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
                    let mut b = candidates.clone();
                    let kb = crate::engine::images::within_reach_one_by_one(
                        &mut b, n, i, reach, &anchor, &radius, &images,
                    );
                    // With and without entries past the candidates (never read: a disk
                    // number there that no disk has would stop the test).
                    for room in [0, 4] {
                        let mut a = candidates.clone();
                        a.resize(n + room, u32::MAX);
                        // SAFETY: the processor has AVX2 (checked above); the candidates are
                        // disks.
                        let ka = unsafe {
                            super::within_reach(&mut a, n, i, reach, &anchor, &radius, &images)
                        };
                        assert_eq!(a[..ka], b[..kb], "disk {i}, mixed {mixed}, room {room}");
                    }
                    kept_total += kb;
                }
            }
        }
        assert!(kept_total > 1000, "too few kept to compare: {kept_total}");
    }
}
