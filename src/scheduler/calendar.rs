//! Calendar queue over per-disk event times (Paul 2007, J. Comput. Phys. 221, 615).
//!
//! Time ahead of the present is cut into buckets of width Δt. A disk whose event falls in a
//! future bucket sits, unsorted, in that bucket's linked list; a disk whose event falls beyond
//! the calendar's span sits in an overflow list; a disk whose event falls in the current bucket
//! (or earlier) sits in a short array, which alone is kept in order (latest first: the earliest
//! leaves from the end). The overflow is the list after the last bucket's, so that an event bound
//! for either is filed by one path, without a branch on which. When the array runs dry the next
//! non-empty bucket is poured into it and sorted; when the last bucket is done the calendar wraps:
//! Δt and the span are tuned again from the overflow's times and the overflow is spread over
//! the new buckets.
//!
//! Each disk holds at most one entry (its earliest event), so a change of a disk's event is an
//! unlink and a link: O(1) for the lists, O(h) moves within the current bucket's h events
//! (O(log h) comparisons beyond a few). With Δt tuned so that a bucket holds O(1) events, every
//! operation costs O(1) on average, against O(log N) for the
//! [complete binary tree](super::CompleteBinaryTree).
//!
//! The order is exactly the tree's: earliest time first and, among equal times, the disk the
//! tree would yield (the leftmost leaf of its heap-shaped layout), so that the engine pops the
//! same events in the same order, bit for bit, whichever queue it uses.
//!
//! A calendar that keeps events ahead (set by the engine where its arrays outgrow the caches
//! and it hints at memory in a pipeline: see [`PIPELINE_FROM`](crate::platform::prefetch::PIPELINE_FROM))
//! serves the memory system in two ways: the array is refilled before
//! it runs dry, so that it always shows the event loop the next few events; and an entry bound
//! for a future bucket is linked into its list only at the next change, once the list's head,
//! asked for ahead, has arrived.

use super::bucket::{places, Entry, SHORT};
use crate::platform::cpu::Lanes;
use serde::{Deserialize, Serialize};

/// End of a list.
const NIL: u32 = u32::MAX;
/// Largest number of buckets and of disks.
const MAX_BUCKETS: usize = 1 << 30;
/// Times looked at to tune Δt (every k-th of the events being filed).
const SAMPLE: usize = 512;
/// Mean number of events per bucket over the earlier half of the filed events (measured: 2 to 8
/// are equally good; the current bucket stays short).
const EVENTS_PER_BUCKET: f64 = 4.0;
/// Span of the calendar, in multiples of the filed events' median time from the earliest: 4
/// keeps about 94 % of exponentially spread times out of the overflow with half as many
/// buckets as events (measured: 2 to 8 are equally good, 1 wraps too often).
const SPAN_MEDIANS: f64 = 4.0;

/// Fewest events in the current bucket of a calendar that keeps events ahead (the bucket is
/// refilled before it runs dry): the minimum and three after it, whose
/// data the event loop asks for ahead (see [`CalendarQueue::next_likely`]). Without it the
/// bucket often holds at most one event after the minimum, and the event loop has little to
/// ask for.
const LOOKAHEAD: usize = 4;

/// Buckets from which on [`CalendarQueue::prefetch_time`] gives its hint (512 KiB of heads:
/// N ≈ 2.6·10⁵ disks). Fewer heads stay cached anyway and the hint would only cost time
/// (chosen by measurement: the book's performance history has the figures).
const PREFETCH_HEADS_FROM: usize = 1 << 17;

/// Where an event belongs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Place {
    /// No event (+∞ or NaN).
    Nowhere,
    /// The current bucket or earlier: the sorted array.
    Current,
    /// A future bucket's list, or the overflow's, which is list `buckets`: beyond the
    /// calendar's span.
    List(usize),
}

/// The calendar's shape, which alone says where an event belongs.
#[derive(Debug, Clone, Copy)]
struct Params {
    /// Start of bucket 0.
    origin: f64,
    /// 1/Δt.
    inv_width: f64,
    /// The current bucket.
    cur: u32,
    /// Number of buckets.
    buckets: usize,
}

impl Params {
    /// Where an event at `t` belongs.
    #[inline(always)]
    fn place(&self, t: f64) -> Place {
        if t.is_nan() || t == f64::INFINITY {
            return Place::Nowhere;
        }
        // Monotone in t (rounding is monotone), so earlier events never sit in later buckets.
        let x = (t - self.origin) * self.inv_width;
        // Through `u32` (buckets never exceed 2³⁰): one instruction each way, where `usize`
        // and `f64` convert in several on x86-64 without AVX-512.
        if x < (self.cur + 1) as f64 {
            Place::Current
        } else {
            // Past the last bucket, the overflow's list: a minimum, not a branch (whether an
            // event overflows is a toss-up, known late, when its time is).
            let last = self.buckets as u32 as f64;
            Place::List((if x < last { x } else { last }) as u32 as usize)
        }
    }
}

