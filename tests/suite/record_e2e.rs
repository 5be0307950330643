//! End to end: real runs recorded to `.rrd` files through `vibrobed::run::run` and the real
//! binary, read back with Rerun's own decoder (`read_back`), and compared with the simulated
//! state at the frame times.
#![cfg(feature = "record")]

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use serde_json::Value;
use vibrobed::output::frame::{ColorBy, FrameView, SceneLayout};
use vibrobed::output::recording::{
    clock_label, orientation_line, read_back, spin_color, RecordingContents, RerunRecorder,
};
use vibrobed::output::summary::{Ending, Summary};
use vibrobed::run::{run, FrameSink, RunOptions};
use vibrobed::{Error, Scenario};

/// 200 disks on a vibrating floor between two walls, open top: 2.9 time units, a frame every
/// 0.1 (not a binary fraction: the last frame time 29 × 0.1 = 2.9000000000000004 rounds above
/// the duration 2.9). On the exact engine, which the frames are compared with.
const BED: &str = r#"{
  "name": "e2e bed",
  "seed": 21,
  "domain": { "width": 30.0, "x_boundary": "walls", "y_boundary": "open" },
  "gravity": 1.0,
  "floor": { "gamma": 3.0, "frequency": 0.5, "restitution": 0.9 },
  "particles": { "count": 200, "radius": 0.5, "temperature": 0.5 },
  "collisions": { "restitution": 0.9 },
  "run": { "duration": 2.9, "warmup": 1.0 },
  "output": { "frame_interval": 0.1, "profile_bins": 10, "profile_height": 10.0 },
  "engine": { "scheme": "event-driven" }
}"#;
const DURATION: f64 = 2.9;
const FRAME_INTERVAL: f64 = 0.1;
/// duration / frame_interval + 1 (frames at 0, 0.1, …, 2.9).
const FRAMES: usize = 30;

const SERIES: [&str; 8] = [
    "temperature/x",
    "temperature/y",
    "energy/kinetic",
    "energy/potential",
    "energy/injected",
    "energy/dissipated",
    "com_height",
    "collisions_per_time",
];

/// A fresh, empty scratch directory for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("record-e2e-{test}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// A copy of one frame as the driver handed it out.
#[derive(Debug, Clone)]
struct Copied {
    index: u64,
    time: f64,
    x: Vec<f64>,
    y: Vec<f64>,
    floor_height: Option<f64>,
    series: Vec<(String, f64)>,
    spins: Option<Vec<(f64, f64)>>,
}

/// A `FrameSink` that keeps copies of every frame and log line.
#[derive(Default, Clone)]
struct Collector {
    frames: Arc<Mutex<Vec<Copied>>>,
    log: Arc<Mutex<Vec<(f64, String, String)>>>,
    finished: Arc<Mutex<bool>>,
}

impl FrameSink for Collector {
    fn frame(&mut self, f: &FrameView) -> vibrobed::Result<()> {
        self.frames.lock().unwrap().push(Copied {
            index: f.index,
            time: f.time,
            x: f.x.to_vec(),
            y: f.y.to_vec(),
            floor_height: f.floor_height,
            series: f.series.iter().map(|(n, v)| (n.to_string(), *v)).collect(),
            spins: f.spins.map(<[_]>::to_vec),
        });
        Ok(())
    }
    fn log_text(&mut self, time: f64, level: &str, text: &str) -> vibrobed::Result<()> {
        self.log
            .lock()
            .unwrap()
            .push((time, level.to_owned(), text.to_owned()));
        Ok(())
    }
    fn finish(self: Box<Self>) -> vibrobed::Result<()> {
        *self.finished.lock().unwrap() = true;
        Ok(())
    }
}

/// The summary as JSON without the two wall-clock fields.
fn dynamics_of(summary: &Summary) -> Value {
    let mut v: Value = serde_json::from_str(&summary.to_json()).unwrap();
    let o = v.as_object_mut().unwrap();
    assert!(o.remove("wall_seconds").is_some());
    assert!(o.remove("collisions_per_second").is_some());
    v
}

fn record(s: &Scenario, path: &Path) -> Summary {
    run(
        s,
        RunOptions {
            rrd: Some(path.to_owned()),
            ..RunOptions::default()
        },
    )
    .expect("recorded run")
}

