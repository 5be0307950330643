//! The report's answer to the question a user brings to it: on this machine, for this
//! observable within this error, what is fastest — one exact run, K exact runs at once (seeds),
//! or an approximate scheme on K threads?
//!
//! Two uses are answered apart. **Averages over seeds** (a profile, a temperature) can be
//! gathered from independent runs, so K exact runs side by side count at their throughput.
//! **One trajectory** (a long transient, a time to rest) cannot be split among seeds: there the
//! choice is one exact run on one core or an approximate scheme on K threads. An approximate
//! variant qualifies when its error on the observable is within the level; the exact engine
//! always does. Cost is wall time per unit of simulated time, as the rows measured it.

use super::{Errors, Row};
use serde::Serialize;

/// The error levels answered for (relative errors).
pub const LEVELS: [f64; 3] = [0.01, 0.03, 0.1];

/// The level the figure answers for, in words beside the legend.
pub const FIGURE_LEVEL: f64 = 0.03;

/// A way to get a result, and what it costs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Way {
    /// In words: `one exact run`, `2 exact runs at once`, `time-step dt = … on 2 threads`.
    pub what: String,
    /// Wall seconds per unit of simulated time.
    pub wall_per_time: f64,
    /// Core seconds per unit of simulated time.
    pub core_per_time: f64,
}

/// The cheapest ways to one observable within one error level.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Answer {
    /// The observable, as the table names it.
    pub observable: &'static str,
    /// The relative error allowed.
    pub level: f64,
    /// The reference's seed spread on it: levels below it are not resolved by this report's
    /// seeds (an approximate error there may be noise).
    pub noise: Option<f64>,
    /// The cheapest way for averages over seeds.
    pub over_seeds: Way,
    /// The cheapest way for one trajectory.
    pub one_trajectory: Way,
}

impl Way {
    fn of(row: &Row, what: String) -> Way {
        Way {
            what,
            wall_per_time: row.wall_per_time,
            core_per_time: row.core_per_time,
        }
    }
}

/// The answers for every observable the scene measures and every level of [`LEVELS`], from the
/// report's rows: the reference first, its seed spread second, its runs at once (if K > 1) in
/// the family `reference` with more than one core.
pub fn answers(rows: &[Row]) -> Vec<Answer> {
    let (Some(exact), Some(spread)) = (rows.first(), rows.get(1)) else {
        return Vec::new();
    };
    let at_once = rows.iter().find(|r| r.family == "reference" && r.cores > 1);
    let one_exact = Way::of(exact, "one exact run".into());
    let exact_at_once = at_once.map_or(one_exact.clone(), |r| {
        Way::of(r, format!("{} exact runs at once", r.cores))
    });
    let mut answers = Vec::new();
    for (k, (observable, reference)) in exact.errors.entries().into_iter().enumerate() {
        if reference.is_none() {
            continue; // not measured in this scene
        }
        for level in LEVELS {
            let approximate = cheapest_approximation(rows, k, level);
            let cheaper = |way: &Way| match &approximate {
                Some(a) if a.wall_per_time < way.wall_per_time => a.clone(),
                _ => way.clone(),
            };
            answers.push(Answer {
                observable,
                level,
                noise: spread.errors.entries()[k].1,
                over_seeds: cheaper(&exact_at_once),
                one_trajectory: cheaper(&one_exact),
            });
        }
    }
    answers
}

/// The cheapest approximate-scheme row whose error on observable `k` is within `level`.
fn cheapest_approximation(rows: &[Row], k: usize, level: f64) -> Option<Way> {
    rows.iter()
        .filter(|r| matches!(r.family.as_str(), "time-step" | "space-time"))
        .filter(|r| r.wall_per_time.is_finite())
        .filter(|r| error(&r.errors, k).is_some_and(|e| e <= level))
        .min_by(|a, b| a.wall_per_time.total_cmp(&b.wall_per_time))
        .map(|r| {
            let threads = if r.cores == 1 { "thread" } else { "threads" };
            Way::of(
                r,
                format!("{} {} on {} {threads}", r.family, r.variant, r.cores),
            )
        })
}

fn error(e: &Errors, k: usize) -> Option<f64> {
    e.entries()[k].1
}

/// A relative error as a percentage, e.g. `3 %` or `0.4 %`.
pub fn percent(v: f64) -> String {
    let p = 100.0 * v;
    if p >= 1.0 {
        format!("{p:.0} %")
    } else {
        format!("{p:.1} %")
    }
}
