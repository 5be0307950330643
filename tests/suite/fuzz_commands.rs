//! Structure-aware fuzzing of the commands other than `check` and `run` (whose scenes
//! `fuzz_fields` changes field by field), on the real binary: `resume` of a checkpointed run
//! with every option it takes (its `--set`s, its outputs, its checkpoint interval) near and past
//! their limits; `sweep plan` of the shipped sweep files changed field by field; `sweep task`,
//! `sweep slurm` and `sweep collect` of a small sweep with their options; `sweep run` of a small
//! sweep file changed leaf by leaf, with its options; `accuracy` of a short scene with its options
//! and the scene's fields; then pairs of such changes (two options of a resume or an accuracy
//! report, two leaves of a sweep file), drawn from a seeded generator. Every case must end with an exit code of the
//! contract (0; 2 naming the field or option, nothing written and no input changed; for
//! `resume`, 4, 5 or 6 for a run ended by a limit or a stall) in bounded memory — never a
//! panic, an abort or a signal — or, still running after [`INTERRUPT_AFTER`], stop on SIGINT.
//!
//! The cases come in a fixed order, a command's first cases (and first pairs) before any
//! command's later ones, and run until a time budget is spent ([`DEFAULT_SECONDS`]; see
//! [`crate::fuzz_budget`]); `VIBROBED_FUZZ_SEED` draws other pairs. A failing case is reported with
//! its command line and its directory.

use crate::fuzz_budget::Budget;
use crate::guarded;

use guarded::{error_field, error_line, Limits, Outcome};
use serde_json::Value;
use std::ffi::OsString;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Duration;
use vibrobed::scenario::checks::{MAX_CHECKPOINTS, MAX_THREADS};

/// Seconds of cases when `VIBROBED_FUZZ_SECONDS` is not set (as in CI): a case takes 10–200
/// ms (the setup, two checkpointed runs and a sweep of two runs, well under a second), so some
/// 500 of the 2366 cases, every command's first ones.
const DEFAULT_SECONDS: u64 = 90;

/// A case still running after this long is sent SIGINT (then SIGKILL 5 s later).
const INTERRUPT_AFTER: Duration = Duration::from_secs(8);

/// Most seeds `accuracy --seeds` takes (`cli::MAX_SEEDS`).
const MAX_SEEDS: u64 = 1000;

/// Numbers tried where an option or field holds `x`: itself, nearby, far, and not numbers.
fn near(x: f64) -> Vec<String> {
    let mut out: Vec<String> = [
        x,
        0.0,
        -x,
        x * (1.0 + 1e-15),
        x * 1e6,
        x / 1e6,
        1e-101,
        1e101,
        5e-324,
        1.7e308,
    ]
    .iter()
    .map(|y| format!("{y:e}"))
    .collect();
    out.extend(["NaN".into(), "inf".into(), "-1".into(), "x".into()]);
    out
}

/// What a case needs in its directory before it runs.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Setup {
    /// Nothing.
    Empty,
    /// `c.ckpt`, a checkpoint of the scene of this name run to t = [`CUT`].
    Checkpoint(&'static str),
    /// `out/`, the small sweep run; `small.json`, its file.
    Sweep,
}

/// Where checkpointed runs stop.
const CUT: f64 = 0.05;

/// Scenes checkpointed for `resume`: a bed on a vibrating floor, and a pour through an inlet.
const CHECKPOINTED: [&str; 2] = ["vibrated_bed.json", "pour.json"];

/// One case: its command's name, what it needs, its arguments.
#[derive(Debug, Clone)]
struct Case {
    command: &'static str,
    setup: Setup,
    args: Vec<String>,
}

fn case(command: &'static str, setup: Setup, args: &[String]) -> Case {
    Case {
        command,
        setup,
        args: args.to_vec(),
    }
}

fn strings(items: &[&str]) -> Vec<String> {
    items.iter().map(|s| s.to_string()).collect()
}

/// `resume c.ckpt --quiet --summary s.json` with `extra`.
fn resume_case(scene: &'static str, extra: &[String]) -> Case {
    let mut args = strings(&["resume", "c.ckpt", "--quiet", "--summary", "s.json"]);
    args.extend(extra.iter().cloned());
    case("resume", Setup::Checkpoint(scene), &args)
}

