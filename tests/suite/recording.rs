//! Writes Rerun recordings of synthetic frames and reads them back with Rerun's decoder.
#![cfg(feature = "record")]

use std::path::{Path, PathBuf};

use vibrobed::measure::ProfileTable;
use vibrobed::output::frame::{ColorBy, FrameView, SceneLayout};
use vibrobed::output::recording::{
    clock_label, orientation_line, read_back, spin_color, RerunRecorder,
};

const N: usize = 3;
const FRAMES: u64 = 10;
const DT: f64 = 0.05;

fn tmp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(format!("recording-{}-{name}.rrd", std::process::id()))
}

fn layout(top: Option<f64>) -> SceneLayout {
    SceneLayout {
        name: "three disks".into(),
        width: 10.0,
        x_periodic: false,
        top,
        y_periodic: false,
        floor: true,
        species: 2,
        speed_scale: 2.0,
        spin_scale: 2.0,
    }
}

/// Synthetic state of frame `k`: three disks moving on straight lines.
struct State {
    x: Vec<f64>,
    y: Vec<f64>,
    vx: Vec<f64>,
    vy: Vec<f64>,
    radius: Vec<f64>,
    species: Vec<u32>,
    time: f64,
    floor: f64,
    series: Vec<(&'static str, f64)>,
}

fn state(k: u64) -> State {
    let t = k as f64 * DT;
    let vx = vec![1.0, -0.5, 0.25];
    let vy = vec![0.3, 2.0, -0.1];
    let x0 = [1.0, 5.0, 8.0];
    let y0 = [1.0, 2.0, 3.3];
    State {
        x: (0..N).map(|i| x0[i] + vx[i] * t).collect(),
        y: (0..N).map(|i| y0[i] + vy[i] * t).collect(),
        vx,
        vy,
        radius: vec![0.5, 0.5, 0.25],
        species: vec![0, 0, 1],
        time: t,
        floor: 0.1 * (t * 7.0).sin(),
        series: vec![
            ("energy/kinetic", 10.0 + t),
            ("temperature/x", 1.0 / (1.0 + t)),
            ("com_height", 2.0 + t),
        ],
    }
}

fn view(k: u64, s: &State) -> FrameView<'_> {
    FrameView {
        index: k,
        time: s.time,
        x: &s.x,
        y: &s.y,
        vx: &s.vx,
        vy: &s.vy,
        radius: &s.radius,
        species: &s.species,
        floor_height: Some(s.floor),
        series: &s.series,
        profile: None,
        spins: None,
        fields: None,
        ids: &[],
    }
}

fn write(path: &Path, color_by: ColorBy, top: Option<f64>) -> RerunRecorder {
    let mut rec = RerunRecorder::create(path, &layout(top), color_by).unwrap();
    rec.log_text(0.0, "info", "recording started").unwrap();
    for k in 0..FRAMES {
        let s = state(k);
        rec.frame(&view(k, &s)).unwrap();
        if k == 4 {
            rec.log_text(s.time, "warning", "warm-up ended").unwrap();
        }
    }
    rec
}

/// The viewer writes a duration timeline as minutes and seconds (`+3m 20s` for t = 200): the
/// recording opens on the `frame` sequence (a plain number) and writes the simulated time of
/// each frame as a plain number on the bed; every log line is on the shown timeline.
#[test]
fn the_viewer_shows_simulated_time_as_plain_numbers() {
    let path = tmp("clock");
    write(&path, ColorBy::Speed, None).finish().unwrap();
    let c = read_back(&path).unwrap();
    assert_eq!(c.shown_timeline.as_deref(), Some("frame"));
    assert_eq!(c.timelines["frame"], "sequence", "{:?}", c.timelines);
    assert_eq!(c.timelines["sim_time"], "duration", "{:?}", c.timelines);
    assert!(c.static_entities.contains("scene/clock"));
    let labels: Vec<(i64, String)> = (0..FRAMES as i64)
        .map(|k| {
            (
                k,
                format!("t = {}", (k as f64 * DT * 100.0).round() / 100.0),
            )
        })
        .collect();
    assert_eq!(c.clock, labels);
    assert_eq!(c.clock[1].1, "t = 0.05");
    let frames: Vec<Option<i64>> = c.log.iter().map(|l| l.frame).collect();
    assert_eq!(
        frames,
        [Some(0), Some(4)],
        "log lines on the frame timeline"
    );
    std::fs::remove_file(&path).ok();
}

