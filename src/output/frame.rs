//! What a frame holds: the state of every disk at one exact simulated time, plus the scene's
//! moving parts and the scalar time series. Output sinks (the Rerun recorder, tests) read frames;
//! they never touch the engine.

use crate::engine::{EnergyFlow, Scene, Snapshot};
use crate::error::Result;
use crate::measure::fields::Fields;
use crate::measure::{Observables, ProfileTable};
use crate::output::partial::Partial;
use crate::physics::disks::Disks;
use crate::scenario::{ColorChoice, Scenario, XBoundary, YBoundary};

/// The fixed geometry of a scene, known before the first frame.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneLayout {
    /// Scene name (from the scenario file).
    pub name: String,
    /// Width of the domain in x (from 0 to `width`).
    pub width: f64,
    /// `true` when x is periodic, `false` for hard walls at x = 0 and x = width.
    pub x_periodic: bool,
    /// Height of the lid (or of the periodic cell in y); `None` for an open top.
    pub top: Option<f64>,
    /// `true` when y is periodic (then `top` is the period).
    pub y_periodic: bool,
    /// `true` when the scene has a floor (static or vibrating) whose mean height is y = 0.
    pub floor: bool,
    /// Number of species (distinct radius classes) for colouring by species.
    pub species: usize,
    /// Speed drawn full red when colouring by speed: one fixed colour scale for the whole run
    /// (blue at rest, grey at half this speed, red at this speed and above).
    pub speed_scale: f64,
    /// Rim speed ω a drawn full colour when colouring rough disks by spin (blue clockwise, red
    /// anticlockwise).
    pub spin_scale: f64,
}

/// How disks are coloured in a recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ColorBy {
    /// By speed |v| (blue at rest → red at [`SceneLayout::speed_scale`] and above).
    #[default]
    Speed,
    /// By species index.
    Species,
    /// By spin, rough disks only: the rim speed ω a on a diverging scale, blue clockwise → grey
    /// not turning → red anticlockwise, full colour at ±[`SceneLayout::spin_scale`].
    Spin,
}

impl From<ColorChoice> for ColorBy {
    fn from(c: ColorChoice) -> ColorBy {
        match c {
            ColorChoice::Speed => ColorBy::Speed,
            ColorChoice::Species => ColorBy::Species,
            ColorChoice::Spin => ColorBy::Spin,
        }
    }
}

impl SceneLayout {
    /// The fixed geometry of the scene, as the recording and the trajectory draw it, and the
    /// colour scale of speeds: `output.speed_scale`, else three times the floor's peak speed,
    /// else three times the initial root-mean-square speed (else 1); and of spins:
    /// `output.spin_scale`, else a third of the speed scale (a rim speed of the floor's peak
    /// speed, or the rms speed).
    pub fn of(s: &Scenario, scene: &Scene, disks: &Disks) -> SceneLayout {
        let floor_speed = scene
            .floor
            .as_ref()
            .map_or(0.0, |f| f.drive().peak_velocity());
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
            species: disks.species.iter().max().map_or(1, |m| m as usize + 1),
            speed_scale,
            spin_scale: s.output.spin_scale.unwrap_or(speed_scale / 3.0),
        }
    }
}

/// Where frames go (the Rerun recorder, or a test's collector).
pub trait FrameSink {
    /// Takes one frame.
    fn frame(&mut self, frame: &FrameView) -> Result<()>;
    /// Logs a line of text at simulated time `time` (`level`: "INFO", "WARN", …).
    fn log_text(&mut self, time: f64, level: &str, text: &str) -> Result<()>;
    /// Closes the output (writes footers).
    fn finish(self: Box<Self>) -> Result<()>;
    /// The file being written, for the watch that notices it removed during the run.
    fn file(&self) -> Option<Partial> {
        None
    }
}

