//! The class **E** of seed 000: placements, elements of the Euclidean group.

use std::ops::Mul;

use glam::DVec3;

use crate::rotation::{compose_rotations, rotate, rotation_matrix};
use crate::series;
use crate::velocity::DE;

/// A placement `E(r, a)` (seed 000, "Modeling the Euclidean group as a class
/// E"): the minimal positive rotation about the origin by φ about n, stored
/// as the rotation vector `r = n·tan(φ/2)`, followed by the translation `a`.
/// A point y is moved to `y * r + a`.
///
/// The product `g₁ * g₂` (Rust's `Mul`) is the seed's `g₁ ∘ g₂`, "first g₁,
/// then g₂": `E(r₁, a₁) ∘ E(r₂, a₂) := E(r₁ ∘ r₂, a₁ * r₂ + a₂)`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct E {
    /// Rotation vector `n·tan(φ/2)`.
    pub r: DVec3,
    /// Translation.
    pub a: DVec3,
}

impl E {
    /// The unit element `E(0, 0)`.
    pub const IDENTITY: E = E {
        r: DVec3::ZERO,
        a: DVec3::ZERO,
    };

    #[inline]
    pub const fn new(r: DVec3, a: DVec3) -> E {
        E { r, a }
    }

    /// A pure rotation `E(r, 0)`.
    #[inline]
    pub const fn rotation(r: DVec3) -> E {
        E { r, a: DVec3::ZERO }
    }

    /// A pure translation `E(0, a)`.
    #[inline]
    pub const fn translation(a: DVec3) -> E {
        E { r: DVec3::ZERO, a }
    }

    /// The group product `self ∘ other` (first self, then other), seed 000:
    /// `E(r₁, a₁) ∘ E(r₂, a₂) := E(r₁ ∘ r₂, a₁ * r₂ + a₂)`.
    #[inline]
    pub fn compose(self, other: E) -> E {
        E {
            r: compose_rotations(self.r, other.r),
            a: rotate(self.a, other.r) + other.a,
        }
    }

    /// The inverse, seed 000: `E(r, a)⁻¹ = E(−r, −a * −r)`.
    #[inline]
    pub fn inverse(self) -> E {
        E {
            r: -self.r,
            a: -rotate(self.a, -self.r),
        }
    }

    /// The rotation angle φ = 2·atan|r| ∈ [0, π].
    #[inline]
    pub fn angle(self) -> f64 {
        crate::rotation::angle_of(self.r)
    }

    /// `Point(y) ∘ E(r, a) := Point(y * r + a)`.
    #[inline]
    pub fn apply_point(self, y: DVec3) -> DVec3 {
        rotate(y, self.r) + self.a
    }

    /// `Vector(y) ∘ E(r, a) := Vector(y * r)` (also for axial vectors).
    #[inline]
    pub fn apply_vector(self, y: DVec3) -> DVec3 {
        rotate(y, self.r)
    }

    /// The rotation matrix of this placement (`M y = y * r`).
    #[inline]
    pub fn matrix(self) -> glam::DMat3 {
        rotation_matrix(self.r)
    }

    /// The logarithm `log: E → dE` (seed 000, with its complex-number form):
    ///
    /// `log E(r, x) := dE(r̂·φ, x∥ + x⊥·Re z + r̂ × x⊥·Im z)`,
    /// `φ := 2 atan|r|`, `z := iφ / (exp(iφ) − 1)`.
    ///
    /// With `Re z = (φ/2)·cot(φ/2)`, `Im z = −φ/2` and `k := atan ρ / ρ`
    /// (ρ = |r|) this is `dE(2k·r, k·x + (1 − k)·x∥ − k·r × x)`, which is
    /// evaluated without any division by a small number: exact to a few ulps
    /// for ρ → 0 and for rotations near π (ρ → ∞). The result has
    /// |ω| = φ ≤ π, so `exp(log g) = g` for every g, while `log(exp h) = h`
    /// holds for |ω| < π.
    #[inline]
    pub fn log(self) -> DE {
        let (r, x) = (self.r, self.a);
        let rr = r.dot(r);
        let rho = rr.sqrt();
        if rho > 1e50 {
            // A rotation by π to within 1e-50: z = iπ/(−2), Re z = 0.
            let n = r / rho;
            let par = n * n.dot(x);
            return DE::new(n * std::f64::consts::PI, par);
        }
        let k = series::atan_over(rho);
        let c = series::one_minus_atan_over_sq(rho); // (1 − k)/ρ²
        DE::new(2.0 * k * r, k * x + c * r.dot(x) * r - k * r.cross(x))
    }
}

impl Mul for E {
    type Output = E;
    /// `g₁ * g₂` is the seed's `g₁ ∘ g₂` (first g₁, then g₂).
    #[inline]
    fn mul(self, rhs: E) -> E {
        self.compose(rhs)
    }
}
