//! Physical sense of a typed scenario: every rule names the field it guards.

pub use super::limits::*;
use super::*;
use crate::scenario::phase_stops::{stride, GROUP};
use crate::scenario::work::{blame_a_factor_set, inlet_disks, most_disks, validate_work};

/// A refused relation between two fields, blamed on the one the user set (`sets`: the `--set`
/// overrides, a sweep's axes): a warm-up past the run's end is the duration's fault when only
/// `run.duration` was set (a shorter run of a scene, or a resume), the warm-up's otherwise; a
/// run asking for too much work is the fault of the factor set (a speed, `engine.dt`, the
/// count) when `run.duration` was not.
pub fn blame_what_was_set(e: Error, s: &Scenario, sets: &[String]) -> Error {
    let set = |field: &str| {
        sets.iter()
            .any(|x| x.split_once('=').is_some_and(|(k, _)| k.trim() == field))
    };
    let warmup = s.run.warmup;
    match &e {
        Error::Input { field, .. }
            if field == "run.warmup"
                && set("run.duration")
                && !set("run.warmup")
                && warmup.is_finite()
                && warmup >= 0.0 =>
        {
            Error::input(
                "run.duration",
                format!(
                    "must be longer than run.warmup = {warmup:?} (got {:?}): lengthen it, or \
                     set a shorter run.warmup",
                    s.run.duration
                ),
            )
        }
        _ => blame_a_factor_set(&e, s, &set).unwrap_or(e),
    }
}

/// A length of the scene, at most [`MAX_LENGTH_RATIO`] smallest radii.
fn resolved_length(field: &str, what: &str, length: f64, a_min: f64) -> Result<()> {
    let ratio = length / a_min;
    if ratio <= MAX_LENGTH_RATIO {
        Ok(())
    } else {
        Err(Error::input(
            field,
            format!(
                "{what} of {length:.4e} is {ratio:.3e} radii of the smallest disk; at most {MAX_LENGTH_RATIO:e} \
                 are resolved in double precision"
            ),
        ))
    }
}

/// A coefficient of restitution, in [0, 1].
fn restitution(field: &str, e: f64) -> Result<()> {
    if (0.0..=1.0).contains(&e) {
        Ok(())
    } else {
        Err(Error::input(field, format!("must lie in [0, 1] (got {e})")))
    }
}

/// A tangential restitution, in [−1, 1].
fn tangential_restitution(field: &str, beta: Option<f64>) -> Result<()> {
    match beta {
        Some(b) if !(-1.0..=1.0).contains(&b) => Err(Error::input(
            field,
            format!("must lie in [-1, 1] (got {b}; -1 is a smooth contact)"),
        )),
        _ => Ok(()),
    }
}

/// A coefficient of friction: finite and not negative.
fn friction(field: &str, mu: Option<f64>) -> Result<()> {
    match mu {
        Some(m) if !(m.is_finite() && (0.0..=MAX_MAGNITUDE).contains(&m)) => Err(Error::input(
            field,
            format!("must be a finite number ≥ 0 (got {m})"),
        )),
        _ => Ok(()),
    }
}

/// Rough disks: friction and tangential restitution of pairs, floor and walls in range, an
/// inertia factor in (0, 1], a finite initial rotational temperature ≥ 0, and the exact engine
/// (the approximate schemes do not rotate disks yet).
fn validate_rough(s: &Scenario) -> Result<()> {
    friction("collisions.friction", s.collisions.friction)?;
    tangential_restitution(
        "collisions.tangential_restitution",
        s.collisions.tangential_restitution,
    )?;
    if let Some(f) = &s.floor {
        friction("floor.friction", f.friction)?;
        tangential_restitution("floor.tangential_restitution", f.tangential_restitution)?;
    }
    friction("domain.wall_friction", s.domain.wall_friction)?;
    tangential_restitution(
        "domain.wall_tangential_restitution",
        s.domain.wall_tangential_restitution,
    )?;
    if let Some(q) = s.particles.inertia_factor {
        if !(MIN_INERTIA_FACTOR..=1.0).contains(&q) {
            return Err(Error::input(
                "particles.inertia_factor",
                format!(
                    "must lie in [{MIN_INERTIA_FACTOR:e}, 1] (got {q:e}; ½ is a uniform disk, 1 a \
                     ring; a smaller one makes spins and their energies overflow)"
                ),
            ));
        }
    }
    if let Some(t) = s.particles.rotational_temperature {
        if !(t.is_finite() && (0.0..=MAX_MAGNITUDE).contains(&t)) {
            return Err(Error::input(
                "particles.rotational_temperature",
                format!("must be a finite number ≥ 0 (got {t})"),
            ));
        }
    }
    Ok(())
}

/// Checks the whole scenario, section by section in the file's order; the first rule broken
/// is the error (so a scenario with several faults always reports the same one).
pub fn validate(s: &Scenario) -> Result<()> {
    // The run's length first: inlets' windows and the output's intervals are read against it.
    validate_run(&s.run)?;
    validate_domain(s)?;
    validate_gravity(s)?;
    validate_floor(s)?;
    validate_particles(s)?;
    validate_orifice(s)?;
    validate_inlets(s)?;
    validate_total_disks(s)?;
    validate_exit_height(s)?;
    validate_collisions(&s.collisions)?;
    validate_rough(s)?;
    validate_output(s)?;
    validate_engine(s)?;
    validate_lengths(s)?;
    crate::scenario::speeds::validate_speeds(s)?;
    validate_work(s)?;
    Ok(())
}

