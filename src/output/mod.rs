//! Output plugins: what the simulation writes out.
pub mod frame;
pub mod progress;
#[cfg(feature = "record")]
pub mod recording;
pub mod trajectory;
