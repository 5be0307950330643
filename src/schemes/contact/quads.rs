//! The Gauss–Seidel sweep four contacts at a time.
//!
//! A sweep updates each contact from the velocities the contacts before it left; contacts that
//! share no disk do not see each other's updates, so solving them at once gives what solving them
//! one after another does. The step's contacts are packed, in their order, into quads of four that
//! share no disk (the boundary's entry aside, which never moves): the sweep's order is the rows'
//! own (bottom up, in groups of pairs that share no disk), so most quads are full. Where the
//! processor has AVX2 a quad is solved in four lanes, each doing exactly the scalar operations in
//! the same order (Rust never contracts a product and a sum): the same impulses bit for bit as one
//! lane at a time, which stays for other processors (the tests compare the two).

use super::Row;
use crate::platform::cpu::Lanes;

/// The lane of a quad that holds no row.
pub(super) const NO_ROW: u32 = u32::MAX;

/// Four contacts that share no disk: each field one value per lane (a [`Row`]'s, see there).
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(32))]
pub(super) struct Quad {
    nx: [f64; 4],
    ny: [f64; 4],
    vbx: [f64; 4],
    vby: [f64; 4],
    wi: [f64; 4],
    wj: [f64; 4],
    wn: [f64; 4],
    wt: [f64; 4],
    mn: [f64; 4],
    mt: [f64; 4],
    target: [f64; 4],
    mu: [f64; 4],
    pn: [f64; 4],
    pt: [f64; 4],
    i: [u32; 4],
    j: [u32; 4],
    /// The row of each lane (`NO_ROW`: an empty lane).
    row: [u32; 4],
}

/// What packing, the pairs' layout and the booking need of a quad of four contacts that share
/// no disk, whatever else it keeps: a full [`Quad`] (boundaries, rough pairs) or a smooth
/// pair's ([`Smooth`](super::smooth::Smooth)).
pub(super) trait Packed: Copy + Default {
    /// Empties lane `l`: a contact of the boundary's entry with itself, without mass or bound,
    /// which never pushes.
    fn clear(&mut self, l: usize, boundary: u32);
    /// Sets lane `l` to row `r`, numbered `row`.
    fn set(&mut self, l: usize, r: &Row, row: u32);
    /// Lane `l`'s disks and row (`NO_ROW`: empty).
    fn lane(&self, l: usize) -> (u32, u32, u32);
    /// Sets lane `l`'s normal, bound and impulses for the step.
    fn refresh(&mut self, l: usize, f: &Fresh);
    /// Lane `l`'s impulses applied to its disks' velocities (`sf` as [`sweep`]'s).
    fn apply(&self, l: usize, vel: &mut [[f64; 4]], sf: f64, pn: f64, pt: f64);
    /// Lane `l`'s normal and tangential impulses and its boundary's vertical velocity.
    fn impulses(&self, l: usize) -> (f64, f64, f64);

    /// Four empty lanes ([`Packed::clear`]).
    fn empty(boundary: u32) -> Self {
        let mut q = Self::default();
        (0..4).for_each(|l| q.clear(l, boundary));
        q
    }

    /// Lane `l`'s contact if it pushed.
    fn pushed(&self, l: usize) -> Option<Pushed> {
        let (i, j, row) = self.lane(l);
        let (pn, pt, vby) = self.impulses(l);
        (row != NO_ROW && pn > 0.0).then_some(Pushed {
            row,
            i,
            j,
            pn,
            pt,
            vby,
        })
    }

    /// Whether the lanes before `lanes` touch disk `i` or `j` (`boundary` is no disk).
    fn touches(&self, lanes: usize, (ri, rj): (u32, u32), boundary: u32) -> bool {
        (0..lanes).any(|l| {
            let (i, j, _) = self.lane(l);
            i == ri || j == ri || (rj != boundary && (i == rj || j == rj))
        })
    }
}

