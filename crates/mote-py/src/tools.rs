//! Whole runs of any engine, packings and the rod-packing estimator.

use std::path::PathBuf;

use numpy::prelude::*;
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{dict_to_toml, front_error};

/// Runs a scene of any engine to its end, as `mote run` does, writing its
/// files to `output` (default `out/<name>`); `scene` is a path,
/// `example:NAME`, TOML text (when it holds a newline) or a dict. Returns a
/// dict: engine, seed, dir, summary (lines), ending ("finished",
/// "unstable: ...", "interrupted: ..."). `resume` continues a checkpoint
/// of any engine instead; `progress=True` shows `mote run`'s opening line
/// and progress bar on stderr. The GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (scene=None, *, output=None, seed=None, steps=None, until=None, dt=None, checkpoint_every=None, trajectory_format=None, resume=None, progress=false))]
#[allow(clippy::too_many_arguments)]
pub fn run<'py>(
    py: Python<'py>,
    scene: Option<Bound<'py, PyAny>>,
    output: Option<PathBuf>,
    seed: Option<u64>,
    steps: Option<u64>,
    until: Option<f64>,
    dt: Option<f64>,
    checkpoint_every: Option<u64>,
    trajectory_format: Option<String>,
    resume: Option<PathBuf>,
    progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let options = mote_front::RunOptions {
        output,
        seed,
        steps,
        until,
        dt,
        checkpoint_every,
        trajectory_format,
        resume: resume.clone(),
        ..mote_front::RunOptions::default()
    };
    let input = match (&scene, &resume) {
        (None, None) => return Err(PyValueError::new_err("give a scene or resume=")),
        (Some(_), Some(_)) => {
            return Err(PyValueError::new_err("give a scene or resume=, not both"))
        }
        (None, Some(_)) => None,
        (Some(s), None) => Some(if let Ok(d) = s.cast::<PyDict>() {
            mote_front::Input {
                name: "python".into(),
                label: "<dict>".into(),
                text: dict_to_toml(d)?,
                plist: false,
            }
        } else if let (Err(_), Ok(path)) =
            (s.cast::<pyo3::types::PyString>(), s.extract::<PathBuf>())
        {
            // a path (pathlib.Path, os.PathLike)
            mote_front::Input::read(&path.to_string_lossy()).map_err(front_error)?
        } else {
            let s: String = s.extract()?;
            if s.contains('\n') {
                mote_front::Input {
                    name: "python".into(),
                    label: "<string>".into(),
                    text: s,
                    plist: false,
                }
            } else {
                mote_front::Input::read(&s).map_err(front_error)?
            }
        }),
    };
    let outcome = py
        .detach(|| {
            // `mote run`'s opening line and progress bar on stderr when asked.
            let mut monitor = mote_front::Terminal::new(!progress);
            match &input {
                Some(i) => mote_front::run_input(i, &options, &mut monitor),
                None => mote_front::run(&options, &mut monitor),
            }
        })
        .map_err(front_error)?;
    let d = PyDict::new(py);
    d.set_item("engine", format!("{:?}", outcome.engine))?;
    d.set_item("seed", outcome.seed)?;
    d.set_item("dir", outcome.dir.display().to_string())?;
    d.set_item("summary", outcome.summary)?;
    let ending = match outcome.ending {
        mote_front::Ending::Finished => "finished".to_string(),
        mote_front::Ending::Unstable(m) => format!("unstable: {m}"),
        mote_front::Ending::Interrupted { message, .. } => format!("interrupted: {message}"),
    };
    d.set_item("ending", ending)?;
    Ok(d)
}

