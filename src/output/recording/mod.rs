//! The Rerun recording sink: streams frames to a `.rrd` file that opens ready to read in the
//! Rerun viewer (`rerun OUT.rrd`, same version as the `rerun` crate, 0.36.3).
//!
//! # What the file holds
//!
//! | entity                          | kind     | content                                          |
//! |---------------------------------|----------|--------------------------------------------------|
//! | `disks`                         | temporal | `Points2D`: centres, radii, colours (by speed, species or spin), class ids = species; instance i is disk i in every frame |
//! | `disks/orientation`             | temporal | `LineStrips2D`, rough disks only: one radius per disk, centre to rim at its angle (line i is disk i) |
//! | `disks/orientation`             | static   | its colour, line width and draw order (over the disks; rough disks only) |
//! | `disks`                         | static   | `AnnotationContext` (species names and colours), y-up `Transform3D` |
//! | `scene`                         | static   | y-up `Transform3D` for everything under it       |
//! | `scene/walls`                   | static   | `LineStrips2D`: hard walls at x = 0 and x = width |
//! | `scene/periodic_edges`          | static   | `LineStrips2D`: the periodic edges x = 0 and x = width, dim |
//! | `scene/lid`                     | static   | `LineStrips2D`: the lid at y = top (lid scenes only) |
//! | `scene/floor`                   | temporal | `LineStrips2D`: the floor at its current height  |
//! | `scene/speed_scale`             | static   | `LineStrips2D` and labelled `Points2D`: the colour scale (colouring by speed or spin) |
//! | `scene/clock`                   | static + temporal | `Points2D` at the bed's top left (static), its label `t = …` per frame: the simulated time as a plain number |
//! | `profiles/packing_fraction`     | temporal | `LineStrips2D`: (φ, height) of the frame, one point per bin |
//! | `profiles/temperature`          | temporal | `LineStrips2D`: ((Tx + Ty)/2, height), bins holding disks |
//! | `profiles/<name>/axes`          | static   | `LineStrips2D` and labelled `Points2D`: axes, ticks, titles |
//! | `series/<name>`                 | temporal | `Scalars`: one value per frame (`energy/rotational` for rough disks only) |
//! | `fields`                        | static   | y-up `Transform3D` (recordings with `output.record_fields` only) |
//! | `fields/packing_fraction`       | static + temporal | `Image` per frame, one pixel per cell of the live 2D fields, coloured by packing fraction (blue 0 → grey 0.4 → red 0.8 and above); a static `Transform3D` stretches pixel (i, j) over cell (i, j) |
//! | `fields/velocity`               | temporal | `Arrows2D`: the mean velocity of each cell that holds disks, from the cell's centre, a cell width per 0.3 × the speed scale |
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
//! Frames go to `FILE.partial`; the footer (with the chunk manifest) is written, the file synced
//! and renamed to `FILE` when the recorder finishes ([`RerunRecorder::finish`], or dropping it,
//! e.g. after an error elsewhere in the run). A process killed outright leaves `FILE.partial`,
//! readable as far as it got. A file that cannot be written (a full disk, a quota, an I/O error,
//! the file removed) stops the writer at once: its error names the file and the operating
//! system's reason, the temporary file is removed, and the next [`RerunRecorder::frame`] (or
//! `finish`) returns that error. Nothing waits for ever on the writer: once SIGINT, SIGTERM or
//! SIGHUP has been received, the recorder gives up a writer stuck for more than [`GRACE`].

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::sync::atomic::Ordering;
use std::sync::mpsc::{self, Receiver, Sender, SyncSender, TrySendError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use rerun::blueprint::components::{PanelState, PlayState};
use rerun::blueprint::{
    Blueprint, BlueprintActivation, BlueprintPanel, ContainerLike, Horizontal, SelectionPanel,
    Spatial2DView, TextDocumentView, TextLogView, TimePanel, TimeSeriesView, Vertical,
};
use rerun::components::{
    ClassId, Color, DrawOrder, LineStrip2D, MediaType, Position2D, Radius, Scalar, Text,
    TextLogLevel,
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
    AnnotationContext, Arrows2D, Image, LineStrips2D, Points2D, RecordingStream,
    RecordingStreamBuilder, Scalars, TextDocument, TextLog, Transform3D,
};

use super::frame::{ColorBy, FrameSink, FrameView, SceneLayout};
use crate::error::Error;
use crate::measure::fields::Fields;
use crate::measure::ProfileTable;

/// Application id written into the recording.
pub const APPLICATION_ID: &str = "vibrobed";
/// Name of the sequence timeline holding the frame index.
pub const FRAME_TIMELINE: &str = "frame";
/// Name of the duration timeline holding the simulated time.
pub const SIM_TIME_TIMELINE: &str = "sim_time";
/// Entity of the disks.
pub const DISKS_ENTITY: &str = "disks";
/// Entity of rough disks' orientations: a radius line per disk, under the disks.
pub const ORIENTATION_ENTITY: &str = "disks/orientation";
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
/// Entity of the live 2D fields (`output.record_fields`): a y-up transform over both below.
pub const FIELDS_ENTITY: &str = "fields";
/// Entity of the live packing fraction: an image, one pixel per cell (one per frame).
pub const FIELDS_PACKING_ENTITY: &str = "fields/packing_fraction";
/// Entity of the live mean velocity: one arrow per cell that holds disks (`Arrows2D`).
pub const FIELDS_VELOCITY_ENTITY: &str = "fields/velocity";
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
/// Longest wait for Rerun's pipeline to hand what is logged to the file (which writes each
/// message as it comes, so this is the disk's time, not a queue's).
const FLUSH_TIMEOUT: Duration = Duration::from_secs(60);
/// How long the recorder still waits for its writer once a signal asked the run to stop.
pub const GRACE: Duration = Duration::from_secs(2);
/// Disk positions gathered at most before a batch is logged.
const BATCH_POINTS: usize = 1 << 20;

fn err(context: &str, e: impl std::fmt::Display) -> String {
    format!("rerun recording: {context}: {e}")
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
mod decode;
mod file;
mod layout;
mod style;
mod writer;

pub use decode::*;
use file::RrdFile;
use style::*;
pub use style::{clock_label, orientation_line, speed_color, spin_color};
use writer::*;

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
    /// Rough disks' `(angle, ω)`; empty for smooth disks.
    spins: Vec<(f64, f64)>,
    floor_height: Option<f64>,
    series: Vec<(&'static str, f64)>,
    profile: Option<ProfileTable>,
    /// The live 2D fields (`output.record_fields`).
    fields: Option<Fields>,
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
        copy(&mut self.spins, f.spins.unwrap_or_default());
        self.floor_height = f.floor_height;
        copy(&mut self.series, f.series);
        self.profile = f.profile.cloned();
        match (&mut self.fields, f.fields) {
            (Some(mine), Some(theirs)) => mine.clone_from(theirs),
            (mine, theirs) => *mine = theirs.cloned(),
        }
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
    /// The temporary file being written.
    file: crate::output::partial::Partial,
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
        let file = RrdFile::create(path)?;
        let partial = file.partial();
        let sink: Box<dyn rerun::sink::LogSink> = Box::new(file.clone());
        let rec = builder
            .recording_name(layout.name.clone())
            // An explicit `--rrd` wins over a `RERUN=0` environment variable.
            .enabled(true)
            .set_sinks(vec![sink])
            .map_err(|e| {
                file.partial().discard();
                err(&format!("cannot create {}", path.display()), e)
            })?;
        rec.set_log_time_enabled(false);
        let mut writer = Writer {
            rec,
            file,
            layout: layout.clone(),
            color_by,
            rough: false,
            wall_height: None,
            last_radii: Vec::new(),
            last_species: Vec::new(),
            blueprint_sent: false,
            legend_pending: None,
            last_frame: None,
            last_time: None,
            step: None,
            batch: Batch::default(),
            field_cells: [0, 0],
        };
        if let Err(e) = writer.log_static_scene() {
            return Err(writer.complete().err().unwrap_or(e));
        }
        Ok(Self {
            pending: Some(writer),
            tx: None,
            recycled: None,
            worker: None,
            file: partial,
            layout: layout.clone(),
            color_by,
        })
    }

    /// Starts the writer thread, with a queue sized for frames of `frame_bytes` bytes.
    fn start(&mut self, frame_bytes: usize) -> Result<(), String> {
        let Some(writer) = self.pending.take() else {
            return Ok(());
        };
        let frame_bytes = frame_bytes + 1;
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
        let tx = self
            .tx
            .as_ref()
            .ok_or_else(|| err("send", "the recording is closed"))?;
        let mut msg = msg;
        let mut waiting = Waiting::new(&self.file.tmp);
        loop {
            match tx.try_send(msg) {
                Ok(()) => return Ok(()),
                Err(TrySendError::Full(m)) => msg = m,
                Err(TrySendError::Disconnected(_)) => {
                    self.tx = None;
                    return Err(self
                        .join()
                        .err()
                        .unwrap_or_else(|| err("send", "the writer thread stopped")));
                }
            }
            waiting.pause()?;
        }
    }

    /// Closes the queue and waits for the writer thread, which completes the file (or, before
    /// the first frame, completes it on this thread).
    fn join(&mut self) -> Result<(), String> {
        if let Some(writer) = self.pending.take() {
            return writer.complete();
        }
        self.tx = None;
        let Some(worker) = self.worker.take() else {
            return Ok(());
        };
        let mut waiting = Waiting::new(&self.file.tmp);
        while !worker.is_finished() {
            // A writer stuck past the grace is left behind: the process ends without it.
            waiting.pause()?;
        }
        worker
            .join()
            .unwrap_or_else(|_| Err(err("writer thread", "panicked")))
    }

    /// Queues one frame, written on timelines `frame` = `f.index` and `sim_time` = `f.time`:
    /// the disks, their orientations (when `f.spins` is `Some`), the floor line (when
    /// `f.floor_height` is `Some`), the profiles (when `f.profile` is `Some`) and every series
    /// value under `series/<name>`. Fails when the per-disk slices have different lengths, or
    /// with the writer's error once it failed.
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
        if f.spins.is_some_and(|s| s.len() != n) {
            return Err(format!(
                "rerun recording: frame {}: spins of {} disks for {} disks",
                f.index,
                f.spins.map_or(0, <[_]>::len),
                n
            ));
        }
        // Six numbers per disk, eight for rough disks.
        let per_disk = if f.spins.is_some() { 8 } else { 6 };
        self.start(per_disk * 8 * n)?;
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

    /// The file being written (`FILE.partial` until the recorder finishes).
    pub fn file(&self) -> &crate::output::partial::Partial {
        &self.file
    }

    /// Writes what is queued, sends the blueprint if no frame was written, flushes everything
    /// to disk and closes the file, writing its footer. Dropping a `RerunRecorder` without
    /// calling this also completes the file, but silently.
    pub fn finish(mut self) -> Result<(), String> {
        self.join()
    }
}

/// A run's frames go to the recording; its failures are output failures (the run goes on).
impl FrameSink for RerunRecorder {
    fn frame(&mut self, frame: &FrameView) -> crate::error::Result<()> {
        RerunRecorder::frame(self, frame).map_err(Error::Io)
    }
    fn log_text(&mut self, time: f64, level: &str, text: &str) -> crate::error::Result<()> {
        RerunRecorder::log_text(self, time, level, text).map_err(Error::Io)
    }
    fn finish(self: Box<Self>) -> crate::error::Result<()> {
        RerunRecorder::finish(*self).map_err(Error::Io)
    }
    fn file(&self) -> Option<crate::output::partial::Partial> {
        Some(RerunRecorder::file(self).clone())
    }
}

/// Waiting on the writer thread: short sleeps, for as long as it takes, but no longer than
/// [`GRACE`] once a signal has asked the run to stop.
struct Waiting<'a> {
    /// The recording's temporary file.
    file: &'a Path,
    /// When the stop signal was first seen while waiting.
    signalled: Option<Instant>,
}

impl<'a> Waiting<'a> {
    fn new(file: &'a Path) -> Self {
        Waiting {
            file,
            signalled: None,
        }
    }

    fn pause(&mut self) -> Result<(), String> {
        if crate::platform::signals::stop_flag().load(Ordering::Relaxed) {
            let since = *self.signalled.get_or_insert_with(Instant::now);
            if since.elapsed() > GRACE {
                return Err(err(
                    "writer",
                    format!(
                        "still writing {} {} s after the stop signal: given up, the file is \
                         left as it is",
                        self.file.display(),
                        GRACE.as_secs()
                    ),
                ));
            }
        }
        std::thread::sleep(Duration::from_millis(1));
        Ok(())
    }
}

impl Drop for RerunRecorder {
    /// A recorder dropped without [`finish`](Self::finish) (an error or a panic in the run)
    /// still writes what is queued and completes the file, laid out.
    fn drop(&mut self) {
        let _ = self.join();
    }
}
