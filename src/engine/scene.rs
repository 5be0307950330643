//! A scenario resolved into what the engine needs: boundaries, floor, collision law, and the
//! initial disks (radii, masses, positions, velocities) drawn from the scenario's seed.

use crate::engine::placement::{self, Region};
use crate::engine::pool::{InletPlan, Newcomers};
use crate::error::{Error, Result};
use crate::physics::disks::{Disks, Spins};
use crate::physics::floor::Floor;
use crate::physics::restitution::Restitution;
use crate::physics::rough::{Friction, Roughness};
use crate::physics::walls::{SideBounds, Top};
use crate::platform::cpu::Lanes;
use crate::scenario::checks::mean_disk_area;
use crate::scenario::{
    GridChoice, MaskChoice, Placement, PlacementKind, QueueChoice, Radius, RemapChoice,
    RenumberChoice, Scenario, XBoundary, YBoundary,
};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Default packing fraction of the initial bed under an open top.
pub const DEFAULT_BED_PACKING: f64 = 0.5;

/// Everything about a scene except the disks.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Scene name.
    pub name: String,
    /// Side boundaries.
    pub sides: SideBounds,
    /// Top boundary.
    pub top: Top,
    /// The floor, if any.
    pub floor: Option<Floor>,
    /// Gravity, if any.
    pub gravity: Option<f64>,
    /// Pair restitution, made elastic by the cures of inelastic collapse that are on.
    pub restitution: Restitution,
    /// Disks landing gently on disks at rest come to rest on them.
    pub resting_contacts: bool,
    /// The tangential laws of rough disks; `None` for smooth ones.
    pub rough: Option<Roughness>,
    /// Neighbour mask choice.
    pub mask: MaskChoice,
    /// Grid storage choice.
    pub grid: GridChoice,
    /// `global` or `local` (`auto` resolved for the scene).
    pub remap: RemapChoice,
    /// Event queue choice.
    pub queue: QueueChoice,
    /// The vector path of the hot loops: the process's ([`Lanes::found`]); the tests choose.
    pub lanes: Lanes,
    /// Whether the engine renumbers its disks (see [`RenumberChoice`]).
    pub renumber: RenumberChoice,
    /// Packing fraction of the box, or of the initial bed under an open top (guides `auto`).
    pub packing: f64,
    /// Neighbour-list skin (DUTC margin) in units of the smallest radius; `None`: all the mask
    /// allows.
    pub skin: Option<f64>,
    /// Invariant checks on.
    pub check_invariants: bool,
    /// Event budget.
    pub max_events: Option<u64>,
    /// The floor's orifice, if any: disks leave through it.
    pub orifice: Option<crate::physics::orifice::Orifice>,
    /// Under an open top, the height at which a rising disk's centre leaves the scene.
    pub exit_height: Option<f64>,
    /// The warm-up's end (the flow rate counts exits from then on).
    pub warmup: f64,
    /// The inlets, resolved.
    pub inlets: Vec<crate::engine::pool::InletPlan>,
    /// The sizes of the disks the inlets bring, in the order of their ids.
    pub newcomers: Newcomers,
    /// Rough disks start and enter spinning at this rotational temperature.
    pub rotational_temperature: f64,
    /// The scenario's seed (entering disks draw from it).
    pub seed: u64,
}

