//! Smooth pairs' quads: what the sweep of a pair of smooth disks reads, and nothing else.
//!
//! A pair of smooth disks has no tangential impulse, no spin and no moving boundary, so its
//! quad keeps the normal, the effective mass, the bound and the normal impulse: 192 bytes
//! against a full [`Quad`]'s 512. Each disk's inverse mass is read with its velocity, from the
//! fourth entry of the solve's copy (`vel[k][3]`, which only these quads read). The sweep
//! streams the step's quads from memory eight times a step (the deep bed: about 14 000 quads),
//! and reading fewer bytes is what makes it cheaper. Each lane does the operations a full quad's
//! lane does with no tangent, so the impulses and velocities are the same bit for bit (tested
//! against [`quads::sweep`]).
//!
//! [`Quad`]: super::quads::Quad
//! [`quads::sweep`]: super::quads::sweep

use super::quads::{larger, Fresh, Packed, NO_ROW};
use super::Row;
use crate::platform::cpu::Lanes;

/// Four contacts of smooth disks that share no disk, each field one value per lane (a
/// [`Row`]'s).
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(32))]
pub(super) struct Smooth {
    nx: [f64; 4],
    ny: [f64; 4],
    mn: [f64; 4],
    target: [f64; 4],
    pn: [f64; 4],
    i: [u32; 4],
    j: [u32; 4],
    row: [u32; 4],
}

impl Packed for Smooth {
    fn clear(&mut self, l: usize, boundary: u32) {
        for field in [
            &mut self.nx,
            &mut self.ny,
            &mut self.mn,
            &mut self.target,
            &mut self.pn,
        ] {
            field[l] = 0.0;
        }
        (self.i[l], self.j[l], self.row[l]) = (boundary, boundary, NO_ROW);
    }

    /// The row's inverse masses must be its disks' in the solve's velocities (`vel[k][3]`).
    fn set(&mut self, l: usize, r: &Row, row: u32) {
        (self.nx[l], self.ny[l]) = r.n;
        (self.mn[l], self.target[l], self.pn[l]) = (r.mn, r.target, r.pn);
        (self.i[l], self.j[l], self.row[l]) = (r.i, r.j, row);
    }

    fn lane(&self, l: usize) -> (u32, u32, u32) {
        (self.i[l], self.j[l], self.row[l])
    }

    fn refresh(&mut self, l: usize, f: &Fresh) {
        (self.nx[l], self.ny[l]) = f.n;
        (self.target[l], self.pn[l]) = (f.target, f.pn);
    }

    fn apply(&self, l: usize, vel: &mut [[f64; 4]], _sf: f64, pn: f64, _pt: f64) {
        apply(self, l, vel, pn);
    }

    fn impulses(&self, l: usize) -> (f64, f64, f64) {
        (self.pn[l], 0.0, 0.0)
    }
}

/// Applies impulse `pn` along the normal to lane `l`'s disks (each disk's inverse mass its
/// velocity's fourth entry).
#[inline(always)]
fn apply(q: &Smooth, l: usize, vel: &mut [[f64; 4]], pn: f64) {
    let (px, py) = (pn * q.nx[l], pn * q.ny[l]);
    let vi = &mut vel[q.i[l] as usize];
    (vi[0], vi[1]) = (vi[0] + px * vi[3], vi[1] + py * vi[3]);
    let vj = &mut vel[q.j[l] as usize];
    (vj[0], vj[1]) = (vj[0] - px * vj[3], vj[1] - py * vj[3]);
}

/// One Gauss–Seidel sweep over smooth pairs: each contact's normal impulse set so that it is at
/// least 0 and meets its bound, given the others'. Returns the largest change of a relative
/// velocity.
pub(super) fn sweep(lanes: Lanes, quads: &mut [Smooth], vel: &mut [[f64; 4]]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if lanes.avx2() {
        // SAFETY: the processor has AVX2 (the lanes say so); every lane's disks index `vel`.
        return unsafe { sweep_avx2(quads, vel) };
    }
    let _ = lanes;
    sweep_one_by_one(quads, vel)
}