/// The time series a frame carries, by name (`series/<name>` in a recording): temperatures,
/// energies, the centre of mass, the collision rate since the last frame; the rotational energy
/// of rough disks (smooth disks' series stop before it); where disks leave (`pool`: how many are
/// live, how many have left), the flow.
pub fn frame_series(
    o: &Observables,
    flow: &EnergyFlow,
    collisions_per_time: f64,
    rotational: Option<f64>,
    pool: Option<(f64, f64)>,
) -> Vec<(&'static str, f64)> {
    let mut series = vec![
        ("temperature/x", o.temperature[0]),
        ("temperature/y", o.temperature[1]),
        ("energy/kinetic", o.kinetic),
        ("energy/potential", o.potential),
        ("energy/injected", flow.injected),
        ("energy/dissipated", flow.dissipated),
        ("com_height", o.com_height),
        ("collisions_per_time", collisions_per_time),
    ];
    if let Some(r) = rotational {
        series.push(("energy/rotational", r));
    }
    if let Some((live, out)) = pool {
        series.extend([("flow/live", live), ("flow/out", out)]);
    }
    series
}

/// One frame: every disk advanced to `time` (not the time of its last event).
#[derive(Debug, Clone, Copy)]
pub struct FrameView<'a> {
    /// Frame number, 0, 1, 2, … .
    pub index: u64,
    /// Simulated time of the frame.
    pub time: f64,
    /// Disk centres, x.
    pub x: &'a [f64],
    /// Disk centres, y.
    pub y: &'a [f64],
    /// Velocities, x.
    pub vx: &'a [f64],
    /// Velocities, y.
    pub vy: &'a [f64],
    /// Disk radii.
    pub radius: &'a [f64],
    /// Species index of each disk.
    pub species: &'a [u32],
    /// Height of the floor at `time` (`None` without a floor).
    pub floor_height: Option<f64>,
    /// Scalar time series sampled at this frame: (name, value), e.g. ("energy/kinetic", 12.5).
    pub series: &'a [(&'static str, f64)],
    /// Height profiles of this frame alone (gravity scenes; the bins of the run's profiles).
    pub profile: Option<&'a ProfileTable>,
    /// Each rough disk's `(angle, ω)` at `time`: its orientation in [0, 2π) and angular
    /// velocity, anticlockwise positive; `None` for smooth disks.
    pub spins: Option<&'a [(f64, f64)]>,
    /// The live 2D fields (`output.record_fields`): a running average over one floor period.
    pub fields: Option<&'a Fields>,
    /// The id of each disk, where disks leave (empty: disk i is entry i).
    pub ids: &'a [u32],
}

impl<'a> FrameView<'a> {
    /// Frame `index` of the disks in `snap`, with the time series and live profiles it carries, and
    /// rough disks' `(angle, ω)`.
    pub fn of(
        index: u64,
        snap: &'a Snapshot,
        (radius, species): (&'a [f64], &'a [u32]),
        (series, profile): (&'a [(&'static str, f64)], Option<&'a ProfileTable>),
        spins: Option<&'a [(f64, f64)]>,
    ) -> FrameView<'a> {
        FrameView {
            index,
            time: snap.time,
            x: &snap.x,
            y: &snap.y,
            vx: &snap.vx,
            vy: &snap.vy,
            radius,
            species,
            floor_height: snap.floor_height,
            series,
            profile,
            spins,
            fields: None,
            ids: &snap.ids,
        }
    }
}

/// A snapshot of the live disks (with their ids), their radii and species, spread over every id
/// of the scene: entry i is the disk whose id is i, those not in the scene at no position
/// (NaN) with radius 0 (`scene_ids`: how many ids the scene gives out at the least).
pub fn spread_by_id(
    snap: &Snapshot,
    radius: &[f64],
    species: &[u32],
    scene_ids: usize,
) -> (Snapshot, Vec<f64>, Vec<u32>) {
    let ids = scene_ids.max(snap.ids.iter().map(|&i| i as usize + 1).max().unwrap_or(0));
    let mut out = Snapshot {
        time: snap.time,
        x: vec![f64::NAN; ids],
        y: vec![f64::NAN; ids],
        vx: vec![0.0; ids],
        vy: vec![0.0; ids],
        floor_height: snap.floor_height,
        ids: Vec::new(),
    };
    let (mut r, mut k) = (vec![0.0; ids], vec![0; ids]);
    for (row, &id) in snap.ids.iter().enumerate() {
        let id = id as usize;
        out.x[id] = snap.x[row];
        out.y[id] = snap.y[row];
        out.vx[id] = snap.vx[row];
        out.vy[id] = snap.vy[row];
        r[id] = radius[row];
        k[id] = species.get(row).copied().unwrap_or(0);
    }
    (out, r, k)
}
