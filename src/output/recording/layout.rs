//! The viewer's layout: the blueprint sent with the first frame, the views' bounds, the
//! profiles' axes, the speed scale, the clock and the legend.

use super::*;

impl Writer {
    /// Top of the bed view: the lid (or periodic height), else the top of the profiles, else
    /// three times the highest disk top of the first frame.
    pub(super) fn view_top(&self, f: &FrameBuf) -> f64 {
        if let Some(top) = self.layout.top {
            return top;
        }
        if let Some((_, top)) = f.profile.as_ref().and_then(profile_range) {
            return top;
        }
        let highest =
            f.y.iter()
                .zip(&f.radius)
                .map(|(y, r)| y + r)
                .fold(f.floor_height.unwrap_or(0.0), f64::max);
        if highest > 0.0 {
            3.0 * highest
        } else {
            self.layout.width
        }
    }

    /// Logs the static parts of one profile view: its y-up transform stretching values of
    /// `0..x_max` to the view's width, the axes with ticks and the titles. Returns the view's
    /// bounds (in the root's coordinates: y flipped).
    pub(super) fn log_profile_axes(
        &self,
        entity: &str,
        title: &str,
        x_max: f64,
        (bottom, top): (f64, f64),
    ) -> Result<[f64; 4], String> {
        let span = top - bottom;
        let kx = PROFILE_ASPECT * span / x_max;
        self.rec
            .log_static(entity, &Transform3D::from_scale((kx as f32, -1.0, 1.0)))
            .map_err(|e| err("profile transform", e))?;
        let tick = 0.015 * span;
        let mut strips = vec![
            vec![[0.0, bottom as f32], [x_max as f32, bottom as f32]],
            vec![[0.0, bottom as f32], [0.0, top as f32]],
        ];
        let mut labels: Vec<(f64, f64, String)> = Vec::new();
        let x_step = nice_ceiling(x_max / 5.0);
        let mut x = 0.0;
        while x <= x_max * (1.0 + 1e-9) {
            strips.push(vec![
                [x as f32, bottom as f32],
                [x as f32, (bottom - tick) as f32],
            ]);
            labels.push((x, bottom - 3.0 * tick, tick_label(x)));
            x += x_step;
        }
        let h_step = nice_ceiling(span / 5.0);
        let mut h = (bottom / h_step).ceil() * h_step;
        while h <= top + 1e-9 * span {
            let x_tick = tick / kx;
            strips.push(vec![[0.0, h as f32], [(-x_tick) as f32, h as f32]]);
            labels.push((-4.0 * x_tick, h, tick_label(h)));
            h += h_step;
        }
        labels.push((0.5 * x_max, bottom - 7.0 * tick, title.to_owned()));
        labels.push((0.0, top + 6.0 * tick, "height".to_owned()));
        self.rec
            .log_static(
                format!("{entity}/axes"),
                &LineStrips2D::new(strips)
                    .with_colors([rgb(AXIS_COLOR)])
                    .with_radii([Radius::new_ui_points(1.0)]),
            )
            .map_err(|e| err("profile axes", e))?;
        self.rec
            .log_static(
                format!("{entity}/axes/labels"),
                &Points2D::new(labels.iter().map(|(x, y, _)| [*x as f32, *y as f32]))
                    .with_labels(labels.iter().map(|(_, _, l)| l.as_str()))
                    .with_radii([Radius::new_ui_points(0.0)])
                    .with_colors([rgb(AXIS_COLOR)])
                    .with_show_labels(true),
            )
            .map_err(|e| err("profile labels", e))?;
        let margin = 0.15 * span;
        Ok([
            -margin,
            x_max * kx + 0.3 * margin,
            -(top + margin),
            -(bottom - 1.5 * margin),
        ])
    }

