//! The report as text: the table printed on stdout and written to `accuracy.txt`, and the CSV
//! files `accuracy.csv` and `effects.csv`.

use super::cheapest::{percent, Way};
use super::Report;
use std::fmt::Write as _;

/// An error cell of the table: two significant digits, `-` where absent.
fn cell(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{v:.2e}"),
        _ => "-".into(),
    }
}

/// A change the effect makes, in per cent (with its sign, given `"+"`: a scalar's change, not
/// a profile's distance), `-` where absent.
fn change(v: Option<f64>, sign: &str) -> String {
    match v {
        Some(v) if v.is_finite() && sign == "+" => format!("{:+.1} %", 100.0 * v),
        Some(v) if v.is_finite() => format!("{:.1} %", 100.0 * v),
        _ => "-".into(),
    }
}

/// A cost cell of the table: `digits` decimals, `-` where not measured.
fn cost(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        "-".into()
    }
}

impl Report {
    /// The table printed on stdout.
    pub fn table(&self) -> String {
        let mut out = String::new();
        self.accuracy_section(&mut out);
        if !self.effects.is_empty() {
            self.effects_section(&mut out);
        }
        let _ = writeln!(out, "\nreport took {:.1} s", self.wall_seconds);
        out
    }

    /// The accuracy–cost table: a title, one line per row and a legend of the columns.
    fn accuracy_section(&self, out: &mut String) {
        let _ = writeln!(
            out,
            "accuracy vs cost: {} ({} disks, {} time units, seeds {:?})",
            self.scenario, self.particles, self.duration, self.seeds
        );
        let _ = writeln!(
            out,
            "on {} cores of {}; errors are relative to the exact engine's seed mean",
            self.cores, self.machine
        );
        let _ = writeln!(
            out,
            "cost: s/t = wall s per unit of simulated time, core·s/t = that × the cores held\n"
        );
        let _ = writeln!(
            out,
            "{:<11} {:<34} {:>9} {:>6} {:>5} {:>9} | {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} | {:>8} {:>8} {:>8} note",
            "family",
            "variant",
            "s/t",
            "×ref",
            "cores",
            "core·s/t",
            "ρ(z)",
            "T(z)",
            "z_cm",
            "T",
            "E_in/t",
            "coll/t",
            "ovl/d",
            "deep",
            "missed",
        );
        for r in &self.rows {
            let e = r.errors;
            let _ = writeln!(
                out,
                "{:<11} {:<34} {:>9} {:>6} {:>5} {:>9} | {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} | {:>8} {:>8} {:>8} {}",
                r.family,
                r.variant,
                cost(r.wall_per_time, 4),
                cost(r.relative_cost, 2),
                if r.cores > 0 { r.cores.to_string() } else { "-".into() },
                cost(r.core_per_time, 4),
                cell(e.density_profile),
                cell(e.temperature_profile),
                cell(e.com_height),
                cell(e.temperature),
                cell(e.energy_input),
                cell(e.collision_rate),
                cell(Some(r.max_overlap)),
                cell(r.deep_fraction),
                cell(r.missed_fraction),
                r.note
            );
        }
        let _ = writeln!(
            out,
            "\nρ(z), T(z): L2 profile errors; ovl/d: largest pair overlap / smallest diameter; deep: overlaps > 10 % of contact per pair collision; missed: missed collisions per pair collision"
        );
        self.answers_section(out);
    }

    /// The answers in words: per observable and error level, the cheapest way there, for
    /// averages over seeds and for one trajectory.
    fn answers_section(&self, out: &mut String) {
        if self.answers.is_empty() {
            return;
        }
        let _ = writeln!(
            out,
            "\nthe cheapest way on this machine ({} cores), wall s per unit of simulated time in brackets:\n",
            self.cores
        );
        let _ = writeln!(
            out,
            "{:<20} {:>6}  {:<46} {:<46} note",
            "observable", "within", "averages over seeds", "one trajectory"
        );
        let way = |w: &Way| format!("{} ({:.2e})", w.what, w.wall_per_time);
        for a in &self.answers {
            let note = match a.noise {
                Some(n) if n > a.level => format!("seed spread {}: not resolved", percent(n)),
                _ => String::new(),
            };
            let _ = writeln!(
                out,
                "{:<20} {:>6}  {:<46} {:<46} {note}",
                a.observable,
                percent(a.level),
                way(&a.over_seeds),
                way(&a.one_trajectory),
            );
        }
    }

