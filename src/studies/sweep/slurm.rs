//! Slurm: a job-array script whose task i runs `vibrobed sweep task SWEEP --index i --out DIR`
//! (the same code path as a local run), and its submission with `sbatch --parsable`.

use crate::error::{Error, Result};
use crate::studies::sweep::plan::{plural, Plan};
use std::path::Path;

/// What goes into the job script besides the array.
#[derive(Debug, Clone, Default)]
pub struct SlurmOptions {
    /// `#SBATCH --partition`.
    pub partition: Option<String>,
    /// `#SBATCH --time` (`[D-]HH:MM:SS`, `MM:SS` or minutes).
    pub time: Option<String>,
    /// At most this many array tasks at once (`--array=0-(n-1)%M`).
    pub array_max: Option<usize>,
    /// Further `#SBATCH` options, verbatim (e.g. `--mem=2G`, `--account=physics`).
    pub extra: Vec<String>,
}

/// Quotes `s` for a POSIX shell.
fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-+=:,@%".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// Checks a Slurm time limit: minutes, `MM:SS`, `HH:MM:SS`, `D-HH`, `D-HH:MM` or `D-HH:MM:SS`.
fn check_time(time: &str) -> Result<()> {
    let (days, rest) = match time.split_once('-') {
        Some((d, r)) => (Some(d), r),
        None => (None, time),
    };
    let parts: Vec<&str> = rest.split(':').collect();
    let numeric = |s: &str| !s.is_empty() && s.chars().all(|c| c.is_ascii_digit());
    let ok = days.is_none_or(numeric)
        && parts.iter().all(|p| numeric(p))
        && (1..=3).contains(&parts.len());
    if ok {
        Ok(())
    } else {
        Err(Error::input(
            "--time",
            format!("`{time}` is not a Slurm time limit (e.g. 01:30:00 or 2-00:00:00)"),
        ))
    }
}

/// Slurm's array list for run indices (sorted): consecutive runs as ranges, `0-3,7,9-10`.
pub fn array_list(indices: &[usize]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut k = 0;
    while k < indices.len() {
        let start = indices[k];
        let mut end = start;
        while k + 1 < indices.len() && indices[k + 1] == end + 1 {
            k += 1;
            end = indices[k];
        }
        parts.push(if end > start {
            format!("{start}-{end}")
        } else {
            start.to_string()
        });
        k += 1;
    }
    parts.join(",")
}

/// The job-array script for the runs `indices` of `plan` (all runs, or those not completed
/// yet), each task on `cpus` cores (the threads its run uses), whose tasks run `exe sweep task SWEEP --index $SLURM_ARRAY_TASK_ID --out DIR` (all
/// paths absolute). Task logs go to `DIR/slurm/`. Slurm sends the task SIGINT a minute before
/// its time limit: the run stops and writes its summary so far, marked
/// `"ending": "interrupted"`, and a later `sweep run` or `sweep slurm` runs it again.
pub fn script(
    plan: &Plan,
    indices: &[usize],
    cpus: usize,
    exe: &Path,
    out: &Path,
    opts: &SlurmOptions,
) -> Result<String> {
    if let Some(time) = &opts.time {
        check_time(time)?;
    }
    if opts.array_max == Some(0) {
        return Err(Error::input("--array-max", "must be at least 1"));
    }
    if let Some(p) = &opts.partition {
        if p.is_empty() || p.chars().any(char::is_whitespace) {
            return Err(Error::input(
                "--partition",
                format!("`{p}` is not a partition name"),
            ));
        }
    }
    for x in &opts.extra {
        if !x.starts_with('-') || x.contains('\n') {
            return Err(Error::input(
                "--sbatch",
                format!("`{x}` is not an sbatch option (e.g. --mem=2G)"),
            ));
        }
    }
    let n = indices.len();
    let mut array = array_list(indices);
    if let Some(m) = opts.array_max {
        array.push_str(&format!("%{m}"));
    }
    let job_name: String = plan
        .name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    let logs = out.join("slurm");
    let mut s = String::from("#!/bin/bash\n");
    s.push_str(&format!(
        "# vibrobed sweep `{}`: {} runs ({} × {}); {n} to run, one array task each.\n",
        plan.name,
        plan.runs.len(),
        plural(plan.points, "point"),
        plural(plan.seeds_per_point(), "seed")
    ));
    s.push_str(&format!("#SBATCH --job-name=vibrobed-{job_name}\n"));
    s.push_str(&format!("#SBATCH --array={array}\n"));
    s.push_str(&format!(
        "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task={cpus}\n"
    ));
    s.push_str(&format!("#SBATCH --output={}/%A_%a.out\n", logs.display()));
    if let Some(p) = &opts.partition {
        s.push_str(&format!("#SBATCH --partition={p}\n"));
    }
    if let Some(t) = &opts.time {
        s.push_str(&format!("#SBATCH --time={t}\n"));
    }
    // SIGINT to the task (which `exec`s vibrobed) a minute before its time limit, whether
    // given here or the partition's.
    s.push_str("#SBATCH --signal=B:INT@60\n");
    for x in &opts.extra {
        s.push_str(&format!("#SBATCH {x}\n"));
    }
    s.push_str(&format!(
        "\nexec {} sweep task {} --index \"$SLURM_ARRAY_TASK_ID\" --out {}\n",
        shell_quote(&exe.display().to_string()),
        shell_quote(&plan.sweep.display().to_string()),
        shell_quote(&out.display().to_string()),
    ));
    Ok(s)
}

/// Submits `script` with `sbatch --parsable` and returns the job id.
pub fn submit(script: &Path) -> Result<String> {
    let output = std::process::Command::new("sbatch")
        .arg("--parsable")
        .arg(script)
        .output()
        .map_err(|e| Error::Runtime(format!("cannot run sbatch: {e}")))?;
    if !output.status.success() {
        return Err(Error::Runtime(format!(
            "sbatch failed ({}): {}",
            output.status,
            String::from_utf8_lossy(&output.stderr).trim()
        )));
    }
    // `--parsable` prints `jobid` or `jobid;cluster`.
    let text = String::from_utf8_lossy(&output.stdout);
    let id = text.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() {
        return Err(Error::Runtime("sbatch printed no job id".into()));
    }
    Ok(id)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quotes_paths_for_the_shell() {
        assert_eq!(shell_quote("/a/b-c.json"), "/a/b-c.json");
        assert_eq!(shell_quote("/a b/it's"), r"'/a b/it'\''s'");
    }

    #[test]
    fn array_lists_compress_consecutive_runs() {
        assert_eq!(array_list(&[0, 1, 2, 3]), "0-3");
        assert_eq!(array_list(&[0, 2, 3, 4, 7, 9, 10]), "0,2-4,7,9-10");
        assert_eq!(array_list(&[5]), "5");
    }

    #[test]
    fn time_limits() {
        for ok in ["30", "10:00", "01:30:00", "2-00:00:00", "1-12"] {
            assert!(check_time(ok).is_ok(), "{ok}");
        }
        for bad in ["", "1h", "01:30:00:00", "a-01", "10::00"] {
            let e = check_time(bad).unwrap_err();
            assert!(e.to_string().starts_with("--time:"), "{bad}: {e}");
        }
    }
}
