//! The class **dE** of seed 000: the Lie algebra of the Euclidean group —
//! velocities, and with the same type momenta and wrenches.

use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

use glam::DVec3;

use crate::placement::E;
use crate::rotation::rotate;
use crate::series;

/// `dE(ω, v)` (seed 000, "Describing velocity"). As a velocity: the angular
/// velocity ω and the translational velocity v of the velocity field
/// `y ↦ v + ω × y` (a body velocity is taken about its centre of mass). The
/// seed uses the same type for pairs (torque T, force F) and
/// (angular momentum L, linear momentum p); the first slot is always the
/// axial vector.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct DE {
    /// Angular part: ω, torque or angular momentum (an axial vector).
    pub omega: DVec3,
    /// Linear part: v, force or linear momentum (a vector).
    pub v: DVec3,
}

impl DE {
    pub const ZERO: DE = DE {
        omega: DVec3::ZERO,
        v: DVec3::ZERO,
    };

    #[inline]
    pub const fn new(omega: DVec3, v: DVec3) -> DE {
        DE { omega, v }
    }

    /// The Lie product (seed 000, corrected version):
    /// `dE(ω₁, v₁) × dE(ω₂, v₂) := dE(ω₁ × ω₂, ω₁ × v₂ − ω₂ × v₁)`,
    /// the commutator of the 4×4 matrices `[[ω×, v], [0, 0]]`.
    #[inline]
    pub fn bracket(self, other: DE) -> DE {
        DE {
            omega: self.omega.cross(other.omega),
            v: self.omega.cross(other.v) - other.omega.cross(self.v),
        }
    }

    /// The action of a placement on a velocity, `h ∘ E(r, a)`: the velocity
    /// field carried along by the placement (the adjoint action),
    /// `dE(ω * r, v * r + a × (ω * r))`.
    ///
    /// It satisfies `exp(h ∘ g) = g⁻¹ ∘ exp(h) ∘ g` and
    /// `(h ∘ g₁) ∘ g₂ = h ∘ (g₁ ∘ g₂)` (both property-tested). The seed prints
    /// the last term as `(ω * r) × a`; with the seed's own definitions of
    /// `x * r`, the point action and exp, that sign moves a rotation about
    /// the origin to a rotation about −a instead of a, so we use the sign
    /// that makes the identity above hold.
    #[inline]
    pub fn act(self, g: E) -> DE {
        let w = rotate(self.omega, g.r);
        DE {
            omega: w,
            v: rotate(self.v, g.r) + g.a.cross(w),
        }
    }

    /// The action of a placement on a momentum or wrench `dE(L, p)` (L about
    /// the origin): `dE(L * r + a × (p * r), p * r)` (the co-adjoint action;
    /// a force p applied at the moved origin has moment a × p).
    #[inline]
    pub fn act_momentum(self, g: E) -> DE {
        let p = rotate(self.v, g.r);
        DE {
            omega: rotate(self.omega, g.r) + g.a.cross(p),
            v: p,
        }
    }

    /// The exponential `exp(dE(ω, v)·τ)` (seed 000, complex-number form):
    ///
    /// `E(ω̂·tan(φ/2), v∥τ + v⊥τ·Re z + ω̂ × v⊥τ·Im z)`,
    /// `φ := |ω|τ`, `z := (exp(iφ) − 1)/(iφ)`, so `Re z = sin φ/φ` and
    /// `Im z = (1 − cos φ)/φ`. This is the flow of the field `v + ω × y` for
    /// the time τ (a screw motion). Evaluated as
    /// `vτ·sinc φ + w(w·vτ)(1 − sinc φ)/φ² + (w × vτ)(1 − cos φ)/φ²` with
    /// `w = ωτ`, each factor by series near 0: accurate for small and large
    /// angles. A rotation by φ > π comes out as the rotation by 2π − φ about
    /// −ω̂, as it must.
    #[inline]
    pub fn exp(self, tau: f64) -> E {
        let w = self.omega * tau;
        let vt = self.v * tau;
        let phi = w.length();
        E {
            r: w * series::half_tan_over(phi),
            a: vt * series::sinc(phi)
                + w * (w.dot(vt) * series::one_minus_sinc_over_sq(phi))
                + w.cross(vt) * series::one_minus_cos_over_sq(phi),
        }
    }

    /// The rotation vector of `exp(dE(ω, ·)·τ)`: `ω̂·tan(|ω|τ/2)`.
    #[inline]
    pub fn exp_rotation(omega: DVec3, tau: f64) -> DVec3 {
        let w = omega * tau;
        w * series::half_tan_over(w.length())
    }

    /// The pairing ⟨momentum, velocity⟩ = L·ω + p·v (twice a kinetic energy,
    /// or a power when `self` is a wrench).
    #[inline]
    pub fn pair(self, velocity: DE) -> f64 {
        self.omega.dot(velocity.omega) + self.v.dot(velocity.v)
    }
}

impl Add for DE {
    type Output = DE;
    /// `dE(ω₁, v₁) + dE(ω₂, v₂) := dE(ω₁ + ω₂, v₁ + v₂)`.
    #[inline]
    fn add(self, o: DE) -> DE {
        DE::new(self.omega + o.omega, self.v + o.v)
    }
}

impl AddAssign for DE {
    #[inline]
    fn add_assign(&mut self, o: DE) {
        self.omega += o.omega;
        self.v += o.v;
    }
}

impl Sub for DE {
    type Output = DE;
    #[inline]
    fn sub(self, o: DE) -> DE {
        DE::new(self.omega - o.omega, self.v - o.v)
    }
}

impl SubAssign for DE {
    #[inline]
    fn sub_assign(&mut self, o: DE) {
        self.omega -= o.omega;
        self.v -= o.v;
    }
}

impl Neg for DE {
    type Output = DE;
    #[inline]
    fn neg(self) -> DE {
        DE::new(-self.omega, -self.v)
    }
}

impl Mul<f64> for DE {
    type Output = DE;
    /// `dE(ω, v)·α := dE(ω·α, v·α)`.
    #[inline]
    fn mul(self, alpha: f64) -> DE {
        DE::new(self.omega * alpha, self.v * alpha)
    }
}