#[test]
fn clock_labels_tell_frames_apart() {
    assert_eq!(clock_label(0.0, None), "t = 0");
    assert_eq!(clock_label(200.0, Some(1.0)), "t = 200");
    assert_eq!(clock_label(137.5, Some(0.5)), "t = 137.5");
    assert_eq!(clock_label(0.25, Some(0.25)), "t = 0.25");
    assert_eq!(clock_label(1.0 / 3.0, None), "t = 0.333");
    assert_eq!(clock_label(12.000_03, Some(1e-5)), "t = 12.00003");
}

#[test]
fn frames_read_back_equal_what_was_logged() {
    let path = tmp("speed");
    write(&path, ColorBy::Speed, None).finish().unwrap();
    let c = read_back(&path).unwrap();

    assert_eq!(c.application_id.as_deref(), Some("vibrobed"));
    let disks = c.entity("disks").expect("entity `disks` missing");
    // One row per frame, and one more at frame 0 with the radii and class ids.
    assert_eq!(disks.rows, FRAMES as usize + 1);
    assert_eq!(disks.frames, FRAMES as usize);
    assert_eq!(c.disks.len(), FRAMES as usize);
    for (k, d) in c.disks.iter().enumerate() {
        let s = state(k as u64);
        assert_eq!(d.frame, k as i64);
        assert!(
            (d.time - s.time).abs() < 1e-9,
            "frame {k}: time {} vs {}",
            d.time,
            s.time
        );
        let expected: Vec<[f32; 2]> =
            s.x.iter()
                .zip(&s.y)
                .map(|(&x, &y)| [x as f32, y as f32])
                .collect();
        assert_eq!(d.positions, expected, "frame {k}");
        assert_eq!(d.radii, vec![0.5f32, 0.5, 0.25], "frame {k}");
        assert_eq!(d.class_ids, vec![0u16, 0, 1], "frame {k}");
        assert_eq!(d.colors.len(), N, "frame {k}: colours by speed");
    }
    // The fastest disk is the reddest (disk 1, |v| ≈ 2.06), the slowest the bluest (disk 2):
    // red minus blue grows with speed.
    let warmth = |rgba: u32| i64::from(rgba >> 24) - i64::from((rgba >> 8) & 0xff);
    let [w0, w1, w2] = [0, 1, 2].map(|i| warmth(c.disks[0].colors[i]));
    assert!(w1 > w0 && w0 > w2, "red - blue: {w0} {w1} {w2}");

    assert_eq!(c.floor.len(), FRAMES as usize);
    for (k, &(f, h)) in c.floor.iter().enumerate() {
        assert_eq!(f, k as i64);
        assert_eq!(h, state(k as u64).floor as f32);
    }

    for name in ["energy/kinetic", "temperature/x", "com_height"] {
        let values = &c.series[name];
        assert_eq!(values.len(), FRAMES as usize, "{name}");
        for (k, &(f, v)) in values.iter().enumerate() {
            let expected = state(k as u64)
                .series
                .iter()
                .find(|s| s.0 == name)
                .unwrap()
                .1;
            assert_eq!((f, v), (k as i64, expected), "{name}");
        }
        let stats = c.entity(&format!("series/{name}")).unwrap();
        assert_eq!(stats.frames, FRAMES as usize);
    }

    assert_eq!(c.log.len(), 2);
    assert_eq!(c.log[0].level, "INFO");
    assert_eq!(c.log[0].text, "recording started");
    assert_eq!(c.log[1].level, "WARN");
    assert_eq!(c.log[1].text, "warm-up ended");
    assert!((c.log[1].time.unwrap() - 4.0 * DT).abs() < 1e-9);

    // Static scene: walls (open top → grown to the disks), transforms, annotation context.
    assert!(
        c.static_entities.contains("scene/walls"),
        "{:?}",
        c.static_entities
    );
    assert!(!c.static_entities.contains("scene/lid"));
    assert!(c.static_entities.contains("disks"));
    // Smooth disks: no orientation, static or per frame.
    assert!(!c.static_entities.contains("disks/orientation"));
    assert!(c.entity("disks/orientation").is_none() && c.orientation.is_empty());
    assert!(c.has_blueprint);
    assert!(c.has_footer, "footer (manifest) missing");
    assert!(c.manifest_chunks > 0);
    std::fs::remove_file(&path).ok();
}

