//! The event queue: one pending event time per particle.
//!
//! A calendar of time blocks after Paul (J. Comput. Phys. 221, 615 (2007))
//! in the form Smallenburg uses (arXiv:2201.01099): events in the current
//! block sit in a small binary heap; later events are dropped, unsorted, into
//! the bucket of their block (a ring of `nb` buckets), and events beyond the
//! ring into an overflow list. When the heap runs dry the next bucket is
//! poured into it. Insertion is O(1) for most events and the heap stays small
//! and in cache. A particle's newer event makes its older entries stale; they
//! are recognised by a per-particle stamp and dropped when they come up.

#[derive(Debug, Clone, Copy)]
struct Entry {
    t: f64,
    i: u32,
    stamp: u32,
}

impl Entry {
    /// Earlier first; ties go to the lower particle index (deterministic).
    #[inline(always)]
    fn before(&self, o: &Entry) -> bool {
        self.t < o.t || (self.t == o.t && self.i < o.i)
    }
}

/// A binary min-heap of entries whose sift-down picks the smaller child
/// without a branch (the comparison's outcome is a coin toss, so a branch
/// would be mispredicted at every other level) and uses Floyd's
/// bottom-up removal: the hole goes down to a leaf, the last entry then
/// climbs from there.
#[derive(Debug, Clone, Default)]
struct MinHeap {
    v: Vec<Entry>,
}

impl MinHeap {
    #[inline]
    fn len(&self) -> usize {
        self.v.len()
    }

    #[inline]
    fn peek(&self) -> Option<&Entry> {
        self.v.first()
    }

    #[inline]
    fn push(&mut self, e: Entry) {
        self.v.push(e);
        self.sift_up(self.v.len() - 1);
    }

    #[inline]
    fn sift_up(&mut self, mut k: usize) {
        let e = self.v[k];
        while k > 0 {
            let parent = (k - 1) / 2;
            if !e.before(&self.v[parent]) {
                break;
            }
            self.v[k] = self.v[parent];
            k = parent;
        }
        self.v[k] = e;
    }

    #[inline]
    fn pop(&mut self) -> Option<Entry> {
        let last = self.v.pop()?;
        let n = self.v.len();
        if n == 0 {
            return Some(last);
        }
        let top = self.v[0];
        // move the hole from the root down to a leaf along smaller children
        let mut hole = 0;
        let mut child = 1;
        while child + 1 < n {
            child += self.v[child + 1].before(&self.v[child]) as usize;
            self.v[hole] = self.v[child];
            hole = child;
            child = 2 * hole + 1;
        }
        if child < n {
            self.v[hole] = self.v[child];
            hole = child;
        }
        self.v[hole] = last;
        self.sift_up(hole);
        Some(top)
    }
}

/// Calendar queue of per-particle event times.
#[derive(Debug, Clone)]
pub struct EventQueue {
    time: Vec<f64>,
    stamp: Vec<u32>,
    heap: MinHeap,
    buckets: Vec<Vec<Entry>>,
    overflow: Vec<Entry>,
    /// Entries (live or stale) in the buckets.
    in_buckets: usize,
    t0: f64,
    dt: f64,
    /// Index of the current block (times in [t0 + cur·dt, t0 + (cur+1)·dt)).
    cur: i64,
    /// Events taken out in the current block, and blocks and events over
    /// the current window of [`WINDOW`] blocks (to keep `dt` tuned).
    pops_in_block: u64,
    window_blocks: u32,
    window_pops: u64,
}

/// Events per block the calendar aims at.
const TARGET: f64 = 32.0;
/// A block holding this many events is far too long: retune at once.
const TOO_MANY: u64 = 1024;
/// Blocks over which the mean number of events per block is watched.
const WINDOW: u32 = 64;