/// The box: a positive width and height, a wall restitution in [0, 1], and a height wherever
/// the box is closed at the top (unless the packing fraction sets it).
fn validate_domain(s: &Scenario) -> Result<()> {
    positive("domain.width", s.domain.width)?;
    restitution("domain.wall_restitution", s.domain.wall_restitution)?;
    if let Some(h) = s.domain.height {
        positive("domain.height", h)?;
    }
    let closed = s.domain.y_boundary != YBoundary::Open;
    if closed && s.domain.height.is_none() && s.particles.packing_fraction.is_none() {
        return Err(Error::input(
            "domain.height",
            "required with y_boundary `lid` or `periodic` (or give particles.packing_fraction)",
        ));
    }
    Ok(())
}

/// Gravity: positive, and only where a floor can hold the disks up.
fn validate_gravity(s: &Scenario) -> Result<()> {
    if let Some(g) = s.gravity {
        positive("gravity", g)?;
        if s.domain.y_boundary == YBoundary::Periodic {
            return Err(Error::input(
                "gravity",
                "with domain.y_boundary = periodic nothing holds the disks up: they fall forever \
                 together, faster and faster; give a floor (y_boundary open or lid) or leave \
                 gravity out",
            ));
        }
    }
    Ok(())
}

/// The floor: present exactly when the box has a bottom (not periodic in y), with a
/// restitution in [0, 1] and a vibration that is fully given.
fn validate_floor(s: &Scenario) -> Result<()> {
    match (&s.floor, s.domain.y_boundary) {
        (Some(_), YBoundary::Periodic) => {
            return Err(Error::input(
                "floor",
                "a floor cannot be combined with domain.y_boundary = periodic",
            ))
        }
        (None, YBoundary::Open | YBoundary::Lid) => {
            return Err(Error::input(
                "floor",
                "required unless domain.y_boundary is periodic: without it disks fall out of the bottom",
            ))
        }
        _ => {}
    }
    if let Some(floor) = &s.floor {
        restitution("floor.restitution", floor.restitution)?;
        validate_vibration(floor, s.gravity)?;
    }
    Ok(())
}

/// The floor's orifice: within the width, wider than the largest disk, in a static, smooth
/// floor under gravity (rough disks may fall through it: its corners are as smooth as the
/// floor), with the exact engine (see the physics page on the orifice).
fn validate_orifice(s: &Scenario) -> Result<()> {
    let Some(floor) = &s.floor else {
        return Ok(());
    };
    let Some(o) = floor.orifice else {
        return Ok(());
    };
    let width = s.domain.width;
    for (field, v) in [("floor.orifice.from", o.from), ("floor.orifice.to", o.to)] {
        if !(v.is_finite() && (0.0..=width).contains(&v)) {
            return Err(Error::input(
                field,
                format!("must lie in [0, domain.width = {width}] (got {v})"),
            ));
        }
    }
    let (_, a_max) = s.all_radius_range();
    if o.to - o.from <= 2.0 * a_max {
        return Err(Error::input(
            "floor.orifice.to",
            format!(
                "the orifice [{}, {}] must be wider than the largest disk (diameter {}): a disk \
                 wedged between its two corners could not be held at rest",
                o.from,
                o.to,
                2.0 * a_max
            ),
        ));
    }
    if s.gravity.is_none() {
        return Err(Error::input(
            "floor.orifice",
            "needs gravity: disks leave by falling through it",
        ));
    }
    if floor.vibrates() {
        return Err(Error::input(
            "floor.orifice",
            "needs a static floor: the corners of a vibrating orifice are not implemented",
        ));
    }
    if floor.friction.is_some() || floor.tangential_restitution.is_some() {
        return Err(Error::input(
            "floor.orifice",
            "needs a smooth floor (no floor.friction or floor.tangential_restitution): rough \
             disks sliding on a rough floor to the orifice's edges are not implemented; rough \
             disks on a smooth floor are (its corners are smooth too)",
        ));
    }
    if s.scheme() != crate::scenario::Scheme::EventDriven {
        return Err(Error::input(
            "floor.orifice",
            "needs engine.scheme = event-driven: the approximate schemes keep every disk for \
             the whole run and have no corner contacts",
        ));
    }
    Ok(())
}