impl Scene {
    /// Resolves a validated scenario into a scene and its initial disks.
    pub fn build(s: &Scenario) -> Result<(Scene, Disks)> {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(s.seed);
        let n = s.disk_count();
        let (radius, mass, species) = sizes(s, &mut rng);
        let width = s.domain.width;
        let height = match (s.domain.y_boundary, s.domain.height) {
            (YBoundary::Open, _) => None,
            (_, Some(h)) => Some(h),
            (_, None) => {
                let phi = s.particles.packing_fraction.expect("validated");
                Some(n as f64 * mean_disk_area(s) / (phi * width))
            }
        };
        let (sides, top) = bounds(s, height);
        let floor = s
            .floor
            .as_ref()
            .map(|f| Floor::new(f.restitution, f.drive(s.gravity), f.phase));
        let floor_top = s.floor_amplitude();
        let positions = positions(s, &radius, height, floor_top, &mut rng)?;
        let mut disks = Disks::new(&positions, radius, mass, species);
        let velocities = match &s.particles.placement {
            Placement::Explicit(e) if e.velocities.is_some() => e.velocities.clone().unwrap(),
            _ => placement::thermal_velocities(
                &disks.mass.to_vec(),
                s.particles.temperature,
                &mut rng,
            ),
        };
        for (i, v) in velocities.iter().enumerate() {
            disks.motion[i].vx = v[0];
            disks.motion[i].vy = v[1];
        }
        debug_assert_eq!(disks.len(), n);
        below_exit(s.domain.exit_height, &disks)?;
        if s.is_rough() {
            disks.spins = Some(spins(s, &disks, &mut rng));
        }
        let inlets = inlet_plans(s, n);
        // Drawn after the initial state, which stays the scene's without inlets.
        let newcomers = newcomers(s, &inlets, &mut rng);
        let scene = Scene {
            name: s.name.clone(),
            sides,
            top,
            floor,
            gravity: s.gravity,
            restitution: s.collisions.law(),
            resting_contacts: s.collisions.resting_contacts,
            rough: rough_laws(s),
            mask: s.engine.mask,
            grid: s.engine.grid,
            lanes: Lanes::found(),
            remap: s
                .engine
                .remap
                .resolve(matches!(top, Top::Open) && s.gravity.is_some_and(|g| g > 0.0)),
            queue: s.engine.queue,
            renumber: s.engine.renumber,
            packing: match height {
                Some(h) => n as f64 * mean_disk_area(s) / (width * h),
                None => s.particles.packing_fraction.unwrap_or(DEFAULT_BED_PACKING),
            },
            skin: s.engine.skin,
            check_invariants: s.engine.check_invariants,
            max_events: s.run.max_events,
            orifice: s.floor.as_ref().and_then(|f| f.orifice).map(|o| {
                crate::physics::orifice::Orifice {
                    from: o.from,
                    to: o.to,
                }
            }),
            exit_height: s.domain.exit_height,
            warmup: s.run.warmup,
            inlets,
            newcomers,
            rotational_temperature: s.particles.rotational_temperature.unwrap_or(0.0),
            seed: s.seed,
        };
        Ok((scene, disks))
    }
}

/// Refuses an exit height that the initial bed reaches: every disk must start wholly below it
/// (one that starts there would leave at once, or above it never).
fn below_exit(exit_height: Option<f64>, disks: &Disks) -> Result<()> {
    let Some(h) = exit_height else {
        return Ok(());
    };
    for (i, (m, a)) in disks.motion.iter().zip(disks.radius.iter()).enumerate() {
        if m.y + a >= h {
            return Err(Error::input(
                "domain.exit_height",
                format!(
                    "{h} must lie above the initial bed: disk {i} reaches {} (its centre {} and \
                     its radius)",
                    m.y + a,
                    m.y
                ),
            ));
        }
    }
    Ok(())
}

/// The tangential laws of a rough scenario (`None` for smooth disks).
fn rough_laws(s: &Scenario) -> Option<Roughness> {
    s.is_rough().then(|| Roughness {
        pair: Friction::of(s.collisions.tangential_restitution, s.collisions.friction),
        floor: s.floor.as_ref().map_or(Friction::SMOOTH, |f| {
            Friction::of(f.tangential_restitution, f.friction)
        }),
        walls: Friction::of(s.domain.wall_tangential_restitution, s.domain.wall_friction),
        inertia_factor: s.particles.inertia_factor.unwrap_or(DEFAULT_INERTIA_FACTOR),
    })
}

