//! The scheduler's sorter: each disk keeps only its own earliest event (Isobe's Local Minima
//! Algorithm) and a complete binary tree over the disks yields the global minimum.

pub mod cbt;

pub use cbt::CompleteBinaryTree;