impl Packed for Quad {
    fn clear(&mut self, l: usize, boundary: u32) {
        for field in [
            &mut self.nx,
            &mut self.ny,
            &mut self.vbx,
            &mut self.vby,
            &mut self.wi,
            &mut self.wj,
            &mut self.wn,
            &mut self.wt,
            &mut self.mn,
            &mut self.mt,
            &mut self.target,
            &mut self.mu,
            &mut self.pn,
            &mut self.pt,
        ] {
            field[l] = 0.0;
        }
        (self.i[l], self.j[l], self.row[l]) = (boundary, boundary, NO_ROW);
    }

    fn set(&mut self, l: usize, r: &Row, row: u32) {
        (self.nx[l], self.ny[l]) = r.n;
        (self.vbx[l], self.vby[l]) = r.vb;
        (self.wi[l], self.wj[l], self.wn[l], self.wt[l]) = (r.wi, r.wj, r.wn, r.wt);
        (self.mn[l], self.mt[l]) = (r.mn, r.mt);
        (self.target[l], self.mu[l]) = (r.target, r.mu);
        (self.pn[l], self.pt[l]) = (r.pn, r.pt);
        (self.i[l], self.j[l], self.row[l]) = (r.i, r.j, row);
    }

    fn lane(&self, l: usize) -> (u32, u32, u32) {
        (self.i[l], self.j[l], self.row[l])
    }

    fn refresh(&mut self, l: usize, f: &Fresh) {
        (self.nx[l], self.ny[l]) = f.n;
        (self.target[l], self.pn[l], self.pt[l]) = (f.target, f.pn, f.pt);
    }

    fn apply(&self, l: usize, vel: &mut [[f64; 4]], sf: f64, pn: f64, pt: f64) {
        apply(self, l, vel, sf, pn, pt);
    }

    fn impulses(&self, l: usize) -> (f64, f64, f64) {
        (self.pn[l], self.pt[l], self.vby[l])
    }
}

/// Where the next contact of disks `(i, j)` goes: the last quad's next lane, or a new quad's
/// first where that one is full or would share a disk (`used` quads filled, `lanes` lanes of the
/// last; a quad's empty lanes cleared as it is left).
pub(super) fn place<Q: Packed>(
    quads: &mut Vec<Q>,
    (used, lanes): (&mut usize, &mut usize),
    ij: (u32, u32),
    boundary: u32,
) -> (usize, usize) {
    if *lanes == 4 || quads[*used - 1].touches(*lanes, ij, boundary) {
        if *used > 0 {
            (*lanes..4).for_each(|l| quads[*used - 1].clear(l, boundary));
        }
        if *used == quads.len() {
            quads.push(Q::empty(boundary));
        }
        *used += 1;
        *lanes = 0;
    }
    *lanes += 1;
    (*used - 1, *lanes - 1)
}

/// What a step sets of a laid-out pair that can close within it: its normal, the bound on its
/// normal velocity after the step, and its warm-start impulses.
#[derive(Debug, Clone, Copy)]
pub(super) struct Fresh {
    pub n: (f64, f64),
    pub target: f64,
    pub pn: f64,
    pub pt: f64,
}

/// Packs a step's rows into quads as they are gathered, a batch at a time: a row that would
/// share a disk with the quad being filled, or find it full, starts the next. Each row's
/// impulses are applied as it is packed (the warm start, in the rows' order; `vel` and `sf` as
/// [`sweep`]'s). The rows themselves are not kept: the quads hold what the sweep and the booking
/// read, and each lane its row's number in the order pushed.
pub(super) struct Packer<'a> {
    quads: &'a mut Vec<Quad>,
    vel: &'a mut [[f64; 4]],
    /// The velocities' entry of a boundary.
    boundary: u32,
    sf: f64,
    /// Quads filled so far, lanes of the last, rows packed.
    used: usize,
    lanes: usize,
    rows: u32,
    /// Rows pushed and not yet packed: packed [`BATCH`] at a time, so that gathering and
    /// packing each run in a loop of their own (interleaved, the packing's scattered stores held
    /// up the gathering's loads: 3 % on a bed of 1000 disks).
    batch: Vec<Row>,
}

