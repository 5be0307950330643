//! The disks, as a structure of arrays: positions, velocities and the time stamp each state
//! belongs to (disks are advanced lazily), radii, masses, collision counters.

/// Structure-of-arrays storage of N disks.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Disks {
    /// Centre x at the disk's own time `t`.
    pub x: Vec<f64>,
    /// Centre y at the disk's own time `t`.
    pub y: Vec<f64>,
    /// Velocity x at time `t`.
    pub vx: Vec<f64>,
    /// Velocity y at time `t`.
    pub vy: Vec<f64>,
    /// The (engine-local) time the stored state belongs to.
    pub t: Vec<f64>,
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
    pub fn new(positions: &[[f64; 2]], radius: Vec<f64>, mass: Vec<f64>, species: Vec<u32>) -> Disks {
        let n = positions.len();
        assert!(radius.len() == n && mass.len() == n && species.len() == n);
        Disks {
            x: positions.iter().map(|p| p[0]).collect(),
            y: positions.iter().map(|p| p[1]).collect(),
            vx: vec![0.0; n],
            vy: vec![0.0; n],
            t: vec![0.0; n],
            radius,
            mass,
            species,
            counter: vec![0; n],
        }
    }

    /// Number of disks.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// `true` when there are no disks.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Smallest and largest radius.
    pub fn radius_range(&self) -> (f64, f64) {
        self.radius
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| (lo.min(r), hi.max(r)))
    }

    /// Bytes held per disk by these arrays.
    pub fn bytes(&self) -> usize {
        8 * (self.x.capacity()
            + self.y.capacity()
            + self.vx.capacity()
            + self.vy.capacity()
            + self.t.capacity()
            + self.radius.capacity()
            + self.mass.capacity())
            + 4 * (self.species.capacity() + self.counter.capacity())
    }
}
