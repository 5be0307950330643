//! Frames while a run goes: the engine runs on its own thread and hands each frame (at
//! `output.frame_interval`) to a bounded queue, from which Python iterates them as numpy arrays,
//! without a trajectory file. The engine waits while the queue is full, so a slow reader slows
//! the run rather than filling the memory. The disks are copied once per frame: the engine
//! reuses its snapshot.

use crate::detached::{self, POLL, STACK};
use crate::errors::IntoPy;
use crate::given::Given;
use crate::running::{ran, Ran};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError, SyncSender};
use std::sync::Mutex;
use std::thread::JoinHandle;
use vibrobed::output::frame::FrameView;
use vibrobed::output::summary::Summary;
use vibrobed::run::{FrameSink, RunOptions};

/// One frame, owned: the disks in the scene at `time`, by row.
struct Frame {
    index: u64,
    time: f64,
    /// Each row's disk id.
    ids: Vec<u32>,
    /// `x, y` of each row, interleaved.
    positions: Vec<f64>,
    /// `vx, vy` of each row, interleaved.
    velocities: Vec<f64>,
    /// `angle, ω` of each row, interleaved (rough disks).
    spins: Option<Vec<f64>>,
    floor_height: Option<f64>,
    series: Vec<(&'static str, f64)>,
}

impl Frame {
    /// The disks of `view` that are in the scene. Where disks leave, the view holds an entry
    /// per id, those not in the scene at NaN: they are left out.
    fn of(view: &FrameView) -> Frame {
        let rows: Vec<usize> = (0..view.x.len()).filter(|&k| !view.x[k].is_nan()).collect();
        let pairs = |a: &[f64], b: &[f64]| rows.iter().flat_map(|&k| [a[k], b[k]]).collect();
        let id = |k: usize| view.ids.get(k).map_or(k as u32, |&i| i);
        // Spins come by row of the live disks; they match only where every row is a live disk.
        let spins = view
            .spins
            .filter(|s| s.len() == view.x.len() && rows.len() == view.x.len())
            .map(|s| s.iter().flat_map(|&(a, w)| [a, w]).collect());
        Frame {
            index: view.index,
            time: view.time,
            ids: rows.iter().map(|&k| id(k)).collect(),
            positions: pairs(view.x, view.y),
            velocities: pairs(view.vx, view.vy),
            spins,
            floor_height: view.floor_height,
            series: view.series.to_vec(),
        }
    }

