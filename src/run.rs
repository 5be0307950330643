//! Running a scenario: set up the scene, drive the engine from one exact sample or frame time to
//! the next, measure, record, and summarise.

use crate::checkpoint::Checkpoint;
use crate::disks::Disks;
use crate::dynamics::{Ballistic, Flight, Straight};
use crate::error::{Error, Result};
use crate::locals::Top;
use crate::measure::{Observables, Profiles};
use crate::output::frame::{FrameView, SceneLayout};
use crate::output::progress::{ProgressMode, ProgressReport};
use crate::output::trajectory::TrajectoryWriter;
use crate::scenario::{checks::mean_disk_area, Scenario, Scheme, XBoundary, YBoundary};
use crate::schemes::{space_time::SpaceTime, time_step::TimeStep, Integrator};
use crate::simulation::{EnergyFlow, Progress, Scene, Simulation, Snapshot};
use crate::summary::{Ending, EnergyAt, EnergySummary, EngineSummary, Summary, Temperature};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Where frames go (the Rerun recorder, or a test's collector).
pub trait FrameSink {
    /// Takes one frame.
    fn frame(&mut self, frame: &FrameView) -> Result<()>;
    /// Logs a line of text at simulated time `time` (`level`: "INFO", "WARN", …).
    fn log_text(&mut self, time: f64, level: &str, text: &str) -> Result<()>;
    /// Closes the output (writes footers).
    fn finish(self: Box<Self>) -> Result<()>;
}

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
    /// Show progress on stderr: a bar on a terminal, a start and an end line otherwise.
    pub progress: bool,
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
    if (opts.checkpoint.is_some() || opts.resume.is_some())
        && s.engine.scheme != Scheme::EventDriven
    {
        return Err(Error::input(
            "engine.scheme",
            "checkpoints need the event-driven scheme (the approximate schemes cannot be resumed)",
        ));
    }
    if let Some(every) = opts.checkpoint.as_ref().and_then(|c| c.every) {
        if !(every.is_finite() && every > 0.0) {
            return Err(Error::input(
                "--checkpoint-every",
                format!("must be a positive finite simulated time (got {every})"),
            ));
        }
    }
    let (scene, disks) = Scene::build(s)?;
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
    match scene.gravity {
        Some(g) => run_with(Ballistic { g }, s, &scene, disks, out, &opts),
        None => run_with(Straight, s, &scene, disks, out, &opts),
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

/// The frame sink: the caller's, else a recording opened only now that the engine has accepted
/// the initial state (a refused scene leaves no file behind).
fn sink_for(
    out: &mut Outputs,
    s: &Scenario,
    scene: &Scene,
    disks: &crate::disks::Disks,
) -> Result<Option<Box<dyn FrameSink>>> {
    match (out.sink.take(), &out.rrd) {
        (Some(sink), _) => Ok(Some(sink)),
        (None, Some(path)) => Ok(Some(open_recording(
            path,
            s,
            scene,
            disks,
            out.recording_id.as_deref(),
        )?)),
        (None, None) => Ok(None),
    }
}

/// Builds the engine of `engine.scheme` for the flight law and drives it.
fn run_with<F: Flight>(
    flight: F,
    s: &Scenario,
    scene: &Scene,
    disks: crate::disks::Disks,
    mut out: Outputs,
    opts: &RunOptions,
) -> Result<Summary> {
    match s.engine.scheme {
        Scheme::EventDriven => {
            let sim = Simulation::new(flight, scene, disks)?;
            let sink = sink_for(&mut out, s, scene, sim.disks())?;
            drive(sim, s, scene, sink, out, opts)
        }
        Scheme::TimeStep => {
            let sim = TimeStep::new(flight, scene, disks, &s.engine)?;
            let sink = sink_for(&mut out, s, scene, sim.disks())?;
            drive(sim, s, scene, sink, out, opts)
        }
        Scheme::SpaceTime => {
            let sim = SpaceTime::new(flight, scene, disks, &s.engine)?;
            let sink = sink_for(&mut out, s, scene, sim.disks())?;
            drive(sim, s, scene, sink, out, opts)
        }
    }
}

/// The fixed geometry of the scene, as the recording and the trajectory draw it, and the colour
/// scale of speeds: `output.speed_scale`, else three times the floor's peak speed, else three
/// times the initial root-mean-square speed (else 1).
fn scene_layout(s: &Scenario, scene: &Scene, disks: &crate::disks::Disks) -> SceneLayout {
    let floor_speed = scene.floor.as_ref().map_or(0.0, |f| f.max_speed());
    let n = disks.len().max(1) as f64;
    let rms = (disks
        .motion
        .iter()
        .map(|m| m.vx * m.vx + m.vy * m.vy)
        .sum::<f64>()
        / n)
        .sqrt();
    let speed_scale = s.output.speed_scale.unwrap_or(if floor_speed > 0.0 {
        3.0 * floor_speed
    } else if rms > 0.0 {
        3.0 * rms
    } else {
        1.0
    });
    SceneLayout {
        name: s.name.clone(),
        width: s.domain.width,
        x_periodic: s.domain.x_boundary == XBoundary::Periodic,
        top: match s.domain.y_boundary {
            YBoundary::Open => None,
            _ => s.domain.height,
        },
        y_periodic: s.domain.y_boundary == YBoundary::Periodic,
        floor: s.floor.is_some(),
        species: disks.species.iter().max().map_or(1, |&m| m as usize + 1),
        speed_scale,
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

/// The trajectory writer of `--trajectory` or `output.trajectory`, if any.
fn open_trajectory(
    s: &Scenario,
    scene: &Scene,
    opts: &RunOptions,
    disks: &crate::disks::Disks,
) -> Result<Option<TrajectoryWriter>> {
    let path = opts
        .trajectory
        .clone()
        .or_else(|| s.output.trajectory.as_ref().map(PathBuf::from));
    path.map(|p| TrajectoryWriter::create(&p, &scene_layout(s, scene, disks)).map_err(Error::Io))
        .transpose()
}

#[cfg(feature = "record")]
fn open_recording(
    path: &std::path::Path,
    s: &Scenario,
    scene: &Scene,
    disks: &crate::disks::Disks,
    recording_id: Option<&str>,
) -> Result<Box<dyn FrameSink>> {
    use crate::output::frame::ColorBy;
    use crate::output::recording::RerunRecorder;
    use crate::scenario::ColorChoice;

    struct Sink(RerunRecorder);
    impl FrameSink for Sink {
        fn frame(&mut self, frame: &FrameView) -> Result<()> {
            self.0.frame(frame).map_err(Error::Io)
        }
        fn log_text(&mut self, time: f64, level: &str, text: &str) -> Result<()> {
            self.0.log_text(time, level, text).map_err(Error::Io)
        }
        fn finish(self: Box<Self>) -> Result<()> {
            self.0.finish().map_err(Error::Io)
        }
    }

    let layout = scene_layout(s, scene, disks);
    let color = match s.output.color_by {
        ColorChoice::Speed => ColorBy::Speed,
        ColorChoice::Species => ColorBy::Species,
    };
    let rec = RerunRecorder::create_with_id(path, &layout, color, recording_id)
        .map_err(|e| Error::Io(format!("cannot record to {}: {e}", path.display())))?;
    Ok(Box::new(Sink(rec)))
}

#[cfg(not(feature = "record"))]
fn open_recording(
    _path: &std::path::Path,
    _s: &Scenario,
    _scene: &Scene,
    _disks: &crate::disks::Disks,
    _recording_id: Option<&str>,
) -> Result<Box<dyn FrameSink>> {
    Err(Error::input(
        "--rrd",
        "this build of vibrobed has no recording (build with the `record` feature)",
    ))
}

/// Simulated time of frame `k`: `k·dt`, or the duration when `k·dt` passes it by round-off only,
/// so that a duration that is a multiple of the frame interval ends with a frame (29 × 0.1 =
/// 2.9000000000000004 > 2.9: without this the last frame of a 2.9-long run would be lost).
fn frame_time(k: u64, dt: f64, duration: f64) -> f64 {
    let t = k as f64 * dt;
    if t > duration && t - duration <= 1e-6 * dt {
        duration
    } else {
        t
    }
}

/// The window over which averages are taken (from the end of the warm-up).
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
struct Window {
    time: f64,
    virial: f64,
    floor_impacts: u64,
}

/// When the run next stops, and for what: samples, frames, the end of the warm-up, the end.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
struct Stops {
    sample_dt: f64,
    frame_dt: f64,
    trajectory_dt: f64,
    duration: f64,
    warmup: f64,
    /// Samples taken so far.
    k_sample: u64,
    /// Frames recorded so far.
    k_frame: u64,
    /// Trajectory frames written so far.
    k_trajectory: u64,
    /// Simulated time between checkpoints (∞: none on a schedule).
    checkpoint_dt: f64,
    /// The next scheduled checkpoint is the `k_checkpoint`-th (from 1: none at the start).
    k_checkpoint: u64,
}

/// The next stop: its time and what is due then.
#[derive(Debug, Clone, Copy)]
struct Stop {
    time: f64,
    sample: bool,
    frame: bool,
    trajectory: bool,
    window: bool,
    checkpoint: bool,
}

impl Stops {
    fn new(s: &Scenario, checkpoint_every: Option<f64>) -> Stops {
        let duration = s.run.duration;
        let default_dt = duration / 200.0;
        Stops {
            sample_dt: s
                .output
                .sample_interval
                .or(s.output.frame_interval)
                .unwrap_or(default_dt),
            frame_dt: s.output.frame_interval.unwrap_or(default_dt),
            trajectory_dt: s
                .output
                .trajectory_interval
                .or(s.output.frame_interval)
                .unwrap_or(default_dt),
            duration,
            warmup: s.run.warmup,
            k_sample: 0,
            k_frame: 0,
            k_trajectory: 0,
            checkpoint_dt: checkpoint_every.unwrap_or(f64::INFINITY),
            k_checkpoint: 1,
        }
    }

    /// After a resume at engine time `t`: frames and trajectory frames the saved run did not
    /// write (it had no recording or trajectory) start at `t`, not at 0; checkpoints follow the
    /// new interval from `t` on.
    fn resume_at(&mut self, t: f64, checkpoint_every: Option<f64>) {
        while frame_time(self.k_frame, self.frame_dt, f64::INFINITY) < t {
            self.k_frame += 1;
        }
        while frame_time(self.k_trajectory, self.trajectory_dt, f64::INFINITY) < t {
            self.k_trajectory += 1;
        }
        self.checkpoint_dt = checkpoint_every.unwrap_or(f64::INFINITY);
        self.k_checkpoint = if self.checkpoint_dt.is_finite() {
            (t / self.checkpoint_dt).floor() as u64 + 1
        } else {
            1
        };
    }

    /// The next stop, given whether frames are recorded, whether a trajectory is written and
    /// whether the window is open.
    fn next(&self, recording: bool, trajectory: bool, window_open: bool) -> Stop {
        let t_sample = frame_time(self.k_sample, self.sample_dt, self.duration);
        let t_frame = if recording {
            frame_time(self.k_frame, self.frame_dt, self.duration)
        } else {
            f64::INFINITY
        };
        let t_trajectory = if trajectory {
            frame_time(self.k_trajectory, self.trajectory_dt, self.duration)
        } else {
            f64::INFINITY
        };
        let t_window = if window_open {
            f64::INFINITY
        } else {
            self.warmup
        };
        let t_checkpoint = self.k_checkpoint as f64 * self.checkpoint_dt;
        let time = t_sample
            .min(t_frame)
            .min(t_trajectory)
            .min(t_window)
            .min(t_checkpoint)
            .min(self.duration);
        Stop {
            time,
            sample: time == t_sample,
            frame: time == t_frame,
            trajectory: time == t_trajectory,
            checkpoint: time == t_checkpoint,
            window: time == t_window,
        }
    }
}

/// What is averaged over the window: temperatures, centre of mass, height profiles.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Averages {
    window: Option<Window>,
    temperature: [f64; 2],
    com_height: f64,
    samples: usize,
    profiles: Option<Profiles>,
}

impl Averages {
    /// Adds one sample (after the warm-up only).
    fn add(&mut self, snap: &Snapshot, disks: &Disks, o: &Observables) {
        self.temperature[0] += o.temperature[0];
        self.temperature[1] += o.temperature[1];
        self.com_height += o.com_height;
        self.samples += 1;
        if let Some(p) = self.profiles.as_mut() {
            p.add(snap, disks);
        }
    }

    fn temperature(&self) -> Temperature {
        let n = self.samples.max(1) as f64;
        Temperature {
            x: self.temperature[0] / n,
            y: self.temperature[1] / n,
            mean: 0.5 * (self.temperature[0] + self.temperature[1]) / n,
        }
    }
}

/// Empty height profiles for a gravity scene: from the floor's lowest point to
/// `output.profile_height` (default: twice the highest disk top at the start).
fn empty_profiles(s: &Scenario, scene: &Scene, snap: &Snapshot, disks: &Disks) -> Option<Profiles> {
    scene.gravity?;
    let bottom = scene.floor.as_ref().map_or(0.0, |f| f.lowest());
    let top = s.output.profile_height.unwrap_or_else(|| {
        let highest = (0..disks.len())
            .map(|i| snap.y[i] + disks.radius[i])
            .fold(0.0, f64::max);
        2.0 * highest.max(bottom + 1.0)
    });
    Some(Profiles::new(
        s.output.profile_bins,
        bottom,
        top,
        s.domain.width,
    ))
}

/// One run of an engine from the start to its ending: the engine, where its frames go, and what
/// is measured along the way.
struct Driver<'a, E: Integrator> {
    sim: E,
    s: &'a Scenario,
    scene: &'a Scene,
    sink: Option<Box<dyn FrameSink>>,
    trajectory: Option<TrajectoryWriter>,
    g: f64,
    snap: Snapshot,
    initial: Observables,
    stops: Stops,
    averages: Averages,
    last_frame_collisions: u64,
    /// The caller's stop flag, also looked at between stops (a run with dense samples or
    /// frames can spend its time there).
    interrupt: Option<&'static AtomicBool>,
    /// Checkpoints to write, if asked.
    checkpoint: Option<CheckpointPlan>,
    /// The recording's id (kept across resumed parts) and the recordings written so far.
    recording_id: Option<String>,
    recordings: Vec<PathBuf>,
    /// Wall time of the parts before a resume, and the clock of this part.
    wall_before: f64,
    clock: Instant,
}

/// The driver's state in a checkpoint: the stop schedule, the averages, the initial energy.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DriverState {
    stops: Stops,
    averages: Averages,
    initial: Observables,
    last_frame_collisions: u64,
    /// Wall seconds spent by the run so far (all its parts).
    wall_seconds: f64,
    /// The engine's time at the checkpoint.
    time: f64,
}

impl DriverState {
    /// Simulated time at which the checkpoint was taken.
    pub fn time(&self) -> f64 {
        self.time
    }
}

impl<'a, E: Integrator> Driver<'a, E> {
    fn new(
        mut sim: E,
        s: &'a Scenario,
        scene: &'a Scene,
        sink: Option<Box<dyn FrameSink>>,
        trajectory: Option<TrajectoryWriter>,
        opts: &RunOptions,
        recording_id: Option<String>,
    ) -> Driver<'a, E> {
        if let Some(flag) = opts.interrupt {
            sim.set_interrupt(flag);
        }
        let g = scene.gravity.unwrap_or(0.0);
        let mut snap = Snapshot::default();
        sim.snapshot_into(0.0, &mut snap);
        let initial = Observables::of(&snap, sim.disks(), g);
        let profiles = empty_profiles(s, scene, &snap, sim.disks());
        Driver {
            sim,
            s,
            scene,
            sink,
            trajectory,
            g,
            snap,
            initial,
            stops: Stops::new(s, opts.checkpoint.as_ref().and_then(|c| c.every)),
            averages: Averages {
                window: None,
                temperature: [0.0; 2],
                com_height: 0.0,
                samples: 0,
                profiles,
            },
            last_frame_collisions: 0,
            interrupt: opts.interrupt,
            checkpoint: opts.checkpoint.clone(),
            recording_id,
            recordings: Vec::new(),
            wall_before: 0.0,
            clock: Instant::now(),
        }
    }

    /// Continues the run a checkpoint holds: the engine's state, the stop schedule (to the new
    /// duration), the averages so far. The duration may be extended, not cut below the
    /// checkpoint's time.
    fn resume(&mut self, ck: Checkpoint) -> Result<()> {
        let at = ck.driver.time;
        if self.stops.duration < at {
            return Err(Error::input(
                "run.duration",
                format!(
                    "the checkpoint is at t = {at}; a resumed run must end at or after it (got {})",
                    self.stops.duration
                ),
            ));
        }
        if ck.driver.averages.profiles.is_some() != self.averages.profiles.is_some() {
            return Err(Error::input(
                "CHECKPOINT",
                "its profiles do not fit this scene",
            ));
        }
        self.sim.restore_state(ck.engine)?;
        let d = ck.driver;
        let duration = self.stops.duration;
        self.stops = Stops {
            duration,
            ..d.stops
        };
        self.stops.resume_at(
            self.sim.time(),
            self.checkpoint.as_ref().and_then(|c| c.every),
        );
        self.averages = d.averages;
        self.initial = d.initial;
        self.last_frame_collisions = d.last_frame_collisions;
        self.wall_before = d.wall_seconds;
        self.recordings = ck.recordings;
        Ok(())
    }

    /// Writes a checkpoint, if asked: the engine between events, this driver, the scene's text.
    fn save_checkpoint(&self) -> Result<()> {
        let Some(plan) = &self.checkpoint else {
            return Ok(());
        };
        let engine = self.sim.saved_state().ok_or_else(|| {
            Error::input(
                "engine.scheme",
                "only the event-driven scheme can be checkpointed",
            )
        })?;
        Checkpoint {
            scenario: plan.scenario.clone(),
            source: plan.source.clone(),
            sets: plan.sets.clone(),
            every: plan.every,
            recording_id: self.recording_id.clone(),
            recordings: self.recordings.clone(),
            driver: DriverState {
                stops: self.stops,
                averages: self.averages.clone(),
                initial: self.initial,
                last_frame_collisions: self.last_frame_collisions,
                wall_seconds: self.wall_before + self.clock.elapsed().as_secs_f64(),
                time: self.sim.time(),
            },
            engine,
        }
        .write(&plan.path)
    }

    /// Runs from stop to stop until the duration, the event limit or an interrupt.
    fn run(&mut self, progress: &ProgressReport) -> Result<Ending> {
        if let Some(sink) = self.sink.as_mut() {
            let text = format!(
                "start: {} disks, scene {}",
                self.sim.disks().len(),
                self.s.name
            );
            sink.log_text(0.0, "INFO", &text)?;
        }
        loop {
            if self.interrupt.is_some_and(|f| f.load(Ordering::Relaxed)) {
                return Ok(Ending::Interrupted);
            }
            let stop = self.stops.next(
                self.sink.is_some(),
                self.trajectory.is_some(),
                self.averages.window.is_some(),
            );
            match self.sim.advance_to(stop.time)? {
                Progress::Reached => {}
                Progress::EventLimit => return Ok(Ending::EventLimit),
                Progress::Interrupted => return Ok(Ending::Interrupted),
            }
            self.sim.snapshot_into(stop.time, &mut self.snap);
            if stop.window {
                self.open_window(stop.time)?;
            }
            if stop.sample {
                self.sample()?;
            }
            if stop.frame {
                self.frame()?;
            }
            if stop.trajectory {
                self.trajectory_frame()?;
            }
            if stop.checkpoint {
                self.stops.k_checkpoint += 1;
                self.save_checkpoint()?;
            }
            progress.update(stop.time, self.sim.counts().collisions());
            if stop.time >= self.stops.duration {
                return Ok(Ending::Completed);
            }
        }
    }

    /// The warm-up is over: averaging starts.
    fn open_window(&mut self, t: f64) -> Result<()> {
        self.averages.window = Some(Window {
            time: t,
            virial: self.sim.virial(),
            floor_impacts: self.sim.counts().floor,
        });
        if let (Some(sink), true) = (self.sink.as_mut(), self.stops.warmup > 0.0) {
            sink.log_text(t, "INFO", "warm-up over: averaging starts")?;
        }
        Ok(())
    }

    /// A sample: measured into the averages after the warm-up; invariants checked if asked.
    fn sample(&mut self) -> Result<()> {
        self.stops.k_sample += 1;
        if self.averages.window.is_some() {
            let o = Observables::of(&self.snap, self.sim.disks(), self.g);
            self.averages.add(&self.snap, self.sim.disks(), &o);
        }
        if self.scene.check_invariants {
            check_sample(&self.sim, &self.snap, &self.initial, self.g)?;
        }
        Ok(())
    }

    /// A frame: the disks and the time series, to the sink.
    fn frame(&mut self) -> Result<()> {
        self.stops.k_frame += 1;
        let Some(sink) = self.sink.as_mut() else {
            return Ok(());
        };
        let sim = &self.sim;
        let snap = &self.snap;
        let o = Observables::of(snap, sim.disks(), self.g);
        let flow = sim.energy_flow_at(snap.time);
        let collisions = sim.counts().collisions();
        let rate = (collisions - self.last_frame_collisions) as f64 / self.stops.frame_dt;
        self.last_frame_collisions = collisions;
        let series = [
            ("temperature/x", o.temperature[0]),
            ("temperature/y", o.temperature[1]),
            ("energy/kinetic", o.kinetic),
            ("energy/potential", o.potential),
            ("energy/injected", flow.injected),
            ("energy/dissipated", flow.dissipated),
            ("com_height", o.com_height),
            (
                "collisions_per_time",
                if self.stops.k_frame > 1 { rate } else { 0.0 },
            ),
        ];
        let d = sim.disks();
        let profile = self
            .averages
            .profiles
            .as_ref()
            .map(|p| p.of_snapshot(snap, d));
        sink.frame(&FrameView {
            index: self.stops.k_frame - 1,
            time: snap.time,
            x: &snap.x,
            y: &snap.y,
            vx: &snap.vx,
            vy: &snap.vy,
            radius: &d.radius,
            species: &d.species,
            floor_height: snap.floor_height,
            series: &series,
            profile: profile.as_ref(),
        })
    }

    /// A trajectory frame: every disk, to the extended XYZ file.
    fn trajectory_frame(&mut self) -> Result<()> {
        self.stops.k_trajectory += 1;
        let Some(w) = self.trajectory.as_mut() else {
            return Ok(());
        };
        let (snap, d) = (&self.snap, self.sim.disks());
        w.frame(&FrameView {
            index: self.stops.k_trajectory - 1,
            time: snap.time,
            x: &snap.x,
            y: &snap.y,
            vx: &snap.vx,
            vy: &snap.vy,
            radius: &d.radius,
            species: &d.species,
            floor_height: snap.floor_height,
            series: &[],
            profile: None,
        })
        .map_err(Error::Io)
    }

    /// Closes the recording with a note on how the run ended.
    fn close_sink(&mut self, ending: Ending, end_time: f64) -> Result<()> {
        if let Some(mut sink) = self.sink.take() {
            let note = match ending {
                Ending::Completed => "run completed".to_string(),
                Ending::Interrupted => format!("interrupted at t = {end_time}"),
                Ending::EventLimit => format!("event limit reached at t = {end_time}"),
            };
            let level = if ending == Ending::Completed {
                "INFO"
            } else {
                "WARN"
            };
            sink.log_text(end_time, level, &note)?;
            sink.finish()?;
        }
        Ok(())
    }

    /// Ends the run: the final state, the outputs closed, the summary.
    fn finish(mut self, ending: Ending, wall: f64, progress: ProgressReport) -> Result<Summary> {
        let end_time = if ending == Ending::Completed {
            self.stops.duration
        } else {
            self.sim.time()
        };
        self.sim.snapshot_into(end_time, &mut self.snap);
        // However the run ended (completed, event limit, signal), its state is saved: a resume
        // can extend the duration or the event budget.
        self.save_checkpoint()?;
        progress.finish(ending, end_time, self.sim.counts().collisions());
        if let Some(w) = self.trajectory.take() {
            w.finish().map_err(Error::Io)?;
        }
        self.close_sink(ending, end_time)?;
        Ok(self.summarise(ending, end_time, wall))
    }

    /// The summary of a run that ended at `end_time`.
    fn summarise(&self, ending: Ending, end_time: f64, wall: f64) -> Summary {
        let (s, scene, sim) = (self.s, self.scene, &self.sim);
        let n = sim.disks().len();
        let last = Observables::of(&self.snap, sim.disks(), self.g);
        let flow = sim.energy_flow_at(self.snap.time);
        let avg = &self.averages;
        let measured = avg
            .window
            .as_ref()
            .map(|w| (end_time - w.time, w))
            .filter(|(dt, _)| *dt > 0.0);
        let compressibility_factor = match (closed_elastic(s, scene), measured) {
            (true, Some((dt, w))) if avg.samples > 0 => {
                let kt = last.kinetic / n as f64; // conserved in a closed elastic box
                Some(1.0 + (sim.virial() - w.virial) / (2.0 * dt * n as f64 * kt))
            }
            _ => None,
        };
        let box_area = match scene.top {
            Top::Lid { height, .. } | Top::Periodic { height } => Some(s.domain.width * height),
            Top::Open => None,
        };
        let counts = sim.counts();
        let setup = sim.setup();
        Summary {
            scenario: s.name.clone(),
            seed: s.seed,
            particles: n,
            ending,
            sim_time: end_time,
            wall_seconds: self.wall_before + wall,
            events: counts,
            collisions_per_second: counts.collisions() as f64 / (self.wall_before + wall).max(1e-9),
            energy: EnergySummary {
                initial: EnergyAt::from(&self.initial),
                final_: EnergyAt::from(&last),
                injected: flow.injected,
                dissipated: flow.dissipated,
                balance_error: balance_error(&self.initial, &last, &flow),
            },
            temperature: avg.temperature(),
            compressibility_factor,
            packing_fraction: box_area.map(|a| n as f64 * mean_disk_area(s) / a),
            max_overlap: sim.max_overlap(),
            com_height: scene
                .gravity
                .map(|_| avg.com_height / avg.samples.max(1) as f64),
            impacts_per_unit_time: match (&scene.floor, measured) {
                (Some(_), Some((dt, w))) => Some((counts.floor - w.floor_impacts) as f64 / dt),
                _ => None,
            },
            profiles: avg.profiles.as_ref().map(|p| p.table()),
            engine: EngineSummary {
                scheme: setup.scheme.into(),
                mask: setup.mask,
                cell: setup.cell,
                grid: setup.grid,
                bytes_per_disk: setup.bytes as f64 / n as f64,
                samples: avg.samples,
            },
            approximation: sim.approximation(),
        }
    }
}

