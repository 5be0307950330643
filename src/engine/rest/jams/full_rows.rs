//! **Full rows** from wall to wall with no play but round-off, ringing sideways between the
//! walls for ever under a cure: a row of flying disks **seated on a row at rest**, each a hair
//! from the top of the disk below, comes to rest on it (`seat_row`); and **a full row on the
//! floor** stops (`stop_floor_row`).

use super::*;
use crate::engine::rest::riders::NO_DISK;
use crate::engine::Simulation;
use crate::physics::flight::Flight;
use crate::physics::walls::SideBounds;

impl<F: Flight> Simulation<F> {
    /// Disks `i` and `j` (brought to now, `(dx, dy)` from `j` to `i`; `rode`: whether each
    /// rode) collide. Under the resting contacts, two disks riding on the floor that meet side by
    /// side ([`side_by_side`]) may belong to a full row on the floor
    /// ([`stop_floor_row`](Self::stop_floor_row)), and two flying disks that meet side by side
    /// among disks at rest to a full row seated on a row at rest ([`seat_row`](Self::seat_row)).
    /// Whether a row stopped or sat (the collision is then done).
    #[inline]
    pub(in crate::engine) fn full_row_takes(
        &mut self,
        i: usize,
        j: usize,
        rode: [bool; 2],
        (dx, dy): (f64, f64),
    ) -> bool {
        if !(self.rest.resting_contacts && side_by_side(dx, dy)) {
            return false;
        }
        match rode {
            [true, true] => {
                self.rest.riders.on_floor(i)
                    && self.rest.riders.on_floor(j)
                    && self.stop_floor_row(i, j)
            }
            [false, false] => self.rest.riders.any() && self.seat_row(i, j),
            _ => false,
        }
    }

    /// Flying disks `i` and `j` (brought to now) meet side by side. If they belong to a *full
    /// row seated on a row at rest* — disks side by side from side wall to side wall (or round
    /// the periodic sides), each at rest (not sliding, on one support) or flying within [`ROOM`]
    /// radii sideways and [`WEDGE_DROP`] radii up from the top of a disk at rest, not sliding,
    /// straight below it — the row comes to rest seated: each flying disk on the top of its
    /// seat, its kinetic energy relative to the seat and the potential energy of the hair it
    /// drops booked as dissipated. Returns whether it did (the collision is then done).
    ///
    /// Such a row has no room sideways but round-off: its disks ring between each other and the
    /// walls in gaps of 10⁻⁶ radii, and under a cure every such collision is elastic, so the row
    /// never slows; a disk a hair out of line stands a few milliradians up on its neighbour and
    /// turns the bouncing of the rows above into sideways motion (the exact jam). Without a
    /// cure the sideways motion would collapse inelastically, in infinitely many collisions, to
    /// the row at rest on its seats: the rule goes there at once.
    pub(in crate::engine) fn seat_row(&mut self, i: usize, j: usize) -> bool {
        // Most flat collisions are of disks with no seat: the row is not walked for them.
        if self.seat_of(i).is_none() || self.seat_of(j).is_none() {
            return false;
        }
        let now = self.now;
        let (h, hd) = self.floor_now();
        let mut row = std::mem::take(&mut self.rest.cluster);
        let mut seats = Vec::new();
        let ok = self.full_row(i, j, &mut row)
            && row.iter().all(|&m| match self.seat_of(m as usize) {
                Some(seat) => {
                    seats.push(seat);
                    true
                }
                None => false,
            })
            && self.seats_hold(&row, &seats);
        if ok {
            self.tally.jams.seated_row += 1;
            // Two seated disks may close in by both their moves: the margin is charged the sum.
            let mut moved = 0.0;
            for (&m, &(seat, x, y)) in row.iter().zip(&seats) {
                let m = m as usize;
                if self.is_riding(m) {
                    continue;
                }
                self.bring(m, now);
                let mass = self.disks.mass[m];
                let (x0, y0) = (self.disks.motion[m].x, self.disks.motion[m].y);
                self.tally.flow.dissipated += mass * self.flight.g() * (y0 - y);
                self.take_velocity(m, (0.0, hd));
                self.disks.motion[m].x = x;
                self.disks.motion[m].y = y;
                self.wrap_position(m);
                moved += (x - x0).hypot(y - y0);
                if self
                    .rest
                    .riders
                    .mount_on_disks(m, y - h, [seat, NO_DISK], self.time())
                {
                    self.tally.counts.rest += 1;
                }
            }
            self.map.dutc.displaced(now, moved);
            self.tally.counts.pair += 1;
            for &m in &row {
                self.moved(m as usize);
            }
        }
        row.clear();
        self.rest.cluster = row;
        ok
    }

