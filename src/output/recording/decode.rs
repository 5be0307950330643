//! Reading a recording back (what the tests compare with the simulated run): the frames of the
//! disks, the profiles, the series, the log and the layout, by Rerun's own decoder.

use super::*;
use rerun::ComponentIdentifier;

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

/// One frame of a live profile: the frame and the points `(value, height)` of its line strip.
pub type ProfileFrame = (i64, Vec<[f32; 2]>);

/// One `TextLog` row.
#[derive(Debug, Clone, PartialEq)]
pub struct LogLine {
    /// Simulated time of the entry (`None` if it has no `sim_time`).
    pub time: Option<f64>,
    /// Frame of the entry on the `frame` timeline (`None` if it has none: the viewer, showing
    /// that timeline, would not list it).
    pub frame: Option<i64>,
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
    /// Recording id of the recording store (the parts of a resumed run share it).
    pub recording_id: Option<String>,
    /// Temporal data per entity path (written without the leading `/`, e.g. `disks`,
    /// `series/energy/kinetic`).
    pub entities: BTreeMap<String, EntityStats>,
    /// Entity paths that hold static data (e.g. `scene/walls`).
    pub static_entities: BTreeSet<String>,
    /// `disks` frame by frame, sorted by frame.
    pub disks: Vec<DiskFrame>,
    /// Rough disks' radius lines per frame: `(frame, [centre, rim point] of each disk)`, sorted
    /// by frame (empty for smooth disks).
    pub orientation: Vec<(i64, Vec<[[f32; 2]; 2]>)>,
    /// Floor height per frame: `(frame, height)`, sorted by frame.
    pub floor: Vec<(i64, f32)>,
    /// Live profiles by name (`packing_fraction`, `temperature`), sorted by frame.
    pub profiles: BTreeMap<String, Vec<ProfileFrame>>,
    /// Series values by name (without the `series/` prefix): `(frame, value)`, sorted by frame.
    pub series: BTreeMap<String, Vec<(i64, f64)>>,
    /// Text log entries sorted by simulated time (entries without time first; ties in file order).
    pub log: Vec<LogLine>,
    /// Whether a blueprint (with its activation command) is in the file.
    pub has_blueprint: bool,
    /// Visual bounds `[x0, x1, y0, y1]` the blueprint gives its 2D views (in the views'
    /// coordinates: y downwards, so heights are negated), in file order.
    pub view_bounds: Vec<[f64; 4]>,
    /// Whether the file ends with a footer holding the manifest of the recording store, i.e. the
    /// stream was closed properly.
    pub has_footer: bool,
    /// Number of chunks listed in the recording's manifest (0 without footer).
    pub manifest_chunks: usize,
    /// Kind of each timeline of the recording's temporal data, as Rerun names it (`sequence`,
    /// `duration`, `timestamp`).
    pub timelines: BTreeMap<String, String>,
    /// The timeline the blueprint's time panel shows.
    pub shown_timeline: Option<String>,
    /// The clock's label per frame: `(frame, "t = …")`, sorted by frame.
    pub clock: Vec<(i64, String)>,
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

/// Reads what the tests look at in a chunk of the blueprint store: the 2D views' visual bounds
/// and the timeline of the time panel.
fn read_blueprint_chunk(chunk: &Chunk, out: &mut RecordingContents) {
    if entity_name(chunk).ends_with("/VisualBounds2D") {
        let id = VisualBounds2D::descriptor_range().component;
        for v in chunk.iter_component::<VisualBounds2DComponent>(id) {
            for b in v.iter() {
                let (x, y) = (b.0.x_range.0, b.0.y_range.0);
                out.view_bounds.push([x[0], x[1], y[0], y[1]]);
            }
        }
    }
    let id = TimePanelBlueprint::descriptor_timeline().component;
    for v in chunk.iter_component::<BlueprintTimelineName>(id) {
        if let Some(name) = v.first() {
            out.shown_timeline = Some(name.0.as_str().to_owned());
        }
    }
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
    let mut gathered = Gathered::default();
    for msg in decoder.by_ref() {
        let msg = msg.map_err(|e| format!("decoding {}: {e}", path.display()))?;
        gathered
            .message(msg)
            .map_err(|e| format!("decoding a chunk of {}: {e}", path.display()))?;
    }
    let mut out = gathered.finish();
    let manifests = decoder
        .rrd_manifests()
        .map_err(|e| format!("reading the footer of {}: {e}", path.display()))?;
    for m in manifests.iter().filter(|m| m.store_id.is_recording()) {
        out.has_footer = true;
        out.manifest_chunks += m.data.num_rows();
    }
    Ok(out)
}

/// What the decoder gathers, message by message, before it assembles [`RecordingContents`]:
/// the disks' components by frame (each logged only when it changes), and the frames and
/// times seen.
#[derive(Default)]
struct Gathered {
    out: RecordingContents,
    frames_seen: BTreeMap<String, BTreeSet<i64>>,
    frame_times: BTreeMap<i64, i64>,
    positions: BTreeMap<i64, Vec<[f32; 2]>>,
    radii: BTreeMap<i64, Vec<f32>>,
    class_ids: BTreeMap<i64, Vec<u16>>,
    colors: BTreeMap<i64, Vec<u32>>,
}

/// The index of every row of `chunk` on `timeline`.
fn indices(chunk: &Chunk, timeline: &'static str) -> Vec<i64> {
    let timeline = TimelineName::from(timeline);
    chunk
        .iter_indices(&timeline)
        .map(|(t, _)| t.as_i64())
        .collect()
}

/// The frame of every row of `chunk` that holds `component`.
fn rows_of(chunk: &Chunk, component: ComponentIdentifier) -> Vec<i64> {
    chunk
        .iter_component_indices(TimelineName::from(FRAME_TIMELINE), component)
        .map(|(t, _)| t.as_i64())
        .collect()
}

/// The first value of each row of `chunk` that holds `component`, with the row's frame.
fn firsts<C: rerun::Component + Clone>(
    chunk: &Chunk,
    component: ComponentIdentifier,
) -> Vec<(i64, C)> {
    rows_of(chunk, component)
        .into_iter()
        .zip(chunk.iter_component::<C>(component))
        .filter_map(|(f, v)| v.first().cloned().map(|c| (f, c)))
        .collect()
}

impl Gathered {
    /// Takes one message of the file: store information, a blueprint, or a chunk of data.
    fn message(&mut self, msg: LogMsg) -> Result<(), String> {
        let (store_id, arrow_msg) = match msg {
            LogMsg::SetStoreInfo(info) => {
                if info.info.store_id.is_recording() {
                    self.out.application_id = Some(info.info.application_id().to_string());
                    self.out.recording_id = Some(info.info.store_id.recording_id().to_string());
                } else {
                    self.out.has_blueprint = true;
                }
                return Ok(());
            }
            LogMsg::BlueprintActivationCommand(_) => {
                self.out.has_blueprint = true;
                return Ok(());
            }
            LogMsg::ArrowMsg(store_id, arrow_msg) => (store_id, arrow_msg),
        };
        let chunk = Chunk::from_arrow_msg(&arrow_msg).map_err(|e| e.to_string())?;
        if !store_id.is_recording() {
            read_blueprint_chunk(&chunk, &mut self.out);
        } else {
            self.data_chunk(&chunk);
        }
        Ok(())
    }

