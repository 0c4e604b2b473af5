//! `[run]` (integrator, time step, length: the envelope's
//! [`RunTable`], read here for point particles), `[output]` (files and their
//! intervals) and `[box]` (the simulation box).

use glam::DVec3;
use serde::Deserialize;
use toml::Spanned;

use mote_io::trajectory::Format;
use mote_io::{ParseError, Source};

use crate::boundary::Boundary;
use crate::integrate::Integrator;
use crate::observe::Probe;
use mote_run::scene::{BoxTable, RunLength, RunTable, Setting};

/// `[output]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSettings {
    /// Folder of the output files (default `out/<scene name>`).
    pub dir: Option<String>,
    /// Steps between rows of observables.csv; 0 turns it off.
    #[serde(default = "default_observables_every")]
    pub observables_every: u64,
    /// Steps between frames of the trajectory; 0 turns it off.
    #[serde(default = "default_trajectory_every")]
    pub trajectory_every: u64,
    /// Format of the trajectory: `xyz` (default), `dump`, `gsd` or `vtk`;
    /// the file is `trajectory.<xyz|dump|gsd|pvd>`.
    pub trajectory_format: Option<Spanned<String>>,
    /// Per-particle quantities added to observables.csv, e.g. `["z[30]", "speed[1]"]`.
    #[serde(default)]
    pub inspect: Vec<Spanned<String>>,
    /// Add the pressure tensor (`pxx pyy pzz pxy pxz pyz`) to
    /// observables.csv; a box periodic on every axis is needed.
    pub pressure_tensor: Option<Spanned<bool>>,
}

fn default_observables_every() -> u64 {
    10
}
fn default_trajectory_every() -> u64 {
    100
}

impl Default for OutputSettings {
    fn default() -> Self {
        Self {
            dir: None,
            observables_every: default_observables_every(),
            trajectory_every: default_trajectory_every(),
            trajectory_format: None,
            inspect: Vec::new(),
            pressure_tensor: None,
        }
    }
}

/// The box of a time-stepped scene's `[box]` (the envelope's
/// [`BoxTable`]): `lo` and `hi` on three axes, the periodic axes (default
/// all).
pub fn scene_box(table: &Spanned<BoxTable>, src: Source) -> Result<Boundary, ParseError> {
    let b = table.get_ref();
    b.axes(src, 3)?;
    let (Some(lo), Some(hi)) = (&b.lo, &b.hi) else {
        return Err(src.error(
            table.span(),
            "[box] needs lo and hi, its lower and upper corners: lo = [0, 0, 0], hi = [10, 10, 10]",
        ));
    };
    let periodic = b.periodic(3);
    Ok(Boundary {
        lo: DVec3::from_slice(lo.get_ref()),
        hi: DVec3::from_slice(hi.get_ref()),
        periodic: [periodic[0], periodic[1], periodic[2]],
    })
}

/// The box of `[box]`, else the one an `[[fcc]]` crystal set, else none.
pub fn boundary(
    bounds: &Option<Spanned<BoxTable>>,
    fcc_box: Option<Boundary>,
    src: Source,
) -> Result<Boundary, ParseError> {
    Ok(match bounds {
        Some(b) => scene_box(b, src)?,
        None => fcc_box.unwrap_or_default(),
    })
}

/// The integrator `[run]` names (default leapfrog), with where it was named.
pub fn integrator_setting(run: &RunTable) -> Setting<String> {
    run.integrator
        .clone()
        .unwrap_or_else(|| Setting::plain("leapfrog".into()))
}

/// The integrator, the time step and the length of the run (if the scene
/// gives one) of a point-particle scene's `[run]`.
pub fn schedule(
    run: &RunTable,
    src: Source,
) -> Result<(Integrator, f64, Option<RunLength>), ParseError> {
    run.refuse(
        src,
        &[(
            "equilibrate",
            "point particles are measured from the first step; equilibrate is the event-driven engine's (run an equilibration as a scene of its own and start from its last frame with [[from_file]])",
        )],
    )?;
    let integrator = integrator_setting(run);
    let known = Integrator::from_name(&integrator.value).ok_or_else(|| {
        integrator.error(
            src,
            format!(
                "unknown integrator '{}': expected {}",
                integrator.value,
                Integrator::NAMES
            ),
        )
    })?;
    let dt = run
        .time_step(src)?
        .ok_or_else(|| src.whole("[run] needs a time step: dt = ..."))?;
    Ok((known, dt, run.length(src)?))
}

impl OutputSettings {
    /// The trajectory's format (`trajectory_format`, default extended XYZ).
    pub fn trajectory_format(&self, src: Source) -> Result<Format, ParseError> {
        match &self.trajectory_format {
            None => Ok(Format::Xyz),
            Some(f) => Format::named(f.get_ref()).ok_or_else(|| {
                src.error(
                    f.span(),
                    format!(
                        "trajectory_format '{}' is not one of {}",
                        f.get_ref(),
                        Format::NAMES
                    ),
                )
            }),
        }
    }

    /// The per-particle columns of `inspect`, checked against the `n` particles.
    pub fn probes(&self, src: Source, n: usize) -> Result<Vec<Probe>, ParseError> {
        let mut probes = Vec::new();
        for p in &self.inspect {
            let probe = Probe::parse(p.get_ref()).map_err(|m| src.error(p.span(), m))?;
            if probe.particle >= n {
                return Err(src.error(
                    p.span(),
                    format!("inspect '{}': there are only {n} particles", p.get_ref()),
                ));
            }
            probes.push(probe);
        }
        Ok(probes)
    }
}
