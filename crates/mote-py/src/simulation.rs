//! `mote.Simulation`: a time-stepped scene that Python steps, reads and
//! writes.
//!
//! Stepping follows `mote run` exactly: the first call primes the
//! integrator and measures the start; observables are measured at the
//! scene's `observables_every` (absolute step multiples) and at the end of
//! each `run` (as `mote run` does at its last step), never at other chunk
//! ends, so `run(steps=N)` gives the bits of `mote run --steps N` and a
//! callback every k steps changes nothing.

use std::path::PathBuf;

use glam::DVec3;
use mote_front::stepper::{PointSample, Points, Scalars, Vectors};
use numpy::ndarray::{ArrayView1, ArrayView2};
use numpy::prelude::*;
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{dict_to_toml, front_error};
use crate::stepping::{simulation_class, time_steps, Stepped};

impl Stepped for Points {
    fn advance(
        &mut self,
        n: u64,
        end_sample: bool,
        progress: &mut (dyn FnMut(u64, f64) + Send),
    ) -> PyResult<()> {
        Points::advance(self, n, end_sample, progress).map_err(front_error)
    }

    fn step(&self) -> u64 {
        Points::step(self)
    }

    fn steps_for(&self, steps: Option<u64>, until: Option<f64>) -> PyResult<u64> {
        time_steps(steps, until, self.time(), self.dt(), || {
            self.scene_steps().map_err(front_error)
        })
    }

    fn time(&self) -> f64 {
        Points::time(self)
    }

    fn len(&self) -> usize {
        Points::len(self)
    }

    fn describe(&self) -> String {
        format!(
            "{}: {} particles, dt = {}",
            self.label(),
            self.len(),
            self.dt()
        )
    }
}

impl Simulation {
    fn build(
        input: &mote_front::Input,
        seed: Option<u64>,
        output: Option<PathBuf>,
    ) -> PyResult<Self> {
        let run = Points::build(input, seed, output.as_deref()).map_err(front_error)?;
        Ok(Simulation::wrap(run))
    }
}

fn view<'py>(this: &Bound<'py, Simulation>, which: Vectors) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let s = this.borrow();
    let e = s.engine()?;
    let v = e.vectors(which);
    // DVec3 is three f64 in a row (repr(C)): an (N, 3) array.
    let arr = unsafe { ArrayView2::from_shape_ptr((v.len(), 3), v.as_ptr() as *const f64) };
    // SAFETY: the particle arrays are never reallocated (a time-stepped
    // system keeps its particles), and the array keeps `this` alive.
    Ok(unsafe { PyArray2::borrow_from_array(&arr, this.clone().into_any()) })
}

fn view1<'py>(
    this: &Bound<'py, Simulation>,
    which: Scalars,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let s = this.borrow();
    let e = s.engine()?;
    let v = e.scalars(which);
    let arr = ArrayView1::from(v);
    // SAFETY: as in `view`.
    Ok(unsafe { PyArray1::borrow_from_array(&arr, this.clone().into_any()) })
}

/// Copies an (N, 3) array of floats into `target`, or says the shape it
/// needs.
fn copy_in(values: &Bound<'_, PyAny>, target: &mut [DVec3], what: &str) -> PyResult<()> {
    let n = target.len();
    let wrong = |got: &str| {
        PyValueError::new_err(format!(
            "{what}: expected an array of shape ({n}, 3), got {got}"
        ))
    };
    // Lists and other sequences become arrays first, as numpy would take them.
    let numpy = values.py().import("numpy")?;
    let converted = numpy
        .call_method1("asarray", (values, "float64"))
        .map_err(|_| wrong("something that is not an array of numbers"))?;
    let array = converted
        .extract::<numpy::PyReadonlyArray2<f64>>()
        .map_err(|_| {
            wrong(&format!(
                "{} dimensions",
                converted
                    .getattr("ndim")
                    .map(|d| d.to_string())
                    .unwrap_or_default()
            ))
        })?;
    let shape = array.shape();
    if shape != [n, 3] {
        return Err(wrong(&format!("shape {shape:?}")));
    }
    let a = array.as_array();
    for (i, t) in target.iter_mut().enumerate() {
        *t = DVec3::new(a[[i, 0]], a[[i, 1]], a[[i, 2]]);
    }
    Ok(())
}

