//! Pair collisions, the engine's main event source: when a disk next meets a listed neighbour
//! ([`search`](search.rs)), and what their collision does ([`collide`](collide.rs)). Where the
//! processor has AVX2, the search's loop over the list runs four at a time ([`lanes`](lanes.rs)).

mod collide;
#[cfg(target_arch = "x86_64")]
pub(in crate::engine) mod lanes;
mod search;
