//! Barnes–Hut Coulomb interaction of point charges in open space:
//! F_i = k q_i Σ_{j≠i} q_j (r_i − r_j) / (|r_i − r_j|² + ε²)^{3/2},
//! U = k Σ_{i<j} q_i q_j / (|r_i − r_j|² + ε²)^{1/2},
//! with k the Coulomb constant of the unit system (1/(4πε₀) in SI, 1 in
//! Gaussian or reduced units) and optional softening ε. Cells are expanded
//! about their centre of |q| with monopole, dipole and quadrupole
//! ([`super::multipole`]): a neutral cell acts through its dipole.

use glam::DVec3;
use rayon::prelude::*;

use super::barnes_hut::{BarnesHut, WalkCounts};
use super::ForceError;
use crate::force::{Interaction, State};

/// Point charges by a Barnes–Hut tree; the charges come with the step's
/// [`State`] (one per particle).
#[derive(Debug, Clone)]
pub struct TreeCoulomb {
    /// Coulomb constant k.
    pub k: f64,
    /// Softening length ε (0 for bare charges).
    pub softening: f64,
    bh: BarnesHut,
}

impl TreeCoulomb {
    pub fn new(k: f64, softening: f64, theta: f64) -> Self {
        Self {
            k,
            softening,
            bh: BarnesHut::new(theta, softening),
        }
    }

    /// Interaction counts of the last evaluation.
    pub fn counts(&self) -> WalkCounts {
        self.bh.counts
    }

    /// Forces F_i into `out` (overwritten).
    pub fn forces(&mut self, state: &State, out: &mut [DVec3]) {
        out.iter_mut().for_each(|f| *f = DVec3::ZERO);
        self.add_forces(state, out);
    }

    /// Relative force errors against the direct sum on every `stride`-th particle.
    pub fn sampled_error(&mut self, state: &State, stride: usize) -> ForceError {
        let n = state.position.len();
        let mut f = vec![DVec3::ZERO; n];
        self.forces(state, &mut f);
        let eps2 = self.softening * self.softening;
        let (pos, q) = (state.position, state.charges());
        let errors: Vec<f64> = (0..n)
            .into_par_iter()
            .step_by(stride.max(1))
            .map(|i| {
                let exact = -self.k * q[i] * super::gravity::direct_field(pos, q, eps2, i);
                (f[i] - exact).length() / exact.length()
            })
            .collect();
        ForceError::from_samples(errors)
    }
}

impl Interaction for TreeCoulomb {
    fn name(&self) -> &'static str {
        "coulomb"
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        let charge = state.charges();
        self.bh.eps2 = self.softening * self.softening;
        self.bh.build(state.position, charge);
        self.bh.evaluate(false);
        for (k, g) in self.bh.gradient().iter().enumerate() {
            let i = self.bh.index(k);
            force[i] -= *g * (self.k * charge[i]);
        }
    }

    /// U = (k/2) Σ_i q_i ψ_i from the tree walk.
    fn potential_energy(&mut self, state: &State) -> f64 {
        self.bh.eps2 = self.softening * self.softening;
        self.bh.build(state.position, state.charges());
        self.bh.evaluate(true);
        let psi = self.bh.potential();
        let q = self.bh.strength();
        0.5 * self.k * (0..psi.len()).map(|k| q[k] * psi[k]).sum::<f64>()
    }
}