/// A packing by growing hard spheres (Lubachevsky–Stillinger), the keys
/// of `mote pack` (`mote pack --help`). Returns a dict: positions (N, D),
/// radii (N,), box (D,), phi, pressure, summary (lines). `output` (a folder,
/// as `mote pack -o` takes) also writes it, `output/packing.EXT` in
/// `format`, with its CSV of windows and POV-Ray scene.
#[pyfunction]
#[pyo3(signature = (n=1000, *, dimension=3, dist="mono", rate=0.01, max_pressure=1e12, phi=None, walls="", jam=true, seed=None, start=None, output=None, format="xyz", method="hard", min_pressure=1e-8))]
#[allow(clippy::too_many_arguments)]
pub fn pack<'py>(
    py: Python<'py>,
    n: usize,
    dimension: usize,
    dist: &str,
    rate: f64,
    max_pressure: f64,
    phi: Option<f64>,
    walls: &str,
    jam: bool,
    seed: Option<u64>,
    start: Option<String>,
    output: Option<PathBuf>,
    format: &str,
    method: &str,
    min_pressure: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let format = mote_io::trajectory::Format::named(format).ok_or_else(|| {
        PyValueError::new_err(format!(
            "format = {format:?}: expected one of {}",
            mote_io::trajectory::Format::NAMES
        ))
    })?;
    if let Some(named) = output
        .as_deref()
        .and_then(mote_front::packing::named_like_a_file)
    {
        return Err(PyValueError::new_err(format!(
            "output = {:?}: output names the packing's folder, as mote.run's does; the packing goes to DIR/packing.{}",
            output.as_ref().map(|p| p.display().to_string()).unwrap_or_default(),
            named.extension()
        )));
    }
    use mote_front::packing::{pack, PackRequest, PackingSpec};
    let spec = PackingSpec {
        n,
        dimension,
        dist: dist.into(),
        rate,
        max_pressure,
        phi,
        walls: walls.into(),
        jam,
        start,
        method: method.into(),
        min_pressure,
        ..PackingSpec::default()
    };
    let (seed, seed_chosen) = mote_front::seed::resolve(seed, None);
    let request = PackRequest {
        output,
        format,
        picture: None,
        checkpoint_every: None,
        seed,
        seed_chosen,
    };
    let label = format!("mote.pack(n={n}, dist={dist:?}, rate={rate})");
    let packed = py
        .detach(|| pack(&spec, &label, &request, &mut mote_front::Silent))
        .map_err(front_error)?;
    let f = &packed.frame;
    let d = PyDict::new(py);
    let flat: Vec<f64> = f
        .positions
        .iter()
        .flat_map(|p| p[..dimension].to_vec())
        .collect();
    d.set_item(
        "positions",
        PyArray1::from_vec(py, flat).reshape([f.positions.len(), dimension])?,
    )?;
    d.set_item("radii", PyArray1::from_vec(py, f.radii.clone()))?;
    let sides: Vec<f64> = (0..dimension).map(|k| f.cell[k][k]).collect();
    d.set_item("box", PyArray1::from_vec(py, sides))?;
    d.set_item("phi", packed.phi)?;
    d.set_item("pressure", packed.pressure)?;
    d.set_item("seed", seed)?;
    d.set_item("summary", packed.summary)?;
    Ok(d)
}

/// The rod-packing estimate of the random close packing fraction (Farr &
/// Groot 2009), as `mote rcp`: `sigma` for a lognormal of log-width σ
/// (number-weighted), or `diameters` with `volumes` for a sum of
/// monodisperse populations; `rods` rods (default 16000). A distribution
/// the rods cannot resolve raises ValueError; one whose third decimal may be
/// off warns (`UserWarning`).
#[pyfunction]
#[pyo3(signature = (*, sigma=None, diameters=None, volumes=None, rods=16000))]
pub fn rcp(
    py: Python<'_>,
    sigma: Option<f64>,
    diameters: Option<Vec<f64>>,
    volumes: Option<Vec<f64>>,
    rods: usize,
) -> PyResult<f64> {
    use mote_rcp::{Population, RodPacking, SizeDistribution};
    let bad = |e: mote_rcp::RcpError| PyValueError::new_err(e.to_string());
    let dist = match (sigma, diameters) {
        (Some(s), None) => SizeDistribution::lognormal(s).map_err(bad)?,
        (None, Some(d)) => {
            let v = volumes.unwrap_or_else(|| vec![1.0; d.len()]);
            if v.len() != d.len() {
                return Err(PyValueError::new_err(format!(
                    "{} diameters but {} volumes",
                    d.len(),
                    v.len()
                )));
            }
            SizeDistribution::new(
                d.iter()
                    .zip(&v)
                    .map(|(&d, &v)| Population::monodisperse(d, v)),
            )
            .map_err(bad)?
        }
        _ => {
            return Err(PyValueError::new_err(
                "give sigma= or diameters= (with volumes=)",
            ))
        }
    };
    // Checked as `mote rcp` checks it: refused where the rods cannot
    // resolve the distribution, a warning where its third decimal may be off.
    let packing = RodPacking::default().rods(rods);
    let out = py
        .detach(|| packing.checked_estimate(&dist, |_| {}))
        .map_err(bad)?;
    if let Some(note) = &out.note {
        let warnings = py.import("warnings")?;
        warnings.call_method1("warn", (note.as_str(),))?;
    }
    Ok(out.phi)
}

/// An image as numpy (height, width, 3) uint8, or written to `path` (PNG)
/// when given (then None).
pub fn image_out<'py>(
    py: Python<'py>,
    image: mote_render::Image,
    path: Option<PathBuf>,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    match path {
        Some(p) => {
            image
                .write_png(&p)
                .map_err(|e| crate::MoteError::new_err(e.to_string()))?;
            Ok(None)
        }
        None => {
            let (h, w) = (image.height as usize, image.width as usize);
            let array = PyArray1::from_vec(py, image.rgb).reshape([h, w, 3])?;
            Ok(Some(array.into_any()))
        }
    }
}

