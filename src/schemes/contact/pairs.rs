//! The Verlet pairs laid out for the sweep, once a list: each pair's lane keeps what does not
//! change until the next list (its disks, masses, Coulomb's coefficient), and a step sets only
//! what it changes (the normal, the bound, the warm start). Smooth disks' pairs go into
//! [`Smooth`] quads, rough ones into full [`Quad`]s.

use super::quads::{self, place, Fresh, Packed, Pushed, Quad, NO_ROW};
use super::smooth::{self, Smooth};
use super::Row;
use crate::platform::cpu::Lanes;

/// The Verlet pairs laid out for the sweep: in [`Smooth`] quads where the disks are smooth (fewer
/// than half the bytes to stream), in full quads where they are rough.
#[derive(Debug)]
pub(super) enum Pairs {
    Smooth(Vec<Smooth>),
    Rough(Vec<Quad>),
}

impl Pairs {
    /// No pairs yet, of smooth or rough disks.
    pub(super) fn new(rough: bool) -> Pairs {
        match rough {
            true => Pairs::Rough(Vec::new()),
            false => Pairs::Smooth(Vec::new()),
        }
    }

    /// [`lay_out`].
    pub(super) fn lay_out(
        &mut self,
        pairs: &[(u32, u32)],
        boundary: u32,
        mu: f64,
        inertia: impl FnMut(u32, u32) -> [f64; 6],
    ) {
        match self {
            Pairs::Smooth(q) => lay_out(pairs, q, boundary, mu, inertia),
            Pairs::Rough(q) => lay_out(pairs, q, boundary, mu, inertia),
        }
    }

    /// One sweep ([`quads::sweep`]).
    pub(super) fn sweep(&mut self, lanes: Lanes, vel: &mut [[f64; 4]], sf: f64) -> f64 {
        match self {
            Pairs::Smooth(q) => smooth::sweep(lanes, q, vel),
            Pairs::Rough(q) => quads::sweep(lanes, q, vel, sf),
        }
    }

    /// Each pair that pushed, in the list's order ([`quads::pushing`]).
    pub(super) fn each_pushing(&self, f: impl FnMut(Pushed)) {
        match self {
            Pairs::Smooth(q) => quads::pushing(q).for_each(f),
            Pairs::Rough(q) => quads::pushing(q).for_each(f),
        }
    }

    /// Bytes held.
    pub(super) fn bytes(&self) -> usize {
        match self {
            Pairs::Smooth(q) => std::mem::size_of::<Smooth>() * q.capacity(),
            Pairs::Rough(q) => std::mem::size_of::<Quad>() * q.capacity(),
        }
    }
}

/// The Verlet pairs of a list, packed into quads once for all the steps until the next list, in
/// the list's order (the sweep's): each lane holds its pair's disks, inverse and effective
/// masses (`inertia`, from the disks' numbers: `[wi, wj, wn, wt, mn, mt]` as a [`Row`]'s) and
/// Coulomb's coefficient `mu`, and as its row the pair's index in the list. What a step changes
/// is set by [`refresh`].
pub(super) fn lay_out<Q: Packed>(
    pairs: &[(u32, u32)],
    quads: &mut Vec<Q>,
    boundary: u32,
    mu: f64,
    mut inertia: impl FnMut(u32, u32) -> [f64; 6],
) {
    let (mut used, mut lanes) = (0, 4);
    for (k, &(i, j)) in pairs.iter().enumerate() {
        let (at, l) = place(quads, (&mut used, &mut lanes), (i, j), boundary);
        let [wi, wj, wn, wt, mn, mt] = inertia(i, j);
        quads[at].set(
            l,
            &Row {
                i,
                j,
                n: (0.0, 0.0),
                vb: (0.0, 0.0),
                wi,
                wj,
                wn,
                wt,
                mn,
                mt,
                target: f64::NEG_INFINITY,
                mu,
                pn: 0.0,
                pt: 0.0,
            },
            k as u32,
        );
    }
    if used > 0 {
        (lanes..4).for_each(|l| quads[used - 1].clear(l, boundary));
    }
    quads.truncate(used);
}

