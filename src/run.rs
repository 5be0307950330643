//! Running a scenario: set up the scene, drive the engine from one exact sample or frame time to
//! the next, measure, record, and summarise.

use crate::dynamics::{Ballistic, Flight, Straight};
use crate::error::{Error, Result};
use crate::measure::{Observables, Profiles};
use crate::output::frame::{FrameView, SceneLayout};
use crate::output::progress::{ProgressMode, ProgressReport};
use crate::output::trajectory::TrajectoryWriter;
use crate::scenario::{checks::mean_disk_area, Scenario, Scheme, XBoundary, YBoundary};
use crate::schemes::{space_time::SpaceTime, time_step::TimeStep, Integrator};
use crate::simulation::{Progress, Scene, Simulation, Snapshot};
use crate::summary::{Ending, EnergyAt, EnergySummary, EngineSummary, Summary, Temperature};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
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
    /// Show progress on stderr: a bar on a terminal, a start and an end line otherwise.
    pub progress: bool,
}

/// Runs a validated scenario and returns its summary.
pub fn run(s: &Scenario, mut opts: RunOptions) -> Result<Summary> {
    let (scene, disks) = Scene::build(s)?;
    let rrd = opts
        .rrd
        .clone()
        .or_else(|| s.output.rrd.as_ref().map(PathBuf::from));
    let sink = opts.sink.take();
    match scene.gravity {
        Some(g) => run_with(Ballistic { g }, s, &scene, disks, sink, rrd, &opts),
        None => run_with(Straight, s, &scene, disks, sink, rrd, &opts),
    }
}

/// The frame sink: the caller's, else a recording opened only now that the engine has accepted
/// the initial state (a refused scene leaves no file behind).
fn sink_for(
    sink: Option<Box<dyn FrameSink>>,
    rrd: Option<PathBuf>,
    s: &Scenario,
    scene: &Scene,
    disks: &crate::disks::Disks,
) -> Result<Option<Box<dyn FrameSink>>> {
    match (sink, rrd) {
        (Some(sink), _) => Ok(Some(sink)),
        (None, Some(path)) => Ok(Some(open_recording(&path, s, scene, disks)?)),
        (None, None) => Ok(None),
    }
}

