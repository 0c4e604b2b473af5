//! `import mote`: the Python API (pyo3 + numpy, built by maturin).
//!
//! Scenes go through the same front as `mote run` (`mote_front`), so a
//! scene file, a TOML string and a Python dict are one format with one
//! parser. A time-stepped scene becomes a [`Simulation`], a rigid one a
//! [`RigidSimulation`], an event-driven one a [`HardSpheres`], a packing
//! one a [`Packing`], each stepped through the front's stepper (mote's one
//! run loop) and read (particle arrays of the first two are numpy views of
//! mote's own memory); every engine runs whole through [`run`]; `pack` (a
//! packing from options) and the rod-packing estimator are functions.

use pyo3::prelude::*;

mod convert;
mod hard_spheres;
mod packing;
mod rigid;
mod simulation;
mod stepping;
mod tools;

pyo3::create_exception!(
    mote,
    MoteError,
    pyo3::exceptions::PyRuntimeError,
    "A run that could not go on (an I/O error, a refused request)."
);
pyo3::create_exception!(
    mote,
    UnstableError,
    MoteError,
    "A run that went unstable: the message names the step and the particle; the simulation keeps the state it reached."
);

/// mote: many-particle simulation (time-stepped, rigid, event-driven,
/// packings, the rod-packing estimator) from Python.
#[pymodule]
fn _mote(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    mote_front::check_simd_request()
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    m.add("MoteError", py.get_type::<MoteError>())?;
    m.add("UnstableError", py.get_type::<UnstableError>())?;
    m.add_class::<simulation::Simulation>()?;
    m.add_class::<rigid::RigidSimulation>()?;
    m.add_class::<hard_spheres::HardSpheres>()?;
    m.add_class::<packing::Packing>()?;
    m.add_function(wrap_pyfunction!(tools::run, m)?)?;
    m.add_function(wrap_pyfunction!(tools::pack, m)?)?;
    m.add_function(wrap_pyfunction!(tools::rcp, m)?)?;
    m.add_function(wrap_pyfunction!(tools::render, m)?)?;
    m.add_function(wrap_pyfunction!(tools::rcp_optimise, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