/// Sets each laid-out pair's lane for the step, in the list's order, from `fresh` (given the
/// pair's index) and applies its warm start to `vel` as [`quads::Packer`] does. A pair that cannot
/// close within the step (`None`) neither pushes nor keeps impulses: its bound is −∞, which no
/// relative velocity falls below, so that its lane changes nothing in the sweep.
pub(super) fn refresh<Q: Packed>(
    quads: &mut [Q],
    vel: &mut [[f64; 4]],
    sf: f64,
    mut fresh: impl FnMut(u32) -> Option<Fresh>,
) {
    for q in quads {
        for l in 0..4 {
            let (_, _, row) = q.lane(l);
            if row == NO_ROW {
                continue;
            }
            match fresh(row) {
                Some(f) => {
                    q.refresh(l, &f);
                    q.apply(l, vel, sf, f.pn, f.pt);
                }
                None => q.refresh(l, &INERT),
            }
        }
    }
}

/// A laid-out pair that cannot close within the step ([`refresh`]).
const INERT: Fresh = Fresh {
    n: (0.0, 0.0),
    target: f64::NEG_INFINITY,
    pn: 0.0,
    pt: 0.0,
};

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Smooth pairs laid out both ways, refreshed alike and swept eight times: the smooth quads
    /// give the full quads' velocities, impulses and largest changes bit for bit, one lane at a
    /// time and four at a time.
    #[test]
    fn smooth_quads_sweep_as_full_quads() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(11);
        let avx2 = Lanes::found();
        let mut pushes = 0;
        for case in 0..40 {
            let n: u32 = rng.random_range(3..60);
            let pairs: Vec<(u32, u32)> = (0..4 * n)
                .map(|_| {
                    let i = rng.random_range(0..n);
                    (i, (i + rng.random_range(1..n)) % n)
                })
                .collect();
            let mass: Vec<f64> = (0..n).map(|_| rng.random_range(0.5..2.0)).collect();
            let inertia = |i: u32, j: u32| {
                let (wi, wj) = (1.0 / mass[i as usize], 1.0 / mass[j as usize]);
                let wn = wi + wj;
                [wi, wj, wn, wn, 1.0 / wn, 1.0 / wn]
            };
            let fresh: Vec<Option<Fresh>> = (0..pairs.len())
                .map(|_| {
                    let angle: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                    rng.random_bool(0.8).then(|| Fresh {
                        n: (angle.cos(), angle.sin()),
                        target: rng.random_range(-0.2..0.2),
                        pn: [0.0, rng.random_range(0.0..0.3)][rng.random_range(0..2)],
                        pt: 0.0,
                    })
                })
                .collect();
            // The solve's copy: velocities, no spin, inverse masses (the smooth quads read them).
            let vel: Vec<[f64; 4]> = (0..=n)
                .map(|k| match k < n {
                    true => [
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        0.0,
                        1.0 / mass[k as usize],
                    ],
                    false => [0.0; 4],
                })
                .collect();
            let (mut full, mut slim): (Vec<Quad>, Vec<Smooth>) = (Vec::new(), Vec::new());
            lay_out(&pairs, &mut full, n, 0.0, inertia);
            lay_out(&pairs, &mut slim, n, 0.0, inertia);
            let take = |k: u32| fresh[k as usize];
            let (mut v_full, mut v_slim) = (vel.clone(), vel.clone());
            refresh(&mut full, &mut v_full, 0.0, take);
            refresh(&mut slim, &mut v_slim, 0.0, take);
            let lanes = if case % 2 == 0 {
                avx2
            } else {
                Lanes::ONE_BY_ONE
            };
            for sweep in 0..8 {
                let a = quads::sweep(lanes, &mut full, &mut v_full, 0.0);
                let b = smooth::sweep(lanes, &mut slim, &mut v_slim);
                assert_eq!(
                    a.to_bits(),
                    b.to_bits(),
                    "case {case}, sweep {sweep}: change"
                );
                let bits = |v: &[[f64; 4]]| -> Vec<u64> {
                    v.iter().flat_map(|x| x.map(f64::to_bits)).collect()
                };
                assert_eq!(bits(&v_full), bits(&v_slim), "case {case}, sweep {sweep}");
                let pn = |p: Box<dyn Iterator<Item = Pushed> + '_>| -> Vec<(u32, u64)> {
                    p.map(|p| (p.row, p.pn.to_bits())).collect()
                };
                let pushed = pn(Box::new(quads::pushing(&full)));
                assert_eq!(pushed, pn(Box::new(quads::pushing(&slim))));
                pushes += pushed.len();
            }
        }
        assert!(pushes > 1000, "the cases push: {pushes}");
    }
}
