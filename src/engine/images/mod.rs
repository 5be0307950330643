//! The domain's periodic images as the engine sees them: the minimum image of a separation, and
//! which candidate neighbours lie within reach of a disk across the images (the filter of the
//! local re-mapping's shells). Where the processor has AVX2, both also run four lanes at a time
//! ([`lanes`](lanes.rs)): the pair search's kernel and the shells' filter share them.

#[cfg(target_arch = "x86_64")]
pub(in crate::engine) mod lanes;

use crate::physics::disks::PerDisk;
use crate::physics::walls::{SideBounds, Top};
use crate::platform::cpu::Lanes;

/// The periodic images of the domain, for minimum-image separations: each direction's period
/// and half period, the half period ∞ where the direction is not periodic (so the comparisons
/// never wrap there). Kept as plain numbers rather than read from [`SideBounds`] and [`Top`]:
/// `Top::Open` carries no height, and a compiler that hoists `0.5 · height` out of a pair loop
/// (it may: the product is only used under a test) then multiplies whatever bytes lie in the
/// unused payload — a subnormal among them costs a microcode assist at every prediction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::engine) struct Images {
    period: [f64; 2],
    half: [f64; 2],
}

impl Images {
    /// The images of a domain bounded by `sides` and `top`.
    pub(in crate::engine) fn of(sides: SideBounds, top: Top) -> Images {
        let x = match sides {
            SideBounds::Periodic { width } => Some(width),
            SideBounds::Walls { .. } => None,
        };
        let y = match top {
            Top::Periodic { height } => Some(height),
            Top::Open | Top::Lid { .. } => None,
        };
        let period = [x.unwrap_or(0.0), y.unwrap_or(0.0)];
        let half = [
            x.map_or(f64::INFINITY, |w| 0.5 * w),
            y.map_or(f64::INFINITY, |h| 0.5 * h),
        ];
        Images { period, half }
    }

    /// Half periods (∞ where not periodic).
    #[cfg(target_arch = "x86_64")]
    pub(in crate::engine) fn half(&self) -> [f64; 2] {
        self.half
    }

    /// Periods (0 where not periodic).
    #[cfg(target_arch = "x86_64")]
    pub(in crate::engine) fn period(&self) -> [f64; 2] {
        self.period
    }

    /// Minimum-image separation where periodic. Positions are wrapped at every mapping and
    /// drift by less than the DUTC margin before the next, so one correction suffices.
    #[inline(always)]
    pub(in crate::engine) fn wrap(&self, dx: f64, dy: f64) -> (f64, f64) {
        let near = |d: f64, k: usize| {
            if d > self.half[k] {
                d - self.period[k]
            } else if d < -self.half[k] {
                d + self.period[k]
            } else {
                d
            }
        };
        (near(dx, 0), near(dy, 1))
    }
}

/// Keeps at the front of `found[..n]`, in order, the candidates whose anchors lie within reach
/// of disk `i`'s: `j ≠ i` and `|Δ|² ≤ (reach + a_j)²` for the minimum image `Δ` of the two
/// anchors (`reach` = `a_i` + the list's margin); returns how many. On the path `lanes`: four at
/// a time ([`lanes::within_reach`](lanes.rs)) or [one by one](within_reach_one_by_one), the same
/// candidates kept.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(in crate::engine) fn within_reach(
    lanes: Lanes,
    found: &mut [u32],
    n: usize,
    i: usize,
    reach: f64,
    anchor: &[[f64; 2]],
    radius: &PerDisk<f64>,
    images: &Images,
) -> usize {
    #[cfg(target_arch = "x86_64")]
    if lanes.avx2() {
        // SAFETY: the processor has AVX2 (`lanes` says so); every candidate and `i` index
        // `anchor` (indexing is checked).
        return unsafe { self::lanes::within_reach(found, n, i, reach, anchor, radius, images) };
    }
    let _ = lanes;
    within_reach_one_by_one(found, n, i, reach, anchor, radius, images)
}

/// [`within_reach`] one candidate at a time, without a branch per candidate (about a third are
/// kept, at random). Out of line where the whole build has AVX2 (the four lanes' loop then
/// stays as it was without the choice).
#[cfg_attr(target_feature = "avx2", inline(never))]
pub(in crate::engine) fn within_reach_one_by_one(
    found: &mut [u32],
    n: usize,
    i: usize,
    reach: f64,
    anchor: &[[f64; 2]],
    radius: &PerDisk<f64>,
    images: &Images,
) -> usize {
    let [xi, yi] = anchor[i];
    let mut kept = 0;
    for k in 0..n {
        let j = found[k] as usize;
        let [xj, yj] = anchor[j];
        let (dx, dy) = images.wrap(xi - xj, yi - yj);
        let r = reach + radius[j];
        found[kept] = j as u32;
        kept += (dx * dx + dy * dy <= r * r && j != i) as usize;
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// The images wrap exactly as matching on the bounds did (one correction by a period where
    /// periodic, nothing elsewhere), for every kind of side and top.
    #[test]
    fn images_wrap_as_the_bounds_say() {
        let by_bounds = |sides: SideBounds, top: Top, mut dx: f64, mut dy: f64| {
            if let SideBounds::Periodic { width } = sides {
                if dx > 0.5 * width {
                    dx -= width;
                } else if dx < -0.5 * width {
                    dx += width;
                }
            }
            if let Top::Periodic { height } = top {
                if dy > 0.5 * height {
                    dy -= height;
                } else if dy < -0.5 * height {
                    dy += height;
                }
            }
            (dx, dy)
        };
        let sides = [
            SideBounds::Periodic { width: 10.3 },
            SideBounds::Walls { width: 7.0, e: 0.9 },
        ];
        let tops = [
            Top::Open,
            Top::Lid {
                height: 5.0,
                e: 1.0,
            },
            Top::Periodic { height: 8.1 },
        ];
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        for &s in &sides {
            for &t in &tops {
                let images = Images::of(s, t);
                for _ in 0..2000 {
                    let (dx, dy) = (rng.random_range(-12.0..12.0), rng.random_range(-12.0..12.0));
                    let (a, b) = (images.wrap(dx, dy), by_bounds(s, t, dx, dy));
                    assert_eq!(a.0.to_bits(), b.0.to_bits(), "{s:?} {t:?} {dx} {dy}");
                    assert_eq!(a.1.to_bits(), b.1.to_bits(), "{s:?} {t:?} {dx} {dy}");
                }
                // Exactly half a period stays.
                if let SideBounds::Periodic { width } = s {
                    assert_eq!(images.wrap(0.5 * width, 0.0).0, 0.5 * width);
                }
            }
        }
        let open = Images::of(sides[1], tops[0]);
        assert_eq!(open.wrap(1e300, -1e300), (1e300, -1e300), "nothing wraps");
    }
}
