//! The disks, as a structure of arrays: positions, velocities and the time stamp each state
//! belongs to (disks are advanced lazily), radii, masses, collision counters.

/// A disk's motion: its state at its own time stamp (kept together: the hot data of the event
/// loop, one cache line's worth per disk).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Motion {
    /// Centre x at time `t`.
    pub x: f64,
    /// Centre y at time `t`.
    pub y: f64,
    /// Velocity x at time `t`.
    pub vx: f64,
    /// Velocity y at time `t`.
    pub vy: f64,
    /// The (engine-local) time the stored state belongs to.
    pub t: f64,
}

/// Storage of N disks: motions together, static properties in their own arrays.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Disks {
    /// Position, velocity and time stamp of each disk.
    pub motion: Vec<Motion>,
    /// Radius.
    pub radius: Vec<f64>,
    /// Mass.
    pub mass: Vec<f64>,
    /// Species index (for output).
    pub species: Vec<u32>,
    /// Number of velocity changes so far (invalidates partners' predicted events).
    pub counter: Vec<u32>,
}

impl Disks {
    /// Disks at rest at the given positions with the given radii and masses, all at time 0.
    pub fn new(
        positions: &[[f64; 2]],
        radius: Vec<f64>,
        mass: Vec<f64>,
        species: Vec<u32>,
    ) -> Disks {
        let n = positions.len();
        assert!(radius.len() == n && mass.len() == n && species.len() == n);
        Disks {
            motion: positions
                .iter()
                .map(|p| Motion {
                    x: p[0],
                    y: p[1],
                    ..Motion::default()
                })
                .collect(),
            radius,
            mass,
            species,
            counter: vec![0; n],
        }
    }

    /// Number of disks.
    pub fn len(&self) -> usize {
        self.radius.len()
    }

    /// `true` when there are no disks.
    pub fn is_empty(&self) -> bool {
        self.radius.is_empty()
    }

    /// Smallest and largest radius.
    pub fn radius_range(&self) -> (f64, f64) {
        self.radius
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| {
                (lo.min(r), hi.max(r))
            })
    }

    /// Root mean square radius (0 without disks).
    pub fn rms_radius(&self) -> f64 {
        let n = self.radius.len().max(1) as f64;
        (self.radius.iter().map(|a| a * a).sum::<f64>() / n).sqrt()
    }

    /// Bytes held by these arrays.
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<Motion>() * self.motion.capacity()
            + 8 * (self.radius.capacity() + self.mass.capacity())
            + 4 * (self.species.capacity() + self.counter.capacity())
    }
}