    /// The effects table (with `--effects`): a title and one line per effect.
    fn effects_section(&self, out: &mut String) {
        let _ = writeln!(
            out,
            "\nwhat each effect costs (exact engine; slowdown = with / without)\n"
        );
        let _ = writeln!(
            out,
            "{:<28} {:<34} {:>12} {:>12} {:>9} {:>9} note",
            "effect",
            "added to the scene without it",
            "µs/coll w/o",
            "µs/coll with",
            "×/coll",
            "×/time",
        );
        for e in &self.effects {
            let _ = writeln!(
                out,
                "{:<28} {:<34} {:>12.3} {:>12.3} {:>9.2} {:>9.2} {}",
                e.effect,
                e.with,
                1e6 * e.per_collision[0],
                1e6 * e.per_collision[1],
                e.slowdown_per_collision,
                e.slowdown_per_time,
                e.note
            );
            if let Some(c) = e.changes {
                let _ = writeln!(
                    out,
                    "{:<28} it changes: ρ(z) {}, T(z) {}, z_cm {}, T {}, E_in/t {}, coll/t {}",
                    "",
                    change(c.density_profile, ""),
                    change(c.temperature_profile, ""),
                    change(c.com_height, "+"),
                    change(c.temperature, "+"),
                    change(c.energy_input, "+"),
                    change(c.collision_rate, "+"),
                );
            }
        }
    }

    /// The rows as CSV.
    pub fn csv(&self) -> String {
        let mut out = String::from(
            "family,variant,settings,seeds,wall_per_time,relative_cost,cores,core_per_time,err_density_profile,err_temperature_profile,err_com_height,err_temperature,err_energy_input,err_collision_rate,max_overlap_per_diameter,overlapped_fraction,deep_fraction,missed_fraction,note\n",
        );
        let f = |v: Option<f64>| {
            v.filter(|v| v.is_finite())
                .map_or(String::new(), |v| format!("{v:e}"))
        };
        for r in &self.rows {
            let e = r.errors;
            let _ = writeln!(
                out,
                "{},\"{}\",\"{}\",{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},\"{}\"",
                r.family,
                r.variant,
                r.settings,
                r.seeds,
                f(Some(r.wall_per_time)),
                f(Some(r.relative_cost)),
                r.cores,
                f(Some(r.core_per_time)),
                f(e.density_profile),
                f(e.temperature_profile),
                f(e.com_height),
                f(e.temperature),
                f(e.energy_input),
                f(e.collision_rate),
                f(Some(r.max_overlap)),
                f(r.overlapped_fraction),
                f(r.deep_fraction),
                f(r.missed_fraction),
                r.note.replace('"', "'")
            );
        }
        out
    }

    /// The answers as CSV: per observable and level, the cheapest way over seeds and for one
    /// trajectory, with their wall and core seconds per unit of simulated time.
    pub fn answers_csv(&self) -> String {
        let mut out = String::from(
            "observable,level,seed_spread,over_seeds,over_seeds_wall_per_time,over_seeds_core_per_time,one_trajectory,one_trajectory_wall_per_time,one_trajectory_core_per_time\n",
        );
        for a in &self.answers {
            let _ = writeln!(
                out,
                "\"{}\",{},{},\"{}\",{:e},{:e},\"{}\",{:e},{:e}",
                a.observable,
                a.level,
                a.noise.map_or(String::new(), |v| format!("{v:e}")),
                a.over_seeds.what,
                a.over_seeds.wall_per_time,
                a.over_seeds.core_per_time,
                a.one_trajectory.what,
                a.one_trajectory.wall_per_time,
                a.one_trajectory.core_per_time,
            );
        }
        out
    }

    /// The effects table as CSV.
    pub fn effects_csv(&self) -> String {
        let mut out = String::from(
            "effect,without,with,seconds_per_collision_without,seconds_per_collision_with,seconds_per_time_without,seconds_per_time_with,slowdown_per_collision,slowdown_per_time,change_density_profile,change_temperature_profile,change_com_height,change_temperature,change_energy_input,change_collision_rate,note\n",
        );
        for e in &self.effects {
            let changes = e
                .changes
                .unwrap_or_default()
                .entries()
                .map(|(_, v)| v.map_or(String::new(), |v| format!("{v:e}")))
                .join(",");
            let _ = writeln!(
                out,
                "\"{}\",\"{}\",\"{}\",{:e},{:e},{:e},{:e},{},{},{},\"{}\"",
                e.effect,
                e.without,
                e.with,
                e.per_collision[0],
                e.per_collision[1],
                e.per_time[0],
                e.per_time[1],
                e.slowdown_per_collision,
                e.slowdown_per_time,
                changes,
                e.note
            );
        }
        out
    }
}