/// Ray-traces `frame` as `mote run --picture` does (the GIL released):
/// what every class's `render` returns ([`image_out`]).
pub fn picture<'py>(
    py: Python<'py>,
    frame: &mote_io::xyz::Frame,
    output: Option<PathBuf>,
    width: u32,
    height: u32,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    let image = py
        .detach(|| mote_render::frame::picture_image(frame, width, height))
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    image_out(py, image, output)
}

/// A table as a dict of numpy columns: `names[k]` holds entry k of every
/// row (the observables of `HardSpheres`, the windows of `Packing`).
pub fn columns<'py>(
    py: Python<'py>,
    names: impl IntoIterator<Item = &'static str>,
    rows: &[impl AsRef<[f64]>],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, name) in names.into_iter().enumerate() {
        let column: Vec<f64> = rows.iter().map(|r| r.as_ref()[k]).collect();
        d.set_item(name, PyArray1::from_vec(py, column))?;
    }
    Ok(d)
}

/// Ray-traces a frame of a trajectory file (`.xyz`, `.dump`, `.gsd`,
/// `.vtp`/`.pvd`; `frame` counts from 0, negative from the end, default
/// the last) as `mote run --picture` does: coloured by species, shadows,
/// box drawn. Returns a (height, width, 3) uint8 array, or writes `output`
/// (PNG) and returns None.
#[pyfunction]
#[pyo3(signature = (trajectory, *, frame=None, output=None, width=800, height=600))]
pub fn render<'py>(
    py: Python<'py>,
    trajectory: PathBuf,
    frame: Option<i64>,
    output: Option<PathBuf>,
    width: u32,
    height: u32,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    let frames = mote_io::trajectory::read_frames(&trajectory)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let f =
        mote_io::trajectory::pick(&frames, frame, &trajectory).map_err(PyValueError::new_err)?;
    picture(py, f, output, width, height)
}

/// The size distribution that packs densest (or closest to `target`) by
/// the rod-packing estimator, as `mote rcp optimise`: populations of
/// `diameters` (d43 of lognormals of log-width `sigmas`, 0 for
/// monodisperse; default all monodisperse) starting at `volumes`; the
/// volume fractions are varied, and the widths too with `widths=True`
/// (Nelder–Mead). Returns a dict: volumes (fractions), sigmas, phi,
/// evaluations.
#[pyfunction]
#[pyo3(signature = (diameters, *, sigmas=None, volumes=None, target=None, widths=false, rods=16000, max_evaluations=600))]
#[allow(clippy::too_many_arguments)]
pub fn rcp_optimise<'py>(
    py: Python<'py>,
    diameters: Vec<f64>,
    sigmas: Option<Vec<f64>>,
    volumes: Option<Vec<f64>>,
    target: Option<f64>,
    widths: bool,
    rods: usize,
    max_evaluations: usize,
) -> PyResult<Bound<'py, PyDict>> {
    use mote_rcp::design::{optimise, Objective, Search};
    use mote_rcp::{Population, RodPacking};
    let p = diameters.len();
    let sigmas = sigmas.unwrap_or_else(|| vec![0.0; p]);
    let volumes = volumes.unwrap_or_else(|| vec![1.0; p]);
    if sigmas.len() != p || volumes.len() != p {
        return Err(PyValueError::new_err(format!(
            "{p} diameters need {p} sigmas and {p} volumes (got {} and {})",
            sigmas.len(),
            volumes.len()
        )));
    }
    let base: Vec<Population> = (0..p)
        .map(|k| {
            if sigmas[k] > 0.0 {
                Population::lognormal(diameters[k], sigmas[k], volumes[k])
            } else {
                Population::monodisperse(diameters[k], volumes[k])
            }
        })
        .collect();
    let search = Search {
        widths,
        max_evaluations,
        ..Search::default()
    };
    let objective = target.map_or(Objective::Maximise, Objective::Target);
    let estimator = RodPacking::default().rods(rods);
    let best = py
        .detach(|| optimise(&base, &estimator, objective, &search))
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let d = PyDict::new(py);
    d.set_item(
        "volumes",
        PyArray1::from_vec(py, best.populations.iter().map(|q| q.volume()).collect()),
    )?;
    d.set_item(
        "sigmas",
        PyArray1::from_vec(py, best.populations.iter().map(|q| q.sigma()).collect()),
    )?;
    d.set_item("phi", best.phi)?;
    d.set_item("evaluations", best.evaluations)?;
    Ok(d)
}