/// The inlets: sizes and masses as `particles` gives them, boxes inside the domain above the
/// floor with room for their largest disk, a rate or a count over a window within the run,
/// speeds and temperatures that make sense; the exact engine.
fn validate_inlets(s: &Scenario) -> Result<()> {
    let mut recycling = 0;
    for (k, inlet) in s.inlets.iter().enumerate() {
        let field = |name: &str| format!("inlets.{k}.{name}");
        validate_inlet_sizes(s, k, inlet)?;
        let a = s.inlet_radius_range(inlet).1;
        let width = s.domain.width;
        let (x, y) = (inlet.x, inlet.y);
        if !(x.from.is_finite() && x.to.is_finite() && x.from <= x.to) {
            return Err(Error::input(field("x"), "needs finite from ≤ to"));
        }
        let (lo, hi) = match s.domain.x_boundary {
            crate::scenario::XBoundary::Walls => (a, width - a),
            crate::scenario::XBoundary::Periodic => (0.0, width),
        };
        if x.from < lo || x.to > hi {
            return Err(Error::input(
                field("x"),
                format!("must lie within [{lo}, {hi}]: a disk entering there must fit between the walls"),
            ));
        }
        if !(y.from.is_finite() && y.to.is_finite() && y.from <= y.to) {
            return Err(Error::input(field("y"), "needs finite from ≤ to"));
        }
        if y.from < a {
            return Err(Error::input(
                field("y.from"),
                format!("must be at least a radius ({a}) above the floor"),
            ));
        }
        if let (Some(h), crate::scenario::YBoundary::Lid) = (s.domain.height, s.domain.y_boundary) {
            if y.to > h - a {
                return Err(Error::input(
                    field("y.to"),
                    "must leave a radius below the lid",
                ));
            }
        }
        let end = inlet.end.unwrap_or(s.run.duration);
        if !(inlet.start.is_finite() && inlet.start >= 0.0) {
            return Err(Error::input(field("start"), "must be ≥ 0"));
        }
        if inlet.end.is_none() && inlet.start >= end {
            return Err(Error::input(
                field("start"),
                format!("must be before the run's end, run.duration = {end} (inlets.{k}.end is not given)"),
            ));
        }
        if !(end.is_finite() && end > inlet.start) {
            return Err(Error::input(field("end"), "must be after start"));
        }
        match (inlet.rate, inlet.count) {
            (Some(_), Some(_)) => {
                return Err(Error::input(field("count"), "give rate or count, not both"))
            }
            (Some(r), None) => positive(&field("rate"), r)?,
            (None, None) if !inlet.recycle => {
                return Err(Error::input(
                    field("rate"),
                    "give rate or count (or recycle: true for an inlet that only recycles)",
                ))
            }
            _ => {}
        }
        for (name, v) in [("speed", inlet.speed), ("temperature", inlet.temperature)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::input(field(name), format!("must be ≥ 0 (got {v})")));
            }
        }
        if inlet.recycle {
            recycling += 1;
            if recycling > 1 {
                return Err(Error::input(field("recycle"), "only one inlet may recycle"));
            }
            if s.floor.as_ref().and_then(|f| f.orifice).is_none() && s.domain.exit_height.is_none()
            {
                return Err(Error::input(
                    field("recycle"),
                    "needs floor.orifice or domain.exit_height: only disks that leave can come back",
                ));
            }
        }
        if s.scheme() != crate::scenario::Scheme::EventDriven {
            return Err(Error::input(
                "inlets",
                "need engine.scheme = event-driven: the approximate schemes keep the same disks \
                 for the whole run",
            ));
        }
        if s.gravity.is_none() || s.floor.is_none() {
            return Err(Error::input("inlets", "need gravity and a floor"));
        }
    }
    Ok(())
}

/// The scene's disks in all, initial and through every inlet, at most [`MAX_DISKS`] (the
/// engine keeps every disk that ever entered): the error names the inlet that passes it.
fn validate_total_disks(s: &Scenario) -> Result<()> {
    let mut total = s.disk_count() as f64;
    for (k, inlet) in s.inlets.iter().enumerate() {
        total += inlet_disks(inlet, inlet.end.unwrap_or(s.run.duration));
        if total > MAX_DISKS as f64 {
            let field = if inlet.count.is_some() {
                "count"
            } else {
                "rate"
            };
            return Err(Error::input(
                format!("inlets.{k}.{field}"),
                format!(
                    "brings the scene's disks in all (initial and through every inlet up to \
                     this one) to {total:.0}; at most {MAX_DISKS} are supported"
                ),
            ));
        }
    }
    Ok(())
}

/// An inlet's sizes and masses: a radius law as `particles.radius` (a species list's counts,
/// the odds of each species, add up to at least one), a positive mass or density (not both),
/// masses double precision handles, and radii within the ratio the neighbour masks support
/// together with every other disk of the scene.
fn validate_inlet_sizes(s: &Scenario, k: usize, inlet: &Inlet) -> Result<()> {
    let field = |name: &str| format!("inlets.{k}.{name}");
    if let Some(law) = &inlet.radius {
        validate_radius_law(law, &field("radius"))?;
        if let Radius::Species(list) = law {
            if list.species.iter().map(|sp| sp.count).sum::<usize>() == 0 {
                return Err(Error::input(
                    field("radius.species"),
                    "the counts (the odds of each species) must add up to at least one",
                ));
            }
        }
    }
    if let Some(m) = inlet.mass {
        positive(&field("mass"), m)?;
    }
    if let Some(d) = inlet.density {
        positive(&field("density"), d)?;
    }
    if inlet.mass.is_some() && inlet.density.is_some() {
        return Err(Error::input(
            field("density"),
            format!("give either inlets.{k}.mass or inlets.{k}.density, not both"),
        ));
    }
    let (lo, hi) = s.inlet_radius_range(inlet);
    let mut masses = vec![s.inlet_mass(inlet, lo, None), s.inlet_mass(inlet, hi, None)];
    if let Radius::Species(list) = s.inlet_radius(inlet) {
        masses.extend(
            list.species
                .iter()
                .map(|sp| s.inlet_mass(inlet, sp.radius, sp.mass)),
        );
    }
    if let Some(m) = masses
        .into_iter()
        .find(|m| !(MIN_MAGNITUDE..=MAX_MAGNITUDE).contains(m))
    {
        return Err(Error::input(
            field("mass"),
            format!(
                "the inlet brings disks of mass {m:e}, outside the range [{MIN_MAGNITUDE:e}, \
                 {MAX_MAGNITUDE:e}] that double precision computes with"
            ),
        ));
    }
    let (a_min, a_max) = s.all_radius_range();
    if a_max / a_min > MAX_RADIUS_RATIO {
        return Err(Error::input(
            field("radius"),
            format!(
                "with the scene's other disks the radii span a ratio of {:.2}, more than \
                 {MAX_RADIUS_RATIO}, the largest the neighbour masks support",
                a_max / a_min
            ),
        ));
    }
    if s.domain.width < 4.0 * a_max {
        return Err(Error::input(
            field("radius"),
            format!("domain.width must be at least 4 radii of the largest disk ({a_max})"),
        ));
    }
    Ok(())
}

