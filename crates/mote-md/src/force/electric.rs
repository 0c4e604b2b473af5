//! Point charges in open space and in an applied electric field.
//!
//! Coulomb's law with optional softening ε, summed over every pair:
//!
//! F_i = k q_i Σ_{j≠i} q_j (r_i − r_j) / (|r_i − r_j|² + ε²)^{3/2},
//! U = k Σ_{i<j} q_i q_j / (|r_i − r_j|² + ε²)^{1/2},
//!
//! with k = 1/(4πε₀) of the unit system. The pair sum is gravity's tiled
//! kernel ([`DirectGravity`]) with charges as source strengths: each pair
//! once, AVX-512 where the CPU has it, the same bits for every thread count.
//!
//! An applied field E(t) = E₀ cos(ωt + φ) (constant for ω = 0) pushes each
//! charge with F_i = q_i E(t); its potential energy U = −Σ q_i E(t)·r_i is
//! defined only where the field's direction is not periodic.
//!
//! Both read the charges from the step's [`State`], as the system holds them.

use glam::DVec3;

use super::whole::Whole;
use super::{DirectGravity, Interaction, State, ViewerHooks, Virial};

/// Coulomb's law between all pairs of charges, in open space.
#[derive(Debug, Clone)]
pub struct DirectCoulomb {
    /// Coulomb's constant k = 1/(4πε₀).
    pub k: f64,
    kernel: DirectGravity,
    field: Vec<DVec3>,
}

impl DirectCoulomb {
    pub fn new(k: f64, softening: f64) -> Self {
        Self {
            k,
            kernel: DirectGravity::new(1.0, softening),
            field: Vec::new(),
        }
    }

    /// The softening length ε.
    pub fn softening(&self) -> f64 {
        self.kernel.softening
    }
}

impl Interaction for DirectCoulomb {
    fn name(&self) -> &'static str {
        "coulomb"
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        // The kernel gives Σ_j q_j (r_j − r_i)/r³: like charges repel.
        let charge = state.charges();
        self.field.clear();
        self.field.resize(state.position.len(), DVec3::ZERO);
        match Whole::charges(state) {
            Whole {
                position,
                value,
                rows: Some((rows, _)),
            } => self
                .kernel
                .inverse_square_rows(&position, &value, &rows, &mut self.field),
            _ => self
                .kernel
                .inverse_square_field(state.position, charge, &mut self.field),
        }
        for ((f, e), q) in force.iter_mut().zip(&self.field).zip(charge) {
            *f -= *e * (self.k * q);
        }
    }

    /// U = (k/2) Σ_i q_i Σ_{j≠i} q_j / r_ij (on ranks, each rank's share:
    /// the sum over its own charges).
    fn potential_energy(&mut self, state: &State) -> f64 {
        let sum = match Whole::charges(state) {
            Whole {
                position,
                value,
                rows: Some((rows, _)),
            } => self.kernel.pair_potential_rows(&position, &value, &rows),
            _ => self
                .kernel
                .pair_potential_sum(state.position, state.charges()),
        };
        0.5 * self.k * sum
    }

    /// Decomposed as [`DirectGravity`]: all charges gathered in id order,
    /// each rank's rows against all.
    fn halo_reach(&self) -> Option<super::HaloReach> {
        Some(super::HaloReach::NONE)
    }
}

/// A uniform electric field E(t) = E₀ cos(ωt + φ) acting on the charges.
#[derive(Debug, Clone)]
pub struct ElectricField {
    /// Amplitude E₀ (the constant field when ω = 0 and φ = 0).
    pub amplitude: DVec3,
    /// Angular frequency ω (0: constant).
    pub angular_frequency: f64,
    /// Phase φ.
    pub phase: f64,
}

impl ElectricField {
    /// E at time t.
    pub fn at(&self, t: f64) -> DVec3 {
        if self.angular_frequency == 0.0 && self.phase == 0.0 {
            self.amplitude
        } else {
            self.amplitude * (self.angular_frequency * t + self.phase).cos()
        }
    }
}

impl Interaction for ElectricField {
    fn viewer(&self) -> Option<&dyn ViewerHooks> {
        Some(self)
    }

    fn viewer_mut(&mut self) -> Option<&mut dyn ViewerHooks> {
        Some(self)
    }

    /// Not part of the pressure (see [`Interaction::virial`]).
    fn virial(&self) -> Option<f64> {
        Some(0.0)
    }

    fn virial_tensor(&mut self, _: &State) -> Option<Virial> {
        Some(Virial::default())
    }

    fn name(&self) -> &'static str {
        "electric_field"
    }

    /// A force on each charge alone.
    fn halo_reach(&self) -> Option<super::HaloReach> {
        Some(super::HaloReach::NONE)
    }

    fn add_forces(&mut self, state: &State, force: &mut [DVec3]) {
        let e = self.at(state.step.time);
        for (f, q) in force.iter_mut().zip(state.charges()) {
            *f += e * *q;
        }
    }

    /// −Σ q E·r, or 0 where the box is periodic along the field (there the
    /// potential is not defined).
    fn potential_energy(&mut self, state: &State) -> f64 {
        let e = self.at(state.step.time);
        if (0..3).any(|a| state.boundary.periodic[a] && self.amplitude[a] != 0.0) {
            return 0.0;
        }
        -state
            .position
            .iter()
            .zip(state.charges())
            .map(|(r, q)| q * e.dot(*r))
            .sum::<f64>()
    }
}

