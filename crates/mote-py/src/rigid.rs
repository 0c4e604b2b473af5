//! `mote.RigidSimulation`: a `[rigid]` scene (clumps of overlapping
//! spheres moved by the FRBI) that Python steps and reads, on `mote run`'s
//! measurement schedule (see [`crate::stepping`]).

use std::path::PathBuf;

use glam::DVec3;
use mote_front::stepper::{BodyVectors, Rigid, RigidObservables};
use numpy::ndarray::ArrayView2;
use numpy::prelude::*;
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{dict_to_toml, front_error};
use crate::stepping::{simulation_class, time_steps, Stepped};

impl Stepped for Rigid {
    fn advance(
        &mut self,
        n: u64,
        end_sample: bool,
        progress: &mut (dyn FnMut(u64, f64) + Send),
    ) -> PyResult<()> {
        Rigid::advance(self, n, end_sample, progress).map_err(front_error)
    }

    fn step(&self) -> u64 {
        Rigid::step(self)
    }

    fn steps_for(&self, steps: Option<u64>, until: Option<f64>) -> PyResult<u64> {
        // A rigid scene always gives its length (steps or until).
        time_steps(steps, until, self.time(), self.dt(), || {
            Ok(Some(self.scene_steps()))
        })
    }

    fn time(&self) -> f64 {
        Rigid::time(self)
    }

    fn len(&self) -> usize {
        Rigid::len(self)
    }

    fn describe(&self) -> String {
        format!(
            "{}: {} bodies, dt = {}",
            self.label(),
            self.len(),
            self.dt()
        )
    }
}

fn body_view<'py>(
    this: &Bound<'py, RigidSimulation>,
    which: BodyVectors,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let s = this.borrow();
    let e = s.engine()?;
    let v = e.vectors(which);
    // SAFETY: DVec3 is three f64 in a row; the bodies' arrays are never
    // reallocated after the scene is built, and the array keeps `this` alive.
    let arr = unsafe { ArrayView2::from_shape_ptr((v.len(), 3), v.as_ptr() as *const f64) };
    Ok(unsafe { PyArray2::borrow_from_array(&arr, this.clone().into_any()) })
}

