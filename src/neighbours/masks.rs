//! Isobe's masks: the cells searched around a disk's cell.
//!
//! A mask holds the cells whose centres lie within a circle around the centre cell's centre
//! (offsets `i² + j² ≤ c`). Any disk outside the mask is then at least `D·l_g` from the centre
//! disk, where `D` is the smallest gap between the centre cell and a cell outside the mask —
//! what DUTC needs. With `c` = 8, 10, 20, 29, 41, 53, 72, 90, 109 this reproduces Isobe's masks
//! and his Table 1 distances exactly (MIN: 24 cells and D = 2, R3: 36 and √5, …, R10: 348 and
//! √85); the tests check both.

use crate::scenario::MaskChoice;

/// One mask: its offsets and the guaranteed distance to its outside.
#[derive(Debug, Clone, PartialEq)]
pub struct Mask {
    /// Name in Isobe's paper (`MIN`, `R3`, …).
    pub name: &'static str,
    /// `(dx, dy)` cell offsets, centre excluded, in row-major order.
    pub offsets: Vec<(i32, i32)>,
    /// The offsets "after" the centre (`dy > 0`, or `dy = 0` and `dx > 0`): one of each pair
    /// of opposite offsets, so that scanning them finds every pair of disks once.
    pub half: Vec<(i32, i32)>,
    /// Squared minimum distance (in cell sides) from the centre cell to any cell outside.
    pub reach_sq: u32,
    /// Largest |dx| or |dy| in the mask.
    pub half_width: i32,
    /// The mask row by row, centre cell included: `(dy, dx_first, dx_last)` (a circle's rows
    /// are contiguous), for scans that read whole rows of a dense grid.
    pub rows: Vec<(i32, i32, i32)>,
    /// [`half`](Self::half) row by row, in the same order.
    pub half_rows: Vec<(i32, i32, i32)>,
}

/// Isobe's Table 1: name, squared minimum distance to the outside, number of cells.
pub const TABLE_1: [(&str, u32, usize); 9] = [
    ("MIN", 4, 24),
    ("R3", 5, 36),
    ("R4", 13, 68),
    ("R5", 18, 96),
    ("R6", 29, 136),
    ("R7", 40, 176),
    ("R8", 52, 224),
    ("R9", 72, 292),
    ("R10", 85, 348),
];

/// Squared centre-distance bound `c` of each mask of [`TABLE_1`] (offsets with `i² + j² ≤ c`).
const CIRCLE: [i32; 9] = [8, 10, 20, 29, 41, 53, 72, 90, 109];

/// Squared gap (in cell sides) between the centre cell and the cell at offset `(dx, dy)`.
fn gap_sq(dx: i32, dy: i32) -> u32 {
    let gap = |d: i32| (d.abs() - 1).max(0) as u32;
    gap(dx).pow(2) + gap(dy).pow(2)
}

impl Mask {
    /// Builds the mask of the cells at offsets `i² + j² ≤ circle` and works out its reach.
    pub fn circle(name: &'static str, circle: i32) -> Mask {
        let half = (circle as f64).sqrt().floor() as i32;
        let mut offsets = Vec::new();
        for dy in -half..=half {
            for dx in -half..=half {
                if (dx, dy) != (0, 0) && dx * dx + dy * dy <= circle {
                    offsets.push((dx, dy));
                }
            }
        }
        let h = half + 2;
        let reach_sq = (-h..=h)
            .flat_map(|dy| (-h..=h).map(move |dx| (dx, dy)))
            .filter(|&(dx, dy)| dx * dx + dy * dy > circle)
            .map(|(dx, dy)| gap_sq(dx, dy))
            .min()
            .expect("cells outside the mask exist");
        let half_offsets = offsets
            .iter()
            .copied()
            .filter(|&(dx, dy)| dy > 0 || (dy == 0 && dx > 0))
            .collect();
        let rows: Vec<(i32, i32, i32)> = (-half..=half)
            .filter_map(|dy| {
                let row = (-half..=half).filter(|&dx| dx * dx + dy * dy <= circle);
                let (lo, hi) = row.fold((i32::MAX, i32::MIN), |(l, h), dx| (l.min(dx), h.max(dx)));
                (lo <= hi).then_some((dy, lo, hi))
            })
            .collect();
        let half_rows = rows
            .iter()
            .filter_map(|&(dy, lo, hi)| match dy {
                0 if hi > 0 => Some((0, 1, hi)),
                d if d > 0 => Some((d, lo, hi)),
                _ => None,
            })
            .collect();
        Mask {
            name,
            offsets,
            half: half_offsets,
            reach_sq,
            half_width: half,
            rows,
            half_rows,
        }
    }