/// The exit height: a positive height under an open top, with the exact engine, above every
/// inlet's box by its largest radius (a disk entering must not leave at once). That it clears
/// the initial bed is checked where the bed is placed ([`Scene::build`](crate::engine::Scene)).
fn validate_exit_height(s: &Scenario) -> Result<()> {
    let Some(h) = s.domain.exit_height else {
        return Ok(());
    };
    const FIELD: &str = "domain.exit_height";
    positive(FIELD, h)?;
    if s.domain.y_boundary != YBoundary::Open {
        return Err(Error::input(
            FIELD,
            "needs domain.y_boundary = open: disks leave by rising through an open top",
        ));
    }
    if s.scheme() != crate::scenario::Scheme::EventDriven {
        return Err(Error::input(
            FIELD,
            "needs engine.scheme = event-driven: the approximate schemes keep every disk for \
             the whole run",
        ));
    }
    for (k, inlet) in s.inlets.iter().enumerate() {
        let top = inlet.y.to + s.inlet_radius_range(inlet).1;
        if h <= top {
            return Err(Error::input(
                FIELD,
                format!(
                    "{h} must lie above inlets.{k} (its box reaches {top} with the radius of its \
                     largest disk): a disk entering there would leave at once"
                ),
            ));
        }
    }
    Ok(())
}

/// The floor's vibration: an amplitude A ≥ 0 or a peak acceleration Γ = Aω²/g (which needs
/// gravity), not both; a frequency whenever it moves; a finite phase.
fn validate_vibration(floor: &Floor, gravity: Option<f64>) -> Result<()> {
    if floor.amplitude.is_some() && floor.gamma.is_some() {
        return Err(Error::input(
            "floor.gamma",
            "give either floor.amplitude or floor.gamma, not both",
        ));
    }
    if let Some(a) = floor.amplitude {
        if !(a.is_finite() && a >= 0.0) {
            return Err(Error::input(
                "floor.amplitude",
                format!("must be ≥ 0 (got {a})"),
            ));
        }
    }
    if let Some(gamma) = floor.gamma {
        positive("floor.gamma", gamma)?;
        if gravity.is_none() {
            return Err(Error::input(
                "floor.gamma",
                "Γ = Aω²/g needs gravity; give floor.amplitude instead",
            ));
        }
    }
    match floor.frequency {
        Some(f) => positive("floor.frequency", f)?,
        None if floor.vibrates() => {
            return Err(Error::input(
                "floor.frequency",
                "required for a vibrating floor",
            ))
        }
        None => {}
    }
    if !floor.phase.is_finite() {
        return Err(Error::input("floor.phase", "must be finite"));
    }
    Ok(())
}

/// The collision law: a restitution in [0, 1], and positive parameters for the cures of
/// inelastic collapse.
fn validate_collisions(c: &Collisions) -> Result<()> {
    restitution("collisions.restitution", c.restitution)?;
    if let Some(tc) = c.tc {
        positive("collisions.tc", tc)?;
    }
    if let Some(v) = c.speed_cutoff {
        positive("collisions.speed_cutoff", v)?;
    }
    Ok(())
}

/// The run's length: a positive duration, and a warm-up that leaves some of it to measure.
fn validate_run(r: &Run) -> Result<()> {
    positive("run.duration", r.duration)?;
    if !(r.warmup.is_finite() && r.warmup >= 0.0 && r.warmup < r.duration) {
        return Err(Error::input(
            "run.warmup",
            format!(
                "must lie in [0, run.duration) (got {:?} with duration {:?})",
                r.warmup, r.duration
            ),
        ));
    }
    if let Some(seconds) = r.max_wall_seconds {
        super::intervals::wall_seconds("run.max_wall_seconds", seconds)?;
    }
    Ok(())
}

/// What the run writes: positive intervals and scales, height profiles only under gravity,
/// a bounded number of bins, frames and samples.
fn validate_output(s: &Scenario) -> Result<()> {
    let o = &s.output;
    if let Some(dt) = o.frame_interval {
        positive("output.frame_interval", dt)?;
    }
    if let Some(dt) = o.sample_interval {
        positive("output.sample_interval", dt)?;
    }
    if let Some(dt) = o.trajectory_interval {
        positive("output.trajectory_interval", dt)?;
    }
    if let Some(v) = o.speed_scale {
        positive("output.speed_scale", v)?;
    }
    if let Some(v) = o.spin_scale {
        positive("output.spin_scale", v)?;
    }
    if o.color_by == ColorChoice::Spin && !s.is_rough() {
        return Err(Error::input(
            "output.color_by",
            "`spin` colours rough disks by their spin: this scene's disks are smooth (name \
             one of the rough disks' fields, e.g. collisions.friction)",
        ));
    }
    if let Some(h) = o.profile_height {
        positive("output.profile_height", h)?;
        if s.gravity.is_none() {
            return Err(Error::input(
                "output.profile_height",
                "height profiles need gravity: this scene has none",
            ));
        }
    }
    validate_fields(s)?;
    if !(1..=MAX_PROFILE_BINS).contains(&o.profile_bins) {
        return Err(Error::input(
            "output.profile_bins",
            format!(
                "must lie in [1, {MAX_PROFILE_BINS}] (got {})",
                o.profile_bins
            ),
        ));
    }
    if !(1..=MAX_PHASE_BINS).contains(&o.phase_bins) {
        return Err(Error::input(
            "output.phase_bins",
            format!("must lie in [1, {MAX_PHASE_BINS}] (got {})", o.phase_bins),
        ));
    }
    validate_output_counts(s)
}

