//! Local re-mapping (`engine.remap = "local"`): a displacement budget per disk on Isobe's grid
//! and masks, so that no disk waits for the fastest one.
//!
//! Each disk has an *anchor*, where it was when its neighbour list was last built, and stays
//! within the shell radius `r` of it: before it could leave, an event of its own re-anchors it
//! and rebuilds its list alone. Two disks inside their shells are at least `|A_i − A_j| − 2r`
//! apart, so the pairs whose anchors are closer than `a_i + a_j + 2r` hold every pair that can
//! touch. The grid maps anchors. Anchors are pairwise at least `2 a_min − r` apart (when one is
//! set the other disk is within `r` of its own and the two do not overlap), so cells whose
//! diagonal is below `2 a_min − r` still hold at most one anchor each (EEPGM); the cells are
//! therefore smaller than Isobe's, and a mask of reach `D` cells gives `2r = D·l_g − 2 a_max`.
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

use super::clock::into_period;
use super::motion::wrap;
use super::Simulation;
use crate::dynamics::Flight;
use crate::error::Result;
use crate::globals::masks::TABLE_1;
use crate::globals::Mask;
use crate::locals::{SideBounds, Top};
use crate::scenario::MaskChoice;

/// Re-anchorings per disk between two whole re-mappings.
pub const REMAP_EVERY: u64 = 16;

/// Relative slack kept between the cell diagonal and the closest two anchors can be.
const CELL_SLACK: f64 = 1e-6;

/// A disk leaves its shell a hair inside the radius the lists assume.
const EXIT_SLACK: f64 = 1e-9;

/// The anchors and the shell radius.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct Shells {
    /// Shell radius r: how far a disk may move from its anchor.
    pub radius: f64,
    /// Room per neighbour list to start with ([`list_room`]).
    pub room: usize,
    /// Where each disk's list was built.
    anchor: Vec<[f64; 2]>,
    /// Re-anchorings since the last whole re-mapping.
    since_map: u64,
    /// Scratch: disks found in the mask.
    #[serde(skip)]
    found: Vec<u32>,
}

/// Cell side for a mask of reach `reach` (in cells) under the local re-mapping: the largest `l`
/// with `√2 l ≤ 2 a_min − r` where `2r = reach·l − 2 a_max`.
fn cell_for(reach: f64, a_min: f64, a_max: f64) -> f64 {
    (2.0 * a_min + a_max) / (std::f64::consts::SQRT_2 + 0.5 * reach) * (1.0 - CELL_SLACK)
}

/// The mask and cell side the local re-mapping uses for disks of radii `a_min..a_max` at
/// packing `phi`, with the shell radius they give. `Auto` takes R5 below φ = 0.2, R4 below
/// 0.45, R3 above (the first that gives a shell of at least 0.3 a_min); a named mask is refused
/// (`None`) if it gives no shell at all.
pub fn local_grid(
    choice: MaskChoice,
    a_min: f64,
    a_max: f64,
    phi: f64,
) -> Option<(Mask, f64, f64)> {
    let shell = |m: &Mask| {
        let l = cell_for(m.reach(), a_min, a_max);
        (l, 0.5 * (m.reach() * l - 2.0 * a_max))
    };
    let Some(index) = Mask::table_index(choice) else {
        let preferred = if phi < 0.2 {
            3
        } else if phi < 0.45 {
            2
        } else {
            1
        };
        return (preferred..TABLE_1.len()).map(Mask::table).find_map(|m| {
            let (l, r) = shell(&m);
            (r >= 0.3 * a_min).then_some((m, l, r))
        });
    };
    let m = Mask::table(index);
    let (l, r) = shell(&m);
    (r > 0.0).then_some((m, l, r))
}

/// Room per list: how many anchors pairwise `2 a_min − r` apart fit within `2 a_max + 2r` of
/// another (an area bound), and never more than the mask has cells.
pub fn list_room(a_min: f64, a_max: f64, r: f64, mask_cells: usize) -> usize {
    let half_gap = 0.5 * (2.0 * a_min - r);
    let reach = 2.0 * a_max + 2.0 * r;
    let bound = ((reach + half_gap) / half_gap).powi(2) - 1.0;
    (bound.floor() as usize).min(mask_cells).max(1)
}