    /// Disks `i` and `j` (brought to now), both riding on the floor, meet side by side. If they
    /// belong to a *full row on the floor* — disks side by side from side wall to side wall
    /// (or round the periodic sides), no gap between neighbours or at a wall wider than
    /// [`ROOM`] radii, each on the floor or flying within [`WEDGE_DROP`] radii above it
    /// (wedged a hair high) — the row stops: every disk takes the floor's velocity, its kinetic energy relative to the
    /// floor booked as dissipated. Returns whether it did (the collision is then done).
    ///
    /// Such a row has no room but round-off (the exact jam): its disks ring between each
    /// other and the walls, every collision elastic under a cure; without one the sideways
    /// motion would collapse inelastically to the row at rest.
    pub(in crate::engine) fn stop_floor_row(&mut self, i: usize, j: usize) -> bool {
        let now = self.now;
        let (h, hd) = self.floor_now();
        let mut row = std::mem::take(&mut self.rest.cluster);
        let ok = self.full_row(i, j, &mut row)
            && row.iter().all(|&m| {
                let m = m as usize;
                if self.is_riding(m) {
                    return self.rest.riders.on_floor(m);
                }
                let (_, y, _, _) = self.state_at(m, now);
                let a = self.disks.radius[m];
                y - a - h <= WEDGE_DROP * a
            });
        if ok {
            self.tally.jams.floor_row += 1;
            for &m in &row {
                let m = m as usize;
                self.bring(m, now);
                self.take_velocity(m, (0.0, hd));
            }
            self.tally.counts.pair += 1;
            for &m in &row {
                let m = m as usize;
                self.moved(m);
                if self.is_riding(m) {
                    self.release_carried(m, None);
                }
            }
        }
        row.clear();
        self.rest.cluster = row;
        ok
    }

    /// Puts in `row` (cleared first) the row through disks `i` and `j` (side by side, at now):
    /// the disks side by side with them leftwards, then rightwards; `true` if it reaches from
    /// side wall to side wall (or round the periodic sides). See [`row_from`](Self::row_from).
    pub(in crate::engine) fn full_row(&self, i: usize, j: usize, row: &mut Vec<u32>) -> bool {
        let now = self.now;
        let (xi, _, _, _) = self.state_at(i, now);
        let (xj, _, _, _) = self.state_at(j, now);
        let (left, right) = if self.wrap(xj - xi, 0.0).0 > 0.0 {
            (i, j)
        } else {
            (j, i)
        };
        row.clear();
        self.row_from(left, -1.0, row) && self.row_from(right, 1.0, row)
    }

    /// Adds to `row` disk `start` and the disks side by side with it in direction `dir` (±1),
    /// up to a side wall; `true` if the chain reaches the wall (or comes round to a disk already
    /// in `row`, where the sides are periodic).
    pub(in crate::engine) fn row_from(&self, start: usize, dir: f64, row: &mut Vec<u32>) -> bool {
        let now = self.now;
        let mut cur = start;
        for _ in 0..ROOM_ROW {
            if row.contains(&(cur as u32)) {
                return matches!(self.bounds.sides, SideBounds::Periodic { .. });
            }
            row.push(cur as u32);
            let (x, y, _, _) = self.state_at(cur, now);
            let a = self.disks.radius[cur];
            if (self.bounds.sides)
                .gap_to_wall(x, a, dir)
                .is_some_and(|gap| gap <= ROOM * a)
            {
                return true;
            }
            let next = self
                .map
                .lists
                .of(cur)
                .iter()
                .map(|&c| c as usize)
                .find(|&c| {
                    let (xc, yc, _, _) = self.state_at(c, now);
                    let (dx, dy) = self.wrap(xc - x, yc - y);
                    let reach = a + self.disks.radius[c];
                    dx * dir > 0.0 && dx.abs() - reach <= ROOM * a && dy.abs() <= WEDGE_DROP * a
                });
            match next {
                Some(c) => cur = c,
                None => return false,
            }
        }
        false
    }

