//! `mote.Packing`: a `[packing]` scene (hard disks or spheres grown by
//! Lubachevsky–Stillinger, or soft spheres pressed by the SP method) that
//! Python steps a pressure window (or a chunk of the soft method) at a
//! time and reads, through the front (`mote_front::stepper::Packing`): the
//! packer and driver of `mote run`, so a packing grown from Python is
//! `mote run`'s (and `mote.pack`'s) bit for bit.

use std::path::PathBuf;

use numpy::prelude::*;
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{dict_to_toml, front_error};
use crate::stepping::{simulation_class, Stepped};

/// The packing behind a Python `Packing` (no Python types: it runs with
/// the GIL released).
pub struct PackEngine {
    run: mote_front::stepper::Packing,
    label: String,
    seed: u64,
}

impl Stepped for PackEngine {
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
                "a packing grows until it jams (or reaches the scene's phi, max_collisions or \
                 time_limit), a pressure window (or a soft packing's chunk) at a time: give \
                 steps= or nothing",
            )),
            (Some(n), None) => Ok(n),
            (None, None) => Ok(u64::MAX),
        }
    }

    fn time(&self) -> f64 {
        self.run.time()
    }

    fn len(&self) -> usize {
        self.run.frame().positions.len()
    }

    fn finished(&self) -> bool {
        self.run.stopped().is_some()
    }

    fn describe(&self) -> String {
        format!(
            "{}: packing {} {}, step {}",
            self.label,
            self.len(),
            if self.run.dimension() == 2 {
                "disks"
            } else {
                "spheres"
            },
            self.run.step()
        )
    }
}

impl Packing {
    fn build(input: &mote_front::Input, seed: Option<u64>) -> PyResult<Self> {
        let (run, seed) = mote_front::stepper::Packing::build(input, seed).map_err(front_error)?;
        Ok(Packing::wrap(PackEngine {
            run,
            label: input.label.clone(),
            seed,
        }))
    }
}

simulation_class! {
    /// A packing from a `[packing]` scene (see docs/pack.md): hard disks
    /// or spheres whose radii grow between exact collisions until the
    /// packing jams (or reaches the scene's `phi`, `max_collisions` or
    /// `time_limit`), a step being one pressure window; or (`method =
    /// "soft"`) soft spheres pressed by a barostat and minimised down to
    /// `min_pressure`, a step being a chunk of 100 steps of the barostat
    /// or the minimiser. `run()` takes it to its end, as `mote run` does.
    ///
    /// >>> p = mote.Packing.from_toml("[packing]\nn = 500\nmax_pressure = 1e8\n", seed=1)
    /// >>> p.run()
    /// >>> p.phi, p.stopped
    pub struct Packing(PackEngine);
    unit = "packing steps", every = 1;

    /// A packing scene file or `example:NAME`; `seed` replaces the scene's.
    #[staticmethod]
    #[pyo3(signature = (path, seed=None))]
    fn from_file(path: PathBuf, seed: Option<u64>) -> PyResult<Self> {
        let input = mote_front::Input::read(&path.to_string_lossy()).map_err(front_error)?;
        Self::build(&input, seed)
    }

    /// A packing scene given as TOML text; `name` labels its messages.
    #[staticmethod]
    #[pyo3(signature = (text, seed=None, name="<string>"))]
    fn from_toml(text: &str, seed: Option<u64>, name: &str) -> PyResult<Self> {
        let input = mote_front::Input {
            name: "python".into(),
            label: name.into(),
            text: text.into(),
            plist: false,
        };
        Self::build(&input, seed)
    }

    /// A packing scene given as a dict of the scene file's tables.
    #[staticmethod]
    #[pyo3(signature = (scene, seed=None))]
    fn from_dict(scene: &Bound<'_, PyDict>, seed: Option<u64>) -> PyResult<Self> {
        Self::from_toml(&dict_to_toml(scene)?, seed, "<dict>")
    }

    /// 2 for disks, 3 for spheres.
    #[getter]
    fn dimension(&self) -> PyResult<usize> {
        Ok(self.engine()?.run.dimension())
    }

    /// The seed of the packing's random start.
    #[getter]
    fn seed(&self) -> PyResult<u64> {
        Ok(self.engine()?.seed)
    }

    /// Why the packing stopped ("pressure": jammed, "target-phi",
    /// "collisions", "wall-clock"; the soft method "done"), or None while
    /// it goes on.
    #[getter]
    fn stopped(&self) -> PyResult<Option<&'static str>> {
        Ok(self.engine()?.run.stopped())
    }

    /// The packing fraction now.
    #[getter]
    fn phi(&self) -> PyResult<f64> {
        Ok(self.engine()?.run.phi())
    }

    /// The reduced pressure Z = PV/(NkT) of the last window, or (soft
    /// method) P/K of the last held or minimised state; NaN before the
    /// first.
    #[getter]
    fn pressure(&self) -> PyResult<f64> {
        Ok(self.engine()?.run.pressure())
    }

    /// Pair collisions so far (None for the soft method).
    #[getter]
    fn collisions(&self) -> PyResult<Option<u64>> {
        Ok(self.engine()?.run.collisions())
    }

    /// The box's edge lengths, (D,).
    #[getter(r#box)]
    fn box_lengths<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let e = self.engine()?;
        let cell = e.run.frame().cell;
        let d = e.run.dimension();
        Ok(PyArray1::from_vec(py, (0..d).map(|k| cell[k][k]).collect()))
    }

    /// Positions now, (N, D): a copy (each sphere flies on its own clock
    /// between collisions; this brings all to now).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let e = self.engine()?;
        let frame = e.run.frame();
        let d = e.run.dimension();
        let flat: Vec<f64> = frame.positions.iter().flat_map(|r| r[..d].to_vec()).collect();
        PyArray1::from_vec(py, flat).reshape([frame.positions.len(), d])
    }

    /// Radii now, (N,), a copy.
    #[getter]
    fn radii<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(PyArray1::from_vec(py, self.engine()?.run.frame().radii))
    }

    /// The rows of `mote run`'s packing.csv so far (numpy arrays): the
    /// pressure windows closed (collisions, time, phi, pressure), or the
    /// soft method's held and minimised states (steps, phi, pressure,
    /// minimised).
    #[getter]
    fn windows<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let run = &self.engine()?.run;
        crate::tools::columns(py, run.columns(), &run.windows())
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
            "<mote.Packing {}: phi = {:.6}, Z = {:.3e}, {}>",
            e.describe(),
            e.run.phi(),
            e.run.pressure(),
            e.run.stopped().unwrap_or("growing")
        ))
    }
}
