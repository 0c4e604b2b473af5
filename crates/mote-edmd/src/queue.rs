//! Indexed 4-ary min-heap over per-particle next-event times.
//!
//! Each particle holds exactly one scheduled event (the "single event" scheme
//! of Smallenburg, arXiv:2201.01099); the heap orders particles by that time.
//! `update` moves one key up or down in O(log N), `min` is O(1).

/// Children per node: 4 entries of 16 bytes fill one cache line.
const ARITY: usize = 4;

/// A min-heap of `(time, particle)` with a position index per particle.
#[derive(Debug, Clone, Default)]
pub struct EventQueue {
    heap: Vec<(f64, u32)>,
    pos: Vec<u32>,
}

impl EventQueue {
    /// A queue of `n` particles, all at time +∞.
    pub fn new(n: usize) -> Self {
        Self {
            heap: (0..n as u32).map(|i| (f64::INFINITY, i)).collect(),
            pos: (0..n as u32).collect(),
        }
    }

    pub fn len(&self) -> usize {
        self.heap.len()
    }

    pub fn is_empty(&self) -> bool {
        self.heap.is_empty()
    }

    /// The particle with the earliest event and its time.
    #[inline]
    pub fn min(&self) -> Option<(f64, usize)> {
        self.heap.first().map(|&(t, i)| (t, i as usize))
    }

    /// Sets the event time of particle `i`.
    #[inline]
    pub fn update(&mut self, i: usize, t: f64) {
        let k = self.pos[i] as usize;
        let old = self.heap[k].0;
        self.heap[k].0 = t;
        if t < old {
            self.sift_up(k);
        } else {
            self.sift_down(k);
        }
    }

    #[inline]
    fn sift_up(&mut self, mut k: usize) {
        let item = self.heap[k];
        while k > 0 {
            let p = (k - 1) / ARITY;
            if self.heap[p].0 <= item.0 {
                break;
            }
            self.heap[k] = self.heap[p];
            self.pos[self.heap[k].1 as usize] = k as u32;
            k = p;
        }
        self.heap[k] = item;
        self.pos[item.1 as usize] = k as u32;
    }

    #[inline]
    fn sift_down(&mut self, mut k: usize) {
        let n = self.heap.len();
        let item = self.heap[k];
        loop {
            let first = ARITY * k + 1;
            if first >= n {
                break;
            }
            let last = (first + ARITY).min(n);
            let mut c = first;
            let mut tc = self.heap[first].0;
            for m in first + 1..last {
                let tm = self.heap[m].0;
                if tm < tc {
                    c = m;
                    tc = tm;
                }
            }
            if tc >= item.0 {
                break;
            }
            self.heap[k] = self.heap[c];
            self.pos[self.heap[k].1 as usize] = k as u32;
            k = c;
        }
        self.heap[k] = item;
        self.pos[item.1 as usize] = k as u32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_order() {
        let mut q = EventQueue::new(100);
        let mut x: u64 = 12345;
        let mut keys = vec![0.0; 100];
        for (i, key) in keys.iter_mut().enumerate() {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            *key = (x >> 11) as f64 / (1u64 << 53) as f64;
            q.update(i, *key);
        }
        let mut last = -1.0;
        for _ in 0..100 {
            let (t, i) = q.min().unwrap();
            assert_eq!(t, keys[i]);
            assert!(t >= last);
            last = t;
            q.update(i, f64::INFINITY);
        }
    }
}
