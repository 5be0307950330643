//! Local re-mapping (`engine.remap = "local"`): a displacement budget per disk, so that no disk
//! waits for the fastest one (the per-disk neighbour lists of the fastest public codes).
//!
//! Each disk has an *anchor*, where it was when its neighbour list was last built, and stays
//! within the shell radius `r` of it: before it could leave, an event of its own re-anchors it
//! and rebuilds its list alone. Two disks inside their shells are at least `|A_i − A_j| − 2r`
//! apart, so the pairs whose anchors are closer than `a_i + a_j + 2r` hold every pair that can
//! touch. The grid maps anchors. Shells are wide (about a diameter at φ = 0.3, half of one at
//! φ = 0.7: see [`local_margin`]), so anchors may lie closer than disks can, and a cell holds
//! several (linked cells; Isobe's hashed array, several entries per cell, under an open top).
//! Cells are at least `2 a_max + 2r` wide, so the 3 × 3 block around a disk's cell
//! ([`block_mask`]) holds every anchor its list can need.
//!
//! A re-anchoring changes no velocity: the predictions of other disks stay valid, and a pair
//! that enters the lists is found by the re-anchored disk's own prediction.
//!
//! The whole grid is still re-mapped now and then (after as many re-anchorings as there are
//! disks times [`REMAP_EVERY`], or at 64 times the published DUTC deadline), only to re-base the
//! clock and pack the storage; correctness never depends on it.
//!
//! Exit times: exact for a straight flight (no gravity); under gravity a flight's displacement
//! is bounded by its straight part plus `½ g τ²`, and a disk riding the floor by its sliding plus
//! the floor's travel, so the event comes a little early, never late.

use crate::engine::Simulation;
use crate::error::Result;
use crate::neighbours::Mask;
use crate::physics::flight::Flight;
use crate::physics::theory::mean_free_path;
use crate::physics::walls::into_period;
use crate::physics::walls::{SideBounds, Top};

/// Re-anchorings per disk between two whole re-mappings.
pub const REMAP_EVERY: u64 = 16;

/// A disk leaves its shell a hair inside the radius the lists assume.
const EXIT_SLACK: f64 = 1e-9;

/// The anchors and the shell radius.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct Shells {
    /// Shell radius r: how far a disk may move from its anchor.
    pub radius: f64,
    /// How far ahead of a disk leaving its shell, along its velocity, its new anchor goes (see
    /// [`anchor_ahead`]).
    ahead: f64,
    /// Where each disk's list was built.
    anchor: Vec<[f64; 2]>,
    /// Re-anchorings since the last whole re-mapping.
    since_map: u64,
    /// Scratch: disks found in the mask.
    #[serde(skip)]
    found: Vec<u32>,
}

/// The mask of the local re-mapping: the 3 × 3 block of cells around a disk's cell (reach one
/// cell), on cells at least as wide as the longest listed pair.
pub fn block_mask() -> Mask {
    Mask::circle("B1", 2)
}

/// Neighbour-list margin `m` of the local re-mapping (pairs are listed while their anchors are
/// closer than `a_i + a_j + m`, and each shell has radius `m/2`), for `n` disks of root mean
/// square radius `a` at packing `phi`: `skin · a_min` if a skin is set, otherwise a list reach
/// of `s · 2a` with `s² = 1 + k/(π n σ²)`, about `k` neighbours beyond contact
/// ([`beyond_contact`]; `π n σ² = 4φ` with `σ = 2a`): s = 2.77 at φ = 0.3 (k = 8), 1.77 at
/// φ = 0.7 (k = 6).
pub fn local_margin(skin: Option<f64>, a_min: f64, a: f64, phi: f64, n: usize) -> f64 {
    match skin {
        Some(skin) => skin * a_min,
        None => {
            let phi = phi.max(1e-3);
            let s = (1.0 + beyond_contact(phi, n) / (4.0 * phi)).sqrt();
            (s - 1.0) * 2.0 * a
        }
    }
}

/// From this many disks on, the lists are sized for memory: six neighbours beyond contact at
/// every packing (see [`beyond_contact`]), and a mapping gathers each disk's pairs again for its
/// predictions rather than keep them beside the new lists.
pub const LEAN_LISTS_FROM: usize = 1 << 18;

/// How many neighbours beyond contact the lists of `n` disks at packing `phi` are sized for:
/// longer lists mean fewer shell exits but longer predictions. Eight up to φ = 0.4, falling
/// to six at φ = 0.6 and above (chosen by measurement); six from [`LEAN_LISTS_FROM`] disks on, at every packing, where the longer lists
/// would still be a little faster but memory is what limits a run.
pub fn beyond_contact(phi: f64, n: usize) -> f64 {
    if n >= LEAN_LISTS_FROM {
        return 6.0;
    }
    let dense = ((phi - 0.4) / 0.2).clamp(0.0, 1.0);
    8.0 - 2.0 * dense
}

