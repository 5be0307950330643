//! What a frame holds: the state of every disk at one exact simulated time, plus the scene's
//! moving parts and the scalar time series. Output sinks (the Rerun recorder, tests) read frames;
//! they never touch the engine.

use crate::measure::fields::Fields;
use crate::measure::ProfileTable;

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
    /// The id of each disk, where disks leave (empty: disk i is entry i).
    pub ids: &'a [u32],
    pub fields: Option<&'a Fields>,
}