simulation_class! {
    /// A time-stepped simulation (gravity, springs, Lennard-Jones, granular,
    /// dipoles, Brownian dynamics) built from a scene: a file, a TOML string
    /// or a dict with the keys of docs/scene-format.md.
    ///
    /// >>> sim = mote.Simulation.from_file("examples/sun-earth.toml")
    /// >>> sim.run(until=365.25)
    /// >>> sim.positions[1]
    pub struct Simulation(Points);
    unit = "steps", every = 100;

    /// A scene file or `example:NAME`; `seed` replaces the scene's. With
    /// `output` (a folder), the run writes there what `mote run` writes as
    /// it goes (observables.csv, the trajectory, on the scene's `[output]`
    /// schedules); without it, no files.
    #[staticmethod]
    #[pyo3(signature = (path, seed=None, output=None))]
    fn from_file(path: PathBuf, seed: Option<u64>, output: Option<PathBuf>) -> PyResult<Self> {
        let input = mote_front::Input::read(&path.to_string_lossy()).map_err(front_error)?;
        Self::build(&input, seed, output)
    }

    /// A scene given as TOML text; `name` labels its messages.
    #[staticmethod]
    #[pyo3(signature = (text, seed=None, name="<string>", output=None))]
    fn from_toml(
        text: &str,
        seed: Option<u64>,
        name: &str,
        output: Option<PathBuf>,
    ) -> PyResult<Self> {
        let input = mote_front::Input {
            name: "python".into(),
            label: name.into(),
            text: text.into(),
            plist: false,
        };
        Self::build(&input, seed, output)
    }

    /// A scene given as a dict of the scene file's tables and keys.
    #[staticmethod]
    #[pyo3(signature = (scene, seed=None, output=None))]
    fn from_dict(
        scene: &Bound<'_, PyDict>,
        seed: Option<u64>,
        output: Option<PathBuf>,
    ) -> PyResult<Self> {
        let text = dict_to_toml(scene)?;
        Self::from_toml(&text, seed, "<dict>", output)
    }

    /// The simulation a checkpoint (`save_checkpoint`, `mote run
    /// --checkpoint-every`) holds, ready to go on bit for bit.
    #[staticmethod]
    fn resume(path: PathBuf) -> PyResult<Self> {
        let cp =
            mote_io::checkpoint::read(&path).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let run = Points::resume(&cp, &path.display().to_string()).map_err(front_error)?;
        Ok(Simulation::wrap(run))
    }

    /// Writes a checkpoint: `Simulation.resume(path)` and `mote run
    /// --resume path` go on from it bit for bit.
    fn save_checkpoint(&self, path: PathBuf) -> PyResult<()> {
        let cp = self.engine()?.checkpoint().map_err(front_error)?;
        mote_io::checkpoint::write(&path, &cp).map_err(|e| crate::MoteError::new_err(e.to_string()))
    }

    #[setter]
    fn set_time(&self, t: f64) -> PyResult<()> {
        if !t.is_finite() {
            return Err(PyValueError::new_err("time must be finite"));
        }
        self.engine()?.set_time(t);
        Ok(())
    }

    /// Time step (settable between runs).
    #[getter]
    fn dt(&self) -> PyResult<f64> {
        Ok(self.engine()?.dt())
    }

    #[setter]
    fn set_dt(&self, dt: f64) -> PyResult<()> {
        self.engine()?.set_dt(crate::stepping::checked_dt(dt)?);
        Ok(())
    }

    /// The seed of the run's random numbers.
    #[getter]
    fn seed(&self) -> PyResult<u64> {
        Ok(self.engine()?.seed())
    }

    /// Positions, (N, 3): a view of mote's memory; writes reach the next step.
    #[getter]
    fn positions<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        view(this, Vectors::Position)
    }

    /// `sim.positions = array`: copies an (N, 3) array in.
    #[setter]
    fn set_positions(&self, values: Bound<'_, PyAny>) -> PyResult<()> {
        let mut e = self.engine()?;
        copy_in(&values, e.vectors_mut(Vectors::Position), "positions")
    }

    /// `sim.velocities = array`: copies an (N, 3) array in.
    #[setter]
    fn set_velocities(&self, values: Bound<'_, PyAny>) -> PyResult<()> {
        let mut e = self.engine()?;
        copy_in(&values, e.vectors_mut(Vectors::Velocity), "velocities")
    }

    /// Velocities, (N, 3), a writable view.
    #[getter]
    fn velocities<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        view(this, Vectors::Velocity)
    }

    /// Angular velocities, (N, 3), a writable view.
    #[getter]
    fn omegas<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        view(this, Vectors::AngularVelocity)
    }

    /// Magnetic dipole moments, (N, 3), a writable view.
    #[getter]
    fn dipoles<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        view(this, Vectors::Dipole)
    }

    /// Masses, (N,), a writable view.
    #[getter]
    fn masses<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        view1(this, Scalars::Mass)
    }

    /// Radii, (N,), a writable view.
    #[getter]
    fn radii<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        view1(this, Scalars::Radius)
    }

    /// Charges, (N,), a writable view.
    #[getter]
    fn charges<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        view1(this, Scalars::Charge)
    }

    /// The box as `(lo, hi, periodic)` — corners (3,), ∓inf on an axis
    /// without faces, and which axes wrap — or None for an open system.
    #[getter(r#box)]
    fn box_corners<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let (lo, hi, periodic) = self.engine()?.boundary();
        // an open box has ∓inf corners on every axis
        if (0..3).all(|k| lo[k].is_infinite() && hi[k].is_infinite()) {
            return Ok(None);
        }
        let lo = PyArray1::from_vec(py, lo.to_array().to_vec());
        let hi = PyArray1::from_vec(py, hi.to_array().to_vec());
        Ok(Some(
            (lo, hi, periodic.to_vec()).into_pyobject(py)?.into_any(),
        ))
    }

    /// The folder the run writes its files to (`output=`), or None.
    #[getter]
    fn output(&self) -> PyResult<Option<PathBuf>> {
        Ok(self.engine()?.output().map(|p| p.to_path_buf()))
    }

    /// The species names of the particles.
    #[getter]
    fn species(&self) -> PyResult<Vec<String>> {
        Ok(self.engine()?.species().to_vec())
    }

    /// The scene's number of each row of the arrays (0 from the first).
    /// Granular scenes store their particles in space order
    /// (`[granular] order`): row k is particle `numbers[k]` of the scene.
    #[getter]
    fn numbers<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<u64>>> {
        Ok(PyArray1::from_vec(py, self.engine()?.numbers()))
    }

    /// The observables measured so far (the columns of `mote run`'s
    /// observables.csv) as numpy arrays: time, kinetic, potential, total,
    /// rotational, kT, pressure, momentum (n, 3), angular_momentum (n, 3),
    /// magnetisation (n, 3).
    #[getter]
    fn observables<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let guard = self.engine()?;
        let s = &guard.samples();
        let d = PyDict::new(py);
        let col = |f: fn(&PointSample) -> f64| PyArray1::from_vec(py, s.iter().map(f).collect());
        let vec3 = |f: fn(&PointSample) -> DVec3| {
            let flat: Vec<f64> = s.iter().flat_map(|o| f(o).to_array()).collect();
            PyArray1::from_vec(py, flat).reshape([s.len(), 3])
        };
        d.set_item("time", col(|o| o.time))?;
        d.set_item("kinetic", col(|o| o.kinetic))?;
        d.set_item("potential", col(|o| o.potential))?;
        d.set_item("total", col(|o| o.kinetic + o.potential))?;
        d.set_item("rotational", col(|o| o.rotational))?;
        d.set_item("kT", col(|o| o.kt))?;
        d.set_item("pressure", col(|o| o.pressure))?;
        d.set_item("momentum", vec3(|o| o.momentum)?)?;
        d.set_item("angular_momentum", vec3(|o| o.angular_momentum)?)?;
        d.set_item("magnetisation", vec3(|o| o.magnetisation)?)?;
        Ok(d)
    }

    /// Ray-traces the current state as `mote run --picture` does: a
    /// (height, width, 3) uint8 array, or a PNG written to `output`.
    #[pyo3(signature = (output=None, width=800, height=600))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        output: Option<PathBuf>,
        width: u32,
        height: u32,
    ) -> PyResult<Option<Bound<'py, PyAny>>> {
        crate::tools::picture(py, &self.engine()?.frame(), output, width, height)
    }

    fn __repr__(&self) -> PyResult<String> {
        let e = self.engine()?;
        Ok(format!(
            "<mote.Simulation {}: {} particles, t = {}, step {}, dt = {}>",
            e.label(),
            e.len(),
            e.time(),
            e.step(),
            e.dt()
        ))
    }
}
