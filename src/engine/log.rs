//! The collision log: what each disk hit and when, kept on request so that tests can compare
//! the engine with the brute-force reference collision by collision.

use serde::Serialize;

/// What a disk collided with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Partner {
    /// Another disk.
    Disk(u32),
    /// The wall at x = 0.
    Left,
    /// The wall at x = width.
    Right,
    /// The lid.
    Lid,
    /// The floor.
    Floor,
}

/// One collision: its absolute time, the disk, and what it hit (for pairs, `disk < partner`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Collision {
    /// Absolute time.
    pub time: f64,
    /// The disk (the lower number for a pair).
    pub disk: u32,
    /// What it hit.
    pub partner: Partner,
}

impl Collision {
    /// A collision record with pairs normalised so that `disk < partner`.
    pub fn new(time: f64, disk: usize, partner: Partner) -> Collision {
        match partner {
            Partner::Disk(j) if (j as usize) < disk => Collision {
                time,
                disk: j,
                partner: Partner::Disk(disk as u32),
            },
            _ => Collision {
                time,
                disk: disk as u32,
                partner,
            },
        }
    }
}
