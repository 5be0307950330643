//! Rough disks in the approximate schemes: the tangential part of each collision (Walton's
//! rule, [`physics::rough`](crate::physics::rough)), applied after the normal part at pair
//! collisions and at impacts on the floor, the side walls and the lid, as the exact engine
//! applies it, so that the schemes and the engine compare like with like. A smooth scene has
//! no laws here and no spins: every call returns 0 at once.

use crate::physics::disks::Disks;
use crate::physics::pair::Impulse;
use crate::physics::rough::{Boundary, Roughness};

/// The tangential laws of a scheme's scene (`None`: smooth disks).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Rub(Option<Roughness>);

impl Rub {
    /// The scene's laws (`None` for a smooth scene).
    pub(crate) fn new(laws: Option<Roughness>) -> Rub {
        Rub(laws)
    }

    /// The tangential part of the collision of disks `i` and `j` at time `now`, after the
    /// normal impulse `imp` (separation `(dx, dy)` from `j` to `i`, the centres' relative
    /// velocity `dv` before it): their velocities and spins change. Returns the kinetic energy
    /// lost (0 for smooth disks, at the cost of one test).
    #[inline(always)]
    pub(crate) fn pair(
        &self,
        disks: &mut Disks,
        (i, j): (usize, usize),
        (dx, dy): (f64, f64),
        dv: (f64, f64),
        imp: &Impulse,
        now: f64,
    ) -> f64 {
        match &self.0 {
            Some(laws) => rough_pair(laws, disks, (i, j), (dx, dy), dv, imp, now),
            None => 0.0,
        }
    }

    /// The tangential part of disk `i`'s impact at time `now` on `boundary`, moving with
    /// velocity `wall` (the floor's; 0 for the others), after the normal part changed the
    /// disk's velocity from `before`. Returns the kinetic energy lost (0 for smooth disks).
    #[inline(always)]
    pub(crate) fn boundary(
        &self,
        disks: &mut Disks,
        i: usize,
        boundary: Boundary,
        wall: (f64, f64),
        before: (f64, f64),
        now: f64,
    ) -> f64 {
        match &self.0 {
            Some(laws) => rough_boundary(laws, disks, i, boundary, (wall, before), now),
            None => 0.0,
        }
    }
}

/// [`Rub::pair`] for rough disks.
#[inline(never)]
fn rough_pair(
    laws: &Roughness,
    disks: &mut Disks,
    (i, j): (usize, usize),
    (dx, dy): (f64, f64),
    dv: (f64, f64),
    imp: &Impulse,
    now: f64,
) -> f64 {
    let n = (dx / imp.distance, dy / imp.distance);
    let k = laws.pair_kick(disks, (i, j), n, dv, imp.momentum);
    if k.j == 0.0 {
        return 0.0;
    }
    k.apply(disks, i, Some(j), now);
    k.energy_lost
}

/// [`Rub::boundary`] for rough disks.
#[inline(never)]
fn rough_boundary(
    laws: &Roughness,
    disks: &mut Disks,
    i: usize,
    boundary: Boundary,
    (wall, before): ((f64, f64), (f64, f64)),
    now: f64,
) -> f64 {
    let k = laws.boundary_kick(disks, i, boundary, wall, before);
    if k.j == 0.0 {
        return 0.0;
    }
    k.apply(disks, i, None, now);
    k.energy_lost
}
