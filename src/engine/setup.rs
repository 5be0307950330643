//! Setting up the engine: the grid and mask for the scene, the initial checks and the first
//! mapping; and the switches a caller sets (interrupt, invariant checks, collision log).

use super::clock::Epoch;
use super::parts::{Bounds, Control, Events, Mapping, Rest, Tally};
use super::remap::dutc::Dutc;
use super::remap::numbering::{self, Numbering};
use super::remap::shells;
use super::rest::jams;
use super::rest::riders::{self, Riders};
use super::{Collision, Scene, Simulation, OVERLAP_TOLERANCE};
use crate::error::{Error, Result};
use crate::neighbours::{Cells, GridGeometry, Mask, NeighbourLists};
use crate::physics::disks::Disks;
use crate::physics::flight::Flight;
use crate::physics::restitution::CollisionLaw;
use crate::physics::walls::{SideBounds, Top};
use crate::scenario::{GridChoice, MaskChoice, RemapChoice};
use std::sync::atomic::AtomicBool;

/// Most cells a dense grid may hold (4 bytes each).
pub const MAX_DENSE_CELLS: u64 = 1 << 28;

/// Whether the grid is Isobe's hashed array: asked for, an open top, or (with `auto`) a closed
/// domain so sparse that a dense grid would hold more than 16 cells per disk (plus 2²⁰).
fn hashed_grid(choice: GridChoice, geometry: &GridGeometry, n: usize) -> Result<bool> {
    let Some(ny) = geometry.ny else {
        return Ok(true);
    };
    let dense_cells = geometry.nx as u64 * ny as u64;
    match choice {
        GridChoice::Hashed => Ok(true),
        GridChoice::Auto => Ok(dense_cells > 16 * n as u64 + (1 << 20)),
        GridChoice::Dense if dense_cells > MAX_DENSE_CELLS => Err(Error::input(
            "engine.grid",
            format!(
                "a dense grid of this box needs {dense_cells} cells, more than {MAX_DENSE_CELLS}: use `hashed` or `auto`"
            ),
        )),
        GridChoice::Dense => Ok(false),
    }
}

/// The domain's extent in y: the floor's lowest point, the lid or period (`None` for an open
/// top), and whether y is periodic.
#[derive(Clone, Copy)]
struct Span {
    bottom: f64,
    top: Option<f64>,
    y_periodic: bool,
}

/// The smallest and largest radius of the disks at the start and of those the inlets bring:
/// what the grid, the masks and the rules of rest are sized for.
fn radius_range(scene: &Scene, disks: &Disks) -> (f64, f64) {
    let (lo, hi) = disks.radius_range();
    let (new_lo, new_hi) = scene.newcomers.radius_range();
    (lo.min(new_lo), hi.max(new_hi))
}

/// Grid, mask and list margin of the local re-mapping: cells that hold a disk and its shell,
/// the 3 × 3 block around a disk as its mask.
fn local_grid(
    scene: &Scene,
    disks: &Disks,
    span: Span,
    shell_packing: f64,
) -> Result<(GridGeometry, Mask, f64)> {
    let (a_min, a_max) = radius_range(scene, disks);
    let n = disks.len();
    if scene.mask != MaskChoice::Auto {
        return Err(Error::input(
            "engine.mask",
            "a mask applies to the global re-mapping; the local one searches the 3 × 3 cells around a disk (set its shell with engine.skin)",
        ));
    }
    let a_rms = disks.rms_radius();
    let mut margin = shells::local_margin(scene.skin, a_min, a_rms, shell_packing, n);
    // A periodic direction needs three cells for the 3 × 3 block not to wrap onto
    // itself: narrow boxes get the shell that fits.
    let periods = [
        (
            "domain.width",
            matches!(scene.sides, SideBounds::Periodic { .. }),
            scene.sides.width(),
        ),
        (
            "domain.height",
            span.y_periodic,
            span.top.unwrap_or(f64::INFINITY) - span.bottom,
        ),
    ];
    for (field, periodic, span) in periods {
        if !periodic {
            continue;
        }
        margin = margin.min(span / 3.0 - 2.0 * a_max);
        if margin <= 0.0 {
            return Err(Error::input(
                field,
                format!("{span} is too small for the local re-mapping: a periodic span must exceed three diameters of the largest disk ({})", 6.0 * a_max),
            ));
        }
    }
    let geometry = GridGeometry::with_cell_at_least(
        2.0 * a_max + margin,
        scene.sides.width(),
        matches!(scene.sides, SideBounds::Periodic { .. }),
        span.bottom,
        span.top,
        span.y_periodic,
    );
    let mask = shells::block_mask();
    let margin = mask.reach() * geometry.cell() - 2.0 * a_max;
    Ok((geometry, mask, margin))
}

