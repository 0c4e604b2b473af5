//! `[gravity]`: Newtonian gravity between all particles, direct or by a
//! Barnes–Hut tree; `[field]`: a uniform gravitational acceleration.

use std::ops::Range;

use glam::DVec3;
use serde::Deserialize;

use mote_io::ParseError;

use super::{Build, Scene, Section};
use crate::force::{DirectGravity, UniformField};
use crate::tree::TreeGravity;

/// `[gravity]`: softened direct-summation Newtonian gravity (002 Eq. 2).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GravitySettings {
    /// Newton's constant; default: the unit system's (k² in astro units).
    #[serde(rename = "G")]
    pub g: Option<f64>,
    #[serde(default)]
    pub softening: f64,
    /// `direct` (default: every pair, exact) or `tree` (Barnes–Hut).
    #[serde(default = "direct")]
    pub method: String,
    /// Opening angle θ of the tree (default 0.5).
    pub theta: Option<f64>,
}

/// Two particles at exactly one position, if any (lowest indices of the
/// first such pair in sorted order).
pub(crate) fn coincident(position: &[DVec3]) -> Option<(usize, usize)> {
    let mut order: Vec<usize> = (0..position.len()).collect();
    let key = |i: &usize| position[*i].to_array().map(f64::to_bits);
    order.sort_unstable_by_key(key);
    order
        .windows(2)
        .find(|w| position[w[0]] == position[w[1]])
        .map(|w| (w[0].min(w[1]), w[0].max(w[1])))
}

pub(crate) fn direct() -> String {
    "direct".into()
}

impl Section for GravitySettings {
    fn add_to(&self, span: Range<usize>, scene: &Scene, b: &mut Build) -> Result<(), ParseError> {
        let err = |msg: String| b.src.error(span.clone(), msg);
        if self.softening.is_nan() || self.softening < 0.0 {
            return Err(err("[gravity] softening must not be negative".into()));
        }
        if self.softening == 0.0 {
            // Unsoftened gravity is infinite where two particles coincide
            // (the pair would be skipped as 0/0 and the run go on wrong).
            if let Some((i, j)) = coincident(&b.particles.position) {
                return Err(err(format!(
                    "particles {i} and {j} coincide at {:?}: unsoftened gravity is infinite there; \
                     move one, or give [gravity] softening > 0",
                    b.particles.position[i].to_array()
                )));
            }
        }
        if b.boundary.periodic.iter().any(|p| *p) {
            // Both methods sum over open space; a periodic box would have
            // every pair at its open-space distance, not its image's.
            return Err(err(
                "[gravity] sums over open space, and the [box] is periodic: leave out [box], or make it open (periodic = [false, false, false])".into(),
            ));
        }
        let g = self.g.unwrap_or(scene.units.gravitational_constant());
        match (self.method.as_str(), self.theta) {
            ("direct", None) => b.forces.push(DirectGravity::new(g, self.softening)),
            ("tree", theta) => {
                let theta = theta.unwrap_or(0.5);
                if !(0.0..1.2).contains(&theta) {
                    return Err(err(format!(
                        "[gravity] theta must be in [0, 1.2), found {theta}"
                    )));
                }
                b.forces.push(TreeGravity::new(g, self.softening, theta));
            }
            ("direct", Some(_)) => {
                return Err(err("[gravity] theta needs method = \"tree\"".into()))
            }
            (other, _) => {
                return Err(err(format!(
                    "[gravity] unknown method '{other}': expected direct or tree"
                )))
            }
        }
        Ok(())
    }
}

/// `[field]`: uniform gravitational acceleration (MPPphys `grav`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldSettings {
    pub g: [f64; 3],
}

impl Section for FieldSettings {
    fn add_to(&self, span: Range<usize>, _: &Scene, b: &mut Build) -> Result<(), ParseError> {
        if self.g.iter().any(|x| !x.is_finite()) {
            return Err(b.src.error(span, "[field] g must be finite"));
        }
        b.forces.push(UniformField {
            g: DVec3::from(self.g),
        });
        Ok(())
    }
}
