//! The physics of single disks and pairs, free of any bookkeeping: the disks' state, free flight
//! (straight or under gravity), when two disks touch and what their collision does, the
//! restitution law and the cures of inelastic collapse, the side walls and the lid, the floor
//! and its drive, and known results for hard disks.

pub mod disks;
pub mod drive;
pub mod flight;
pub mod floor;
pub mod orifice;
pub mod pair;
pub mod restitution;
pub mod rough;
pub mod slide;
pub mod theory;
pub mod walls;
