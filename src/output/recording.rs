//! The Rerun recording sink: streams frames to a `.rrd` file that opens ready to read in the
//! Rerun viewer (`rerun OUT.rrd`, same version as the `rerun` crate, 0.36.3).
//!
//! # What the file holds
//!
//! | entity                          | kind     | content                                          |
//! |---------------------------------|----------|--------------------------------------------------|
//! | `disks`                         | temporal | `Points2D`: centres, radii, colours (by speed or species), class ids = species; instance i is disk i in every frame |
//! | `disks`                         | static   | `AnnotationContext` (species names and colours), y-up `Transform3D` |
//! | `scene`                         | static   | y-up `Transform3D` for everything under it       |
//! | `scene/walls`                   | static   | `LineStrips2D`: hard walls at x = 0 and x = width |
//! | `scene/periodic_edges`          | static   | `LineStrips2D`: the periodic edges x = 0 and x = width, dim |
//! | `scene/lid`                     | static   | `LineStrips2D`: the lid at y = top (lid scenes only) |
//! | `scene/floor`                   | temporal | `LineStrips2D`: the floor at its current height  |
//! | `scene/speed_scale`             | static   | `LineStrips2D` and labelled `Points2D`: the colour scale (colouring by speed) |
//! | `scene/clock`                   | static + temporal | `Points2D` at the bed's top left (static), its label `t = …` per frame: the simulated time as a plain number |
//! | `profiles/packing_fraction`     | temporal | `LineStrips2D`: (φ, height) of the frame, one point per bin |
//! | `profiles/temperature`          | temporal | `LineStrips2D`: ((Tx + Ty)/2, height), bins holding disks |
//! | `profiles/<name>/axes`          | static   | `LineStrips2D` and labelled `Points2D`: axes, ticks, titles |
//! | `series/<name>`                 | temporal | `Scalars`: one value per frame                   |
//! | `legend`                        | static   | `TextDocument` (Markdown): what the colours and views show |
//! | `log`                           | temporal | `TextLog`: notable events                        |
//!
//! Timelines: sequence `frame` (the frame index) and duration `sim_time` (simulated time, stored
//! with nanosecond resolution). The wall-clock `log_time` timeline is disabled so that the file
//! content depends on the simulated run only. The viewer opens on `frame`: Rerun 0.36 has no
//! timeline kind for a real number, and writes a duration as minutes and seconds (`+3m 20s` for
//! t = 200), whereas a sequence is a plain number (`#200`). The simulated time itself is written
//! as a plain number on the bed (`scene/clock`, `t = 200`), and `sim_time` keeps it exactly for
//! tools and for anyone who picks it in the viewer.
//!
//! Rerun's 2D views draw y downwards; `disks`, `scene` and each profile carry a static
//! `Transform3D` with a y scale of −1 so that gravity points down on screen (a profile's also
//! stretches its values across the width of its view). The logged data themselves are the
//! simulation coordinates and the measured values, which is what [`read_back`] returns.
//!
//! Walls for an open top have no natural height: they are drawn up to 1.25 × the highest disk
//! top (or floor) seen so far, and re-logged as static data whenever a disk climbs above them.
//!
//! # Layout
//!
//! The blueprint, sent with the first frame, puts the bed on top across the whole width, fitted
//! to the domain's width and to the height of the profiles (`output.profile_height`, else twice
//! the initial bed), or to three times the first frame's bed without profiles, or to the lid:
//! the bed, not the empty sky. Below it: packing fraction and granular temperature against
//! height (same heights as the bed), the time series (one view per group, i.e. per first path
//! segment of the series names), the legend and the text log. Blueprint, selection and time
//! panels start collapsed; the timeline is `frame`, following the data: a finished file opens on
//! its last frame (press play or drag the time cursor to go through the run).
//!
//! # Cost
//!
//! [`RerunRecorder::frame`] copies the frame into a recycled buffer and hands it to a writer
//! thread (started with the first frame) over a bounded channel: the simulation waits only when
//! the writer is [`QUEUE`] frames behind (fewer for large frames, see [`QUEUE_BYTES`]). The
//! writer gathers [`BATCH`] frames and logs them column-wise (`send_columns`: one chunk per
//! entity per batch), so that Rerun's batcher has little left to do.
//!
//! # Completeness of the file
//!
//! The footer (with the chunk manifest) is written when the underlying `RecordingStream` is
//! dropped. [`RerunRecorder::finish`] drains the queue, flushes, drops the stream and reports
//! errors; simply dropping a `RerunRecorder` (e.g. while unwinding from an error) also drains
//! the queue and completes the file. Only a process that exits without running destructors
//! (`std::process::exit`, default SIGINT handling, abort) leaves a file without its footer.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::sync::mpsc::{self, Receiver, Sender, SyncSender};
use std::thread::JoinHandle;

use rerun::blueprint::components::{PanelState, PlayState};
use rerun::blueprint::{
    Blueprint, BlueprintActivation, BlueprintPanel, ContainerLike, Horizontal, SelectionPanel,
    Spatial2DView, TextDocumentView, TextLogView, TimePanel, TimeSeriesView, Vertical,
};
use rerun::components::{
    ClassId, Color, LineStrip2D, MediaType, Position2D, Radius, Scalar, Text, TextLogLevel,
};
use rerun::datatypes::{ClassDescriptionMapElem, Rgba32};
use rerun::external::re_log_encoding::DecoderApp;
use rerun::external::re_sdk_types::blueprint::archetypes::{TimePanelBlueprint, VisualBounds2D};
use rerun::external::re_sdk_types::blueprint::components::TimelineName as BlueprintTimelineName;
use rerun::external::re_sdk_types::blueprint::components::VisualBounds2D as VisualBounds2DComponent;
use rerun::external::re_sdk_types::datatypes::{Range1D, Range2D};
use rerun::log::{Chunk, LogMsg, TimeColumn};
use rerun::time::{TimeCell, TimelineName};
use rerun::{
    AnnotationContext, LineStrips2D, Points2D, RecordingStream, RecordingStreamBuilder, Scalars,
    TextDocument, TextLog, Transform3D,
};

use super::frame::{ColorBy, FrameView, SceneLayout};
use crate::measure::ProfileTable;

/// Application id written into the recording.
pub const APPLICATION_ID: &str = "vibrobed";
/// Name of the sequence timeline holding the frame index.
pub const FRAME_TIMELINE: &str = "frame";
/// Name of the duration timeline holding the simulated time.
pub const SIM_TIME_TIMELINE: &str = "sim_time";
/// Entity of the disks.
pub const DISKS_ENTITY: &str = "disks";
/// Entity of the walls (static).
pub const WALLS_ENTITY: &str = "scene/walls";
/// Entity of the periodic edges (static).
pub const PERIODIC_EDGES_ENTITY: &str = "scene/periodic_edges";
/// Entity of the lid (static).
pub const LID_ENTITY: &str = "scene/lid";
/// Entity of the floor (one line per frame).
pub const FLOOR_ENTITY: &str = "scene/floor";
/// Entity of the colour scale drawn in the bed view (static).
pub const SPEED_SCALE_ENTITY: &str = "scene/speed_scale";
/// Entity of the clock: the simulated time of the frame, written at the bed's top left.
pub const CLOCK_ENTITY: &str = "scene/clock";
/// Entity of the packing-fraction profile (one line strip per frame).
pub const PACKING_PROFILE_ENTITY: &str = "profiles/packing_fraction";
/// Entity of the temperature profile (one line strip per frame).
pub const TEMPERATURE_PROFILE_ENTITY: &str = "profiles/temperature";
/// Prefix of the time-series entities: series `name` goes to `series/<name>`.
pub const SERIES_PREFIX: &str = "series";
/// Entity of the legend (static Markdown text).
pub const LEGEND_ENTITY: &str = "legend";
/// Entity of the text log.
pub const LOG_ENTITY: &str = "log";

