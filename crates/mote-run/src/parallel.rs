//! How a step's parallel sections run: the pool's workers kept polling for
//! work while a run steps, and blocks handed out by a counter.
//!
//! **Kept warm.** //! A step is several short parallel sections (free flight, contacts, the
//! kick, …) with serial work between them. A rayon worker that finds no
//! work sleeps after a few tens of microseconds, and waking it took 50 to
//! 100 µs on the virtual machines mote is measured on — as long as half of
//! a section on two threads, so the woken worker arrived when the section
//! was nearly done (two threads ran the trimer benchmark 1.3 times as fast
//! as one). While a run steps, [`keep_warm`] keeps every other worker of
//! the pool polling for work (rayon's `yield_now`, then the scheduler's),
//! as OpenMP's active wait policy does; a worker that finds nothing for a
//! millisecond goes back to rayon's sleep, so nothing spins once stepping
//! stops or pauses. Which blocks a section has, and so every result, does
//! not depend on it.
//!
//! **Blocks by a counter.** A section cut into a few dozen blocks of
//! unequal work (the contacts of rows of a neighbour list) lost 20–30 % of
//! its two-thread speed-up to rayon's tree of joins, whose leaves are
//! several blocks each and whose waits end late. [`for_each_block`] runs
//! one task per thread, each taking the next block from a counter until
//! none is left (OpenMP's dynamic schedule): measured on two threads, 13
//! blocks of 31 µs took 220 µs against 260–275 µs through rayon's
//! iterators (215 µs is the least, seven blocks on one thread). Each block
//! writes its own item, so the results are those of any other order.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use rayon::prelude::*;

/// How long a kept worker polls without finding work before it sleeps.
const POLL: Duration = Duration::from_millis(1);

/// Workers polling now, in every pool.
static POLLING: AtomicUsize = AtomicUsize::new(0);

/// Sets the current pool's other workers polling for work, unless they
/// still are (from the last step) or the pool has one thread. Called before
/// each step; costs one atomic load when they are.
pub fn keep_warm() {
    if rayon::current_num_threads() < 2 || POLLING.load(Ordering::Acquire) > 0 {
        return;
    }
    let caller = rayon::current_thread_index();
    POLLING.fetch_add(rayon::current_num_threads(), Ordering::AcqRel);
    // A broadcast job runs on its own worker (none steals it): the caller,
    // when it is a worker, stops at once, the others poll.
    rayon::spawn_broadcast(move |ctx| {
        if Some(ctx.index()) != caller {
            poll();
        }
        POLLING.fetch_sub(1, Ordering::AcqRel);
    });
}

/// Calls `work(b, &mut items[b])` for every block b: one task per thread of
/// the current pool, each taking the next block from a counter until none
/// is left. The blocks' order across threads varies; what each block writes
/// to its own item does not.
pub fn for_each_block<T: Send>(items: &mut [T], work: impl Fn(usize, &mut T) + Sync) {
    if rayon::current_num_threads() < 2 || items.len() < 2 {
        for (b, item) in items.iter_mut().enumerate() {
            work(b, item);
        }
        return;
    }
    // Each block is taken once, so its lock is never contended; it only
    // hands the block's item to whichever thread took it.
    let slots: Vec<Mutex<&mut T>> = items.iter_mut().map(Mutex::new).collect();
    let next = AtomicUsize::new(0);
    let tasks = rayon::current_num_threads().min(slots.len());
    (0..tasks)
        .into_par_iter()
        .with_max_len(1)
        .for_each(|_| loop {
            let b = next.fetch_add(1, Ordering::Relaxed);
            let Some(slot) = slots.get(b) else {
                break;
            };
            let mut item = slot.lock().unwrap_or_else(|e| e.into_inner());
            work(b, &mut item);
        });
}

/// Runs the pool's pending work until none has come for [`POLL`].
fn poll() {
    let mut idle_since = Instant::now();
    loop {
        match rayon::yield_now() {
            Some(rayon::Yield::Executed) => idle_since = Instant::now(),
            _ if idle_since.elapsed() > POLL => return,
            // Nothing to do: let any other thread of the machine run.
            _ => std::thread::yield_now(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every block is worked once, on any number of threads, and writes
    /// its own item.
    #[test]
    fn every_block_is_worked_once() {
        for threads in [1, 2, 5] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut items = vec![0u64; 37];
            let calls = AtomicUsize::new(0);
            pool.install(|| {
                for_each_block(&mut items, |b, item| {
                    calls.fetch_add(1, Ordering::Relaxed);
                    *item += (b * b) as u64 + 1;
                })
            });
            assert_eq!(calls.load(Ordering::Relaxed), 37, "{threads} threads");
            let want: Vec<u64> = (0..37).map(|b| (b * b) as u64 + 1).collect();
            assert_eq!(items, want, "{threads} threads");
        }
    }

    /// Kept workers do the pool's work and then stop polling: a parallel
    /// sum after `keep_warm` is the sum, and within a few POLLs of the last
    /// work every worker has gone back to sleep (none is left spinning).
    #[test]
    fn kept_workers_do_the_work_and_then_sleep() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        pool.install(|| {
            for _ in 0..20 {
                keep_warm();
                let s: u64 = (0..100_000u64).into_par_iter().sum();
                assert_eq!(s, 100_000 * 99_999 / 2);
            }
        });
        let deadline = Instant::now() + 200 * POLL;
        while POLLING.load(Ordering::Acquire) > 0 {
            assert!(Instant::now() < deadline, "workers still polling");
            std::thread::sleep(POLL);
        }
    }
}
