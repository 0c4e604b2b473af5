//! The virial tensor of a force evaluation, for the pressure tensor of a
//! periodic system (Allen & Tildesley, 2nd ed., Eq. 2.184):
//!
//! P_αβ V = Σ_i m_i v_iα v_iβ + W_αβ,   W_αβ = Σ_pairs r_ij,α F_ij,β,
//!
//! with r_ij = r_i − r_j and F_ij the force on i from j. For central pair
//! forces W is symmetric; for contacts with tangential forces it need not
//! be, and, as LAMMPS's `compute pressure` does, the off-diagonal entries
//! kept are W_xy, W_xz and W_yz (r_α F_β with α before β). The scalar
//! virial is the trace, W = Σ r_ij · F_ij, and P = (2K + W)/(3V).

use glam::DVec3;

/// W_αβ stored as [xx, yy, zz, xy, xz, yz] (LAMMPS's order).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Virial(pub [f64; 6]);

impl Virial {
    /// The names of the six entries, in their order.
    pub const AXES: [&'static str; 6] = ["xx", "yy", "zz", "xy", "xz", "yz"];

    /// The contribution r ⊗ F of one pair (r = r_i − r_j, F the force on i).
    #[inline]
    pub fn pair(r: DVec3, f: DVec3) -> Self {
        Self([
            r.x * f.x,
            r.y * f.y,
            r.z * f.z,
            r.x * f.y,
            r.x * f.z,
            r.y * f.z,
        ])
    }

    /// s · r ⊗ r, the contribution of a central force F = s r.
    #[inline]
    pub fn central(r: DVec3, s: f64) -> Self {
        Self::pair(r, r * s)
    }

    /// c times the unit tensor.
    pub fn isotropic(c: f64) -> Self {
        Self([c, c, c, 0.0, 0.0, 0.0])
    }

    /// The scalar virial W = tr W.
    pub fn trace(&self) -> f64 {
        self.0[0] + self.0[1] + self.0[2]
    }

    pub fn scaled(self, s: f64) -> Self {
        Self(self.0.map(|w| w * s))
    }
}

impl std::ops::AddAssign for Virial {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        for (a, b) in self.0.iter_mut().zip(o.0) {
            *a += b;
        }
    }
}

impl std::ops::Add for Virial {
    type Output = Self;
    #[inline]
    fn add(mut self, o: Self) -> Self {
        self += o;
        self
    }
}

impl std::iter::Sum for Virial {
    fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
        iter.fold(Self::default(), |a, b| a + b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_trace_is_the_dot_product() {
        let (r, f) = (DVec3::new(1.0, -2.0, 0.5), DVec3::new(0.3, 4.0, -1.0));
        assert!((Virial::pair(r, f).trace() - r.dot(f)).abs() < 1e-15);
        let c = Virial::central(r, 2.0);
        assert_eq!(c.0[3], 2.0 * r.x * r.y);
        assert_eq!(c.trace(), 2.0 * r.length_squared());
    }
}
