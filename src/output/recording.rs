//! The Rerun recording sink: streams frames to a `.rrd` file that opens ready to read in the
//! Rerun viewer (`rerun OUT.rrd`, same version as the `rerun` crate, 0.36.3).
//!
//! # What the file holds
//!
//! | entity            | kind     | content                                                    |
//! |-------------------|----------|------------------------------------------------------------|
//! | `disks`           | temporal | `Points2D`: centres, radii, colours (by speed or species), class ids = species |
//! | `disks`           | static   | `AnnotationContext` (species names and colours), y-up `Transform3D` |
//! | `scene`           | static   | y-up `Transform3D` for everything under it                 |
//! | `scene/walls`     | static   | `LineStrips2D`: vertical walls at x = 0 and x = width (hard x walls only) |
//! | `scene/lid`       | static   | `LineStrips2D`: the lid at y = top (lid scenes only)        |
//! | `scene/floor`     | temporal | `LineStrips2D`: the floor at its current height            |
//! | `series/<name>`   | temporal | `Scalars`: one value per frame                              |
//! | `log`             | temporal | `TextLog`: notable events                                   |
//!
//! Timelines: sequence `frame` (the frame index) and duration `sim_time` (simulated time, stored
//! with nanosecond resolution, one simulated time unit shown as one second). The wall-clock
//! `log_time` timeline is disabled so that the file content depends on the simulation only.
//!
//! Rerun's 2D views draw y downwards; `disks` and `scene` carry a static `Transform3D` with scale
//! (1, −1, 1) so that gravity points down on screen. The logged data themselves are the simulation
//! coordinates (y up), which is what [`read_back`] returns.
//!
//! Walls for an open top (no lid, y not periodic) have no natural height: they are drawn up to
//! 1.25 × the highest disk top (or floor) seen so far, and re-logged as static data whenever a disk
//! climbs above them, so the viewer shows one stable, tall-enough pair of walls at every time.
//!
//! Radii and class ids are logged with the first frame and again only when they change (Rerun's
//! latest-at semantics carries them over); positions, colours and the floor are logged every frame.
//!
//! The blueprint (disks large on the left; one time-series view per series group, i.e. per first
//! path segment of the series names, or per series without a group, and the text log stacked on
//! the right; blueprint, selection and time panels collapsed; timeline `sim_time`) is sent with
//! the first frame, when the series names are known, or by [`RerunRecorder::finish`] (or the
//! drop of the recorder) when no frame was ever written.
//!
//! # Completeness of the file
//!
//! The footer (with the chunk manifest) is written when the underlying `RecordingStream` is
//! dropped. [`RerunRecorder::finish`] flushes and drops it and reports errors; simply dropping a
//! `RerunRecorder` (e.g. while unwinding from an error) also completes the file. Only a process
//! that exits without running destructors (`std::process::exit`, default SIGINT handling, abort)
//! leaves a file without its footer.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use rerun::blueprint::components::PanelState;
use rerun::blueprint::{
    Blueprint, BlueprintActivation, BlueprintPanel, ContainerLike, Horizontal, SelectionPanel,
    Spatial2DView, TextLogView, TimePanel, TimeSeriesView, Vertical,
};
use rerun::components::{ClassId, Color, Position2D, Radius, Scalar, Text, TextLogLevel};
use rerun::datatypes::{ClassDescriptionMapElem, Rgba32};
use rerun::external::re_log_encoding::DecoderApp;
use rerun::log::{Chunk, LogMsg};
use rerun::time::{TimeCell, TimelineName};
use rerun::{
    AnnotationContext, LineStrips2D, Points2D, RecordingStream, RecordingStreamBuilder, Scalars,
    TextLog, Transform3D,
};

use super::frame::{ColorBy, FrameView, SceneLayout};

