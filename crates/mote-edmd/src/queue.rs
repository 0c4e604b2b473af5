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

use std::cmp::Ordering;
use std::collections::BinaryHeap;

#[derive(Debug, Clone, Copy)]
struct Entry {
    t: f64,
    i: u32,
    stamp: u32,
}

impl PartialEq for Entry {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    /// Reversed, so that `BinaryHeap` (a max-heap) yields the earliest first;
    /// ties go to the lower particle index (deterministic).
    fn cmp(&self, o: &Self) -> Ordering {
        o.t.total_cmp(&self.t).then(o.i.cmp(&self.i))
    }
}

/// Calendar queue of per-particle event times.
#[derive(Debug, Clone)]
pub struct EventQueue {
    time: Vec<f64>,
    stamp: Vec<u32>,
    heap: BinaryHeap<Entry>,
    buckets: Vec<Vec<Entry>>,
    overflow: Vec<Entry>,
    /// Entries (live or stale) in the buckets.
    in_buckets: usize,
    t0: f64,
    dt: f64,
    /// Index of the current block (times in [t0 + cur·dt, t0 + (cur+1)·dt)).
    cur: i64,
}

impl EventQueue {
    /// A queue of `n` particles, all without event (time +∞), with blocks
    /// of length `dt` starting at `t0`.
    pub fn new(n: usize, t0: f64, dt: f64) -> Self {
        let nb = (n / 4).clamp(16, 1 << 20);
        Self {
            time: crate::system::huge_vec(n, f64::INFINITY),
            stamp: crate::system::huge_vec(n, 0),
            heap: BinaryHeap::new(),
            buckets: vec![Vec::new(); nb],
            overflow: Vec::new(),
            in_buckets: 0,
            t0,
            dt: if dt > 0.0 && dt.is_finite() { dt } else { 1.0 },
            cur: 0,
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
    fn block(&self, t: f64) -> i64 {
        ((t - self.t0) / self.dt).floor() as i64
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
    #[inline]
    pub fn pop(&mut self) {
        self.heap.pop();
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
}
