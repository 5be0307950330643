//! What the machine and the operating system offer the run: the vector path of the hot loops,
//! allocator settings for large scenes, memory prefetch hints, the signals that stop a run, and
//! the file the code was loaded from.

pub mod binary;
pub mod cpu;
#[cfg(target_arch = "x86_64")]
pub(crate) mod masks;
pub mod memory;
pub mod prefetch;
pub mod signals;
pub mod transpose;