/// `resume c.ckpt` with one option or override changed at a time.
fn resume_cases() -> Vec<Case> {
    let mut out = Vec::new();
    for scene in CHECKPOINTED {
        out.extend(resume_extras().iter().map(|e| resume_case(scene, e)));
    }
    out
}

/// What [`resume_cases`] adds to a resume, one option or override each.
fn resume_extras() -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut with = |extra: &[String]| out.push(extra.to_vec());
    for v in near(2.0 * CUT) {
        with(&strings(&["--set", &format!("run.duration={v}")]));
        with(&strings(&["--checkpoint-every", &v]));
        with(&strings(&["--set", &format!("run.max_wall_seconds={v}")]));
    }
    for v in ["0", "1", "100000", "18446744073709551615", "-1", "1e3"] {
        with(&strings(&["--set", &format!("run.max_events={v}")]));
    }
    let every = 2.0 * CUT / MAX_CHECKPOINTS;
    for v in [every, every * (1.0 + 1e-15), every * (1.0 - 1e-15)] {
        let extra = [
            "--set",
            "run.duration=0.1",
            "--checkpoint-every",
            &format!("{v:e}"),
        ];
        with(&strings(&extra));
    }
    for extra in [
        &["--set", "particles.count=5"][..],
        &["--set", "run.warmup=0"],
        &["--set", "run.duration"],
        &["--set", "=1"],
        &["--summary", "c.ckpt"],
        &["--profiles", "./c.ckpt"],
        &["--trajectory", "c.ckpt.tmp"],
        &["--trajectory", "s.json"],
        &["--checkpoint", "s.json"],
        &["--checkpoint", "d.ckpt", "--trajectory", "d.ckpt.tmp"],
        &["--fields", "f.csv"],
        &["--profiles", "missing/p.csv"],
        &["--trajectory", "."],
        &["--progress-every", "0"],
        &["--progress-every", "NaN"],
        &["--summary", "-"],
        &["--fields", "-"],
        &["--checkpoint", "-"],
    ] {
        with(&strings(extra));
    }
    out
}

/// The shipped sweep files, their scenario made absolute, with their JSON.
fn shipped_sweeps() -> Vec<Value> {
    let dir = guarded::crate_root().join("scenarios").join("sweeps");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("scenarios/sweeps/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|p| {
            let mut v: Value =
                serde_json::from_str(&std::fs::read_to_string(p).expect("sweep")).expect("JSON");
            let scene = v["scenario"].as_str().expect("a scenario").to_string();
            v["scenario"] = Value::String(dir.join(scene).display().to_string());
            v
        })
        .collect()
}

/// Each leaf of `v` (numbers and strings; lists looked into), by its path of keys and indices.
fn leaves(v: &Value, path: &[String], out: &mut Vec<(Vec<String>, Value)>) {
    let mut down = |k: String, x: &Value| {
        let mut p = path.to_vec();
        p.push(k);
        leaves(x, &p, out);
    };
    match v {
        Value::Object(map) => map.iter().for_each(|(k, x)| down(k.clone(), x)),
        Value::Array(items) => items
            .iter()
            .enumerate()
            .take(2)
            .for_each(|(i, x)| down(i.to_string(), x)),
        _ => out.push((path.to_vec(), v.clone())),
    }
}

/// `v` with the leaf at `path` replaced by `value`.
fn replaced(v: &Value, path: &[String], value: Value) -> Value {
    let mut out = v.clone();
    let mut at = &mut out;
    for k in path {
        at = match at {
            Value::Array(items) => &mut items[k.parse::<usize>().expect("an index")],
            other => &mut other[k.as_str()],
        };
    }
    *at = value;
    out
}