/// Grid, mask and list margin of Isobe's global re-mapping: cells of the smallest disk
/// (EEPGM), the mask chosen for the scene's sizes and packing.
fn global_grid(scene: &Scene, disks: &Disks, span: Span) -> Result<(GridGeometry, Mask, f64)> {
    let (a_min, a_max) = radius_range(scene, disks);
    let geometry = GridGeometry::new(
        a_min,
        scene.sides.width(),
        matches!(scene.sides, SideBounds::Periodic { .. }),
        span.bottom,
        span.top,
        span.y_periodic,
    );
    let mask = Mask::choose(scene.mask, geometry.cell(), a_min, a_max, scene.packing);
    let mask = mask.ok_or_else(|| {
        Error::input(
            "engine.mask",
            format!(
                "the mask does not reach beyond contact of the largest disks (radius {a_max}, cells of {:.4})",
                geometry.cell()
            ),
        )
    })?;
    let margin = mask.reach() * geometry.cell() - 2.0 * a_max;
    let margin = match scene.skin {
        Some(skin) => (skin * a_min).min(margin),
        None => margin,
    };
    Ok((geometry, mask, margin))
}

impl<F: Flight> Simulation<F> {
    /// Sets up the engine for `scene` with the disks in their initial state (all at time 0).
    pub fn new(flight: F, scene: &Scene, disks: Disks) -> Result<Simulation<F>> {
        let n = disks.len();
        let (a_min, a_max) = radius_range(scene, &disks);
        let floor = scene.floor.clone();
        let bottom = floor.as_ref().map_or(0.0, |f| f.lowest());
        // Disks falling through an orifice reach a radius below the floor before they leave.
        let bottom = if scene.orifice.is_some() {
            bottom - 2.0 * a_max
        } else {
            bottom
        };
        let (top_y, y_periodic) = match scene.top {
            Top::Open => (None, false),
            Top::Lid { height, .. } => (Some(height), false),
            Top::Periodic { height } => (Some(height), true),
        };
        let local = scene.remap == RemapChoice::Local;
        let shell_packing = shells::packing_for_shells(scene.packing, scene.floor.is_some());
        let span = Span {
            bottom,
            top: top_y,
            y_periodic,
        };
        let (geometry, mask, margin) = if local {
            local_grid(scene, &disks, span, shell_packing)?
        } else {
            global_grid(scene, &disks, span)?
        };
        geometry.check_mask_fits(mask.half_width)?;
        let shells = local.then(|| {
            let gravity = flight.g() != 0.0 || scene.floor.is_some();
            let ahead =
                shells::anchor_ahead(0.5 * margin, disks.rms_radius(), shell_packing, gravity);
            shells::Shells::new(n, 0.5 * margin, ahead)
        });
        let settled = flight.g() != 0.0 || scene.floor.is_some();
        let renumber_every = numbering::renumber_every(disks.rms_radius(), scene.packing, settled);
        // The calendar keeps events ahead for the event loop's pipeline of hints (local
        // re-mapping), and in the largest scenes under either re-mapping.
        let pipelining = (local && n >= crate::platform::prefetch::PIPELINE_FROM)
            || n >= crate::platform::prefetch::KEEP_AHEAD_FROM;
        let mut sim = Simulation {
            flight,
            disks,
            base: Epoch::default(),
            now: 0.0,
            events: Events::new(n, scene.queue, pipelining),
            map: Mapping {
                cells: Cells::for_geometry(
                    &geometry,
                    &mask,
                    hashed_grid(scene.grid, &geometry, n)?,
                    local,
                ),
                geometry,
                mask,
                lists: NeighbourLists::default(),
                margin,
                dutc: Dutc::new(0.0, 0.0, 0.0),
                shells,
                numbering: Numbering::new(scene.renumber, n, renumber_every),
            },
            bounds: Bounds {
                sides: scene.sides,
                top: scene.top,
                images: super::images::Images::of(scene.sides, scene.top),
                floor,
                orifice: scene.orifice,
                exit_height: scene.exit_height,
                outlets: scene.orifice.is_some() || scene.exit_height.is_some(),
            },
            restitution: CollisionLaw::new(scene.restitution, n),
            friction: scene.rough,
            rest: Rest::new(scene.resting_contacts),
            tally: Tally::default(),
            control: Control::new(scene, n, pipelining),
            pool: None,
        };
        if sim.bounds.outlets || !scene.inlets.is_empty() {
            let pool = super::pool::Pool::new(
                &sim.disks,
                scene.warmup,
                (&scene.inlets, &scene.newcomers),
                scene.rough.map(|_| scene.rotational_temperature),
                scene.seed,
            );
            let cap = pool.capacity();
            sim.pool = Some(Box::new(pool));
            sim.map.numbering.keep_ids(n);
            sim.map.numbering.reserve_to(cap);
            sim.disks.reserve_to(cap);
            let ev = &mut sim.events;
            ev.time.reserve_exact(cap + 1 - ev.time.len().min(cap + 1));
            ev.code.reserve_exact(cap - ev.code.len().min(cap));
            ev.counter.reserve_exact(cap - ev.counter.len().min(cap));
        }
        if sim.bounds.floor.is_some() {
            sim.rest.riders = Riders::new(n, riders::carried_room(a_min, a_max));
            if sim.floor_friction().is_some() {
                sim.rest.riders = std::mem::take(&mut sim.rest.riders).with_slides();
            }
            if let Some(pool) = &sim.pool {
                sim.rest.riders.reserve_to(pool.capacity());
            }
            if sim.rest.resting_contacts {
                sim.rest.same_instant = vec![(f64::NAN, 0); n];
                sim.rest.zeno_instant2 = jams::instant2(sim.flight.g(), sim.bounds.floor.as_ref());
            }
        }
        sim.check_initial_state()?;
        sim.remap().map_err(|e| match e {
            Error::Runtime(m) => Error::input("particles.placement", m),
            other => other,
        })?;
        sim.tally.counts.rebuild = 0;
        let (o, i, j) = sim.overlap_at(0.0);
        if o > OVERLAP_TOLERANCE * (sim.disks().radius[i] + sim.disks().radius[j]) {
            return Err(Error::input(
                "particles.placement",
                format!("disks {i} and {j} overlap by {o:e} at the start"),
            ));
        }
        sim.tally.max_overlap = o.max(0.0);
        Ok(sim)
    }