/// Colours follow one fixed scale (`speed_scale` = 2): a disk keeps its colour while others
/// speed up, rest is blue, the scale and above are red.
#[test]
fn colour_scale_is_fixed() {
    let path = tmp("scale");
    let mut rec = RerunRecorder::create(&path, &layout(None), ColorBy::Speed).unwrap();
    let s = state(0);
    let speeds = [[1.0, 0.0, 0.0], [1.0, 40.0, 0.0]];
    for (k, vx) in speeds.iter().enumerate() {
        let vy = [0.0; 3];
        let mut f = view(k as u64, &s);
        f.vx = vx;
        f.vy = &vy;
        rec.frame(&f).unwrap();
    }
    rec.finish().unwrap();
    let c = read_back(&path).unwrap();
    assert_eq!(c.disks.len(), 2);
    let [a, b] = [&c.disks[0].colors, &c.disks[1].colors];
    assert_eq!(a[0], b[0], "disk 0 kept its speed and must keep its colour");
    assert_eq!(a[2], 0x3b4cc0ff, "at rest: blue");
    assert_eq!(b[1], 0xb40426ff, "above the scale: red");
    assert_ne!(a[1], b[1]);
    std::fs::remove_file(&path).ok();
}

/// Live profiles: one line strip per frame and profile, points (value, height); the
/// temperature leaves out bins without disks.
#[test]
fn profiles_read_back() {
    let path = tmp("profiles");
    let mut rec = RerunRecorder::create(&path, &layout(None), ColorBy::Speed).unwrap();
    let table = |k: u64| ProfileTable {
        height: vec![0.5, 1.5, 2.5],
        density: vec![0.4, 0.0, 0.1],
        packing_fraction: vec![0.3 + 0.01 * k as f64, 0.0, 0.05],
        temperature_x: vec![1.0, 0.0, 2.0],
        temperature_y: vec![3.0, 0.0, 4.0 + k as f64],
        velocity_x: vec![0.0; 3],
        velocity_y: vec![0.0; 3],
        temperature_rotational: None,
        above_top: 0.0,
    };
    for k in 0..FRAMES {
        let s = state(k);
        let p = table(k);
        let mut f = view(k, &s);
        f.profile = Some(&p);
        rec.frame(&f).unwrap();
    }
    rec.finish().unwrap();
    let c = read_back(&path).unwrap();
    let phi = &c.profiles["packing_fraction"];
    let temp = &c.profiles["temperature"];
    assert_eq!(phi.len(), FRAMES as usize);
    assert_eq!(temp.len(), FRAMES as usize);
    for k in 0..FRAMES {
        let (f, pts) = &phi[k as usize];
        assert_eq!(*f, k as i64);
        let v = (0.3 + 0.01 * k as f64) as f32;
        assert_eq!(pts, &vec![[v, 0.5], [0.0, 1.5], [0.05, 2.5]]);
        let (_, pts) = &temp[k as usize];
        assert_eq!(pts, &vec![[2.0, 0.5], [(3.0 + 0.5 * k as f64) as f32, 2.5]]);
    }
    assert!(c.entity("profiles/packing_fraction").is_some());
    for e in [
        "profiles/packing_fraction/axes",
        "profiles/temperature/axes",
        "legend",
        "scene/speed_scale",
    ] {
        assert!(
            c.static_entities.contains(e),
            "{e}: {:?}",
            c.static_entities
        );
    }
    std::fs::remove_file(&path).ok();
}

#[test]
fn species_colouring_and_lid() {
    let path = tmp("species");
    write(&path, ColorBy::Species, Some(8.0)).finish().unwrap();
    let c = read_back(&path).unwrap();
    assert_eq!(c.entity("disks").unwrap().frames, FRAMES as usize);
    assert!(c.disks.iter().all(|d| d.colors.is_empty()));
    assert!(c.disks.iter().all(|d| d.class_ids == vec![0, 0, 1]));
    assert!(c.static_entities.contains("scene/lid"));
    assert!(c.static_entities.contains("scene/walls"));
    assert!(c.has_footer);
    std::fs::remove_file(&path).ok();
}