/// Application id written into the recording.
pub const APPLICATION_ID: &str = "vibrobed";
/// Name of the sequence timeline holding the frame index.
pub const FRAME_TIMELINE: &str = "frame";
/// Name of the duration timeline holding the simulated time.
pub const SIM_TIME_TIMELINE: &str = "sim_time";
/// Entity of the disks.
pub const DISKS_ENTITY: &str = "disks";
/// Entity of the walls (static).
pub const WALLS_ENTITY: &str = "scene/walls";
/// Entity of the lid (static).
pub const LID_ENTITY: &str = "scene/lid";
/// Entity of the floor (one line per frame).
pub const FLOOR_ENTITY: &str = "scene/floor";
/// Prefix of the time-series entities: series `name` goes to `series/<name>`.
pub const SERIES_PREFIX: &str = "series";
/// Entity of the text log.
pub const LOG_ENTITY: &str = "log";

/// Colours of species 0, 1, … (cycled), also used for the annotation context.
const SPECIES_PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];
const WALL_COLOR: [u8; 3] = [170, 170, 170];
const FLOOR_COLOR: [u8; 3] = [230, 140, 30];

/// Streams a simulation to a Rerun `.rrd` file. See the [module documentation](self) for the
/// file layout. Only compiled with the `record` feature.
pub struct RerunRecorder {
    rec: RecordingStream,
    layout: SceneLayout,
    color_by: ColorBy,
    /// Height the walls are currently drawn to (open top only).
    wall_height: Option<f64>,
    /// Radii last logged (re-logged only on change).
    last_radii: Vec<f64>,
    /// Species last logged (re-logged only on change).
    last_species: Vec<u32>,
    blueprint_sent: bool,
    /// Reused buffers.
    positions: Vec<[f32; 2]>,
    colors: Vec<Color>,
}

impl std::fmt::Debug for RerunRecorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RerunRecorder")
            .field("layout", &self.layout)
            .field("color_by", &self.color_by)
            .finish_non_exhaustive()
    }
}

fn err(context: &str, e: impl std::fmt::Display) -> String {
    format!("rerun recording: {context}: {e}")
}

fn rgb(c: [u8; 3]) -> Color {
    Color::from_rgb(c[0], c[1], c[2])
}

