//! Disks at rest: riding the floor or resting on disks at rest (`riders`), coming to rest and
//! letting go (`resting`), and the jam rules that end a burst of events at one instant (`jams`).

pub(super) mod jams;
pub(super) mod resting;
pub mod riders;

/// Of disks `i` and `j`, one riding (`rode`: whether each rode), the flying one and the one
/// at rest.
pub(super) fn flying_and_riding(i: usize, j: usize, rode: [bool; 2]) -> (usize, usize) {
    if rode[0] {
        (j, i)
    } else {
        (i, j)
    }
}