/// The 2D fields' grid: at least one cell a side, at most [`MAX_FIELD_BINS`], a positive top,
/// and only under gravity (their vertical axis is the height above the floor).
fn validate_fields(s: &Scenario) -> Result<()> {
    let o = &s.output;
    if let Some(h) = o.field_height {
        positive("output.field_height", h)?;
    }
    if let Some(bins) = o.field_bins {
        if let Some(n) = bins.into_iter().find(|n| !(1..=MAX_FIELD_BINS).contains(n)) {
            return Err(Error::input(
                "output.field_bins",
                format!("[nx, ny]: each must lie in [1, {MAX_FIELD_BINS}] (got {n})"),
            ));
        }
        let [nx, ny] = bins;
        if nx * ny > MAX_FIELD_CELLS {
            return Err(Error::input(
                "output.field_bins",
                format!(
                    "[{nx}, {ny}] asks for {} cells; at most {MAX_FIELD_CELLS} are supported",
                    nx * ny
                ),
            ));
        }
    }
    let named = [
        ("output.field_bins", o.field_bins.is_some()),
        ("output.field_height", o.field_height.is_some()),
        ("output.record_fields", o.record_fields),
    ];
    if let Some((field, _)) = named.iter().find(|(_, set)| *set) {
        if s.gravity.is_none() {
            return Err(Error::input(
                *field,
                "2D fields are over x and height: they need gravity, and this scene has none",
            ));
        }
    }
    Ok(())
}

/// The engine's knobs: a dense grid only under a lid or period, a positive skin, the schemes'
/// knobs with their scheme, a bounded number of steps, a sync distance of at least 10⁻³ radii.
fn validate_engine(s: &Scenario) -> Result<()> {
    let e = &s.engine;
    if e.grid == GridChoice::Dense && s.domain.y_boundary == YBoundary::Open {
        return Err(Error::input(
            "engine.grid",
            "a dense grid needs a bounded height: use `hashed` (or `auto`) for an open top",
        ));
    }
    if let Some(skin) = e.skin {
        positive("engine.skin", skin)?;
    }
    validate_scheme_knobs(e, s.scheme())?;
    if let Some(dt) = e.dt {
        at_most("engine.dt", "steps", s.run.duration / dt, MAX_STEPS)?;
    }
    if let Some(d) = e.sync_distance {
        if d < 1e-3 {
            return Err(Error::input(
                "engine.sync_distance",
                format!("must be at least 1e-3 smallest radii (got {d:e})"),
            ));
        }
    }
    Ok(())
}

/// Frames, samples and trajectory frames: how many the run asks for (at the intervals of
/// [`Scenario::frame_interval`] and its siblings, defaults included), and what the frames and
/// samples cost, each a visit of every disk.
fn validate_output_counts(s: &Scenario) -> Result<()> {
    let d = s.run.duration;
    let o = &s.output;
    if let Some(dt) = o.frame_interval {
        at_most("output.frame_interval", "frames", d / dt, MAX_OUTPUT_TIMES)?;
    }
    if let Some(dt) = o.sample_interval {
        at_most(
            "output.sample_interval",
            "samples",
            d / dt,
            MAX_OUTPUT_TIMES,
        )?;
    }
    if let Some(dt) = o.trajectory_interval {
        at_most(
            "output.trajectory_interval",
            "trajectory frames",
            d / dt,
            MAX_OUTPUT_TIMES,
        )?;
    }
    validate_output_visits(s)
}

/// Disk visits of the frames and samples (every disk the scene may hold, each frame and each
/// sample), at most [`MAX_OUTPUT_VISITS`]; the error names the interval that asks for more of
/// them (the frame interval when neither is given).
fn validate_output_visits(s: &Scenario) -> Result<()> {
    let d = s.run.duration;
    let frames = d / s.frame_interval() + 1.0;
    let samples = d / s.sample_interval() + 1.0;
    let disks = most_disks(s);
    let visits = disks * (frames + samples);
    if visits <= MAX_OUTPUT_VISITS {
        return Ok(());
    }
    let field = if samples > frames && s.output.sample_interval.is_some() {
        "output.sample_interval"
    } else {
        "output.frame_interval"
    };
    Err(Error::input(
        field,
        format!(
            "asks for {frames:.3e} frames and {samples:.3e} samples of up to {disks:.3e} disks \
             ({visits:.3e} disk visits, each some nanoseconds); at most {MAX_OUTPUT_VISITS:e} \
             are supported (longer intervals, or fewer disks)"
        ),
    ))
}

/// Disk frames (disks × frames) of a recording or trajectory asked for by `field` (a frame
/// every `interval`, or the frame interval), at most [`MAX_RECORDED_DISKS`]; every disk that
/// may enter through an inlet counted.
pub fn validate_recorded(s: &Scenario, field: &str, interval: Option<f64>) -> Result<()> {
    let frames = s.run.duration / interval.unwrap_or_else(|| s.frame_interval()) + 1.0;
    let disks = most_disks(s);
    let size = frames * disks;
    if size <= MAX_RECORDED_DISKS {
        return Ok(());
    }
    Err(Error::input(
        field,
        format!(
            "would hold {frames:.3e} frames of up to {disks:.3e} disks ({size:.3e} disk frames); \
             at most {MAX_RECORDED_DISKS:e} are supported (a longer output.frame_interval or \
             output.trajectory_interval records fewer)"
        ),
    ))
}

