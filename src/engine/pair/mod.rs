//! Pair collisions, the engine's main event source: when a disk next meets a listed neighbour
//! ([`search`](search.rs)), and what their collision does ([`collide`](collide.rs)).

mod collide;
mod search;