/// Values tried at a sweep file's leaf holding `v`.
fn sweep_values(v: &Value) -> Vec<Value> {
    let mut out: Vec<Value> = match v {
        Value::Number(n) => near(n.as_f64().unwrap_or(1.0))
            .iter()
            .filter_map(|s| serde_json::from_str(s).ok())
            .collect(),
        Value::String(s) if s.contains('=') => {
            let key = s.split('=').next().unwrap_or("");
            [
                format!("{key}=1e300"),
                format!("{key}="),
                "nope=1".into(),
                format!("{key}.x.y=1"),
                "=".into(),
            ]
            .map(Value::String)
            .to_vec()
        }
        Value::String(_) => ["", "nope", "floor", "particles.radius.min", "run.duration"]
            .map(|s| Value::String(s.into()))
            .to_vec(),
        _ => Vec::new(),
    };
    out.extend([
        Value::Null,
        serde_json::json!([]),
        serde_json::json!({}),
        serde_json::json!(100001),
    ]);
    out
}

/// `sweep plan` of each shipped sweep file changed at one leaf at a time, and with its axes'
/// and seeds' counts at the bounds.
fn plan_cases() -> Vec<Case> {
    let mut per_sweep: Vec<Vec<Case>> = Vec::new();
    for sweep in shipped_sweeps() {
        let mut cases: Vec<Case> = leaf_changes(&sweep)
            .into_iter()
            .map(|(path, value)| plan_case(&replaced(&sweep, &path, value)))
            .collect();
        for n in [99_999u64, 100_000, 100_001, u64::MAX] {
            cases.push(plan_case(&replaced(
                &sweep,
                &strings(&["seeds"]),
                serde_json::json!(n),
            )));
            let range = serde_json::json!([{"key": "run.duration", "range": {"from": 1, "to": 2, "count": n}}]);
            cases.push(plan_case(&replaced(&sweep, &strings(&["axes"]), range)));
        }
        per_sweep.push(cases);
    }
    interleave(&per_sweep)
}

/// A leaf changed: its path and its new value.
type LeafChange = (Vec<String>, Value);

/// Each leaf of the sweep file `sweep` but its scenario, with each of its [`sweep_values`].
fn leaf_changes(sweep: &Value) -> Vec<LeafChange> {
    let mut found = Vec::new();
    leaves(sweep, &[], &mut found);
    let mut out = Vec::new();
    for (path, v) in found.iter().filter(|(p, _)| p[0] != "scenario") {
        out.extend(
            sweep_values(v)
                .into_iter()
                .map(|value| (path.clone(), value)),
        );
    }
    out
}

/// `sweep` with `changes` made in turn (a later change into a leaf an earlier one replaced by
/// a value without it is dropped).
fn changed(sweep: &Value, changes: &[LeafChange]) -> Value {
    changes.iter().fold(sweep.clone(), |v, (path, value)| {
        if has_parent(&v, path) {
            replaced(&v, path, value.clone())
        } else {
            v
        }
    })
}

/// Whether every step of `path` but the last leads into an object or a list long enough.
fn has_parent(v: &Value, path: &[String]) -> bool {
    let mut at = v;
    for k in &path[..path.len().saturating_sub(1)] {
        at = match at {
            Value::Array(items) => match k.parse::<usize>().ok().and_then(|i| items.get(i)) {
                Some(x) => x,
                None => return false,
            },
            Value::Object(map) => match map.get(k) {
                Some(x) => x,
                None => return false,
            },
            _ => return false,
        };
    }
    match (at, path.last()) {
        (Value::Array(items), Some(k)) => k.parse::<usize>().is_ok_and(|i| i < items.len()),
        (Value::Object(_), _) => true,
        _ => false,
    }
}

/// `sweep plan FILE`, the file given inline (written into the case's directory as `s.json`).
fn plan_case(sweep: &Value) -> Case {
    let text = sweep.to_string();
    case(
        "sweep plan",
        Setup::Empty,
        &["sweep".into(), "plan".into(), format!("@{text}")],
    )
}