    /// The seat of disk `m` (at now), and where `m` sits on it: a disk at rest, not sliding,
    /// straight below it to within [`ROOM`] radii sideways, whose top is at most
    /// [`WEDGE_DROP`] radii below `m`'s bottom. A disk at rest on one disk, not sliding, is
    /// seated where it is.
    pub(in crate::engine) fn seat_of(&self, m: usize) -> Option<(u32, f64, f64)> {
        let now = self.now;
        let (x, y, _, _) = self.state_at(m, now);
        if self.is_riding(m) {
            let [s, other] = self.rest.riders.supports(m);
            return (self.disks.motion[m].vx == 0.0 && s != NO_DISK && other == NO_DISK)
                .then_some((s, x, y));
        }
        let a = self.disks.radius[m];
        self.map.lists.of(m).iter().find_map(|&c| {
            let c = c as usize;
            if !self.is_riding(c)
                || self.disks.motion[c].vx != 0.0
                || self.rest.riders.slide(c).is_some()
            {
                return None;
            }
            let (xc, yc, _, _) = self.state_at(c, now);
            let (dx, dy) = self.wrap(x - xc, y - yc);
            let reach = a + self.disks.radius[c];
            let above = dy - reach;
            (dx.abs() <= ROOM * a && above <= WEDGE_DROP * a && above >= -ROOM * a).then_some((
                c as u32,
                x - dx,
                y - above,
            ))
        })
    }

    /// Whether the row's disks, each on its seat, overlap nothing: the side walls, each other,
    /// or any other disk near them (round-off aside).
    pub(in crate::engine) fn seats_hold(&self, row: &[u32], seats: &[(u32, f64, f64)]) -> bool {
        let now = self.now;
        let place = |m: usize| {
            row.iter()
                .position(|&r| r as usize == m)
                .map(|k| (seats[k].1, seats[k].2))
        };
        row.iter().zip(seats).all(|(&m, &(seat, x, y))| {
            let m = m as usize;
            let a = self.disks.radius[m];
            if let SideBounds::Walls { width, .. } = self.bounds.sides {
                if x - a < -TIGHT * a || width - x - a < -TIGHT * a {
                    return false;
                }
            }
            self.map.lists.of(m).iter().all(|&c| {
                let c = c as usize;
                if c == seat as usize {
                    return true;
                }
                let (xc, yc) = place(c).unwrap_or_else(|| {
                    let (xc, yc, _, _) = self.state_at(c, now);
                    (xc, yc)
                });
                let (dx, dy) = self.wrap(x - xc, y - yc);
                let reach = a + self.disks.radius[c];
                dx * dx + dy * dy >= reach * reach * (1.0 - 2.0 * TIGHT)
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::jams_in;

    /// A full row of flying disks a hair above a row at rest, wall to wall, comes to rest on it.
    #[test]
    fn a_full_row_ringing_on_a_row_at_rest_is_seated() {
        assert!(jams_in("row_ringing_on_a_row_at_rest.json", &[]).seated_row > 0);
    }

    /// A bed poured between walls exactly three diameters apart leaves a full row on the floor,
    /// ringing sideways with no play but round-off: it stops.
    #[test]
    fn a_full_row_on_the_floor_stops() {
        let jams = jams_in("bed_at_rest_tc.json", &["domain.width=3", "seed=4"]);
        assert!(jams.floor_row > 0);
    }
}
