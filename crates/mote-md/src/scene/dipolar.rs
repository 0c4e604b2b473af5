//! `[dipolar]`: magnetic dipole–dipole forces and torques between particles
//! with a `dipole` (004 Eq. 8): all pairs, pairs within a cut-off (with a
//! reaction field and WCA repulsion in the same loop), Ewald sums, or P3M;
//! `[magnetic_field]`: the applied field H (Zeeman, 004 Eq. 10).

use std::ops::Range;

use glam::DVec3;
use serde::Deserialize;

use mote_io::ParseError;

use super::electric::{ewald_box, positive, P3mKeys};
use super::gravity::direct;
use super::{Build, Scene, Section};
use crate::force::dipolar::{
    vacuum_permeability, AppliedField, DipoleDipole, PairRepulsion, Zeeman,
};
use crate::force::ewald::EwaldDipoles;
use crate::force::p3m::P3mDipoles;

/// `[dipolar]`: magnetic dipole–dipole forces and torques (004 Eq. 8)
/// between particles with a `dipole`, optionally with WCA repulsion.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DipolarSettings {
    /// μ₀ (default: the unit system's; 4π in LJ units).
    pub mu0: Option<f64>,
    /// `direct` (default: all pairs, or pairs within `cutoff`), `ewald`
    /// (Ewald summation with tin-foil boundaries in a cubic periodic box)
    /// or `p3m` (the Ewald sum's k-space part on a mesh: any orthorhombic
    /// periodic box, O(N log N)).
    #[serde(default = "direct")]
    pub method: String,
    /// Cut-off with the minimum image (periodic boxes); absent: all pairs.
    /// With Ewald: the real-space cut-off (default half the box); with
    /// P3M: tuned when not given.
    pub cutoff: Option<f64>,
    /// Ewald and P3M: the RMS force error aimed at, in force units (Wang &
    /// Holm 2001, Eqs. 38 and 46, choose α and the k-vectors; for P3M,
    /// Cerdà et al. 2008 the mesh).
    pub accuracy: Option<f64>,
    /// Verlet skin of the cut-off list (default 0.3; P3M: a tenth of the
    /// cut-off given, else 0.3 mean particle spacings, at most a tenth of the shortest side).
    pub skin: Option<f64>,
    /// P3M: mesh points along each axis (default: tuned).
    pub mesh: Option<[usize; 3]>,
    /// P3M: assignment order 1–7 (default: tuned, 3–7).
    pub order: Option<usize>,
    /// Relative permeability of the reaction field beyond the cut-off;
    /// `"conducting"` for ε_RF = ∞ (absent: none).
    pub reaction_field: Option<toml::Value>,
    /// WCA repulsion `{ epsilon, sigma }` in the same pair loop.
    pub wca: Option<WcaSettings>,
    /// Turn every dipole into a random direction (same |m|) at the start.
    #[serde(default)]
    pub random_orientation: bool,
}

/// `{ epsilon, sigma }` of a WCA repulsion.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WcaSettings {
    pub epsilon: f64,
    pub sigma: f64,
}

/// `[magnetic_field]`: an applied field H acting on the dipoles (Zeeman,
/// 004 Eq. 10): uniform `h = [..]`, or rotating with `amplitude`,
/// `angular_frequency` (rad per time), `axis`, `phase`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MagneticFieldSettings {
    pub h: Option<[f64; 3]>,
    pub amplitude: Option<f64>,
    pub angular_frequency: Option<f64>,
    pub axis: Option<[f64; 3]>,
    #[serde(default)]
    pub phase: f64,
    pub mu0: Option<f64>,
}

