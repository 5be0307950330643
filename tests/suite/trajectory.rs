//! Trajectories (`--trajectory`, extended XYZ): the frames hold the simulated state at the
//! trajectory times, the file is complete after an interrupt, and ASE reads it (where Python and
//! ASE are available: `VIBROBED_PYTHON`, else `python3`; the test says why when it skips).

use crate::common;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use vibrobed::output::frame::FrameView;
use vibrobed::output::summary::Ending;
use vibrobed::run::{run, FrameSink, RunOptions};
use vibrobed::Scenario;

/// 60 disks of two sizes between walls on a vibrating floor, open top.
const BED: &str = r#"{
  "name": "trajectory bed",
  "seed": 5,
  "domain": { "width": 12.0, "x_boundary": "walls", "y_boundary": "open" },
  "gravity": 1.0,
  "floor": { "gamma": 3.0, "frequency": 0.5, "restitution": 0.9 },
  "particles": {
    "radius": { "species": [ { "count": 50, "radius": 0.5 }, { "count": 10, "radius": 0.7 } ] },
    "temperature": 0.5
  },
  "collisions": { "restitution": 0.9 },
  "run": { "duration": 2.0 },
  "output": { "frame_interval": 0.25 }
}"#;

fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("trajectory-{test}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// One frame as parsed back from the file.
#[derive(Debug)]
struct XyzFrame {
    comment: String,
    species: Vec<String>,
    /// x, y, z, radius, vx, vy, vz per disk.
    columns: Vec<[f64; 7]>,
}

impl XyzFrame {
    /// The value of `key=` on the comment line.
    fn key(&self, key: &str) -> Option<&str> {
        self.comment
            .split_whitespace()
            .find_map(|kv| kv.strip_prefix(&format!("{key}=")))
    }
}

/// Parses an extended XYZ file of this crate's layout; panics on anything incomplete.
fn parse(path: &Path) -> Vec<XyzFrame> {
    let text = std::fs::read_to_string(path).expect("trajectory readable");
    let mut lines = text.lines();
    let mut frames = Vec::new();
    while let Some(count) = lines.next() {
        let n: usize = count.trim().parse().expect("count line");
        let comment = lines.next().expect("comment line").to_owned();
        let mut species = Vec::new();
        let mut columns = Vec::new();
        for i in 0..n {
            let line = lines
                .next()
                .unwrap_or_else(|| panic!("frame {}: line {i} missing", frames.len()));
            let f: Vec<&str> = line.split_whitespace().collect();
            assert_eq!(f.len(), 8, "{line}");
            species.push(f[0].to_owned());
            let mut c = [0.0; 7];
            for (k, v) in f[1..].iter().enumerate() {
                c[k] = v.parse().unwrap_or_else(|_| panic!("number: {v}"));
            }
            columns.push(c);
        }
        frames.push(XyzFrame {
            comment,
            species,
            columns,
        });
    }
    frames
}

/// A frame's time, x, y, vx, vy.
type Copied = (f64, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);

/// A sink keeping copies of the frames and optionally raising a flag at a given frame.
#[derive(Clone, Default)]
struct Collector {
    frames: Arc<Mutex<Vec<Copied>>>,
    raise_at: Option<(u64, &'static AtomicBool)>,
}

impl FrameSink for Collector {
    fn frame(&mut self, f: &FrameView) -> vibrobed::Result<()> {
        self.frames.lock().unwrap().push((
            f.time,
            f.x.to_vec(),
            f.y.to_vec(),
            f.vx.to_vec(),
            f.vy.to_vec(),
        ));
        if let Some((k, flag)) = self.raise_at {
            if f.index == k {
                flag.store(true, Ordering::Relaxed);
            }
        }
        Ok(())
    }
    fn log_text(&mut self, _: f64, _: &str, _: &str) -> vibrobed::Result<()> {
        Ok(())
    }
    fn finish(self: Box<Self>) -> vibrobed::Result<()> {
        Ok(())
    }
}

fn bed() -> Scenario {
    common::scenario(BED)
}

/// The summary as JSON without the wall-clock fields.
fn dynamics_of(summary: &vibrobed::output::summary::Summary) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_str(&summary.to_json()).unwrap();
    let o = v.as_object_mut().unwrap();
    o.remove("wall_seconds");
    o.remove("collisions_per_second");
    v
}

/// Frames at 0, 0.25, …, 2.0 hold exactly (to the last bit) the state a frame sink sees at the
/// same times; species, radii, cell, time and floor height are on every frame; writing the
/// trajectory changes nothing in the dynamics.
#[test]
fn frames_hold_the_simulated_state() {
    let dir = scratch("state");
    let path = dir.join("bed.xyz");
    let s = bed();
    let collector = Collector::default();
    let with = run(
        &s,
        RunOptions {
            trajectory: Some(path.clone()),
            sink: Some(Box::new(collector.clone())),
            ..RunOptions::default()
        },
    )
    .unwrap();
    let without = run(&s, RunOptions::default()).unwrap();
    assert_eq!(dynamics_of(&with), dynamics_of(&without));
    assert!(!dir.join("bed.xyz.partial").exists());

    let frames = parse(&path);
    let seen = collector.frames.lock().unwrap();
    assert_eq!(frames.len(), 9);
    assert_eq!(seen.len(), 9);
    for (k, (f, (t, x, y, vx, vy))) in frames.iter().zip(seen.iter()).enumerate() {
        assert_eq!(f.key("Time").unwrap().parse::<f64>().unwrap(), *t);
        assert_eq!(*t, 0.25 * k as f64);
        assert_eq!(f.key("frame"), Some(k.to_string().as_str()));
        assert!(f.key("floor_height").is_some());
        assert_eq!(f.key("pbc"), Some("\"F"));
        assert!(
            f.comment.starts_with("Lattice=\"12.0 0 0 0 "),
            "{}",
            f.comment
        );
        assert!(f
            .comment
            .contains("Properties=species:S:1:pos:R:3:radius:R:1:velo:R:3"));
        assert_eq!(f.columns.len(), 60);
        for (i, c) in f.columns.iter().enumerate() {
            assert_eq!([c[0], c[1], c[4], c[5]], [x[i], y[i], vx[i], vy[i]]);
            assert_eq!([c[2], c[6]], [0.0, 0.0]);
        }
        let big = f.columns.iter().filter(|c| c[3] == 0.7).count();
        assert_eq!(big, 10);
        for (sp, c) in f.species.iter().zip(&f.columns) {
            assert_eq!(sp, if c[3] == 0.7 { "He" } else { "H" });
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `output.trajectory_interval` sets its own cadence; `output.trajectory` works like `--trajectory`.
#[test]
fn interval_and_scenario_field() {
    let dir = scratch("interval");
    let path = dir.join("from_scenario.xyz");
    let mut s = bed();
    s.output.trajectory = Some(path.display().to_string());
    s.output.trajectory_interval = Some(0.5);
    let summary = run(&s, RunOptions::default()).unwrap();
    assert_eq!(summary.ending, Ending::Completed);
    let frames = parse(&path);
    let times: Vec<f64> = frames
        .iter()
        .map(|f| f.key("Time").unwrap().parse().unwrap())
        .collect();
    assert_eq!(times, vec![0.0, 0.5, 1.0, 1.5, 2.0]);
    std::fs::remove_dir_all(&dir).ok();
}

static STOP: AtomicBool = AtomicBool::new(false);

/// An interrupt (the flag Ctrl-C sets) ends the run early; the trajectory is in place, with
/// every frame up to the interrupt complete, and no temporary file is left.
#[test]
fn interrupt_leaves_complete_frames() {
    let dir = scratch("interrupt");
    let path = dir.join("cut.xyz");
    let collector = Collector {
        raise_at: Some((3, &STOP)),
        ..Collector::default()
    };
    let summary = run(
        &bed(),
        RunOptions {
            trajectory: Some(path.clone()),
            sink: Some(Box::new(collector)),
            interrupt: Some(&STOP),
            ..RunOptions::default()
        },
    )
    .unwrap();
    assert_eq!(summary.ending, Ending::Interrupted);
    assert!(!dir.join("cut.xyz.partial").exists());
    let frames = parse(&path); // panics on an incomplete frame
    assert_eq!(
        frames.len(),
        4,
        "frames 0..=3, written before the interrupt"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// ASE reads every frame (`ase.io.read(F, index=":")`) with positions, velocities and radii.
#[test]
#[ignore = "needs a Python with ASE (VIBROBED_PYTHON); examples/run.sh runs it"]
fn ase_reads_the_trajectory() {
    let python = std::env::var("VIBROBED_PYTHON").unwrap_or_else(|_| "python3".into());
    let probe = std::process::Command::new(&python)
        .args(["-c", "import ase"])
        .output();
    match probe {
        Err(e) => panic!("cannot run {python}: {e}"),
        Ok(out) if !out.status.success() => {
            panic!(
                "{python} has no ASE (import ase failed; set VIBROBED_PYTHON to a Python with ASE)"
            )
        }
        Ok(_) => {}
    }
    let dir = scratch("ase");
    let path = dir.join("bed.xyz");
    run(
        &bed(),
        RunOptions {
            trajectory: Some(path.clone()),
            ..RunOptions::default()
        },
    )
    .unwrap();
    let script = r#"
import sys, ase.io
frames = ase.io.read(sys.argv[1], index=":")
assert len(frames) == 9, len(frames)
a = frames[-1]
assert len(a) == 60
assert abs(a.info["Time"] - 2.0) < 1e-12, a.info
assert list(a.pbc) == [False, False, False]
assert abs(a.cell[0][0] - 12.0) < 1e-12
assert sorted(set(a.get_chemical_symbols())) == ["H", "He"]
assert (a.arrays["radius"] > 0.4).all()
assert a.arrays["velo"].shape == (60, 3)
assert (a.positions[:, 2] == 0).all()
print("ase read", len(frames), "frames")
"#;
    let out = std::process::Command::new(&python)
        .args(["-c", script])
        .arg(&path)
        .output()
        .expect("python runs");
    assert!(
        out.status.success(),
        "ASE failed to read the trajectory:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    println!("{}", String::from_utf8_lossy(&out.stdout).trim());
    std::fs::remove_dir_all(&dir).ok();
}
