//! Cartesian multipole expansions of a cell's sources up to the quadrupole.
//!
//! Sources are point "charges" s (masses for gravity, charges for Coulomb)
//! and point dipoles μ. About a centre c, with offsets d = r − c, a cell has
//!
//! - monopole M = Σ s,
//! - dipole p = Σ s d + Σ μ,
//! - traceless quadrupole Q = Σ s (3 d dᵀ − d² 1) + Σ [3 (d μᵀ + μ dᵀ) − 2 (d·μ) 1],
//!
//! (Jackson, Classical Electrodynamics, 3rd ed., Eqs. 4.9–4.10, with the
//! displaced point dipole as the limit of two charges). At a point x with
//! R = x − c, r = |R|, the potential ψ(x) = Σ s/|x − r_j| + Σ μ·(x − r_j)/|x − r_j|³ is
//!
//! ψ = M/r + p·R/r³ + ½ RᵀQR/r⁵ + O(r⁻⁴),
//!
//! and its gradient (the gravitational field per unit G; minus the electric field)
//!
//! ∇ψ = −M R/r³ + p/r³ − 3 (p·R) R/r⁵ + Q R/r⁵ − (5/2)(RᵀQR) R/r⁷.
//!
//! Plummer softening replaces r² by r² + ε² throughout (exact for the
//! monopole, as REBOUND does for its quadrupole terms).

use glam::DVec3;

/// A cell's expansion: centre, monopole, dipole and traceless quadrupole.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Multipole {
    /// Expansion centre c.
    pub centre: DVec3,
    /// M = Σ s.
    pub monopole: f64,
    /// p = Σ s d + Σ μ.
    pub dipole: DVec3,
    /// Q as [xx, yy, zz, xy, xz, yz].
    pub quadrupole: [f64; 6],
}

impl Multipole {
    /// An empty expansion about `centre`.
    pub fn about(centre: DVec3) -> Self {
        Self {
            centre,
            ..Self::default()
        }
    }

    /// Adds a point source of strength `s` at `r`.
    #[inline]
    pub fn add_charge(&mut self, s: f64, r: DVec3) {
        let d = r - self.centre;
        let d2 = d.length_squared();
        self.monopole += s;
        self.dipole += s * d;
        let q = &mut self.quadrupole;
        q[0] += s * (3.0 * d.x * d.x - d2);
        q[1] += s * (3.0 * d.y * d.y - d2);
        q[2] += s * (3.0 * d.z * d.z - d2);
        q[3] += s * 3.0 * d.x * d.y;
        q[4] += s * 3.0 * d.x * d.z;
        q[5] += s * 3.0 * d.y * d.z;
    }

    /// Adds a point dipole of moment `mu` at `r`.
    #[inline]
    pub fn add_dipole(&mut self, mu: DVec3, r: DVec3) {
        let d = r - self.centre;
        let dm = d.dot(mu);
        self.dipole += mu;
        let q = &mut self.quadrupole;
        q[0] += 6.0 * d.x * mu.x - 2.0 * dm;
        q[1] += 6.0 * d.y * mu.y - 2.0 * dm;
        q[2] += 6.0 * d.z * mu.z - 2.0 * dm;
        q[3] += 3.0 * (d.x * mu.y + d.y * mu.x);
        q[4] += 3.0 * (d.x * mu.z + d.z * mu.x);
        q[5] += 3.0 * (d.y * mu.z + d.z * mu.y);
    }

    /// Q R.
    #[inline]
    pub fn quadrupole_times(&self, r: DVec3) -> DVec3 {
        let q = &self.quadrupole;
        DVec3::new(
            q[0] * r.x + q[3] * r.y + q[4] * r.z,
            q[3] * r.x + q[1] * r.y + q[5] * r.z,
            q[4] * r.x + q[5] * r.y + q[2] * r.z,
        )
    }

    /// Potential ψ and its gradient ∇ψ at `x` (module docs), softened by ε².
    #[inline]
    pub fn potential_and_gradient(&self, x: DVec3, eps2: f64) -> (f64, DVec3) {
        let r = x - self.centre;
        let r2 = r.length_squared() + eps2;
        let inv = 1.0 / r2.sqrt();
        let inv2 = inv * inv;
        let inv3 = inv * inv2;
        let inv5 = inv3 * inv2;
        let pr = self.dipole.dot(r);
        let qr = self.quadrupole_times(r);
        let rqr = r.dot(qr);
        let psi = self.monopole * inv + pr * inv3 + 0.5 * rqr * inv5;
        let grad = self.dipole * inv3 + qr * inv5
            - r * (self.monopole * inv3 + 3.0 * pr * inv5 + 2.5 * rqr * inv5 * inv2);
        (psi, grad)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Far from a cluster of charges and dipoles the expansion agrees with
    /// the exact potential to O((a/r)³) and its gradient with −E.
    #[test]
    fn expansion_converges_to_the_exact_potential() {
        let charges = [
            (1.0, DVec3::new(0.1, -0.2, 0.05)),
            (-0.7, DVec3::new(-0.15, 0.1, 0.2)),
            (0.4, DVec3::new(0.0, 0.12, -0.18)),
        ];
        let dipoles = [(DVec3::new(0.3, -0.1, 0.2), DVec3::new(0.05, 0.1, -0.1))];
        let mut m = Multipole::about(DVec3::new(0.01, 0.02, -0.01));
        for &(s, r) in &charges {
            m.add_charge(s, r);
        }
        for &(mu, r) in &dipoles {
            m.add_dipole(mu, r);
        }
        let exact = |x: DVec3| {
            let mut psi = 0.0;
            for &(s, r) in &charges {
                psi += s / (x - r).length();
            }
            for &(mu, r) in &dipoles {
                psi += mu.dot(x - r) / (x - r).length().powi(3);
            }
            psi
        };
        let dir = DVec3::new(0.6, -0.48, 0.64);
        let mut last = f64::INFINITY;
        for dist in [4.0, 8.0, 16.0, 32.0] {
            let x = dir * dist;
            let (psi, grad) = m.potential_and_gradient(x, 0.0);
            let err = (psi - exact(x)).abs();
            // Octupole remainder ∝ r⁻⁴: halving a/r cuts it by ~16.
            assert!(err < last / 10.0, "r = {dist}: {err:e} after {last:e}");
            last = err;
            let h = 1e-4 * dist;
            let fd = DVec3::new(
                exact(x + DVec3::X * h) - exact(x - DVec3::X * h),
                exact(x + DVec3::Y * h) - exact(x - DVec3::Y * h),
                exact(x + DVec3::Z * h) - exact(x - DVec3::Z * h),
            ) / (2.0 * h);
            assert!((grad - fd).length() < 2e-2 * fd.length() * (4.0 / dist).powi(2));
        }
        assert!(last < 1e-6, "{last:e}");
    }
}