/// Dropping the recorder without `finish` (error paths, unwinding) still completes the file.
#[test]
fn dropped_recorder_leaves_a_complete_file() {
    let path = tmp("dropped");
    drop(write(&path, ColorBy::Speed, None));
    let c = read_back(&path).unwrap();
    assert_eq!(c.entity("disks").unwrap().frames, FRAMES as usize);
    assert_eq!(c.disks.len(), FRAMES as usize);
    assert!(c.has_footer);
    std::fs::remove_file(&path).ok();
}

#[test]
fn recording_without_frames_is_valid() {
    let path = tmp("empty");
    RerunRecorder::create(&path, &layout(None), ColorBy::Speed)
        .unwrap()
        .finish()
        .unwrap();
    let c = read_back(&path).unwrap();
    assert!(c.entity("disks").is_none());
    assert!(c.disks.is_empty());
    assert!(c.has_blueprint);
    assert!(c.has_footer);
    std::fs::remove_file(&path).ok();
}

/// A recorder dropped before its first frame (a run failing early) still lays the file out.
#[test]
fn dropped_recorder_without_frames_has_its_blueprint() {
    let path = tmp("dropped-empty");
    let mut rec = RerunRecorder::create(&path, &layout(None), ColorBy::Speed).unwrap();
    rec.log_text(0.0, "error", "failed before the first frame")
        .unwrap();
    drop(rec);
    let c = read_back(&path).unwrap();
    assert!(c.disks.is_empty());
    assert!(c.has_blueprint);
    assert!(c.has_footer);
    assert_eq!(c.log.len(), 1);
    assert_eq!(c.log[0].level, "ERROR");
    std::fs::remove_file(&path).ok();
}

#[test]
fn mismatched_slices_are_an_error() {
    let path = tmp("bad");
    let mut rec = RerunRecorder::create(&path, &layout(None), ColorBy::Speed).unwrap();
    let s = state(0);
    let mut f = view(0, &s);
    f.y = &s.y[..2];
    assert!(rec.frame(&f).is_err());
    rec.finish().unwrap();
    std::fs::remove_file(&path).ok();
}

#[test]
fn garbage_is_not_a_recording() {
    let path = tmp("garbage");
    std::fs::write(&path, b"this is not an rrd file at all").unwrap();
    assert!(read_back(&path).is_err());
    std::fs::remove_file(&path).ok();
}

/// Cost of recording: `cargo test --release --test suite -- --ignored --nocapture recording::recording_throughput`.
#[test]
#[ignore = "a measurement of the recorder's cost, not a check: run it by name"]
fn recording_throughput() {
    let n = 1000;
    let frames = 500u64;
    let path = tmp("throughput");
    let mut rec = RerunRecorder::create(&path, &layout(None), ColorBy::Speed).unwrap();
    let radius = vec![0.01; n];
    let species = vec![0; n];
    let vx: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
    let vy: Vec<f64> = (0..n).map(|i| (i as f64 * 0.91).cos()).collect();
    let series = [
        ("energy/kinetic", 1.0),
        ("temperature/x", 2.0),
        ("temperature/y", 3.0),
    ];
    let start = std::time::Instant::now();
    for k in 0..frames {
        let t = k as f64 * 0.01;
        let x: Vec<f64> = (0..n).map(|i| (i % 100) as f64 * 0.1 + vx[i] * t).collect();
        let y: Vec<f64> = (0..n).map(|i| (i / 100) as f64 * 0.1 + vy[i] * t).collect();
        rec.frame(&FrameView {
            index: k,
            time: t,
            x: &x,
            y: &y,
            vx: &vx,
            vy: &vy,
            radius: &radius,
            species: &species,
            floor_height: Some(0.0),
            series: &series,
            profile: None,
            spins: None,
            fields: None,
            ids: &[],
        })
        .unwrap();
    }
    let logged = start.elapsed().as_secs_f64();
    rec.finish().unwrap();
    let total = start.elapsed().as_secs_f64();
    let bytes = std::fs::metadata(&path).unwrap().len();
    eprintln!(
        "{frames} frames x {n} disks: log {logged:.3} s ({:.0} frames/s), with close {total:.3} s, {bytes} bytes ({:.0} B/frame)",
        frames as f64 / logged,
        bytes as f64 / frames as f64
    );
    let read = std::time::Instant::now();
    let c = read_back(&path).unwrap();
    eprintln!("read back in {:.3} s", read.elapsed().as_secs_f64());
    assert_eq!(c.disks.len(), frames as usize);
    std::fs::remove_file(&path).ok();
}

