//! Thermostats, applied after each step of the integrator.
//!
//! - Langevin: an Ornstein–Uhlenbeck step on the velocities,
//!   v ← c v + √((1 − c²) k T / m) ξ with c = e^{−γ Δt} — exact for the
//!   friction and noise part, so velocity Verlet followed by it samples the
//!   canonical ensemble up to O(Δt²) (Bussi & Parrinello, PRE 75, 056707 (2007)).
//! - Bussi (CSVR): all velocities rescaled by α, with the kinetic energy K
//!   drawn from the canonical-sampling stochastic velocity rescaling of
//!   Bussi, Donadio & Parrinello, J. Chem. Phys. 126, 014101 (2007), Eq. (A7):
//!   α² = c + (1−c)(R₁² + Σ_{i=2}^{N_f} R_i²) K̄/(N_f K) + 2R₁√(c(1−c) K̄/(N_f K)),
//!   c = e^{−Δt/τ}, K̄ = N_f k T / 2.
//!
//! Neither is applied along fixed axes.

use rand::Rng;
use rand_distr::{Distribution, Gamma, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::particles::System;

/// A thermostat and its parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Thermostat {
    /// Langevin friction γ (per time) at temperature kT (energy).
    Langevin { kt: f64, gamma: f64 },
    /// Bussi stochastic velocity rescaling with relaxation time τ at temperature kT.
    Bussi { kt: f64, tau: f64 },
}

impl Thermostat {
    /// Applies one step of length `dt` to the velocities.
    pub fn apply(&self, sys: &mut System, dt: f64, rng: &mut Xoshiro256PlusPlus) {
        match *self {
            Thermostat::Langevin { kt, gamma } => {
                let c = (-gamma * dt).exp();
                let p = &mut sys.particles;
                for i in 0..p.len() {
                    let s = ((1.0 - c * c) * kt / p.mass[i]).sqrt();
                    let xi = glam::DVec3::new(
                        rng.sample(StandardNormal),
                        rng.sample(StandardNormal),
                        rng.sample(StandardNormal),
                    );
                    p.velocity[i] = (p.velocity[i] * c + xi * s) * p.mobility[i];
                }
            }
            Thermostat::Bussi { kt, tau } => {
                let nf = sys.degrees_of_freedom();
                let p = &mut sys.particles;
                let k: f64 = (0..p.len())
                    .map(|i| 0.5 * p.mass[i] * p.velocity[i].length_squared())
                    .sum();
                if k <= 0.0 || nf < 1.0 {
                    return;
                }
                let k_target = 0.5 * nf * kt;
                let c = (-dt / tau).exp();
                let r1: f64 = rng.sample(StandardNormal);
                // Σ_{i=2}^{N_f} R_i² is χ² with N_f − 1 degrees of freedom = 2·Gamma((N_f − 1)/2, 1).
                let rest = if nf > 1.0 {
                    2.0 * Gamma::new(0.5 * (nf - 1.0), 1.0)
                        .map(|g| g.sample(rng))
                        .unwrap_or(nf - 1.0)
                } else {
                    0.0
                };
                let ratio = k_target / (nf * k);
                let alpha2 = c
                    + (1.0 - c) * (r1 * r1 + rest) * ratio
                    + 2.0 * r1 * (c * (1.0 - c) * ratio).sqrt();
                let alpha = alpha2.max(0.0).sqrt();
                p.velocity.iter_mut().for_each(|v| *v *= alpha);
            }
        }
    }
}
