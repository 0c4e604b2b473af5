//! Damped springs between particle pairs (002 Eq. 4):
//!
//! F_i = Σ_j [ D_ij (x_j − x_i)/|x_j − x_i| (|x_j − x_i| − l_ij) + c_ij (v_j − v_i) ],
//!
//! with stiffness D, damping c (along the full relative velocity, as in the
//! seed) and rest length l; F_j = −F_i for each spring. In a periodic box
//! x_j − x_i is the minimum image, so a spring may cross the box's faces.

use glam::DVec3;

use super::{Interaction, State, Virial};

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
    /// Elastic plus damping force on particle i of one spring whose
    /// separation is d = x_j − x_i.
    #[inline]
    fn force_on_i(s: &Spring, d: DVec3, vi: DVec3, vj: DVec3) -> DVec3 {
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
        let image = state.boundary.image();
        let mut virial = 0.0;
        for s in &self.springs {
            let d = image.apply(x[s.j] - x[s.i]);
            let f = Self::force_on_i(s, d, v[s.i], v[s.j]);
            force[s.i] += f;
            force[s.j] -= f;
            // r_ij · F_ij with r_ij = x_i − x_j = −d and F_ij = f on i.
            virial -= d.dot(f);
        }
        self.virial = virial;
    }

    fn virial(&self) -> Option<f64> {
        Some(self.virial)
    }

    fn virial_tensor(&mut self, state: &State) -> Option<Virial> {
        let (x, v) = (state.position, state.velocity);
        let image = state.boundary.image();
        Some(
            self.springs
                .iter()
                .map(|s| {
                    let d = image.apply(x[s.j] - x[s.i]);
                    Virial::pair(-d, Self::force_on_i(s, d, v[s.i], v[s.j]))
                })
                .sum(),
        )
    }

    /// U = Σ ½ D (|x_j − x_i| − l)².
    fn potential_energy(&mut self, state: &State) -> f64 {
        let (x, image) = (state.position, state.boundary.image());
        self.springs
            .iter()
            .map(|s| {
                let stretch = image.apply(x[s.j] - x[s.i]).length() - s.rest_length;
                0.5 * s.stiffness * stretch * stretch
            })
            .sum()
    }
}
