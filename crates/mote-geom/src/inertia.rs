//! The class **I** of seed 000: inertia, the map from velocity to momentum.

use std::ops::Mul;

use glam::DVec3;

use crate::placement::E;
use crate::rotation::rotate;
use crate::velocity::DE;

/// `I(I₁, I₂, I₃, a₁, a₂, a₃, μ)` (seed 000, "Describing inertia"): principal
/// moments `moments[k]` about the unit axes `axes[k]` (through the centre of
/// mass), and the mass μ (or their inverses, see [`Inertia::inverse`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertia {
    pub moments: [f64; 3],
    pub axes: [DVec3; 3],
    pub mass: f64,
}

impl Inertia {
    #[inline]
    pub const fn new(moments: [f64; 3], axes: [DVec3; 3], mass: f64) -> Inertia {
        Inertia {
            moments,
            axes,
            mass,
        }
    }

    /// `I⁻¹ := I(1/I₁, 1/I₂, 1/I₃, a₁, a₂, a₃, 1/μ)`.
    #[inline]
    pub fn inverse(self) -> Inertia {
        Inertia {
            moments: self.moments.map(|m| 1.0 / m),
            axes: self.axes,
            mass: 1.0 / self.mass,
        }
    }

    /// `I ∘ E(r, x) := I(I₁, I₂, I₃, a₁ * r, a₂ * r, a₃ * r, μ)`.
    #[inline]
    pub fn act(self, g: E) -> Inertia {
        self.rotated(g.r)
    }

    /// `I ∘ E(r, ·)`: the axes rotated by the rotation vector r.
    #[inline]
    pub fn rotated(self, r: DVec3) -> Inertia {
        Inertia {
            moments: self.moments,
            axes: self.axes.map(|a| rotate(a, r)),
            mass: self.mass,
        }
    }

    /// The angular part of `I * dE(ω, ·)`: `Σ aₖ·Iₖ·(ω·aₖ)`.
    #[inline]
    pub fn angular(&self, omega: DVec3) -> DVec3 {
        self.axes[0] * (self.moments[0] * omega.dot(self.axes[0]))
            + self.axes[1] * (self.moments[1] * omega.dot(self.axes[1]))
            + self.axes[2] * (self.moments[2] * omega.dot(self.axes[2]))
    }

    /// `½ h·(I * h)`: the kinetic energy of the velocity h.
    #[inline]
    pub fn kinetic_energy(&self, h: DE) -> f64 {
        0.5 * (*self * h).pair(h)
    }
}

impl Mul<DE> for Inertia {
    type Output = DE;
    /// Momentum from velocity (seed 000):
    /// `I * dE(ω, v) := dE(Σ aₖ·Iₖ·(ω·aₖ), v·μ)`.
    #[inline]
    fn mul(self, h: DE) -> DE {
        DE::new(self.angular(h.omega), h.v * self.mass)
    }
}