/// The initial spins of rough disks: normal with variance `T_rot / I`, scaled so that
/// `Σ I ω² = N T_rot` exactly (drawn after everything else, so the rest of the state is the
/// smooth scene's).
fn spins(s: &Scenario, disks: &Disks, rng: &mut Xoshiro256PlusPlus) -> Spins {
    let q = s.particles.inertia_factor.unwrap_or(DEFAULT_INERTIA_FACTOR);
    let t_rot = s.particles.rotational_temperature.unwrap_or(0.0);
    let inertia: Vec<f64> = (0..disks.len())
        .map(|k| q * disks.mass[k] * disks.radius[k] * disks.radius[k])
        .collect();
    let mut omega: Vec<f64> = inertia
        .iter()
        .map(|i| placement::gaussian(rng) * (t_rot / i).sqrt())
        .collect();
    let sum: f64 = omega.iter().zip(&inertia).map(|(w, i)| i * w * w).sum();
    if sum > 0.0 {
        let scale = (disks.len() as f64 * t_rot / sum).sqrt();
        omega.iter_mut().for_each(|w| *w *= scale);
    }
    Spins::new(q, omega)
}

/// `q` in `I = q m a²` unless the scenario says: a uniform disk.
pub const DEFAULT_INERTIA_FACTOR: f64 = 0.5;

/// The side walls (or x period) and the lid (or y period, or an open top) of scenario `s` with
/// its domain `height` (`None`: open).
fn bounds(s: &Scenario, height: Option<f64>) -> (SideBounds, Top) {
    let width = s.domain.width;
    let sides = match s.domain.x_boundary {
        XBoundary::Walls => SideBounds::Walls {
            width,
            e: s.domain.wall_restitution,
        },
        XBoundary::Periodic => SideBounds::Periodic { width },
    };
    let top = match s.domain.y_boundary {
        YBoundary::Open => Top::Open,
        YBoundary::Lid => Top::Lid {
            height: height.expect("closed"),
            e: s.domain.wall_restitution,
        },
        YBoundary::Periodic => Top::Periodic {
            height: height.expect("closed"),
        },
    };
    (sides, top)
}

/// The disks' initial centres: the scenario's, or placed in rows in the domain (melted for
/// `random`) above the floor's highest point `floor_top`.
fn positions(
    s: &Scenario,
    radius: &[f64],
    height: Option<f64>,
    floor_top: f64,
    rng: &mut Xoshiro256PlusPlus,
) -> Result<Vec<[f64; 2]>> {
    let (n, width) = (s.disk_count(), s.domain.width);
    let positions = match &s.particles.placement {
        Placement::Explicit(e) => e.positions.clone(),
        Placement::Kind(kind) => {
            let (y0, y1, fill) = match height {
                Some(h) if s.domain.y_boundary == YBoundary::Periodic => (0.0, h, h),
                Some(h) => (floor_top, h, h - floor_top),
                None => {
                    let phi = s.particles.packing_fraction.unwrap_or(DEFAULT_BED_PACKING);
                    let bed = n as f64 * mean_disk_area(s) / (phi * width);
                    (floor_top, f64::INFINITY, bed)
                }
            };
            if fill <= 0.0 {
                return Err(Error::input(
                    "domain.height",
                    "leaves no room above the floor's highest position",
                ));
            }
            let region = Region {
                x0: 0.0,
                x1: width,
                y0,
                y1,
                x_periodic: s.domain.x_boundary == XBoundary::Periodic,
                y_periodic: s.domain.y_boundary == YBoundary::Periodic,
            };
            let melt = *kind == PlacementKind::Random;
            match placement::place(radius, region, fill, melt, rng) {
                Ok(positions) => positions,
                // Under an open top the bed's height is only a start: a few disks in a wide
                // box fill less than a row, so the bed is raised until the rows hold them.
                Err(_) if height.is_none() => {
                    let mut fill = fill.max(2.0 * s.radius_range().1);
                    loop {
                        fill *= 1.25;
                        if let Ok(p) = placement::place(radius, region, fill, melt, rng) {
                            break p;
                        }
                        if fill > 4.0 * n as f64 * s.radius_range().1 {
                            return Err(Error::input(
                                "domain.width",
                                "is too narrow for a row of the largest disks",
                            ));
                        }
                    }
                }
                Err(e) => return Err(e),
            }
        }
    };
    Ok(positions)
}