impl EventQueue {
    /// A queue of `n` particles, all without event (time +∞), with blocks
    /// of length `dt` starting at `t0`.
    pub fn new(n: usize, t0: f64, dt: f64) -> Self {
        let nb = (n / 4).clamp(16, 1 << 20);
        Self {
            time: crate::system::huge_vec(n, f64::INFINITY),
            stamp: crate::system::huge_vec(n, 0),
            heap: MinHeap::default(),
            buckets: vec![Vec::new(); nb],
            overflow: Vec::new(),
            in_buckets: 0,
            t0,
            dt: if dt > 0.0 && dt.is_finite() { dt } else { 1.0 },
            cur: 0,
            pops_in_block: 0,
            window_blocks: 0,
            window_pops: 0,
        }
    }

    /// Rebuilds the queue with a new block length (from the current times).
    pub fn retune(&mut self, t0: f64, dt: f64) {
        let times = std::mem::take(&mut self.time);
        *self = Self::new(times.len(), t0, dt);
        for (i, t) in times.into_iter().enumerate() {
            self.update(i, t);
        }
    }

    pub fn len(&self) -> usize {
        self.time.len()
    }

    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// Current event time of particle `i`.
    pub fn time(&self, i: usize) -> f64 {
        self.time[i]
    }

    #[inline]
    /// The block of time t, within ±2⁶² so that the ring's arithmetic
    /// (block + ring length, block + 1) cannot overflow: every event beyond
    /// 2⁶² blocks (a time like 10³⁰⁰, from extreme but finite input) shares
    /// the last block, where the heap still orders them by their times.
    fn block(&self, t: f64) -> i64 {
        const FAR: f64 = (1u64 << 62) as f64;
        ((t - self.t0) / self.dt).floor().clamp(-FAR, FAR) as i64
    }

    /// Sets the event time of particle `i` (+∞: no event).
    #[inline]
    pub fn update(&mut self, i: usize, t: f64) {
        self.stamp[i] = self.stamp[i].wrapping_add(1);
        self.time[i] = t;
        if t == f64::INFINITY {
            return;
        }
        let e = Entry {
            t,
            i: i as u32,
            stamp: self.stamp[i],
        };
        let b = self.block(t);
        if b <= self.cur {
            self.heap.push(e);
        } else if b < self.cur + self.buckets.len() as i64 {
            let nb = self.buckets.len() as i64;
            self.buckets[b.rem_euclid(nb) as usize].push(e);
            self.in_buckets += 1;
        } else {
            self.overflow.push(e);
        }
    }

    /// The particle with the earliest event and its time (None if no
    /// particle has an event).
    #[inline]
    pub fn min(&mut self) -> Option<(f64, usize)> {
        loop {
            while let Some(top) = self.heap.peek() {
                if self.stamp[top.i as usize] == top.stamp {
                    return Some((top.t, top.i as usize));
                }
                self.heap.pop();
            }
            if !self.advance() {
                return None;
            }
        }
    }

    /// Removes the earliest entry, which the caller has just had from
    /// [`EventQueue::min`] and must file anew with [`EventQueue::update`].
    ///
    /// The event rate can change by orders of magnitude within a run (a
    /// packing approaching jamming collides ever faster): when one block
    /// has yielded [`TOO_MANY`] events, the calendar is rebuilt with blocks
    /// short enough for [`TARGET`] events each.
    #[inline]
    pub fn pop(&mut self) {
        let Some(top) = self.heap.pop() else { return };
        self.pops_in_block += 1;
        if self.pops_in_block >= TOO_MANY {
            let dt = self.dt * TARGET / self.pops_in_block as f64;
            // every live event is at or after the one just taken
            self.retune(top.t, dt);
        }
    }

