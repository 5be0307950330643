//! One run of an engine from its start to its ending: the stops, and at each what is due — the
//! samples, the phase bins, frames, trajectory frames, checkpoints. The summary is made in
//! `summary`, the engine's states read through `views`.

use super::averages::{Averages, Window};
use super::failures::Failures;
use super::frames::{trajectory_frame, Frames};
use super::stops::Stops;
use super::streams::{Given, Streams, Takes};
use super::views::{fill_snapshot, floor_tally, holds, Snapped, StatesAt, Taken};
use super::{CheckpointPlan, RunOptions};
use crate::engine::{Progress, Scene, Snapshot};
use crate::error::Result;
use crate::measure::phase::{PhaseBins, PhaseClock};
use crate::measure::Observables;
use crate::output::progress::ProgressReport;
use crate::output::summary::{Ending, Summary};
use crate::output::watch::Watch;
use crate::physics::disks::Disks;
use crate::scenario::Scenario;
use crate::schemes::Integrator;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// From this many disks on, a sample's measurements read the engine's states instead of a copy:
/// the copy (32 bytes a disk) raised the peak memory of a run of 10⁶ disks by a fifth (142 →
/// 173 MB), while the extra reads cost nothing measurable there. Below, the copy is cheaper (a
/// sample of the shipped bed reads every state four times). Both give the same
/// measurements bit for bit: the same states, in the scenario's order.
const ON_THE_FLY_FROM: usize = 1 << 18;

/// One run of an engine from the start to its ending: the engine, where its frames go, and what
/// is measured along the way.
pub(super) struct Driver<'a, E: Integrator> {
    pub(super) sim: E,
    pub(super) s: &'a Scenario,
    pub(super) scene: &'a Scene,
    /// The outputs written at stops (recording, trajectory, checkpoint).
    pub(super) streams: Streams,
    pub(super) g: f64,
    /// The time of the current stop.
    pub(super) now: f64,
    /// Every disk's state at `now`, filled only for what needs them all at once (frames,
    /// trajectories, the overlap check); measurements read the engine on the fly.
    pub(super) snap: Snapshot,
    pub(super) initial: Observables,
    pub(super) stops: Stops,
    pub(super) averages: Averages,
    /// What the recording's frames carry from one frame to the next.
    pub(super) frames: Frames,
    /// The first sample time from which every disk has been at rest at every sample (`None`
    /// while some disk moves).
    pub(super) at_rest_since: Option<f64>,
    /// The caller's stop flag, also looked at between stops (a run with dense samples or
    /// frames can spend its time there).
    pub(super) interrupt: Option<&'static AtomicBool>,
    /// What a checkpoint holds of the run's start, if checkpoints are asked for.
    pub(super) checkpoint: Option<CheckpointPlan>,
    /// The recording's id (kept across resumed parts) and the recordings written so far.
    pub(super) recording_id: Option<String>,
    pub(super) recordings: Vec<PathBuf>,
    /// Wall time of the parts before a resume, and the clock of this part.
    pub(super) wall_before: f64,
    pub(super) clock: Instant,
    /// Outputs that could not be written.
    pub(super) failures: Failures,
    /// The thread that notices output files removed during the run.
    pub(super) watch: Watch,
    /// A sample taken at the last stop and not yet in the averages (engines with threads of
    /// their own add it while they run on to the next stop), and a spare copy of the states for
    /// the next one.
    pub(super) taken: Option<Taken>,
    pub(super) spare: Snapshot,
    /// The disks' radii and masses, which such a sample's measurement reads while the engine
    /// runs (engines with threads never change them; the states in this copy are not read).
    pub(super) sizes: Option<Disks>,
}