/// `true` for a closed elastic box without gravity, where the compressibility factor is defined.
fn closed_elastic(s: &Scenario, scene: &Scene) -> bool {
    scene.gravity.is_none()
        && s.domain.y_boundary != YBoundary::Open
        && scene.restitution == 1.0
        && s.domain.wall_restitution == 1.0
        && scene
            .floor
            .as_ref()
            .is_none_or(|f| f.is_static() && f.restitution == 1.0)
}

/// |now − initial − injected + dissipated| relative to the largest term of the energy budget.
fn balance_error(initial: &Observables, now: &Observables, flow: &EnergyFlow) -> f64 {
    let balance = now.energy() - initial.energy() - flow.injected + flow.dissipated;
    let scale = initial
        .energy()
        .abs()
        .max(now.energy().abs())
        .max(flow.injected.abs())
        .max(flow.dissipated)
        .max(f64::MIN_POSITIVE);
    balance.abs() / scale
}

/// Drives engine `sim` through the scenario and summarises the run.
fn drive<E: Integrator>(
    sim: E,
    s: &Scenario,
    scene: &Scene,
    sink: Option<Box<dyn FrameSink>>,
    out: Outputs,
    opts: &RunOptions,
) -> Result<Summary> {
    let trajectory = open_trajectory(s, scene, opts, sim.disks())?;
    let mut driver = Driver::new(sim, s, scene, sink, trajectory, opts, out.recording_id);
    if let Some(ck) = out.resume {
        driver.resume(*ck)?;
    }
    if let Some(rrd) = out.rrd {
        driver.recordings.push(rrd);
    }
    let progress = ProgressReport::start(
        ProgressMode::for_stderr(opts.progress),
        &s.name,
        driver.sim.disks().len(),
        s.run.duration,
    );
    driver.clock = Instant::now();
    let ending = driver.run(&progress)?;
    let wall = driver.clock.elapsed().as_secs_f64();
    driver.finish(ending, wall, progress)
}

/// Invariant checks at a sample: no overlap, energy balance.
fn check_sample<E: Integrator>(
    sim: &E,
    snap: &Snapshot,
    initial: &Observables,
    g: f64,
) -> Result<()> {
    sim.check_state(snap)?;
    let now = Observables::of(snap, sim.disks(), g);
    let flow = sim.energy_flow_at(snap.time);
    let error = balance_error(initial, &now, &flow);
    if error > 1e-9 {
        return Err(Error::Runtime(format!(
            "energy budget off by {error:e} (relative) at time {}",
            snap.time
        )));
    }
    Ok(())
}
