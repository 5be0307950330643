//! The writer thread: frames gathered in batches and logged column-wise, the static scene, the
//! walls of an open top, the text log.

use super::*;

/// Values of one entity gathered over a batch, with their times.
#[derive(Debug)]
pub(super) struct Column<T> {
    pub(super) frames: Vec<i64>,
    pub(super) nanos: Vec<i64>,
    pub(super) values: Vec<T>,
}

impl<T> Default for Column<T> {
    fn default() -> Self {
        Self {
            frames: Vec::new(),
            nanos: Vec::new(),
            values: Vec::new(),
        }
    }
}

impl<T> Column<T> {
    pub(super) fn push(&mut self, frame: i64, nanos: i64, value: T) {
        self.frames.push(frame);
        self.nanos.push(nanos);
        self.values.push(value);
    }

    /// The time columns, leaving the column empty (its buffers kept).
    pub(super) fn take_times(&mut self) -> [TimeColumn; 2] {
        [
            TimeColumn::new_sequence(FRAME_TIMELINE, self.frames.drain(..)),
            TimeColumn::new_duration_nanos(SIM_TIME_TIMELINE, self.nanos.drain(..)),
        ]
    }
}

/// Frames gathered by the writer thread, logged together.
#[derive(Debug, Default)]
pub(super) struct Batch {
    /// Disk positions of all frames, one after the other; `values` holds each frame's count.
    pub(super) disks: Column<usize>,
    pub(super) positions: Vec<[f32; 2]>,
    pub(super) colors: Vec<Color>,
    /// Rough disks' radius lines of all frames, one frame after the other; `values` holds each
    /// frame's count.
    pub(super) orientation: Column<usize>,
    pub(super) radius_lines: Vec<[[f32; 2]; 2]>,
    pub(super) floor: Column<LineStrip2D>,
    pub(super) packing: Column<LineStrip2D>,
    pub(super) temperature: Column<LineStrip2D>,
    pub(super) series: BTreeMap<&'static str, Column<f64>>,
    /// The clock's label of each frame.
    pub(super) clock: Column<String>,
    /// The live fields of each frame: the heat map (frame, time, RGB bytes, one pixel per cell)
    /// and the arrows of all frames (`values`: each frame's count; origins, vectors).
    pub(super) field_images: Vec<(i64, f64, Vec<u8>)>,
    pub(super) field_arrows: Column<usize>,
    pub(super) arrow_origins: Vec<[f32; 2]>,
    pub(super) arrow_vectors: Vec<[f32; 2]>,
}

/// Packing fraction drawn full red in the live fields' heat map.
const FIELDS_PHI_RED: f64 = 0.8;
/// Mean speed drawn as an arrow one cell wide, as a fraction of the speed scale.
const FIELDS_ARROW_SPEED: f64 = 0.3;

impl Batch {
    /// The live fields of one frame (at `time`): a pixel per cell coloured by the packing
    /// fraction, an arrow per cell that holds disks.
    fn gather_fields(&mut self, f: &Fields, (index, time): (i64, f64), speed_scale: f64) {
        let g = *f.grid();
        let arrow = g.cell()[0] / (FIELDS_ARROW_SPEED * speed_scale);
        let mut arrows = 0;
        let mut pixels = Vec::with_capacity(3 * g.len());
        for j in 0..g.ny {
            for i in 0..g.nx {
                let [x, y] = g.centre(i, j);
                let centre = [x as f32, y as f32];
                let phi = f.packing_fraction(i, j);
                pixels.extend_from_slice(&speed_color(phi / FIELDS_PHI_RED).to_array()[..3]);
                if let (Some([ux, uy]), true) = (f.mean_velocity(i, j), phi > 0.01) {
                    self.arrow_origins.push(centre);
                    self.arrow_vectors
                        .push([(ux * arrow) as f32, (uy * arrow) as f32]);
                    arrows += 1;
                }
            }
        }
        self.field_images.push((index, time, pixels));
        self.field_arrows.push(index, nanos(time), arrows);
    }
}