/// Frames the simulation may run ahead of the writer thread before it waits (fewer for large
/// frames: at most [`QUEUE_BYTES`] of them, and at least 2).
pub const QUEUE: usize = 64;
/// Bytes of queued frames above which the queue is shortened.
pub const QUEUE_BYTES: usize = 64 << 20;
/// Frames logged together, column-wise, by the writer thread (fewer when they hold more than
/// 2²⁰ disks together).
pub const BATCH: usize = 32;
/// Disk positions gathered at most before a batch is logged.
const BATCH_POINTS: usize = 1 << 20;

/// Colours of species 0, 1, … (cycled), also used for the annotation context.
const SPECIES_PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];
const WALL_COLOR: [u8; 3] = [170, 170, 170];
const EDGE_COLOR: [u8; 3] = [90, 90, 90];
const FLOOR_COLOR: [u8; 3] = [230, 140, 30];
const AXIS_COLOR: [u8; 3] = [150, 150, 150];
const PACKING_COLOR: [u8; 3] = [80, 170, 255];
const TEMPERATURE_COLOR: [u8; 3] = [255, 110, 80];
const CLOCK_COLOR: [u8; 3] = [230, 230, 230];
/// Width of a profile view in units of its height range (its values are stretched to it).
const PROFILE_ASPECT: f64 = 0.6;

fn err(context: &str, e: impl std::fmt::Display) -> String {
    format!("rerun recording: {context}: {e}")
}

fn rgb(c: [u8; 3]) -> Color {
    Color::from_rgb(c[0], c[1], c[2])
}

