//! What every Python simulation class shares. Each steps `mote run`'s
//! propagator through the front's [`mote_front::stepper::Stepper`], that
//! is through mote's one run loop (`mote_run::Driver`): the first call
//! primes the propagator and measures the start; then the observables are
//! measured on the scene's schedule (absolute steps) and at the end of each
//! `run`, as `mote run` does at its last step, never at other chunk ends.
//! So `run()` gives the bits of `mote run`, and chunks or callbacks change
//! nothing.

use std::sync::{Mutex, MutexGuard};

use mote_run::scene::RunLength;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// What the shared `run` loop needs of a simulation's engine.
pub trait Stepped: Send {
    /// Advances `n` steps, measuring on the schedule and, with
    /// `end_sample`, after the last; `progress(step, time)` now and then.
    fn advance(
        &mut self,
        n: u64,
        end_sample: bool,
        progress: &mut (dyn FnMut(u64, f64) + Send),
    ) -> PyResult<()>;
    /// The step now.
    fn step(&self) -> u64;
    /// The steps a `run(steps, until)` takes from now: `steps`, to the
    /// first step at or past `until`, or to the scene's own end.
    fn steps_for(&self, steps: Option<u64>, until: Option<f64>) -> PyResult<u64>;
    /// The opening line's description (label, size, step).
    fn describe(&self) -> String;
    /// The simulated time.
    fn time(&self) -> f64;
    /// The number of particles (bodies for clumps).
    fn len(&self) -> usize;
    /// Whether the run has reached an end of its own (a jammed packing).
    fn finished(&self) -> bool {
        false
    }
}

/// Defines a Python simulation class once: the struct holding its engine
/// behind a lock, and the methods every class has — `step`, `run`, the
/// `time` and `steps` getters, `len()` — beside the class's own. `unit`
/// names a step in the docstrings ("steps", "output intervals"); `every`
/// is `run`'s default callback interval.
macro_rules! simulation_class {
    (
        $(#[$attr:meta])*
        pub struct $class:ident($engine:ty);
        unit = $unit:literal, every = $every:literal;
        $($own:tt)*
    ) => {
        $(#[$attr])*
        #[pyo3::pyclass(module = "mote")]
        pub struct $class {
            /// Behind a lock: Python may call from several threads.
            engine: std::sync::Mutex<$engine>,
        }

        impl $class {
            fn wrap(engine: $engine) -> Self {
                $class {
                    engine: std::sync::Mutex::new(engine),
                }
            }

            fn engine(&self) -> pyo3::PyResult<std::sync::MutexGuard<'_, $engine>> {
                $crate::stepping::lock(&self.engine)
            }
        }

        impl $crate::stepping::HasEngine for $class {
            type Engine = $engine;
            fn engine(&self) -> pyo3::PyResult<std::sync::MutexGuard<'_, $engine>> {
                $crate::stepping::lock(&self.engine)
            }
        }

        #[pyo3::pymethods]
        impl $class {
            #[doc = concat!("Advances `n` ", $unit, " (the GIL is released meanwhile).")]
            #[pyo3(signature = (n=1))]
            fn step(&self, py: pyo3::Python<'_>, n: u64) -> pyo3::PyResult<()> {
                let mut guard = self.engine()?;
                let engine = &mut *guard;
                py.detach(|| $crate::stepping::Stepped::advance(engine, n, false, &mut |_, _| {}))
            }

            #[doc = concat!(
                "Runs `steps` ", $unit, ", or to the first step at time `until` or past it ",
                "(where the class steps in time), or to the scene's end when neither is given, calling `callback(sim)` every `every` ", $unit,
                " when given; `progress=True` shows `mote run`'s progress bar on stderr. ",
                "The GIL is released while mote computes."
            )]
            #[pyo3(signature = (steps=None, until=None, callback=None, every=$every, progress=false))]
            fn run(
                slf: pyo3::Bound<'_, Self>,
                steps: Option<u64>,
                until: Option<f64>,
                callback: Option<pyo3::Bound<'_, pyo3::PyAny>>,
                every: u64,
                progress: bool,
            ) -> pyo3::PyResult<()> {
                $crate::stepping::run_loop(&slf, steps, until, callback, every, progress)
            }

            /// Simulated time.
            #[getter]
            fn time(&self) -> pyo3::PyResult<f64> {
                Ok($crate::stepping::Stepped::time(&*self.engine()?))
            }

            #[doc = concat!("The ", $unit, " taken.")]
            #[getter]
            fn steps(&self) -> pyo3::PyResult<u64> {
                Ok($crate::stepping::Stepped::step(&*self.engine()?))
            }

            fn __len__(&self) -> pyo3::PyResult<usize> {
                Ok($crate::stepping::Stepped::len(&*self.engine()?))
            }

            $($own)*
        }
    };
}
pub(crate) use simulation_class;

/// The steps of a time-stepped run from `time` with steps of `dt`: `steps`,
/// or to the first step at or past `until` (`mote run --until`'s rule), or
/// to `scene_end`, the scene's own.
pub fn time_steps(
    steps: Option<u64>,
    until: Option<f64>,
    time: f64,
    dt: f64,
    scene_end: impl FnOnce() -> PyResult<Option<u64>>,
) -> PyResult<u64> {
    let length = match (steps, until) {
        (Some(_), Some(_)) => return Err(PyValueError::new_err("give steps or until, not both")),
        (Some(n), None) => RunLength::Steps(n),
        (None, Some(t)) if t.is_finite() => RunLength::Until(t),
        (None, Some(t)) => {
            return Err(PyValueError::new_err(format!(
                "until = {t}: must be a finite time"
            )))
        }
        (None, None) => {
            return scene_end()?.ok_or_else(|| {
                PyValueError::new_err("the scene gives no run length: give steps= or until=")
            })
        }
    };
    length.steps_from(time, dt).map_err(PyValueError::new_err)
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
        let total = e.steps_for(steps, until)?;
        let length = if total == u64::MAX {
            "until it stops".to_string()
        } else {
            format!("{total} steps")
        };
        (
            e.step(),
            total,
            format!("mote (Python) {}, {length}", e.describe()),
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
            if engine.finished() {
                break;
            }
            let last = done + n == total;
            let terminal = &mut terminal;
            py.detach(|| {
                engine.advance(n, last, &mut |step, t| {
                    let note = format!("t = {t:.6e}");
                    mote_front::Monitor::progress(terminal, step - first, total, &note)
                })
            })?;
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