/// Asserts the disk positions of frame `k` in the file equal (as f32) `x`, `y`.
fn assert_positions(c: &RecordingContents, k: usize, x: &[f64], y: &[f64], what: &str) {
    let d = &c.disks[k];
    assert_eq!(d.frame, k as i64);
    assert_eq!(d.positions.len(), x.len(), "frame {k}: disk count");
    for (i, p) in d.positions.iter().enumerate() {
        assert_eq!(
            *p,
            [x[i] as f32, y[i] as f32],
            "frame {k} (t = {}), disk {i}: file vs {what}",
            d.time
        );
    }
}

/// The file holds what the issue asks for: entities, frame count, frame times, positions equal
/// to the simulated state at the frame times (checked against an engine stepped independently
/// and against the frames the driver handed to a sink), floor, series, log, blueprint, footer.
/// Recording changes nothing in the dynamics: summaries with a recording, with a sink and
/// without either agree except for the wall-clock fields.
#[test]
fn recorded_run_reads_back_as_simulated() {
    let dir = scratch("bed");
    let path = dir.join("bed.rrd");
    let s = common::scenario(BED);
    let recorded = record(&s, &path);
    let plain = run(&s, RunOptions::default()).unwrap();
    let collector = Collector::default();
    let sunk = run(
        &s,
        RunOptions {
            sink: Some(Box::new(collector.clone())),
            ..RunOptions::default()
        },
    )
    .unwrap();
    assert_eq!(
        dynamics_of(&recorded),
        dynamics_of(&plain),
        "recording changed the run"
    );
    assert_eq!(
        dynamics_of(&sunk),
        dynamics_of(&plain),
        "a frame sink changed the run"
    );
    assert!(*collector.finished.lock().unwrap(), "sink not finished");

    let c = read_back(&path).unwrap();
    assert_eq!(c.application_id.as_deref(), Some("vibrobed"));
    assert!(c.has_footer, "footer missing");
    assert!(c.manifest_chunks > 0);
    assert!(c.has_blueprint);

    // Entities.
    let mut temporal: Vec<String> = vec![
        "disks".into(),
        "log".into(),
        "profiles/packing_fraction".into(),
        "profiles/temperature".into(),
        "scene/clock".into(),
        "scene/floor".into(),
    ];
    temporal.extend(SERIES.iter().map(|n| format!("series/{n}")));
    temporal.sort();
    assert_eq!(
        c.entities.keys().cloned().collect::<Vec<_>>(),
        temporal,
        "temporal entities"
    );
    for e in [
        "disks",
        "scene",
        "scene/walls",
        "scene/speed_scale",
        "legend",
        "profiles/packing_fraction",
        "profiles/packing_fraction/axes",
        "profiles/temperature/axes",
    ] {
        assert!(
            c.static_entities.contains(e),
            "static {e}: {:?}",
            c.static_entities
        );
    }
    assert!(
        !c.static_entities.contains("scene/lid"),
        "no lid in an open bed"
    );
    assert!(
        !c.static_entities.contains("disks/orientation") && c.orientation.is_empty(),
        "smooth disks have no orientation"
    );

    // Frames: count, indices, times.
    for e in temporal.iter().filter(|e| *e != "log") {
        let stats = c.entity(e).unwrap();
        assert_eq!(stats.frames, FRAMES, "{e}: frames");
        // `disks`: one row per frame, and one more at frame 0 holding radii and class ids.
        let rows = if e == "disks" { FRAMES + 1 } else { FRAMES };
        assert_eq!(stats.rows, rows, "{e}: rows");
    }
    assert_eq!(c.disks.len(), FRAMES);
    for (k, d) in c.disks.iter().enumerate() {
        assert_eq!(d.frame, k as i64);
        let t = (k as f64 * FRAME_INTERVAL).min(DURATION);
        assert!((d.time - t).abs() < 1e-9, "frame {k} at {} not {t}", d.time);
        assert_eq!(d.radii, vec![0.5f32; 200], "frame {k}: radii");
        assert_eq!(d.class_ids, vec![0u16; 200], "frame {k}: species");
        assert_eq!(d.colors.len(), 200, "frame {k}: colours by speed");
    }

    // Positions equal an independently stepped engine at the frame times: the disks are
    // advanced to the exact frame time, not left at their last event.
    let mut sim = common::ballistic(BED);
    for k in [0, 1, 7, 15, 22, FRAMES - 1] {
        let t = (k as f64 * FRAME_INTERVAL).min(DURATION);
        sim.advance_to(t).unwrap();
        let snap = sim.snapshot(t);
        assert_positions(&c, k, &snap.x, &snap.y, "engine snapshot");
    }

    // … and the frames the driver hands to any sink.
    let frames = collector.frames.lock().unwrap();
    assert_eq!(frames.len(), FRAMES);
    for (k, f) in frames.iter().enumerate() {
        assert_eq!(f.index, k as u64);
        assert!((c.disks[k].time - f.time).abs() < 1e-9);
        assert_positions(&c, k, &f.x, &f.y, "sink frame");
        assert_eq!(c.floor[k], (k as i64, f.floor_height.unwrap() as f32));
        for (name, value) in &f.series {
            assert_eq!(c.series[name][k], (k as i64, *value), "series {name}");
        }
    }
    assert_eq!(c.series.len(), SERIES.len());
    assert!(frames.iter().all(|f| f.spins.is_none()));

    // The layout: the bed view spans the domain's width (30) and the profiles' heights (up to
    // 10, y flipped), the two profile views share those heights.
    assert_eq!(c.view_bounds.len(), 3, "{:?}", c.view_bounds);
    let (bed, profiles): (Vec<[f64; 4]>, Vec<[f64; 4]>) =
        c.view_bounds.iter().partition(|b| b[1] > 30.0);
    assert_eq!(bed.len(), 1, "{:?}", c.view_bounds);
    let bed = bed[0];
    assert!(bed[0] < 0.0 && bed[0] > -1.0 && bed[1] < 31.0, "{bed:?}");
    assert!(
        bed[2] < -10.0 && bed[2] > -11.0 && bed[3] > 0.0 && bed[3] < 1.0,
        "{bed:?}"
    );
    for p in &profiles {
        assert!(p[2] < -10.0 && p[3] > 0.0, "{p:?}");
    }

    // Live profiles: 10 bins up to height 10, one strip per frame; the packing fraction of
    // frame k integrates to the area of the disks' parts between the bottom and the top at
    // frame k (each disk's chord integrated numerically here).
    assert_eq!(c.profiles["packing_fraction"].len(), FRAMES);
    assert_eq!(c.profiles["temperature"].len(), FRAMES);
    for (k, (f, pts)) in c.profiles["packing_fraction"].iter().enumerate() {
        assert_eq!(*f, k as i64);
        assert_eq!(pts.len(), 10);
        let h = f64::from(pts[1][1] - pts[0][1]);
        let top = f64::from(pts[9][1]) + 0.5 * h;
        assert!((top - 10.0).abs() < 1e-5, "profile top {top}");
        let bottom = f64::from(pts[0][1]) - 0.5 * h;
        let disk = std::f64::consts::PI * 0.25;
        let below: f64 = frames[k]
            .y
            .iter()
            .map(|&y| area_between(y, 0.5, bottom, top) / disk)
            .sum();
        let area: f64 = pts.iter().map(|p| f64::from(p[0]) * h * 30.0).sum();
        assert!(
            (area / disk - below).abs() < 1e-3 * below.max(1.0),
            "frame {k}: {} disks' area in the profile, {below} disks below {top}",
            area / disk
        );
    }

    // The floor moves (Γ = 3), the walls exist, the bed is above the floor.
    let heights: Vec<f32> = c.floor.iter().map(|&(_, h)| h).collect();
    assert!(heights.iter().any(|&h| h > 0.0) && heights.iter().any(|&h| h < 0.0));

    // Log: start, warm-up over, completed.
    let texts: Vec<&str> = c.log.iter().map(|l| l.text.as_str()).collect();
    assert_eq!(texts.len(), 3, "{texts:?}");
    assert!(texts[0].starts_with("start: 200 disks"), "{texts:?}");
    assert_eq!(texts[1], "warm-up over: averaging starts");
    assert!((c.log[1].time.unwrap() - 1.0).abs() < 1e-9);
    assert_eq!(texts[2], "run completed");
    assert!((c.log[2].time.unwrap() - DURATION).abs() < 1e-9);
    assert!(c.log.iter().all(|l| l.level == "INFO"));

    // Time as the viewer shows it: the frame number (a sequence: plain numbers, where a
    // duration reads `+3m 20s`), the simulated time on the bed, the log on that timeline.
    assert_eq!(c.shown_timeline.as_deref(), Some("frame"));
    assert_eq!(c.timelines["frame"], "sequence");
    let clock: Vec<(i64, String)> = (0..FRAMES)
        .map(|k| {
            let step = (k > 0).then_some(FRAME_INTERVAL);
            (k as i64, clock_label(c.disks[k].time, step))
        })
        .collect();
    assert_eq!(c.clock, clock);
    assert_eq!(c.clock[FRAMES - 1].1, "t = 2.9");
    let frames: Vec<Option<i64>> = c.log.iter().map(|l| l.frame).collect();
    assert_eq!(frames, [Some(0), Some(10), Some(FRAMES as i64 - 1)]);
    std::fs::remove_dir_all(&dir).ok();
}