/// One disk's entry: its list links (unused while it is in the current bucket). It is filed
/// at the disk's time in the caller's `times`, so the calendar keeps no copy of it; where it
/// is filed follows from that time (see [`CalendarQueue::place`]): the calendar's parameters
/// change only when everything concerned is filed anew.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
struct Node {
    next: u32,
    prev: u32,
}

/// A calendar of unsorted linked lists plus a sorted array for the current bucket, over
/// `times[0..n]` (`times.len() == n + 1`, `times[n] = ∞`, as for the tree). Each disk is filed
/// at `times[i]`: a change of it must be followed by [`update`](Self::update) with the time it
/// replaced, before another time changes (a wrap of the calendar finds its overflow from the
/// times). Times must not be −∞; +∞ (or NaN) means no event.
///
/// Memory: 8 bytes per disk (list links) plus 4 per bucket (one bucket per two finite events)
/// and 16 per event of the current bucket: about 10 bytes per disk, against 8 for the tree.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct CalendarQueue {
    /// The tree's order: disk i is the ((i − shift) mod n)-th leaf from the left.
    shift: u32,
    /// Start of bucket 0.
    origin: f64,
    /// 1/Δt.
    inv_width: f64,
    /// The current bucket: events of buckets ≤ `cur` are in `current`.
    cur: u32,
    /// First disk of each bucket's list (`NIL` if empty), then of the overflow's.
    head: Vec<u32>,
    /// Length of the overflow's list.
    over_len: u32,
    /// Per disk.
    node: Vec<Node>,
    /// The events of buckets ≤ `cur`, latest first (the earliest is the last).
    current: Vec<Entry>,
    /// Sampled times for tuning (kept to avoid allocating at each wrap).
    #[serde(skip)]
    sample: Vec<f64>,
    /// A disk taken out of its old place whose new event belongs to a future bucket or the
    /// overflow, not yet linked into that list (`NIL`: none). Where events are kept
    /// ahead, the link waits for the next update (see [`update`](Self::update)).
    pending: u32,
    /// Events are kept ahead in the current bucket and entries linked late (see
    /// [`keeping_ahead`](Self::keeping_ahead)).
    keep_ahead: bool,
    /// Where the look-ahead walk is: a bucket after the current one and a disk in its list
    /// (see [`walk_ahead`](Self::walk_ahead)); only a hint, never needed to be right.
    #[serde(skip)]
    ahead: (u32, u32),
}

impl CalendarQueue {
    /// `true` when the queue is shaped for the disks of `times` (`n + 1` entries) and every
    /// link is in range (a checkpoint's queue is checked before it is used).
    pub fn fits(&self, times: &[f64]) -> bool {
        let Some(n) = times.len().checked_sub(1) else {
            return false;
        };
        // 0 for a queue never built: the checks below then fail before `place` is asked.
        let nb = self.head.len().saturating_sub(1);
        let disk_ok = |d: u32| d == NIL || (d as usize) < n;
        self.node.len() == n
            && n < MAX_BUCKETS
            && (self.shift as usize) < n.max(1)
            && (2..=MAX_BUCKETS + 1).contains(&self.head.len())
            && (self.cur as usize) < nb
            && self.inv_width.is_finite()
            && self.inv_width > 0.0
            && self.origin.is_finite()
            && disk_ok(self.pending)
            // An entry waiting to be linked belongs to a future bucket or the overflow.
            && (self.pending == NIL
                || matches!(self.place(times[self.pending as usize]), Place::List(_)))
            && self.head.iter().all(|&d| disk_ok(d))
            && self.current.iter().all(|e| {
                (e.disk as usize) < n
                    && e.rank == self.rank(e.disk)
                    && e.t.to_bits() == times[e.disk as usize].to_bits()
                    && self.place(e.t) == Place::Current
            })
            // Strictly sorted (so each disk at most once), and every disk due in it is there.
            && self.current.windows(2).all(|w| w[1].before(&w[0]))
            && self
                .node
                .iter()
                .enumerate()
                .all(|(i, e)| match self.place(times[i]) {
                    Place::Nowhere | Place::Current => true,
                    _ => disk_ok(e.next) && disk_ok(e.prev),
                })
            && (0..n)
                .filter(|&i| self.place(times[i]) == Place::Current)
                .count()
                == self.current.len()
    }

    /// An empty queue that keeps events ahead (`true`) or not (the default); built with
    /// [`rebuild`](Self::rebuild), which keeps the choice. Where it does, the current bucket
    /// is refilled before it runs dry, four events long, so that
    /// [`next_likely`](Self::next_likely) shows the event loop the next few events, and an
    /// entry bound for a future bucket is linked late (see [`update`](Self::update)): for an
    /// event loop that asks for their data ahead, where the arrays outgrow the caches.
    pub fn keeping_ahead(on: bool) -> CalendarQueue {
        CalendarQueue {
            keep_ahead: on,
            ..CalendarQueue::default()
        }
    }