/// Rows packed at a time ([`Packer`]).
const BATCH: usize = 64;

impl<'a> Packer<'a> {
    /// Packs into `quads` in place (a new quad copied in only when the last step had fewer).
    pub(super) fn new(
        quads: &'a mut Vec<Quad>,
        vel: &'a mut [[f64; 4]],
        boundary: u32,
        sf: f64,
    ) -> Packer<'a> {
        Packer {
            quads,
            vel,
            boundary,
            sf,
            used: 0,
            lanes: 4,
            rows: 0,
            batch: Vec::with_capacity(BATCH),
        }
    }

    /// The next row (packed with its batch).
    #[inline]
    pub(super) fn push(&mut self, r: &Row) {
        self.batch.push(*r);
        if self.batch.len() == BATCH {
            self.pack_batch();
        }
    }

    /// Packs the rows pushed and not yet packed.
    fn pack_batch(&mut self) {
        let batch = std::mem::take(&mut self.batch);
        for r in &batch {
            self.pack(r);
        }
        self.batch = batch;
        self.batch.clear();
    }

    /// Packs one row.
    #[inline(always)]
    fn pack(&mut self, r: &Row) {
        let lanes = (&mut self.used, &mut self.lanes);
        let (at, l) = place(self.quads, lanes, (r.i, r.j), self.boundary);
        let q = &mut self.quads[at];
        q.set(l, r, self.rows);
        apply(q, l, self.vel, self.sf, r.pn, r.pt);
        self.rows += 1;
    }

    /// Empties the last quad's lanes left over and drops the quads not filled.
    pub(super) fn finish(mut self) {
        self.pack_batch();
        if self.used > 0 {
            (self.lanes..4).for_each(|l| self.quads[self.used - 1].clear(l, self.boundary));
        }
        self.quads.truncate(self.used);
    }
}

/// A contact that pushed in the solve: its row's number (in the order pushed), its disks, its
/// impulses, and the boundary's vertical velocity (0 for pairs).
pub(super) struct Pushed {
    pub row: u32,
    pub i: u32,
    pub j: u32,
    pub pn: f64,
    pub pt: f64,
    pub vby: f64,
}

/// The contacts whose normal impulse is positive, in the rows' order (the quads hold them in
/// that order, a quad's empty lanes last).
pub(super) fn pushing<Q: Packed>(quads: &[Q]) -> impl Iterator<Item = Pushed> + '_ {
    quads
        .iter()
        .flat_map(|q| (0..4).filter_map(|l| q.pushed(l)))
}

/// One Gauss–Seidel sweep: each contact's impulses set so that it meets its bound (the normal
/// one at least 0, the tangential one in Coulomb's cone, 0 on smooth disks), given the others'.
/// Returns the largest change of a relative velocity.
pub(super) fn sweep(lanes: Lanes, quads: &mut [Quad], vel: &mut [[f64; 4]], sf: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if lanes.avx2() {
        // SAFETY: the processor has AVX2 (the lanes say so); every lane's disks index `vel`.
        return unsafe { sweep_avx2(quads, vel, sf) };
    }
    let _ = lanes;
    sweep_one_by_one(quads, vel, sf)
}

/// [`sweep`] one lane at a time, in the rows' order.
fn sweep_one_by_one(quads: &mut [Quad], vel: &mut [[f64; 4]], sf: f64) -> f64 {
    let mut change = 0.0;
    for q in quads {
        for l in 0..4 {
            let (un, ut) = relative(q, l, vel);
            let pn = larger(q.pn[l] + (q.target[l] - un) * q.mn[l], 0.0);
            let cap = q.mu[l] * pn;
            let pt = q.pt[l] - ut * q.mt[l];
            let pt = smaller(cap, larger(-cap, pt));
            let (dpn, dpt) = (pn - q.pn[l], pt - q.pt[l]);
            if dpn != 0.0 || dpt != 0.0 {
                apply(q, l, vel, sf, dpn, dpt);
                (q.pn[l], q.pt[l]) = (pn, pt);
                change = larger((dpn * q.wn[l]).abs(), change);
                change = larger((dpt * q.wt[l]).abs(), change);
            }
        }
    }
    change
}

