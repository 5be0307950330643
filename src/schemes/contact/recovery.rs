//! Overlap recovery by position only (the *split impulse* of rigid-body engines): an overlap
//! left by an unconverged step is removed by moving the disks apart, not by giving them speed.
//! Pushing overlapping disks apart through their velocities (`u⁺ ≥ overlap/dt`) leaves that
//! speed in the bed after the overlap is gone: energy made from nothing, which a dense bed keeps
//! as jitter, and with which a bed the floor cannot throw never comes to rest. Here the step's
//! velocity solve only stops overlapping contacts from closing further, and a second projected
//! Gauss–Seidel solve over the overlapping contacts alone finds *pseudo-velocities* `w` that
//! open each overlap by [`RECOVERY`] of itself within the step; the step moves each disk by
//! `dt·(v⁺ + w)` and then forgets `w`.

/// The fraction of an overlap a step removes.
const RECOVERY: f64 = 0.1;

/// Overlaps up to this many radii of the smallest disk are left alone (the *slop*): an
/// unconverged solve leaves most of a resting bed's contacts overlapping by a hair, more than
/// one a disk, and opening them all made a step of such a bed about 40 % dearer; a deeper
/// overlap is opened down to the slop.
const SLOP: f64 = 1e-3;

/// Gauss–Seidel sweeps of the pseudo-velocity solve, at most: what a sweep leaves is removed in
/// the next step.
const SWEEPS: u32 = 2;

/// One overlapping contact: disk `i` against disk `j` (or a boundary, an entry whose inverse mass
/// is 0), unit normal `n` from `j` to `i`.
#[derive(Debug, Clone, Copy)]
struct Overlap {
    i: u32,
    j: u32,
    n: (f64, f64),
    wi: f64,
    wj: f64,
    /// Effective mass along the normal.
    mn: f64,
    /// The normal pseudo-velocity that opens the step's share of the overlap.
    target: f64,
    /// Accumulated pseudo-impulse (≥ 0: recovery only pushes).
    p: f64,
}

/// The step's overlapping contacts and the disks' pseudo-velocities (one more entry than disks,
/// which stays 0: the other side of a boundary contact).
#[derive(Debug, Default)]
pub struct Recovery {
    overlaps: Vec<Overlap>,
    push: Vec<[f64; 2]>,
    /// [`SLOP`] in lengths.
    slop: f64,
}

impl Recovery {
    /// For `n` disks, the smallest of radius `a_min`.
    pub fn new(n: usize, a_min: f64) -> Recovery {
        Recovery {
            overlaps: Vec::new(),
            push: vec![[0.0; 2]; n + 1],
            slop: SLOP * a_min,
        }
    }

    /// Forgets the last step's contacts and pseudo-velocities.
    pub fn clear(&mut self) {
        for o in self.overlaps.drain(..) {
            self.push[o.i as usize] = [0.0; 2];
            self.push[o.j as usize] = [0.0; 2];
        }
    }

    /// Whether a contact at `gap` overlaps beyond the slop, so that [`Recovery::add`] keeps it.
    #[inline]
    pub fn opens(&self, gap: f64) -> bool {
        -gap - self.slop > 0.0
    }

    /// A contact of the step with gap `gap` (negative: an overlap), inverse masses `wi`, `wj`
    /// and effective normal mass `mn`, in a step `dt` long: kept if it overlaps beyond the slop.
    #[inline]
    pub fn add(
        &mut self,
        (i, j): (u32, u32),
        n: (f64, f64),
        (wi, wj, mn): (f64, f64, f64),
        gap: f64,
        dt: f64,
    ) {
        if !self.opens(gap) {
            return;
        }
        let overlap = -gap - self.slop;
        self.overlaps.push(Overlap {
            i,
            j,
            n,
            wi,
            wj,
            mn,
            target: RECOVERY * overlap / dt,
            p: 0.0,
        });
    }

    /// Projected Gauss–Seidel for the pseudo-velocities: every overlap opens at least at its
    /// target speed, by pushes only.
    pub fn solve(&mut self) {
        for _ in 0..SWEEPS {
            for o in &mut self.overlaps {
                let (wi, wj) = (self.push[o.i as usize], self.push[o.j as usize]);
                let u = (wi[0] - wj[0]) * o.n.0 + (wi[1] - wj[1]) * o.n.1;
                let p = (o.p + (o.target - u) * o.mn).max(0.0);
                let dp = p - o.p;
                o.p = p;
                let (i, j) = (o.i as usize, o.j as usize);
                self.push[i][0] += o.wi * dp * o.n.0;
                self.push[i][1] += o.wi * dp * o.n.1;
                self.push[j][0] -= o.wj * dp * o.n.0;
                self.push[j][1] -= o.wj * dp * o.n.1;
            }
        }
    }

    /// Disk `k`'s pseudo-velocity.
    #[inline]
    pub fn push(&self, k: usize) -> [f64; 2] {
        self.push[k]
    }
}