    /// Builds the queue over `times[0..n]` (`times.len() == n + 1`, `times[n] = ∞`): tunes Δt
    /// from the times and files every disk, O(n).
    pub fn build(times: &[f64]) -> CalendarQueue {
        let mut queue = CalendarQueue::default();
        queue.rebuild(times);
        queue
    }

    /// [`build`](Self::build) in place, reusing the arrays (no allocation once they are large
    /// enough).
    pub fn rebuild(&mut self, times: &[f64]) {
        let n = times.len() - 1;
        assert!(n < MAX_BUCKETS, "too many disks for the calendar");
        // The tree's leaves sit at n..2n in heap order; those of the deepest level (positions
        // from 2^D, the largest power of two below 2n) come first from the left, so the tree's
        // order of leaves starts at disk 2^D − n and wraps round.
        self.shift = if n == 0 {
            0
        } else {
            let deepest = 1usize << (usize::BITS - 1 - (2 * n - 1).leading_zeros());
            (deepest - n) as u32
        };
        self.current.clear();
        self.pending = NIL;
        self.ahead = (0, NIL);
        self.over_len = 0;

        let mut t_min = f64::INFINITY;
        let mut count = 0usize;
        for &t in &times[..n] {
            if t < f64::INFINITY {
                t_min = t_min.min(t);
                count += 1;
            }
        }
        self.sample.clear();
        let stride = (n / SAMPLE).max(1);
        self.sample.extend(
            times[..n]
                .iter()
                .step_by(stride)
                .filter(|t| **t < f64::INFINITY),
        );
        self.tune(t_min, count);
        self.node.clear();
        self.node.resize(
            n,
            Node {
                next: NIL,
                prev: NIL,
            },
        );
        for (i, &t) in times[..n].iter().enumerate() {
            self.file(i as u32, t, true);
        }
        self.sort_current();
        self.refill(times);
    }

    /// Sets origin, Δt and the number of buckets for `count` events from `t_min` on, whose
    /// sampled times are in `self.sample`: a bucket holds about [`EVENTS_PER_BUCKET`] events
    /// over the earlier half of them (Δt from the sample's median), and the buckets span
    /// [`SPAN_MEDIANS`] medians.
    fn tune(&mut self, t_min: f64, count: usize) {
        let mut width = 0.0;
        if count > 0 && !self.sample.is_empty() {
            let mid = self.sample.len() / 2;
            let (_, median, _) = self
                .sample
                .select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
            let spread = *median - t_min;
            width = EVENTS_PER_BUCKET * 2.0 * spread / count as f64;
        }
        let inv_width = 1.0 / width;
        self.inv_width = if inv_width.is_finite() && inv_width > 0.0 {
            inv_width
        } else {
            1.0
        };
        self.origin = if t_min.is_finite() { t_min } else { 0.0 };
        self.cur = 0;
        let buckets = (count as f64 * SPAN_MEDIANS / (2.0 * EVENTS_PER_BUCKET)).ceil() as usize;
        let buckets = buckets.clamp(1, MAX_BUCKETS);
        self.head.clear();
        self.head.resize(buckets + 1, NIL);
    }

    /// Where an event at `t` belongs now.
    #[inline(always)]
    fn place(&self, t: f64) -> Place {
        self.params().place(t)
    }

    /// Files disk `i` (filed nowhere) at time `t`; into the current bucket unsorted if `bulk`
    /// (the caller sorts it when done).
    #[inline(always)]
    fn file(&mut self, i: u32, t: f64, bulk: bool) {
        match self.place(t) {
            Place::Nowhere => {}
            Place::Current if bulk => self.current.push(self.entry(i, t)),
            Place::Current => self.insert_current(self.entry(i, t)),
            Place::List(l) => {
                self.over_len += (l == self.buckets()) as u32;
                let h = self.head[l];
                self.head[l] = self.link(i, h);
            }
        }
    }

    /// Puts disk `i` in front of the list starting at `first`; returns the new first. Without a
    /// branch on whether the list was empty (a toss-up, known late: the list is the event's):
    /// then `i`'s own back link is the one written, with the same `NIL`.
    #[inline(always)]
    fn link(&mut self, i: u32, first: u32) -> u32 {
        let node = &mut self.node[i as usize];
        node.next = first;
        node.prev = NIL;
        let empty = first == NIL;
        let (at, back) = if empty { (i, NIL) } else { (first, i) };
        self.node[at as usize].prev = back;
        i
    }

    /// Takes disk `i` out of wherever it is filed (`at`, at time `old`).
    #[inline(always)]
    fn unfile(&mut self, i: u32, at: Place, old: f64) {
        let Node { next, prev } = self.node[i as usize];
        match at {
            Place::Nowhere => {}
            Place::Current => self.remove_current(self.entry(i, old)),
            Place::List(l) => {
                if prev != NIL {
                    self.node[prev as usize].next = next;
                } else {
                    self.head[l] = next;
                }
                if next != NIL {
                    self.node[next as usize].prev = prev;
                }
                self.over_len -= (l == self.buckets()) as u32;
            }
        }
    }

