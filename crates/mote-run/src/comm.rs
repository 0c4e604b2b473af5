//! The ranks of a run and what passes between them, in MPI's model: every
//! rank runs the same program on its part of the state, and the ranks meet
//! in paired exchanges (MPI_Sendrecv) and collectives (gather to rank 0,
//! broadcast from it). An engine that decomposes its state is written
//! against [`Comm`] alone; [`Solo`] is one process, [`in_process`] runs
//! ranks as threads of one process (what the tests of a decomposition run
//! on every machine), and the `mpi` feature of the binary gives the ranks
//! of `mpirun`.
//!
//! Numbers travel as f64; integers below 2⁵³ (particle ids, counts) travel
//! exactly in them.

use std::collections::{HashMap, VecDeque};
use std::sync::{Arc, Condvar, Mutex};

/// The ranks of a run, seen from one of them.
pub trait Comm: Send + Sync {
    /// This rank, 0 ≤ rank < size.
    fn rank(&self) -> usize;
    /// The number of ranks.
    fn size(&self) -> usize;
    /// Sends `send` to rank `to` and returns what rank `from` sent to this
    /// one in its matching call (MPI_Sendrecv; `None` is MPI_PROC_NULL: no
    /// send, or nothing received). Messages between two ranks arrive in
    /// the order they were sent; a rank may be its own partner.
    fn exchange(&self, to: Option<usize>, send: &[f64], from: Option<usize>) -> Vec<f64>;
    /// At rank 0, every rank's `send` in rank order; empty elsewhere.
    fn gather(&self, send: &[f64]) -> Vec<Vec<f64>>;
    /// Rank 0's `data`, at every rank (the others' `data` is not read).
    fn broadcast(&self, data: &[f64]) -> Vec<f64>;

    /// The largest `x` over the ranks, at every rank.
    fn max(&self, x: f64) -> f64 {
        let all = self.gather(&[x]);
        let top = all.iter().map(|v| v[0]).fold(f64::NEG_INFINITY, f64::max);
        self.broadcast(&[top])[0]
    }

    /// Σ `x` over the ranks in rank order, element by element, at every
    /// rank: the same bits on every rank (an MPI_Allreduce may differ by
    /// round-off between them).
    fn sum(&self, x: &[f64]) -> Vec<f64> {
        let all = self.gather(x);
        let mut total = vec![0.0; x.len()];
        for v in &all {
            for (t, y) in total.iter_mut().zip(v) {
                *t += y;
            }
        }
        self.broadcast(&total)
    }
}

/// One process: rank 0 of 1.
#[derive(Debug, Clone, Copy, Default)]
pub struct Solo;

impl Comm for Solo {
    fn rank(&self) -> usize {
        0
    }

    fn size(&self) -> usize {
        1
    }

    fn exchange(&self, to: Option<usize>, send: &[f64], from: Option<usize>) -> Vec<f64> {
        assert!(
            to.unwrap_or(0) == 0 && from.unwrap_or(0) == 0,
            "one process has rank 0 alone"
        );
        match (to, from) {
            (Some(_), Some(_)) => send.to_vec(),
            (None, Some(_)) => panic!("rank 0 waits for a message it never sent"),
            _ => Vec::new(),
        }
    }

    fn gather(&self, send: &[f64]) -> Vec<Vec<f64>> {
        vec![send.to_vec()]
    }

    fn broadcast(&self, data: &[f64]) -> Vec<f64> {
        data.to_vec()
    }
}

/// A message's kind: a paired exchange or a collective, kept apart so that
/// one can never be taken for the other.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Kind {
    Exchange,
    Collective,
}

/// The messages from one rank to another of one kind, in sending order.
type Queues = HashMap<(usize, usize, Kind), VecDeque<Vec<f64>>>;

/// The messages in flight between the ranks of [`in_process`].
#[derive(Default)]
struct Post {
    boxes: Mutex<Queues>,
    arrived: Condvar,
}

impl Post {
    fn send(&self, from: usize, to: usize, kind: Kind, data: Vec<f64>) {
        let mut boxes = self.boxes.lock().expect("a rank panicked");
        boxes.entry((from, to, kind)).or_default().push_back(data);
        self.arrived.notify_all();
    }

