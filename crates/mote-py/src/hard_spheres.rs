//! `mote.HardSpheres`: an event-driven scene (hard disks or spheres) that
//! Python steps an output interval at a time and reads, through the front
//! (`mote_front::stepper::HardSpheres`): the propagator and driver of
//! `mote run`, so a run from Python ends in `mote run`'s bits.

use std::path::PathBuf;

use numpy::prelude::*;
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{dict_to_toml, front_error};
use crate::stepping::{simulation_class, Stepped};

/// The run behind a Python `HardSpheres` (no Python types: it runs with
/// the GIL released).
pub struct HardEngine {
    run: mote_front::stepper::HardSpheres,
    label: String,
    seed: u64,
}

impl Stepped for HardEngine {
    fn advance(
        &mut self,
        n: u64,
        end_sample: bool,
        progress: &mut (dyn FnMut(u64, f64) + Send),
    ) -> PyResult<()> {
        self.run
            .advance(n, end_sample, progress)
            .map_err(front_error)
    }

    fn step(&self) -> u64 {
        self.run.step()
    }

    fn steps_for(&self, steps: Option<u64>, until: Option<f64>) -> PyResult<u64> {
        match (steps, until) {
            (_, Some(_)) => Err(PyValueError::new_err(
                "hard spheres run to the scene's end ([run] until) an output interval at a time: \
                 give steps= (intervals) or nothing",
            )),
            (Some(n), None) => Ok(n),
            (None, None) => Ok(self.run.last_step().saturating_sub(self.run.step())),
        }
    }

    fn time(&self) -> f64 {
        self.run.time()
    }

    fn len(&self) -> usize {
        self.run.frame().positions.len()
    }

    fn describe(&self) -> String {
        format!(
            "{}: {} hard {}, output interval {} of {}",
            self.label,
            self.run.frame().positions.len(),
            if self.run.dimension() == 2 {
                "disks"
            } else {
                "spheres"
            },
            self.run.step(),
            self.run.last_step()
        )
    }
}

impl HardSpheres {
    fn build(input: &mote_front::Input, seed: Option<u64>, force: bool) -> PyResult<Self> {
        let (run, seed) =
            mote_front::stepper::HardSpheres::build(input, seed, force).map_err(front_error)?;
        Ok(HardSpheres::wrap(HardEngine {
            run,
            label: input.label.clone(),
            seed,
        }))
    }

    /// An (N, D) array of the frame's rows (D = 2 for disks).
    fn rows<'py>(
        &self,
        py: Python<'py>,
        which: fn(&mote_io::xyz::Frame) -> &[[f64; 3]],
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let e = self.engine()?;
        let frame = e.run.frame();
        let d = e.run.dimension();
        let rows = which(&frame);
        let flat: Vec<f64> = rows.iter().flat_map(|r| r[..d].to_vec()).collect();
        PyArray1::from_vec(py, flat).reshape([rows.len(), d])
    }
}

simulation_class! {
    /// Event-driven hard disks or spheres (a scene with `[event_driven]`, see
    /// docs/edmd.md): free flight between exact elastic collisions. A step is
    /// one output interval of the scene (`[output] interval`).
    ///
    /// >>> hs = mote.HardSpheres.from_file("example:eos")
    /// >>> hs.run()                       # to the scene's [run] until
    /// >>> hs.observables["compressibility"][-1]
    pub struct HardSpheres(HardEngine);
    unit = "output intervals", every = 1;

    /// An event-driven scene file or `example:NAME`; `seed` replaces the
    /// scene's; `force` runs a scene expected to take more than 10⁹ events.
    #[staticmethod]
    #[pyo3(signature = (path, seed=None, force=false))]
    fn from_file(path: PathBuf, seed: Option<u64>, force: bool) -> PyResult<Self> {
        let input = mote_front::Input::read(&path.to_string_lossy()).map_err(front_error)?;
        Self::build(&input, seed, force)
    }

    /// An event-driven scene given as TOML text; `name` labels its messages.
    #[staticmethod]
    #[pyo3(signature = (text, seed=None, name="<string>", force=false))]
    fn from_toml(text: &str, seed: Option<u64>, name: &str, force: bool) -> PyResult<Self> {
        let input = mote_front::Input {
            name: "python".into(),
            label: name.into(),
            text: text.into(),
            plist: false,
        };
        Self::build(&input, seed, force)
    }

    /// An event-driven scene given as a dict of the scene file's tables.
    #[staticmethod]
    #[pyo3(signature = (scene, seed=None, force=false))]
    fn from_dict(scene: &Bound<'_, PyDict>, seed: Option<u64>, force: bool) -> PyResult<Self> {
        Self::from_toml(&dict_to_toml(scene)?, seed, "<dict>", force)
    }

    /// The output interval at which the scene's run ends.
    #[getter]
    fn last_step(&self) -> PyResult<u64> {
        Ok(self.engine()?.run.last_step())
    }

    /// 2 for disks, 3 for spheres.
    #[getter]
    fn dimension(&self) -> PyResult<usize> {
        Ok(self.engine()?.run.dimension())
    }

    /// The seed of the run's random numbers.
    #[getter]
    fn seed(&self) -> PyResult<u64> {
        Ok(self.engine()?.seed)
    }

    /// The box's edge lengths, (D,): the box is [0, L_0] × … (periodic
    /// axes wrap; particles are written where they fly, so a position may
    /// lie just outside until its next list renewal brings it back).
    #[getter(r#box)]
    fn box_lengths<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let e = self.engine()?;
        let cell = e.run.frame().cell;
        let d = e.run.dimension();
        Ok(PyArray1::from_vec(py, (0..d).map(|k| cell[k][k]).collect()))
    }

    /// Positions now, (N, D) in the scene's order: a copy (each particle
    /// flies on its own clock between collisions; this brings all to now).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, |f| &f.positions)
    }

    /// Velocities, (N, D), a copy.
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        self.rows(py, |f| &f.velocities)
    }

    /// Radii, (N,), a copy.
    #[getter]
    fn radii<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(PyArray1::from_vec(py, self.engine()?.run.frame().radii))
    }

    /// Masses, (N,), a copy.
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(PyArray1::from_vec(py, self.engine()?.run.frame().masses))
    }

    /// The observables measured so far, one value per output interval and
    /// at the start: the columns of `mote run`'s observables.csv (time,
    /// collisions, collision_rate, mean_free_time, temperature,
    /// kinetic_energy, energy_drift, compressibility, pressure,
    /// wall_pressure) as numpy arrays.
    #[getter]
    fn observables<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let e = self.engine()?;
        let names = e.run.columns().iter().map(|(name, _unit)| *name);
        crate::tools::columns(py, names, &e.run.samples())
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
        crate::tools::picture(py, &self.engine()?.run.frame(), output, width, height)
    }

    fn __repr__(&self) -> PyResult<String> {
        let e = self.engine()?;
        Ok(format!(
            "<mote.HardSpheres {}: {} {}, t = {}, interval {} of {}>",
            e.label,
            e.run.frame().positions.len(),
            if e.run.dimension() == 2 {
                "disks"
            } else {
                "spheres"
            },
            e.run.time(),
            e.run.step(),
            e.run.last_step()
        ))
    }
}