impl<'a, E: Integrator> Driver<'a, E> {
    pub(super) fn new(
        mut sim: E,
        s: &'a Scenario,
        scene: &'a Scene,
        streams: Streams,
        opts: &RunOptions,
        recording_id: Option<String>,
    ) -> Driver<'a, E> {
        if let Some(flag) = opts.interrupt {
            sim.set_interrupt(flag);
        }
        let g = scene.gravity.unwrap_or(0.0);
        let initial = Observables::of(&StatesAt(&sim, 0.0), sim.disks(), g);
        let averages = Averages::new(
            s,
            scene,
            &StatesAt(&sim, 0.0),
            sim.disks(),
            opts.fields || opts.fields_file.is_some(),
        );
        let phase = match (&scene.floor, scene.gravity) {
            (Some(f), Some(_)) => PhaseClock::of(f, s.output.phase_bins, s.sample_interval()),
            _ => None,
        };
        let stops = Stops::new(s, opts.checkpoint.as_ref().and_then(|c| c.every), phase);
        let live = streams.take(Takes::Frames);
        let frames = Frames::new((s, scene), &sim, stops.frame_dt, live);
        Driver {
            sim,
            s,
            scene,
            streams,
            g,
            now: 0.0,
            snap: Snapshot::default(),
            initial,
            stops,
            averages,
            frames,
            at_rest_since: None,
            interrupt: opts.interrupt,
            checkpoint: opts.checkpoint.clone(),
            recording_id,
            recordings: Vec::new(),
            wall_before: 0.0,
            clock: Instant::now(),
            failures: Failures::default(),
            watch: Watch::start(Vec::new()),
            taken: None,
            spare: Snapshot::default(),
            sizes: None,
        }
    }

    /// Runs from stop to stop until the duration, the event limit or an interrupt, every sample
    /// in the averages at the end.
    pub(super) fn run(&mut self, progress: &ProgressReport) -> Result<Ending> {
        let ending = self.run_stops(progress);
        self.settle();
        ending
    }

    /// The stops of [`run`](Self::run).
    fn run_stops(&mut self, progress: &ProgressReport) -> Result<Ending> {
        let text = format!(
            "start: {} disks, scene {}",
            self.sim.disks().len(),
            self.s.name
        );
        self.log_text(0.0, "INFO", &text);
        loop {
            if self.interrupt.is_some_and(|f| f.load(Ordering::Relaxed)) {
                return Ok(Ending::Interrupted);
            }
            let stop = self.stops.next(
                self.streams.take(Takes::Frames),
                self.streams.take(Takes::TrajectoryFrames),
                self.averages.window.is_some(),
            );
            match self.advance_to(stop.time)? {
                Progress::Reached => {}
                Progress::EventLimit => return Ok(Ending::EventLimit),
                Progress::Interrupted => return Ok(Ending::Interrupted),
                Progress::Stalled => {
                    let report = self.sim.stall_report().unwrap_or("no report");
                    eprintln!("vibrobed: {report}");
                    return Ok(Ending::Stalled);
                }
            }
            self.now = stop.time;
            if stop.window {
                self.open_window(stop.time)?;
            }
            if stop.sample {
                self.sample()?;
            }
            if stop.phase {
                self.phase_stop();
            }
            if stop.frame {
                self.frame();
            }
            if stop.trajectory {
                self.trajectory_frame();
            }
            if stop.checkpoint {
                self.stops.k_checkpoint += 1;
                self.checkpoint()?;
            }
            self.drop_outputs_gone();
            progress.update(stop.time, self.sim.counts().collisions());
            if stop.time >= self.stops.duration {
                return Ok(Ending::Completed);
            }
        }
    }

    /// The warm-up is over: averaging starts.
    pub(super) fn open_window(&mut self, t: f64) -> Result<()> {
        self.averages.window = Some(Window {
            time: t,
            virial: self.sim.virial(),
            floor_impacts: self.sim.counts().floor,
            floor_impulse: self.sim.energy_flow_at(t).floor_impulse,
        });
        if let Some(clock) = self.stops.phase {
            let k = clock.first_edge_from(t);
            self.stops.k_phase = k;
            // The bed's shape in the columns of the state's coarse grid.
            let columns = self
                .averages
                .state_fields
                .as_ref()
                .map_or(1, |f| f.grid().nx);
            let mut bins = PhaseBins::new(clock, columns, self.s.domain.width);
            bins.open(floor_tally(&self.sim, t), k);
            self.averages.phase = Some(bins);
        }
        if self.stops.warmup > 0.0 {
            self.log_text(t, "INFO", "warm-up over: averaging starts");
        }
        Ok(())
    }

    /// A bin edge of the floor's phase: the floor's impacts since the last edge booked, the
    /// centre of mass and the lower edge sampled.
    fn phase_stop(&mut self) {
        let Some(clock) = self.stops.phase else {
            return;
        };
        let k = self.stops.k_phase;
        self.stops.k_phase = clock.next_edge(k);
        let Some(bins) = self.averages.phase.as_mut() else {
            return;
        };
        bins.book(k, floor_tally(&self.sim, self.now));
        let floor = self.sim.floor_height_at(self.now).unwrap_or(0.0);
        fill_snapshot(&self.sim, self.now, &mut self.snap);
        bins.sample(k, &self.snap, self.sim.disks(), floor);
    }

    /// Runs the engine to `target`, adding the sample taken at the last stop meanwhile (on a
    /// thread of the engine's own: the measurement does not keep its cores waiting). The
    /// samples go into the averages in the order they were taken, as they would one by one.
    fn advance_to(&mut self, target: f64) -> Result<Progress> {
        let Some(taken) = self.taken.take() else {
            return self.sim.advance_to(target);
        };
        let sizes = self.sizes.get_or_insert_with(|| self.sim.disks().clone());
        let (averages, g) = (&mut self.averages, self.g);
        let progress = self
            .sim
            .advance_beside(target, || taken.add_to(averages, sizes, g));
        self.spare = taken.snap;
        progress
    }

    /// Adds the sample taken at the last stop, if it is not in the averages yet.
    pub(super) fn settle(&mut self) {
        if let Some(taken) = self.taken.take() {
            taken.add_to(&mut self.averages, self.sim.disks(), self.g);
            self.spare = taken.snap;
        }
    }

    /// A sample: measured into the averages after the warm-up; invariants checked if asked.
    pub(super) fn sample(&mut self) -> Result<()> {
        self.stops.k_sample += 1;
        let at_rest = self.sim.disks_at_rest();
        self.at_rest_since = if at_rest == self.sim.disks().len() {
            // The engine knows the end of the last motion to the event; else the sample.
            self.sim
                .at_rest_since()
                .or(self.at_rest_since)
                .or(Some(self.now))
        } else {
            None
        };
        if self.averages.window.is_some() {
            self.settle();
            self.measure();
            self.averages.at_rest += at_rest as f64 / self.sim.disks().len() as f64;
        }
        if self.scene.check_invariants {
            super::invariants::check_sample(&self.sim, self.now, &self.initial, self.g)?;
        }
        Ok(())
    }

    /// The sample's measurements of the disks' states, into the averages (or taken, to be added
    /// while engines on threads run on). They read every state several times: from a copy
    /// filled once, or, from [`ON_THE_FLY_FROM`] disks on (one thread, no frame's copy at this
    /// stop), from the engine itself each time.
    fn measure(&mut self) {
        let threads = self.sim.has_threads();
        let copied = holds(&self.snap, self.now);
        if !threads && !copied && self.sim.disks().len() >= ON_THE_FLY_FROM {
            let states = StatesAt(&self.sim, self.now);
            self.averages.add(&states, self.sim.disks(), self.g);
            return;
        }
        fill_snapshot(&self.sim, self.now, &mut self.snap);
        if threads {
            self.taken = Some(Taken::of(
                &self.sim,
                &self.snap,
                std::mem::take(&mut self.spare),
            ));
        } else {
            let states = Snapped(&self.snap, &self.sim);
            self.averages.add(&states, self.sim.disks(), self.g);
        }
    }

    /// A frame: the disks, the time series, the live profiles and fields, to the outputs that
    /// take frames.
    pub(super) fn frame(&mut self) {
        self.stops.k_frame += 1;
        if !self.streams.take(Takes::Frames) {
            return;
        }
        fill_snapshot(&self.sim, self.now, &mut self.snap);
        let time = self.sim.time();
        let (streams, failures) = (&mut self.streams, &mut self.failures);
        self.frames.frame(
            (&self.sim, &self.snap),
            self.averages.profiles.as_ref(),
            (self.stops.k_frame, self.stops.frame_dt),
            self.s.disk_count(),
            |view| streams.give(Takes::Frames, &Given::Frame(view), time, failures),
        );
    }

    /// A line of text to the outputs.
    fn log_text(&mut self, at: f64, level: &str, text: &str) {
        let time = self.sim.time();
        (self.streams).log_text(at, (level, text), time, &mut self.failures);
    }

    /// The outputs whose files the watch found gone (it has said so), to the failure policy.
    fn drop_outputs_gone(&mut self) {
        let time = self.sim.time();
        for output in self.watch.gone() {
            self.streams.gone(output, time, &mut self.failures);
        }
    }

    /// A trajectory frame: every disk, to the outputs that take trajectory frames.
    pub(super) fn trajectory_frame(&mut self) {
        self.stops.k_trajectory += 1;
        if !self.streams.take(Takes::TrajectoryFrames) {
            return;
        }
        fill_snapshot(&self.sim, self.now, &mut self.snap);
        let time = self.sim.time();
        let (streams, failures) = (&mut self.streams, &mut self.failures);
        let k = self.stops.k_trajectory;
        trajectory_frame((&self.sim, &self.snap), k, |view| {
            streams.give(Takes::TrajectoryFrames, &Given::Frame(view), time, failures)
        });
    }

    /// What the run measured, to the outputs that take its end: the fields once sampled after
    /// the warm-up.
    fn measured(&mut self, ending: Ending, end_time: f64) {
        let fields = self.averages.fields.as_ref().filter(|f| f.samples() > 0);
        let given = Given::End(fields, ending, end_time);
        let time = self.sim.time();
        (self.streams).give(Takes::End, &given, time, &mut self.failures);
    }

    /// Closes the outputs with a note on how the run ended.
    fn close_streams(&mut self, ending: Ending, end_time: f64) {
        let note = match ending {
            Ending::Completed => "run completed".to_string(),
            Ending::Interrupted => format!("interrupted at t = {end_time}"),
            Ending::EventLimit => format!("event limit reached at t = {end_time}"),
            Ending::WallLimit => format!("wall-clock limit reached at t = {end_time}"),
            Ending::Stalled => format!("simulated time stopped advancing at t = {end_time}"),
        };
        let level = if ending == Ending::Completed {
            "INFO"
        } else {
            "WARN"
        };
        let time = self.sim.time();
        (self.streams).close((end_time, level, &note), time, &mut self.failures);
    }

    /// Ends the run: the final state, the outputs closed, the summary.
    pub(super) fn finish(
        mut self,
        ending: Ending,
        wall: f64,
        progress: ProgressReport,
    ) -> Result<Summary> {
        let end_time = if ending == Ending::Completed {
            self.stops.duration
        } else {
            self.sim.time()
        };
        // However the run ended (completed, event limit, signal), its state is saved: a resume
        // can extend the duration or the event budget.
        self.checkpoint()?;
        progress.finish(ending, end_time, self.sim.counts().collisions());
        self.drop_outputs_gone();
        self.measured(ending, end_time);
        self.close_streams(ending, end_time);
        Ok(self.summarise(ending, end_time, wall))
    }
}