/// Lengths the scene spans, in smallest radii: width, closed height, floor amplitude.
fn validate_lengths(s: &Scenario) -> Result<()> {
    let (a_min, _) = s.radius_range();
    resolved_length("domain.width", "a width", s.domain.width, a_min)?;
    if let Some(phi) = s.particles.packing_fraction {
        let height = s.disk_count() as f64 * mean_disk_area(s) / (phi * s.domain.width);
        resolved_length("particles.packing_fraction", "a bed height", height, a_min)?;
    }
    if let Some(h) = s.domain.height {
        resolved_length("domain.height", "a height", h, a_min)?;
    }
    if let Some(floor) = &s.floor {
        match floor.gamma {
            Some(gamma) => resolved_length(
                "floor.gamma",
                &format!(
                    "Γ = {gamma} with gravity = {} and floor.frequency = {} gives a floor amplitude Γg/ω²",
                    s.gravity.unwrap_or(0.0),
                    floor.frequency.unwrap_or(0.0)
                ),
                s.floor_amplitude(),
                a_min,
            )?,
            None => resolved_length(
                "floor.amplitude",
                "a floor amplitude",
                s.floor_amplitude(),
                a_min,
            )?,
        }
    }
    Ok(())
}

/// The schemes that run on several threads (the exact engine runs on one core).
const APPROXIMATE: &[Scheme] = &[Scheme::TimeStep, Scheme::SpaceTime];

/// The most threads `engine.threads` may ask for.
pub const MAX_THREADS: u64 = 4096;

/// The most strips `engine.strips` may ask for (the scene may allow fewer: each strip is at
/// least four columns of cells wide).
pub const MAX_STRIPS: u64 = 1 << 16;

/// The approximate schemes' knobs: positive, and only with the scheme they belong to (a knob
/// that the chosen scheme would ignore is refused rather than silently dropped).
fn validate_scheme_knobs(e: &Engine, scheme: Scheme) -> Result<()> {
    let knobs = [
        (
            "engine.dt",
            e.dt,
            &[Scheme::TimeStep, Scheme::Contact, Scheme::Hybrid][..],
        ),
        (
            "engine.verlet_skin",
            e.verlet_skin,
            &[Scheme::TimeStep, Scheme::Contact, Scheme::Hybrid][..],
        ),
        (
            "engine.sync_distance",
            e.sync_distance,
            &[Scheme::SpaceTime][..],
        ),
        (
            "engine.cell_size",
            e.cell_size,
            &[
                Scheme::TimeStep,
                Scheme::SpaceTime,
                Scheme::Contact,
                Scheme::Hybrid,
            ][..],
        ),
        (
            "engine.strips",
            e.strips.map(|k| k as f64),
            &[Scheme::SpaceTime][..],
        ),
    ];
    let threads = ("engine.threads", e.threads.map(|t| t as f64), APPROXIMATE);
    if let Some(t) = e.threads {
        if !(1..=MAX_THREADS).contains(&t) {
            return Err(Error::input(
                "engine.threads",
                format!(
                    "must be a whole number from 1 to {MAX_THREADS} (got {t}; absent: every core)"
                ),
            ));
        }
    }
    if let Some(k) = e.strips {
        if !(1..=MAX_STRIPS).contains(&k) {
            return Err(Error::input(
                "engine.strips",
                format!("must be a whole number from 1 to {MAX_STRIPS} (got {k}; absent: 1)"),
            ));
        }
    }
    for (field, value, schemes) in knobs.into_iter().chain([threads]) {
        let Some(v) = value else { continue };
        positive(field, v)?;
        if !schemes.contains(&scheme) {
            let names: Vec<&str> = schemes
                .iter()
                .map(|s| match s {
                    Scheme::TimeStep => "time-step",
                    Scheme::SpaceTime => "space-time",
                    Scheme::Contact => "contact",
                    Scheme::Hybrid => "hybrid",
                    Scheme::EventDriven => "event-driven",
                    Scheme::Auto => "auto",
                })
                .collect();
            return Err(Error::input(
                field,
                format!(
                    "applies to engine.scheme {} only (the scene uses another scheme)",
                    names.join(" or ")
                ),
            ));
        }
    }
    Ok(())
}

/// The disks: their radii, count and masses, a temperature ≥ 0, a packing fraction below the
/// densest packing, explicit placements of the right length, and a box they fit in.
fn validate_particles(s: &Scenario) -> Result<()> {
    let p = &s.particles;
    validate_radii(p)?;
    validate_count(s)?;
    validate_mass_law(s)?;
    if !(p.temperature.is_finite() && p.temperature >= 0.0) {
        return Err(Error::input(
            "particles.temperature",
            format!("must be ≥ 0 (got {})", p.temperature),
        ));
    }
    if let Some(phi) = p.packing_fraction {
        if !(phi > 0.0 && phi < MAX_PACKING) {
            return Err(Error::input(
                "particles.packing_fraction",
                format!("must lie in (0, {MAX_PACKING:.4}) (got {phi})"),
            ));
        }
    }
    if let Placement::Explicit(e) = &p.placement {
        validate_explicit_placement(e, s.disk_count())?;
    }
    validate_fit_in_box(s)
}

/// The particles' radius law ([`validate_radius_law`]); a species list sets the count itself.
fn validate_radii(p: &Particles) -> Result<()> {
    validate_radius_law(&p.radius, "particles.radius")?;
    if matches!(p.radius, Radius::Species(_)) && p.count.is_some() {
        return Err(Error::input(
            "particles.count",
            "leave it out when particles.radius lists species with counts",
        ));
    }
    Ok(())
}

/// A radius law (`field`: where it is): a positive radius, a uniform range with min ≤ max, or
/// a non-empty list of species (positive radii and masses).
fn validate_radius_law(law: &Radius, field: &str) -> Result<()> {
    match law {
        Radius::Fixed(r) => positive(field, *r)?,
        Radius::Uniform(u) => {
            positive(&format!("{field}.min"), u.min)?;
            positive(&format!("{field}.max"), u.max)?;
            if u.min > u.max {
                return Err(Error::input(
                    format!("{field}.min"),
                    format!("must not exceed {field}.max ({} > {})", u.min, u.max),
                ));
            }
        }
        Radius::Species(list) => {
            if list.species.is_empty() {
                return Err(Error::input(
                    format!("{field}.species"),
                    "list at least one species",
                ));
            }
            for (k, sp) in list.species.iter().enumerate() {
                positive(&format!("{field}.species.{k}.radius"), sp.radius)?;
                if let Some(m) = sp.mass {
                    positive(&format!("{field}.species.{k}.mass"), m)?;
                }
            }
        }
    }
    Ok(())
}

