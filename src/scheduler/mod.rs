//! The scheduler's sorter: each disk keeps only its own earliest event (Isobe's Local Minima
//! Algorithm) and a queue over the disks yields the global minimum: a complete binary tree
//! (Isobe 1999) or a calendar of linked lists with a short sorted array for the current bucket
//! (Paul 2007), chosen by `engine.queue`. Both yield the same disk at every step, so the choice
//! changes only speed.

mod bucket;
pub mod calendar;
pub mod cbt;

pub use calendar::CalendarQueue;
pub use cbt::CompleteBinaryTree;

use serde::{Deserialize, Serialize};

/// The event queue over per-disk event times `times[0..n]` (`times.len() == n + 1`,
/// `times[n] = ∞`): either sorter behind one interface. Every method is one match. Both yield
/// the same disk for the same times, so the choice changes speed and memory, never results.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub enum EventQueue {
    /// Tournament tree: O(log N) per change, 8 bytes per disk.
    Tree(CompleteBinaryTree),
    /// Calendar queue: O(1) per change on average, about 10 bytes per disk.
    Calendar(CalendarQueue),
}

impl EventQueue {
    /// Files every disk anew from `times`, keeping the kind of queue. O(n).
    pub fn rebuild(&mut self, times: &[f64]) {
        match self {
            EventQueue::Tree(t) => *t = CompleteBinaryTree::build(times),
            EventQueue::Calendar(c) => c.rebuild(times),
        }
    }

    /// The disk with the earliest event (ties: the tree's order). O(1).
    #[inline(always)]
    pub fn min(&self) -> usize {
        match self {
            EventQueue::Tree(t) => t.min(),
            EventQueue::Calendar(c) => c.min(),
        }
    }

    /// Disk `i`'s event time changed from `old` (the time it was filed at) to `times[i]`.
    #[inline(always)]
    pub fn update(&mut self, times: &[f64], i: usize, old: f64) {
        match self {
            EventQueue::Tree(t) => t.update(times, i),
            EventQueue::Calendar(c) => c.update(times, i, old),
        }
    }

    /// Hints that disk `i`'s entry will be changed soon (a calendar's entries are spread over
    /// memory; the tree's top levels stay cached anyway).
    #[inline(always)]
    pub fn prefetch(&self, i: usize) {
        if let EventQueue::Calendar(c) = self {
            c.prefetch(i);
        }
    }

    /// Hints that disk `i`'s entry will leave its place soon (a calendar's list neighbours;
    /// `i`'s own entry asked for before, with [`prefetch`](Self::prefetch)).
    #[inline(always)]
    pub fn prefetch_links(&self, i: usize) {
        if let EventQueue::Calendar(c) = self {
            c.prefetch_links(i);
        }
    }

    /// Disks likely to be next after [`min`](Self::min) (the calendar's current bucket knows
    /// them; the tree does not).
    #[inline(always)]
    pub fn next_likely(&self) -> [Option<usize>; 3] {
        match self {
            EventQueue::Tree(_) => [None; 3],
            EventQueue::Calendar(c) => c.next_likely(),
        }
    }

    /// Hints that an event at `t` will be filed soon.
    #[inline(always)]
    pub fn prefetch_time(&self, t: f64) {
        if let EventQueue::Calendar(c) = self {
            c.prefetch_time(t);
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        match self {
            EventQueue::Tree(t) => t.bytes(),
            EventQueue::Calendar(c) => c.bytes(),
        }
    }

    /// `true` when the queue is shaped for the disks of `times` (`n + 1` entries) and filed as
    /// they say (checkpoints are checked before use).
    pub fn fits(&self, times: &[f64]) -> bool {
        match self {
            EventQueue::Tree(t) => t.fits(times.len().saturating_sub(1)),
            EventQueue::Calendar(c) => c.fits(times),
        }
    }

    /// `tree` or `calendar`.
    pub fn kind(&self) -> &'static str {
        match self {
            EventQueue::Tree(_) => "tree",
            EventQueue::Calendar(_) => "calendar",
        }
    }
}