    /// Guaranteed distance from the centre cell to the outside, in cell sides.
    pub fn reach(&self) -> f64 {
        (self.reach_sq as f64).sqrt()
    }

    /// Isobe's mask number `k` of Table 1 (0 = MIN, 1 = R3, …, 8 = R10).
    pub fn table(k: usize) -> Mask {
        Mask::circle(TABLE_1[k].0, CIRCLE[k])
    }

    /// The mask a scenario asks for. `Auto` takes the mask that gives the elastic gas of equal
    /// disks the most collisions per wall second at the scene's packing fraction `phi` (R6
    /// below φ = 0.15, R4 below 0.55, R3 above; chosen by measurement), or the smallest
    /// larger one whose neighbour-list margin `reach·l_g − 2 a_max` is at least `0.5 a_min`.
    pub fn choose(choice: MaskChoice, cell: f64, a_min: f64, a_max: f64, phi: f64) -> Option<Mask> {
        let fits = |m: &Mask| m.reach() * cell - 2.0 * a_max > 0.0;
        let index = match choice {
            MaskChoice::Auto => {
                let preferred = if phi < 0.15 {
                    4
                } else if phi < 0.55 {
                    2
                } else {
                    1
                };
                return (preferred..TABLE_1.len())
                    .map(Mask::table)
                    .find(|m| m.reach() * cell - 2.0 * a_max >= 0.5 * a_min);
            }
            named => Mask::table_index(named).expect("a named mask"),
        };
        Some(Mask::table(index)).filter(fits)
    }

    /// The place in [`TABLE_1`] of a named mask (`None` for `Auto`).
    pub fn table_index(choice: MaskChoice) -> Option<usize> {
        Some(match choice {
            MaskChoice::Auto => return None,
            MaskChoice::Min => 0,
            MaskChoice::R3 => 1,
            MaskChoice::R4 => 2,
            MaskChoice::R5 => 3,
            MaskChoice::R6 => 4,
            MaskChoice::R7 => 5,
            MaskChoice::R8 => 6,
            MaskChoice::R9 => 7,
            MaskChoice::R10 => 8,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_list_the_mask_and_its_half_in_order() {
        for k in 0..TABLE_1.len() {
            let m = Mask::table(k);
            let expand = |rows: &[(i32, i32, i32)]| -> Vec<(i32, i32)> {
                rows.iter()
                    .flat_map(|&(dy, lo, hi)| (lo..=hi).map(move |dx| (dx, dy)))
                    .collect()
            };
            assert_eq!(expand(&m.half_rows), m.half, "{}", m.name);
            let mut all = m.offsets.clone();
            all.push((0, 0));
            all.sort_by_key(|&(dx, dy)| (dy, dx));
            assert_eq!(expand(&m.rows), all, "{}", m.name);
        }
    }

    #[test]
    fn reproduces_isobe_table_1() {
        for (k, &(name, reach_sq, cells)) in TABLE_1.iter().enumerate() {
            let m = Mask::table(k);
            assert_eq!(m.offsets.len(), cells, "{name}: cell count");
            // The stated distance is attained by some cell just outside the mask.
            let h = m.half_width + 2;
            let outside_min = (-h..=h)
                .flat_map(|dy| (-h..=h).map(move |dx| (dx, dy)))
                .filter(|&(dx, dy)| (dx, dy) != (0, 0) && !m.offsets.contains(&(dx, dy)))
                .map(|(dx, dy)| gap_sq(dx, dy))
                .min()
                .unwrap();
            assert_eq!(outside_min, reach_sq, "{name}: distance to the outside");
            assert_eq!(m.reach_sq, reach_sq, "{name}: computed reach");
        }
    }

    #[test]
    fn masks_are_symmetric() {
        for k in 0..TABLE_1.len() {
            let m = Mask::table(k);
            for &(dx, dy) in &m.offsets {
                assert!(m.offsets.contains(&(-dx, -dy)));
                // Exactly one of two opposite offsets is in the half mask.
                assert!(m.half.contains(&(dx, dy)) != m.half.contains(&(-dx, -dy)));
            }
            assert_eq!(2 * m.half.len(), m.offsets.len());
        }
    }
}