/// How far ahead of a disk leaving its shell (along its velocity) its new anchor goes, for
/// shells of radius `r` and disks of root mean square radius `a` at packing `phi` with no
/// gravity: a disk that leaves its shell is mostly in flight, and flies on about a mean free
/// path λ; anchored ahead of itself it can fly on farther before it leaves again. Where λ is
/// short (dense gases) the next collision turns it back: the shift is `min(r/2, 0.7 λ)`, and
/// none where that is less than `r/4` (a disk rattling in its cage gains nothing; from
/// φ ≈ 0.5 on). The shift saves shell exits in dilute gases; in dense ones a longer shift
/// would only cost (chosen by measurement).
/// Under gravity, 0 (flights bend, beds rattle).
pub fn anchor_ahead(r: f64, a: f64, phi: f64, gravity: bool) -> f64 {
    let ahead = (0.5 * r).min(0.7 * mean_free_path(a, phi));
    if gravity || ahead < 0.25 * r {
        0.0
    } else {
        ahead
    }
}

/// Packing of a settled bed: what a bed on a floor under gravity compacts to, whatever its
/// initial placement.
pub const SETTLED_BED_PACKING: f64 = 0.7;

/// The packing the shells are sized for: the scene's, or with a floor at least a settled bed's
/// ([`SETTLED_BED_PACKING`]): a bed spends its run settled, and shells sized for a looser
/// initial placement would be too wide for it, its lists too long.
pub fn packing_for_shells(packing: f64, floor: bool) -> f64 {
    if floor {
        packing.max(SETTLED_BED_PACKING)
    } else {
        packing
    }
}

impl Shells {
    /// Shells of radius `r` for `n` disks (anchored at the first mapping), re-anchored
    /// `ahead` ahead of a disk that leaves its shell.
    pub fn new(n: usize, r: f64, ahead: f64) -> Shells {
        Shells {
            radius: r,
            ahead: ahead.clamp(0.0, r),
            anchor: vec![[0.0; 2]; n],
            since_map: 0,
            found: Vec::new(),
        }
    }

    /// A disk enters as the last one, anchored where it is.
    pub fn push(&mut self, at: [f64; 2]) {
        self.anchor.push(at);
    }

    /// Disk `k` leaves, the last disk taking its number.
    pub fn swap_remove(&mut self, k: usize) {
        self.anchor.swap_remove(k);
    }

    /// Number of disks.
    pub fn len(&self) -> usize {
        self.anchor.len()
    }

    /// Bytes held (the anchors).
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<[f64; 2]>() * self.anchor.capacity()
    }

    /// `true` without disks.
    pub fn is_empty(&self) -> bool {
        self.anchor.is_empty()
    }

    /// Disk `i`'s anchor.
    #[inline(always)]
    pub fn anchor(&self, i: usize) -> [f64; 2] {
        self.anchor[i]
    }

    /// Hints that disk `i`'s anchor will be read soon.
    #[inline(always)]
    pub fn prefetch(&self, i: usize) {
        crate::platform::prefetch::prefetch(&self.anchor, i);
    }
}

/// First time τ ≥ 0 at which `|d + v τ| = rho`, for `|d| < rho` (∞ if `v = 0`).
#[inline]
fn leave_circle(dx: f64, dy: f64, vx: f64, vy: f64, rho: f64) -> f64 {
    let room = rho * rho - (dx * dx + dy * dy);
    if room <= 0.0 {
        return 0.0;
    }
    let b = dx * vx + dy * vy;
    let v2 = vx * vx + vy * vy;
    // The positive root of v² τ² + 2 b τ − room = 0, in the form without cancellation.
    room / (b + (b * b + v2 * room).sqrt())
}

