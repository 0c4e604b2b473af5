//! `[run]` (integrator, time step, length), `[output]` (files and their
//! intervals) and `[box]` (the simulation box).

use glam::DVec3;
use serde::Deserialize;
use toml::Spanned;

use mote_io::trajectory::Format;
use mote_io::{ParseError, Source};

use super::all_free;
use crate::boundary::Boundary;
use crate::integrate::Integrator;
use crate::observe::Probe;
use crate::simulation::RunLength;

/// `[run]`: integrator, time step and length.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSettings {
    /// Default: leapfrog.
    #[serde(default = "default_integrator")]
    pub integrator: Setting<String>,
    pub dt: Option<Setting<f64>>,
    pub steps: Option<u64>,
    pub until: Option<f64>,
    /// Move to the centre-of-mass frame before the run (only if nothing is fixed).
    #[serde(default)]
    pub centre_of_mass: bool,
}

fn default_integrator() -> Setting<String> {
    Setting {
        value: "leapfrog".into(),
        origin: Origin::Default,
    }
}

/// A run setting and where it was given, so that an error about it names
/// its line in the scene, or the option that replaced the scene's value.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting<T> {
    pub value: T,
    pub origin: Origin,
}

/// Where a [`Setting`] was given.
#[derive(Debug, Clone, PartialEq)]
pub enum Origin {
    /// In the scene text, at this byte span.
    Scene(std::ops::Range<usize>),
    /// By a command-line option or argument (`--dt`) replacing the scene's.
    Option(&'static str),
    /// Nowhere: the default, or an MPPphys particle file's own.
    Default,
}

impl<T: std::fmt::Display> Setting<T> {
    /// The value as `option` gave it.
    pub fn from_option(option: &'static str, value: T) -> Self {
        Setting {
            value,
            origin: Origin::Option(option),
        }
    }

    /// A value given nowhere in particular (a default, a particle file's).
    pub fn plain(value: T) -> Self {
        Setting {
            value,
            origin: Origin::Default,
        }
    }

    /// An error about this setting: `file:line: message` where the scene
    /// gave it, `file: --option value: message` where an option did.
    pub fn error(&self, src: Source, message: impl Into<String>) -> ParseError {
        match &self.origin {
            Origin::Scene(span) => src.error(span.clone(), message),
            Origin::Option(option) => ParseError::new(
                src.file,
                0,
                format!("{option} {}: {}", self.value, message.into()),
            ),
            Origin::Default => src.whole(message),
        }
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Setting<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let spanned = Spanned::<T>::deserialize(d)?;
        Ok(Setting {
            origin: Origin::Scene(spanned.span()),
            value: spanned.into_inner(),
        })
    }
}

impl Default for RunSettings {
    fn default() -> Self {
        Self {
            integrator: default_integrator(),
            dt: None,
            steps: None,
            until: None,
            centre_of_mass: false,
        }
    }
}

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

/// `[box]`: an orthorhombic simulation box.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSettings {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    #[serde(default = "all_free")]
    pub periodic: [bool; 3],
}

/// The box of `[box]`, else the one an `[[fcc]]` crystal set, else none.
pub fn boundary(
    bounds: &Option<Spanned<BoxSettings>>,
    fcc_box: Option<Boundary>,
    src: Source,
) -> Result<Boundary, ParseError> {
    Ok(match bounds {
        Some(b) => {
            let v = b.get_ref();
            if (0..3).any(|k| v.hi[k].is_nan() || v.lo[k].is_nan() || v.hi[k] <= v.lo[k]) {
                return Err(src.error(b.span(), "[box] needs lo < hi on every axis"));
            }
            Boundary {
                lo: DVec3::from(v.lo),
                hi: DVec3::from(v.hi),
                periodic: v.periodic,
            }
        }
        None => fcc_box.unwrap_or_default(),
    })
}

impl RunSettings {
    /// The integrator, the time step and the length of the run (if the
    /// scene gives one).
    pub fn schedule(
        &self,
        src: Source,
    ) -> Result<(Integrator, f64, Option<RunLength>), ParseError> {
        let integrator = Integrator::from_name(&self.integrator.value).ok_or_else(|| {
            self.integrator.error(
                src,
                format!(
                    "unknown integrator '{}': expected {}",
                    self.integrator.value,
                    Integrator::NAMES
                ),
            )
        })?;
        let dt = match &self.dt {
            Some(dt) if dt.value > 0.0 && dt.value.is_finite() => dt.value,
            Some(dt) => {
                return Err(dt.error(src, format!("dt must be positive, found {}", dt.value)))
            }
            None => return Err(src.whole("[run] needs a time step: dt = ...")),
        };
        let length = match (self.steps, self.until) {
            (Some(_), Some(_)) => return Err(src.whole("[run] takes steps or until, not both")),
            (Some(s), None) => Some(RunLength::Steps(s)),
            (None, Some(t)) if t > 0.0 => Some(RunLength::Until(t)),
            (None, Some(t)) => {
                return Err(ParseError::new(
                    src.file,
                    src.key_line("until"),
                    format!(
                        "until = {t}: must be a time after the start (t = 0); steps = 0 runs none"
                    ),
                ))
            }
            (None, None) => None,
        };
        Ok((integrator, dt, length))
    }
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
