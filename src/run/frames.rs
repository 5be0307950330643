//! What the frames show, made of the engine at a stop: every disk (spread by id where disks
//! leave), and for the recording's frames the time series, the live profiles and the live 2D
//! fields; the trajectory's frames hold the disks alone.

use super::averages::field_grid;
use super::views::StatesAt;
use crate::engine::{Scene, Snapshot};
use crate::measure::fields::Fields;
use crate::measure::{Observables, Profiles};
use crate::output::frame::{frame_series, spread_by_id, FrameView};
use crate::scenario::Scenario;
use crate::schemes::Integrator;

/// What the recording's frames carry from one frame to the next.
pub(super) struct Frames {
    /// The collisions counted at the last frame (the rate is taken since).
    pub(super) last_collisions: u64,
    /// The live fields (`output.record_fields`) and the factor by which they forget their past
    /// at each frame.
    live_fields: Option<(Fields, f64)>,
    /// Gravity, for the potential energy (0 without).
    g: f64,
}

impl Frames {
    /// The frames of a run of `sim` from its start, `frame_dt` apart; `live`: whether the live
    /// fields are shown (asked for, and some output takes the frames).
    pub(super) fn new<E: Integrator>(
        (s, scene): (&Scenario, &Scene),
        sim: &E,
        frame_dt: f64,
        live: bool,
    ) -> Frames {
        let live_fields = (live && s.output.record_fields)
            .then(|| field_grid(s, scene, &StatesAt(sim, 0.0), sim.disks()))
            .flatten()
            .map(|grid| (Fields::new(grid), forget_factor(scene, frame_dt)));
        Frames {
            last_collisions: 0,
            live_fields,
            g: scene.gravity.unwrap_or(0.0),
        }
    }

    /// Frame `k` (from 1, `frame_dt` after the last) of `sim`'s disks in `snap`, with the time
    /// series, the live profiles of `profiles` and the live fields, handed to `give`
    /// (`scene_ids`: how many ids the scene gives out, where disks leave).
    pub(super) fn frame<E: Integrator>(
        &mut self,
        (sim, snap): (&E, &Snapshot),
        profiles: Option<&Profiles>,
        (k, frame_dt): (u64, f64),
        scene_ids: usize,
        give: impl FnOnce(&FrameView),
    ) {
        let o = Observables::of(snap, sim.disks(), self.g);
        let collisions = sim.counts().collisions();
        let rate = (collisions - self.last_collisions) as f64 / frame_dt;
        self.last_collisions = collisions;
        let series = frame_series(
            &o,
            &sim.energy_flow_at(snap.time),
            if k > 1 { rate } else { 0.0 },
            sim.rotational_energy(snap.time),
            sim.flow().map(|f| (snap.x.len() as f64, f.left as f64)),
        );
        let spins = sim.spins_at(snap.time);
        let d = sim.disks();
        let profile = profiles.map(|p| p.of_instant(snap, d));
        let (radius, species) = (d.radius.to_vec(), d.species.to_vec());
        if let Some((f, forget)) = self.live_fields.as_mut() {
            f.decay(*forget);
            f.add(snap, d);
        }
        // Where disks leave, instance i of the recording stays disk i: every id has an entry,
        // those not in the scene drawn nowhere (no position, radius 0).
        let by_id =
            (!snap.ids.is_empty()).then(|| spread_by_id(snap, &radius, &species, scene_ids));
        let (snap, radius, species) = match &by_id {
            Some((s, r, k)) => (s, r, k),
            None => (snap, &radius, &species),
        };
        let mut view = FrameView::of(
            k - 1,
            snap,
            (radius, species),
            (&series, profile.as_ref()),
            spins.as_deref(),
        );
        view.fields = self.live_fields.as_ref().map(|(f, _)| f);
        give(&view);
    }
}

/// Trajectory frame `k` (from 1) of `sim`'s disks in `snap`: the disks alone, handed to `give`.
pub(super) fn trajectory_frame<E: Integrator>(
    (sim, snap): (&E, &Snapshot),
    k: u64,
    give: impl FnOnce(&FrameView),
) {
    let d = sim.disks();
    let (radius, species) = (d.radius.to_vec(), d.species.to_vec());
    let spins = sim.spins_at(snap.time);
    let view = FrameView::of(
        k - 1,
        snap,
        (&radius, &species),
        (&[], None),
        spins.as_deref(),
    );
    give(&view);
}

/// The factor by which the recording's live fields forget their past at each frame, `frame_dt`
/// apart: e^(−frame_dt / period), an exponential running average over one floor period; 0 (the
/// frame alone) without a vibrating floor.
fn forget_factor(scene: &Scene, frame_dt: f64) -> f64 {
    match &scene.floor {
        Some(f) if !f.is_static() => (-frame_dt / f.period_or_one()).exp(),
        _ => 0.0,
    }
}