impl Section for DipolarSettings {
    fn add_to(&self, span: Range<usize>, scene: &Scene, b: &mut Build) -> Result<(), ParseError> {
        let mu0_default = vacuum_permeability(scene.units);
        let src = b.src;
        let boundary = b.boundary;
        let err = |span: Range<usize>, msg: String| src.error(span, msg);
        let v = self;
        let mu0 = v
            .mu0
            .or(mu0_default)
            .ok_or_else(|| err(span.clone(), "[dipolar] needs mu0 in these units".into()))?;
        if v.random_orientation && b.centres_of_bodies {
            return Err(err(
                span,
                "[dipolar] random_orientation turns point particles' dipoles; a body's dipole is its template's, turned with the body (random_orientation of [[rigid.lattice]] and [[rigid.random]])".into(),
            ));
        }
        if v.random_orientation {
            use rand::Rng;
            for m in b.particles.dipole.iter_mut() {
                let len = m.length();
                let u: f64 = 2.0 * b.rng.gen::<f64>() - 1.0;
                let phi = 2.0 * std::f64::consts::PI * b.rng.gen::<f64>();
                let s = (1.0 - u * u).sqrt();
                *m = DVec3::new(s * phi.cos(), s * phi.sin(), u) * len;
            }
        }
        let method = self.method.as_str();
        let keys: &[(&str, bool)] = match method {
            "ewald" => &[
                ("skin", self.skin.is_some()),
                ("reaction_field", self.reaction_field.is_some()),
                ("wca", self.wca.is_some()),
                ("mesh", self.mesh.is_some()),
                ("order", self.order.is_some()),
            ],
            "p3m" => &[
                ("reaction_field", self.reaction_field.is_some()),
                ("wca", self.wca.is_some()),
            ],
            _ => &[
                ("mesh", self.mesh.is_some()),
                ("order", self.order.is_some()),
            ],
        };
        for (key, given) in keys {
            if *given {
                return Err(err(
                    span.clone(),
                    format!(
                        "[dipolar] {key} does not apply to method = \"{method}\"{}",
                        if *key == "wca" {
                            " (add [lennard_jones] wca = true beside it)"
                        } else if matches!(*key, "mesh" | "order") {
                            " (it is a key of method = \"p3m\")"
                        } else {
                            ""
                        }
                    ),
                ));
            }
        }
        match method {
            "direct" => {}
            "p3m" => {
                let keys = P3mKeys {
                    accuracy: self.accuracy,
                    cutoff: self.cutoff,
                    skin: self.skin,
                    mesh: self.mesh,
                    order: self.order,
                };
                let dipole = &b.particles.dipole;
                let request = keys.request("dipolar", span.clone(), src, dipole.len(), boundary)?;
                let k = mu0 / (4.0 * std::f64::consts::PI);
                let p3m = P3mDipoles::tuned(k, &request, dipole, &boundary)
                    .map_err(|e| err(span.clone(), format!("[dipolar] {e}")))?;
                b.forces.push(p3m);
                return Ok(());
            }
            "ewald" => {
                let l = ewald_box(src, span.clone(), boundary, "dipolar")?;
                let rc = self.cutoff.unwrap_or(0.5 * l);
                let accuracy = self.accuracy.ok_or_else(|| {
                    err(
                        span.clone(),
                        "[dipolar] method = \"ewald\" needs accuracy = the RMS force error aimed at (force units)".into(),
                    )
                })?;
                positive(src, span.clone(), "[dipolar] accuracy", accuracy)?;
                positive(src, span.clone(), "[dipolar] cutoff", rc)?;
                if rc > 0.5 * l {
                    return Err(err(
                        span.clone(),
                        format!("[dipolar] the Ewald cut-off {rc} must be at most half the box side {l}"),
                    ));
                }
                let k = mu0 / (4.0 * std::f64::consts::PI);
                let ewald = EwaldDipoles::new(k, &b.particles.dipole, l, rc, accuracy);
                b.forces.push(ewald);
                return Ok(());
            }
            other => {
                return Err(err(
                    span.clone(),
                    format!("[dipolar] unknown method '{other}': expected direct, ewald or p3m"),
                ))
            }
        }
        if self.accuracy.is_some() {
            return Err(err(
                span.clone(),
                "[dipolar] accuracy needs method = \"ewald\" or \"p3m\"".into(),
            ));
        }
        if v.cutoff.is_none() && boundary.periodic.iter().any(|p| *p) {
            return Err(err(
                span.clone(),
                "[dipolar] without cutoff sums every pair over open space, and the [box] is periodic: give cutoff = r_c (the minimum image, with a reaction field), method = \"ewald\" or method = \"p3m\"".into(),
            ));
        }
        let mut pair = match v.cutoff {
            None => DipoleDipole::all_pairs(mu0),
            Some(rc) => DipoleDipole::cut_off(mu0, rc, v.skin.unwrap_or(0.3), boundary)
                .map_err(|e| err(span.clone(), format!("[dipolar] {e}")))?,
        };
        match &v.reaction_field {
            None => {}
            Some(toml::Value::String(s)) if s == "conducting" => {
                pair = pair.with_reaction_field(f64::INFINITY)
            }
            Some(toml::Value::Float(x)) if *x >= 1.0 => pair = pair.with_reaction_field(*x),
            Some(toml::Value::Integer(x)) if *x >= 1 => {
                pair = pair.with_reaction_field(*x as f64)
            }
            Some(other) => {
                return Err(err(
                    span.clone(),
                    format!("[dipolar] reaction_field must be \"conducting\" or a permeability ≥ 1, found {other}"),
                ))
            }
        }
        if let Some(w) = &v.wca {
            pair = pair
                .with_repulsion(PairRepulsion::wca(w.epsilon, w.sigma))
                .map_err(|e| err(span.clone(), format!("[dipolar] {e}")))?;
        }
        if let Some((lj, every)) = fused_lennard_jones(scene) {
            pair = pair
                .with_repulsion(lj)
                .map_err(|e| err(span.clone(), format!("[dipolar] with [lennard_jones]: {e}")))?;
            pair.list.every = every;
        }
        b.forces.push(pair);
        Ok(())
    }
}