    /// Logs the colour scale in the sky of the bed view, near its top right corner below
    /// `view_top`: a bar of 20 coloured segments, and labels under it: from 0 to the scale for
    /// speeds, from minus to plus the scale for spins (the same colours, centred on zero).
    pub(super) fn log_colour_scale(&self, view_top: f64, bottom: f64) -> Result<(), String> {
        let w = self.layout.width;
        let span = view_top - bottom;
        let length = (0.2 * w).min(1.5 * span);
        let (x0, y) = (w - length - 0.01 * w, view_top - 0.1 * span);
        let thickness = 0.025 * span;
        let scale = if self.color_by == ColorBy::Spin {
            self.layout.spin_scale
        } else {
            self.layout.speed_scale
        };
        let segments = 20;
        let strips: Vec<[[f32; 2]; 2]> = (0..segments)
            .map(|k| {
                let a = x0 + length * k as f64 / segments as f64;
                let b = x0 + length * (k + 1) as f64 / segments as f64;
                line([[a, y], [b, y]])
            })
            .collect();
        let colors: Vec<Color> = (0..segments)
            .map(|k| speed_color((k as f64 + 0.5) / segments as f64))
            .collect();
        self.rec
            .log_static(
                SPEED_SCALE_ENTITY,
                &LineStrips2D::new(strips)
                    .with_colors(colors)
                    .with_radii([Radius::new_scene_units(thickness as f32)]),
            )
            .map_err(|e| err("colour scale", e))?;
        let (low, middle, name) = if self.color_by == ColorBy::Spin {
            (
                format!("≤ −{}", tick_label(scale)),
                "0".to_owned(),
                "spin ω a",
            )
        } else {
            ("0".to_owned(), tick_label(0.5 * scale), "speed |v|")
        };
        let labels = [
            (x0, low),
            (x0 + 0.5 * length, middle),
            (x0 + length, format!("≥ {}", tick_label(scale))),
            (x0 - 0.2 * length, name.to_owned()),
        ];
        self.rec
            .log_static(
                format!("{SPEED_SCALE_ENTITY}/labels"),
                &Points2D::new(labels.iter().enumerate().map(|(i, (x, _))| {
                    let y = if i < 3 { y - 3.5 * thickness } else { y };
                    [*x as f32, y as f32]
                }))
                .with_labels(labels.iter().map(|(_, l)| l.as_str()))
                .with_radii([Radius::new_ui_points(0.0)])
                .with_colors([rgb(AXIS_COLOR)])
                .with_show_labels(true),
            )
            .map_err(|e| err("colour scale", e))
    }

    /// Logs (static) where the clock is written: at the top left of the bed view, below
    /// `view_top`; its label comes with each frame.
    pub(super) fn log_clock(&self, view_top: f64, bottom: f64) -> Result<(), String> {
        let (w, span) = (self.layout.width, view_top - bottom);
        let at = [(0.06 * w) as f32, (view_top - 0.06 * span) as f32];
        self.rec
            .log_static(
                CLOCK_ENTITY,
                &Points2D::new([at])
                    .with_radii([Radius::new_ui_points(0.0)])
                    .with_colors([rgb(CLOCK_COLOR)])
                    .with_show_labels(true),
            )
            .map_err(|e| err("clock", e))
    }

    /// The legend: what the colours and the views show.
    /// `step` is the simulated time between frames (`None` with a single frame).
    pub(super) fn log_legend(&self, has_profiles: bool, step: Option<f64>) -> Result<(), String> {
        let mut text = String::new();
        match self.color_by {
            ColorBy::Speed => text.push_str(&format!(
                "**Disks**: speed |v| on one scale for the whole run, blue at rest → grey at \
                 {} → red at {} and above (bar at the top right; `output.speed_scale`).\n\n",
                tick_label(0.5 * self.layout.speed_scale),
                tick_label(self.layout.speed_scale)
            )),
            ColorBy::Species => text.push_str(
                "**Disks coloured by species** (radius class; hover a disk for its class).\n\n",
            ),
            ColorBy::Spin => text.push_str(&format!(
                "**Disks coloured by spin**: the rim speed ω a on one scale for the whole run, \
                 blue turning clockwise at {s} and faster → grey not turning → red turning \
                 anticlockwise at {s} and faster (bar at the top right; `output.spin_scale`).\n\n",
                s = tick_label(self.layout.spin_scale)
            )),
        }
        if self.rough {
            text.push_str(
                "**Orientation**: the dark line in each disk is a radius fixed in the disk; it \
                 turns with the disk's spin.\n\n",
            );
        }
        text.push_str(
            "**Follow a disk**: click it; instance *i* is disk *i* in every frame (and line *i* \
             of a `--trajectory` frame).\n\n",
        );
        if has_profiles {
            text.push_str(
                "**Profiles** of the current frame in the summary's height bins: packing \
                 fraction φ (each disk's area split over the bins it covers) and granular \
                 temperature T = (Tx + Ty)/2 about each bin's mean velocity.\n\n",
            );
        }
        let spacing = step.map_or(String::new(), |dt| {
            format!(
                ", {} time units apart",
                clock_label(dt, Some(dt)).trim_start_matches("t = ")
            )
        });
        text.push_str(&format!(
            "**Time**: the time panel and the plots count frames (timeline `frame`{spacing}); \
             the simulated time of the frame shown is written at the top left of the bed \
             (t = …). Timeline `sim_time` holds the same times, written by the viewer as \
             durations (one time unit as one second).\n\n"
        ));
        text.push_str("Floor: orange. Walls: grey; periodic edges: dark grey.");
        self.rec
            .log_static(
                LEGEND_ENTITY,
                &TextDocument::new(text).with_media_type(MediaType::markdown()),
            )
            .map_err(|e| err("legend", e))
    }