    fn receive(&self, from: usize, to: usize, kind: Kind) -> Vec<f64> {
        let mut boxes = self.boxes.lock().expect("a rank panicked");
        loop {
            if let Some(data) = boxes.get_mut(&(from, to, kind)).and_then(|q| q.pop_front()) {
                return data;
            }
            boxes = self.arrived.wait(boxes).expect("a rank panicked");
        }
    }
}

/// One rank of [`in_process`].
struct Local {
    rank: usize,
    size: usize,
    post: Arc<Post>,
}

impl Comm for Local {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.size
    }

    fn exchange(&self, to: Option<usize>, send: &[f64], from: Option<usize>) -> Vec<f64> {
        if let Some(to) = to {
            assert!(to < self.size, "no rank {to}");
            self.post.send(self.rank, to, Kind::Exchange, send.to_vec());
        }
        from.map_or_else(Vec::new, |from| {
            assert!(from < self.size, "no rank {from}");
            self.post.receive(from, self.rank, Kind::Exchange)
        })
    }

    fn gather(&self, send: &[f64]) -> Vec<Vec<f64>> {
        self.post
            .send(self.rank, 0, Kind::Collective, send.to_vec());
        if self.rank != 0 {
            return Vec::new();
        }
        (0..self.size)
            .map(|r| self.post.receive(r, 0, Kind::Collective))
            .collect()
    }

    fn broadcast(&self, data: &[f64]) -> Vec<f64> {
        if self.rank == 0 {
            for r in 1..self.size {
                self.post.send(0, r, Kind::Collective, data.to_vec());
            }
            data.to_vec()
        } else {
            self.post.receive(0, self.rank, Kind::Collective)
        }
    }
}

/// Runs `work` as `ranks` ranks, each on a thread of its own, and returns
/// what each returned, in rank order: a decomposed run inside one process,
/// as `mpirun -np ranks` would run it across processes. A rank that panics
/// panics the caller.
pub fn in_process<T: Send>(ranks: usize, work: impl Fn(Arc<dyn Comm>) -> T + Sync) -> Vec<T> {
    assert!(ranks > 0, "at least one rank");
    let post = Arc::new(Post::default());
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..ranks)
            .map(|rank| {
                let comm: Arc<dyn Comm> = Arc::new(Local {
                    rank,
                    size: ranks,
                    post: Arc::clone(&post),
                });
                let work = &work;
                scope.spawn(move || work(comm))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ring: each rank sends its number to the next and hears the one
    /// before; messages between a pair keep their order.
    #[test]
    fn exchanges_pair_ranks_in_order() {
        for ranks in [1, 2, 3, 5] {
            let heard = in_process(ranks, |c| {
                let (next, before) = ((c.rank() + 1) % ranks, (c.rank() + ranks - 1) % ranks);
                let a = c.exchange(Some(next), &[c.rank() as f64], Some(before));
                let b = c.exchange(Some(next), &[10.0 + c.rank() as f64, 1.0], Some(before));
                // An open end: rank 0 sends to no one, the last hears no one.
                let up = (c.rank() + 1 < ranks).then_some(c.rank() + 1);
                let down = c.rank().checked_sub(1);
                let c_ = c.exchange(up, &[c.rank() as f64], down);
                (a, b, c_)
            });
            for (r, (a, b, c)) in heard.iter().enumerate() {
                let before = ((r + ranks - 1) % ranks) as f64;
                assert_eq!(a, &vec![before]);
                assert_eq!(b, &vec![10.0 + before, 1.0]);
                let down: Vec<f64> = r.checked_sub(1).map(|d| d as f64).into_iter().collect();
                assert_eq!(c, &down);
            }
        }
    }

    #[test]
    fn collectives_reach_every_rank() {
        let out = in_process(4, |c| {
            let x = c.rank() as f64 + 0.5;
            (c.max(x), c.sum(&[x, 1.0]), c.gather(&[x]).len())
        });
        for (r, (max, sum, gathered)) in out.into_iter().enumerate() {
            assert_eq!(max, 3.5);
            assert_eq!(sum, vec![8.0, 4.0]);
            assert_eq!(gathered, if r == 0 { 4 } else { 0 });
        }
        assert_eq!(Solo.sum(&[2.0]), vec![2.0]);
        assert_eq!(Solo.exchange(Some(0), &[1.0, 2.0], Some(0)), vec![1.0, 2.0]);
        assert!(Solo.exchange(Some(0), &[1.0], None).is_empty());
    }
}
