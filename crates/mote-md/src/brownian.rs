//! Overdamped (Brownian) dynamics of spheres with orientations, and the
//! Langevin thermostat of inertial rotation.
//!
//! Without inertia the equations of motion of 004 (Eqs. 14–16, after
//! Odenbach & Ilg) become, with the thermal forces and torques of the
//! fluctuation–dissipation theorem added (004 neglects them; its Eq. 15
//! reads ṙ = ξ_t F where the friction divides, ṙ = F/ξ_t),
//!
//! dr = F/ξ_t dt + √(2 k_BT/ξ_t) dW,       (004 Eqs. 13, 15)
//! dφ = τ/ξ_r dt + √(2 k_BT/ξ_r) dW_r,     (004 Eqs. 14, 16)
//!
//! where dφ is the rotation vector by which the particle (and its moment m)
//! turns. The Euler–Maruyama step draws Δr and Δφ over a step h and turns
//! m by Rodrigues' formula ([`rotate`]), which keeps |m| exactly (to
//! round-off): the orientation stays on its sphere without projection. The
//! rotation by a random vector carries the drift of diffusion on the
//! sphere: ⟨u(t)·u(0)⟩ = exp(−2 D_r t) with D_r = k_BT/ξ_r, and the
//! stationary distribution of a dipole in a field H is Boltzmann's,
//! ∝ exp(μ₀ m·H/k_BT), to first order in h (both tested). Stokes friction
//! of a sphere of radius a in a liquid of viscosity η: ξ_t = 6πηa,
//! ξ_r = 8πηa³.
//!
//! Random numbers are counter-based like the thermostat's
//! ([`Noise`]): the normal deviates of particle i at step k come from
//! xoshiro256++ seeded by (seed, k, id of i). A step's result therefore
//! depends on neither the thread count, nor the number of ranks of a
//! decomposed run, nor the history (a resumed run draws the same numbers).
//!
//! [`rotate`]: crate::integrate::rotate

use glam::DVec3;
use rand::Rng;
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;

use crate::force::{ForceField, Spin, State};
use crate::integrate::rotate;
use crate::particles::System;
use crate::thermostat::Noise;

/// Translational and rotational friction coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Friction {
    /// The same ξ_t (force per velocity) and ξ_r (torque per angular
    /// velocity) for every particle.
    Uniform { translational: f64, rotational: f64 },
    /// Stokes drag of each particle's sphere in a liquid of viscosity η:
    /// ξ_t = 6πηa, ξ_r = 8πηa³ (a = the particle's radius).
    Stokes { viscosity: f64 },
}

impl Friction {
    /// (ξ_t, ξ_r) of a particle of radius a.
    #[inline]
    pub fn of(&self, radius: f64) -> (f64, f64) {
        match *self {
            Friction::Uniform {
                translational,
                rotational,
            } => (translational, rotational),
            Friction::Stokes { viscosity } => {
                let pi = std::f64::consts::PI;
                (
                    6.0 * pi * viscosity * radius,
                    8.0 * pi * viscosity * radius.powi(3),
                )
            }
        }
    }
}

/// Euler–Maruyama integrator of overdamped translation and rotation.
#[derive(Debug, Clone)]
pub struct BrownianStepper {
    /// Thermal energy k_BT.
    pub kt: f64,
    pub friction: Friction,
    /// Whether the moments turn (rotational Brownian motion and torques).
    pub rotate: bool,
    force: Vec<DVec3>,
    torque: Vec<DVec3>,
}

impl BrownianStepper {
    pub fn new(kt: f64, friction: Friction) -> Self {
        Self {
            kt,
            friction,
            rotate: true,
            force: Vec::new(),
            torque: Vec::new(),
        }
    }

    /// The forces and torques of every interaction at the current state,
    /// one step `h` after the previous evaluation.
    fn forces_and_torques(&mut self, sys: &System, ff: &mut ForceField, h: f64) {
        let p = &sys.particles;
        let n = p.len();
        self.force.clear();
        self.force.resize(n, DVec3::ZERO);
        self.torque.clear();
        self.torque.resize(n, DVec3::ZERO);
        let state = State::of(sys, &p.position, &p.velocity, sys.time, h);
        let spin = Spin {
            angular_velocity: &p.angular_velocity,
        };
        ff.add_forces_and_torques(&state, &spin, &mut self.force, &mut self.torque);
    }

