//! One run from Python, as `vibrobed run` and `vibrobed resume` run it: the outputs checked
//! before it starts, the engine off the GIL on its own thread (Ctrl-C stops it cleanly), the
//! files written at the end, and the summary and the 2D fields handed back.

use crate::detached;
use crate::errors::IntoPy;
use crate::files::Files;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibrobed::measure::fields::Fields;
use vibrobed::output::summary::Summary;
use vibrobed::run::checkpoint::Checkpoint;
use vibrobed::run::{CheckpointPlan, RunOptions};
use vibrobed::Scenario;

/// What a run hands back: the summary's JSON (the command line's, byte for byte), the 2D fields
/// when they were measured, and what the Python side says at once without parsing the JSON: the
/// ending and the outputs that failed (output, error).
pub type Ran = (
    String,
    Option<Py<PyDict>>,
    String,
    Vec<(&'static str, String)>,
);

/// What a run starts from, beside its scenario and its files.
pub struct Start {
    /// Where and how often to checkpoint.
    pub checkpoint: Option<CheckpointPlan>,
    /// The checkpoint a resume continues.
    pub resume: Option<Box<Checkpoint>>,
    /// Measure the 2D fields even when no file is asked for.
    pub measure_fields: bool,
    /// Progress on stderr.
    pub progress: bool,
    /// Wall seconds between progress lines off a terminal (default: the command line's).
    pub progress_every: Option<f64>,
}

/// Runs `s` (its outputs already checked), writes the files of `files`, and hands back the
/// summary and the fields.
pub fn simulate(py: Python<'_>, s: &Scenario, files: &Files, start: Start) -> PyResult<Ran> {
    let stop = detached::stop_flag();
    let Start {
        checkpoint,
        resume,
        measure_fields,
        progress,
        progress_every,
    } = start;
    let (rrd, trajectory) = (files.rrd.clone(), files.trajectory.clone());
    let written_after = files.written_after();
    let fields = measure_fields || files.fields.is_some();
    let fields_file = files.fields.clone();
    let summary = detached::run(py, stop, move || {
        vibrobed::run::run(
            s,
            RunOptions {
                rrd,
                trajectory,
                sink: None,
                interrupt: Some(stop),
                checkpoint,
                resume,
                progress,
                progress_every,
                progress_label: None,
                fields,
                fields_file,
                written_after,
            },
        )
    })?
    .py()?;
    files.write(&summary).py()?;
    ran(py, &summary)
}

/// The summary's JSON, the fields as numpy arrays, the ending and the failed outputs.
pub fn ran(py: Python<'_>, summary: &Summary) -> PyResult<Ran> {
    let fields = summary
        .fields
        .as_ref()
        .map(|f| fields_dict(py, f))
        .transpose()?;
    let failures = summary
        .output_failures
        .iter()
        .map(|f| (f.output, f.error.clone()))
        .collect();
    // The ending's name as the summary writes it (`event-limit`, …).
    let ending = serde_json::to_value(summary.ending)
        .ok()
        .and_then(|v| v.as_str().map(str::to_owned))
        .expect("an ending serialises as its name");
    Ok((summary.to_json(), fields, ending, failures))
}

/// The 2D fields: `x` (the cells' centres across, `nx`) and `y` (up, `ny`), and each quantity
/// as an `ny × nx` array (row j at height `y[j]`; NaN where it is undefined).
fn fields_dict(py: Python<'_>, f: &Fields) -> PyResult<Py<PyDict>> {
    let g = *f.grid();
    let out = PyDict::new(py);
    let x: Vec<f64> = (0..g.nx).map(|i| g.centre(i, 0)[0]).collect();
    let y: Vec<f64> = (0..g.ny).map(|j| g.centre(0, j)[1]).collect();
    out.set_item("x", PyArray1::from_vec(py, x))?;
    out.set_item("y", PyArray1::from_vec(py, y))?;
    for (name, values) in vibrobed::output::fields::columns(f) {
        let grid = PyArray1::from_vec(py, values).reshape([g.ny, g.nx])?;
        out.set_item(name, grid)?;
    }
    Ok(out.unbind())
}