/// Blue (slow) → light grey → red (fast), `t` in [0, 1] ("coolwarm").
fn speed_color(t: f64) -> Color {
    const STOPS: [[f64; 3]; 3] = [
        [59.0, 76.0, 192.0],
        [221.0, 221.0, 221.0],
        [180.0, 4.0, 38.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let (a, b, s) = if t < 0.5 {
        (STOPS[0], STOPS[1], t * 2.0)
    } else {
        (STOPS[1], STOPS[2], t * 2.0 - 1.0)
    };
    let mix = |i: usize| (a[i] + (b[i] - a[i]) * s).round() as u8;
    Color::from_rgb(mix(0), mix(1), mix(2))
}

fn line(points: [[f64; 2]; 2]) -> [[f32; 2]; 2] {
    points.map(|[x, y]| [x as f32, y as f32])
}

impl RerunRecorder {
    /// Opens `path` for writing (truncating it), disables the wall-clock `log_time` timeline and
    /// logs the static scene: y-up transforms, the species annotation context, the walls
    /// (when x is bounded by walls and the top is known) and the lid (when there is one).
    pub fn create(path: &Path, layout: &SceneLayout, color_by: ColorBy) -> Result<Self, String> {
        let rec = RecordingStreamBuilder::new(APPLICATION_ID)
            .recording_name(layout.name.clone())
            // An explicit `--rrd` wins over a `RERUN=0` environment variable.
            .enabled(true)
            .save(path)
            .map_err(|e| err(&format!("cannot create {}", path.display()), e))?;
        rec.set_log_time_enabled(false);

        let mut recorder = Self {
            rec,
            layout: layout.clone(),
            color_by,
            wall_height: None,
            last_radii: Vec::new(),
            last_species: Vec::new(),
            blueprint_sent: false,
            positions: Vec::new(),
            colors: Vec::new(),
        };
        recorder.log_static_scene()?;
        Ok(recorder)
    }

    fn log_static_scene(&mut self) -> Result<(), String> {
        let flip = Transform3D::from_scale((1.0, -1.0, 1.0));
        self.rec
            .log_static(DISKS_ENTITY, &flip)
            .map_err(|e| err("transform", e))?;
        self.rec
            .log_static("scene", &flip)
            .map_err(|e| err("transform", e))?;

        let classes: Vec<ClassDescriptionMapElem> = (0..self.layout.species.max(1))
            .map(|s| {
                let c = SPECIES_PALETTE[s % SPECIES_PALETTE.len()];
                let id = u16::try_from(s).unwrap_or(u16::MAX);
                (
                    id,
                    format!("species {s}").as_str(),
                    Rgba32::from_rgb(c[0], c[1], c[2]),
                )
                    .into()
            })
            .collect();
        self.rec
            .log_static(DISKS_ENTITY, &AnnotationContext::new(classes))
            .map_err(|e| err("annotation context", e))?;

        if let (Some(top), false) = (self.layout.top, self.layout.y_periodic) {
            let w = self.layout.width;
            self.rec
                .log_static(
                    LID_ENTITY,
                    &LineStrips2D::new([line([[0.0, top], [w, top]])])
                        .with_colors([rgb(WALL_COLOR)])
                        .with_radii([Radius::new_ui_points(1.5)]),
                )
                .map_err(|e| err("lid", e))?;
        }
        if let Some(top) = self.layout.top {
            self.log_walls(top)?;
        }
        Ok(())
    }

    /// Logs (static) the two walls from y = 0 (or below, when the floor dips) up to `height`.
    fn log_walls(&mut self, height: f64) -> Result<(), String> {
        self.wall_height = Some(height);
        if self.layout.x_periodic {
            return Ok(());
        }
        let w = self.layout.width;
        self.rec
            .log_static(
                WALLS_ENTITY,
                &LineStrips2D::new([
                    line([[0.0, 0.0], [0.0, height]]),
                    line([[w, 0.0], [w, height]]),
                ])
                .with_colors([rgb(WALL_COLOR)])
                .with_radii([Radius::new_ui_points(1.5)]),
            )
            .map_err(|e| err("walls", e))
    }

    /// Writes one frame on timelines `frame` = `f.index` and `sim_time` = `f.time`: the disks,
    /// the floor line (when `f.floor_height` is `Some`) and every series value under
    /// `series/<name>`. Fails when the per-disk slices have different lengths.
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
        if !self.blueprint_sent {
            self.send_blueprint(f.series)?;
        }

        self.rec
            .set_time_sequence(FRAME_TIMELINE, i64::try_from(f.index).unwrap_or(i64::MAX));
        self.set_sim_time(f.time);

        // Open top: grow the walls when something rises above 80 % of them.
        if self.layout.top.is_none() && !self.layout.x_periodic {
            let mut highest = f.floor_height.unwrap_or(0.0);
            for (y, r) in f.y.iter().zip(f.radius) {
                if y + r > highest {
                    highest = y + r;
                }
            }
            let needed = if highest > 0.0 {
                highest * 1.25
            } else {
                self.layout.width
            };
            if self.wall_height.is_none_or(|h| highest > 0.8 * h) {
                self.log_walls(needed)?;
            }
        }

        self.positions.clear();
        self.positions
            .extend(f.x.iter().zip(f.y).map(|(&x, &y)| [x as f32, y as f32]));
        let mut points = Points2D::new(self.positions.iter().copied());

        if self.last_radii.as_slice() != f.radius {
            points = points.with_radii(f.radius.iter().map(|&r| Radius::new_scene_units(r as f32)));
            self.last_radii.clear();
            self.last_radii.extend_from_slice(f.radius);
        }
        let species_changed = if f.species.is_empty() {
            self.last_species.len() != n || self.last_species.iter().any(|&s| s != 0)
        } else {
            self.last_species.as_slice() != f.species
        };
        if species_changed {
            self.last_species.clear();
            if f.species.is_empty() {
                self.last_species.resize(n, 0);
            } else {
                self.last_species.extend_from_slice(f.species);
            }
            points = points.with_class_ids(
                self.last_species
                    .iter()
                    .map(|&s| ClassId::from(u16::try_from(s).unwrap_or(u16::MAX))),
            );
        }
        if self.color_by == ColorBy::Speed {
            let mut vmax = 0.0f64;
            for (vx, vy) in f.vx.iter().zip(f.vy) {
                vmax = vmax.max(vx.hypot(*vy));
            }
            self.colors.clear();
            self.colors.extend(f.vx.iter().zip(f.vy).map(|(vx, vy)| {
                if vmax > 0.0 {
                    speed_color(vx.hypot(*vy) / vmax)
                } else {
                    speed_color(0.0)
                }
            }));
            points = points.with_colors(self.colors.iter().copied());
        }
        // With `ColorBy::Species` no colours are logged: the class ids pick them from the
        // annotation context.
        self.rec
            .log(DISKS_ENTITY, &points)
            .map_err(|e| err("disks", e))?;

        if let Some(h) = f.floor_height {
            let w = self.layout.width;
            self.rec
                .log(
                    FLOOR_ENTITY,
                    &LineStrips2D::new([line([[0.0, h], [w, h]])])
                        .with_colors([rgb(FLOOR_COLOR)])
                        .with_radii([Radius::new_ui_points(2.5)]),
                )
                .map_err(|e| err("floor", e))?;
        }

        for (name, value) in f.series {
            self.rec
                .log(format!("{SERIES_PREFIX}/{name}"), &Scalars::single(*value))
                .map_err(|e| err(&format!("series {name}"), e))?;
        }
        Ok(())
    }

    fn set_sim_time(&self, time: f64) {
        // Nanosecond resolution; negative times (e.g. before the end of warm-up) are allowed.
        let nanos = (time * 1e9).round();
        let nanos = if nanos.is_finite() {
            nanos.clamp(-9.0e18, 9.0e18) as i64
        } else {
            0
        };
        self.rec
            .set_time(SIM_TIME_TIMELINE, TimeCell::from_duration_nanos(nanos));
    }

    /// Logs a line of text under `log` at simulated time `time` (the `frame` timeline keeps the
    /// last frame index written from this thread). `level` is a Rerun level (`TRACE`, `DEBUG`,
    /// `INFO`, `WARN`, `ERROR`, `CRITICAL`; case-insensitive, `warning` means `WARN`).
    pub fn log_text(&mut self, time: f64, level: &str, text: &str) -> Result<(), String> {
        let level = match level.to_ascii_uppercase().as_str() {
            "WARNING" => TextLogLevel::WARN.to_owned(),
            other => other.to_owned(),
        };
        self.set_sim_time(time);
        self.rec
            .log(
                LOG_ENTITY,
                &TextLog::new(text).with_level(TextLogLevel::from(level)),
            )
            .map_err(|e| err("text log", e))
    }

    /// Series groups: `energy/kinetic` belongs to group `energy`; a name without `/` is a
    /// group of its own.
    fn send_blueprint(&mut self, series: &[(&'static str, f64)]) -> Result<(), String> {
        let mut groups: BTreeMap<&str, ()> = BTreeMap::new();
        let mut loose: Vec<&str> = Vec::new();
        for (name, _) in series {
            match name.split_once('/') {
                Some((g, _)) => {
                    groups.insert(g, ());
                }
                None => loose.push(name),
            }
        }
        let mut right: Vec<ContainerLike> = Vec::new();
        for g in groups.keys() {
            right.push(
                TimeSeriesView::new(*g)
                    .with_origin(format!("/{SERIES_PREFIX}/{g}"))
                    .into(),
            );
        }
        // A series without a group has its own view: sharing one y axis would squash the
        // smaller (e.g. centre-of-mass height beside collisions per unit time).
        for name in &loose {
            right.push(
                TimeSeriesView::new(*name)
                    .with_origin(format!("/{SERIES_PREFIX}/{name}"))
                    .into(),
            );
        }
        right.push(
            TextLogView::new("log")
                .with_origin(format!("/{LOG_ENTITY}"))
                .into(),
        );

        let disks = Spatial2DView::new(self.layout.name.clone())
            .with_origin("/")
            .with_contents([format!("/{DISKS_ENTITY}"), "/scene/**".to_owned()]);
        let root = Horizontal::new([disks.into(), Vertical::new(right).into()])
            .with_column_shares([2.0, 1.0]);
        // Side and time panels collapsed (the time panel keeps its play controls), so that the
        // views get the window; simulated time is the timeline shown.
        Blueprint::new(root)
            .with_auto_views(false)
            .with_blueprint_panel(BlueprintPanel::from_state(PanelState::Collapsed))
            .with_selection_panel(SelectionPanel::from_state(PanelState::Collapsed))
            .with_time_panel(
                TimePanel::new()
                    .with_state(PanelState::Collapsed)
                    .with_timeline(SIM_TIME_TIMELINE),
            )
            .send(
                &self.rec,
                BlueprintActivation {
                    make_active: true,
                    make_default: true,
                },
            )
            .map_err(|e| err("blueprint", e))?;
        self.blueprint_sent = true;
        Ok(())
    }

    /// Sends the blueprint if no frame was written, flushes everything to disk and closes the
    /// file, writing its footer. Dropping a `RerunRecorder` without calling this also completes
    /// the file, but silently.
    pub fn finish(mut self) -> Result<(), String> {
        if !self.blueprint_sent {
            self.send_blueprint(&[])?;
        }
        self.rec.flush_blocking().map_err(|e| err("flush", e))?;
        drop(self);
        Ok(())
    }
}

impl Drop for RerunRecorder {
    /// A recorder dropped without [`finish`](Self::finish) (an error or a panic in the run)
    /// still sends the blueprint, so that the file opens laid out; the `RecordingStream` inside
    /// then flushes and writes the footer.
    fn drop(&mut self) {
        if !self.blueprint_sent {
            let _ = self.send_blueprint(&[]);
        }
    }
}

/// One frame of `disks` as decoded from a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct DiskFrame {
    /// Value on the `frame` timeline.
    pub frame: i64,
    /// Value on the `sim_time` timeline, in simulated time units (nanosecond resolution).
    pub time: f64,
    /// Disk centres `[x, y]` in simulation coordinates (y up), as logged (f32).
    pub positions: Vec<[f32; 2]>,
    /// Radii in effect at this frame (latest logged at or before it).
    pub radii: Vec<f32>,
    /// Class ids (species) in effect at this frame (latest logged at or before it).
    pub class_ids: Vec<u16>,
    /// Colours logged with this frame as `0xRRGGBBAA` (empty when colouring by species).
    pub colors: Vec<u32>,
}

/// One `TextLog` row.
#[derive(Debug, Clone, PartialEq)]
pub struct LogLine {
    /// Simulated time of the entry (`None` if it has no `sim_time`).
    pub time: Option<f64>,
    /// Level, e.g. `INFO`, `WARN`.
    pub level: String,
    /// The text.
    pub text: String,
}

/// Row and frame counts of one entity's temporal data.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct EntityStats {
    /// Number of temporal rows.
    pub rows: usize,
    /// Number of distinct `frame` values among those rows.
    pub frames: usize,
}

/// What [`read_back`] found in a `.rrd` file.
#[derive(Debug, Clone, Default)]
pub struct RecordingContents {
    /// Application id of the recording store.
    pub application_id: Option<String>,
    /// Temporal data per entity path (written without the leading `/`, e.g. `disks`,
    /// `series/energy/kinetic`).
    pub entities: BTreeMap<String, EntityStats>,
    /// Entity paths that hold static data (e.g. `scene/walls`).
    pub static_entities: BTreeSet<String>,
    /// `disks` frame by frame, sorted by frame.
    pub disks: Vec<DiskFrame>,
    /// Floor height per frame: `(frame, height)`, sorted by frame.
    pub floor: Vec<(i64, f32)>,
    /// Series values by name (without the `series/` prefix): `(frame, value)`, sorted by frame.
    pub series: BTreeMap<String, Vec<(i64, f64)>>,
    /// Text log entries sorted by simulated time (entries without time first; ties in file order).
    pub log: Vec<LogLine>,
    /// Whether a blueprint (with its activation command) is in the file.
    pub has_blueprint: bool,
    /// Whether the file ends with a footer holding the manifest of the recording store, i.e. the
    /// stream was closed properly.
    pub has_footer: bool,
    /// Number of chunks listed in the recording's manifest (0 without footer).
    pub manifest_chunks: usize,
}

impl RecordingContents {
    /// Temporal stats of `entity` (path without leading `/`), if it has temporal data.
    pub fn entity(&self, entity: &str) -> Option<&EntityStats> {
        self.entities.get(entity)
    }
}

/// The value logged at or before frame `f` (Rerun's latest-at), or empty.
fn latest<T: Clone>(map: &BTreeMap<i64, Vec<T>>, f: i64) -> Vec<T> {
    map.range(..=f)
        .next_back()
        .map(|(_, v)| v.clone())
        .unwrap_or_default()
}

fn entity_name(chunk: &Chunk) -> String {
    chunk
        .entity_path()
        .to_string()
        .trim_start_matches('/')
        .to_owned()
}

/// Decodes a `.rrd` file written by [`RerunRecorder`] with Rerun's own decoder and returns
/// its contents: per-entity frame counts, disk positions per frame, floor heights, series, the
/// text log and whether the blueprint and the footer are present. Used by tests and by
/// `vibrobed` tooling. Fails when the file cannot be read or is not a valid RRD stream (a file
/// cut short fails too; a file merely lacking its footer decodes with `has_footer == false`).
pub fn read_back(path: &Path) -> Result<RecordingContents, String> {
    let file =
        std::fs::File::open(path).map_err(|e| format!("cannot open {}: {e}", path.display()))?;
    let reader = std::io::BufReader::new(file);
    let mut decoder = DecoderApp::decode_eager(reader)
        .map_err(|e| format!("{} is not a valid RRD file: {e}", path.display()))?;

    let frame_tl = TimelineName::from(FRAME_TIMELINE);
    let time_tl = TimelineName::from(SIM_TIME_TIMELINE);
    let positions_id = Points2D::descriptor_positions().component;
    let radii_id = Points2D::descriptor_radii().component;
    let colors_id = Points2D::descriptor_colors().component;
    let class_ids_id = Points2D::descriptor_class_ids().component;
    let strips_id = LineStrips2D::descriptor_strips().component;
    let scalars_id = Scalars::descriptor_scalars().component;
    let text_id = TextLog::descriptor_text().component;
    let level_id = TextLog::descriptor_level().component;

    let mut out = RecordingContents::default();
    let mut frames_seen: BTreeMap<String, BTreeSet<i64>> = BTreeMap::new();
    let mut frame_times: BTreeMap<i64, i64> = BTreeMap::new();
    let mut positions: BTreeMap<i64, Vec<[f32; 2]>> = BTreeMap::new();
    let mut radii: BTreeMap<i64, Vec<f32>> = BTreeMap::new();
    let mut class_ids: BTreeMap<i64, Vec<u16>> = BTreeMap::new();
    let mut colors: BTreeMap<i64, Vec<u32>> = BTreeMap::new();

    for msg in decoder.by_ref() {
        let msg = msg.map_err(|e| format!("decoding {}: {e}", path.display()))?;
        let (store_id, arrow_msg) = match msg {
            LogMsg::SetStoreInfo(info) => {
                if info.info.store_id.is_recording() {
                    out.application_id = Some(info.info.application_id().to_string());
                } else {
                    out.has_blueprint = true;
                }
                continue;
            }
            LogMsg::BlueprintActivationCommand(_) => {
                out.has_blueprint = true;
                continue;
            }
            LogMsg::ArrowMsg(store_id, arrow_msg) => (store_id, arrow_msg),
        };
        if !store_id.is_recording() {
            continue;
        }
        let chunk = Chunk::from_arrow_msg(&arrow_msg)
            .map_err(|e| format!("decoding a chunk of {}: {e}", path.display()))?;
        let entity = entity_name(&chunk);
        if chunk.is_static() {
            out.static_entities.insert(entity);
            continue;
        }
        let stats = out.entities.entry(entity.clone()).or_default();
        stats.rows += chunk.num_rows();
        let frames: Vec<i64> = chunk
            .iter_indices(&frame_tl)
            .map(|(t, _)| t.as_i64())
            .collect();
        let times: Vec<i64> = chunk
            .iter_indices(&time_tl)
            .map(|(t, _)| t.as_i64())
            .collect();
        if times.len() == frames.len() {
            for (f, t) in frames.iter().zip(&times) {
                frame_times.entry(*f).or_insert(*t);
            }
        }
        frames_seen
            .entry(entity.clone())
            .or_default()
            .extend(frames.iter().copied());

        // Per component: the frame of every row holding it, zipped with its values.
        let rows_of = |component| {
            chunk
                .iter_component_indices(frame_tl, component)
                .map(|(t, _)| t.as_i64())
                .collect::<Vec<i64>>()
        };
        if entity == DISKS_ENTITY {
            for (f, v) in rows_of(positions_id)
                .into_iter()
                .zip(chunk.iter_component::<Position2D>(positions_id))
            {
                positions.insert(f, v.iter().map(|p| [p.x(), p.y()]).collect());
            }
            for (f, v) in rows_of(radii_id)
                .into_iter()
                .zip(chunk.iter_component::<Radius>(radii_id))
            {
                radii.insert(f, v.iter().map(|r| r.0 .0).collect());
            }
            for (f, v) in rows_of(class_ids_id)
                .into_iter()
                .zip(chunk.iter_component::<ClassId>(class_ids_id))
            {
                class_ids.insert(f, v.iter().map(|c| c.0 .0).collect());
            }
            for (f, v) in rows_of(colors_id)
                .into_iter()
                .zip(chunk.iter_component::<Color>(colors_id))
            {
                colors.insert(f, v.iter().map(|c| c.to_u32()).collect());
            }
        } else if entity == FLOOR_ENTITY {
            for (f, v) in rows_of(strips_id)
                .into_iter()
                .zip(chunk.iter_component::<rerun::components::LineStrip2D>(strips_id))
            {
                if let Some(p) = v.first().and_then(|s| s.0.first()) {
                    out.floor.push((f, p.y()));
                }
            }
        } else if let Some(name) = entity.strip_prefix(&format!("{SERIES_PREFIX}/")) {
            let values = out.series.entry(name.to_owned()).or_default();
            for (f, v) in rows_of(scalars_id)
                .into_iter()
                .zip(chunk.iter_component::<Scalar>(scalars_id))
            {
                if let Some(s) = v.first() {
                    values.push((f, s.0 .0));
                }
            }
        } else if entity == LOG_ENTITY {
            let texts: Vec<String> = chunk
                .iter_component::<Text>(text_id)
                .map(|v| v.first().map(|t| t.as_str().to_owned()).unwrap_or_default())
                .collect();
            let levels: Vec<String> = chunk
                .iter_component::<TextLogLevel>(level_id)
                .map(|v| v.first().map(|l| l.as_str().to_owned()).unwrap_or_default())
                .collect();
            for (i, text) in texts.into_iter().enumerate() {
                out.log.push(LogLine {
                    time: times.get(i).map(|&ns| ns as f64 * 1e-9),
                    level: levels.get(i).cloned().unwrap_or_default(),
                    text,
                });
            }
        }
    }

    for (entity, frames) in frames_seen {
        if let Some(stats) = out.entities.get_mut(&entity) {
            stats.frames = frames.len();
        }
    }
    out.disks = positions
        .into_iter()
        .map(|(f, p)| DiskFrame {
            frame: f,
            time: frame_times.get(&f).map_or(f64::NAN, |&ns| ns as f64 * 1e-9),
            positions: p,
            radii: latest(&radii, f),
            class_ids: latest(&class_ids, f),
            colors: colors.get(&f).cloned().unwrap_or_default(),
        })
        .collect();
    out.floor.sort_by_key(|&(f, _)| f);
    out.log.sort_by(|a, b| {
        a.time
            .unwrap_or(f64::NEG_INFINITY)
            .total_cmp(&b.time.unwrap_or(f64::NEG_INFINITY))
    });
    for values in out.series.values_mut() {
        values.sort_by_key(|&(f, _)| f);
    }

    let manifests = decoder
        .rrd_manifests()
        .map_err(|e| format!("reading the footer of {}: {e}", path.display()))?;
    for m in manifests.iter().filter(|m| m.store_id.is_recording()) {
        out.has_footer = true;
        out.manifest_chunks += m.data.num_rows();
    }
    Ok(out)
}