simulation_class! {
    /// Rigid clumps of overlapping spheres (a scene with `[rigid]`, see
    /// docs/rigid.md) stepped by the Fast Rigid Bodies Integrator.
    ///
    /// >>> sim = mote.RigidSimulation.from_file("example:magnet-in-field")
    /// >>> sim.run(steps=1000)
    /// >>> sim.orientations      # unit quaternions (w, x, y, z) of the bodies
    pub struct RigidSimulation(Rigid);
    unit = "steps", every = 100;

    /// A rigid scene file or `example:NAME`; `seed` replaces the scene's.
    #[staticmethod]
    #[pyo3(signature = (path, seed=None))]
    fn from_file(path: PathBuf, seed: Option<u64>) -> PyResult<Self> {
        let input = mote_front::Input::read(&path.to_string_lossy()).map_err(front_error)?;
        Self::from_toml(&input.text, seed, &input.label)
    }

    /// A rigid scene given as TOML text; `name` labels its messages.
    #[staticmethod]
    #[pyo3(signature = (text, seed=None, name="<string>"))]
    fn from_toml(text: &str, seed: Option<u64>, name: &str) -> PyResult<Self> {
        Ok(RigidSimulation::wrap(
            Rigid::build(text, name, seed).map_err(front_error)?,
        ))
    }

    /// A rigid scene given as a dict of the scene file's tables and keys.
    #[staticmethod]
    #[pyo3(signature = (scene, seed=None))]
    fn from_dict(scene: &Bound<'_, PyDict>, seed: Option<u64>) -> PyResult<Self> {
        Self::from_toml(&dict_to_toml(scene)?, seed, "<dict>")
    }

    /// The rigid simulation a checkpoint (`save_checkpoint`) holds: bodies,
    /// spins and contact histories, ready to go on bit for bit.
    #[staticmethod]
    fn resume(path: PathBuf) -> PyResult<Self> {
        let cp =
            mote_io::checkpoint::read(&path).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let run = Rigid::resume(&cp, &path.display().to_string()).map_err(front_error)?;
        Ok(RigidSimulation::wrap(run))
    }

    /// Writes a checkpoint that `RigidSimulation.resume` continues bit for bit.
    fn save_checkpoint(&self, path: PathBuf) -> PyResult<()> {
        let cp = self.engine()?.checkpoint().map_err(front_error)?;
        mote_io::checkpoint::write(&path, &cp).map_err(|e| crate::MoteError::new_err(e.to_string()))
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

    /// Centres of mass, (N, 3): a writable view of mote's memory.
    #[getter]
    fn positions<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        body_view(this, BodyVectors::Position)
    }

    /// Velocities of the centres of mass, (N, 3), a writable view.
    #[getter]
    fn velocities<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        body_view(this, BodyVectors::Velocity)
    }

    /// Angular velocities ω, (N, 3), a writable view.
    #[getter]
    fn omegas<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        body_view(this, BodyVectors::Omega)
    }

    /// Rotation vectors r = n·tan(φ/2) of the bodies' placements (seed
    /// 000), (N, 3), a writable view.
    #[getter]
    fn rotations<'py>(this: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        body_view(this, BodyVectors::Rotation)
    }

    /// Orientations as unit quaternions (w, x, y, z) = (1, r)/√(1 + r²),
    /// (N, 4) (a copy).
    #[getter]
    fn orientations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let e = self.engine()?;
        let r = e.vectors(BodyVectors::Rotation);
        let flat: Vec<f64> = r
            .iter()
            .flat_map(|r| {
                let c = 1.0 / (1.0 + r.length_squared()).sqrt();
                [c, r.x * c, r.y * c, r.z * c]
            })
            .collect();
        PyArray1::from_vec(py, flat).reshape([r.len(), 4])
    }

    /// Masses of the bodies, (N,) (a copy: they belong to the templates).
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(PyArray1::from_vec(py, self.engine()?.masses()))
    }

    /// The scene's number of each body row of the arrays (0 from the
    /// first). Rigid scenes store their bodies in space order (`[rigid]
    /// order`): row k is body `numbers[k]` of the scene.
    #[getter]
    fn numbers<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<u64>>> {
        Ok(PyArray1::from_vec(py, self.engine()?.numbers()))
    }

    /// The spheres in the world, body after body in the scene's numbering:
    /// dict of positions (M, 3), velocities (M, 3), radii (M,), body (M,)
    /// the scene number of the body of each (see `numbers`).
    fn spheres<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let f = self.engine()?.spheres();
        let m = f.positions.len();
        let flat = |v: &[[f64; 3]]| v.iter().flat_map(|x| *x).collect::<Vec<f64>>();
        let d = PyDict::new(py);
        d.set_item(
            "positions",
            PyArray1::from_vec(py, flat(&f.positions)).reshape([m, 3])?,
        )?;
        d.set_item(
            "velocities",
            PyArray1::from_vec(py, flat(&f.velocities)).reshape([m, 3])?,
        )?;
        d.set_item("radii", PyArray1::from_vec(py, f.radii))?;
        d.set_item("body", PyArray1::from_vec(py, f.bodies))?;
        Ok(d)
    }

    /// The observables measured so far (the columns of `mote run`'s
    /// observables.csv): time, kinetic, translational, rotational,
    /// potential, total (n,), momentum, angular_momentum (n, 3), and
    /// pressure (n,) where the run measures it (a box periodic on every
    /// axis, every interaction with a virial).
    #[getter]
    fn observables<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let guard = self.engine()?;
        let s = &guard.samples();
        let d = PyDict::new(py);
        let col =
            |f: fn(&RigidObservables) -> f64| PyArray1::from_vec(py, s.iter().map(f).collect());
        let vec3 = |f: fn(&RigidObservables) -> DVec3| {
            let flat: Vec<f64> = s.iter().flat_map(|o| f(o).to_array()).collect();
            PyArray1::from_vec(py, flat).reshape([s.len(), 3])
        };
        d.set_item("time", col(|o| o.time))?;
        d.set_item("kinetic", col(|o| o.translational + o.rotational))?;
        d.set_item("translational", col(|o| o.translational))?;
        d.set_item("rotational", col(|o| o.rotational))?;
        d.set_item("potential", col(|o| o.potential))?;
        d.set_item(
            "total",
            col(|o| o.translational + o.rotational + o.potential),
        )?;
        d.set_item("momentum", vec3(|o| o.momentum)?)?;
        d.set_item("angular_momentum", vec3(|o| o.angular_momentum)?)?;
        if guard.measures_pressure() {
            d.set_item("pressure", col(|o| o.pressure.unwrap_or(f64::NAN)))?;
        }
        Ok(d)
    }

    fn __repr__(&self) -> PyResult<String> {
        let e = self.engine()?;
        Ok(format!(
            "<mote.RigidSimulation {}: {} bodies, t = {}, step {}, dt = {}>",
            e.label(),
            e.len(),
            e.time(),
            e.step(),
            e.dt()
        ))
    }
}
