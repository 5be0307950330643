//! Disks at rest: riding the floor or resting on disks at rest (`riders`), coming to rest and
//! letting go (`resting`), and the jam rules that end a burst of events at one instant (`jams`).

pub(super) mod jams;
pub(super) mod resting;
pub mod riders;