/// Rough disks: a radius line per disk, from its centre to the point of its rim at its angle
/// (anticlockwise from +x, radii of two sizes, angles turning through the quadrants), in every frame; colours
/// by spin diverge about zero on the spin scale (rim speed ω a = ±1 full blue or red).
#[test]
fn rough_disks_show_their_orientation_and_spin() {
    let path = tmp("rough");
    // Spins on a scale of their own, half the speeds'.
    let layout = SceneLayout {
        spin_scale: 1.0,
        ..layout(None)
    };
    let mut rec = RerunRecorder::create(&path, &layout, ColorBy::Spin).unwrap();
    // ω such that ω a = −1 (clockwise, full blue), 0, and 0.5 (anticlockwise, half way to red).
    let omega = [-2.0, 0.0, 2.0];
    let spins_at = |t: f64| -> Vec<(f64, f64)> {
        let angle0 = [0.3, 2.0, 4.0];
        (0..N)
            .map(|i| {
                (
                    (angle0[i] + omega[i] * t).rem_euclid(std::f64::consts::TAU),
                    omega[i],
                )
            })
            .collect()
    };
    for k in 0..FRAMES {
        let s = state(k);
        let spins = spins_at(s.time);
        let mut f = view(k, &s);
        f.spins = Some(&spins);
        rec.frame(&f).unwrap();
    }
    rec.finish().unwrap();
    let c = read_back(&path).unwrap();
    assert_eq!(
        c.entity("disks/orientation").unwrap().frames,
        FRAMES as usize
    );
    assert!(c.static_entities.contains("disks/orientation"), "its look");
    assert_eq!(c.orientation.len(), FRAMES as usize);
    for (k, (frame, lines)) in c.orientation.iter().enumerate() {
        let s = state(k as u64);
        let spins = spins_at(s.time);
        assert_eq!(*frame, k as i64);
        assert_eq!(lines.len(), N);
        for i in 0..N {
            let [centre, rim] = lines[i];
            assert_eq!(
                centre,
                [s.x[i] as f32, s.y[i] as f32],
                "frame {k}, disk {i}"
            );
            let (dx, dy) = (f64::from(rim[0] - centre[0]), f64::from(rim[1] - centre[1]));
            let a = s.radius[i];
            assert!(
                (dx.hypot(dy) - a).abs() < 1e-5,
                "frame {k}, disk {i}: length"
            );
            let (sin, cos) = spins[i].0.sin_cos();
            assert!(
                (dx - a * cos).abs() < 1e-5 && (dy - a * sin).abs() < 1e-5,
                "frame {k}, disk {i}: ({dx}, {dy}) at angle {}",
                spins[i].0
            );
        }
        let colors = &c.disks[k].colors;
        assert_eq!(colors[0], 0x3b4cc0ff, "ω a = −1: full blue");
        assert_eq!(colors[1], 0xddddddff, "not turning: grey");
        assert_eq!(
            colors[2],
            spin_color(0.5).to_u32(),
            "ω a = 0.5: half way to red"
        );
    }
    // A line of the helper: radius 2 at a quarter turn points straight up.
    assert_eq!(
        orientation_line(1.0, 1.0, 2.0, std::f64::consts::FRAC_PI_2)[1][1],
        3.0
    );
    std::fs::remove_file(&path).ok();
}

/// Spins of another length than the disks are refused, like any per-disk slice.
#[test]
fn spins_of_the_wrong_length_are_an_error() {
    let path = tmp("bad-spins");
    let mut rec = RerunRecorder::create(&path, &layout(None), ColorBy::Spin).unwrap();
    let s = state(0);
    let spins = [(0.0, 1.0)];
    let mut f = view(0, &s);
    f.spins = Some(&spins);
    let e = rec.frame(&f).unwrap_err();
    assert!(e.contains("spins of 1 disks for 3 disks"), "{e}");
    drop(rec);
    std::fs::remove_file(&path).ok();
}