    /// Stop [`advance_to`](Self::advance_to) at the next event once `flag` is set (Ctrl-C).
    pub fn set_interrupt(&mut self, flag: &'static AtomicBool) {
        self.control.interrupt = Some(flag);
    }

    /// Stops [`advance_to`](Self::advance_to) with
    /// [`Progress::EventLimit`](super::Progress::EventLimit) once `limit` events (as
    /// `run.max_events` counts them) have been done since the start.
    pub fn set_event_limit(&mut self, limit: u64) {
        self.control.event_limit = limit;
    }

    /// Publishes the run's clock as `time` plus this engine's and `collisions` plus its own (a
    /// part of a run that began before it; see [`published_clock`](super::published_clock)).
    pub fn set_published_origin(&mut self, time: f64, collisions: u64) {
        self.control.published_origin = (time, collisions);
    }

    /// Starts (or stops) keeping a log of every collision, for comparison with the reference.
    pub fn set_logging(&mut self, on: bool) {
        self.control.log = on.then(Vec::new);
    }

    /// Takes the collisions logged so far.
    pub fn take_log(&mut self) -> Vec<Collision> {
        self.control
            .log
            .as_mut()
            .map(std::mem::take)
            .unwrap_or_default()
    }

    /// Switches the invariant checks on or off.
    pub fn set_checks(&mut self, on: bool) {
        self.control.check = on;
    }

    /// Refuses an initial state with overlaps beyond tolerance or disks outside the domain.
    pub(super) fn check_initial_state(&self) -> Result<()> {
        let d = &self.disks;
        for i in 0..d.len() {
            let (x, y, a) = (d.motion[i].x, d.motion[i].y, d.radius[i]);
            let tol = OVERLAP_TOLERANCE * a;
            if !(x.is_finite()
                && y.is_finite()
                && d.motion[i].vx.is_finite()
                && d.motion[i].vy.is_finite())
            {
                return Err(Error::input(
                    "particles.placement",
                    format!("disk {i} has a non-finite position or velocity"),
                ));
            }
            if let SideBounds::Walls { width, .. } = self.bounds.sides {
                if x < a - tol || x > width - a + tol {
                    return Err(Error::input(
                        "particles.placement",
                        format!("disk {i} at x = {x} crosses a side wall"),
                    ));
                }
            }
            if let Some(f) = &self.bounds.floor {
                if y - a < f.height(0.0) - tol {
                    return Err(Error::input(
                        "particles.placement",
                        format!("disk {i} at y = {y} is below the floor"),
                    ));
                }
            }
            if let Top::Lid { height, .. } = self.bounds.top {
                if y + a > height + tol {
                    return Err(Error::input(
                        "particles.placement",
                        format!("disk {i} at y = {y} is above the lid"),
                    ));
                }
            }
        }
        Ok(())
    }
}
