//! Damped springs between particle pairs (002 Eq. 4):
//!
//! F_i = Σ_j [ D_ij (x_j − x_i)/|x_j − x_i| (|x_j − x_i| − l_ij) + c_ij (v_j − v_i) ],
//!
//! with stiffness D, damping c (along the full relative velocity, as in the
//! seed) and rest length l; F_j = −F_i for each spring.

use glam::DVec3;

use super::{Interaction, State};

/// One spring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spring {
    pub i: usize,
    pub j: usize,
    /// Stiffness D.
    pub stiffness: f64,
    /// Damping coefficient c.
    pub damping: f64,
    /// Rest length l.
    pub rest_length: f64,
}

/// All springs of a mass–spring network.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SpringNetwork {
    pub springs: Vec<Spring>,
    /// W = Σ r_ij · F_ij of the last force evaluation.
    pub virial: f64,
}

impl SpringNetwork {
    /// Elastic plus damping force on particle i of one spring.
    #[inline]
    fn force_on_i(s: &Spring, xi: DVec3, xj: DVec3, vi: DVec3, vj: DVec3) -> DVec3 {
        let d = xj - xi;
        let len = d.length();
        let elastic = if len > 0.0 {
            d * (s.stiffness * (len - s.rest_length) / len)
        } else {
            DVec3::ZERO
        };
        elastic + (vj - vi) * s.damping
    }
}

impl Interaction for SpringNetwork {
    fn name(&self) -> &'static str {
        "springs"
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        let (x, v) = (state.position, state.velocity);
        let mut virial = 0.0;
        for s in &self.springs {
            let f = Self::force_on_i(s, x[s.i], x[s.j], v[s.i], v[s.j]);
            force[s.i] += f;
            force[s.j] -= f;
            // r_ij · F_ij with r_ij = x_i − x_j and F_ij = f on i.
            virial += (x[s.i] - x[s.j]).dot(f);
        }
        self.virial = virial;
    }

    fn virial(&self) -> Option<f64> {
        Some(self.virial)
    }

    /// U = Σ ½ D (|x_j − x_i| − l)².
    fn potential_energy(&mut self, state: &State) -> f64 {
        self.springs
            .iter()
            .map(|s| {
                let stretch = (state.position[s.j] - state.position[s.i]).length() - s.rest_length;
                0.5 * s.stiffness * stretch * stretch
            })
            .sum()
    }
}