    /// Takes a chunk of the recording's data: its entity's rows, frames and times, and what
    /// the entity holds.
    fn data_chunk(&mut self, chunk: &Chunk) {
        let entity = entity_name(chunk);
        if chunk.is_static() {
            self.out.static_entities.insert(entity);
            return;
        }
        for column in chunk.timelines().values() {
            let timeline = column.timeline();
            self.out
                .timelines
                .insert(timeline.name().to_string(), timeline.typ().to_string());
        }
        self.out.entities.entry(entity.clone()).or_default().rows += chunk.num_rows();
        let (frames, times) = (
            indices(chunk, FRAME_TIMELINE),
            indices(chunk, SIM_TIME_TIMELINE),
        );
        if times.len() == frames.len() {
            for (f, t) in frames.iter().zip(&times) {
                self.frame_times.entry(*f).or_insert(*t);
            }
        }
        self.frames_seen
            .entry(entity.clone())
            .or_default()
            .extend(frames.iter().copied());
        self.entity_values(&entity, chunk, &frames, &times);
    }

    /// What `entity`'s chunk holds, by entity: the disks, the clock, the floor, the profiles, the
    /// series, the log.
    fn entity_values(&mut self, entity: &str, chunk: &Chunk, frames: &[i64], times: &[i64]) {
        let labels = Points2D::descriptor_labels().component;
        let strips = LineStrips2D::descriptor_strips().component;
        let out = &mut self.out;
        if entity == DISKS_ENTITY {
            self.disks(chunk);
        } else if entity == ORIENTATION_ENTITY {
            for (f, v) in rows_of(chunk, strips)
                .into_iter()
                .zip(chunk.iter_component::<LineStrip2D>(strips))
            {
                let lines = v.iter().map(|s| match s.0.as_slice() {
                    [a, b] => [[a.x(), a.y()], [b.x(), b.y()]],
                    _ => [[f32::NAN; 2]; 2], // Not a radius line: no test would pass it.
                });
                out.orientation.push((f, lines.collect()));
            }
        } else if entity == CLOCK_ENTITY {
            for (f, t) in firsts::<Text>(chunk, labels) {
                out.clock.push((f, t.as_str().to_owned()));
            }
        } else if entity == FLOOR_ENTITY {
            for (f, s) in firsts::<LineStrip2D>(chunk, strips) {
                if let Some(p) = s.0.first() {
                    out.floor.push((f, p.y()));
                }
            }
        } else if entity == PACKING_PROFILE_ENTITY || entity == TEMPERATURE_PROFILE_ENTITY {
            let name = entity.trim_start_matches("profiles/").to_owned();
            let values = out.profiles.entry(name).or_default();
            for (f, s) in firsts::<LineStrip2D>(chunk, strips) {
                values.push((f, s.0.iter().map(|p| [p.x(), p.y()]).collect()));
            }
        } else if let Some(name) = entity.strip_prefix(&format!("{SERIES_PREFIX}/")) {
            let values = out.series.entry(name.to_owned()).or_default();
            let scalars = Scalars::descriptor_scalars().component;
            for (f, s) in firsts::<Scalar>(chunk, scalars) {
                values.push((f, s.0 .0));
            }
        } else if entity == LOG_ENTITY {
            read_log_chunk(chunk, frames, times, out);
        }
    }

