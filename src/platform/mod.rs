//! What the machine and the operating system offer the run: allocator settings for large scenes,
//! memory prefetch hints, and the signals that stop a run.

pub mod memory;
pub mod prefetch;
pub mod signals;
