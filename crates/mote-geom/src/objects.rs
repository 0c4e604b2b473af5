//! The geometric objects a placement acts on (seed 000, "The class E as a
//! nucleus of Euclidean geometry"): a type is a concept of Euclidean
//! geometry iff `(y ∘ g₁) ∘ g₂ = y ∘ (g₁ ∘ g₂)`.

use glam::DVec3;

use crate::inertia::Inertia;
use crate::placement::E;
use crate::rotation::rotate;
use crate::velocity::DE;

/// The right action `y ∘ g` of placements on a geometric object.
pub trait Act: Sized {
    fn act(self, g: E) -> Self;
}

/// A point: `Point(y) ∘ E(r, x) := Point(y * r + x)`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Point(pub DVec3);

/// A (polar) vector: `Vector(y) ∘ E(r, x) := Vector(y * r)`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Vector(pub DVec3);

/// An axial vector (angular velocity, torque, magnetic moment):
/// `AxialVector(y) ∘ E(r, x) := AxialVector(y * r)` — under proper motions
/// it transforms as a vector; the difference would show only under
/// reflections, which E does not contain.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct AxialVector(pub DVec3);

impl Act for Point {
    #[inline]
    fn act(self, g: E) -> Point {
        Point(rotate(self.0, g.r) + g.a)
    }
}

impl Act for Vector {
    #[inline]
    fn act(self, g: E) -> Vector {
        Vector(rotate(self.0, g.r))
    }
}

impl Act for AxialVector {
    #[inline]
    fn act(self, g: E) -> AxialVector {
        AxialVector(rotate(self.0, g.r))
    }
}

impl Act for E {
    /// `g ∘ E`: a placement acts on placements by the group product.
    #[inline]
    fn act(self, g: E) -> E {
        self.compose(g)
    }
}

impl Act for DE {
    /// The adjoint action on velocities, see [`DE::act`].
    #[inline]
    fn act(self, g: E) -> DE {
        DE::act(self, g)
    }
}

impl Act for Inertia {
    #[inline]
    fn act(self, g: E) -> Inertia {
        Inertia::act(self, g)
    }
}

impl Point {
    /// The vector from `other` to `self`, `self − other`.
    #[inline]
    pub fn minus(self, other: Point) -> Vector {
        Vector(self.0 - other.0)
    }
}
