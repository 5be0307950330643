//! Output plugins: what the simulation writes out.
pub mod frame;
#[cfg(feature = "record")]
pub mod recording;
