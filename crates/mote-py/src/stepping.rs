//! The stepping both Python simulations share, on `mote run`'s schedule:
//! the first call primes the propagator and measures the start; then the
//! observables are measured at multiples of `observables_every` (absolute
//! steps) and at the end of each `run`, as `mote run` does at its last
//! step, never at other chunk ends. So `run(steps=N)` gives the bits of
//! `mote run --steps N`, and chunks or callbacks change nothing.

use std::sync::{Mutex, MutexGuard};

use mote_md::{MdError, RunLength};
use mote_run::{Propagator, Stopped};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::convert::md_error;

/// A propagator with its measured samples.
pub struct Stepping<P: Propagator> {
    pub state: P,
    pub observables_every: u64,
    pub primed: bool,
    pub samples: Vec<P::Sample>,
}

impl<P: Propagator<Error = MdError>> Stepping<P> {
    pub fn new(state: P, observables_every: u64) -> Self {
        Stepping {
            state,
            observables_every,
            primed: false,
            samples: Vec::new(),
        }
    }

    /// Primes (a no-op once primed, unless the state asks again) and
    /// measures the start on the first call.
    pub fn prepare(&mut self) -> Result<(), MdError> {
        self.state.prime(&mut |_| {})?;
        if !self.primed {
            let s = self.state.measure();
            self.samples.push(s);
            self.primed = true;
        }
        Ok(())
    }

    /// Advances `n` steps, measuring on the schedule and, with
    /// `end_sample`, after the last; `progress(step, time)` every 16 steps.
    pub fn advance(
        &mut self,
        n: u64,
        end_sample: bool,
        progress: &mut (dyn FnMut(u64, f64) + Send),
    ) -> Result<(), MdError> {
        self.prepare()?;
        let last = self.state.step() + n;
        let every = self.observables_every;
        while self.state.step() < last {
            self.state.advance()?;
            let step = self.state.step();
            if let Some((particle, what)) = self.state.unstable() {
                return Err(Stopped::Unstable {
                    step,
                    time: self.state.time(),
                    particle,
                    what,
                }
                .into());
            }
            let end = end_sample && step == last;
            if end || (every > 0 && step.is_multiple_of(every)) {
                let s = self.state.measure();
                self.samples.push(s);
            }
            if step.is_multiple_of(16) {
                progress(step, self.state.time());
            }
        }
        Ok(())
    }
}

/// What the shared `run` loop needs of a simulation's engine.
pub trait Stepped: Send {
    /// Advances as [`Stepping::advance`].
    fn advance(
        &mut self,
        n: u64,
        end_sample: bool,
        progress: &mut (dyn FnMut(u64, f64) + Send),
    ) -> Result<(), MdError>;
    /// Step, time, time step.
    fn clock(&self) -> (u64, f64, f64);
    /// The scene's own run length, if it gives one.
    fn scene_length(&self) -> PyResult<Option<RunLength>>;
    /// The opening line's description (label, size).
    fn describe(&self) -> String;
}

/// A Python class that holds a [`Stepped`] engine behind a lock.
pub trait HasEngine {
    type Engine: Stepped;
    fn engine(&self) -> PyResult<MutexGuard<'_, Self::Engine>>;
}

/// `run(steps, until, callback, every, progress)` of every simulation
/// class: the length, the chunks between callbacks (the GIL released in
/// each), `mote run`'s progress bar when asked.
pub fn run_loop<T: HasEngine + pyo3::PyClass<Frozen = pyo3::pyclass::boolean_struct::False>>(
    slf: &Bound<'_, T>,
    steps: Option<u64>,
    until: Option<f64>,
    callback: Option<Bound<'_, PyAny>>,
    every: u64,
    progress: bool,
) -> PyResult<()> {
    let py = slf.py();
    let (first, total, line) = {
        let s = slf.borrow();
        let e = s.engine()?;
        let (step, time, dt) = e.clock();
        let length = match (steps, until) {
            (Some(_), Some(_)) => {
                return Err(PyValueError::new_err("give steps or until, not both"))
            }
            (Some(n), None) => RunLength::Steps(n),
            (None, Some(t)) if t.is_finite() => RunLength::Until(t),
            (None, Some(t)) => {
                return Err(PyValueError::new_err(format!(
                    "until = {t}: must be a finite time"
                )))
            }
            (None, None) => e.scene_length()?.ok_or_else(|| {
                PyValueError::new_err("the scene gives no run length: give steps= or until=")
            })?,
        };
        let total = length
            .steps_from(time, dt)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        (
            step,
            total,
            format!("mote (Python) {}, dt = {dt}, {total} steps", e.describe()),
        )
    };
    if every == 0 {
        return Err(PyValueError::new_err("every must be at least 1"));
    }
    let chunk = if callback.is_some() {
        every
    } else {
        total.max(1)
    };
    let mut terminal = mote_front::Terminal::new(!progress);
    mote_front::Monitor::start(&mut terminal, &line);
    let mut done = 0;
    while done < total {
        let n = chunk.min(total - done);
        {
            let s = slf.borrow();
            let mut guard = s.engine()?;
            let engine = &mut *guard;
            let last = done + n == total;
            let terminal = &mut terminal;
            py.detach(|| {
                engine.advance(n, last, &mut |step, t| {
                    let note = format!("t = {t:.6e}");
                    mote_front::Monitor::progress(terminal, step - first, total, &note)
                })
            })
            .map_err(md_error)?;
        }
        done += n;
        if let Some(f) = &callback {
            f.call1((slf.clone(),))?;
        }
    }
    mote_front::Monitor::finish(&mut terminal);
    Ok(())
}

/// A simulation's engine, unless another thread is running it (waiting
/// for it while holding the GIL could deadlock with that thread's return).
pub fn lock<E>(engine: &Mutex<E>) -> PyResult<MutexGuard<'_, E>> {
    match engine.try_lock() {
        Ok(g) => Ok(g),
        // A panic while holding the lock leaves the state as it was at that
        // point: still readable.
        Err(std::sync::TryLockError::Poisoned(p)) => Ok(p.into_inner()),
        Err(std::sync::TryLockError::WouldBlock) => Err(crate::MoteError::new_err(
            "the simulation is running in another thread",
        )),
    }
}

/// A time step a run can take: positive and finite.
pub fn checked_dt(dt: f64) -> PyResult<f64> {
    if dt > 0.0 && dt.is_finite() {
        Ok(dt)
    } else {
        Err(PyValueError::new_err(format!(
            "dt = {dt}: must be positive and finite"
        )))
    }
}