/// Builds the engine of `engine.scheme` for the flight law and drives it.
fn run_with<F: Flight>(
    flight: F,
    s: &Scenario,
    scene: &Scene,
    disks: crate::disks::Disks,
    sink: Option<Box<dyn FrameSink>>,
    rrd: Option<PathBuf>,
    opts: &RunOptions,
) -> Result<Summary> {
    match s.engine.scheme {
        Scheme::EventDriven => {
            let sim = Simulation::new(flight, scene, disks)?;
            let sink = sink_for(sink, rrd, s, scene, sim.disks())?;
            drive(sim, s, scene, sink, opts)
        }
        Scheme::TimeStep => {
            let sim = TimeStep::new(flight, scene, disks, &s.engine)?;
            let sink = sink_for(sink, rrd, s, scene, sim.disks())?;
            drive(sim, s, scene, sink, opts)
        }
        Scheme::SpaceTime => {
            let sim = SpaceTime::new(flight, scene, disks, &s.engine)?;
            let sink = sink_for(sink, rrd, s, scene, sim.disks())?;
            drive(sim, s, scene, sink, opts)
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
    let rec = RerunRecorder::create(path, &layout, color)
        .map_err(|e| Error::Io(format!("cannot record to {}: {e}", path.display())))?;
    Ok(Box::new(Sink(rec)))
}

#[cfg(not(feature = "record"))]
fn open_recording(
    _path: &std::path::Path,
    _s: &Scenario,
    _scene: &Scene,
    _disks: &crate::disks::Disks,
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
struct Window {
    time: f64,
    virial: f64,
    floor_impacts: u64,
}

fn drive<E: Integrator>(
    mut sim: E,
    s: &Scenario,
    scene: &Scene,
    mut sink: Option<Box<dyn FrameSink>>,
    opts: &RunOptions,
) -> Result<Summary> {
    if let Some(flag) = opts.interrupt {
        sim.set_interrupt(flag);
    }
    let g = scene.gravity.unwrap_or(0.0);
    let n = sim.disks().len();
    let duration = s.run.duration;
    let warmup = s.run.warmup;
    let default_dt = duration / 200.0;
    let frame_dt = s.output.frame_interval.unwrap_or(default_dt);
    let sample_dt = s
        .output
        .sample_interval
        .or(s.output.frame_interval)
        .unwrap_or(default_dt);
    let mut snap = Snapshot::default();
    sim.snapshot_into(0.0, &mut snap);
    let initial = Observables::of(&snap, sim.disks(), g);
    let mut profiles = scene.gravity.map(|_| {
        let bottom = scene.floor.as_ref().map_or(0.0, |f| f.lowest());
        let top = s.output.profile_height.unwrap_or_else(|| {
            let highest = (0..n)
                .map(|i| snap.y[i] + sim.disks().radius[i])
                .fold(0.0, f64::max);
            2.0 * highest.max(bottom + 1.0)
        });
        Profiles::new(s.output.profile_bins, bottom, top, s.domain.width)
    });
    let mut trajectory = open_trajectory(s, scene, opts, sim.disks())?;
    let trajectory_dt = s.output.trajectory_interval.unwrap_or(frame_dt);
    let mut k_trajectory = 0u64;
    let progress = ProgressReport::start(
        ProgressMode::for_stderr(opts.progress),
        &s.name,
        n,
        duration,
    );
    if let Some(sink) = sink.as_mut() {
        sink.log_text(
            0.0,
            "INFO",
            &format!("start: {} disks, scene {}", n, s.name),
        )?;
    }
    let (mut k_sample, mut k_frame) = (0u64, 0u64);
    let mut window: Option<Window> = None;
    let (mut t_sum, mut com_sum, mut samples) = ([0.0f64; 2], 0.0, 0usize);
    let mut last_frame_collisions = 0u64;
    let clock = Instant::now();
    let ending = loop {
        // The stop flag is also looked at between stops: a run with dense frames or samples
        // can spend its time there rather than in the engine.
        if opts
            .interrupt
            .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed))
        {
            break Ending::Interrupted;
        }
        let t_sample = frame_time(k_sample, sample_dt, duration);
        let t_frame = if sink.is_some() {
            frame_time(k_frame, frame_dt, duration)
        } else {
            f64::INFINITY
        };
        let t_window = if window.is_none() {
            warmup
        } else {
            f64::INFINITY
        };
        let t_trajectory = if trajectory.is_some() {
            frame_time(k_trajectory, trajectory_dt, duration)
        } else {
            f64::INFINITY
        };
        let t = t_sample
            .min(t_frame)
            .min(t_window)
            .min(t_trajectory)
            .min(duration);
        match sim.advance_to(t)? {
            Progress::Reached => {}
            Progress::EventLimit => break Ending::EventLimit,
            Progress::Interrupted => break Ending::Interrupted,
        }
        sim.snapshot_into(t, &mut snap);
        if t == t_window {
            window = Some(Window {
                time: t,
                virial: sim.virial(),
                floor_impacts: sim.counts().floor,
            });
            if let (Some(sink), true) = (sink.as_mut(), warmup > 0.0) {
                sink.log_text(t, "INFO", "warm-up over: averaging starts")?;
            }
        }
        if t == t_sample {
            k_sample += 1;
            if window.is_some() {
                let o = Observables::of(&snap, sim.disks(), g);
                t_sum[0] += o.temperature[0];
                t_sum[1] += o.temperature[1];
                com_sum += o.com_height;
                samples += 1;
                if let Some(p) = profiles.as_mut() {
                    p.add(&snap, sim.disks());
                }
            }
            if scene.check_invariants {
                check_sample(&sim, &snap, &initial, g)?;
            }
        }
        if t == t_frame {
            k_frame += 1;
            if let Some(sink) = sink.as_mut() {
                let o = Observables::of(&snap, sim.disks(), g);
                let flow = sim.energy_flow_at(snap.time);
                let collisions = sim.counts().collisions();
                let rate = (collisions - last_frame_collisions) as f64 / frame_dt;
                last_frame_collisions = collisions;
                let series = [
                    ("temperature/x", o.temperature[0]),
                    ("temperature/y", o.temperature[1]),
                    ("energy/kinetic", o.kinetic),
                    ("energy/potential", o.potential),
                    ("energy/injected", flow.injected),
                    ("energy/dissipated", flow.dissipated),
                    ("com_height", o.com_height),
                    ("collisions_per_time", if k_frame > 1 { rate } else { 0.0 }),
                ];
                let d = sim.disks();
                let profile = profiles.as_ref().map(|p| p.of_snapshot(&snap, d));
                sink.frame(&FrameView {
                    index: k_frame - 1,
                    time: t,
                    x: &snap.x,
                    y: &snap.y,
                    vx: &snap.vx,
                    vy: &snap.vy,
                    radius: &d.radius,
                    species: &d.species,
                    floor_height: snap.floor_height,
                    series: &series,
                    profile: profile.as_ref(),
                })?;
            }
        }
        if t == t_trajectory {
            k_trajectory += 1;
            if let Some(w) = trajectory.as_mut() {
                let d = sim.disks();
                w.frame(&FrameView {
                    index: k_trajectory - 1,
                    time: t,
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
                .map_err(Error::Io)?;
            }
        }
        progress.update(t, sim.counts().collisions());
        if t >= duration {
            break Ending::Completed;
        }
    };
    let wall = clock.elapsed().as_secs_f64();
    let end_time = if ending == Ending::Completed {
        duration
    } else {
        sim.time()
    };
    sim.snapshot_into(end_time, &mut snap);
    progress.finish(ending, end_time, sim.counts().collisions());
    let last = Observables::of(&snap, sim.disks(), g);
    if let Some(w) = trajectory {
        w.finish().map_err(Error::Io)?;
    }
    if let Some(mut sink) = sink {
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
    let flow = sim.energy_flow_at(snap.time);
    let balance = last.energy() - initial.energy() - flow.injected + flow.dissipated;
    let scale = initial
        .energy()
        .abs()
        .max(last.energy().abs())
        .max(flow.injected.abs())
        .max(flow.dissipated)
        .max(f64::MIN_POSITIVE);
    let samples_f = samples.max(1) as f64;
    let temperature = Temperature {
        x: t_sum[0] / samples_f,
        y: t_sum[1] / samples_f,
        mean: 0.5 * (t_sum[0] + t_sum[1]) / samples_f,
    };
    let measured = window
        .as_ref()
        .map(|w| (end_time - w.time, w))
        .filter(|(dt, _)| *dt > 0.0);
    let closed_elastic = scene.gravity.is_none()
        && s.domain.y_boundary != YBoundary::Open
        && scene.restitution == 1.0
        && s.domain.wall_restitution == 1.0
        && scene
            .floor
            .as_ref()
            .is_none_or(|f| f.is_static() && f.restitution == 1.0);
    let box_area = match scene.top {
        crate::locals::Top::Lid { height, .. } | crate::locals::Top::Periodic { height } => {
            Some(s.domain.width * height)
        }
        crate::locals::Top::Open => None,
    };
    let compressibility_factor = match (closed_elastic, measured) {
        (true, Some((dt, w))) if samples > 0 => {
            let kt = last.kinetic / n as f64; // conserved in a closed elastic box
            Some(1.0 + (sim.virial() - w.virial) / (2.0 * dt * n as f64 * kt))
        }
        _ => None,
    };
    let counts = sim.counts();
    let setup = sim.setup();
    Ok(Summary {
        scenario: s.name.clone(),
        seed: s.seed,
        particles: n,
        ending,
        sim_time: end_time,
        wall_seconds: wall,
        events: counts,
        collisions_per_second: counts.collisions() as f64 / wall.max(1e-9),
        energy: EnergySummary {
            initial: EnergyAt::from(&initial),
            final_: EnergyAt::from(&last),
            injected: flow.injected,
            dissipated: flow.dissipated,
            balance_error: balance.abs() / scale,
        },
        temperature,
        compressibility_factor,
        packing_fraction: box_area.map(|a| n as f64 * mean_disk_area(s) / a),
        max_overlap: sim.max_overlap(),
        com_height: scene.gravity.map(|_| com_sum / samples_f),
        impacts_per_unit_time: match (&scene.floor, measured) {
            (Some(_), Some((dt, w))) => Some((counts.floor - w.floor_impacts) as f64 / dt),
            _ => None,
        },
        profiles: profiles.map(|p| p.table()),
        engine: EngineSummary {
            scheme: setup.scheme.into(),
            mask: setup.mask,
            cell: setup.cell,
            grid: setup.grid,
            bytes_per_disk: setup.bytes as f64 / n as f64,
            samples,
        },
        approximation: sim.approximation(),
    })
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
    let balance = now.energy() - initial.energy() - flow.injected + flow.dissipated;
    let scale = initial
        .energy()
        .abs()
        .max(now.energy().abs())
        .max(flow.injected.abs())
        .max(flow.dissipated)
        .max(f64::MIN_POSITIVE);
    if balance.abs() > 1e-9 * scale {
        return Err(Error::Runtime(format!(
            "energy budget off by {:e} (relative) at time {}",
            balance.abs() / scale,
            snap.time
        )));
    }
    Ok(())
}