impl<F: Flight> Simulation<F> {
    /// Local time by which disk `i`, now at `(x, y)` moving at `(vx, vy)`, could leave its
    /// shell; `now` if it is at the edge already.
    pub(in crate::engine) fn shell_exit(
        &self,
        i: usize,
        (x, y, vx, vy): (f64, f64, f64, f64),
    ) -> f64 {
        let Some(sh) = &self.map.shells else {
            return f64::INFINITY;
        };
        let now = self.now;
        let [ax, ay] = sh.anchor[i];
        let (dx, dy) = self.wrap(x - ax, y - ay);
        let rho = sh.radius * (1.0 - EXIT_SLACK);
        if self.is_riding(i) {
            // Sliding at vx, carried up and down by the floor (within its span, at its speed).
            let (span, lift) = self
                .bounds
                .floor
                .as_ref()
                .map_or((0.0, 0.0), |f| f.ride_bounds());
            let room = rho - dx.abs() - dy.abs();
            if room <= 0.0 {
                return now;
            }
            let slide = self.riding_speed_bound(i, vx);
            let by_speed = room / (slide + lift);
            let by_span = if room > span {
                (room - span) / slide
            } else {
                0.0
            };
            return now + by_speed.max(by_span);
        }
        let g = self.flight.g();
        let straight = leave_circle(dx, dy, vx, vy, rho);
        if g == 0.0 {
            return now + straight;
        }
        // |d + v τ − ½ g τ² ŷ| ≤ |d + v τ| + ½ g τ²: (a) before the straight exit, the fall is
        // at most ½ g τ_s², so the straight part may use the rest; (b) |d| + |v| τ + ½ g τ².
        let fall = 0.5 * g * straight * straight;
        let a = if fall < rho {
            leave_circle(dx, dy, vx, vy, rho - fall)
        } else {
            0.0
        };
        let rest = rho - (dx * dx + dy * dy).sqrt();
        let b = if rest > 0.0 {
            let v = (vx * vx + vy * vy).sqrt();
            2.0 * rest / (v + (v * v + 2.0 * g * rest).sqrt())
        } else {
            0.0
        };
        now + a.max(b)
    }

    /// Disk `i` reaches the edge of its shell: it is anchored anew (where it is, or a little
    /// ahead of it: [`anchor_ahead`]), moved in the grid, and its list alone is rebuilt; then it
    /// is re-predicted.
    pub(in crate::engine) fn leave_shell(&mut self, i: usize) -> Result<()> {
        let now = self.now;
        if self.control.prefetching {
            self.map.lists.prefetch_neighbours(i);
        }
        self.bring(i, now);
        self.wrap_position(i);
        let m = self.disks.motion[i];
        let Some(ahead) = self.map.shells.as_ref().map(|sh| sh.ahead) else {
            return Ok(());
        };
        let a = self.anchor_for(m, ahead);
        let Some(sh) = self.map.shells.as_mut() else {
            return Ok(());
        };
        let [ox, oy] = sh.anchor[i];
        sh.anchor[i] = a;
        sh.since_map += 1;
        let due = sh.since_map >= REMAP_EVERY * sh.anchor.len() as u64
            || self
                .map
                .numbering
                .due(self.tally.counts.pair, sh.anchor.len());
        self.tally.counts.shell += 1;
        let from = self.map.geometry.cell_of(ox, oy);
        let to = self.map.geometry.cell_of(a[0], a[1]);
        if from != to
            && !self.map.cells.relocate(
                &self.map.geometry,
                from,
                to,
                i as u32,
                self.control.lanes,
            )?
        {
            // The grid's storage is full where the disk goes: re-map everything now.
            return self.remap();
        }
        let found = self.relist(i, to);
        if due {
            self.map.dutc.deadline = now;
        }
        match found {
            Some(found) => self.file_found(i, found),
            None => self.predict(i),
        }
        Ok(())
    }

    /// Where a disk in motion `m` (at now, in the period) is anchored when it leaves its shell:
    /// `ahead` ahead of it along its velocity (see [`anchor_ahead`]), if that point is inside
    /// the box (or brought into the period); where it is otherwise. Any anchor within the shell
    /// radius of the disk keeps the lists complete.
    fn anchor_for(&self, m: crate::physics::disks::Motion, ahead: f64) -> [f64; 2] {
        let v = (m.vx * m.vx + m.vy * m.vy).sqrt();
        if ahead <= 0.0 || v == 0.0 {
            return [m.x, m.y];
        }
        let k = ahead / v;
        let (mut x, mut y) = (m.x + k * m.vx, m.y + k * m.vy);
        let mut inside = true;
        match self.bounds.sides {
            SideBounds::Periodic { width } => x = into_period(x, width),
            SideBounds::Walls { width, .. } => inside &= (0.0..=width).contains(&x),
        }
        match self.bounds.top {
            Top::Periodic { height } => y = into_period(y, height),
            Top::Lid { height, .. } => inside &= (0.0..=height).contains(&y),
            Top::Open => inside = false,
        }
        if inside {
            [x, y]
        } else {
            [m.x, m.y]
        }
    }

