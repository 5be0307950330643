//! Running a scenario: set up the scene, drive the engine from one exact sample or frame time to
//! the next, measure, record, and summarise.

use crate::engine::published_clock::PublishedClock;
use crate::engine::{Scene, Simulation};
use crate::error::{Error, Result};
use crate::output::frame::SceneLayout;
use crate::output::open_recording;
use crate::output::progress::{ProgressMode, ProgressReport, DEFAULT_EVERY};
use crate::output::summary::Summary;
use crate::output::trajectory::TrajectoryWriter;
use crate::output::watch::{Target, Watch};
use crate::physics::flight::{Ballistic, Flight, Straight};
use crate::scenario::{Scenario, Scheme};
use crate::schemes::{
    contact::Contact, handover::Handover, space_time::SpaceTime, time_step::TimeStep, Integrator,
};
use checkpoint::Checkpoint;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

mod averages;
pub mod checkpoint;
mod driver;
mod failures;
mod fields_file;
mod frames;
mod invariants;
mod resume;
pub mod state;
mod stops;
mod streams;
mod summary;
mod views;
mod wall_limit;

use driver::Driver;
use resume::CheckpointFile;
use streams::{OnFailure, Streams, Takes};
use wall_limit::WallLimit;

/// Where frames go: the recording, or a test's collector.
pub use crate::output::frame::FrameSink;

