//! What ends the sequences a bed coming to rest would otherwise ring in for ever, each a
//! rule of the resting contacts (`collisions.resting_contacts`, see
//! [`resting`](crate::engine::rest::resting)) but the pressed slider, a rule of the slide on
//! the floor, each in a file of its own with its test (the hard case where it engages:
//! [`JamCounts`](crate::engine::JamCounts) counts each rule):
//!
//! - [`slot`](slot.rs): a slot between supports at rest that do not give;
//! - [`cluster`](cluster.rs): a jammed cluster of slow flying disks that only hold as a whole;
//! - [`jammed_row`](jammed_row.rs): a jammed row, disks at rest side by side from wall to
//!   wall, hit level;
//! - [`gentle_push`](gentle_push.rs): a gentle push on a disk at rest;
//! - [`held`](held.rs): what those two share, a flying disk meeting a disk at rest that does
//!   not give;
//! - [`pocket`](pocket.rs): a pocket by a side wall, where a frictionless disk slides to the
//!   wall and back;
//! - [`zeno`](zeno.rs): a closed wedge, or disks ringing in gaps of round-off, where a flying
//!   disk has events at one instant without end;
//! - [`floor_room`](floor_room.rs): a slot on the floor a hair too narrow, left by a row of
//!   disks that came to rest a hair apart, where a disk would stay wedged above the floor and
//!   tilt every column above it;
//! - [`full_rows`](full_rows.rs): a full row of flying disks seated on a row at rest, and a
//!   full row on the floor, each with no play but round-off, ringing sideways between the walls;
//! - [`pressed_slider`](pressed_slider.rs): a disk sliding on a rough floor pressed gently
//!   into another, which rolls at once.

mod cluster;
mod floor_room;
mod full_rows;
mod gentle_push;
mod held;
mod jammed_row;
mod pocket;
mod pressed_slider;
mod slot;
mod zeno;

use crate::engine::rest::resting::HAIR;
use crate::physics::floor::Floor;

/// A slot whose two contact normals sum to less than this (they are within ~6° of opposite)
/// stops a disk moving deeper into it (see `stop_in_slot`).
pub const WEDGE: f64 = 0.1;

/// A slot whose two contact normals sum to less than this (within ~0.06° of opposite) has no
/// deeper end: a disk that bounces across it between supports that do not slide, barely moving
/// along it (slower than the sleep speed), would bounce at least ~π/10⁻³ times before it left,
/// either way (see `stop_in_slot`).
pub const PARALLEL: f64 = 1e-3;

/// More events than this for one flying disk at one instant stop it (see `stop_zeno`).
pub const ZENO: u32 = 64;

/// Events of one disk closer together than this many time units `√(a/g)` count as at one
/// instant (see `stop_zeno`): a disk at the sleep speed crosses 10⁻¹² radii in that time.
pub const INSTANT: f64 = 1e-9;

/// A flying disk within this many radii of the floor may be let down onto it (see
/// `room_on_floor`).
pub const WEDGE_DROP: f64 = 0.02;

/// The most, in radii of the landing disk, that a row of disks at rest on the floor is pushed
/// aside to make room for it (see `room_on_floor`): a [`HAIR`].
pub const ROOM: f64 = HAIR;

/// Round-off allowed when a row pushed aside fills the width exactly, in radii.
const TIGHT: f64 = 1e-12;

/// The longest row pushed aside (see `room_on_floor`).
const ROOM_ROW: usize = 64;

/// Whether a flying disk at `(sx, sy)` from a disk at rest meets it from above, or level within
/// a flat angle (rows at rest differ in height by round-off): a push that cannot lift the disk
/// at rest.
#[inline]
fn level(sx: f64, sy: f64) -> bool {
    sy >= -WEDGE_DROP * sx.abs()
}

/// Whether two disks meeting at `(dx, dy)` from one to the other meet side by side, level
/// within a flat angle: where a full row rings ([`full_rows`](full_rows.rs)).
#[inline]
fn side_by_side(dx: f64, dy: f64) -> bool {
    dy.abs() <= WEDGE_DROP * dx.abs()
}

/// How to let a disk down onto the floor (see `room_on_floor`): move the disks `shifts` in the
/// direction `dir` (±1 in x), each by its distance (the landing disk first, by a negative one:
/// away from the row), and lower the landing disk by `drop`.
pub(in crate::engine) struct Room {
    dir: f64,
    drop: f64,
    shifts: Vec<(u32, f64)>,
}

/// The square of [`INSTANT`] time units per unit radius, `INSTANT² / (g + h''_max)`, for disks
/// pressed by gravity `g` and the floor's largest acceleration (0, exactly one instant, if
/// nothing presses).
pub fn instant2(g: f64, floor: Option<&Floor>) -> f64 {
    let press = g + floor.map_or(0.0, |f| f.max_acceleration());
    if press > 0.0 {
        INSTANT * INSTANT / press
    } else {
        0.0
    }
}

/// What the rules' tests share: a hard case run to its end.
#[cfg(test)]
pub(super) mod tests {
    use crate::engine::{JamCounts, Progress, Scene, Simulation};
    use crate::physics::flight::Ballistic;
    use crate::scenario::Scenario;

    /// Runs the hard case `scenarios/hard/{file}` (with `--set` overrides `sets`) to its end,
    /// with the invariant checks on: the jam rules that engaged.
    pub(super) fn jams_in(file: &str, sets: &[&str]) -> JamCounts {
        run_hard_case(file, sets).jam_counts()
    }

    /// The engine after running the hard case `scenarios/hard/{file}` (with `--set` overrides
    /// `sets`) to its end, with the invariant checks on.
    pub(in crate::engine::rest) fn run_hard_case(
        file: &str,
        sets: &[&str],
    ) -> Simulation<Ballistic> {
        run_hard_case_to(file, sets).0
    }

    /// The engine after running the hard case `scenarios/hard/{file}` (with `--set` overrides
    /// `sets`) with the invariant checks on, and how the run ended: at its end, or on its event
    /// budget or the stall guard.
    pub(in crate::engine::rest) fn run_hard_case_to(
        file: &str,
        sets: &[&str],
    ) -> (Simulation<Ballistic>, Progress) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/hard")
            .join(file);
        let mut all = vec!["engine.check_invariants=true".to_string()];
        all.extend(sets.iter().map(|s| s.to_string()));
        let scenario = Scenario::load(&path, &all).expect("the hard case is valid");
        let (scene, disks) = Scene::build(&scenario).expect("scene builds");
        let g = scene.gravity.expect("the hard cases of rest have gravity");
        let mut sim = Simulation::new(Ballistic { g }, &scene, disks).expect("engine starts");
        let progress = sim
            .advance_to(scenario.run.duration)
            .expect("runs with the checks on");
        (sim, progress)
    }

    /// Every jam rule but the pressed slider is one of the resting contacts: without them none
    /// engages, in the cases where they engage (the pressed slider, for rough disks, has its
    /// own test).
    #[test]
    fn no_rule_engages_without_resting_contacts() {
        let off = "collisions.resting_contacts=false";
        for (file, sets) in [
            ("slot_a_hair_narrow.json", vec![off]),
            ("stack_gamma_1.2.json", vec![off]),
        ] {
            assert_eq!(jams_in(file, &sets), JamCounts::default(), "{file}");
        }
    }
}
