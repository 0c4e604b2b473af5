//! Stepping a run from outside, a stretch at a time (Python's classes):
//! the propagator `mote run` steps, moved by the same [`Driver`], so that
//! stepping in stretches measures on `mote run`'s schedule and ends in its
//! bits, and a signal or a non-finite state stops it the same way.

use std::sync::{Arc, Mutex, MutexGuard};

use mote_run::{Driver, Observer, Propagator};

mod hard_spheres;
mod packing;
mod points;
mod rigid;

pub use hard_spheres::HardSpheres;
pub use packing::Packing;
pub use points::{PointSample, Points, Scalars, Vectors};
pub use rigid::{BodyVectors, Rigid, RigidObservables};

/// A propagator, the driver that steps it and the samples taken so far:
/// at the start, at multiples of `observables_every` (absolute steps) and
/// at the end of each stretch that ends a run, never at other stretch ends.
pub struct Stepper<P: Propagator> {
    pub state: P,
    driver: Driver<P>,
    samples: Arc<Mutex<Vec<P::Sample>>>,
    started: bool,
}

/// The observer that keeps the samples.
struct Samples<S> {
    every: u64,
    taken: Arc<Mutex<Vec<S>>>,
}

impl<P> Observer<P> for Samples<P::Sample>
where
    P: Propagator,
    P::Sample: Send,
{
    fn every(&self) -> u64 {
        self.every
    }

    fn observe(&mut self, _: &P, sample: &P::Sample) -> Result<(), P::Error> {
        lock(&self.taken).push(sample.clone());
        Ok(())
    }
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

impl<P> Stepper<P>
where
    P: Propagator + Send + 'static,
    P::Sample: Send + 'static,
{
    /// A state not yet started; `observables_every` 0 measures only the
    /// start and the ends of runs.
    pub fn new(state: P, observables_every: u64) -> Self {
        let samples = Arc::new(Mutex::new(Vec::new()));
        let mut driver = Driver::new();
        driver.observers.push(Box::new(Samples {
            every: if observables_every == 0 {
                u64::MAX
            } else {
                observables_every
            },
            taken: samples.clone(),
        }));
        Stepper {
            state,
            driver,
            samples,
            started: false,
        }
    }

    /// Adds an observer (a file the run writes as it goes).
    pub fn observe_with(&mut self, observer: Box<dyn Observer<P>>) {
        self.driver.observers.push(observer);
    }

    /// Marks the run as started: a state taken from a checkpoint, whose
    /// run already measured its start.
    pub fn mark_started(&mut self) {
        self.started = true;
    }

    /// Advances as [`Stepper::advance`], calling `progress(step, time)`
    /// every 16 steps.
    pub fn advance_every_16(
        &mut self,
        n: u64,
        ends_run: bool,
        progress: &mut dyn FnMut(u64, f64),
    ) -> Result<(), P::Error> {
        self.advance(n, ends_run, &mut |p| {
            if p.step().is_multiple_of(16) {
                progress(p.step(), p.time())
            }
        })
    }

    /// Starts the run on the first call: primes the state and measures
    /// the start (a propagator is primed once per run; a state that must
    /// be primed again, after its particles were moved from outside, is
    /// primed by its owner).
    pub fn prepare(&mut self) -> Result<(), P::Error> {
        if !self.started {
            self.driver.start(&mut self.state, &mut |_| {})?;
            self.started = true;
        }
        Ok(())
    }

    /// Advances `n` steps through the driver; `ends_run` makes the last of
    /// them the end of a run (sampled, as `mote run` samples its last step).
    pub fn advance(
        &mut self,
        n: u64,
        ends_run: bool,
        progress: &mut dyn FnMut(&P),
    ) -> Result<(), P::Error> {
        self.prepare()?;
        let last = self.state.step().saturating_add(n);
        self.driver
            .advance_to(&mut self.state, last, ends_run, progress)
            .map(|_| ())
    }

    /// The samples taken so far.
    pub fn samples(&self) -> MutexGuard<'_, Vec<P::Sample>> {
        lock(&self.samples)
    }
}