/// The number of disks: at least one, at most [`MAX_DISKS`] (the error names the field that
/// sets it: the count, or the species list).
fn validate_count(s: &Scenario) -> Result<()> {
    let n = s.disk_count();
    let count_field = match &s.particles.radius {
        Radius::Species(_) => "particles.radius.species",
        _ => "particles.count",
    };
    if n == 0 {
        return Err(Error::input(count_field, "at least one disk is needed"));
    }
    if n > MAX_DISKS {
        return Err(Error::input(
            count_field,
            format!("asks for {n} disks; at most {MAX_DISKS} are supported"),
        ));
    }
    Ok(())
}

/// A positive mass or a positive density, not both, giving masses double precision handles.
fn validate_mass_law(s: &Scenario) -> Result<()> {
    let p = &s.particles;
    if let Some(m) = p.mass {
        positive("particles.mass", m)?;
    }
    if let Some(d) = p.density {
        positive("particles.density", d)?;
    }
    if p.mass.is_some() && p.density.is_some() {
        return Err(Error::input(
            "particles.density",
            "give either particles.mass or particles.density, not both",
        ));
    }
    validate_masses(s)
}

/// Explicit positions (and velocities, if given): one per disk.
fn validate_explicit_placement(e: &ExplicitPlacement, n: usize) -> Result<()> {
    if e.positions.len() != n {
        return Err(Error::input(
            "particles.placement.positions",
            format!("lists {} positions for {n} disks", e.positions.len()),
        ));
    }
    if let Some(v) = &e.velocities {
        if v.len() != n {
            return Err(Error::input(
                "particles.placement.velocities",
                format!("lists {} velocities for {n} disks", v.len()),
            ));
        }
    }
    Ok(())
}

/// The disks fit the box: a width of at least 4 of the largest radii, a radius ratio the
/// neighbour masks support (≤ 6), and in a closed box of stated height, a packing fraction
/// below the densest possible.
fn validate_fit_in_box(s: &Scenario) -> Result<()> {
    let n = s.disk_count();
    let (rmin, rmax) = s.radius_range();
    if s.domain.width < 4.0 * rmax {
        return Err(Error::input(
            "domain.width",
            format!(
                "must be at least 4 radii of the largest disk ({})",
                4.0 * rmax
            ),
        ));
    }
    if rmax / rmin > MAX_RADIUS_RATIO {
        return Err(Error::input(
            "particles.radius",
            format!(
                "radius ratio {:.2} exceeds 6, the largest the neighbour masks support",
                rmax / rmin
            ),
        ));
    }
    // Packing fraction of a closed box with a stated height.
    if let (true, Some(h)) = (s.domain.y_boundary != YBoundary::Open, s.domain.height) {
        let mean_area = mean_disk_area(s);
        let phi = n as f64 * mean_area / (s.domain.width * h);
        if phi >= MAX_PACKING {
            return Err(Error::input(
                "particles.count",
                format!(
                    "{n} disks fill a packing fraction {phi:.3} of the box, above the densest possible {MAX_PACKING:.4}"
                ),
            ));
        }
    }
    Ok(())
}

/// The disks' masses (from `particles.mass`, `particles.density`, a species' mass, or equal
/// areal density) within [`MIN_MAGNITUDE`, `MAX_MAGNITUDE`]: collision impulses multiply them.
fn validate_masses(s: &Scenario) -> Result<()> {
    let p = &s.particles;
    let (a_min, a_max) = s.radius_range();
    let area = |a: f64| std::f64::consts::PI * a * a;
    let (field, lightest, heaviest) = match (p.mass, p.density) {
        (_, Some(rho)) => ("particles.density", rho * area(a_min), rho * area(a_max)),
        (Some(m), None) => ("particles.mass", m, m),
        (None, None) => ("particles.radius", 1.0, (a_max / a_min).powi(2)),
    };
    for m in [lightest, heaviest] {
        if !(MIN_MAGNITUDE..=MAX_MAGNITUDE).contains(&m) {
            return Err(Error::input(
                field,
                format!(
                    "gives disks of mass {m:e}, outside the range [{MIN_MAGNITUDE:e}, {MAX_MAGNITUDE:e}] that double precision computes with"
                ),
            ));
        }
    }
    Ok(())
}

/// Mean disk area π⟨r²⟩ of the scene's radius law.
pub fn mean_disk_area(s: &Scenario) -> f64 {
    let pi = std::f64::consts::PI;
    match &s.particles.radius {
        Radius::Fixed(r) => pi * r * r,
        Radius::Uniform(u) => pi * (u.min * u.min + u.min * u.max + u.max * u.max) / 3.0,
        Radius::Species(list) => {
            let n = s.disk_count();
            list.species
                .iter()
                .map(|sp| sp.count as f64 * pi * sp.radius * sp.radius)
                .sum::<f64>()
                / n.max(1) as f64
        }
    }
}

/// Things a valid scenario asks for that are likely not what its author wants, each a sentence
/// for the user (the command line prints them as notes; they never stop a run).
pub fn advisories(s: &Scenario) -> Vec<String> {
    let mut notes = Vec::new();
    if let Some(note) = commensurate_row(s) {
        notes.push(note);
    }
    if let Some(note) = collapse_without_cure(s) {
        notes.push(note);
    }
    if let Some(note) = cutoff_in_a_deep_pile(s) {
        notes.push(note);
    }
    if let Some(note) = few_resolved_periods(s) {
        notes.push(note);
    }
    notes
}