    /// Sends the blueprint (see the module documentation): `series` names the time series,
    /// `profile` (the first frame's) gives the height range of the profile views, `view_top`
    /// the top of the bed view.
    pub(super) fn send_blueprint(
        &mut self,
        series: &[(&'static str, f64)],
        profile: Option<&ProfileTable>,
        view_top: Option<f64>,
        fields: bool,
    ) -> Result<(), String> {
        self.blueprint_sent = true;
        let mut bounds: Vec<(String, [f64; 4])> = Vec::new();
        let range = profile.and_then(profile_range);
        let mut bed = self.bed_view(view_top, range, &mut bounds)?;
        if fields {
            // Beside the bed, over the same region: the live fields.
            let (view, path) = view_with_path(
                Spatial2DView::new("fields: packing fraction, mean velocity")
                    .with_origin("/")
                    .with_contents([format!("/{FIELDS_ENTITY}/**")]),
            );
            if let Some(fitted) = bounds.last().map(|b| b.1) {
                bounds.push((path, fitted));
            }
            bed = Horizontal::new([bed, view]).into();
        }
        // Below: profiles, time series, legend and log.
        let mut row: Vec<ContainerLike> = Vec::new();
        let mut shares: Vec<f32> = Vec::new();
        if let (Some(p), Some(range)) = (profile, range) {
            for view in self.profile_views(p, range, &mut bounds)? {
                row.push(view);
                shares.push(1.0);
            }
        }
        if let Some(plots) = series_views(series) {
            row.push(plots);
            shares.push(1.4);
        }
        self.legend_pending = Some(profile.is_some());
        row.push(
            Vertical::new([
                TextDocumentView::new("legend")
                    .with_origin(format!("/{LEGEND_ENTITY}"))
                    .into(),
                TextLogView::new("log")
                    .with_origin(format!("/{LOG_ENTITY}"))
                    .into(),
            ])
            .with_row_shares([2.0, 1.0])
            .into(),
        );
        shares.push(1.0);
        let root = Vertical::new([bed, Horizontal::new(row).with_column_shares(shares).into()])
            .with_row_shares([1.0, 2.0]);
        send_with_bounds(&self.rec, &with_panels(root), &bounds)
    }

    /// The bed's view, across the top, fitted from the bottom of the profiles (or the floor) to
    /// `view_top` (with the speed scale and the clock drawn beside the bed); its bounds go to
    /// `bounds`.
    fn bed_view(
        &mut self,
        view_top: Option<f64>,
        range: Option<(f64, f64)>,
        bounds: &mut Vec<(String, [f64; 4])>,
    ) -> Result<ContainerLike, String> {
        let w = self.layout.width;
        let mut contents = vec![format!("/{DISKS_ENTITY}"), "/scene/**".to_owned()];
        if self.rough {
            contents.push(format!("/{ORIENTATION_ENTITY}"));
        }
        let view = Spatial2DView::new(self.layout.name.clone())
            .with_origin("/")
            .with_contents(contents);
        let Some(top) = view_top else {
            return Ok(view.into());
        };
        let bed_bottom = range.map_or(0.0, |(b, _)| b.min(0.0));
        let span = top - bed_bottom;
        if self.color_by != ColorBy::Species {
            self.log_colour_scale(top, bed_bottom)?;
        }
        self.log_clock(top, bed_bottom)?;
        let (view, path) = view_with_path(view);
        let fitted = [
            -0.01 * w,
            1.01 * w,
            -(top + 0.02 * span),
            -(bed_bottom - 0.04 * span),
        ];
        bounds.push((path, fitted));
        Ok(view)
    }

    /// The views of the packing fraction and the temperature against height (over `range`), with
    /// their axes; their bounds go to `bounds`.
    fn profile_views(
        &mut self,
        p: &ProfileTable,
        range: (f64, f64),
        bounds: &mut Vec<(String, [f64; 4])>,
    ) -> Result<Vec<ContainerLike>, String> {
        // A layer of centres in one bin thinner than a diameter can exceed φ = 1.
        let phi_max = 1.25;
        let t_max = nice_ceiling(0.25 * self.layout.speed_scale.powi(2)).max(nice_ceiling(
            p.temperature_x
                .iter()
                .zip(&p.temperature_y)
                .map(|(a, b)| 0.5 * (a + b))
                .fold(0.0, f64::max),
        ));
        let mut views = Vec::new();
        for (entity, title, x_max, name) in [
            (
                PACKING_PROFILE_ENTITY,
                "packing fraction φ",
                phi_max,
                "packing fraction vs height",
            ),
            (
                TEMPERATURE_PROFILE_ENTITY,
                "temperature T",
                t_max,
                "temperature vs height",
            ),
        ] {
            let b = self.log_profile_axes(entity, title, x_max, range)?;
            let (view, path) = view_with_path(
                Spatial2DView::new(name)
                    .with_origin("/")
                    .with_contents([format!("/{entity}/**")]),
            );
            bounds.push((path, b));
            views.push(view);
        }
        Ok(views)
    }
}

/// (bottom, top) of the bins of a profile table.
pub(super) fn profile_range(p: &ProfileTable) -> Option<(f64, f64)> {
    let (first, last) = (*p.height.first()?, *p.height.last()?);
    let half = if p.height.len() > 1 {
        0.5 * (last - first) / (p.height.len() - 1) as f64
    } else {
        0.5
    };
    Some((first - half, last + half))
}

/// The view as a container entry, and its path in the blueprint store.
pub(super) fn view_with_path(view: Spatial2DView) -> (ContainerLike, String) {
    match ContainerLike::from(view) {
        ContainerLike::View(v) => {
            let path = v.blueprint_path().to_string();
            (ContainerLike::View(v), path)
        }
        other => (other, String::new()),
    }
}

/// Sends `blueprint` to `rec` together with the visual bounds `[x0, x1, y0, y1]` of the views at
/// the given blueprint paths (the Rust blueprint API has no setter for a 2D view's bounds: they
/// are logged as the `VisualBounds2D` property of each view into the same blueprint store).
pub(super) fn send_with_bounds(
    rec: &RecordingStream,
    blueprint: &Blueprint,
    bounds: &[(String, [f64; 4])],
) -> Result<(), String> {
    let activation = BlueprintActivation {
        make_active: true,
        make_default: true,
    };
    let (memory, storage) = RecordingStreamBuilder::new(APPLICATION_ID)
        .memory()
        .map_err(|e| err("blueprint", e))?;
    blueprint
        .send(&memory, activation)
        .map_err(|e| err("blueprint", e))?;
    let mut messages = Vec::new();
    let mut command = None;
    for msg in storage.take() {
        match msg {
            LogMsg::BlueprintActivationCommand(cmd) => command = Some(cmd),
            msg if msg.store_id().is_blueprint() => messages.push(msg),
            _ => {}
        }
    }
    let command = command.ok_or_else(|| err("blueprint", "no activation command"))?;
    if !bounds.is_empty() {
        let (extra, extra_storage) = RecordingStreamBuilder::new(APPLICATION_ID)
            .recording_id(command.blueprint_id.recording_id().clone())
            .blueprint()
            .memory()
            .map_err(|e| err("blueprint", e))?;
        extra.set_time_sequence("blueprint", 0);
        for (path, [x0, x1, y0, y1]) in bounds {
            extra
                .log(
                    format!("{path}/VisualBounds2D"),
                    &VisualBounds2D::new(Range2D {
                        x_range: Range1D([*x0, *x1]),
                        y_range: Range1D([*y0, *y1]),
                    }),
                )
                .map_err(|e| err("view bounds", e))?;
        }
        messages.extend(
            extra_storage
                .take()
                .into_iter()
                .filter(|m| matches!(m, LogMsg::ArrowMsg(..))),
        );
    }
    rec.send_blueprint(messages, command);
    Ok(())
}

/// The time series' views, one per group (the first path segment of the series' names), and one
/// of its own for each series without a group: sharing one y axis would squash the smaller (e.g.
/// centre-of-mass height beside collisions per unit time). `None` without series.
fn series_views(series: &[(&'static str, f64)]) -> Option<ContainerLike> {
    let mut groups: BTreeSet<&str> = BTreeSet::new();
    let mut loose: Vec<&str> = Vec::new();
    for (name, _) in series {
        match name.split_once('/') {
            Some((g, _)) => {
                groups.insert(g);
            }
            None => loose.push(name),
        }
    }
    let view = |name: &str| -> ContainerLike {
        TimeSeriesView::new(name)
            .with_origin(format!("/{SERIES_PREFIX}/{name}"))
            .into()
    };
    let plots: Vec<ContainerLike> = groups.iter().chain(&loose).map(|g| view(g)).collect();
    (!plots.is_empty()).then(|| Vertical::new(plots).into())
}

/// The blueprint of `root` with the side and time panels collapsed (the time panel keeps its
/// play controls), so that the views get the window; the timeline shown is the frame number, a
/// plain number (the module documentation says why).
fn with_panels(root: Vertical) -> Blueprint {
    Blueprint::new(root)
        .with_auto_views(false)
        .with_blueprint_panel(BlueprintPanel::from_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::from_state(PanelState::Collapsed))
        .with_time_panel(
            TimePanel::new()
                .with_state(PanelState::Collapsed)
                .with_timeline(FRAME_TIMELINE)
                .with_play_state(PlayState::Following),
        )
}