/// `a` if it is the larger, else `b` (so `b` where either is a NaN, and where they are zeros of
/// either sign): the rule of the processor's `max`, in both paths.
#[inline(always)]
pub(super) fn larger(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// `a` if it is the smaller, else `b`: the rule of the processor's `min`, as [`larger`].
#[inline(always)]
fn smaller(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

/// Normal and tangential relative velocity of lane `l`'s contact (the tangent `(−n_y, n_x)`).
#[inline(always)]
fn relative(q: &Quad, l: usize, vel: &[[f64; 4]]) -> (f64, f64) {
    let (vi, vj) = (vel[q.i[l] as usize], vel[q.j[l] as usize]);
    let (vx, vy) = (vi[0] - vj[0] - q.vbx[l], vi[1] - vj[1] - q.vby[l]);
    let un = vx * q.nx[l] + vy * q.ny[l];
    let ut = -vx * q.ny[l] + vy * q.nx[l] - (vi[2] + vj[2]);
    (un, ut)
}

/// Applies impulses `pn` along the normal and `pt` along the tangent to lane `l`'s disks (a
/// tangential impulse at the rim turns each disk by `−p_t/(q m)` in rim speed).
#[inline(always)]
fn apply(q: &Quad, l: usize, vel: &mut [[f64; 4]], sf: f64, pn: f64, pt: f64) {
    let (nx, ny) = (q.nx[l], q.ny[l]);
    let (px, py) = (pn * nx - pt * ny, pn * ny + pt * nx);
    let (wi, wj) = (q.wi[l], q.wj[l]);
    let vi = &mut vel[q.i[l] as usize];
    (vi[0], vi[1], vi[2]) = (vi[0] + px * wi, vi[1] + py * wi, vi[2] - pt * wi * sf);
    // A boundary (the entry past the last disk) does not move.
    if wj != 0.0 {
        let vj = &mut vel[q.j[l] as usize];
        (vj[0], vj[1], vj[2]) = (vj[0] - px * wj, vj[1] - py * wj, vj[2] - pt * wj * sf);
    }
}

/// [`sweep`] four lanes at a time: [`sweep_one_by_one`]'s operations on each lane, a lane
/// that does not change writing back what it read.
///
/// # Safety
///
/// Only where the processor has AVX2; every lane's `i` and `j` index `vel` (checked).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sweep_avx2(quads: &mut [Quad], vel: &mut [[f64; 4]], sf: f64) -> f64 {
    use crate::platform::transpose::transpose;
    use std::arch::x86_64::*;
    let zero = _mm256_setzero_pd();
    let sign = _mm256_set1_pd(-0.0);
    let sf = _mm256_set1_pd(sf);
    let mut change = zero;
    let load = |a: &[f64; 4]| _mm256_load_pd(a.as_ptr());
    for q in quads.iter_mut() {
        // Each disk's (vx, vy, ω a, _) to columns, and back.
        let gather = |ks: [u32; 4], vel: &[[f64; 4]]| {
            transpose(ks.map(|k| _mm256_loadu_pd(vel[k as usize].as_ptr())))
        };
        let scatter = |ks: [u32; 4], c: [__m256d; 4], vel: &mut [[f64; 4]]| {
            for (k, r) in ks.iter().zip(transpose(c)) {
                _mm256_storeu_pd(vel[*k as usize].as_mut_ptr(), r);
            }
        };
        let vi = gather(q.i, vel);
        let vj = gather(q.j, vel);
        let (nx, ny) = (load(&q.nx), load(&q.ny));
        let vx = _mm256_sub_pd(_mm256_sub_pd(vi[0], vj[0]), load(&q.vbx));
        let vy = _mm256_sub_pd(_mm256_sub_pd(vi[1], vj[1]), load(&q.vby));
        let un = _mm256_add_pd(_mm256_mul_pd(vx, nx), _mm256_mul_pd(vy, ny));
        let ut = _mm256_sub_pd(
            _mm256_add_pd(
                _mm256_mul_pd(_mm256_xor_pd(vx, sign), ny),
                _mm256_mul_pd(vy, nx),
            ),
            _mm256_add_pd(vi[2], vj[2]),
        );
        let (pn0, pt0) = (load(&q.pn), load(&q.pt));
        let pn = _mm256_add_pd(
            pn0,
            _mm256_mul_pd(_mm256_sub_pd(load(&q.target), un), load(&q.mn)),
        );
        let pn = _mm256_max_pd(pn, zero);
        let cap = _mm256_mul_pd(load(&q.mu), pn);
        let pt = _mm256_sub_pd(pt0, _mm256_mul_pd(ut, load(&q.mt)));
        let pt = _mm256_min_pd(cap, _mm256_max_pd(_mm256_xor_pd(cap, sign), pt));
        let (dpn, dpt) = (_mm256_sub_pd(pn, pn0), _mm256_sub_pd(pt, pt0));
        let changed = _mm256_or_pd(
            _mm256_cmp_pd::<_CMP_NEQ_UQ>(dpn, zero),
            _mm256_cmp_pd::<_CMP_NEQ_UQ>(dpt, zero),
        );
        if _mm256_movemask_pd(changed) == 0 {
            continue;
        }
        let px = _mm256_sub_pd(_mm256_mul_pd(dpn, nx), _mm256_mul_pd(dpt, ny));
        let py = _mm256_add_pd(_mm256_mul_pd(dpn, ny), _mm256_mul_pd(dpt, nx));
        let (wi, wj) = (load(&q.wi), load(&q.wj));
        let moved_i = [
            _mm256_add_pd(vi[0], _mm256_mul_pd(px, wi)),
            _mm256_add_pd(vi[1], _mm256_mul_pd(py, wi)),
            _mm256_sub_pd(vi[2], _mm256_mul_pd(_mm256_mul_pd(dpt, wi), sf)),
            vi[3],
        ];
        let moved_j = [
            _mm256_sub_pd(vj[0], _mm256_mul_pd(px, wj)),
            _mm256_sub_pd(vj[1], _mm256_mul_pd(py, wj)),
            _mm256_sub_pd(vj[2], _mm256_mul_pd(_mm256_mul_pd(dpt, wj), sf)),
            vj[3],
        ];
        let moves_j = _mm256_and_pd(changed, _mm256_cmp_pd::<_CMP_NEQ_UQ>(wj, zero));
        let pick = |old: [__m256d; 4], new: [__m256d; 4], mask| {
            [0, 1, 2, 3].map(|c| _mm256_blendv_pd(old[c], new[c], mask))
        };
        scatter(q.i, pick(vi, moved_i, changed), vel);
        scatter(q.j, pick(vj, moved_j, moves_j), vel);
        _mm256_store_pd(q.pn.as_mut_ptr(), _mm256_blendv_pd(pn0, pn, changed));
        _mm256_store_pd(q.pt.as_mut_ptr(), _mm256_blendv_pd(pt0, pt, changed));
        // A lane that did not change adds zeros.
        let n_change = _mm256_andnot_pd(sign, _mm256_mul_pd(dpn, load(&q.wn)));
        let t_change = _mm256_andnot_pd(sign, _mm256_mul_pd(dpt, load(&q.wt)));
        change = _mm256_max_pd(n_change, change);
        change = _mm256_max_pd(t_change, change);
    }
    let mut lanes = [0.0; 4];
    _mm256_storeu_pd(lanes.as_mut_ptr(), change);
    lanes.into_iter().fold(0.0, |c, x| larger(x, c))
}

#[cfg(test)]
mod tests {
    use super::super::Row;
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Packs `rows` in order ([`Packer`]).
    fn pack(rows: &[Row], boundary: u32, quads: &mut Vec<Quad>, vel: &mut [[f64; 4]], sf: f64) {
        let mut packer = Packer::new(quads, vel, boundary, sf);
        rows.iter().for_each(|r| packer.push(r));
        packer.finish();
    }

    /// The quads' impulses back to their rows.
    fn unpack(quads: &[Quad], rows: &mut [Row]) {
        for q in quads {
            for l in (0..4).filter(|&l| q.row[l] != NO_ROW) {
                let r = &mut rows[q.row[l] as usize];
                (r.pn, r.pt) = (q.pn[l], q.pt[l]);
            }
        }
    }

    /// The sweep as one loop over the rows in order, one at a time (the sweep before quads).
    fn sweep_rows(rows: &mut [Row], vel: &mut [[f64; 4]], sf: f64) -> f64 {
        let mut change = 0.0f64;
        for r in rows {
            let (vi, vj) = (vel[r.i as usize], vel[r.j as usize]);
            let (vx, vy) = (vi[0] - vj[0] - r.vb.0, vi[1] - vj[1] - r.vb.1);
            let un = vx * r.n.0 + vy * r.n.1;
            let ut = -vx * r.n.1 + vy * r.n.0 - (vi[2] + vj[2]);
            let pn = (r.pn + (r.target - un) * r.mn).max(0.0);
            let cap = r.mu * pn;
            let pt = (r.pt - ut * r.mt).clamp(-cap, cap);
            let (dpn, dpt) = (pn - r.pn, pt - r.pt);
            if dpn != 0.0 || dpt != 0.0 {
                let (px, py) = (dpn * r.n.0 - dpt * r.n.1, dpn * r.n.1 + dpt * r.n.0);
                let v = &mut vel[r.i as usize];
                (v[0], v[1], v[2]) = (v[0] + px * r.wi, v[1] + py * r.wi, v[2] - dpt * r.wi * sf);
                if r.wj != 0.0 {
                    let v = &mut vel[r.j as usize];
                    (v[0], v[1], v[2]) =
                        (v[0] - px * r.wj, v[1] - py * r.wj, v[2] - dpt * r.wj * sf);
                }
                (r.pn, r.pt) = (pn, pt);
                change = change.max((dpn * r.wn).abs()).max((dpt * r.wt).abs());
            }
        }
        change
    }

    /// A step's worth of contacts among `n` disks: floor rows first, then pairs, some sharing
    /// disks with the rows just before them, with warm impulses, bounds that push and bounds that
    /// hold, and masses and spins of rough or smooth disks.
    fn contacts(rng: &mut impl Rng, n: u32, rough: bool) -> Vec<Row> {
        let mut rows = Vec::new();
        let mu = if rough { 0.5 } else { 0.0 };
        let row = |i: u32, j: u32, rng: &mut dyn rand::RngCore| {
            let angle: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let (wi, wj) = (rng.random_range(0.5..2.0), if j == n { 0.0 } else { 1.0 });
            let w = wi + wj;
            let wt = w * 1.5;
            Row {
                i,
                j,
                n: (angle.cos(), angle.sin()),
                vb: if j == n {
                    (0.0, rng.random_range(-0.1..0.1))
                } else {
                    (0.0, 0.0)
                },
                wi,
                wj,
                wn: w,
                wt,
                mn: 1.0 / w,
                mt: 1.0 / wt,
                target: rng.random_range(-0.2..0.2),
                mu,
                pn: if rng.random_bool(0.5) {
                    rng.random_range(0.0..0.3)
                } else {
                    0.0
                },
                pt: if rough {
                    rng.random_range(-0.05..0.05)
                } else {
                    0.0
                },
            }
        };
        for i in 0..n {
            if rng.random_bool(0.3) {
                rows.push(row(i, n, rng));
            }
        }
        for _ in 0..4 * n {
            let i = rng.random_range(0..n);
            let j = (i + rng.random_range(1..n)) % n;
            rows.push(row(i, j, rng));
        }
        rows
    }

    /// The quads' sweep, one lane at a time and four at a time, gives the rows' sweep bit for
    /// bit: the same velocities, impulses and largest change, sweep after sweep; the quads are
    /// packed in place over the last case's, as from step to step.
    #[test]
    fn quads_sweep_as_the_rows_in_order() {
        let avx2 = Lanes::found().avx2();
        if !avx2 {
            eprintln!("no AVX2 here: only the one-lane path is compared");
        }
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
        let mut quads = Vec::new();
        for case in 0..40 {
            let n = rng.random_range(3..60);
            let rough = case % 2 == 1;
            let sf = if rough { 2.0 } else { 0.0 };
            let mut rows = contacts(&mut rng, n, rough);
            let mut vel: Vec<[f64; 4]> = (0..n)
                .map(|_| {
                    let spin = if rough {
                        rng.random_range(-1.0..1.0)
                    } else {
                        0.0
                    };
                    [
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        spin,
                        0.0,
                    ]
                })
                .collect();
            vel.push([0.0; 4]);
            let mut vel_one = vel.clone();
            pack(&rows, n, &mut quads, &mut vel_one, sf);
            assert!(quads.len() * 4 >= rows.len());
            let quads_one = &mut quads.clone();
            let (mut vel_four, mut quads_four) = (vel_one.clone(), quads.clone());
            for r in &rows {
                let (px, py) = (r.pn * r.n.0 - r.pt * r.n.1, r.pn * r.n.1 + r.pt * r.n.0);
                let v = &mut vel[r.i as usize];
                (v[0], v[1], v[2]) = (v[0] + px * r.wi, v[1] + py * r.wi, v[2] - r.pt * r.wi * sf);
                if r.wj != 0.0 {
                    let v = &mut vel[r.j as usize];
                    (v[0], v[1], v[2]) =
                        (v[0] - px * r.wj, v[1] - py * r.wj, v[2] - r.pt * r.wj * sf);
                }
            }
            for sweep_no in 0..8 {
                let want = sweep_rows(&mut rows, &mut vel, sf);
                assert!(
                    sweep_no > 0 || want > 0.0,
                    "case {case}: the first sweep pushes"
                );
                let one = sweep_one_by_one(quads_one, &mut vel_one, sf);
                assert_eq!(
                    one.to_bits(),
                    want.to_bits(),
                    "case {case}, sweep {sweep_no}"
                );
                if avx2 {
                    let four = sweep(Lanes::found(), &mut quads_four, &mut vel_four, sf);
                    assert_eq!(
                        four.to_bits(),
                        want.to_bits(),
                        "case {case}, sweep {sweep_no}"
                    );
                }
            }
            let bits = |v: &[[f64; 4]]| -> Vec<u64> {
                v.iter()
                    .flat_map(|d| d[..3].iter().map(|x| x.to_bits()))
                    .collect()
            };
            assert_eq!(bits(&vel_one), bits(&vel), "case {case}: velocities");
            let mut got = rows.clone();
            unpack(quads_one, &mut got);
            let impulses = |rs: &[Row]| -> Vec<(u64, u64)> {
                rs.iter()
                    .map(|r| (r.pn.to_bits(), r.pt.to_bits()))
                    .collect()
            };
            assert_eq!(impulses(&got), impulses(&rows), "case {case}: impulses");
            let pushed: Vec<(u32, u64, u64)> = pushing(quads_one)
                .map(|p| (p.row, p.pn.to_bits(), p.pt.to_bits()))
                .collect();
            let want: Vec<(u32, u64, u64)> = (rows.iter().enumerate())
                .filter(|(_, r)| r.pn > 0.0)
                .map(|(k, r)| (k as u32, r.pn.to_bits(), r.pt.to_bits()))
                .collect();
            assert!(!want.is_empty(), "case {case}: some contact pushes");
            assert_eq!(
                pushed, want,
                "case {case}: the contacts that pushed, in order"
            );
            if avx2 {
                assert_eq!(
                    bits(&vel_four),
                    bits(&vel),
                    "case {case}: velocities, four lanes"
                );
                unpack(&quads_four, &mut got);
                assert_eq!(
                    impulses(&got),
                    impulses(&rows),
                    "case {case}: impulses, four lanes"
                );
            }
        }
    }
}