/// `sweep task`, `sweep slurm` and `sweep collect` of the small sweep with their options.
fn small_sweep_cases() -> Vec<Case> {
    let mut out = Vec::new();
    let collect = |extra: &[&str]| {
        let mut args = strings(&["sweep", "collect", "out"]);
        args.extend(strings(extra));
        case("sweep collect", Setup::Sweep, &args)
    };
    let plot = ["--x", "floor.restitution", "--y", "com_height"];
    for extra in [
        &[] as &[&str],
        &plot,
        &["--x", "nope", "--y", "com_height"],
        &["--x", "floor.restitution", "--y", "nope"],
        &["--x", "floor.restitution"],
        &["--y", "com_height"],
        &["--states", "floor.restitution", "seed"],
        &["--states", "nope", "nope"],
        &["--log"],
    ] {
        out.push(collect(extra));
    }
    for extra in [
        &["--plot", "out/plan.json"][..],
        &["--plot", "out/0"],
        &["--plot", "out/0/x.svg"],
        &["--plot", "missing/x.svg"],
        &["--plot", "."],
        &["--by", "nope"],
        &["--by", "floor.restitution"],
        &["--fit", "power", "--offset", "fit"],
    ] {
        let mut all = plot.to_vec();
        all.extend(extra);
        out.push(collect(&all));
    }
    for v in near(1.0) {
        let mut all = plot.to_vec();
        all.extend(["--fit", "power", "--offset", &v]);
        out.push(collect(&all));
        let mut all = plot.to_vec();
        all.extend(["--fit", "power", "--fit-range", &v, "2"]);
        out.push(collect(&all));
    }
    for index in ["0", "1", "2", "18446744073709551615", "-1"] {
        let args = strings(&[
            "sweep",
            "task",
            "small.json",
            "--index",
            index,
            "--out",
            "out",
        ]);
        out.push(case("sweep task", Setup::Sweep, &args));
    }
    for extra in [
        &["--time", "01:00:00"][..],
        &["--time", "nope"],
        &["--array-max", "0"],
        &["--array-max", "18446744073709551615"],
        &["--partition", ""],
        &["--sbatch", "--mem=2G\nrm -rf /"],
    ] {
        let mut args = strings(&["sweep", "slurm", "small.json", "--out", "slurm"]);
        args.extend(strings(extra));
        out.push(case("sweep slurm", Setup::Sweep, &args));
    }
    out
}

/// The sweep `sweep run` is fuzzed on: two runs of the bouncing ball, a second each.
fn small_sweep() -> Value {
    serde_json::json!({
        "name": "small",
        "scenario": guarded::scenario("bouncing_ball.json"),
        "set": ["run.duration=1", "run.warmup=0"],
        "axes": [{ "key": "floor.restitution", "values": [0.5, 0.9] }],
        "seeds": 1
    })
}

/// `sweep run FILE --out out -q` of `sweep` (given inline), with `extra`.
fn sweep_run_case(sweep: &Value, extra: &[String]) -> Case {
    let mut args = strings(&["sweep", "run", &format!("@{sweep}"), "--out", "out", "-q"]);
    args.extend(extra.iter().cloned());
    case("sweep run", Setup::Empty, &args)
}

/// What `sweep run` of the small sweep is given beside it, one option each.
fn sweep_run_extras() -> Vec<Vec<String>> {
    let mut out: Vec<Vec<String>> = Vec::new();
    for v in near(1.0) {
        out.push(strings(&["--max-run-seconds", &v]));
        out.push(strings(&["--progress-every", &v]));
    }
    for n in ["0", "1", "2", "1000000", "18446744073709551615", "-1"] {
        out.push(strings(&["--jobs", n]));
    }
    for extra in [
        &["--out", "-"][..],
        &["--out", "s.json"],
        &["--out", "missing/deeper/out"],
        &["--out", "."],
        &["--out", ""],
    ] {
        out.push(strings(extra));
    }
    out
}

/// `sweep run` of the small sweep with one leaf of its file, or one option, changed.
fn sweep_run_cases() -> Vec<Case> {
    let sweep = small_sweep();
    let files = leaf_changes(&sweep)
        .into_iter()
        .map(|change| sweep_run_case(&changed(&sweep, &[change]), &[]));
    let options = sweep_run_extras()
        .into_iter()
        .map(|extra| sweep_run_case(&sweep, &extra));
    interleave(&[files.collect(), options.collect()])
}

/// A fixed sequence of draws (xorshift64*, as `fuzz_fields` draws its pairs).
struct Draws(u64);

