//! Plummer spheres sampled as in Aarseth, Hénon & Wielen (1974), A&A 37, 183:
//! the density ρ(r) = (3M/4πa³)(1 + r²/a²)^{−5/2} has the cumulative mass
//! M(r)/M = r³/(r² + a²)^{3/2}, inverted as r = a (X^{−2/3} − 1)^{−1/2} for
//! uniform X; speeds are q v_esc(r), v_esc = √(2GM) (r² + a²)^{−1/4}, with q
//! drawn from g(q) ∝ q² (1 − q²)^{7/2} by von Neumann rejection; positions
//! and velocities are isotropic. The sample is shifted to its centre of mass
//! and momentum. Exact totals: U = −3πGM²/(32a), K = −U/2, half-mass
//! radius a/√(2^{2/3} − 1) ≈ 1.305 a.

use glam::DVec3;
use rand::Rng;

use crate::particles::ParticleInit;

/// A Plummer sphere of N equal masses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlummerSphere {
    pub n: usize,
    /// Total mass M.
    pub mass: f64,
    /// Plummer radius a.
    pub radius: f64,
    /// Newton's constant G.
    pub g: f64,
    /// Radii beyond this are drawn again (AHW 1974 cut at 10a in their
    /// example; `None` keeps the full, infinite model).
    pub max_radius: Option<f64>,
}

impl PlummerSphere {
    /// N bodies in Hénon's standard units: G = M = 1, a = 3π/16, so that
    /// the total energy is −1/4 and the virial radius 1.
    pub fn henon(n: usize) -> Self {
        Self {
            n,
            mass: 1.0,
            radius: 3.0 * std::f64::consts::PI / 16.0,
            g: 1.0,
            max_radius: None,
        }
    }

    /// Potential energy of the smooth model, −3πGM²/(32a).
    pub fn potential_energy(&self) -> f64 {
        -3.0 * std::f64::consts::PI * self.g * self.mass * self.mass / (32.0 * self.radius)
    }

    /// Positions and velocities (centre-of-mass frame), masses M/N each.
    pub fn sample(&self, rng: &mut impl Rng) -> (Vec<DVec3>, Vec<DVec3>) {
        let mut pos = Vec::with_capacity(self.n);
        let mut vel = Vec::with_capacity(self.n);
        let v_scale = (self.g * self.mass / self.radius).sqrt();
        let max = self.max_radius.map(|r| r / self.radius);
        for _ in 0..self.n {
            let r = loop {
                let x: f64 = rng.gen();
                if x <= 0.0 {
                    continue;
                }
                let r = 1.0 / (x.powf(-2.0 / 3.0) - 1.0).sqrt();
                if r.is_finite() && max.is_none_or(|m| r <= m) {
                    break r;
                }
            };
            let q = loop {
                let q: f64 = rng.gen();
                let y: f64 = 0.1 * rng.gen::<f64>();
                if y < q * q * (1.0 - q * q).powf(3.5) {
                    break q;
                }
            };
            let v = q * 2f64.sqrt() * (1.0 + r * r).powf(-0.25);
            pos.push(isotropic(rng) * (r * self.radius));
            vel.push(isotropic(rng) * (v * v_scale));
        }
        let n = self.n.max(1) as f64;
        let com = pos.iter().copied().sum::<DVec3>() / n;
        let cov = vel.iter().copied().sum::<DVec3>() / n;
        pos.iter_mut().for_each(|r| *r -= com);
        vel.iter_mut().for_each(|v| *v -= cov);
        (pos, vel)
    }

    /// The sample as particles (mass M/N; other fields from `template`).
    pub fn particles(&self, template: &ParticleInit, rng: &mut impl Rng) -> Vec<ParticleInit> {
        let (pos, vel) = self.sample(rng);
        let m = self.mass / self.n as f64;
        pos.into_iter()
            .zip(vel)
            .map(|(position, velocity)| ParticleInit {
                position,
                velocity: template.velocity + velocity,
                mass: m,
                ..template.clone()
            })
            .collect()
    }
}

/// A uniformly random unit vector (cos θ uniform in [−1, 1], φ in [0, 2π)).
fn isotropic(rng: &mut impl Rng) -> DVec3 {
    let z: f64 = 2.0 * rng.gen::<f64>() - 1.0;
    let phi = 2.0 * std::f64::consts::PI * rng.gen::<f64>();
    let s = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), z)
}