/// Blue (at rest) → light grey → red (`t` ≥ 1), `t` = speed / scale, clamped ("coolwarm").
pub fn speed_color(t: f64) -> Color {
    const STOPS: [[f64; 3]; 3] = [
        [59.0, 76.0, 192.0],
        [221.0, 221.0, 221.0],
        [180.0, 4.0, 38.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let (a, b, s) = if t < 0.5 {
        (STOPS[0], STOPS[1], t * 2.0)
    } else {
        (STOPS[1], STOPS[2], t * 2.0 - 1.0)
    };
    let mix = |i: usize| (a[i] + (b[i] - a[i]) * s).round() as u8;
    Color::from_rgb(mix(0), mix(1), mix(2))
}

fn line(points: [[f64; 2]; 2]) -> [[f32; 2]; 2] {
    points.map(|[x, y]| [x as f32, y as f32])
}

fn nanos(time: f64) -> i64 {
    // Nanosecond resolution; negative times are allowed.
    let n = (time * 1e9).round();
    if n.is_finite() {
        n.clamp(-9.0e18, 9.0e18) as i64
    } else {
        0
    }
}

/// A short label for an axis tick or a speed: `0`, `0.25`, `1.9`, `120`.
fn tick_label(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// A "nice" axis end at or above `v` (1, 2, 2.5 or 5 times a power of ten).
fn nice_ceiling(v: f64) -> f64 {
    if !(v.is_finite() && v > 0.0) {
        return 1.0;
    }
    let p = 10f64.powf(v.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|&c| c >= v * (1.0 - 1e-12))
        .unwrap_or(10.0 * p)
}

/// The clock's label for simulated time `time`: `t = 137`, `t = 0.45`, with the digits that tell
/// frames `step` apart (one more than the step's first significant digit), trailing zeros
/// dropped; three decimals when the step is not known (the first frame).
pub fn clock_label(time: f64, step: Option<f64>) -> String {
    let decimals = step
        .filter(|s| s.is_finite() && *s > 0.0)
        .map_or(3, |s| ((-s.log10()).ceil() as i64 + 1).clamp(0, 9) as usize);
    let s = format!("{time:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    format!("t = {}", if s == "-0" { "0" } else { s })
}

/// A frame owned by the queue (the buffers are recycled).
#[derive(Debug, Default)]
struct FrameBuf {
    index: u64,
    time: f64,
    x: Vec<f64>,
    y: Vec<f64>,
    vx: Vec<f64>,
    vy: Vec<f64>,
    radius: Vec<f64>,
    species: Vec<u32>,
    floor_height: Option<f64>,
    series: Vec<(&'static str, f64)>,
    profile: Option<ProfileTable>,
}

impl FrameBuf {
    fn fill(&mut self, f: &FrameView) {
        fn copy<T: Copy>(dst: &mut Vec<T>, src: &[T]) {
            dst.clear();
            dst.extend_from_slice(src);
        }
        self.index = f.index;
        self.time = f.time;
        copy(&mut self.x, f.x);
        copy(&mut self.y, f.y);
        copy(&mut self.vx, f.vx);
        copy(&mut self.vy, f.vy);
        copy(&mut self.radius, f.radius);
        copy(&mut self.species, f.species);
        self.floor_height = f.floor_height;
        copy(&mut self.series, f.series);
        self.profile = f.profile.cloned();
    }
}

/// What the simulation sends to the writer thread.
enum Msg {
    Frame(Box<FrameBuf>),
    Text {
        time: f64,
        level: String,
        text: String,
    },
}

/// Streams a simulation to a Rerun `.rrd` file. See the [module documentation](self) for the
/// file layout. Only compiled with the `record` feature.
pub struct RerunRecorder {
    /// The writer before the first frame (it then moves to its thread).
    pending: Option<Writer>,
    tx: Option<SyncSender<Msg>>,
    /// Buffers the writer is done with.
    recycled: Option<Receiver<Box<FrameBuf>>>,
    worker: Option<JoinHandle<Result<(), String>>>,
    layout: SceneLayout,
    color_by: ColorBy,
}

impl std::fmt::Debug for RerunRecorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RerunRecorder")
            .field("layout", &self.layout)
            .field("color_by", &self.color_by)
            .finish_non_exhaustive()
    }
}

impl RerunRecorder {
    /// Opens `path` for writing (truncating it), disables the wall-clock `log_time` timeline,
    /// logs the static scene (y-up transforms, the species annotation context, the walls or
    /// periodic edges, the lid, the colour scale) and starts the writer thread.
    pub fn create(path: &Path, layout: &SceneLayout, color_by: ColorBy) -> Result<Self, String> {
        Self::create_with_id(path, layout, color_by, None)
    }

    /// As [`create`](Self::create), with a given recording id: a run resumed from a checkpoint
    /// writes its frames to a new file under the id of the recording it continues, so that the
    /// viewer, given both files, shows them as one recording.
    pub fn create_with_id(
        path: &Path,
        layout: &SceneLayout,
        color_by: ColorBy,
        recording_id: Option<&str>,
    ) -> Result<Self, String> {
        let mut builder = RecordingStreamBuilder::new(APPLICATION_ID);
        if let Some(id) = recording_id {
            builder = builder.recording_id(id);
        }
        let rec = builder
            .recording_name(layout.name.clone())
            // An explicit `--rrd` wins over a `RERUN=0` environment variable.
            .enabled(true)
            .save(path)
            .map_err(|e| err(&format!("cannot create {}", path.display()), e))?;
        rec.set_log_time_enabled(false);
        let mut writer = Writer {
            rec,
            layout: layout.clone(),
            color_by,
            wall_height: None,
            last_radii: Vec::new(),
            last_species: Vec::new(),
            blueprint_sent: false,
            legend_pending: None,
            last_frame: None,
            last_time: None,
            step: None,
            batch: Batch::default(),
        };
        writer.log_static_scene()?;
        Ok(Self {
            pending: Some(writer),
            tx: None,
            recycled: None,
            worker: None,
            layout: layout.clone(),
            color_by,
        })
    }

    /// Starts the writer thread, with a queue sized for frames of `disks` disks.
    fn start(&mut self, disks: usize) -> Result<(), String> {
        let Some(writer) = self.pending.take() else {
            return Ok(());
        };
        let frame_bytes = 6 * 8 * disks + 1;
        let (tx, rx) = mpsc::sync_channel::<Msg>((QUEUE_BYTES / frame_bytes).clamp(2, QUEUE));
        let (recycle_tx, recycled) = mpsc::channel();
        let worker = std::thread::Builder::new()
            .name("vibrobed-rrd".into())
            .spawn(move || writer.run(rx, recycle_tx))
            .map_err(|e| err("cannot start the writer thread", e))?;
        self.tx = Some(tx);
        self.recycled = Some(recycled);
        self.worker = Some(worker);
        Ok(())
    }

    /// Hands `msg` to the writer (on this thread before the first frame); when the writer has
    /// stopped (after an error), returns its error.
    fn send(&mut self, msg: Msg) -> Result<(), String> {
        if let Some(writer) = self.pending.as_mut() {
            return match msg {
                Msg::Text { time, level, text } => writer.text(time, &level, &text),
                Msg::Frame(_) => Err(err("send", "the writer thread was not started")),
            };
        }
        let sent = self
            .tx
            .as_ref()
            .ok_or_else(|| err("send", "the recording is closed"))?
            .send(msg);
        if sent.is_err() {
            self.tx = None;
            return Err(self
                .join()
                .err()
                .unwrap_or_else(|| err("send", "the writer thread stopped")));
        }
        Ok(())
    }

    /// Closes the queue and waits for the writer thread, which completes the file (or, before
    /// the first frame, completes it on this thread).
    fn join(&mut self) -> Result<(), String> {
        if let Some(mut writer) = self.pending.take() {
            return writer.close();
        }
        self.tx = None;
        match self.worker.take() {
            Some(worker) => worker
                .join()
                .unwrap_or_else(|_| Err(err("writer thread", "panicked"))),
            None => Ok(()),
        }
    }

    /// Queues one frame, written on timelines `frame` = `f.index` and `sim_time` = `f.time`:
    /// the disks, the floor line (when `f.floor_height` is `Some`), the profiles (when
    /// `f.profile` is `Some`) and every series value under `series/<name>`. Fails when the
    /// per-disk slices have different lengths, or with the writer's error once it failed.
    pub fn frame(&mut self, f: &FrameView) -> Result<(), String> {
        let n = f.x.len();
        if f.y.len() != n || f.vx.len() != n || f.vy.len() != n || f.radius.len() != n {
            return Err(format!(
                "rerun recording: frame {}: per-disk slices differ in length (x {}, y {}, vx {}, vy {}, radius {})",
                f.index,
                n,
                f.y.len(),
                f.vx.len(),
                f.vy.len(),
                f.radius.len()
            ));
        }
        if !f.species.is_empty() && f.species.len() != n {
            return Err(format!(
                "rerun recording: frame {}: {} species for {} disks",
                f.index,
                f.species.len(),
                n
            ));
        }
        self.start(n)?;
        let mut buf = self
            .recycled
            .as_ref()
            .and_then(|r| r.try_recv().ok())
            .unwrap_or_default();
        buf.fill(f);
        self.send(Msg::Frame(buf))
    }

    /// Logs a line of text under `log` at simulated time `time` (on the `frame` timeline, the
    /// last frame queued before it, or the next frame when it is due at `time`; frame 0 before
    /// the first frame). `level` is a Rerun level (`TRACE`, `DEBUG`, `INFO`,
    /// `WARN`, `ERROR`, `CRITICAL`; case-insensitive, `warning` means `WARN`).
    pub fn log_text(&mut self, time: f64, level: &str, text: &str) -> Result<(), String> {
        let level = match level.to_ascii_uppercase().as_str() {
            "WARNING" => TextLogLevel::WARN.to_owned(),
            other => other.to_owned(),
        };
        self.send(Msg::Text {
            time,
            level,
            text: text.to_owned(),
        })
    }

    /// Writes what is queued, sends the blueprint if no frame was written, flushes everything
    /// to disk and closes the file, writing its footer. Dropping a `RerunRecorder` without
    /// calling this also completes the file, but silently.
    pub fn finish(mut self) -> Result<(), String> {
        self.join()
    }
}

impl Drop for RerunRecorder {
    /// A recorder dropped without [`finish`](Self::finish) (an error or a panic in the run)
    /// still writes what is queued and completes the file, laid out.
    fn drop(&mut self) {
        let _ = self.join();
    }
}

/// Values of one entity gathered over a batch, with their times.
#[derive(Debug)]
struct Column<T> {
    frames: Vec<i64>,
    nanos: Vec<i64>,
    values: Vec<T>,
}

impl<T> Default for Column<T> {
    fn default() -> Self {
        Self {
            frames: Vec::new(),
            nanos: Vec::new(),
            values: Vec::new(),
        }
    }
}

impl<T> Column<T> {
    fn push(&mut self, frame: i64, nanos: i64, value: T) {
        self.frames.push(frame);
        self.nanos.push(nanos);
        self.values.push(value);
    }

    /// The time columns, leaving the column empty (its buffers kept).
    fn take_times(&mut self) -> [TimeColumn; 2] {
        [
            TimeColumn::new_sequence(FRAME_TIMELINE, self.frames.drain(..)),
            TimeColumn::new_duration_nanos(SIM_TIME_TIMELINE, self.nanos.drain(..)),
        ]
    }
}

/// Frames gathered by the writer thread, logged together.
#[derive(Debug, Default)]
struct Batch {
    /// Disk positions of all frames, one after the other; `values` holds each frame's count.
    disks: Column<usize>,
    positions: Vec<[f32; 2]>,
    colors: Vec<Color>,
    floor: Column<LineStrip2D>,
    packing: Column<LineStrip2D>,
    temperature: Column<LineStrip2D>,
    series: BTreeMap<&'static str, Column<f64>>,
    /// The clock's label of each frame.
    clock: Column<String>,
}

/// The writer thread's side: the stream and what has been logged so far.
struct Writer {
    rec: RecordingStream,
    layout: SceneLayout,
    color_by: ColorBy,
    /// Height the walls are currently drawn to (open top only).
    wall_height: Option<f64>,
    /// Radii last logged (re-logged only on change).
    last_radii: Vec<f64>,
    /// Species last logged (re-logged only on change).
    last_species: Vec<u32>,
    blueprint_sent: bool,
    /// The legend waits for the second frame, which tells the time between frames; it holds
    /// whether the scene has profiles.
    legend_pending: Option<bool>,
    /// Index of the last frame logged.
    last_frame: Option<i64>,
    /// Simulated time of the last frame logged.
    last_time: Option<f64>,
    /// Simulated time between the first two frames.
    step: Option<f64>,
    batch: Batch,
}

impl Writer {
    /// Logs the queued messages until the queue closes, then completes the file.
    fn run(mut self, rx: Receiver<Msg>, recycle: Sender<Box<FrameBuf>>) -> Result<(), String> {
        let mut result = Ok(());
        for msg in rx {
            let step = match msg {
                Msg::Frame(buf) => {
                    let r = self.frame(&buf);
                    let _ = recycle.send(buf);
                    r
                }
                Msg::Text { time, level, text } => self.text(time, &level, &text),
            };
            if let Err(e) = step {
                result = Err(e);
                break; // Dropping `rx` tells the recorder.
            }
        }
        let closed = self.close();
        result.and(closed)
    }

    fn close(&mut self) -> Result<(), String> {
        let flushed = self.flush_batch();
        if !self.blueprint_sent {
            self.send_blueprint(&[], None, None)?;
        }
        if let Some(has_profiles) = self.legend_pending.take() {
            self.log_legend(has_profiles, None)?;
        }
        flushed?;
        self.rec.flush_blocking().map_err(|e| err("flush", e))
        // The stream is dropped with `self`: the footer is written then.
    }

    fn log_static_scene(&mut self) -> Result<(), String> {
        let flip = Transform3D::from_scale((1.0, -1.0, 1.0));
        for entity in [DISKS_ENTITY, "scene"] {
            self.rec
                .log_static(entity, &flip)
                .map_err(|e| err("transform", e))?;
        }

        let classes: Vec<ClassDescriptionMapElem> = (0..self.layout.species.max(1))
            .map(|s| {
                let c = SPECIES_PALETTE[s % SPECIES_PALETTE.len()];
                let id = u16::try_from(s).unwrap_or(u16::MAX);
                (
                    id,
                    format!("species {s}").as_str(),
                    Rgba32::from_rgb(c[0], c[1], c[2]),
                )
                    .into()
            })
            .collect();
        self.rec
            .log_static(DISKS_ENTITY, &AnnotationContext::new(classes))
            .map_err(|e| err("annotation context", e))?;

        let w = self.layout.width;
        if let (Some(top), false) = (self.layout.top, self.layout.y_periodic) {
            self.rec
                .log_static(
                    LID_ENTITY,
                    &LineStrips2D::new([line([[0.0, top], [w, top]])])
                        .with_colors([rgb(WALL_COLOR)])
                        .with_radii([Radius::new_ui_points(1.5)]),
                )
                .map_err(|e| err("lid", e))?;
        }
        if let Some(top) = self.layout.top {
            self.log_walls(top)?;
        }
        Ok(())
    }

    /// Logs (static) the two walls from y = 0 up to `height`, or the periodic edges.
    fn log_walls(&mut self, height: f64) -> Result<(), String> {
        self.wall_height = Some(height);
        let w = self.layout.width;
        let (entity, color, width) = if self.layout.x_periodic {
            (PERIODIC_EDGES_ENTITY, EDGE_COLOR, 0.75)
        } else {
            (WALLS_ENTITY, WALL_COLOR, 1.5)
        };
        self.rec
            .log_static(
                entity,
                &LineStrips2D::new([
                    line([[0.0, 0.0], [0.0, height]]),
                    line([[w, 0.0], [w, height]]),
                ])
                .with_colors([rgb(color)])
                .with_radii([Radius::new_ui_points(width)]),
            )
            .map_err(|e| err("walls", e))
    }

    fn set_time(&self, frame: Option<i64>, time: f64) {
        if let Some(f) = frame {
            self.rec.set_time_sequence(FRAME_TIMELINE, f);
        }
        self.rec.set_time(
            SIM_TIME_TIMELINE,
            TimeCell::from_duration_nanos(nanos(time)),
        );
    }

    /// The frame a text at simulated time `time` belongs to on the `frame` timeline (the one
    /// shown): the last frame logged, or the next one when `time` is already its time (frames
    /// are `step` apart); frame 0 before any frame, so that the text shows on that timeline.
    fn frame_at(&self, time: f64) -> i64 {
        match (self.last_frame, self.last_time, self.step) {
            (Some(k), Some(t), Some(dt)) if dt > 0.0 => {
                k + ((time - t) / dt + 1e-9).floor().clamp(0.0, 1.0) as i64
            }
            (Some(k), ..) => k,
            (None, ..) => 0,
        }
    }

    fn text(&mut self, time: f64, level: &str, text: &str) -> Result<(), String> {
        self.set_time(Some(self.frame_at(time)), time);
        self.rec
            .log(
                LOG_ENTITY,
                &TextLog::new(text).with_level(TextLogLevel::from(level.to_owned())),
            )
            .map_err(|e| err("text log", e))
    }

    fn frame(&mut self, f: &FrameBuf) -> Result<(), String> {
        let n = f.x.len();
        let index = i64::try_from(f.index).unwrap_or(i64::MAX);
        let t = nanos(f.time);
        if !self.blueprint_sent {
            let view_top = self.view_top(f);
            self.send_blueprint(&f.series, f.profile.as_ref(), Some(view_top))?;
        }
        self.last_frame = Some(index);
        let step = self.last_time.map(|t0| f.time - t0);
        self.last_time = Some(f.time);
        self.step = self.step.or(step);
        if let (Some(has_profiles), Some(_)) = (self.legend_pending, step) {
            self.legend_pending = None;
            self.log_legend(has_profiles, step)?;
        }

        // Open top: grow the walls when something rises above 80 % of them.
        if self.layout.top.is_none() {
            let highest =
                f.y.iter()
                    .zip(&f.radius)
                    .map(|(y, r)| y + r)
                    .fold(f.floor_height.unwrap_or(0.0), f64::max);
            let needed = if highest > 0.0 {
                highest * 1.25
            } else {
                self.layout.width
            };
            if self.wall_height.is_none_or(|h| highest > 0.8 * h) {
                self.log_walls(needed)?;
            }
        }

        // Radii and class ids: with the first frame and whenever they change.
        let species_changed = if f.species.is_empty() {
            self.last_species.len() != n || self.last_species.iter().any(|&s| s != 0)
        } else {
            self.last_species != f.species
        };
        if self.last_radii != f.radius || species_changed {
            self.set_time(Some(index), f.time);
            let class_ids: Vec<ClassId> = if f.species.is_empty() {
                vec![ClassId::from(0u16); n]
            } else {
                f.species
                    .iter()
                    .map(|&s| ClassId::from(u16::try_from(s).unwrap_or(u16::MAX)))
                    .collect()
            };
            self.rec
                .log(
                    DISKS_ENTITY,
                    &Points2D::update_fields()
                        .with_radii(f.radius.iter().map(|&r| Radius::new_scene_units(r as f32)))
                        .with_class_ids(class_ids),
                )
                .map_err(|e| err("radii", e))?;
            self.last_radii.clone_from(&f.radius);
            self.last_species = if f.species.is_empty() {
                vec![0; n]
            } else {
                f.species.clone()
            };
        }

        let b = &mut self.batch;
        b.clock.push(index, t, clock_label(f.time, step));
        b.disks.push(index, t, n);
        b.positions
            .extend(f.x.iter().zip(&f.y).map(|(&x, &y)| [x as f32, y as f32]));
        if self.color_by == ColorBy::Speed {
            let scale = self.layout.speed_scale;
            b.colors.extend(
                f.vx.iter()
                    .zip(&f.vy)
                    .map(|(vx, vy)| speed_color(vx.hypot(*vy) / scale)),
            );
        }
        if let Some(h) = f.floor_height {
            let strip =
                LineStrip2D::from_iter([[0.0, h as f32], [self.layout.width as f32, h as f32]]);
            b.floor.push(index, t, strip);
        }
        if let Some(p) = &f.profile {
            let phi = p
                .height
                .iter()
                .zip(&p.packing_fraction)
                .map(|(&h, &v)| [v as f32, h as f32]);
            b.packing.push(index, t, LineStrip2D::from_iter(phi));
            let temp = p
                .height
                .iter()
                .zip(p.temperature_x.iter().zip(&p.temperature_y))
                .zip(&p.density)
                .filter(|(_, &d)| d > 0.0)
                .map(|((&h, (&tx, &ty)), _)| [(0.5 * (tx + ty)) as f32, h as f32]);
            b.temperature.push(index, t, LineStrip2D::from_iter(temp));
        }
        for &(name, value) in &f.series {
            b.series.entry(name).or_default().push(index, t, value);
        }
        if b.disks.values.len() >= BATCH || b.positions.len() >= BATCH_POINTS {
            self.flush_batch()?;
        }
        Ok(())
    }

    /// Logs the gathered frames column-wise: one chunk per entity.
    fn flush_batch(&mut self) -> Result<(), String> {
        let b = &mut self.batch;
        if b.disks.values.is_empty() {
            return Ok(());
        }
        let lengths: Vec<usize> = b.disks.values.drain(..).collect();
        let mut points = Points2D::new(b.positions.drain(..));
        if !b.colors.is_empty() {
            points = points.with_colors(b.colors.drain(..));
        }
        let columns = points.columns(lengths).map_err(|e| err("disks", e))?;
        self.rec
            .send_columns(DISKS_ENTITY, b.disks.take_times(), columns)
            .map_err(|e| err("disks", e))?;

        for (entity, column, color) in [
            (FLOOR_ENTITY, &mut b.floor, FLOOR_COLOR),
            (PACKING_PROFILE_ENTITY, &mut b.packing, PACKING_COLOR),
            (
                TEMPERATURE_PROFILE_ENTITY,
                &mut b.temperature,
                TEMPERATURE_COLOR,
            ),
        ] {
            if column.values.is_empty() {
                continue;
            }
            let k = column.values.len();
            let strips = LineStrips2D::new(column.values.drain(..))
                .with_colors(std::iter::repeat_n(rgb(color), k))
                .with_radii(std::iter::repeat_n(Radius::new_ui_points(2.0), k));
            let columns = strips
                .columns(std::iter::repeat_n(1, k))
                .map_err(|e| err(entity, e))?;
            self.rec
                .send_columns(entity, column.take_times(), columns)
                .map_err(|e| err(entity, e))?;
        }
        if !b.clock.values.is_empty() {
            let labels = Points2D::update_fields().with_labels(b.clock.values.drain(..));
            let columns = labels
                .columns_of_unit_batches()
                .map_err(|e| err("clock", e))?;
            self.rec
                .send_columns(CLOCK_ENTITY, b.clock.take_times(), columns)
                .map_err(|e| err("clock", e))?;
        }
        for (name, column) in &mut b.series {
            if column.values.is_empty() {
                continue;
            }
            let columns = Scalars::new(column.values.drain(..))
                .columns_of_unit_batches()
                .map_err(|e| err(name, e))?;
            self.rec
                .send_columns(
                    format!("{SERIES_PREFIX}/{name}"),
                    column.take_times(),
                    columns,
                )
                .map_err(|e| err(&format!("series {name}"), e))?;
        }
        Ok(())
    }

    /// Top of the bed view: the lid (or periodic height), else the top of the profiles, else
    /// three times the highest disk top of the first frame.
    fn view_top(&self, f: &FrameBuf) -> f64 {
        if let Some(top) = self.layout.top {
            return top;
        }
        if let Some((_, top)) = f.profile.as_ref().and_then(profile_range) {
            return top;
        }
        let highest =
            f.y.iter()
                .zip(&f.radius)
                .map(|(y, r)| y + r)
                .fold(f.floor_height.unwrap_or(0.0), f64::max);
        if highest > 0.0 {
            3.0 * highest
        } else {
            self.layout.width
        }
    }

    /// Logs the static parts of one profile view: its y-up transform stretching values of
    /// `0..x_max` to the view's width, the axes with ticks and the titles. Returns the view's
    /// bounds (in the root's coordinates: y flipped).
    fn log_profile_axes(
        &self,
        entity: &str,
        title: &str,
        x_max: f64,
        (bottom, top): (f64, f64),
    ) -> Result<[f64; 4], String> {
        let span = top - bottom;
        let kx = PROFILE_ASPECT * span / x_max;
        self.rec
            .log_static(entity, &Transform3D::from_scale((kx as f32, -1.0, 1.0)))
            .map_err(|e| err("profile transform", e))?;
        let tick = 0.015 * span;
        let mut strips = vec![
            vec![[0.0, bottom as f32], [x_max as f32, bottom as f32]],
            vec![[0.0, bottom as f32], [0.0, top as f32]],
        ];
        let mut labels: Vec<(f64, f64, String)> = Vec::new();
        let x_step = nice_ceiling(x_max / 5.0);
        let mut x = 0.0;
        while x <= x_max * (1.0 + 1e-9) {
            strips.push(vec![
                [x as f32, bottom as f32],
                [x as f32, (bottom - tick) as f32],
            ]);
            labels.push((x, bottom - 3.0 * tick, tick_label(x)));
            x += x_step;
        }
        let h_step = nice_ceiling(span / 5.0);
        let mut h = (bottom / h_step).ceil() * h_step;
        while h <= top + 1e-9 * span {
            let x_tick = tick / kx;
            strips.push(vec![[0.0, h as f32], [(-x_tick) as f32, h as f32]]);
            labels.push((-4.0 * x_tick, h, tick_label(h)));
            h += h_step;
        }
        labels.push((0.5 * x_max, bottom - 7.0 * tick, title.to_owned()));
        labels.push((0.0, top + 6.0 * tick, "height".to_owned()));
        self.rec
            .log_static(
                format!("{entity}/axes"),
                &LineStrips2D::new(strips)
                    .with_colors([rgb(AXIS_COLOR)])
                    .with_radii([Radius::new_ui_points(1.0)]),
            )
            .map_err(|e| err("profile axes", e))?;
        self.rec
            .log_static(
                format!("{entity}/axes/labels"),
                &Points2D::new(labels.iter().map(|(x, y, _)| [*x as f32, *y as f32]))
                    .with_labels(labels.iter().map(|(_, _, l)| l.as_str()))
                    .with_radii([Radius::new_ui_points(0.0)])
                    .with_colors([rgb(AXIS_COLOR)])
                    .with_show_labels(true),
            )
            .map_err(|e| err("profile labels", e))?;
        let margin = 0.15 * span;
        Ok([
            -margin,
            x_max * kx + 0.3 * margin,
            -(top + margin),
            -(bottom - 1.5 * margin),
        ])
    }

    /// Logs the colour scale in the sky of the bed view, near its top right corner below
    /// `view_top`: a bar of 20 coloured segments from 0 to the scale, and labels under it.
    fn log_speed_scale(&self, view_top: f64, bottom: f64) -> Result<(), String> {
        let w = self.layout.width;
        let span = view_top - bottom;
        let length = (0.2 * w).min(1.5 * span);
        let (x0, y) = (w - length - 0.01 * w, view_top - 0.1 * span);
        let thickness = 0.025 * span;
        let scale = self.layout.speed_scale;
        let segments = 20;
        let strips: Vec<[[f32; 2]; 2]> = (0..segments)
            .map(|k| {
                let a = x0 + length * k as f64 / segments as f64;
                let b = x0 + length * (k + 1) as f64 / segments as f64;
                line([[a, y], [b, y]])
            })
            .collect();
        let colors: Vec<Color> = (0..segments)
            .map(|k| speed_color((k as f64 + 0.5) / segments as f64))
            .collect();
        self.rec
            .log_static(
                SPEED_SCALE_ENTITY,
                &LineStrips2D::new(strips)
                    .with_colors(colors)
                    .with_radii([Radius::new_scene_units(thickness as f32)]),
            )
            .map_err(|e| err("colour scale", e))?;
        let labels = [
            (x0, "0".to_owned()),
            (x0 + 0.5 * length, tick_label(0.5 * scale)),
            (x0 + length, format!("≥ {}", tick_label(scale))),
            (x0 - 0.2 * length, "speed |v|".to_owned()),
        ];
        self.rec
            .log_static(
                format!("{SPEED_SCALE_ENTITY}/labels"),
                &Points2D::new(labels.iter().enumerate().map(|(i, (x, _))| {
                    let y = if i < 3 { y - 3.5 * thickness } else { y };
                    [*x as f32, y as f32]
                }))
                .with_labels(labels.iter().map(|(_, l)| l.as_str()))
                .with_radii([Radius::new_ui_points(0.0)])
                .with_colors([rgb(AXIS_COLOR)])
                .with_show_labels(true),
            )
            .map_err(|e| err("colour scale", e))
    }

    /// Logs (static) where the clock is written: at the top left of the bed view, below
    /// `view_top`; its label comes with each frame.
    fn log_clock(&self, view_top: f64, bottom: f64) -> Result<(), String> {
        let (w, span) = (self.layout.width, view_top - bottom);
        let at = [(0.06 * w) as f32, (view_top - 0.06 * span) as f32];
        self.rec
            .log_static(
                CLOCK_ENTITY,
                &Points2D::new([at])
                    .with_radii([Radius::new_ui_points(0.0)])
                    .with_colors([rgb(CLOCK_COLOR)])
                    .with_show_labels(true),
            )
            .map_err(|e| err("clock", e))
    }

    /// The legend: what the colours and the views show.
    /// `step` is the simulated time between frames (`None` with a single frame).
    fn log_legend(&self, has_profiles: bool, step: Option<f64>) -> Result<(), String> {
        let mut text = String::new();
        match self.color_by {
            ColorBy::Speed => text.push_str(&format!(
                "**Disks**: speed |v| on one scale for the whole run, blue at rest → grey at \
                 {} → red at {} and above (bar at the top right; `output.speed_scale`).\n\n",
                tick_label(0.5 * self.layout.speed_scale),
                tick_label(self.layout.speed_scale)
            )),
            ColorBy::Species => text.push_str(
                "**Disks coloured by species** (radius class; hover a disk for its class).\n\n",
            ),
        }
        text.push_str(
            "**Follow a disk**: click it; instance *i* is disk *i* in every frame (and line *i* \
             of a `--trajectory` frame).\n\n",
        );
        if has_profiles {
            text.push_str(
                "**Profiles** of the current frame in the summary's height bins: packing \
                 fraction φ (each disk's area split over the bins it covers) and granular \
                 temperature T = (Tx + Ty)/2 about each bin's mean velocity.\n\n",
            );
        }
        let spacing = step.map_or(String::new(), |dt| {
            format!(
                ", {} time units apart",
                clock_label(dt, Some(dt)).trim_start_matches("t = ")
            )
        });
        text.push_str(&format!(
            "**Time**: the time panel and the plots count frames (timeline `frame`{spacing}); \
             the simulated time of the frame shown is written at the top left of the bed \
             (t = …). Timeline `sim_time` holds the same times, written by the viewer as \
             durations (one time unit as one second).\n\n"
        ));
        text.push_str("Floor: orange. Walls: grey; periodic edges: dark grey.");
        self.rec
            .log_static(
                LEGEND_ENTITY,
                &TextDocument::new(text).with_media_type(MediaType::markdown()),
            )
            .map_err(|e| err("legend", e))
    }

    /// Sends the blueprint (see the module documentation): `series` names the time series,
    /// `profile` (the first frame's) gives the height range of the profile views, `view_top`
    /// the top of the bed view.
    fn send_blueprint(
        &mut self,
        series: &[(&'static str, f64)],
        profile: Option<&ProfileTable>,
        view_top: Option<f64>,
    ) -> Result<(), String> {
        self.blueprint_sent = true;
        let mut bounds: Vec<(String, [f64; 4])> = Vec::new();
        let range = profile.and_then(profile_range);
        let w = self.layout.width;

        // The bed, across the top.
        let bed_bottom = range.map_or(0.0, |(b, _)| b.min(0.0));
        let bed = if let Some(top) = view_top {
            let span = top - bed_bottom;
            if self.color_by == ColorBy::Speed {
                self.log_speed_scale(top, bed_bottom)?;
            }
            self.log_clock(top, bed_bottom)?;
            let (view, path) = view_with_path(
                Spatial2DView::new(self.layout.name.clone())
                    .with_origin("/")
                    .with_contents([format!("/{DISKS_ENTITY}"), "/scene/**".to_owned()]),
            );
            bounds.push((
                path,
                [
                    -0.01 * w,
                    1.01 * w,
                    -(top + 0.02 * span),
                    -(bed_bottom - 0.04 * span),
                ],
            ));
            view
        } else {
            Spatial2DView::new(self.layout.name.clone())
                .with_origin("/")
                .with_contents([format!("/{DISKS_ENTITY}"), "/scene/**".to_owned()])
                .into()
        };

        // Below: profiles, time series, legend and log.
        let mut row: Vec<ContainerLike> = Vec::new();
        let mut shares: Vec<f32> = Vec::new();
        if let (Some(p), Some(range)) = (profile, range) {
            // A layer of centres in one bin thinner than a diameter can exceed φ = 1.
            let phi_max = 1.25;
            let t_max = nice_ceiling(0.25 * self.layout.speed_scale.powi(2)).max(nice_ceiling(
                p.temperature_x
                    .iter()
                    .zip(&p.temperature_y)
                    .map(|(a, b)| 0.5 * (a + b))
                    .fold(0.0, f64::max),
            ));
            for (entity, title, x_max, name) in [
                (
                    PACKING_PROFILE_ENTITY,
                    "packing fraction φ",
                    phi_max,
                    "packing fraction vs height",
                ),
                (
                    TEMPERATURE_PROFILE_ENTITY,
                    "temperature T",
                    t_max,
                    "temperature vs height",
                ),
            ] {
                let b = self.log_profile_axes(entity, title, x_max, range)?;
                let (view, path) = view_with_path(
                    Spatial2DView::new(name)
                        .with_origin("/")
                        .with_contents([format!("/{entity}/**")]),
                );
                bounds.push((path, b));
                row.push(view);
                shares.push(1.0);
            }
        }
        let mut groups: BTreeSet<&str> = BTreeSet::new();
        let mut loose: Vec<&str> = Vec::new();
        for (name, _) in series {
            match name.split_once('/') {
                Some((g, _)) => {
                    groups.insert(g);
                }
                None => loose.push(name),
            }
        }
        let mut plots: Vec<ContainerLike> = Vec::new();
        for g in &groups {
            plots.push(
                TimeSeriesView::new(*g)
                    .with_origin(format!("/{SERIES_PREFIX}/{g}"))
                    .into(),
            );
        }
        // A series without a group has its own view: sharing one y axis would squash the
        // smaller (e.g. centre-of-mass height beside collisions per unit time).
        for name in &loose {
            plots.push(
                TimeSeriesView::new(*name)
                    .with_origin(format!("/{SERIES_PREFIX}/{name}"))
                    .into(),
            );
        }
        if !plots.is_empty() {
            row.push(Vertical::new(plots).into());
            shares.push(1.4);
        }
        self.legend_pending = Some(profile.is_some());
        row.push(
            Vertical::new([
                TextDocumentView::new("legend")
                    .with_origin(format!("/{LEGEND_ENTITY}"))
                    .into(),
                TextLogView::new("log")
                    .with_origin(format!("/{LOG_ENTITY}"))
                    .into(),
            ])
            .with_row_shares([2.0, 1.0])
            .into(),
        );
        shares.push(1.0);

        let root = Vertical::new([bed, Horizontal::new(row).with_column_shares(shares).into()])
            .with_row_shares([1.0, 2.0]);
        // Side and time panels collapsed (the time panel keeps its play controls), so that the
        // views get the window; the timeline shown is the frame number, a plain number (the
        // module documentation says why).
        let blueprint = Blueprint::new(root)
            .with_auto_views(false)
            .with_blueprint_panel(BlueprintPanel::from_state(PanelState::Collapsed))
            .with_selection_panel(SelectionPanel::from_state(PanelState::Collapsed))
            .with_time_panel(
                TimePanel::new()
                    .with_state(PanelState::Collapsed)
                    .with_timeline(FRAME_TIMELINE)
                    .with_play_state(PlayState::Following),
            );
        send_with_bounds(&self.rec, &blueprint, &bounds)
    }
}

/// (bottom, top) of the bins of a profile table.
fn profile_range(p: &ProfileTable) -> Option<(f64, f64)> {
    let (first, last) = (*p.height.first()?, *p.height.last()?);
    let half = if p.height.len() > 1 {
        0.5 * (last - first) / (p.height.len() - 1) as f64
    } else {
        0.5
    };
    Some((first - half, last + half))
}

/// The view as a container entry, and its path in the blueprint store.
fn view_with_path(view: Spatial2DView) -> (ContainerLike, String) {
    match ContainerLike::from(view) {
        ContainerLike::View(v) => {
            let path = v.blueprint_path().to_string();
            (ContainerLike::View(v), path)
        }
        other => (other, String::new()),
    }
}

/// Sends `blueprint` to `rec` together with the visual bounds `[x0, x1, y0, y1]` of the views at
/// the given blueprint paths (the Rust blueprint API has no setter for a 2D view's bounds: they
/// are logged as the `VisualBounds2D` property of each view into the same blueprint store).
fn send_with_bounds(
    rec: &RecordingStream,
    blueprint: &Blueprint,
    bounds: &[(String, [f64; 4])],
) -> Result<(), String> {
    let activation = BlueprintActivation {
        make_active: true,
        make_default: true,
    };
    let (memory, storage) = RecordingStreamBuilder::new(APPLICATION_ID)
        .memory()
        .map_err(|e| err("blueprint", e))?;
    blueprint
        .send(&memory, activation)
        .map_err(|e| err("blueprint", e))?;
    let mut messages = Vec::new();
    let mut command = None;
    for msg in storage.take() {
        match msg {
            LogMsg::BlueprintActivationCommand(cmd) => command = Some(cmd),
            msg if msg.store_id().is_blueprint() => messages.push(msg),
            _ => {}
        }
    }
    let command = command.ok_or_else(|| err("blueprint", "no activation command"))?;
    if !bounds.is_empty() {
        let (extra, extra_storage) = RecordingStreamBuilder::new(APPLICATION_ID)
            .recording_id(command.blueprint_id.recording_id().clone())
            .blueprint()
            .memory()
            .map_err(|e| err("blueprint", e))?;
        extra.set_time_sequence("blueprint", 0);
        for (path, [x0, x1, y0, y1]) in bounds {
            extra
                .log(
                    format!("{path}/VisualBounds2D"),
                    &VisualBounds2D::new(Range2D {
                        x_range: Range1D([*x0, *x1]),
                        y_range: Range1D([*y0, *y1]),
                    }),
                )
                .map_err(|e| err("view bounds", e))?;
        }
        messages.extend(
            extra_storage
                .take()
                .into_iter()
                .filter(|m| matches!(m, LogMsg::ArrowMsg(..))),
        );
    }
    rec.send_blueprint(messages, command);
    Ok(())
}

/// One frame of `disks` as decoded from a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct DiskFrame {
    /// Value on the `frame` timeline.
    pub frame: i64,
    /// Value on the `sim_time` timeline, in simulated time units (nanosecond resolution).
    pub time: f64,
    /// Disk centres `[x, y]` in simulation coordinates (y up), as logged (f32).
    pub positions: Vec<[f32; 2]>,
    /// Radii in effect at this frame (latest logged at or before it).
    pub radii: Vec<f32>,
    /// Class ids (species) in effect at this frame (latest logged at or before it).
    pub class_ids: Vec<u16>,
    /// Colours logged with this frame as `0xRRGGBBAA` (empty when colouring by species).
    pub colors: Vec<u32>,
}

/// One frame of a live profile: the frame and the points `(value, height)` of its line strip.
pub type ProfileFrame = (i64, Vec<[f32; 2]>);

/// One `TextLog` row.
#[derive(Debug, Clone, PartialEq)]
pub struct LogLine {
    /// Simulated time of the entry (`None` if it has no `sim_time`).
    pub time: Option<f64>,
    /// Frame of the entry on the `frame` timeline (`None` if it has none: the viewer, showing
    /// that timeline, would not list it).
    pub frame: Option<i64>,
    /// Level, e.g. `INFO`, `WARN`.
    pub level: String,
    /// The text.
    pub text: String,
}

/// Row and frame counts of one entity's temporal data.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct EntityStats {
    /// Number of temporal rows.
    pub rows: usize,
    /// Number of distinct `frame` values among those rows.
    pub frames: usize,
}

/// What [`read_back`] found in a `.rrd` file.
#[derive(Debug, Clone, Default)]
pub struct RecordingContents {
    /// Application id of the recording store.
    pub application_id: Option<String>,
    /// Recording id of the recording store (the parts of a resumed run share it).
    pub recording_id: Option<String>,
    /// Temporal data per entity path (written without the leading `/`, e.g. `disks`,
    /// `series/energy/kinetic`).
    pub entities: BTreeMap<String, EntityStats>,
    /// Entity paths that hold static data (e.g. `scene/walls`).
    pub static_entities: BTreeSet<String>,
    /// `disks` frame by frame, sorted by frame.
    pub disks: Vec<DiskFrame>,
    /// Floor height per frame: `(frame, height)`, sorted by frame.
    pub floor: Vec<(i64, f32)>,
    /// Live profiles by name (`packing_fraction`, `temperature`), sorted by frame.
    pub profiles: BTreeMap<String, Vec<ProfileFrame>>,
    /// Series values by name (without the `series/` prefix): `(frame, value)`, sorted by frame.
    pub series: BTreeMap<String, Vec<(i64, f64)>>,
    /// Text log entries sorted by simulated time (entries without time first; ties in file order).
    pub log: Vec<LogLine>,
    /// Whether a blueprint (with its activation command) is in the file.
    pub has_blueprint: bool,
    /// Visual bounds `[x0, x1, y0, y1]` the blueprint gives its 2D views (in the views'
    /// coordinates: y downwards, so heights are negated), in file order.
    pub view_bounds: Vec<[f64; 4]>,
    /// Whether the file ends with a footer holding the manifest of the recording store, i.e. the
    /// stream was closed properly.
    pub has_footer: bool,
    /// Number of chunks listed in the recording's manifest (0 without footer).
    pub manifest_chunks: usize,
    /// Kind of each timeline of the recording's temporal data, as Rerun names it (`sequence`,
    /// `duration`, `timestamp`).
    pub timelines: BTreeMap<String, String>,
    /// The timeline the blueprint's time panel shows.
    pub shown_timeline: Option<String>,
    /// The clock's label per frame: `(frame, "t = …")`, sorted by frame.
    pub clock: Vec<(i64, String)>,
}

impl RecordingContents {
    /// Temporal stats of `entity` (path without leading `/`), if it has temporal data.
    pub fn entity(&self, entity: &str) -> Option<&EntityStats> {
        self.entities.get(entity)
    }
}

/// The value logged at or before frame `f` (Rerun's latest-at), or empty.
fn latest<T: Clone>(map: &BTreeMap<i64, Vec<T>>, f: i64) -> Vec<T> {
    map.range(..=f)
        .next_back()
        .map(|(_, v)| v.clone())
        .unwrap_or_default()
}

fn entity_name(chunk: &Chunk) -> String {
    chunk
        .entity_path()
        .to_string()
        .trim_start_matches('/')
        .to_owned()
}

/// Reads what the tests look at in a chunk of the blueprint store: the 2D views' visual bounds
/// and the timeline of the time panel.
fn read_blueprint_chunk(chunk: &Chunk, out: &mut RecordingContents) {
    if entity_name(chunk).ends_with("/VisualBounds2D") {
        let id = VisualBounds2D::descriptor_range().component;
        for v in chunk.iter_component::<VisualBounds2DComponent>(id) {
            for b in v.iter() {
                let (x, y) = (b.0.x_range.0, b.0.y_range.0);
                out.view_bounds.push([x[0], x[1], y[0], y[1]]);
            }
        }
    }
    let id = TimePanelBlueprint::descriptor_timeline().component;
    for v in chunk.iter_component::<BlueprintTimelineName>(id) {
        if let Some(name) = v.first() {
            out.shown_timeline = Some(name.0.as_str().to_owned());
        }
    }
}

/// Decodes a `.rrd` file written by [`RerunRecorder`] with Rerun's own decoder and returns
/// its contents: per-entity frame counts, disk positions per frame, floor heights, series, the
/// text log and whether the blueprint and the footer are present. Used by tests and by
/// `vibrobed` tooling. Fails when the file cannot be read or is not a valid RRD stream (a file
/// cut short fails too; a file merely lacking its footer decodes with `has_footer == false`).
pub fn read_back(path: &Path) -> Result<RecordingContents, String> {
    let file =
        std::fs::File::open(path).map_err(|e| format!("cannot open {}: {e}", path.display()))?;
    let reader = std::io::BufReader::new(file);
    let mut decoder = DecoderApp::decode_eager(reader)
        .map_err(|e| format!("{} is not a valid RRD file: {e}", path.display()))?;

    let frame_tl = TimelineName::from(FRAME_TIMELINE);
    let time_tl = TimelineName::from(SIM_TIME_TIMELINE);
    let positions_id = Points2D::descriptor_positions().component;
    let radii_id = Points2D::descriptor_radii().component;
    let colors_id = Points2D::descriptor_colors().component;
    let class_ids_id = Points2D::descriptor_class_ids().component;
    let labels_id = Points2D::descriptor_labels().component;
    let strips_id = LineStrips2D::descriptor_strips().component;
    let scalars_id = Scalars::descriptor_scalars().component;
    let text_id = TextLog::descriptor_text().component;
    let level_id = TextLog::descriptor_level().component;

    let mut out = RecordingContents::default();
    let mut frames_seen: BTreeMap<String, BTreeSet<i64>> = BTreeMap::new();
    let mut frame_times: BTreeMap<i64, i64> = BTreeMap::new();
    let mut positions: BTreeMap<i64, Vec<[f32; 2]>> = BTreeMap::new();
    let mut radii: BTreeMap<i64, Vec<f32>> = BTreeMap::new();
    let mut class_ids: BTreeMap<i64, Vec<u16>> = BTreeMap::new();
    let mut colors: BTreeMap<i64, Vec<u32>> = BTreeMap::new();

    for msg in decoder.by_ref() {
        let msg = msg.map_err(|e| format!("decoding {}: {e}", path.display()))?;
        let (store_id, arrow_msg) = match msg {
            LogMsg::SetStoreInfo(info) => {
                if info.info.store_id.is_recording() {
                    out.application_id = Some(info.info.application_id().to_string());
                    out.recording_id = Some(info.info.store_id.recording_id().to_string());
                } else {
                    out.has_blueprint = true;
                }
                continue;
            }
            LogMsg::BlueprintActivationCommand(_) => {
                out.has_blueprint = true;
                continue;
            }
            LogMsg::ArrowMsg(store_id, arrow_msg) => (store_id, arrow_msg),
        };
        let chunk = Chunk::from_arrow_msg(&arrow_msg)
            .map_err(|e| format!("decoding a chunk of {}: {e}", path.display()))?;
        if !store_id.is_recording() {
            read_blueprint_chunk(&chunk, &mut out);
            continue;
        }
        let entity = entity_name(&chunk);
        if chunk.is_static() {
            out.static_entities.insert(entity);
            continue;
        }
        for column in chunk.timelines().values() {
            let timeline = column.timeline();
            out.timelines
                .insert(timeline.name().to_string(), timeline.typ().to_string());
        }
        let stats = out.entities.entry(entity.clone()).or_default();
        stats.rows += chunk.num_rows();
        let frames: Vec<i64> = chunk
            .iter_indices(&frame_tl)
            .map(|(t, _)| t.as_i64())
            .collect();
        let times: Vec<i64> = chunk
            .iter_indices(&time_tl)
            .map(|(t, _)| t.as_i64())
            .collect();
        if times.len() == frames.len() {
            for (f, t) in frames.iter().zip(&times) {
                frame_times.entry(*f).or_insert(*t);
            }
        }
        frames_seen
            .entry(entity.clone())
            .or_default()
            .extend(frames.iter().copied());

        // Per component: the frame of every row holding it, zipped with its values.
        let rows_of = |component| {
            chunk
                .iter_component_indices(frame_tl, component)
                .map(|(t, _)| t.as_i64())
                .collect::<Vec<i64>>()
        };
        if entity == DISKS_ENTITY {
            for (f, v) in rows_of(positions_id)
                .into_iter()
                .zip(chunk.iter_component::<Position2D>(positions_id))
            {
                positions.insert(f, v.iter().map(|p| [p.x(), p.y()]).collect());
            }
            for (f, v) in rows_of(radii_id)
                .into_iter()
                .zip(chunk.iter_component::<Radius>(radii_id))
            {
                radii.insert(f, v.iter().map(|r| r.0 .0).collect());
            }
            for (f, v) in rows_of(class_ids_id)
                .into_iter()
                .zip(chunk.iter_component::<ClassId>(class_ids_id))
            {
                class_ids.insert(f, v.iter().map(|c| c.0 .0).collect());
            }
            for (f, v) in rows_of(colors_id)
                .into_iter()
                .zip(chunk.iter_component::<Color>(colors_id))
            {
                colors.insert(f, v.iter().map(|c| c.to_u32()).collect());
            }
        } else if entity == CLOCK_ENTITY {
            for (f, v) in rows_of(labels_id)
                .into_iter()
                .zip(chunk.iter_component::<Text>(labels_id))
            {
                if let Some(t) = v.first() {
                    out.clock.push((f, t.as_str().to_owned()));
                }
            }
        } else if entity == FLOOR_ENTITY {
            for (f, v) in rows_of(strips_id)
                .into_iter()
                .zip(chunk.iter_component::<LineStrip2D>(strips_id))
            {
                if let Some(p) = v.first().and_then(|s| s.0.first()) {
                    out.floor.push((f, p.y()));
                }
            }
        } else if entity == PACKING_PROFILE_ENTITY || entity == TEMPERATURE_PROFILE_ENTITY {
            let name = entity.trim_start_matches("profiles/").to_owned();
            let values = out.profiles.entry(name).or_default();
            for (f, v) in rows_of(strips_id)
                .into_iter()
                .zip(chunk.iter_component::<LineStrip2D>(strips_id))
            {
                if let Some(s) = v.first() {
                    values.push((f, s.0.iter().map(|p| [p.x(), p.y()]).collect()));
                }
            }
        } else if let Some(name) = entity.strip_prefix(&format!("{SERIES_PREFIX}/")) {
            let values = out.series.entry(name.to_owned()).or_default();
            for (f, v) in rows_of(scalars_id)
                .into_iter()
                .zip(chunk.iter_component::<Scalar>(scalars_id))
            {
                if let Some(s) = v.first() {
                    values.push((f, s.0 .0));
                }
            }
        } else if entity == LOG_ENTITY {
            let texts: Vec<String> = chunk
                .iter_component::<Text>(text_id)
                .map(|v| v.first().map(|t| t.as_str().to_owned()).unwrap_or_default())
                .collect();
            let levels: Vec<String> = chunk
                .iter_component::<TextLogLevel>(level_id)
                .map(|v| v.first().map(|l| l.as_str().to_owned()).unwrap_or_default())
                .collect();
            for (i, text) in texts.into_iter().enumerate() {
                out.log.push(LogLine {
                    time: times.get(i).map(|&ns| ns as f64 * 1e-9),
                    frame: frames.get(i).copied(),
                    level: levels.get(i).cloned().unwrap_or_default(),
                    text,
                });
            }
        }
    }

    for (entity, frames) in frames_seen {
        if let Some(stats) = out.entities.get_mut(&entity) {
            stats.frames = frames.len();
        }
    }
    out.disks = positions
        .into_iter()
        .map(|(f, p)| DiskFrame {
            frame: f,
            time: frame_times.get(&f).map_or(f64::NAN, |&ns| ns as f64 * 1e-9),
            positions: p,
            radii: latest(&radii, f),
            class_ids: latest(&class_ids, f),
            colors: colors.get(&f).cloned().unwrap_or_default(),
        })
        .collect();
    out.floor.sort_by_key(|&(f, _)| f);
    out.clock.sort_by_key(|(f, _)| *f);
    out.log.sort_by(|a, b| {
        a.time
            .unwrap_or(f64::NEG_INFINITY)
            .total_cmp(&b.time.unwrap_or(f64::NEG_INFINITY))
    });
    for values in out.series.values_mut() {
        values.sort_by_key(|&(f, _)| f);
    }
    for values in out.profiles.values_mut() {
        values.sort_by_key(|(f, _)| *f);
    }

    let manifests = decoder
        .rrd_manifests()
        .map_err(|e| format!("reading the footer of {}: {e}", path.display()))?;
    for m in manifests.iter().filter(|m| m.store_id.is_recording()) {
        out.has_footer = true;
        out.manifest_chunks += m.data.num_rows();
    }
    Ok(out)
}
