//! `vibrobed._vibrobed`: the native part of the Python package. It calls the vibrobed library as
//! the command line does — the same checks, messages, engine and outputs — and hands results
//! back as JSON text and numpy arrays; python/vibrobed/ wraps it into the Python API (dicts,
//! DataFrames, the `Result` and `Frame` types).

mod detached;
mod errors;
mod files;
mod frames;
mod given;
mod running;
mod sweep;

use errors::IntoPy;
use files::Files;
use given::Given;
use pyo3::prelude::*;
use running::{simulate, Ran, Start};
use std::collections::HashMap;
use std::path::PathBuf;
use vibrobed::cli::{output_paths, resumed, OutputArgs};
use vibrobed::run::CheckpointPlan;
use vibrobed::scenario::intervals;

/// The typed scenario as JSON (every default filled in) and its advisories (what the command
/// line prints as notes).
#[pyfunction]
#[pyo3(signature = (path=None, text=None, sets=Vec::new()))]
fn load(
    path: Option<PathBuf>,
    text: Option<String>,
    sets: Vec<String>,
) -> PyResult<(String, Vec<String>)> {
    let s = Given::new(path, text, sets)
        .and_then(|g| g.scenario())
        .py()?;
    let json = serde_json::to_string(&s).expect("a scenario serialises");
    Ok((json, s.advisories()))
}

/// `vibrobed check`: the scenario, its scene and engine built without running; the disk count.
#[pyfunction]
#[pyo3(signature = (path=None, text=None, sets=Vec::new()))]
fn check(
    py: Python<'_>,
    path: Option<PathBuf>,
    text: Option<String>,
    sets: Vec<String>,
) -> PyResult<usize> {
    let s = Given::new(path, text, sets)
        .and_then(|g| g.scenario())
        .py()?;
    py.detach(|| vibrobed::run::check(&s)).py()?;
    output_paths(&s, &OutputArgs::default()).py()?;
    Ok(s.disk_count())
}

/// `vibrobed run`: `files` maps option names (`rrd`, `summary`, `profiles`, `fields`,
/// `trajectory`, `checkpoint`) to paths.
#[pyfunction]
#[pyo3(signature = (path=None, text=None, sets=Vec::new(), files=HashMap::new(),
                    checkpoint_every=None, measure_fields=false, progress=false,
                    progress_every=None))]
#[allow(clippy::too_many_arguments)]
fn run(
    py: Python<'_>,
    path: Option<PathBuf>,
    text: Option<String>,
    sets: Vec<String>,
    files: HashMap<String, PathBuf>,
    checkpoint_every: Option<f64>,
    measure_fields: bool,
    progress: bool,
    progress_every: Option<f64>,
) -> PyResult<Ran> {
    intervals::progress_every(progress_every).py()?;
    let scenario_file = path.clone();
    let given = Given::new(path, text, sets).py()?;
    let s = given.scenario().py()?;
    let files = Files::from_map(files).py()?;
    let inputs = match &scenario_file {
        Some(path) => vec![("SCENARIO", path.as_path())],
        None => Vec::new(),
    };
    output_paths(&s, &files.args(inputs)).py()?;
    let checkpoint = files.checkpoint.clone().map(|path| CheckpointPlan {
        path,
        every: checkpoint_every,
        scenario: given.text.clone(),
        source: given.source.clone(),
        sets: given.sets.clone(),
    });
    let start = Start {
        checkpoint,
        resume: None,
        measure_fields,
        progress,
        progress_every,
    };
    simulate(py, &s, &files, start)
}

/// `vibrobed resume`: continues the run a checkpoint holds (`sets`: only `run.duration` and
/// `run.max_events`).
#[pyfunction]
#[pyo3(signature = (checkpoint_file, sets=Vec::new(), files=HashMap::new(),
                    checkpoint_every=None, progress=false, progress_every=None))]
fn resume(
    py: Python<'_>,
    checkpoint_file: PathBuf,
    sets: Vec<String>,
    files: HashMap<String, PathBuf>,
    checkpoint_every: Option<f64>,
    progress: bool,
    progress_every: Option<f64>,
) -> PyResult<Ran> {
    intervals::progress_every(progress_every).py()?;
    let files = Files::from_map(files).py()?;
    let (s, plan, ck) = resumed(
        &checkpoint_file,
        &sets,
        files.rrd.as_deref(),
        files.trajectory.as_deref(),
        files.checkpoint.clone(),
        checkpoint_every,
    )
    .py()?;
    output_paths(&s, &files.args(vec![("CHECKPOINT", &checkpoint_file)])).py()?;
    let start = Start {
        checkpoint: Some(plan),
        resume: Some(ck),
        measure_fields: false,
        progress,
        progress_every,
    };
    simulate(py, &s, &files, start)
}

/// `vibrobed sweep run`: (ran now, done before, interrupted, failed, ended early). With `text`
/// (a sweep given as a dict), `sweep` is where the text is written once it is known good.
#[pyfunction]
#[pyo3(signature = (sweep, out, jobs=None, progress=false, progress_every=None,
                    max_run_seconds=None, text=None))]
#[allow(clippy::too_many_arguments)]
fn sweep_run(
    py: Python<'_>,
    sweep: PathBuf,
    out: PathBuf,
    jobs: Option<usize>,
    progress: bool,
    progress_every: Option<f64>,
    max_run_seconds: Option<f64>,
    text: Option<String>,
) -> PyResult<sweep::Report> {
    intervals::progress_every(progress_every).py()?;
    let limits = sweep::Limits {
        progress_every,
        max_run_seconds,
    };
    sweep::run(py, &sweep, text.as_deref(), &out, jobs, progress, limits)
}

/// `vibrobed sweep collect` without a plot: `runs.csv` and `points.csv` as text.
#[pyfunction]
fn sweep_collect(py: Python<'_>, out: PathBuf) -> PyResult<(String, String)> {
    py.detach(|| sweep::collect(&out)).py()
}

#[pymodule]
fn _vibrobed(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("ScenarioError", m.py().get_type::<errors::ScenarioError>())?;
    m.add_class::<frames::Frames>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(resume, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_run, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_collect, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