    /// The frame as a dict of numpy arrays (`positions`, `velocities`, `spins`: n × 2).
    fn into_py(self, py: Python<'_>) -> PyResult<Py<PyDict>> {
        let n = self.ids.len();
        let d = PyDict::new(py);
        d.set_item("index", self.index)?;
        d.set_item("time", self.time)?;
        d.set_item("ids", PyArray1::from_vec(py, self.ids))?;
        d.set_item(
            "positions",
            PyArray1::from_vec(py, self.positions).reshape([n, 2])?,
        )?;
        d.set_item(
            "velocities",
            PyArray1::from_vec(py, self.velocities).reshape([n, 2])?,
        )?;
        let spins = self
            .spins
            .map(|s| PyArray1::from_vec(py, s).reshape([n, 2]))
            .transpose()?;
        d.set_item("spins", spins)?;
        d.set_item("floor_height", self.floor_height)?;
        let series = PyDict::new(py);
        for (name, value) in self.series {
            series.set_item(name, value)?;
        }
        d.set_item("series", series)?;
        Ok(d.unbind())
    }
}

/// The engine's frame sink: each frame into the queue (waiting while it is full).
struct Queue(SyncSender<Frame>);

impl FrameSink for Queue {
    fn frame(&mut self, frame: &FrameView) -> vibrobed::Result<()> {
        self.0
            .send(Frame::of(frame))
            .map_err(|_| vibrobed::Error::Io("the frames are no longer read".into()))
    }
    fn log_text(&mut self, _time: f64, _level: &str, _text: &str) -> vibrobed::Result<()> {
        Ok(())
    }
    fn finish(self: Box<Self>) -> vibrobed::Result<()> {
        Ok(())
    }
}

/// A run under way, iterated frame by frame; `finish` waits for its end and hands back what
/// `run` hands back.
#[pyclass(module = "vibrobed._vibrobed")]
pub struct Frames {
    /// The queue; `None` once the run has ended and been joined.
    queue: Mutex<Option<Receiver<Frame>>>,
    /// The engine's thread.
    thread: Mutex<Option<JoinHandle<vibrobed::Result<Summary>>>>,
    /// The run's stop flag.
    stop: &'static AtomicBool,
}

#[pymethods]
impl Frames {
    /// Starts the run of `path` (or of `text`) with `sets`, its frames through a queue of
    /// `queue` frames.
    #[new]
    #[pyo3(signature = (path=None, text=None, sets=Vec::new(), queue=4))]
    fn new(
        path: Option<std::path::PathBuf>,
        text: Option<String>,
        sets: Vec<String>,
        queue: usize,
    ) -> PyResult<Frames> {
        let s = Given::new(path, text, sets)
            .and_then(|g| g.scenario())
            .py()?;
        let stop = detached::stop_flag();
        let (tx, rx) = sync_channel(queue.max(1));
        let thread = std::thread::Builder::new()
            .name("vibrobed-frames".into())
            .stack_size(STACK)
            .spawn(move || {
                vibrobed::run::run(
                    &s,
                    RunOptions {
                        sink: Some(Box::new(Queue(tx))),
                        interrupt: Some(stop),
                        ..Default::default()
                    },
                )
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start the run's thread: {e}")))?;
        Ok(Frames {
            queue: Mutex::new(Some(rx)),
            thread: Mutex::new(Some(thread)),
            stop,
        })
    }

    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    /// The next frame, waiting for it with the GIL released; Ctrl-C stops the run (the frames
    /// already queued can still be read, and `finish` gives the interrupted result).
    fn __next__(&self, py: Python<'_>) -> PyResult<Option<Py<PyDict>>> {
        loop {
            let queue = &self.queue;
            let got = py.detach(|| {
                let queue = queue.lock().expect("one reader");
                queue.as_ref().map(|rx| rx.recv_timeout(POLL))
            });
            match got {
                Some(Ok(frame)) => return frame.into_py(py).map(Some),
                None | Some(Err(RecvTimeoutError::Disconnected)) => return Ok(None),
                Some(Err(RecvTimeoutError::Timeout)) => {}
            }
            if let Err(e) = py.check_signals() {
                self.stop.store(true, Ordering::Relaxed);
                return Err(e);
            }
        }
    }

    /// Stops the run at its next event (its result is then marked interrupted).
    fn stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
    }

    /// Waits for the run's end, dropping the frames not read, and hands back its summary's
    /// JSON and its fields (as `run` does).
    fn finish(&self, py: Python<'_>) -> PyResult<Ran> {
        let thread = self.thread.lock().expect("one caller").take();
        let Some(thread) = thread else {
            return Err(PyRuntimeError::new_err(
                "this run's result was already taken",
            ));
        };
        let queue = self.queue.lock().expect("one reader").take();
        let stop = self.stop;
        let summary = detached::run(py, stop, move || {
            // Drain the queue, so that the engine never waits on a full one, until it closes.
            if let Some(rx) = queue {
                while rx.recv().is_ok() {}
            }
            thread.join()
        })?
        .map_err(|_| PyRuntimeError::new_err("the run's thread panicked"))?
        .py()?;
        ran(py, &summary)
    }
}

impl Drop for Frames {
    /// A run dropped before its end is stopped, and its thread joined.
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        let queue = self.queue.get_mut().ok().and_then(Option::take);
        drop(queue);
        if let Some(thread) = self.thread.get_mut().ok().and_then(Option::take) {
            let _ = thread.join();
        }
    }
}
