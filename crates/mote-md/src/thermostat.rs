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
//! Neither is applied along fixed axes. Their random numbers are
//! counter-based ([`Noise`]): Langevin's of particle i at step k from a
//! stream seeded by (seed, k, id of i), Bussi's from one seeded by
//! (seed, k), so neither the number of threads or ranks nor a resume
//! changes them.

use rand::Rng;
use rand_distr::{Distribution, Gamma, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;

use crate::particles::System;

/// A thermostat and its parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Thermostat {
    /// Langevin friction γ (per time) at temperature kT (energy).
    Langevin { kt: f64, gamma: f64 },
    /// Bussi stochastic velocity rescaling with relaxation time τ at temperature kT.
    Bussi { kt: f64, tau: f64 },
}

/// Where a step's random numbers come from: the run's seed and the step
/// (a resumed run draws what the uninterrupted one drew), the particles'
/// ids and, in a decomposed run, its ranks.
#[derive(Clone, Copy)]
pub struct Noise<'a> {
    pub seed: u64,
    pub step: u64,
    /// The id of each particle (empty: its index).
    pub ids: &'a [u64],
    /// The ranks a decomposed run's sums go over.
    pub comm: Option<&'a dyn mote_run::comm::Comm>,
}

impl Noise<'_> {
    /// The stream of the whole system at this step (xoshiro256++ seeded
    /// through SplitMix64 from the seed and the step).
    pub fn global(&self) -> Xoshiro256PlusPlus {
        use rand::SeedableRng;
        Xoshiro256PlusPlus::seed_from_u64(
            self.seed
                ^ self
                    .step
                    .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    .rotate_left(17),
        )
    }

    /// The stream of particle i at this step, from the seed, the step and
    /// the particle's id: the same numbers on any number of threads or
    /// ranks, whichever rank holds the particle.
    pub fn particle(&self, i: usize) -> Xoshiro256PlusPlus {
        use rand::SeedableRng;
        let id = self.ids.get(i).copied().unwrap_or(i as u64);
        Xoshiro256PlusPlus::seed_from_u64(
            self.seed
                ^ self
                    .step
                    .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    .rotate_left(17)
                ^ id.wrapping_add(1)
                    .wrapping_mul(0xBF58_476D_1CE4_E5B9)
                    .rotate_left(29),
        )
    }
}

impl Thermostat {
    /// Applies one step of length `dt` to the velocities, drawing from
    /// `noise`: Langevin each particle from its own stream, Bussi one
    /// rescaling from the system's (its kinetic energy and degrees of
    /// freedom summed over the ranks of a decomposed run).
    pub fn apply(&self, sys: &mut System, dt: f64, noise: &Noise) {
        match *self {
            Thermostat::Langevin { kt, gamma } => {
                let c = (-gamma * dt).exp();
                let p = &mut sys.particles;
                let (mass, mobility) = (&p.mass, &p.mobility);
                p.velocity
                    .par_iter_mut()
                    .enumerate()
                    .with_min_len(1024)
                    .for_each(|(i, v)| {
                        let mut rng = noise.particle(i);
                        let s = ((1.0 - c * c) * kt / mass[i]).sqrt();
                        let xi = glam::DVec3::new(
                            rng.sample(StandardNormal),
                            rng.sample(StandardNormal),
                            rng.sample(StandardNormal),
                        );
                        *v = (*v * c + xi * s) * mobility[i];
                    });
            }
            Thermostat::Bussi { kt, tau } => {
                let mut nf = sys.degrees_of_freedom();
                let p = &mut sys.particles;
                let mut k: f64 = (0..p.len())
                    .map(|i| 0.5 * p.mass[i] * p.velocity[i].length_squared())
                    .sum();
                if let Some(comm) = noise.comm {
                    let free: f64 = p.mobility.iter().map(|m| m.x + m.y + m.z).sum();
                    let total = comm.sum(&[k, free, p.len() as f64]);
                    k = total[0];
                    nf = crate::particles::translational_freedom(total[1], total[2]);
                }
                if k <= 0.0 || nf < 1.0 {
                    return;
                }
                let mut rng = noise.global();
                let k_target = 0.5 * nf * kt;
                let c = (-dt / tau).exp();
                let r1: f64 = rng.sample(StandardNormal);
                // Σ_{i=2}^{N_f} R_i² is χ² with N_f − 1 degrees of freedom = 2·Gamma((N_f − 1)/2, 1).
                let rest = if nf > 1.0 {
                    2.0 * Gamma::new(0.5 * (nf - 1.0), 1.0)
                        .map(|g| g.sample(&mut rng))
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