    /// Keeps the current bucket non-empty while any event is filed ([`LOOKAHEAD`] events long
    /// while there are that many where events are kept ahead): pours the next non-empty
    /// bucket into it (and sorts it), wrapping the calendar when the buckets are done.
    fn refill(&mut self, times: &[f64]) {
        while self.current.len() < self.least() {
            if (self.cur as usize) + 1 < self.buckets() {
                self.cur += 1;
                let mut d = std::mem::replace(&mut self.head[self.cur as usize], NIL);
                while d != NIL {
                    let next = self.node[d as usize].next;
                    self.current.push(self.entry(d, times[d as usize]));
                    d = next;
                }
                self.sort_current();
            } else if self.over_len > 0 {
                self.wrap(times);
            } else {
                return;
            }
        }
    }

    /// All buckets are done and the current bucket is (nearly) empty: tune the calendar to the
    /// overflow's events and spread them over it (the earliest land in the current bucket).
    ///
    /// By now nearly every event is in the overflow (those filed while the buckets were being
    /// done fell past their end). Along its list the overflow is one cache miss after another
    /// (in large scenes a sizeable share of the run), so it is read in disk order, by a pass
    /// over all times: an event is in the overflow when its place under the
    /// calendar being wrapped is the overflow's list (every bucket is done, so every other
    /// filed event is in the current bucket; no entry is pending, as one is linked before a
    /// refill), every disk being filed at its time (each change of a time is followed by its
    /// [`update`](Self::update) before the next). Should the pass find another number of
    /// events than the overflow holds, the list is walked instead.
    fn wrap(&mut self, times: &[f64]) {
        if self.pending != NIL {
            return self.wrap_along_the_list(times);
        }
        let n = self.node.len();
        let old = self.params();
        let overflow = Place::List(old.buckets);
        let stride = (self.over_len as usize / SAMPLE).max(1);
        let mut t_min = f64::INFINITY;
        let mut count = 0usize;
        self.sample.clear();
        for &t in &times[..n] {
            if old.place(t) == overflow {
                t_min = t_min.min(t);
                if count.is_multiple_of(stride) {
                    self.sample.push(t);
                }
                count += 1;
            }
        }
        if count != self.over_len as usize {
            return self.wrap_along_the_list(times);
        }
        self.tune(t_min, count);
        self.over_len = 0;
        for (i, &t) in times[..n].iter().enumerate() {
            if old.place(t) == overflow {
                self.file(i as u32, t, true);
            }
        }
        self.sort_current();
    }

    /// [`wrap`](Self::wrap), reading the overflow along its list.
    #[cold]
    fn wrap_along_the_list(&mut self, times: &[f64]) {
        let count = self.over_len as usize;
        let stride = (count / SAMPLE).max(1);
        let mut t_min = f64::INFINITY;
        self.sample.clear();
        let first = self.head[self.buckets()];
        let mut d = first;
        let mut k = 0;
        while d != NIL {
            let (t, next) = (times[d as usize], self.node[d as usize].next);
            t_min = t_min.min(t);
            if k % stride == 0 {
                self.sample.push(t);
            }
            k += 1;
            d = next;
        }
        // The new calendar's lists start empty; the old overflow's entries keep their links.
        self.tune(t_min, count);
        let mut d = first;
        self.over_len = 0;
        while d != NIL {
            let next = self.node[d as usize].next;
            self.file(d, times[d as usize], true);
            d = next;
        }
        self.sort_current();
    }

    /// The calendar's shape now (what [`place`](Self::place) reads).
    #[inline(always)]
    fn params(&self) -> Params {
        Params {
            origin: self.origin,
            inv_width: self.inv_width,
            cur: self.cur,
            buckets: self.buckets(),
        }
    }

    /// Number of buckets (the overflow's list comes after theirs).
    #[inline(always)]
    fn buckets(&self) -> usize {
        self.head.len() - 1
    }

    /// `true` where events are kept ahead and entries linked late.
    #[inline(always)]
    fn keeps_ahead(&self) -> bool {
        self.keep_ahead
    }

    /// Fewest events the current bucket is refilled to hold (while there are any).
    #[inline(always)]
    fn least(&self) -> usize {
        if self.keeps_ahead() {
            LOOKAHEAD
        } else {
            1
        }
    }

    /// The disk with the earliest event (ties as in the tree); with no finite event, the disk the
    /// tree would yield among all-infinite times. O(1).
    #[inline(always)]
    pub fn min(&self) -> usize {
        match self.current.last() {
            Some(e) => e.disk as usize,
            None => self.shift as usize,
        }
    }

