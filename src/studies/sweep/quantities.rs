//! What each summary field and sweep key means and its unit, in the scenario's units of length,
//! time and mass: the axis descriptions of the sweep's plot and of its state map.

/// What a field or sweep key means and its unit, in the scenario's units of length, time and
/// mass. A name ending in `.` stands for every field under it.
const QUANTITIES: [(&str, &str, &str); 34] = [
    ("drive.amplitude", "floor amplitude A", "length"),
    ("drive.frequency", "floor frequency f", "1/time"),
    ("drive.gamma", "Γ = Aω²/g", "dimensionless"),
    (
        "drive.peak_velocity",
        "peak floor velocity Aω",
        "length/time",
    ),
    ("floor.amplitude", "floor amplitude A", "length"),
    ("floor.frequency", "floor frequency f", "1/time"),
    ("floor.gamma", "Γ = Aω²/g", "dimensionless"),
    ("floor.restitution", "floor restitution", "dimensionless"),
    ("floor.phase", "floor phase", "rad"),
    ("collisions.restitution", "restitution e", "dimensionless"),
    ("collisions.tc", "TC duration", "time"),
    ("collisions.speed_cutoff", "speed cutoff", "length/time"),
    ("particles.count", "disks", "count"),
    ("particles", "disks", "count"),
    ("particles.radius", "disk radius", "length"),
    (
        "particles.packing_fraction",
        "packing fraction",
        "dimensionless",
    ),
    (
        "particles.temperature",
        "initial temperature",
        "mass·length²/time²",
    ),
    ("gravity", "gravity g", "length/time²"),
    ("domain.width", "width", "length"),
    ("domain.height", "height", "length"),
    ("run.duration", "duration", "time"),
    ("sim_time", "simulated time", "time"),
    ("wall_seconds", "wall-clock time", "s"),
    (
        "collisions_per_second",
        "collisions per wall-clock second",
        "1/s",
    ),
    ("temperature.", "granular temperature", "mass·length²/time²"),
    ("energy.", "energy", "mass·length²/time²"),
    ("com_height", "centre-of-mass height", "length"),
    (
        "impacts_per_unit_time",
        "floor impacts per unit time",
        "1/time",
    ),
    (
        "floor_pressure.",
        "floor pressure (force per width)",
        "mass/time²",
    ),
    ("packing_fraction", "packing fraction", "dimensionless"),
    ("compressibility_factor", "Z = PA/(NkT)", "dimensionless"),
    ("max_overlap", "largest overlap", "length"),
    ("at_rest_since", "time to rest", "time"),
    ("events.", "event count", "count"),
];

/// The meaning and unit of a summary field or sweep key (`None` if not known).
pub fn quantity(name: &str) -> Option<(&'static str, &'static str)> {
    QUANTITIES
        .iter()
        .find(|(key, ..)| {
            if key.ends_with('.') {
                name.starts_with(key)
            } else {
                name == *key
            }
        })
        .map(|&(_, meaning, unit)| (meaning, unit))
}

/// The axis description of a field or sweep key: its name and unit, e.g.
/// `drive.peak_velocity (length/time)`; `scenario units` when the unit is not known.
pub fn axis_label(name: &str) -> String {
    format!(
        "{name} ({})",
        quantity(name).map_or("scenario units", |q| q.1)
    )
}