    /// Moves to the next non-empty block; false if there are no events.
    fn advance(&mut self) -> bool {
        let nb = self.buckets.len() as i64;
        if self.in_buckets == 0 {
            // only the overflow is left: jump to its earliest live block
            self.overflow
                .retain(|e| self.stamp[e.i as usize] == e.stamp);
            let Some(tmin) = self.overflow.iter().map(|e| e.t).min_by(f64::total_cmp) else {
                return false;
            };
            self.cur = self.block(tmin) - 1;
            self.redistribute_overflow();
        }
        self.cur += 1;
        if self.cur.rem_euclid(nb) == 0 {
            self.redistribute_overflow();
        }
        // Blocks far too short for the event rate (most of them empty) make
        // every event pay for many block changes, blocks too long a deep
        // heap: retune when the mean is off by more than 4× either way.
        self.window_blocks += 1;
        self.window_pops += self.pops_in_block;
        self.pops_in_block = 0;
        if self.window_blocks == WINDOW {
            let per_block = self.window_pops as f64 / WINDOW as f64;
            self.window_blocks = 0;
            self.window_pops = 0;
            if !(TARGET / 4.0..=4.0 * TARGET).contains(&per_block) {
                let start = self.t0 + self.cur as f64 * self.dt;
                let dt = self.dt * TARGET / per_block.max(TARGET / 256.0);
                self.retune(start, dt);
                return true;
            }
        }
        let k = self.cur.rem_euclid(nb) as usize;
        let bucket = std::mem::take(&mut self.buckets[k]);
        self.in_buckets -= bucket.len();
        for e in &bucket {
            if self.stamp[e.i as usize] == e.stamp {
                self.heap.push(*e);
            }
        }
        // keep the allocation
        let mut bucket = bucket;
        bucket.clear();
        self.buckets[k] = bucket;
        // a block that starts with far more events than aimed at: shorter
        // blocks (a heap of 10³ entries costs twice one of 30 per event)
        let live = self.heap.len();
        if live as f64 > 8.0 * TARGET {
            let start = self.t0 + self.cur as f64 * self.dt;
            let dt = self.dt * TARGET / live as f64;
            self.retune(start, dt);
        }
        true
    }

    /// Puts overflow events that now fall inside the ring into buckets.
    fn redistribute_overflow(&mut self) {
        let nb = self.buckets.len() as i64;
        let old = std::mem::take(&mut self.overflow);
        for e in old {
            if self.stamp[e.i as usize] != e.stamp {
                continue;
            }
            let b = self.block(e.t);
            if b <= self.cur {
                self.heap.push(e);
            } else if b < self.cur + nb {
                self.buckets[b.rem_euclid(nb) as usize].push(e);
                self.in_buckets += 1;
            } else {
                self.overflow.push(e);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_order() {
        let n = 1000;
        let mut q = EventQueue::new(n, 0.0, 0.01);
        let mut x: u64 = 12345;
        let mut rnd = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut keys = vec![0.0; n];
        for (i, key) in keys.iter_mut().enumerate() {
            // a spread of scales, some far beyond the ring (overflow)
            *key = rnd() * if i % 7 == 0 { 100.0 } else { 3.0 };
            q.update(i, *key);
        }
        // change some keys (the stale entries must be ignored)
        for i in (0..n).step_by(3) {
            keys[i] = rnd() * 5.0;
            q.update(i, keys[i]);
        }
        let mut last = -1.0;
        for _ in 0..n {
            let (t, i) = q.min().unwrap();
            assert_eq!(t, keys[i]);
            assert!(t >= last);
            last = t;
            q.update(i, f64::INFINITY);
        }
        assert!(q.min().is_none());
    }

    /// Times far beyond the ring's reach in blocks (10³⁰⁰ with blocks of
    /// 10⁻²) pop in order after the near ones, without overflowing the
    /// block arithmetic (a hostile packing scene reached it).
    #[test]
    fn times_beyond_any_block_pop_in_order() {
        let mut q = EventQueue::new(4, 0.0, 0.01);
        let keys = [1e300, 0.5, 1e299, f64::MAX];
        for (i, &t) in keys.iter().enumerate() {
            q.update(i, t);
        }
        let mut popped = Vec::new();
        while let Some((t, i)) = q.min() {
            popped.push(t);
            q.update(i, f64::INFINITY);
        }
        assert_eq!(popped, [0.5, 1e299, 1e300, f64::MAX]);
    }
}