    /// Disk `i`'s event time changed from `old` (the time it was filed at) to `times[i]`: move
    /// its entry. O(1) on average, O(log h) within the current bucket.
    ///
    /// Where events are kept ahead, an entry bound for a
    /// future bucket or the overflow is linked there only at the next update (or before the
    /// current bucket is refilled): the bucket's head, asked for as soon as the event's time
    /// was known ([`prefetch_time`](Self::prefetch_time)), has arrived by then. Such an entry
    /// is never the earliest (the current bucket holds every earlier event), so the order is
    /// the same.
    #[inline]
    pub fn update(&mut self, times: &[f64], i: usize, old: f64) {
        let t = times[i];
        let from = if self.pending == i as u32 {
            // Taken out of its old place at its last update, not linked since.
            self.pending = NIL;
            Place::Nowhere
        } else {
            self.link_pending(times);
            self.place(old)
        };
        let to = self.place(t);
        if from == Place::Current && to == Place::Current {
            // Stays in the current bucket: moves within it.
            self.remove_current(self.entry(i as u32, old));
            self.insert_current(self.entry(i as u32, t));
            return;
        }
        self.unfile(i as u32, from, old);
        if self.keeps_ahead() && matches!(to, Place::List(_)) {
            self.pending = i as u32;
        } else {
            self.file(i as u32, t, false);
        }
        if self.current.len() < self.least() {
            self.link_pending(times);
            self.refill(times);
        }
        if self.node.len() >= crate::platform::prefetch::PREFETCH_FROM {
            self.walk_ahead(times);
        }
    }

    /// Links the pending entry (if any) into its list.
    #[inline(always)]
    fn link_pending(&mut self, times: &[f64]) {
        if self.pending != NIL {
            let d = std::mem::replace(&mut self.pending, NIL);
            self.file(d, times[d as usize], false);
        }
    }

    /// One step of a walk through the lists of the buckets after the current one, asking the
    /// memory system for each entry a step before the walk reads it: by the time a bucket is
    /// poured into the current bucket its entries are cached, instead of costing one miss after
    /// another (a list is a chain: each entry says where the next is). It changes nothing but
    /// timing.
    ///
    /// An entry whose event changed since the walk reached it has been filed elsewhere: its
    /// link leads into another bucket's list, far ahead, or nowhere (an entry in the current
    /// bucket keeps a stale link), so the walk starts its bucket again instead of following it.
    /// Without that check, pouring a bucket in a large scene would still wait on one miss
    /// after another.
    #[inline(always)]
    fn walk_ahead(&mut self, times: &[f64]) {
        let (mut bucket, disk) = self.ahead;
        let next = if disk != NIL
            && (disk as usize) < self.node.len()
            && self.place(times[disk as usize]) == Place::List(bucket as usize)
        {
            self.node[disk as usize].next
        } else {
            NIL
        };
        if next != NIL {
            self.ahead = (bucket, next);
            crate::platform::prefetch::prefetch(&self.node, next as usize);
            crate::platform::prefetch::prefetch(times, next as usize);
            return;
        }
        // The next two buckets: farther ahead, what it brings would be evicted before use.
        bucket = if bucket > self.cur && bucket < self.cur + 2 {
            bucket + 1
        } else {
            self.cur + 1
        };
        let first = if (bucket as usize) < self.buckets() {
            self.head[bucket as usize]
        } else {
            bucket = self.cur;
            NIL
        };
        self.ahead = (bucket, first);
        if first != NIL {
            crate::platform::prefetch::prefetch(&self.node, first as usize);
            crate::platform::prefetch::prefetch(times, first as usize);
        }
    }

    /// The three disks next after [`min`](Self::min) in the current bucket, in order, where it
    /// holds them.
    #[inline(always)]
    pub fn next_likely(&self) -> [Option<usize>; 3] {
        let len = self.current.len();
        [2, 3, 4].map(|k| len.checked_sub(k).map(|k| self.current[k].disk as usize))
    }

    /// Hints that an event at `t` will be filed soon: the head of its bucket, read when it is
    /// filed, a miss at random once the heads outgrow the caches (from
    /// 2¹⁷ buckets on; below, the hint only costs).
    #[inline(always)]
    pub fn prefetch_time(&self, t: f64) {
        if self.head.len() < PREFETCH_HEADS_FROM {
            return;
        }
        if let Place::List(b) = self.place(t) {
            crate::platform::prefetch::prefetch(&self.head, b);
        }
    }

    /// Hints that disk `i`'s entry will be read soon.
    #[inline(always)]
    pub fn prefetch(&self, i: usize) {
        crate::platform::prefetch::prefetch(&self.node, i);
    }

