//! The series of `sweep collect --by KEY`: the points split by the values of one or more axes,
//! one series (and one fit) per group; and the check that no other axis varies along x within a
//! group, which would pool two series into one line.

use crate::error::{Error, Result};
use crate::studies::sweep::collect::Collected;

/// One group of points: its label (`particles.count=60`, or `all points`) and its points.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// `KEY=VALUE, …` of the grouping keys.
    pub label: String,
    /// Point numbers, in order.
    pub points: Vec<usize>,
}

/// The groups of `c`'s points by the values of `by` (in the order each value first appears);
/// one group of every point without `by`. Refused (bad input): `x` or a key that is not an axis, and
/// an axis other than `x` and `by` that takes several values at one x within a group (a second
/// axis: it would be pooled into the series and its fit).
pub fn groups(c: &Collected, x: &str, by: &[String]) -> Result<Vec<Group>> {
    c.require_axis("--x", x)?;
    for key in by {
        c.require_axis("--by", key)?;
    }
    let mut out: Vec<Group> = Vec::new();
    for p in c.points.iter().map(|p| p.point) {
        let label = if by.is_empty() {
            "all points".to_string()
        } else {
            by.iter()
                .map(|k| format!("{k}={}", c.point_cell(k, p)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        match out.iter_mut().find(|g| g.label == label) {
            Some(g) => g.points.push(p),
            None => out.push(Group {
                label,
                points: vec![p],
            }),
        }
    }
    for g in &out {
        pooled_axis(c, x, by, g)?;
    }
    Ok(out)
}

/// Refuses a group in which an axis other than `x` and `by` takes several values at one x
/// (two series pooled into one); warns when it takes several values that follow x but not one
/// to one (a sweep whose axes vary together along x, as `zip` makes them, each x with its value:
/// one series, said once), and says nothing for an axis one to one with x (as
/// `floor.amplitude` follows `drive.peak_velocity` at one frequency).
fn pooled_axis(c: &Collected, x: &str, by: &[String], g: &Group) -> Result<()> {
    for axis in &c.plan.axes {
        if axis == x || by.contains(axis) {
            continue;
        }
        let pairs: Vec<(String, String)> = g
            .points
            .iter()
            .map(|&p| (c.point_cell(axis, p), c.point_cell(x, p)))
            .collect();
        let mut values: Vec<&str> = pairs.iter().map(|(a, _)| a.as_str()).collect();
        values.sort();
        values.dedup();
        if values.len() < 2 {
            continue;
        }
        let follows_x = pairs
            .iter()
            .all(|(a, xa)| pairs.iter().all(|(b, xb)| xa != xb || a == b));
        let one_to_one = pairs
            .iter()
            .all(|(a, xa)| pairs.iter().all(|(b, xb)| a != b || xa == xb));
        let values = values.join(", ");
        if !follows_x {
            return Err(Error::input(
                "--by",
                format!(
                    "the axis {axis} also varies ({values}) at one {x}: one line and fit over \
                     all its values would pool them; give --by {axis} for a series each"
                ),
            ));
        }
        if !one_to_one {
            eprintln!(
                "vibrobed: warning: the axis {axis} also varies ({values}) along {x} (one value \
                 at each x): its points are one series; --by {axis} splits them"
            );
        }
    }
    Ok(())
}