impl Draws {
    /// The draws of `VIBROBED_FUZZ_SEED` (default 0x62).
    fn seeded() -> Draws {
        let seed = std::env::var("VIBROBED_FUZZ_SEED")
            .ok()
            .map(|t| t.trim().parse().expect("VIBROBED_FUZZ_SEED is a number"));
        Draws(seed.unwrap_or(0x62) | 1)
    }

    /// An index below `n`.
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 33) as usize % n.max(1)
    }

    /// Two items of `list`, drawn.
    fn two<T: Clone>(&mut self, list: &[T]) -> (T, T) {
        (
            list[self.below(list.len())].clone(),
            list[self.below(list.len())].clone(),
        )
    }
}

/// Pairs drawn per command: more than the time budget reaches, so that another seed or a
/// longer budget tries others.
const PAIRS: usize = 400;

/// Pairs of changes, each command's in its own list: two options of a resume (of either
/// checkpoint) or of an accuracy report; two leaves of a shipped sweep file (`sweep plan`) or
/// of the small sweep (`sweep run`), or a leaf and an option of `sweep run`.
fn pair_cases(draws: &mut Draws) -> Vec<Vec<Case>> {
    let resume = resume_extras();
    let accuracy = accuracy_extras();
    let sweeps = shipped_sweeps();
    let plan: Vec<Vec<LeafChange>> = sweeps.iter().map(leaf_changes).collect();
    let small = small_sweep();
    let run_files = leaf_changes(&small);
    let run_options = sweep_run_extras();
    let mut lists: Vec<Vec<Case>> = vec![Vec::new(); 4];
    for _ in 0..PAIRS {
        let scene = CHECKPOINTED[draws.below(CHECKPOINTED.len())];
        let (a, b) = draws.two(&resume);
        lists[0].push(resume_case(scene, &[a, b].concat()));
        let (a, b) = draws.two(&accuracy);
        lists[1].push(accuracy_case(&[a, b].concat()));
        let k = draws.below(sweeps.len());
        let (a, b) = draws.two(&plan[k]);
        lists[2].push(plan_case(&changed(&sweeps[k], &[a, b])));
        let (a, b) = draws.two(&run_files);
        let option = &run_options[draws.below(run_options.len())];
        lists[3].push(match draws.below(2) {
            0 => sweep_run_case(&changed(&small, &[a, b]), &[]),
            _ => sweep_run_case(&changed(&small, &[a]), option),
        });
    }
    lists
}

/// `accuracy` of the bouncing ball cut short, with its options and, one at a time, the
/// scene's numeric fields changed.
fn accuracy_cases() -> Vec<Case> {
    accuracy_extras().iter().map(|e| accuracy_case(e)).collect()
}

/// `accuracy` of the bouncing ball cut short, with `extra`.
fn accuracy_case(extra: &[String]) -> Case {
    let ball = guarded::scenario("bouncing_ball.json")
        .display()
        .to_string();
    let mut args = strings(&[
        "accuracy",
        &ball,
        "--quick",
        "--quiet",
        "--out",
        "a",
        "--set",
        "run.duration=2",
        "--set",
        "run.warmup=0",
    ]);
    args.extend(extra.iter().cloned());
    case("accuracy", Setup::Empty, &args)
}

/// What [`accuracy_cases`] adds to the report, one option or field each.
fn accuracy_extras() -> Vec<Vec<String>> {
    let with = |extra: &[String]| extra.to_vec();
    let mut out = Vec::new();
    for n in [0, 1, 2, MAX_SEEDS + 1, u64::MAX] {
        out.push(with(&strings(&["--seeds", &n.to_string()])));
    }
    let most = MAX_THREADS;
    for n in [0, 1, most, most + 1] {
        out.push(with(&strings(&["--cores", &n.to_string()])));
    }
    out.push(with(&strings(&["--effects"])));
    out.push(with(&strings(&["--out", "missing/a"])));
    out.push(with(&strings(&["--out", "-"])));
    for field in [
        "floor.amplitude",
        "floor.frequency",
        "floor.restitution",
        "gravity",
    ] {
        for v in near(0.5) {
            out.push(with(&strings(&["--set", &format!("{field}={v}")])));
        }
    }
    out
}