    /// Hints that the neighbours of disk `i`'s entry in its list will be changed soon (when
    /// `i` leaves it); `i`'s entry should be cached already.
    #[inline(always)]
    pub fn prefetch_links(&self, i: usize) {
        if let Some(&Node { next, prev }) = self.node.get(i) {
            crate::platform::prefetch::prefetch(&self.node, next as usize);
            crate::platform::prefetch::prefetch(&self.node, prev as usize);
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<Node>() * self.node.capacity()
            + 4 * self.head.capacity()
            + std::mem::size_of::<Entry>() * self.current.capacity()
            + 8 * self.sample.capacity()
    }

    // --- The current bucket: a sorted array, latest first ---

    /// Disk `i`'s place in the tree's order, without a branch.
    #[inline(always)]
    fn rank(&self, i: u32) -> u32 {
        let r = i.wrapping_sub(self.shift);
        r.wrapping_add(self.node.len() as u32 * (i < self.shift) as u32)
    }

    /// Disk `i`'s entry for an event at `t`.
    #[inline(always)]
    fn entry(&self, i: u32, t: f64) -> Entry {
        Entry {
            t,
            rank: self.rank(i),
            disk: i,
        }
    }

    /// Puts `e` in its place in the current bucket, after every later entry: in a short
    /// bucket by moving the earlier entries up one by one from the end (one loop, whose exit
    /// is the only branch that can mispredict), in a long one by bisection.
    #[inline(always)]
    fn insert_current(&mut self, e: Entry) {
        let len = self.current.len();
        if len > SHORT {
            let k = self.current.partition_point(|x| e.before(x));
            self.current.insert(k, e);
            return;
        }
        self.current.push(e);
        let mut k = len;
        while k > 0 && self.current[k - 1].before(&e) {
            self.current[k] = self.current[k - 1];
            k -= 1;
        }
        self.current[k] = e;
    }

    /// Takes `e` (filed) out of the current bucket: the earliest (the last) at once, another
    /// found by its key (bisection) or, in a short bucket, by its disk.
    #[inline(always)]
    fn remove_current(&mut self, e: Entry) {
        let len = self.current.len();
        if self.current.last().is_some_and(|l| l.disk == e.disk) {
            self.current.pop();
            return;
        }
        if len > SHORT {
            let k = self.current.partition_point(|x| e.before(x));
            debug_assert_eq!(self.current[k].disk, e.disk, "a filed entry");
            self.current.remove(k);
            return;
        }
        let k = self.current.iter().rposition(|x| x.disk == e.disk);
        let k = k.expect("a filed entry");
        for m in k..len - 1 {
            self.current[m] = self.current[m + 1];
        }
        self.current.pop();
    }

    /// Sorts the current bucket (after entries were added unsorted): a short one by counting.
    fn sort_current(&mut self) {
        let len = self.current.len();
        if let Some(&first) = self.current.first().filter(|_| len <= SHORT) {
            let place = places(&self.current, Lanes::found());
            let mut sorted = [first; SHORT];
            for (&e, &p) in self.current.iter().zip(&place) {
                sorted[p as usize] = e;
            }
            self.current.copy_from_slice(&sorted[..len]);
            return;
        }
        self.current.sort_unstable_by(|a, b| {
            if b.before(a) {
                std::cmp::Ordering::Less
            } else if a.before(b) {
                std::cmp::Ordering::Greater
            } else {
                std::cmp::Ordering::Equal
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::super::CompleteBinaryTree;
    use super::*;
    use proptest::prelude::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// The disk the tree must yield, found by brute force: earliest time, ties in leaf order.
    fn expected(times: &[f64], tree: &CompleteBinaryTree) -> usize {
        let n = times.len() - 1;
        let t = times[tree.min()];
        // (Checked by brute force where that is cheap.)
        assert!(
            n > 10_000 || times[..n].iter().all(|&s| s >= t),
            "the tree missed the minimum"
        );
        tree.min()
    }

    /// A random time from `now`: mostly exponential, sometimes equal to now or to a grid value
    /// (ties), far in the future, or +∞; if `plain`, exponential or (one in four, after the
    /// start) very soon after now (in the next few buckets of a large calendar), without ties.
    fn draw(rng: &mut Xoshiro256PlusPlus, now: f64, scale: f64, plain: bool) -> f64 {
        let kind = if plain && now > 0.0 {
            [5, 5, 5, 6][rng.random_range(0..4)]
        } else if plain {
            5
        } else {
            rng.random_range(0..20)
        };
        match kind {
            6 => now + 3e-5 * scale * rng.random::<f64>(),
            0 => f64::INFINITY,
            1 => now,
            2 => now + 1e9 * scale * rng.random::<f64>(),
            3 | 4 => (now / scale).ceil() * scale + (rng.random_range(0..4) as f64) * scale,
            _ => now - scale * rng.random::<f64>().max(1e-300).ln(),
        }
    }

    /// Drives the tree and the calendar with the same engine-like sequence: pop the earliest
    /// disk and give it a new time, change some other disks' times (any time from now on),
    /// sometimes re-base the clock and rebuild; both must yield the same disk at every step.
    fn drive(seed: u64, n: usize, steps: usize, plain: bool, keep_ahead: bool) {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let scale = 10f64.powi(rng.random_range(-3..3));
        let mut times: Vec<f64> = (0..n).map(|_| draw(&mut rng, 0.0, scale, plain)).collect();
        times.push(f64::INFINITY);
        let mut tree = CompleteBinaryTree::build(&times);
        let mut cal = CalendarQueue::keeping_ahead(keep_ahead);
        cal.rebuild(&times);
        let mut now = 0.0;
        for step in 0..steps {
            let i = expected(&times, &tree);
            assert_eq!(cal.min(), i, "seed {seed} n {n} step {step}");
            if rng.random_range(0..100 + 4 * n) == 0 {
                // Re-mapping: the clock restarts at 0, every disk is predicted anew (rarely
                // enough that the calendar also wraps between re-mappings).
                for t in times[..n].iter_mut() {
                    *t = draw(&mut rng, 0.0, scale, plain);
                }
                now = 0.0;
                tree = CompleteBinaryTree::build(&times);
                cal.rebuild(&times);
                assert!(cal.fits(&times));
                continue;
            }
            match rng.random_range(0..100) {
                0..=9 if n > 0 => {
                    let j = rng.random_range(0..n);
                    let old = times[j];
                    times[j] = draw(&mut rng, now, scale, plain);
                    tree.update(&times, j);
                    cal.update(&times, j, old);
                }
                _ => {
                    if times[i] == f64::INFINITY {
                        now = 0.0;
                        for t in times[..n].iter_mut() {
                            *t = draw(&mut rng, 0.0, scale, plain);
                        }
                        tree = CompleteBinaryTree::build(&times);
                        cal.rebuild(&times);
                        continue;
                    }
                    now = times[i];
                    times[i] = draw(&mut rng, now, scale, plain);
                    tree.update(&times, i);
                    cal.update(&times, i, now);
                    // Sometimes at once again (a disk re-predicted twice in a row).
                    if rng.random_bool(0.05) {
                        let old = times[i];
                        times[i] = draw(&mut rng, now, scale, plain);
                        tree.update(&times, i);
                        cal.update(&times, i, old);
                    }
                    // A pair collision: the partner is re-predicted too.
                    if n > 1 && rng.random_bool(0.7) {
                        let j = rng.random_range(0..n);
                        let old = times[j];
                        times[j] = draw(&mut rng, now, scale, plain);
                        tree.update(&times, j);
                        cal.update(&times, j, old);
                    }
                }
            }
            if step % 1000 == 500 {
                // Through a checkpoint (with any entry waiting to be linked).
                let bytes = postcard::to_allocvec(&cal).expect("the calendar serializes");
                cal = postcard::from_bytes(&bytes).expect("and back");
            }
            if step % 64 == 0 {
                assert!(
                    cal.fits(&times),
                    "seed {seed} n {n} step {step}: filed as the times say"
                );
                // The current bucket holds `least()` events while there are that many (it is
                // refilled before it runs dry where events are kept ahead).
                let ahead =
                    cal.head[cal.cur as usize + 1..].iter().any(|&h| h != NIL) || cal.over_len > 0;
                assert!(
                    cal.current.len() >= cal.least() || !ahead,
                    "seed {seed} n {n} step {step}: {} events in the current bucket",
                    cal.current.len()
                );
            }
        }
        assert!(cal.fits(&times));
    }

    #[test]
    fn yields_what_the_tree_yields() {
        for (seed, n) in [
            (1, 0),
            (2, 1),
            (3, 2),
            (4, 3),
            (5, 5),
            (6, 7),
            (7, 17),
            (8, 100),
            (9, 1000),
            (10, 4096),
            (11, 5000),
        ] {
            drive(seed, n, 20_000 + 20 * n, false, false);
        }
    }

    /// Where events are kept ahead the current bucket holds events after the minimum,
    /// refilled before it runs dry, and entries are linked late: still the tree's order (times
    /// without ties, so that the current bucket is short).
    #[test]
    fn yields_what_the_tree_yields_with_events_kept_ahead() {
        assert_eq!(CalendarQueue::keeping_ahead(true).least(), LOOKAHEAD);
        assert_eq!(CalendarQueue::keeping_ahead(false).least(), 1);
        for (seed, n) in [(12, 1 << 18), (13, 5000), (14, 17), (15, 1)] {
            drive(seed, n, 20_000 + 20 * n.min(5000), true, true);
        }
    }

    #[test]
    fn ties_in_the_trees_order_for_every_size() {
        for n in 1..300 {
            for value in [0.0, 1.5, f64::INFINITY] {
                let mut times = vec![value; n + 1];
                times[n] = f64::INFINITY;
                let tree = CompleteBinaryTree::build(&times);
                let cal = CalendarQueue::build(&times);
                assert_eq!(cal.min(), tree.min(), "n {n} all at {value}");
            }
            // Two equal earliest times at every pair of places (small n) or a few (large n).
            let pairs: Vec<(usize, usize)> = if n < 24 {
                (0..n).flat_map(|a| (0..n).map(move |b| (a, b))).collect()
            } else {
                vec![(0, n - 1), (n / 3, n / 2), (n - 2, 1)]
            };
            for (a, b) in pairs {
                let mut times: Vec<f64> = (0..n).map(|k| 2.0 + k as f64).collect();
                times.push(f64::INFINITY);
                times[a] = 1.0;
                times[b] = 1.0;
                let tree = CompleteBinaryTree::build(&times);
                let mut cal = CalendarQueue::build(&times);
                assert_eq!(cal.min(), tree.min(), "n {n} ties at {a}, {b}");
                // The same after updates rather than a build.
                let mut times2 = vec![f64::INFINITY; n + 1];
                let mut cal2 = CalendarQueue::build(&times2);
                for i in 0..n {
                    times2[i] = times[i];
                    cal2.update(&times2, i, f64::INFINITY);
                }
                assert_eq!(cal2.min(), tree.min());
                // Every time changed before the updates: the wraps they cause cannot find the
                // overflow from the times and walk its list.
                let mut cal3 = CalendarQueue::build(&vec![f64::INFINITY; n + 1]);
                for i in 0..n {
                    cal3.update(&times, i, f64::INFINITY);
                }
                assert_eq!(cal3.min(), tree.min());
                cal.update(&times, a, times[a]);
                assert_eq!(cal.min(), tree.min());
            }
        }
    }

    #[test]
    fn survives_a_checkpoint() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(99);
        let n = 300;
        let mut times: Vec<f64> = (0..n).map(|_| draw(&mut rng, 0.0, 1.0, false)).collect();
        times.push(f64::INFINITY);
        let mut cal = CalendarQueue::build(&times);
        let mut tree = CompleteBinaryTree::build(&times);
        for _ in 0..1000 {
            let i = tree.min();
            let (old, t) = (times[i], times[i].min(1e6));
            times[i] = draw(&mut rng, t, 1.0, false);
            tree.update(&times, i);
            cal.update(&times, i, old);
        }
        let bytes = postcard::to_allocvec(&cal).unwrap();
        let mut back: CalendarQueue = postcard::from_bytes(&bytes).unwrap();
        assert!(back.fits(&times));
        let mut more = times.clone();
        more.push(f64::INFINITY);
        assert!(!back.fits(&more));
        for _ in 0..5000 {
            let i = tree.min();
            assert_eq!(back.min(), i);
            let (old, t) = (times[i], times[i].min(1e6));
            times[i] = draw(&mut rng, t, 1.0, false);
            tree.update(&times, i);
            back.update(&times, i, old);
        }
    }

    #[test]
    fn no_allocation_in_steady_state() {
        // After a warm-up the arrays keep their size: the bytes held stop growing.
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let n = 2000;
        let mut times: Vec<f64> = (0..n).map(|_| draw(&mut rng, 0.0, 1.0, false)).collect();
        times.push(f64::INFINITY);
        let mut cal = CalendarQueue::build(&times);
        let mut now = 0.0;
        let mut step = |cal: &mut CalendarQueue, times: &mut Vec<f64>, now: &mut f64| {
            let i = cal.min();
            *now = times[i];
            times[i] = *now - rng.random::<f64>().max(1e-300).ln();
            cal.update(times, i, *now);
        };
        for _ in 0..200_000 {
            step(&mut cal, &mut times, &mut now);
        }
        let bytes = cal.bytes();
        for _ in 0..200_000 {
            step(&mut cal, &mut times, &mut now);
        }
        assert!(cal.bytes() <= bytes, "{} > {bytes}", cal.bytes());
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 512,
            // As in tests/suite/solver_properties.rs: no regression files, the same cases every run
            // (PROPTEST_RNG_SEED explores others).
            failure_persistence: None,
            rng_seed: proptest::test_runner::RngSeed::Fixed(
                std::env::var("PROPTEST_RNG_SEED")
                    .ok()
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(20261121),
            ),
            ..ProptestConfig::default()
        })]
        /// Arbitrary sequences of updates (times from a few values, so that ties abound, or
        /// anywhere) keep the calendar's minimum the tree's.
        #[test]
        fn any_update_sequence(
            n in 1usize..40,
            init in proptest::collection::vec(0u8..8, 40),
            ops in proptest::collection::vec((0usize..40, 0u8..10, 0.0f64..1e3), 0..300),
        ) {
            let value = |k: u8, x: f64| match k {
                0 => f64::INFINITY,
                1..=4 => k as f64,
                5 => x,
                6 => x * 1e9,
                _ => x * 1e-6,
            };
            let mut times: Vec<f64> = init[..n].iter().map(|&k| value(k, 0.5)).collect();
            times.push(f64::INFINITY);
            let mut tree = CompleteBinaryTree::build(&times);
            let mut cal = CalendarQueue::build(&times);
            prop_assert_eq!(cal.min(), tree.min());
            for (j, k, x) in ops {
                let j = j % n;
                let old = times[j];
                times[j] = value(k, x);
                tree.update(&times, j);
                cal.update(&times, j, old);
                prop_assert_eq!(cal.min(), tree.min());
                if k == 9 {
                    cal.rebuild(&times);
                    prop_assert_eq!(cal.min(), tree.min());
                }
            }
            prop_assert!(cal.fits(&times));
        }
    }
}