/// Groups of four floor periods the window should resolve for the phase-resolved motion and the
/// bed's state to rest on more than a few periods.
const FEW_GROUPS: f64 = 2.0;

/// A vibrating floor under gravity whose window after the warm-up resolves fewer than
/// [`FEW_GROUPS`] groups of four floor periods at the scene's sample interval (the phase stops
/// are kept no more frequent than the samples).
fn few_resolved_periods(s: &Scenario) -> Option<String> {
    let floor = s.floor.as_ref()?;
    s.gravity?;
    floor.frequency.filter(|f| *f > 0.0)?;
    let period = floor.drive(s.gravity).period();
    let window = s.run.duration - s.run.warmup;
    if !floor.vibrates() || window <= 0.0 {
        return None;
    }
    let bins = s.output.phase_bins;
    let stride = stride(bins, s.sample_interval(), period);
    let groups = (window / period / (GROUP as f64 * stride as f64)).floor();
    (groups < FEW_GROUPS).then(|| {
        format!(
            "the window after the warm-up ({window} time units) resolves {groups} group(s) of \
             four floor periods at this sample interval ({}): the phase table and the bed's \
             state rest on few periods, and with none resolved no state but `solid` is \
             given; output.sample_interval = {} or less resolves every period",
            s.sample_interval(),
            period / bins as f64
        )
    })
}

/// Whether the scene's bed can come to rest: gravity, and a floor that never pulls away
/// faster than gravity (static, or Γ < 1).
fn can_rest(s: &Scenario) -> bool {
    let (Some(floor), Some(g)) = (s.floor.as_ref(), s.gravity.filter(|&g| g > 0.0)) else {
        return false;
    };
    floor
        .gamma
        .unwrap_or_else(|| floor.drive(s.gravity).gamma(g))
        < 1.0
}

/// Fewest disks the collapse advisory calls a bed.
const BED: usize = 10;

/// A bed that can come to rest, with inelastic collisions and no cure of inelastic collapse (the
/// exact engine's; the other schemes have no collapse, the hybrid scheme TC by default):
/// as it settles, dense regions may collide infinitely often in finite time (100-disk piles
/// poured with e ≤ 0.5 and no cure all collapsed in flight, during the pour).
fn collapse_without_cure(s: &Scenario) -> Option<String> {
    let law = s.collisions.law();
    let bed = s.disk_count() >= BED;
    let cured = law.cured() || s.scheme() != Scheme::EventDriven;
    if !bed || !can_rest(s) || !law.inelastic() || cured {
        return None;
    }
    Some(format!(
        "collisions.restitution = {} with no cure of inelastic collapse: a bed settling on the \
         floor may collapse (infinitely many collisions in finite time) before it comes to \
         rest, and the run then ends at run.max_events; collisions.tc (10⁻³ √(d/g) is a good \
         start) lets it settle, and engine.scheme = \"hybrid\" also runs a dense bed (riding \
         or resting on the floor) at a fixed cost",
        law.e
    ))
}

/// Fewest layers (disks × mean diameter / width) the speed-cutoff advisory calls a deep pile.
const DEEP: f64 = 15.0;

/// A deep pile that can come to rest, its collapse cured by the speed cutoff: collisions slower
/// than v_min are elastic, so motion between the sleep speed (≈ 10⁻³ √(g a), below which
/// disks come to rest) and v_min is never dissipated: piles about 20 layers deep may rattle
/// until the event limit, where TC settles them (the book's speed-cutoff page).
fn cutoff_in_a_deep_pile(s: &Scenario) -> Option<String> {
    let law = s.collisions.law();
    let v_min = law.speed_cutoff?;
    let (a_min, a_max) = s.radius_range();
    let layers = s.disk_count() as f64 * (a_min + a_max) / s.domain.width;
    if !can_rest(s) || !law.inelastic() || law.tc.is_some() || layers < DEEP {
        return None;
    }
    Some(format!(
        "collisions.speed_cutoff = {v_min} in a pile about {layers:.0} layers deep: collisions \
         slower than the cutoff are elastic, so the pile may keep rattling at speeds between \
         the sleep speed (≈ 10⁻³ √(g a)) and the cutoff and never come to rest (the run then \
         ends at run.max_events); collisions.tc (10⁻³ √(d/g)) settles deep piles"
    ))
}

/// A bed that can come to rest (static floor or Γ < 1, with gravity), of equal disks, in a
/// width of exactly a whole number of diameters: a bottom row fills it with no room to spare,
/// and hard disks pressed into such a row collide ever more often (an exact jam).
fn commensurate_row(s: &Scenario) -> Option<String> {
    if !can_rest(s) {
        return None;
    }
    let (a_min, a_max) = s.radius_range();
    if a_min != a_max {
        return None;
    }
    let per_row = s.domain.width / (2.0 * a_min);
    let whole = per_row.round();
    if whole < 1.0 || (per_row - whole).abs() > 1e-9 * whole || s.disk_count() < whole as usize {
        return None;
    }
    Some(format!(
        "domain.width = {} is exactly {whole} disk diameters: rows fill it with no room to \
         spare; a row at rest is held rigid, but a full row that has not come to rest rings ever \
         faster in deep beds (the run may end at run.max_events); a width slightly off a whole \
         number of diameters (e.g. {}) avoids this exact jam",
        s.domain.width,
        s.domain.width + 0.3 * 2.0 * a_min
    ))
}