/// How to run.
#[derive(Default)]
pub struct RunOptions {
    /// Record frames to this .rrd file (overrides `output.rrd`).
    pub rrd: Option<PathBuf>,
    /// Write an extended XYZ trajectory to this file (overrides `output.trajectory`).
    pub trajectory: Option<PathBuf>,
    /// Frame sink to use instead of a recording (tests).
    pub sink: Option<Box<dyn FrameSink>>,
    /// Stop at the next event once this flag is set.
    pub interrupt: Option<&'static AtomicBool>,
    /// Write checkpoints (`--checkpoint`): at the end, however the run ends, and every
    /// `every` of simulated time if set.
    pub checkpoint: Option<CheckpointPlan>,
    /// Continue the run a checkpoint holds (`vibrobed resume`) instead of starting afresh.
    pub resume: Option<Box<Checkpoint>>,
    /// Show progress on stderr: a bar on a terminal, a start line, a line every
    /// `progress_every` seconds and an end line otherwise.
    pub progress: bool,
    /// Wall seconds between progress lines off a terminal (default
    /// [`DEFAULT_EVERY`]).
    pub progress_every: Option<f64>,
    /// The name of a sweep's run: with `progress`, only its lines every `progress_every` seconds
    /// off a terminal, named so (the sweep tells when each run starts and ends), none on one.
    pub progress_label: Option<String>,
    /// Measure the 2D fields after the warm-up (`run --fields`; gravity scenes).
    pub fields: bool,
    /// Write the fields measured to this file at the end (measuring them).
    pub fields_file: Option<PathBuf>,
    /// Files written once the run has ended (`summary`, `profiles`: the output and its path),
    /// whose directories are watched while it runs.
    pub written_after: Vec<(&'static str, PathBuf)>,
}

/// Where and how often a run writes checkpoints, and what it needs to rebuild its scene.
#[derive(Debug, Clone, Default)]
pub struct CheckpointPlan {
    /// The checkpoint file (rewritten atomically each time).
    pub path: PathBuf,
    /// Simulated time between checkpoints; `None`: only at the end (and on a signal).
    pub every: Option<f64>,
    /// The scenario's text.
    pub scenario: String,
    /// Where the scenario was read from.
    pub source: PathBuf,
    /// The `--set` overrides, in order.
    pub sets: Vec<String>,
}

/// Runs a validated scenario and returns its summary.
pub fn run(s: &Scenario, mut opts: RunOptions) -> Result<Summary> {
    crate::platform::memory::for_disks(s.disk_count());
    if (opts.checkpoint.is_some() || opts.resume.is_some())
        && !matches!(s.scheme(), Scheme::EventDriven | Scheme::Hybrid)
    {
        return Err(Error::input(
            "engine.scheme",
            "checkpoints need the event-driven or hybrid scheme (the approximate schemes cannot \
             be resumed)",
        ));
    }
    if let Some(every) = opts.checkpoint.as_ref().and_then(|c| c.every) {
        crate::scenario::intervals::checkpoint_every(every, s.run.duration)?;
    }
    // The placement's Monte Carlo watches the stop flag: a run interrupted while its disks
    // are placed stops then.
    let (scene, disks) =
        crate::engine::placement::interruptible(opts.interrupt, || Scene::build(s))?;
    let rrd = opts
        .rrd
        .clone()
        .or_else(|| s.output.rrd.as_ref().map(PathBuf::from));
    let resume = opts.resume.take();
    let recording_id = resume
        .as_ref()
        .and_then(|c| c.recording_id.clone())
        .or_else(|| rrd.as_ref().map(|_| new_recording_id()));
    let out = Outputs {
        sink: opts.sink.take(),
        rrd,
        recording_id,
        resume,
    };
    let layout = SceneLayout::of(s, &scene, &disks);
    let then = Driving {
        s,
        scene: &scene,
        layout,
        out,
        opts: &opts,
    };
    with_engine(s, &scene, disks, then)
}

/// Builds the scene and the engine of `engine.scheme` (grid, neighbour lists, first
/// predictions) without simulating: `vibrobed check` accepts exactly what a run accepts. A
/// `random` placement is left unmelted ([`placement::unmelted`](crate::engine::placement::unmelted)).
pub fn check(s: &Scenario) -> Result<()> {
    let (scene, disks) = crate::engine::placement::unmelted(|| Scene::build(s))?;
    struct Built;
    impl WithEngine for Built {
        type Output = ();
        fn with<E: Integrator>(self, _: E) -> Result<()> {
            Ok(())
        }
    }
    with_engine(s, &scene, disks, Built)
}

/// What is done with the engine once it is built, whichever scheme and flight law it has.
trait WithEngine {
    /// What comes of it.
    type Output;
    /// Does it with engine `sim`.
    fn with<E: Integrator>(self, sim: E) -> Result<Self::Output>;
}

/// Builds the engine of `engine.scheme` with the scene's flight law and hands it to `then`: the
/// one place where a scheme and a flight law are chosen.
fn with_engine<W: WithEngine>(
    s: &Scenario,
    scene: &Scene,
    disks: crate::physics::disks::Disks,
    then: W,
) -> Result<W::Output> {
    fn build<F: Flight, W: WithEngine>(
        flight: F,
        s: &Scenario,
        scene: &Scene,
        disks: crate::physics::disks::Disks,
        then: W,
    ) -> Result<W::Output> {
        match s.scheme() {
            Scheme::EventDriven | Scheme::Auto => then.with(Simulation::new(flight, scene, disks)?),
            Scheme::TimeStep => then.with(TimeStep::new(flight, scene, disks, &s.engine)?),
            Scheme::SpaceTime => then.with(SpaceTime::new(flight, scene, disks, &s.engine)?),
            Scheme::Contact => then.with(Contact::new(flight, scene, disks, &s.engine)?),
            Scheme::Hybrid => then.with(Handover::new(flight, scene, disks, &s.engine)?),
        }
    }
    match scene.gravity {
        Some(g) => build(Ballistic { g }, s, scene, disks, then),
        None => build(Straight, s, scene, disks, then),
    }
}

/// Where a run's frames go, and the run it continues, if any.
struct Outputs {
    /// The caller's frame sink (tests), used instead of a recording.
    sink: Option<Box<dyn FrameSink>>,
    /// The recording file.
    rrd: Option<PathBuf>,
    /// The recording's id: the resumed run's, else a new one when recording.
    recording_id: Option<String>,
    /// The checkpoint to continue from.
    resume: Option<Box<Checkpoint>>,
}

/// The outputs written at stops, opened only now that the engine has accepted the initial state
/// (a refused scene leaves no file behind): the frame sink — the caller's, else the recording —
/// at the frames, the trajectory of `--trajectory` or `output.trajectory` at its frames, the
/// fields of `--fields` at the end, the checkpoint of `--checkpoint` at the checkpoints. A new
/// output is one more registration here.
fn open_streams(
    out: &mut Outputs,
    s: &Scenario,
    layout: &SceneLayout,
    opts: &RunOptions,
) -> Result<Streams> {
    let mut streams = Streams::default();
    let recording = match (out.sink.take(), &out.rrd) {
        (Some(sink), _) => Some(sink),
        (None, Some(path)) => Some(open_recording(
            path,
            s,
            layout,
            out.recording_id.as_deref(),
        )?),
        (None, None) => None,
    };
    if let Some(sink) = recording {
        let path = out.rrd.clone().unwrap_or_default();
        let (named, sink) = (("recording", path), Box::new(sink));
        streams.add(named, Takes::Frames, OnFailure::Drop, sink);
    }
    let trajectory = opts
        .trajectory
        .clone()
        .or_else(|| s.output.trajectory.as_ref().map(PathBuf::from));
    if let Some(path) = trajectory {
        let w = TrajectoryWriter::create(&path, layout).map_err(Error::Io)?;
        let path = w.partial().path.clone();
        let sink: Box<dyn FrameSink> = Box::new(w);
        streams.add(
            ("trajectory", path),
            Takes::TrajectoryFrames,
            OnFailure::Drop,
            Box::new(sink),
        );
    }
    if let Some(path) = &opts.fields_file {
        let named = ("fields", path.clone());
        let file = Box::new(fields_file::FieldsFile(path.clone()));
        streams.add(named, Takes::End, OnFailure::TryAgain, file);
    }
    if let Some(plan) = &opts.checkpoint {
        let file = CheckpointFile(plan.path.clone());
        let named = ("checkpoint", plan.path.clone());
        streams.add(
            named,
            Takes::Checkpoints,
            OnFailure::TryAgain,
            Box::new(file),
        );
    }
    Ok(streams)
}

/// A run's engine, once built, is driven through the scenario: its frame sink opened only now
/// that the engine has accepted the initial state.
struct Driving<'a> {
    s: &'a Scenario,
    scene: &'a Scene,
    layout: SceneLayout,
    out: Outputs,
    opts: &'a RunOptions,
}