/// The `[lennard_jones]` a cut-off `[dipolar]` takes into its own pair
/// loop (004 Eq. 9: one pass over the pairs for both laws, LAMMPS's
/// `lj/cut/dipole/cut`), with the list's rebuild interval; `None` where the
/// two stay apart (all pairs, Ewald, a `wca` already in `[dipolar]`, no
/// `[lennard_jones]`). The forces are the two laws' sum either way.
pub(crate) fn fused_lennard_jones(scene: &Scene) -> Option<(PairRepulsion, u64)> {
    let d = scene.dipolar.as_ref()?.get_ref();
    let lj = scene.lennard_jones.as_ref()?.get_ref();
    if d.method != "direct" || d.cutoff.is_none() || d.wca.is_some() {
        return None;
    }
    let repulsion = if lj.wca {
        PairRepulsion::wca(lj.epsilon, lj.sigma)
    } else {
        PairRepulsion {
            epsilon: lj.epsilon,
            sigma: lj.sigma,
            cutoff: lj.cutoff.unwrap_or(2.5 * lj.sigma),
            shifted: lj.shifted,
        }
    };
    Some((repulsion, lj.rebuild_every))
}

impl Section for MagneticFieldSettings {
    fn add_to(&self, span: Range<usize>, scene: &Scene, b: &mut Build) -> Result<(), ParseError> {
        let mu0_default = vacuum_permeability(scene.units);
        let src = b.src;
        let err = |span: Range<usize>, msg: String| src.error(span, msg);
        let v = self;
        let mu0 = v.mu0.or(mu0_default).ok_or_else(|| {
            err(
                span.clone(),
                "[magnetic_field] needs mu0 in these units".into(),
            )
        })?;
        let field = match (v.h, v.amplitude, v.angular_frequency) {
            (Some(h), None, None) => AppliedField::Uniform(DVec3::from(h)),
            (None, Some(amplitude), Some(angular_frequency)) => AppliedField::Rotating {
                amplitude,
                angular_frequency,
                axis: DVec3::from(v.axis.unwrap_or([0.0, 0.0, 1.0])).normalize(),
                phase: v.phase,
            },
            _ => {
                return Err(err(
                    span.clone(),
                    "[magnetic_field] takes h = [..] (uniform) or amplitude and angular_frequency (rotating)".into(),
                ))
            }
        };
        b.forces.push(Zeeman::new(mu0, field));
        Ok(())
    }
}
