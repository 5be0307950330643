//! The variants the accuracy report runs against the reference, in table order: the exact engine
//! re-run on the same seeds, the approximate schemes with a sweep of their step, the other floor
//! models, the cures of inelastic collapse, the scene without resting contacts, and recording.

use super::ensemble::Ensemble;
use super::fmt_g;
use crate::engine::Scene;
use crate::physics::disks::Disks;
use crate::physics::drive::{FloorModel, Waveform};
use crate::scenario::Scenario;
use crate::schemes::time_step;

/// A variant: a family, a label and the overrides that make it.
#[derive(Debug, Clone)]
pub(super) struct Variant {
    /// The family it is drawn and grouped with (`reference`, `time-step`, `floor`, …).
    pub(super) family: &'static str,
    /// What was changed, in words.
    pub(super) label: String,
    /// The `--set` overrides applied to the reference scenario.
    pub(super) sets: Vec<String>,
    /// Whether its runs record frames.
    pub(super) record: bool,
}

impl Variant {
    /// A variant that does not record.
    pub(super) fn new(family: &'static str, label: impl Into<String>, sets: &[String]) -> Variant {
        Variant {
            family,
            label: label.into(),
            sets: sets.to_vec(),
            record: false,
        }
    }
}

/// What the variants are chosen from: the reference scene and what its exact runs measured.
pub(super) struct Basis<'a> {
    /// The reference scenario (exact engine, no recording).
    pub(super) reference: &'a Scenario,
    /// The reference scene and disks, as built.
    pub(super) scene: &'a Scene,
    pub(super) disks: &'a Disks,
    /// The exact engine's ensemble (its collision rate and temperature set the dissipation
    /// variants' scales).
    pub(super) exact: &'a Ensemble,
    /// Fewer sweep points.
    pub(super) quick: bool,
    /// Threads the approximate schemes run on.
    pub(super) cores: usize,
    /// The scenario's `engine.strips`, which the space-time variants keep.
    pub(super) strips: Option<u64>,
}

/// Every variant, in table order.
pub(super) fn all(b: &Basis) -> Vec<Variant> {
    let mut variants = vec![Variant::new("reference", "exact, re-run same seeds", &[])];
    variants.extend(time_step_sweep(b));
    variants.extend(space_time_sweep(b));
    variants.extend(floor_models(b.scene));
    if b.scene.restitution.inelastic() {
        variants.extend(collapse_cures(b));
    }
    if b.scene.floor.is_some() && b.reference.collisions.resting_contacts {
        // What resting contacts buy where a bed comes to rest: the same scene without them.
        variants.push(Variant::new(
            "resting",
            "resting contacts off",
            &["collisions.resting_contacts=false".into()],
        ));
    }
    let mut rec = Variant::new("recording", "recording frames on", &[]);
    rec.record = true;
    variants.push(rec);
    variants
}

/// Sweep factors of a scheme's step.
fn sweep(quick: bool) -> Vec<(f64, &'static str)> {
    if quick {
        vec![(2.0, "×2"), (1.0, "×1"), (0.5, "×½")]
    } else {
        vec![
            (4.0, "×4"),
            (2.0, "×2"),
            (1.0, "×1"),
            (0.5, "×½"),
            (0.25, "×¼"),
        ]
    }
}

/// The time-step scheme around its default step (none where the scene has no default step), on
/// the report's cores.
fn time_step_sweep(b: &Basis) -> Vec<Variant> {
    let Some(dt0) = time_step::default_dt(b.scene, b.disks) else {
        return Vec::new();
    };
    sweep(b.quick)
        .into_iter()
        .map(|(f, name)| {
            let dt = dt0 * f;
            Variant::new(
                "time-step",
                format!("dt = {} ({name})", fmt_g(dt)),
                &[
                    "engine.scheme=time-step".into(),
                    format!("engine.dt={dt:e}"),
                    format!("engine.threads={}", b.cores),
                ],
            )
        })
        .collect()
}

/// The space-time scheme around its default synchronisation distance (labelled in diameters),
/// on the report's cores.
fn space_time_sweep(b: &Basis) -> Vec<Variant> {
    let (a_min, _) = b.disks.radius_range();
    let diameter = 2.0 * a_min;
    sweep(b.quick)
        .into_iter()
        .map(|(f, name)| {
            let d = crate::schemes::space_time::DEFAULT_SYNC_DISTANCE * f;
            let mut sets = vec![
                "engine.scheme=space-time".into(),
                format!("engine.sync_distance={d:e}"),
                format!("engine.threads={}", b.cores),
            ];
            sets.extend(b.strips.map(|k| format!("engine.strips={k}")));
            Variant::new(
                "space-time",
                format!("D = {} d ({name})", fmt_g(d * a_min / diameter)),
                &sets,
            )
        })
        .collect()
}

/// The floor models other than the scene's own (none unless the floor vibrates).
fn floor_models(scene: &Scene) -> Vec<Variant> {
    let Some(floor) = scene.floor.as_ref().filter(|f| !f.is_static()) else {
        return Vec::new();
    };
    let models = [
        (Waveform::Sine, FloorModel::Exact, "exact sine"),
        (
            Waveform::Sine,
            FloorModel::FixedPosition,
            "fixed-position sine",
        ),
        (Waveform::Triangle, FloorModel::Exact, "triangle wave"),
    ];
    models
        .into_iter()
        .filter(|&(w, m, _)| (w, m) != (floor.drive().waveform, floor.drive().model))
        .map(|(w, m, name)| {
            let w_name = match w {
                Waveform::Sine => "sine",
                Waveform::Triangle => "triangle",
                Waveform::Sawtooth => "sawtooth",
            };
            let m_name = match m {
                FloorModel::Exact => "exact",
                FloorModel::FixedPosition => "fixed-position",
            };
            Variant::new(
                "floor",
                format!("floor: {name}"),
                &[
                    format!("floor.waveform={w_name}"),
                    format!("floor.model={m_name}"),
                ],
            )
        })
        .collect()
}

/// The cures of inelastic collapse: TC with a contact time that is a fraction of the mean time
/// between a disk's collisions, and a speed cutoff that is a fraction of the thermal speed.
fn collapse_cures(b: &Basis) -> Vec<Variant> {
    // Scales: the mean time between a disk's collisions, and the thermal speed.
    let pair_rate = b.exact.scalar(|m| Some(m.collision_rate)).unwrap_or(0.0);
    let n = b.reference.disk_count() as f64;
    let tau = if pair_rate > 0.0 {
        n / (2.0 * pair_rate)
    } else {
        1.0
    };
    let v_th = b
        .exact
        .scalar(|m| Some(m.temperature))
        .unwrap_or(1.0)
        .max(0.0)
        .sqrt();
    let factors: &[f64] = if b.quick {
        &[1e-2]
    } else {
        &[1e-3, 1e-2, 1e-1]
    };
    let mut variants = Vec::new();
    for &f in factors {
        let tc = f * tau;
        variants.push(Variant::new(
            "dissipation",
            format!("TC t_c = {} (τ_coll×{f})", fmt_g(tc)),
            &[format!("collisions.tc={tc:e}")],
        ));
    }
    // A bed at rest has no thermal speed to scale a cutoff with.
    for &f in factors.iter().filter(|_| v_th > 0.0) {
        let v = f * v_th;
        variants.push(Variant::new(
            "dissipation",
            format!("speed cutoff {} (v_T×{f})", fmt_g(v)),
            &[format!("collisions.speed_cutoff={v:e}")],
        ));
    }
    variants
}