/// The first item of each list, then the second of each, and so on.
fn interleave<T: Clone>(lists: &[Vec<T>]) -> Vec<T> {
    let longest = lists.iter().map(Vec::len).max().unwrap_or(0);
    (0..longest)
        .flat_map(|k| lists.iter().filter_map(move |l| l.get(k).cloned()))
        .collect()
}

/// Copies `from` into `to`, folders and all.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("a directory");
    for entry in std::fs::read_dir(from).expect("a directory").flatten() {
        let target = to.join(entry.file_name());
        if entry.path().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).expect("a copy");
        }
    }
}

/// The files under `dir` with their contents, for "nothing written, nothing changed".
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = entry.path();
            if p.is_dir() {
                out.push((p.clone(), Vec::new()));
                stack.push(p);
            } else {
                let bytes = std::fs::read(&p).unwrap_or_default();
                out.push((p, bytes));
            }
        }
    }
    out.sort();
    out
}

/// Runs `vibrobed args` in `dir` under the guard.
fn vibrobed(dir: &Path, args: &[String]) -> Outcome {
    let os: Vec<OsString> = args.iter().map(OsString::from).collect();
    let logs = dir.with_extension("logs");
    let out = guarded::run(
        &os,
        dir,
        &logs,
        Limits {
            interrupt_after: INTERRUPT_AFTER,
            kill_after: Duration::from_secs(5),
        },
    );
    let _ = std::fs::remove_dir_all(&logs);
    out
}

/// Prepares each setup once under `root`: the checkpoints and the small sweep.
fn prepare(root: &Path) {
    for scene in CHECKPOINTED {
        let dir = root.join(scene);
        std::fs::create_dir_all(&dir).expect("setup directory");
        let path = guarded::scenario(scene).display().to_string();
        let cut = format!("run.duration={CUT}");
        let args = strings(&[
            "run",
            &path,
            "--quiet",
            "--checkpoint",
            "c.ckpt",
            "--summary",
            "first.json",
            "--set",
            &cut,
            "--set",
            "run.warmup=0",
        ]);
        let out = vibrobed(&dir, &args);
        assert_eq!(out.code(), Some(0), "setup: {}", out.describe());
        std::fs::remove_file(dir.join("first.json")).expect("the first part's summary");
    }
    let dir = root.join("sweep");
    std::fs::create_dir_all(&dir).expect("setup directory");
    std::fs::write(dir.join("small.json"), small_sweep().to_string()).expect("sweep file");
    let out = vibrobed(
        &dir,
        &strings(&["sweep", "run", "small.json", "--out", "out", "-q"]),
    );
    assert_eq!(out.code(), Some(0), "setup: {}", out.describe());
}

/// Fills `dir` with what `setup` needs (from `root`); returns the arguments with an inline
/// sweep file written out.
fn set_up(root: &Path, dir: &Path, c: &Case) -> Vec<String> {
    match c.setup {
        Setup::Empty => {}
        Setup::Checkpoint(scene) => {
            std::fs::copy(root.join(scene).join("c.ckpt"), dir.join("c.ckpt")).expect("copy");
        }
        Setup::Sweep => copy_tree(&root.join("sweep"), dir),
    }
    c.args
        .iter()
        .map(|a| match a.strip_prefix('@') {
            Some(text) => {
                std::fs::write(dir.join("s.json"), text).expect("sweep file");
                "s.json".to_string()
            }
            None => a.clone(),
        })
        .collect()
}