impl ViewerHooks for ElectricField {
    fn steer(&mut self, change: &mote_run::Change) -> Option<Result<String, String>> {
        let mote_run::Change::Field {
            kind: mote_run::FieldKind::Electric,
            value,
        } = change
        else {
            return None;
        };
        if self.angular_frequency != 0.0 {
            return Some(Err(format!(
                "the electric field oscillates (ω = {}): only a constant one can be set",
                self.angular_frequency
            )));
        }
        let e = DVec3::from(*value);
        let text = format!(
            "electric field E {} → {}",
            super::vector_text(self.at(0.0)),
            super::vector_text(e)
        );
        self.amplitude = e;
        self.phase = 0.0;
        Some(Ok(text))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state<'a>(
        pos: &'a [DVec3],
        vel: &'a [DVec3],
        mass: &'a [f64],
        charge: &'a [f64],
    ) -> State<'a> {
        State::new(pos, vel, mass, 0.0).with_charges(charge)
    }

    /// Two charges: F = k q₁ q₂ / r² along the line, repulsive for like
    /// charges, attractive for unlike ones; U = k q₁ q₂ / r.
    #[test]
    fn two_charges_follow_coulombs_law() {
        let pos = [DVec3::new(0.5, -1.0, 2.0), DVec3::new(0.5, 2.0, 2.0)];
        let (vel, mass) = ([DVec3::ZERO; 2], [1.0; 2]);
        for (q1, q2) in [(2.0, 3.0), (2.0, -3.0)] {
            let q = [q1, q2];
            let mut c = DirectCoulomb::new(0.7, 0.0);
            let mut f = [DVec3::ZERO; 2];
            c.add_forces(&state(&pos, &vel, &mass, &q), &mut f);
            let magnitude = 0.7 * q1 * q2 / 9.0;
            assert!((f[0].y + magnitude).abs() < 1e-15 * magnitude.abs());
            assert!((f[1].y - magnitude).abs() < 1e-15 * magnitude.abs());
            assert_eq!(f[0].x, 0.0);
            let u = c.potential_energy(&state(&pos, &vel, &mass, &q));
            assert!((u - 0.7 * q1 * q2 / 3.0).abs() < 1e-15);
        }
    }

    /// Forces are −∇U: central differences of the energy of a random
    /// neutral cloud agree with the forces.
    #[test]
    fn forces_are_minus_the_gradient_of_the_energy() {
        let n = 40;
        let pos: Vec<DVec3> = (0..n)
            .map(|k| {
                let t = k as f64;
                DVec3::new((1.3 * t).sin(), (0.7 * t).cos(), (2.9 * t).sin()) * 3.0
            })
            .collect();
        let charge: Vec<f64> = (0..n)
            .map(|k| if k % 2 == 0 { 1.5 } else { -1.5 })
            .collect();
        let (vel, mass) = (vec![DVec3::ZERO; n], vec![1.0; n]);
        let mut c = DirectCoulomb::new(1.0, 0.05);
        let mut f = vec![DVec3::ZERO; n];
        c.add_forces(&state(&pos, &vel, &mass, &charge), &mut f);
        let h = 1e-6;
        for i in [0, 7, 33] {
            for a in 0..3 {
                let mut p = pos.clone();
                p[i][a] += h;
                let up = c.potential_energy(&state(&p, &vel, &mass, &charge));
                p[i][a] -= 2.0 * h;
                let down = c.potential_energy(&state(&p, &vel, &mass, &charge));
                let numeric = -(up - down) / (2.0 * h);
                assert!(
                    (numeric - f[i][a]).abs() < 1e-6 * f[i].length().max(1.0),
                    "particle {i} axis {a}: {numeric} vs {}",
                    f[i][a]
                );
            }
        }
    }

    #[test]
    fn an_oscillating_field_pushes_with_q_e_cos() {
        let mut e = ElectricField {
            amplitude: DVec3::new(0.0, 2.0, 0.0),
            angular_frequency: 3.0,
            phase: 0.25,
        };
        let pos = [DVec3::new(1.0, 4.0, 0.0)];
        let (vel, mass) = ([DVec3::ZERO], [1.0]);
        let mut s = state(&pos, &vel, &mass, &[-0.5]);
        s.step.time = 0.4;
        let mut f = [DVec3::ZERO];
        e.add_forces(&s, &mut f);
        let c = (3.0f64 * 0.4 + 0.25).cos();
        assert_eq!(f[0], DVec3::new(0.0, -0.5 * 2.0 * c, 0.0));
        assert!((e.potential_energy(&s) - 0.5 * 2.0 * c * 4.0).abs() < 1e-15);
        // Periodic along the field: no potential.
        let periodic = crate::boundary::Boundary::periodic(DVec3::ZERO, DVec3::splat(10.0));
        assert_eq!(e.potential_energy(&s.in_box(&periodic)), 0.0);
    }
}