impl WithEngine for Driving<'_> {
    type Output = Summary;
    fn with<E: Integrator>(mut self, sim: E) -> Result<Summary> {
        crate::platform::signals::built();
        let streams = open_streams(&mut self.out, self.s, &self.layout, self.opts)?;
        drive(sim, self.s, self.scene, streams, self.out, self.opts)
    }
}

/// A new recording id, from the wall clock: two runs of one scene are two recordings in the
/// viewer, while the parts of one resumed run share their first part's id.
fn new_recording_id() -> String {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    format!("vibrobed-{nanos:x}")
}

/// What the watch looks at: what the outputs at stops ask it to (the recording's and the
/// trajectory's temporary files, the checkpoint's directory), and the directories of the files
/// written at the end.
fn watch_targets<E: Integrator>(driver: &Driver<E>, opts: &RunOptions) -> Vec<Target> {
    let later = opts.written_after.iter();
    let later = later.map(|(output, path)| Target::later(output, path));
    driver.streams.watched().into_iter().chain(later).collect()
}

/// Drives engine `sim` through the scenario and summarises the run.
fn drive<E: Integrator>(
    sim: E,
    s: &Scenario,
    scene: &Scene,
    streams: Streams,
    out: Outputs,
    opts: &RunOptions,
) -> Result<Summary> {
    let mut driver = Driver::new(sim, s, scene, streams, opts, out.recording_id);
    if let Some(ck) = out.resume {
        driver.resume(*ck)?;
    }
    driver.recordings.extend(out.rrd);
    driver.watch = Watch::start(watch_targets(&driver, opts));
    let limit = s
        .run
        .max_wall_seconds
        .map(|seconds| WallLimit::start(seconds, opts.interrupt));
    if let Some(l) = &limit {
        driver.sim.set_interrupt(l.flag());
        driver.interrupt = Some(l.flag());
    }
    let clock = Arc::new(PublishedClock::new(
        driver.sim.time(),
        driver.sim.counts().collisions(),
    ));
    let _published = PublishedClock::install(Arc::clone(&clock));
    let progress = ProgressReport::start(
        progress_mode(opts),
        (
            opts.progress_label.as_deref().unwrap_or(&s.name),
            driver.sim.disks().len(),
        ),
        s.run.duration,
        opts.progress_every.unwrap_or(DEFAULT_EVERY),
        clock,
    );
    driver.clock = Instant::now();
    let ending = driver.run(&progress)?;
    let ending = limit.as_ref().map_or(ending, |l| l.ending(ending));
    drop(limit);
    let wall = driver.clock.elapsed().as_secs_f64();
    driver.finish(ending, wall, progress)
}

/// How a run shows its progress: not at all unless asked; a sweep's run only by lines off a
/// terminal, and on one (where its pool draws the bar) only by the note on a growing cost; a
/// run of its own as [`ProgressMode::for_stderr`].
fn progress_mode(opts: &RunOptions) -> ProgressMode {
    use std::io::IsTerminal;
    match (opts.progress, &opts.progress_label) {
        (false, _) => ProgressMode::Quiet,
        (true, Some(_)) if std::io::stderr().is_terminal() => ProgressMode::Notes,
        (true, Some(_)) => ProgressMode::Periodic,
        (true, None) => ProgressMode::for_stderr(true),
    }
}