    /// The disks' components, by frame: positions in every frame, radii, classes and colours
    /// when they change.
    fn disks(&mut self, chunk: &Chunk) {
        let id = Points2D::descriptor_positions().component;
        for (f, v) in rows_of(chunk, id)
            .into_iter()
            .zip(chunk.iter_component::<Position2D>(id))
        {
            self.positions
                .insert(f, v.iter().map(|p| [p.x(), p.y()]).collect());
        }
        let id = Points2D::descriptor_radii().component;
        for (f, v) in rows_of(chunk, id)
            .into_iter()
            .zip(chunk.iter_component::<Radius>(id))
        {
            self.radii.insert(f, v.iter().map(|r| r.0 .0).collect());
        }
        let id = Points2D::descriptor_class_ids().component;
        for (f, v) in rows_of(chunk, id)
            .into_iter()
            .zip(chunk.iter_component::<ClassId>(id))
        {
            self.class_ids.insert(f, v.iter().map(|c| c.0 .0).collect());
        }
        let id = Points2D::descriptor_colors().component;
        for (f, v) in rows_of(chunk, id)
            .into_iter()
            .zip(chunk.iter_component::<Color>(id))
        {
            self.colors
                .insert(f, v.iter().map(|c| c.to_u32()).collect());
        }
    }

    /// The contents, every list in frame (or time) order.
    fn finish(self) -> RecordingContents {
        let mut out = self.out;
        for (entity, frames) in self.frames_seen {
            if let Some(stats) = out.entities.get_mut(&entity) {
                stats.frames = frames.len();
            }
        }
        let (frame_times, radii, class_ids, colors) =
            (self.frame_times, self.radii, self.class_ids, self.colors);
        out.disks = self
            .positions
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
        out.orientation.sort_by_key(|(f, _)| *f);
        out.clock.sort_by_key(|(f, _)| *f);
        out.log.sort_by(|a, b| {
            a.time
                .unwrap_or(f64::NEG_INFINITY)
                .total_cmp(&b.time.unwrap_or(f64::NEG_INFINITY))
        });
        for values in out.series.values_mut() {
            values.sort_by_key(|&(f, _)| f);
        }
        for values in out.profiles.values_mut() {
            values.sort_by_key(|(f, _)| *f);
        }
        out
    }
}

/// The text log's lines in `chunk` (rows at `frames` and `times`), into `out`.
fn read_log_chunk(chunk: &Chunk, frames: &[i64], times: &[i64], out: &mut RecordingContents) {
    let texts: Vec<String> = chunk
        .iter_component::<Text>(TextLog::descriptor_text().component)
        .map(|v| v.first().map(|t| t.as_str().to_owned()).unwrap_or_default())
        .collect();
    let levels: Vec<String> = chunk
        .iter_component::<TextLogLevel>(TextLog::descriptor_level().component)
        .map(|v| v.first().map(|l| l.as_str().to_owned()).unwrap_or_default())
        .collect();
    for (i, text) in texts.into_iter().enumerate() {
        out.log.push(LogLine {
            time: times.get(i).map(|&ns| ns as f64 * 1e-9),
            frame: frames.get(i).copied(),
            level: levels.get(i).cloned().unwrap_or_default(),
            text,
        });
    }
}