impl Shells {
    /// Shells of radius `r` for `n` disks (anchored at the first mapping), with lists of
    /// `room` entries to start with.
    pub fn new(n: usize, r: f64, room: usize) -> Shells {
        Shells {
            radius: r,
            room,
            anchor: vec![[0.0; 2]; n],
            since_map: 0,
            found: Vec::new(),
        }
    }

    /// Number of disks.
    pub fn len(&self) -> usize {
        self.anchor.len()
    }

    /// `true` without disks.
    pub fn is_empty(&self) -> bool {
        self.anchor.is_empty()
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
    pub(super) fn shell_exit(&self, i: usize, (x, y, vx, vy): (f64, f64, f64, f64)) -> f64 {
        let Some(sh) = &self.shells else {
            return f64::INFINITY;
        };
        let now = self.now;
        let [ax, ay] = sh.anchor[i];
        let (dx, dy) = self.wrap(x - ax, y - ay);
        let rho = sh.radius * (1.0 - EXIT_SLACK);
        if self.is_riding(i) {
            // Sliding at vx, carried up and down by the floor (within its span, at its speed).
            let (span, lift) = self.floor.as_ref().map_or((0.0, 0.0), |f| f.ride_bounds());
            let room = rho - dx.abs() - dy.abs();
            if room <= 0.0 {
                return now;
            }
            let slide = vx.abs();
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

    /// Disk `i` reaches the edge of its shell: it is anchored where it is, moved in the grid,
    /// and its list alone is rebuilt; then it is re-predicted.
    pub(super) fn leave_shell(&mut self, i: usize) -> Result<()> {
        let now = self.now;
        self.bring(i, now);
        self.wrap_position(i);
        let m = self.disks.motion[i];
        let Some(sh) = self.shells.as_mut() else {
            return Ok(());
        };
        let [ox, oy] = sh.anchor[i];
        sh.anchor[i] = [m.x, m.y];
        sh.since_map += 1;
        let due = sh.since_map >= REMAP_EVERY * sh.anchor.len() as u64;
        self.counts.shell += 1;
        let from = self.geometry.cell_of(ox, oy);
        let to = self.geometry.cell_of(m.x, m.y);
        if from != to && !self.cells.relocate(&self.geometry, from, to, i as u32)? {
            // The grid's storage is full where the disk goes: re-map everything now.
            return self.remap();
        }
        self.relist(i, to);
        if due {
            self.dutc.deadline = now;
        }
        self.predict(i);
        Ok(())
    }

    /// Rebuilds disk `i`'s list from the anchors in the mask around its cell `cell`.
    fn relist(&mut self, i: usize, cell: (u32, u32)) {
        let Some(sh) = self.shells.as_mut() else {
            return;
        };
        let (anchor, found) = (&sh.anchor, &mut sh.found);
        found.clear();
        self.cells.gather(&self.geometry, &self.mask, cell, |j| {
            if j as usize != i {
                found.push(j)
            }
        });
        let [xi, yi] = anchor[i];
        let ai = self.disks.radius[i];
        found.retain(|&j| {
            let [xj, yj] = anchor[j as usize];
            let (dx, dy) = wrap(self.sides, self.top, xi - xj, yi - yj);
            let reach = ai + self.disks.radius[j as usize] + self.margin;
            dx * dx + dy * dy <= reach * reach
        });
        self.lists.replace(i, found);
    }

    /// At a whole re-mapping: every disk is anchored where it is.
    pub(super) fn anchor_all(&mut self) {
        let Some(sh) = self.shells.as_mut() else {
            return;
        };
        for (a, m) in sh.anchor.iter_mut().zip(&self.disks.motion) {
            *a = [m.x, m.y];
        }
        sh.since_map = 0;
    }

    /// Puts disk `i`'s position back in the period where the sides or the top are periodic.
    pub(super) fn wrap_position(&mut self, i: usize) {
        let m = &mut self.disks.motion[i];
        if let SideBounds::Periodic { width } = self.sides {
            m.x = into_period(m.x, width);
        }
        if let Top::Periodic { height } = self.top {
            m.y = into_period(m.y, height);
        }
    }
}