    /// Advances the system by one step h (004 Eqs. 15–16 with noise).
    /// `step_index` and `seed` pick the random numbers (pass the number of
    /// the step being taken, e.g. `sys.step + 1`, and the run's seed).
    /// Velocities and angular velocities are set to the drifts F/ξ_t and
    /// τ/ξ_r (the noise has no velocity); fixed axes (`mobility`) do not
    /// move, and fully fixed particles do not turn.
    pub fn step(
        &mut self,
        sys: &mut System,
        ff: &mut ForceField,
        h: f64,
        step_index: u64,
        seed: u64,
    ) {
        // A decomposed run's particles may migrate here, before the
        // evaluation.
        ff.before_forces(sys);
        self.forces_and_torques(sys, ff, h);
        let (kt, friction, turn) = (self.kt, self.friction, self.rotate);
        let (force, torque) = (&self.force, &self.torque);
        let noise = Noise {
            seed,
            step: step_index,
            ids: ff.domain.as_ref().map_or(&[], |d| &d.halo().id),
            comm: None,
        };
        let p = &mut sys.particles;
        let radius = &p.radius;
        let mobility = &p.mobility;
        (
            &mut p.position,
            &mut p.velocity,
            &mut p.angular_velocity,
            &mut p.dipole,
        )
            .into_par_iter()
            .enumerate()
            .with_min_len(256)
            .for_each(|(i, (pos, vel, omega, dip))| {
                let mut rng = noise.particle(i);
                let zt = normal3(&mut rng);
                let zr = normal3(&mut rng);
                let (xi_t, xi_r) = friction.of(radius[i]);
                let drift = force[i] / xi_t;
                let dr = (drift * h + zt * (2.0 * kt * h / xi_t).sqrt()) * mobility[i];
                *pos += dr;
                *vel = drift * mobility[i];
                if turn && mobility[i] != DVec3::ZERO {
                    let spin = torque[i] / xi_r;
                    *omega = spin;
                    if *dip != DVec3::ZERO {
                        let dphi = spin * h + zr * (2.0 * kt * h / xi_r).sqrt();
                        *dip = rotate(*dip, dphi);
                    }
                }
            });
        sys.wrap_positions();
        sys.carried_acceleration.clear();
        sys.carried_angular_acceleration.clear();
        sys.time += h;
        sys.step += 1;
    }
}

#[inline]
fn normal3(rng: &mut Xoshiro256PlusPlus) -> DVec3 {
    DVec3::new(
        rng.sample(StandardNormal),
        rng.sample(StandardNormal),
        rng.sample(StandardNormal),
    )
}

/// The Langevin thermostat of inertial rotation, the rotational twin of
/// `Thermostat::Langevin`: an exact Ornstein–Uhlenbeck step
/// ω ← c ω + √((1 − c²) k_BT / I) ζ, c = e^{−γ_r Δt}, for every particle
/// that rotates (I > 0, not fixed). With γ_r = ξ_r / I it is the inertial
/// form of 004 Eq. 14, Θ ω̇ = N − ξ_r ω + N^B.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotationalLangevin {
    pub kt: f64,
    /// Rotational friction rate γ_r (per time).
    pub gamma: f64,
}

impl RotationalLangevin {
    /// Applies one step of length `dt` to the angular velocities.
    pub fn apply(&self, sys: &mut System, dt: f64, rng: &mut Xoshiro256PlusPlus) {
        let c = (-self.gamma * dt).exp();
        let p = &mut sys.particles;
        for i in 0..p.len() {
            let zeta = normal3(rng);
            if p.rotates(i) {
                let s = ((1.0 - c * c) * self.kt / p.inertia[i]).sqrt();
                p.angular_velocity[i] = p.angular_velocity[i] * c + zeta * s;
            }
        }
    }
}
