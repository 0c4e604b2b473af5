//! Baths and friction: `[damping]` (a force −γ v), `[thermostat]`
//! (Langevin or Bussi–Donadio–Parrinello) and `[brownian]` (overdamped
//! Brownian dynamics instead of Newton's equations).

use std::ops::Range;

use serde::Deserialize;
use toml::Spanned;

use mote_io::{ParseError, Source};

use super::{yes, Build, Scene, Section};
use crate::brownian::BrownianStepper;
use crate::force::GlobalDamping;
use crate::thermostat::Thermostat;

/// `[damping]`: force −γ v on every particle (MPPphys `damp`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DampingSettings {
    pub gamma: f64,
}

impl Section for DampingSettings {
    fn add_to(&self, span: Range<usize>, _: &Scene, b: &mut Build) -> Result<(), ParseError> {
        if !self.gamma.is_finite() {
            return Err(b.src.error(span, "[damping] gamma must be finite"));
        }
        b.forces.push(GlobalDamping { gamma: self.gamma });
        Ok(())
    }
}

/// `[thermostat]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThermostatSettings {
    /// `langevin` or `bussi`.
    pub kind: String,
    /// Temperature as k_B T in energy units (in LJ units: T*).
    pub kt: f64,
    /// Langevin friction γ (per time).
    pub gamma: Option<f64>,
    /// Bussi relaxation time τ.
    pub tau: Option<f64>,
}

/// `[brownian]`: overdamped Brownian dynamics at `kt` with friction
/// coefficients `translational` ξ_t and `rotational` ξ_r, or the Stokes
/// drag of each sphere in a liquid of `viscosity`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BrownianSettings {
    pub kt: f64,
    pub translational: Option<f64>,
    pub rotational: Option<f64>,
    pub viscosity: Option<f64>,
    /// Turn the dipoles (rotational diffusion and torques; default true).
    #[serde(default = "yes")]
    pub rotate: bool,
}

/// The Brownian stepper of `[brownian]`, if the scene has one.
pub fn brownian(
    table: &Option<Spanned<BrownianSettings>>,
    build: &Build,
) -> Result<Option<BrownianStepper>, ParseError> {
    let particles = &build.particles;
    let err = |span: Range<usize>, msg: String| build.src.error(span, msg);
    Ok(match table {
        None => None,
        Some(b) => {
            let v = b.get_ref();
            use crate::brownian::Friction;
            let friction =
                match (v.translational, v.rotational, v.viscosity) {
                    (Some(t), Some(r), None) if t > 0.0 && r > 0.0 => Friction::Uniform {
                        translational: t,
                        rotational: r,
                    },
                    (None, None, Some(eta)) if eta > 0.0 => {
                        if particles.radius.iter().any(|r| *r <= 0.0) {
                            return Err(err(
                                b.span(),
                                "[brownian] viscosity needs every particle's radius > 0".into(),
                            ));
                        }
                        Friction::Stokes { viscosity: eta }
                    }
                    _ => return Err(err(
                        b.span(),
                        "[brownian] needs translational > 0 and rotational > 0, or viscosity > 0"
                            .into(),
                    )),
                };
            if v.kt.is_nan() || v.kt < 0.0 {
                return Err(err(b.span(), "[brownian] needs kt ≥ 0".into()));
            }
            let mut bd = BrownianStepper::new(v.kt, friction);
            bd.rotate = v.rotate;
            Some(bd)
        }
    })
}

/// The thermostat of `[thermostat]`, if the scene has one.
pub fn thermostat(
    table: &Option<Spanned<ThermostatSettings>>,
    src: Source,
) -> Result<Option<Thermostat>, ParseError> {
    let err = |span: Range<usize>, msg: String| src.error(span, msg);
    Ok(match table {
        None => None,
        Some(t) => {
            let v = t.get_ref();
            if v.kt.is_nan() || v.kt < 0.0 {
                return Err(err(t.span(), "[thermostat] needs kt ≥ 0".into()));
            }
            Some(match (v.kind.as_str(), v.gamma, v.tau) {
                ("langevin", Some(gamma), _) if gamma > 0.0 => {
                    Thermostat::Langevin { kt: v.kt, gamma }
                }
                ("bussi", _, Some(tau)) if tau > 0.0 => Thermostat::Bussi { kt: v.kt, tau },
                ("langevin", _, _) => {
                    return Err(err(
                        t.span(),
                        "a langevin thermostat needs gamma > 0".into(),
                    ))
                }
                ("bussi", _, _) => {
                    return Err(err(t.span(), "a bussi thermostat needs tau > 0".into()))
                }
                (other, _, _) => {
                    return Err(err(
                        t.span(),
                        format!("unknown thermostat '{other}': expected langevin or bussi"),
                    ))
                }
            })
        }
    })
}
