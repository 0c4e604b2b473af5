//! `[lennard_jones]`: Lennard-Jones or WCA between all particles within
//! a cut-off, through a Verlet list on a ghost list (periodic boxes);
//! beside a cut-off `[dipolar]`, in the dipolar pair loop.

use std::ops::Range;

use serde::Deserialize;

use mote_io::ParseError;

use super::{one, yes, Build, Scene, Section};
use crate::force::LennardJones;

/// `[lennard_jones]`: LJ or WCA between all particles through a Verlet list.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LennardJonesSettings {
    #[serde(default = "one")]
    pub epsilon: f64,
    #[serde(default = "one")]
    pub sigma: f64,
    /// Cut-off r_c in units of length (default 2.5 σ; WCA: 2^{1/6} σ).
    pub cutoff: Option<f64>,
    /// Subtract U(r_c) (default true).
    #[serde(default = "yes")]
    pub shifted: bool,
    /// Purely repulsive WCA: cut at 2^{1/6} σ and shifted.
    #[serde(default)]
    pub wca: bool,
    /// Verlet-list skin (default 0.3 σ).
    pub skin: Option<f64>,
    /// Also rebuild the list every this many steps (0: only on displacement).
    #[serde(default)]
    pub rebuild_every: u64,
}

impl Section for LennardJonesSettings {
    fn add_to(&self, span: Range<usize>, scene: &Scene, b: &mut Build) -> Result<(), ParseError> {
        let src = b.src;
        let boundary = b.boundary;
        let err = |span: Range<usize>, msg: String| src.error(span, msg);
        let v = self;
        if v.epsilon <= 0.0 || v.sigma <= 0.0 {
            return Err(err(
                span.clone(),
                "[lennard_jones] needs epsilon > 0 and sigma > 0".into(),
            ));
        }
        let skin = v.skin.unwrap_or(0.3 * v.sigma);
        let mut pair = if v.wca {
            LennardJones::wca(v.epsilon, v.sigma, skin)
        } else {
            let rc = v.cutoff.unwrap_or(2.5 * v.sigma);
            LennardJones::new(v.epsilon, v.sigma, rc, v.shifted, skin)
        };
        if pair.cutoff <= 0.0 || skin < 0.0 {
            return Err(err(
                span.clone(),
                "[lennard_jones] needs cutoff > 0 and skin ≥ 0".into(),
            ));
        }
        let reach = pair.cutoff + skin;
        let l = boundary.lengths();
        if (0..3).any(|k| boundary.periodic[k] && l[k] < 2.0 * reach) {
            return Err(err(
                span.clone(),
                format!("the periodic box ({} × {} × {}) must be at least twice cutoff + skin = {reach} on every periodic axis", l.x, l.y, l.z),
            ));
        }
        pair.list.every = v.rebuild_every;
        // Beside a cut-off [dipolar], both laws run in the dipolar pair
        // loop (one pass over the pairs; see `dipolar::fused_lennard_jones`).
        if super::dipolar::fused_lennard_jones(scene).is_none() {
            b.forces.push(pair);
        }
        Ok(())
    }
}
