//! Mutze's Euclidean geometry (seed 000, "Modeling the dynamics of
//! irregularly shaped particles", the classes **E**, **dE** and **I**):
//!
//! - [`E`]: a placement, an element of the Euclidean group, stored as the
//!   rotation vector `r = n·tan(φ/2)` and the translation `a`;
//! - [`DE`]: an element of its Lie algebra — a velocity (ω, v), and with the
//!   same type a momentum (L, p) or a wrench (torque T, force F);
//! - [`Inertia`]: `I(I₁, I₂, I₃, a₁, a₂, a₃, μ)`, which turns a velocity into
//!   a momentum;
//! - [`exp`](DE::exp) and [`log`](E::log) between them;
//! - [`Point`], [`Vector`], [`AxialVector`]: the objects a placement acts on.
//!
//! Conventions (seed 000): placements act from the right, `y ∘ g`, so that
//! `(y ∘ g₁) ∘ g₂ = y ∘ (g₁ ∘ g₂)` — `g₁ ∘ g₂` means "first g₁, then g₂".
//! A point `y` is moved by `E(r, a)` to `y * r + a` where `y * r` is the
//! active rotation of `y` by the angle φ about n.
//!
//! Everything here is pure arithmetic on `glam::DVec3`: no allocation, no
//! state, `Copy` types. The one property the seed insists on holds by
//! construction: any product of any number of placements is again an exact
//! Euclidean transformation (the rotation formula is orthogonal for every
//! `r`), so rounding can never shear or scale a rigid body; it only moves it
//! by a slightly different Euclidean transformation.

// Unsafe code only where the lane layer meets the vector instructions
// (`lanes::gather`), each block with the reason it is sound.
#![deny(unsafe_code)]

pub mod grids;
mod inertia;
pub mod lanes;
mod objects;
mod placement;
mod rotation;
mod series;
pub mod simd;
mod velocity;

pub use glam::{DMat3, DVec3};
pub use inertia::Inertia;
pub use objects::{Act, AxialVector, Point, Vector};
pub use placement::E;
pub use rotation::{
    angle_of, compose_rotations, from_axis_angle, inverse_rotation, rotate, rotation_matrix,
    EPSILON,
};
pub use velocity::DE;