/// Rough disks (the bed with friction on pairs, floor and walls, spinning at the start, coloured
/// by spin): each frame holds a radius line per disk from its centre to its rim at its angle,
/// the disks' colours say which way they turn, and the rotational energy is plotted with the
/// others. The run itself is the one without a recording.
#[test]
fn a_rough_bed_records_orientations_spins_and_rotational_energy() {
    let dir = scratch("rough");
    let path = dir.join("rough.rrd");
    let mut s = common::scenario(BED);
    s.collisions.friction = Some(0.5);
    s.floor.as_mut().unwrap().friction = Some(0.5);
    s.domain.wall_friction = Some(0.5);
    s.particles.rotational_temperature = Some(0.5);
    s.output.color_by = vibrobed::scenario::ColorChoice::Spin;
    let recorded = record(&s, &path);
    let collector = Collector::default();
    let sunk = run(
        &s,
        RunOptions {
            sink: Some(Box::new(collector.clone())),
            ..RunOptions::default()
        },
    )
    .unwrap();
    assert_eq!(dynamics_of(&recorded), dynamics_of(&sunk));
    let c = read_back(&path).unwrap();
    assert!(c.has_footer);
    for e in ["disks/orientation", "series/energy/rotational"] {
        assert_eq!(c.entity(e).map(|s| s.frames), Some(FRAMES), "{e}");
    }
    assert!(c.static_entities.contains("disks/orientation"));
    assert!(
        c.static_entities.contains("scene/speed_scale"),
        "spin scale"
    );
    let frames = collector.frames.lock().unwrap();
    assert_eq!(c.orientation.len(), FRAMES);
    let (mut clockwise, mut anticlockwise) = (0, 0);
    for (k, f) in frames.iter().enumerate() {
        let spins = f.spins.as_ref().expect("rough frames carry spins");
        let (frame, lines) = &c.orientation[k];
        assert_eq!((*frame, lines.len()), (k as i64, 200));
        for (i, (line, &(angle, omega))) in lines.iter().zip(spins).enumerate() {
            let (x, y) = (f.x[i], f.y[i]);
            assert_eq!(line[0], [x as f32, y as f32], "frame {k}, disk {i}: centre");
            assert_eq!(*line, orientation_line(x, y, 0.5, angle));
            let (dx, dy) = (
                f64::from(line[1][0]) - x as f32 as f64,
                f64::from(line[1][1]) - y as f32 as f64,
            );
            assert!(
                (dx.hypot(dy) - 0.5).abs() < 1e-5,
                "frame {k}, disk {i}: length"
            );
            let turn = (dy.atan2(dx) - angle).rem_euclid(std::f64::consts::TAU);
            assert!(
                turn.min(std::f64::consts::TAU - turn) < 1e-4,
                "frame {k}, disk {i}"
            );
            // Red turning anticlockwise, blue clockwise (clear spins only), full colour at a rim
            // speed of the floor's peak speed Aω = Γ g / ω (the default spin scale).
            let rgba = c.disks[k].colors[i];
            let floor_speed = 3.0 / (std::f64::consts::TAU * 0.5);
            let expected = spin_color(omega * 0.5 / floor_speed).to_u32();
            assert!(
                channels_within_one(rgba, expected),
                "frame {k}, disk {i}: {rgba:08x} vs {expected:08x}"
            );
            let (red, blue) = (rgba >> 24, (rgba >> 8) & 0xff);
            if omega * 0.5 > 0.1 {
                assert!(red > blue, "frame {k}, disk {i}: ω = {omega}");
                anticlockwise += 1;
            } else if omega * 0.5 < -0.1 {
                assert!(blue > red, "frame {k}, disk {i}: ω = {omega}");
                clockwise += 1;
            }
        }
        // Σ ½ I ω², I = ½ m a² (m = 1, a = 0.5).
        let rotational: f64 = spins.iter().map(|&(_, w)| 0.5 * 0.125 * w * w).sum();
        let (_, plotted) = c.series["energy/rotational"][k];
        assert!(
            (plotted - rotational).abs() <= 1e-12 * rotational,
            "frame {k}: {plotted} vs {rotational}"
        );
    }
    assert!(
        clockwise > 100 && anticlockwise > 100,
        "{clockwise} {anticlockwise}"
    );
    let last = c.series["energy/rotational"][FRAMES - 1].1;
    let summary = recorded.energy.final_.rotational.unwrap();
    assert!(
        (last - summary).abs() <= 1e-12 * summary,
        "{last} vs {summary}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Colouring by spin needs spins: a smooth scene asking for it is refused, naming the field.
#[test]
fn spin_colours_need_rough_disks() {
    let mut s = common::scenario(BED);
    s.output.color_by = vibrobed::scenario::ColorChoice::Spin;
    match s.validate() {
        Err(Error::Input { field, .. }) => assert_eq!(field, "output.color_by"),
        other => panic!("smooth disks coloured by spin: {other:?}"),
    }
    s.collisions.friction = Some(0.5);
    s.validate().expect("rough disks may be coloured by spin");
}

/// Whether two `0xRRGGBBAA` colours differ by at most one in each channel (the scale's last bit
/// may round either way).
fn channels_within_one(a: u32, b: u32) -> bool {
    (0..4).all(|k| ((a >> (8 * k)) & 0xff).abs_diff((b >> (8 * k)) & 0xff) <= 1)
}

/// `output.rrd` in the scenario records without `--rrd`; `output.color_by = "species"` logs
/// class ids instead of per-frame colours; a frame interval that does not divide the duration
/// gives the frames on its grid only; a run stopped by `run.max_events` closes its file with a
/// warning in the log.
#[test]
fn scenario_fields_and_event_limit() {
    let dir = scratch("fields");
    let path = dir.join("from-scenario.rrd");
    let mut s = common::scenario(BED);
    s.output.rrd = Some(path.to_str().unwrap().to_owned());
    s.output.color_by = vibrobed::scenario::ColorChoice::Species;
    s.output.frame_interval = Some(0.25);
    let summary = run(&s, RunOptions::default()).unwrap();
    assert_eq!(summary.ending, vibrobed::output::summary::Ending::Completed);
    let c = read_back(&path).unwrap();
    assert!(c.has_footer);
    assert_eq!(c.disks.len(), 12); // 0, 0.25, …, 2.75 (2.9 is not a multiple of 0.25)
    assert_eq!(c.entity("disks").unwrap().frames, 12);
    assert!(c.disks.iter().all(|d| d.colors.is_empty()));
    assert!(c.disks.iter().all(|d| d.class_ids == vec![0u16; 200]));

    let path = dir.join("limited.rrd");
    let mut s = common::scenario(BED);
    s.run.max_events = Some(2_000);
    let summary = record(&s, &path);
    assert_eq!(
        summary.ending,
        vibrobed::output::summary::Ending::EventLimit
    );
    assert!(summary.sim_time < DURATION);
    let c = read_back(&path).unwrap();
    assert!(c.has_footer);
    let expected = (summary.sim_time / FRAME_INTERVAL).floor() as usize + 1;
    assert!(
        c.disks.len().abs_diff(expected) <= 1,
        "{} frames up to t = {}",
        c.disks.len(),
        summary.sim_time
    );
    let last = c.log.last().unwrap();
    assert_eq!(last.level, "WARN");
    assert!(
        last.text.starts_with("event limit reached"),
        "{}",
        last.text
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The Rerun recorder behind a sink that fails at frame `fail_at`, as a full disk or any other
/// error in the middle of a run would.
struct FailingRecorder {
    rec: RerunRecorder,
    fail_at: u64,
}

impl FrameSink for FailingRecorder {
    fn frame(&mut self, f: &FrameView) -> vibrobed::Result<()> {
        if f.index == self.fail_at {
            return Err(Error::Io(format!("disk full at frame {}", f.index)));
        }
        self.rec.frame(f).map_err(Error::Io)
    }
    fn log_text(&mut self, time: f64, level: &str, text: &str) -> vibrobed::Result<()> {
        self.rec.log_text(time, level, text).map_err(Error::Io)
    }
    fn finish(self: Box<Self>) -> vibrobed::Result<()> {
        self.rec.finish().map_err(Error::Io)
    }
}

/// A sink that fails in the middle of a run, after frames were written, is dropped and the run
/// goes on: the summary lists the failure, and the recorder behind the sink, dropped, leaves a
/// complete file with the frames it was given.
#[test]
fn run_failing_mid_way_leaves_a_complete_file() {
    let dir = scratch("failed");
    let path = dir.join("failed.rrd");
    let s = common::scenario(BED);
    let layout = SceneLayout {
        name: s.name.clone(),
        width: s.domain.width,
        x_periodic: false,
        top: None,
        y_periodic: false,
        floor: true,
        species: 1,
        speed_scale: 2.0,
        spin_scale: 2.0,
    };
    let rec = RerunRecorder::create(&path, &layout, ColorBy::Speed).unwrap();
    let summary = run(
        &s,
        RunOptions {
            sink: Some(Box::new(FailingRecorder { rec, fail_at: 12 })),
            ..RunOptions::default()
        },
    )
    .expect("the run goes on without its recording");
    assert_eq!(summary.ending, Ending::Completed);
    let [failure] = &summary.output_failures[..] else {
        panic!("one failure expected: {:?}", summary.output_failures);
    };
    assert_eq!(failure.output, "recording");
    assert_eq!(failure.error, "disk full at frame 12");
    assert_eq!(failure.failures, 1);
    let c = read_back(&path).expect("the file is a valid recording");
    assert!(c.has_footer, "footer missing after an error");
    assert!(c.has_blueprint);
    assert_eq!(c.disks.len(), 12);
    assert_eq!(c.entity("disks").unwrap().frames, 12);
    assert!(c.static_entities.contains("scene/walls"));
    std::fs::remove_dir_all(&dir).ok();
}

/// A run refused by the engine after `run` opened the recording (overlapping disks are only
/// detected when the engine starts) leaves no file or a complete one, never a broken one.
#[test]
fn refused_run_leaves_no_broken_file() {
    let dir = scratch("refused");
    let path = dir.join("refused.rrd");
    let s = common::scenario(
        r#"{
      "name": "overlapping",
      "seed": 1,
      "domain": { "width": 10.0, "x_boundary": "walls", "y_boundary": "open" },
      "gravity": 1.0,
      "floor": { "restitution": 0.9 },
      "particles": {
        "count": 2, "radius": 0.5,
        "placement": { "positions": [[5.0, 2.0], [5.2, 2.0]], "velocities": [[0.0, 0.0], [0.0, 0.0]] }
      },
      "run": { "duration": 1.0 },
      "output": { "frame_interval": 0.1 }
    }"#,
    );
    let e = run(
        &s,
        RunOptions {
            rrd: Some(path.clone()),
            ..RunOptions::default()
        },
    )
    .expect_err("overlapping disks must be refused");
    assert!(matches!(e, Error::Input { .. }), "{e}");
    if path.exists() {
        let c = read_back(&path).expect("the file is a valid recording");
        assert!(c.has_footer, "footer missing after an error");
        assert!(c.has_blueprint);
        assert!(c.disks.is_empty());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Ctrl-C on the real binary: exit code 130, the summary so far marked interrupted, and a
/// complete recording holding the frames up to the interruption.
#[test]
fn interrupted_binary_leaves_a_complete_file() {
    let dir = scratch("sigint");
    let rrd = dir.join("long.rrd");
    let summary = dir.join("summary.json");
    let mut child = Command::new(env!("CARGO_BIN_EXE_vibrobed"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["run", "scenarios/vibrated_bed.json", "--quiet"])
        .args([
            "--set",
            "run.duration=100000",
            "--set",
            "output.frame_interval=0.05",
        ])
        .arg("--rrd")
        .arg(&rrd)
        .arg("--summary")
        .arg(&summary)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the vibrobed binary starts");

    // The file exists (under its temporary name until it is complete) once the run (and its
    // Ctrl-C handler) has started; then let it run.
    let partial = dir.join("long.rrd.partial");
    let start = Instant::now();
    while !partial.exists() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no recording after 60 s"
        );
        assert!(child.try_wait().unwrap().is_none(), "vibrobed ended early");
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(1000));
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(kill.success());

    let deadline = Instant::now() + Duration::from_secs(60);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            child.kill().ok();
            panic!("vibrobed did not stop within 60 s of SIGINT");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        status.code(),
        Some(130),
        "status {status:?}, stderr: {stderr}"
    );

    let json: Value = serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    assert_eq!(json["ending"], "interrupted");
    let sim_time = json["sim_time"].as_f64().unwrap();
    assert!(sim_time > 0.0 && sim_time < 1e6);

    let c = read_back(&rrd).expect("the interrupted recording decodes");
    assert!(c.has_footer, "footer missing after Ctrl-C");
    assert!(c.has_blueprint);
    assert!(!c.disks.is_empty(), "no frame recorded");
    assert_eq!(c.disks.len(), c.entity("disks").unwrap().frames);
    assert!(c.disks.iter().all(|d| d.positions.len() == 1000));
    let last_frame = c.disks.last().unwrap().time;
    assert!(
        last_frame <= sim_time + 1e-9 && sim_time - last_frame <= 0.05 + 1e-9,
        "last frame at {last_frame}, interrupted at {sim_time}"
    );
    let last = c.log.last().unwrap();
    assert_eq!(last.level, "WARN");
    assert!(
        last.text.starts_with("interrupted at t = "),
        "{}",
        last.text
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Area of a disk of radius `a` centred at height `y` between heights `lo` and `hi`, by the
/// midpoint rule on its chord length `2√(a² − (z − y)²)`.
fn area_between(y: f64, a: f64, lo: f64, hi: f64) -> f64 {
    let (z0, z1) = ((y - a).max(lo), (y + a).min(hi));
    if z1 <= z0 {
        return 0.0;
    }
    let steps = 2000;
    let dz = (z1 - z0) / steps as f64;
    (0..steps)
        .map(|k| {
            let z = z0 + (k as f64 + 0.5) * dz - y;
            2.0 * (a * a - z * z).max(0.0).sqrt() * dz
        })
        .sum()
}

/// `output.record_fields`: the live 2D fields are in every frame (a heat map image and the
/// arrows of the mean velocity), the run is the run without them, and a recording without the
/// switch holds none of their entities and the same disks.
#[test]
fn live_fields_are_recorded_only_when_asked() {
    let dir = scratch("fields");
    let (with, without) = (dir.join("with.rrd"), dir.join("without.rrd"));
    let mut s = common::scenario(BED);
    let plain = record(&s, &without);
    s.output.record_fields = true;
    let fielded = record(&s, &with);
    assert_eq!(dynamics_of(&plain), dynamics_of(&fielded));
    let (a, b) = (read_back(&with).unwrap(), read_back(&without).unwrap());
    for e in ["fields/packing_fraction", "fields/velocity"] {
        assert_eq!(a.entity(e).map(|s| s.frames), Some(FRAMES), "{e}");
        assert!(b.entity(e).is_none(), "{e} without the switch");
    }
    assert!(a.static_entities.contains("fields"));
    assert!(!b.static_entities.iter().any(|e| e.starts_with("fields")));
    assert_eq!(a.disks, b.disks);
    assert_eq!(
        a.view_bounds.len(),
        b.view_bounds.len() + 1,
        "the fields' view"
    );
}