/// The writer thread's side: the stream and what has been logged so far.
pub(super) struct Writer {
    pub(super) rec: RecordingStream,
    /// The file the stream writes (its first error stops the writer).
    pub(super) file: RrdFile,
    pub(super) layout: SceneLayout,
    pub(super) color_by: ColorBy,
    /// Whether the disks are rough (the first frame carries spins): their orientations are
    /// drawn.
    pub(super) rough: bool,
    /// Height the walls are currently drawn to (open top only).
    pub(super) wall_height: Option<f64>,
    /// Radii last logged (re-logged only on change).
    pub(super) last_radii: Vec<f64>,
    /// Species last logged (re-logged only on change).
    pub(super) last_species: Vec<u32>,
    pub(super) blueprint_sent: bool,
    /// The legend waits for the second frame, which tells the time between frames; it holds
    /// whether the scene has profiles.
    pub(super) legend_pending: Option<bool>,
    /// Index of the last frame logged.
    pub(super) last_frame: Option<i64>,
    /// Simulated time of the last frame logged.
    pub(super) last_time: Option<f64>,
    /// Simulated time between the first two frames.
    pub(super) step: Option<f64>,
    pub(super) batch: Batch,
    /// The live fields' grid `[nx, ny]` (the heat map's resolution).
    pub(super) field_cells: [u32; 2],
}

impl Writer {
    /// Logs the queued messages until the queue closes or the file fails, then completes the
    /// file (or removes it after a failure).
    pub(super) fn run(
        mut self,
        rx: Receiver<Msg>,
        recycle: Sender<Box<FrameBuf>>,
    ) -> Result<(), String> {
        let mut result = Ok(());
        for msg in rx {
            let step = match msg {
                Msg::Frame(buf) => {
                    let r = self.frame(&buf);
                    let _ = recycle.send(buf);
                    r
                }
                Msg::Text { time, level, text } => self.text(time, &level, &text),
            };
            if let Err(e) = step.and_then(|()| self.file.error().map_or(Ok(()), Err)) {
                result = Err(e);
                break; // Dropping `rx` tells the recorder.
            }
        }
        let completed = self.complete();
        result.and(completed)
    }

    /// Logs what is gathered, closes the stream and completes the file: footer, sync, rename
    /// into place; or removes it after a failure. A failure of the file comes first: it says
    /// what the operating system refused.
    pub(super) fn complete(mut self) -> Result<(), String> {
        let closed = self.close();
        let Writer { rec, file, .. } = self;
        drop(rec); // Joins Rerun's threads: every message has reached `file`.
        match (file.finish(), closed) {
            (Err(e), _) | (Ok(()), Err(e)) => Err(e),
            (Ok(()), Ok(())) => Ok(()),
        }
    }

    fn close(&mut self) -> Result<(), String> {
        let flushed = self.flush_batch();
        if !self.blueprint_sent {
            self.send_blueprint(&[], None, None, false)?;
        }
        if let Some(has_profiles) = self.legend_pending.take() {
            self.log_legend(has_profiles, None)?;
        }
        flushed?;
        self.rec
            .flush_with_timeout(FLUSH_TIMEOUT)
            .map_err(|e| err("flush", e))
    }