/// What is wrong with one finished case (None: within the contract). `before`: the directory
/// before the case ran.
fn judge(c: &Case, out: &Outcome, dir: &Path, before: &[(PathBuf, Vec<u8>)]) -> Option<String> {
    let mut problems: Vec<String> = Vec::new();
    if out.panicked() {
        problems.push("panicked or aborted".into());
    }
    if out.killed {
        problems.push("did not stop within 5 s of SIGINT".into());
    } else if let Some(sig) = out.signal() {
        if !(sig == 2 && out.interrupted_at.is_some()) {
            problems.push(format!("ended by signal {sig}"));
        }
    }
    let resume = c.command == "resume";
    match out.code() {
        Some(0) | None => {}
        Some(4..=6) if resume => {}
        // A sweep whose runs were stopped by their event or wall-clock limit.
        Some(4 | 5) if c.command == "sweep run" => {}
        Some(130) if out.interrupted_at.is_some() => {}
        // A comparison that cannot be made (a variant stopped by its event cap) fails as it
        // runs, writing nothing.
        Some(1) if c.command == "accuracy" && snapshot(dir) == before => {}
        Some(2) => {
            if !names_a_field(&out.stderr) {
                problems.push(format!(
                    "exit 2 naming no field: {:?}",
                    error_line(&out.stderr)
                ));
            }
            let after = snapshot(dir);
            if after != before {
                let names = |s: &[(PathBuf, Vec<u8>)]| -> Vec<String> {
                    s.iter().map(|(p, _)| p.display().to_string()).collect()
                };
                problems.push(format!(
                    "exit 2 but files were written or changed: before {:?}, after {:?}",
                    names(before),
                    names(&after)
                ));
            }
        }
        Some(code) => problems.push(format!("exit code {code} is not in the contract")),
    }
    (!problems.is_empty()).then(|| problems.join("; "))
}

/// Whether the error names a field or option: `vibrobed: FIELD: …`, that of a sweep's point
/// (`vibrobed: point N (AXES): FIELD: …`), a field with its value (`vibrobed: FIELD (…): …`),
/// a place in a JSON file, or an option as the command-line parser names it.
fn names_a_field(stderr: &str) -> bool {
    let line = error_line(stderr).unwrap_or("");
    let located = line.contains("field `") || line.contains(" at line ");
    let parser = stderr.contains("Usage:") || stderr.contains("--help");
    let of_a_point = line
        .strip_prefix("point ")
        .and_then(|rest| rest.split_once("): "))
        .is_some_and(|(_, rest)| error_field(&format!("vibrobed: {rest}")).is_some());
    // A sweep file's field with what it holds: `set[0] (--set …): …`.
    let with_context = line
        .split_once(" (")
        .is_some_and(|(field, _)| error_field(&format!("vibrobed: {field}: …")).is_some());
    error_field(stderr).is_some() || located || parser || of_a_point || with_context
}

#[test]
fn every_command_and_option_changed_ends_within_the_contract() {
    let root = guarded::fresh_dir("fuzz-commands");
    let budget = Budget::from_env(DEFAULT_SECONDS);
    prepare(&root.join("setup"));
    let mut lists = vec![
        resume_cases(),
        plan_cases(),
        small_sweep_cases(),
        sweep_run_cases(),
        accuracy_cases(),
    ];
    lists.extend(pair_cases(&mut Draws::seeded()));
    let all = interleave(&lists);
    let mut failures = String::new();
    let mut tally: std::collections::BTreeMap<String, usize> = Default::default();
    let mut ran = 0;
    for (i, c) in all.iter().enumerate() {
        if budget.spent() {
            break;
        }
        let dir = root.join(format!("case-{i:05}"));
        std::fs::create_dir_all(&dir).expect("case directory");
        let args = set_up(&root.join("setup"), &dir, c);
        let before = snapshot(&dir);
        let out = vibrobed(&dir, &args);
        ran += 1;
        let code = out.code().map_or("signal".into(), |k| format!("exit {k}"));
        *tally.entry(format!("{} {code}", c.command)).or_default() += 1;
        match judge(c, &out, &dir, &before) {
            Some(why) => {
                let _ = writeln!(
                    failures,
                    "\n=== case #{i} in {}: {why}\nvibrobed {}\n{}",
                    dir.display(),
                    args.join(" "),
                    out.describe()
                );
            }
            None => {
                let _ = std::fs::remove_dir_all(&dir);
            }
        }
    }
    budget.report("fuzz commands", ran, all.len(), &format!("{tally:?}"));
    assert!(failures.is_empty(), "fuzz commands:{failures}");
    let _ = std::fs::remove_dir_all(&root);
}