    /// Rebuilds disk `i`'s list from the anchors in the mask around its cell `cell`. Where no
    /// disk rides, `i`'s earliest pair contact is searched on the new list before the lists are
    /// changed (the processor overlaps the search's square roots and divisions with the lists'
    /// changes, which it does not read) and returned; otherwise `None` (the prediction needs
    /// the stored lists).
    fn relist(&mut self, i: usize, cell: (u32, u32)) -> Option<(f64, u32, f64)> {
        let hint = self.control.prefetching;
        let sh = self.map.shells.as_mut()?;
        let (anchor, found) = (&sh.anchor, &mut sh.found);
        let n = self
            .map
            .cells
            .gather_into(&self.map.geometry, &self.map.mask, cell, found);
        if hint {
            // Read just below.
            for &j in &found[..n] {
                crate::platform::prefetch::prefetch(anchor, j as usize);
            }
        }
        let reach = self.disks.radius[i] + self.map.margin;
        let radius = &self.disks.radius;
        let kept = crate::engine::images::within_reach(
            self.control.lanes,
            found,
            n,
            i,
            reach,
            anchor,
            radius,
            &self.bounds.images,
        );
        let new = &self.map.shells.as_ref()?.found[..kept];
        let contact =
            (!self.rest.riders.any()).then(|| self.pair_event_over(i, new, self.pair_horizon()));
        self.map.lists.replace(i, new, self.control.lanes);
        contact
    }

    /// At a whole re-mapping: every disk is anchored where it is.
    pub(in crate::engine) fn anchor_all(&mut self) {
        let Some(sh) = self.map.shells.as_mut() else {
            return;
        };
        for (a, m) in sh.anchor.iter_mut().zip(&self.disks.motion) {
            *a = [m.x, m.y];
        }
        sh.since_map = 0;
    }

    /// Puts disk `i`'s position back in the period where the sides or the top are periodic.
    pub(in crate::engine) fn wrap_position(&mut self, i: usize) {
        let m = &mut self.disks.motion[i];
        if let SideBounds::Periodic { width } = self.bounds.sides {
            m.x = into_period(m.x, width);
        }
        if let Top::Periodic { height } = self.bounds.top {
            m.y = into_period(m.y, height);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_hold_eight_neighbours_beyond_contact_in_dilute_gases_six_in_dense_or_large_ones() {
        assert_eq!(beyond_contact(0.1, 2500), 8.0);
        assert_eq!(beyond_contact(0.4, 2500), 8.0);
        assert!((beyond_contact(0.5, 2500) - 7.0).abs() < 1e-12);
        assert_eq!(beyond_contact(0.6, 2500), 6.0);
        assert_eq!(beyond_contact(0.7, 2500), 6.0);
        assert_eq!(beyond_contact(0.3, LEAN_LISTS_FROM - 1), 8.0);
        assert_eq!(beyond_contact(0.3, LEAN_LISTS_FROM), 6.0);
        // s² = 1 + k/(4φ): list reach s·2a = 2.77 diameters at φ = 0.3 (eight), 1.77 at 0.7.
        let reach = |phi: f64, n: usize| 1.0 + local_margin(None, 0.5, 0.5, phi, n);
        assert!((reach(0.3, 2500) - (1.0f64 + 8.0 / 1.2).sqrt()).abs() < 1e-12);
        assert!((reach(0.3, 1 << 20) - (1.0f64 + 6.0 / 1.2).sqrt()).abs() < 1e-12);
        assert!((reach(0.7, 2500) - (1.0f64 + 6.0 / 2.8).sqrt()).abs() < 1e-12);
        assert_eq!(
            local_margin(Some(3.0), 0.5, 0.5, 0.3, 2500),
            1.5,
            "a skin overrides"
        );
    }

    #[test]
    fn disks_are_anchored_ahead_only_in_dilute_gases_without_gravity() {
        let r = |phi: f64| 0.5 * local_margin(None, 0.5, 0.5, phi, 2500);
        // Dilute: half the shell radius ahead.
        assert_eq!(anchor_ahead(r(0.2), 0.5, 0.2, false), 0.5 * r(0.2));
        assert_eq!(anchor_ahead(r(0.1), 0.5, 0.1, false), 0.5 * r(0.1));
        // Between: 0.7 λ; dense (a quarter of the shell or less): none; gravity: none.
        for phi in [0.3, 0.45] {
            let mid = anchor_ahead(r(phi), 0.5, phi, false);
            assert!((mid - 0.7 * mean_free_path(0.5, phi)).abs() < 1e-15);
            assert!(mid > 0.25 * r(phi) && mid < 0.5 * r(phi));
        }
        assert_eq!(anchor_ahead(r(0.55), 0.5, 0.55, false), 0.0);
        assert_eq!(anchor_ahead(r(0.7), 0.5, 0.7, false), 0.0);
        assert_eq!(anchor_ahead(r(0.3), 0.5, 0.3, true), 0.0);
    }
}
