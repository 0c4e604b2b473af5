//! Rotation vectors `r = n·tan(φ/2)` (seed 000, class **E**): their product
//! `r₁ ∘ r₂` and their action `x * r` on vectors.

use glam::{DMat3, DVec3};

/// The seed's ε: when `1 − r₁·r₂` is smaller than ε in magnitude the product
/// is a rotation by (almost exactly) π and the division uses 1/ε instead
/// (seed 000: "a fixed small number for which I use ε = 10⁻¹²").
pub const EPSILON: f64 = 1e-12;

/// The product of rotation vectors, "first r₁, then r₂" (seed 000):
///
/// `s := 1 − r₁·r₂`, `S := 1/ε if |s| < ε else 1/s`,
/// `r₁ ∘ r₂ := (r₁ + r₂ − r₁ × r₂)·S`.
///
/// It is the quaternion product `(1, r₂)(1, r₁)` divided by its scalar part,
/// so `x * (r₁ ∘ r₂) = (x * r₁) * r₂` for every x.
#[inline]
pub fn compose_rotations(r1: DVec3, r2: DVec3) -> DVec3 {
    let s = 1.0 - r1.dot(r2);
    let big_s = if s.abs() < EPSILON {
        1.0 / EPSILON
    } else {
        1.0 / s
    };
    (r1 + r2 - r1.cross(r2)) * big_s
}

/// The inverse rotation vector, `−r`.
#[inline]
pub fn inverse_rotation(r: DVec3) -> DVec3 {
    -r
}

/// The action of a rotation vector on a vector, postfix `x * r` (seed 000):
///
/// `x * r := (x(1 − r·r) + 2(x·r)r − 2 x × r) / (1 + r·r)`,
///
/// the active rotation of x by φ = 2·atan|r| about r/|r|
/// (`x * r = x + 2 r × x + O(|r|²)`). The formula is orthogonal for every
/// r, however large (rotations near π have |r| → ∞).
#[inline]
pub fn rotate(x: DVec3, r: DVec3) -> DVec3 {
    let rr = r.dot(r);
    if rr > 1e100 {
        // |r| beyond 1e50: a rotation by π to within 1e-50 rad; avoid
        // overflow of rr² by working with the unit axis.
        let n = r / rr.sqrt();
        return 2.0 * x.dot(n) * n - x;
    }
    (x * (1.0 - rr) + 2.0 * x.dot(r) * r - 2.0 * x.cross(r)) / (1.0 + rr)
}

/// The rotation vector of the rotation by `angle` (radians) about the unit
/// vector `axis`: `axis·tan(angle/2)`.
#[inline]
pub fn from_axis_angle(axis: DVec3, angle: f64) -> DVec3 {
    axis * (0.5 * angle).tan()
}

/// The rotation angle φ = 2·atan|r| ∈ [0, π] of a rotation vector.
#[inline]
pub fn angle_of(r: DVec3) -> f64 {
    2.0 * r.length().atan()
}

/// The matrix M with `M x = x * r` for all x (for applying one rotation to
/// many vectors, e.g. all sphere centres of a body).
#[inline]
pub fn rotation_matrix(r: DVec3) -> DMat3 {
    DMat3::from_cols(
        rotate(DVec3::X, r),
        rotate(DVec3::Y, r),
        rotate(DVec3::Z, r),
    )
}