    pub(super) fn log_static_scene(&mut self) -> Result<(), String> {
        let flip = Transform3D::from_scale((1.0, -1.0, 1.0));
        for entity in [DISKS_ENTITY, "scene"] {
            self.rec
                .log_static(entity, &flip)
                .map_err(|e| err("transform", e))?;
        }

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

        let w = self.layout.width;
        if let (Some(top), false) = (self.layout.top, self.layout.y_periodic) {
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

    /// Logs (static) the two walls from y = 0 up to `height`, or the periodic edges.
    pub(super) fn log_walls(&mut self, height: f64) -> Result<(), String> {
        self.wall_height = Some(height);
        let w = self.layout.width;
        let (entity, color, width) = if self.layout.x_periodic {
            (PERIODIC_EDGES_ENTITY, EDGE_COLOR, 0.75)
        } else {
            (WALLS_ENTITY, WALL_COLOR, 1.5)
        };
        self.rec
            .log_static(
                entity,
                &LineStrips2D::new([
                    line([[0.0, 0.0], [0.0, height]]),
                    line([[w, 0.0], [w, height]]),
                ])
                .with_colors([rgb(color)])
                .with_radii([Radius::new_ui_points(width)]),
            )
            .map_err(|e| err("walls", e))
    }

    pub(super) fn set_time(&self, frame: Option<i64>, time: f64) {
        if let Some(f) = frame {
            self.rec.set_time_sequence(FRAME_TIMELINE, f);
        }
        self.rec.set_time(
            SIM_TIME_TIMELINE,
            TimeCell::from_duration_nanos(nanos(time)),
        );
    }

    /// The frame a text at simulated time `time` belongs to on the `frame` timeline (the one
    /// shown): the last frame logged, or the next one when `time` is already its time (frames
    /// are `step` apart); frame 0 before any frame, so that the text shows on that timeline.
    pub(super) fn frame_at(&self, time: f64) -> i64 {
        match (self.last_frame, self.last_time, self.step) {
            (Some(k), Some(t), Some(dt)) if dt > 0.0 => {
                k + ((time - t) / dt + 1e-9).floor().clamp(0.0, 1.0) as i64
            }
            (Some(k), ..) => k,
            (None, ..) => 0,
        }
    }

    pub(super) fn text(&mut self, time: f64, level: &str, text: &str) -> Result<(), String> {
        self.set_time(Some(self.frame_at(time)), time);
        self.rec
            .log(
                LOG_ENTITY,
                &TextLog::new(text).with_level(TextLogLevel::from(level.to_owned())),
            )
            .map_err(|e| err("text log", e))
    }

    pub(super) fn frame(&mut self, f: &FrameBuf) -> Result<(), String> {
        let index = i64::try_from(f.index).unwrap_or(i64::MAX);
        if !self.blueprint_sent {
            self.rough = !f.spins.is_empty();
            if self.rough {
                self.log_orientation_style(f)?;
            }
            if let Some(fields) = &f.fields {
                self.log_fields_style(fields)?;
            }
            let view_top = self.view_top(f);
            self.send_blueprint(
                &f.series,
                f.profile.as_ref(),
                Some(view_top),
                f.fields.is_some(),
            )?;
        }
        self.last_frame = Some(index);
        let step = self.last_time.map(|t0| f.time - t0);
        self.last_time = Some(f.time);
        self.step = self.step.or(step);
        if let (Some(has_profiles), Some(_)) = (self.legend_pending, step) {
            self.legend_pending = None;
            self.log_legend(has_profiles, step)?;
        }
        if self.layout.top.is_none() {
            self.grow_walls(f)?;
        }
        self.log_sizes_if_changed(f, index)?;
        self.gather(f, index, step);
        let b = &self.batch;
        if b.disks.values.len() >= BATCH || b.positions.len() >= BATCH_POINTS {
            self.flush_batch()?;
        }
        Ok(())
    }

    /// The live fields' heat maps gathered, one image per frame (an image is not logged by
    /// columns).
    fn flush_field_images(&mut self) -> Result<(), String> {
        let images = std::mem::take(&mut self.batch.field_images);
        for (index, time, pixels) in images {
            self.set_time(Some(index), time);
            let [nx, ny] = self.field_cells;
            self.rec
                .log(FIELDS_PACKING_ENTITY, &Image::from_rgb24(pixels, [nx, ny]))
                .map_err(|e| err("fields", e))?;
        }
        Ok(())
    }

    /// The live fields' static part: y up (as the bed); the heat map's pixels stretched to the
    /// cells (pixel (i, j) over cell (i, j)); arrows dark (Rerun draws images under lines and arrows).
    fn log_fields_style(&mut self, f: &Fields) -> Result<(), String> {
        let g = *f.grid();
        let [dx, dy] = g.cell();
        self.field_cells = [g.nx as u32, g.ny as u32];
        self.rec
            .log_static(FIELDS_ENTITY, &Transform3D::from_scale((1.0, -1.0, 1.0)))
            .map_err(|e| err("fields", e))?;
        self.rec
            .log_static(
                FIELDS_PACKING_ENTITY,
                &Transform3D::from_translation_scale(
                    (0.0, g.bottom as f32, 0.0),
                    (dx as f32, dy as f32, 1.0),
                ),
            )
            .map_err(|e| err("fields", e))?;
        self.rec
            .log_static(
                FIELDS_VELOCITY_ENTITY,
                &Arrows2D::update_fields()
                    .with_colors([Color::from_rgb(20, 20, 20)])
                    .with_radii([Radius::new_ui_points(1.0)]),
            )
            .map_err(|e| err("fields", e))
    }

    /// The radius lines' look, static: dark, a fixed fraction of the smallest disk's radius
    /// wide (in scene units, so that they scale with the disks), drawn over the disks (Rerun
    /// draws 2D lines under points by default).
    fn log_orientation_style(&self, f: &FrameBuf) -> Result<(), String> {
        let smallest = f.radius.iter().copied().fold(f64::INFINITY, f64::min);
        let half_width = if smallest.is_finite() {
            ORIENTATION_HALF_WIDTH * smallest
        } else {
            ORIENTATION_HALF_WIDTH
        };
        self.rec
            .log_static(
                ORIENTATION_ENTITY,
                &LineStrips2D::update_fields()
                    .with_colors([rgb(ORIENTATION_COLOR)])
                    .with_radii([Radius::new_scene_units(half_width as f32)])
                    .with_draw_order(DrawOrder::DEFAULT_POINTS2D.0 .0 + 1.0),
            )
            .map_err(|e| err("orientation", e))
    }

    /// Open top: the walls grow when something rises above 80 % of them.
    fn grow_walls(&mut self, f: &FrameBuf) -> Result<(), String> {
        let highest =
            f.y.iter()
                .zip(&f.radius)
                .map(|(y, r)| y + r)
                .fold(f.floor_height.unwrap_or(0.0), f64::max);
        let needed = if highest > 0.0 {
            highest * 1.25
        } else {
            self.layout.width
        };
        if self.wall_height.is_none_or(|h| highest > 0.8 * h) {
            self.log_walls(needed)?;
        }
        Ok(())
    }

    /// Radii and class ids, logged at frame `index`: with the first frame and whenever they
    /// change.
    fn log_sizes_if_changed(&mut self, f: &FrameBuf, index: i64) -> Result<(), String> {
        let n = f.x.len();
        let species_changed = if f.species.is_empty() {
            self.last_species.len() != n || self.last_species.iter().any(|&s| s != 0)
        } else {
            self.last_species != f.species
        };
        if self.last_radii != f.radius || species_changed {
            self.set_time(Some(index), f.time);
            let class_ids: Vec<ClassId> = if f.species.is_empty() {
                vec![ClassId::from(0u16); n]
            } else {
                f.species
                    .iter()
                    .map(|&s| ClassId::from(u16::try_from(s).unwrap_or(u16::MAX)))
                    .collect()
            };
            self.rec
                .log(
                    DISKS_ENTITY,
                    &Points2D::update_fields()
                        .with_radii(f.radius.iter().map(|&r| Radius::new_scene_units(r as f32)))
                        .with_class_ids(class_ids),
                )
                .map_err(|e| err("radii", e))?;
            self.last_radii.clone_from(&f.radius);
            self.last_species = if f.species.is_empty() {
                vec![0; n]
            } else {
                f.species.clone()
            };
        }
        Ok(())
    }

    /// Frame `f` (number `index`, `step` after the frame before) into the batch: the clock, the
    /// disks' positions and colours, rough disks' radius lines, the floor, the profiles, the
    /// series.
    fn gather(&mut self, f: &FrameBuf, index: i64, step: Option<f64>) {
        let (n, t) = (f.x.len(), nanos(f.time));
        let b = &mut self.batch;
        b.clock.push(index, t, clock_label(f.time, step));
        b.disks.push(index, t, n);
        b.positions
            .extend(f.x.iter().zip(&f.y).map(|(&x, &y)| [x as f32, y as f32]));
        let (speeds, spins) = (self.layout.speed_scale, self.layout.spin_scale);
        match self.color_by {
            ColorBy::Speed => b.colors.extend(
                f.vx.iter()
                    .zip(&f.vy)
                    .map(|(vx, vy)| speed_color(vx.hypot(*vy) / speeds)),
            ),
            ColorBy::Spin => b.colors.extend(
                f.spins
                    .iter()
                    .zip(&f.radius)
                    .map(|(&(_, w), a)| spin_color(w * a / spins)),
            ),
            ColorBy::Species => {}
        }
        if !f.spins.is_empty() {
            b.orientation.push(index, t, n);
            b.radius_lines.extend(
                f.spins
                    .iter()
                    .zip(f.x.iter().zip(&f.y).zip(&f.radius))
                    .map(|(&(angle, _), ((&x, &y), &a))| orientation_line(x, y, a, angle)),
            );
        }
        if let Some(h) = f.floor_height {
            let strip =
                LineStrip2D::from_iter([[0.0, h as f32], [self.layout.width as f32, h as f32]]);
            b.floor.push(index, t, strip);
        }
        if let Some(p) = &f.profile {
            let phi = p
                .height
                .iter()
                .zip(&p.packing_fraction)
                .map(|(&h, &v)| [v as f32, h as f32]);
            b.packing.push(index, t, LineStrip2D::from_iter(phi));
            let temp = p
                .height
                .iter()
                .zip(p.temperature_x.iter().zip(&p.temperature_y))
                .zip(&p.density)
                .filter(|(_, &d)| d > 0.0)
                .map(|((&h, (&tx, &ty)), _)| [(0.5 * (tx + ty)) as f32, h as f32]);
            b.temperature.push(index, t, LineStrip2D::from_iter(temp));
        }
        for &(name, value) in &f.series {
            b.series.entry(name).or_default().push(index, t, value);
        }
        if let Some(fields) = &f.fields {
            b.gather_fields(fields, (index, f.time), self.layout.speed_scale);
        }
    }

    /// Logs the gathered frames column-wise: one chunk per entity.
    pub(super) fn flush_batch(&mut self) -> Result<(), String> {
        let b = &mut self.batch;
        if b.disks.values.is_empty() {
            return Ok(());
        }
        let lengths: Vec<usize> = b.disks.values.drain(..).collect();
        let mut points = Points2D::new(b.positions.drain(..));
        if !b.colors.is_empty() {
            points = points.with_colors(b.colors.drain(..));
        }
        let columns = points.columns(lengths).map_err(|e| err("disks", e))?;
        self.rec
            .send_columns(DISKS_ENTITY, b.disks.take_times(), columns)
            .map_err(|e| err("disks", e))?;
        if !b.orientation.values.is_empty() {
            let lengths: Vec<usize> = b.orientation.values.drain(..).collect();
            let columns = LineStrips2D::new(b.radius_lines.drain(..))
                .columns(lengths)
                .map_err(|e| err("orientation", e))?;
            self.rec
                .send_columns(ORIENTATION_ENTITY, b.orientation.take_times(), columns)
                .map_err(|e| err("orientation", e))?;
        }

        for (entity, column, color) in [
            (FLOOR_ENTITY, &mut b.floor, FLOOR_COLOR),
            (PACKING_PROFILE_ENTITY, &mut b.packing, PACKING_COLOR),
            (
                TEMPERATURE_PROFILE_ENTITY,
                &mut b.temperature,
                TEMPERATURE_COLOR,
            ),
        ] {
            if column.values.is_empty() {
                continue;
            }
            let k = column.values.len();
            let strips = LineStrips2D::new(column.values.drain(..))
                .with_colors(std::iter::repeat_n(rgb(color), k))
                .with_radii(std::iter::repeat_n(Radius::new_ui_points(2.0), k));
            let columns = strips
                .columns(std::iter::repeat_n(1, k))
                .map_err(|e| err(entity, e))?;
            self.rec
                .send_columns(entity, column.take_times(), columns)
                .map_err(|e| err(entity, e))?;
        }
        if !b.field_arrows.values.is_empty() {
            let lengths: Vec<usize> = b.field_arrows.values.drain(..).collect();
            let columns = Arrows2D::from_vectors(b.arrow_vectors.drain(..))
                .with_origins(b.arrow_origins.drain(..))
                .columns(lengths)
                .map_err(|e| err("fields", e))?;
            self.rec
                .send_columns(FIELDS_VELOCITY_ENTITY, b.field_arrows.take_times(), columns)
                .map_err(|e| err("fields", e))?;
        }
        self.flush_field_images()?;
        let b = &mut self.batch;
        if !b.clock.values.is_empty() {
            let labels = Points2D::update_fields().with_labels(b.clock.values.drain(..));
            let columns = labels
                .columns_of_unit_batches()
                .map_err(|e| err("clock", e))?;
            self.rec
                .send_columns(CLOCK_ENTITY, b.clock.take_times(), columns)
                .map_err(|e| err("clock", e))?;
        }
        for (name, column) in &mut b.series {
            if column.values.is_empty() {
                continue;
            }
            let columns = Scalars::new(column.values.drain(..))
                .columns_of_unit_batches()
                .map_err(|e| err(name, e))?;
            self.rec
                .send_columns(
                    format!("{SERIES_PREFIX}/{name}"),
                    column.take_times(),
                    columns,
                )
                .map_err(|e| err(&format!("series {name}"), e))?;
        }
        Ok(())
    }
}