/// [`sweep`] one lane at a time, in the rows' order.
fn sweep_one_by_one(quads: &mut [Smooth], vel: &mut [[f64; 4]]) -> f64 {
    let mut change = 0.0;
    for q in quads {
        for l in 0..4 {
            let (vi, vj) = (vel[q.i[l] as usize], vel[q.j[l] as usize]);
            let un = (vi[0] - vj[0]) * q.nx[l] + (vi[1] - vj[1]) * q.ny[l];
            let pn = larger(q.pn[l] + (q.target[l] - un) * q.mn[l], 0.0);
            let dpn = pn - q.pn[l];
            if dpn != 0.0 {
                apply(q, l, vel, dpn);
                q.pn[l] = pn;
                let wn = vel[q.i[l] as usize][3] + vel[q.j[l] as usize][3];
                change = larger((dpn * wn).abs(), change);
            }
        }
    }
    change
}

/// [`sweep`] four lanes at a time: [`sweep_one_by_one`]'s operations on each lane, a lane that
/// does not change writing back what it read.
///
/// # Safety
///
/// Only where the processor has AVX2; every lane's `i` and `j` index `vel` (checked).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sweep_avx2(quads: &mut [Smooth], vel: &mut [[f64; 4]]) -> f64 {
    use crate::platform::transpose::transpose;
    use std::arch::x86_64::*;
    let zero = _mm256_setzero_pd();
    let sign = _mm256_set1_pd(-0.0);
    let mut change = zero;
    let load = |a: &[f64; 4]| _mm256_load_pd(a.as_ptr());
    for q in quads.iter_mut() {
        // Each disk's (vx, vy, _, 1/m) to columns, and back.
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
        let vx = _mm256_sub_pd(vi[0], vj[0]);
        let vy = _mm256_sub_pd(vi[1], vj[1]);
        let un = _mm256_add_pd(_mm256_mul_pd(vx, nx), _mm256_mul_pd(vy, ny));
        let pn0 = load(&q.pn);
        let pn = _mm256_add_pd(
            pn0,
            _mm256_mul_pd(_mm256_sub_pd(load(&q.target), un), load(&q.mn)),
        );
        let pn = _mm256_max_pd(pn, zero);
        let dpn = _mm256_sub_pd(pn, pn0);
        let changed = _mm256_cmp_pd::<_CMP_NEQ_UQ>(dpn, zero);
        if _mm256_movemask_pd(changed) == 0 {
            continue;
        }
        let (px, py) = (_mm256_mul_pd(dpn, nx), _mm256_mul_pd(dpn, ny));
        let (wi, wj) = (vi[3], vj[3]);
        let moved_i = [
            _mm256_add_pd(vi[0], _mm256_mul_pd(px, wi)),
            _mm256_add_pd(vi[1], _mm256_mul_pd(py, wi)),
            vi[2],
            vi[3],
        ];
        let moved_j = [
            _mm256_sub_pd(vj[0], _mm256_mul_pd(px, wj)),
            _mm256_sub_pd(vj[1], _mm256_mul_pd(py, wj)),
            vj[2],
            vj[3],
        ];
        let pick = |old: [__m256d; 4], new: [__m256d; 4]| {
            [0, 1, 2, 3].map(|c| _mm256_blendv_pd(old[c], new[c], changed))
        };
        scatter(q.i, pick(vi, moved_i), vel);
        scatter(q.j, pick(vj, moved_j), vel);
        _mm256_store_pd(q.pn.as_mut_ptr(), _mm256_blendv_pd(pn0, pn, changed));
        // A lane that did not change adds zeros.
        let wn = _mm256_add_pd(wi, wj);
        let n_change = _mm256_andnot_pd(sign, _mm256_mul_pd(dpn, wn));
        change = _mm256_max_pd(n_change, change);
    }
    let mut lanes = [0.0; 4];
    _mm256_storeu_pd(lanes.as_mut_ptr(), change);
    lanes.into_iter().fold(0.0, |c, x| larger(x, c))
}