/// The inlets' plans, their new disks numbered from `n` (the disks at the start) inlet after
/// inlet.
fn inlet_plans(s: &Scenario, n: usize) -> Vec<InletPlan> {
    let mut first_id = n as u64;
    s.inlets
        .iter()
        .map(|i| {
            let plan = inlet_plan(i, s.run.duration, first_id);
            first_id += plan.total;
            plan
        })
        .collect()
}

/// The radius, mass and species of each disk the inlets bring, drawn from each inlet's
/// radius law (a species list's counts are the odds of each species, numbered in that list).
fn newcomers(s: &Scenario, plans: &[InletPlan], rng: &mut Xoshiro256PlusPlus) -> Newcomers {
    let mut new = Newcomers::default();
    for (inlet, plan) in s.inlets.iter().zip(plans) {
        let law = s.inlet_radius(inlet);
        for _ in 0..plan.total {
            let (a, species, species_mass) = draw_radius(law, rng);
            new.radius.push(a);
            new.mass.push(s.inlet_mass(inlet, a, species_mass));
            new.species.push(species);
        }
    }
    new
}

/// One radius from `law` (a draw only where it is not a single number): with its species and
/// that species' mass, if any.
fn draw_radius(law: &Radius, rng: &mut Xoshiro256PlusPlus) -> (f64, u32, Option<f64>) {
    match law {
        Radius::Fixed(r) => (*r, 0, None),
        Radius::Uniform(u) => (u.min + (u.max - u.min) * rng.random::<f64>(), 0, None),
        Radius::Species(list) => {
            let total: usize = list.species.iter().map(|sp| sp.count).sum();
            let mut pick = (rng.random::<f64>() * total as f64) as usize;
            let k = list
                .species
                .iter()
                .position(|sp| {
                    let this = pick < sp.count;
                    pick = pick.saturating_sub(sp.count);
                    this
                })
                .unwrap_or(list.species.len().saturating_sub(1));
            let sp = &list.species[k];
            (sp.radius, k as u32, sp.mass)
        }
    }
}

/// An inlet's box and schedule: `count` disks spread evenly over `[start, end)`, or one every
/// 1/`rate` from `start` while before `end` (the run's end when absent); its new disks take
/// the ids from `first_id` on.
fn inlet_plan(i: &crate::scenario::Inlet, duration: f64, first_id: u64) -> InletPlan {
    let end = i.end.unwrap_or(duration);
    let window = end - i.start;
    let (period, total) = match (i.rate, i.count) {
        (Some(r), _) => (1.0 / r, (r * window).ceil() as u64),
        (None, Some(n)) => (window / n as f64, n),
        (None, None) => (f64::INFINITY, 0),
    };
    InletPlan {
        x0: i.x.from,
        x1: i.x.to,
        y0: i.y.from,
        y1: i.y.to,
        start: i.start,
        period,
        total,
        speed: i.speed,
        temperature: i.temperature,
        recycle: i.recycle,
        first_id,
        next: 0,
    }
}

/// Radii, masses and species of every disk.
fn sizes(s: &Scenario, rng: &mut Xoshiro256PlusPlus) -> (Vec<f64>, Vec<f64>, Vec<u32>) {
    let p = &s.particles;
    let n = s.disk_count();
    let (radius, species, species_mass): (Vec<f64>, Vec<u32>, Vec<Option<f64>>) = match &p.radius {
        Radius::Fixed(r) => (vec![*r; n], vec![0; n], vec![None; n]),
        Radius::Uniform(u) => (
            (0..n)
                .map(|_| u.min + (u.max - u.min) * rng.random::<f64>())
                .collect(),
            vec![0; n],
            vec![None; n],
        ),
        Radius::Species(list) => {
            let mut r = Vec::with_capacity(n);
            let mut sp = Vec::with_capacity(n);
            let mut m = Vec::with_capacity(n);
            for (k, species) in list.species.iter().enumerate() {
                for _ in 0..species.count {
                    r.push(species.radius);
                    sp.push(k as u32);
                    m.push(species.mass);
                }
            }
            (r, sp, m)
        }
    };
    let mass = radius
        .iter()
        .zip(&species_mass)
        .map(|(&a, &m)| s.particle_mass(a, m))
        .collect();
    (radius, mass, species)
}
