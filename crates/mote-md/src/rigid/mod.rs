//! Rigid bodies made of overlapping spheres, moved by Mutze's Fast Rigid
//! Bodies Integrator (seed 000, "Modeling the dynamics of irregularly shaped
//! particles").
//!
//! - [`template`]: a union of spheres with material, charge and dipole
//!   ([`ClumpSpec`]) becomes a shared [`BodyTemplate`] with mass properties
//!   by randomised quasi-Monte Carlo integration (with error estimates);
//! - [`shapes`]: dumbbells, trimers, random irregular clumps;
//! - [`bodies`]: the state — placements `E(r, x)` and velocities `dE(ω, v)`
//!   as a structure of arrays — and its observables;
//! - [`interaction`]: the [`BodyInteraction`] trait and the world-frame view
//!   of spheres and dipoles it reads (where contact models plug in);
//! - [`sources`]: fields, gravity, drag, Coulomb between conducting planes,
//!   the latent image;
//! - [`centres`]: point-particle interactions between the bodies' centres
//!   (Coulomb and dipole–dipole in open space: the point particles' kernels);
//! - [`magnet`]: the magnetic roller and the moments it induces;
//! - [`contacts`]: Hertz–Mindlin contacts between spheres of different
//!   bodies and with walls;
//! - [`scene`]: the `[rigid]` scene format;
//! - [`flow`]: clumps inserted into regions and taken out at outlets;
//! - [`run`]: the FRBI as a propagator of the one loop, its observers and checkpoints;
//! - [`frbi`]: `freeStep`, `react` and the many-body step.
//!
//! The algebra (E, dE, I, exp, log) is the crate `mote-geom`.

pub mod bodies;
pub mod centres;
pub mod contacts;
pub mod flow;
pub mod frbi;
mod free8;
pub mod from_file;
pub mod interaction;
pub mod magnet;
pub mod run;
pub mod scene;
pub mod shapes;
pub mod sources;
pub mod template;

pub use bodies::{BodyObservables, RigidBodies};
pub use centres::{AtCentres, Coulomb, DipoleDipole};
pub use contacts::RigidContacts;
pub use frbi::{free_step, react, BodyEnergies, Frbi, FreeFlight, SpinUpdate};
pub use interaction::{BodyInteraction, BodyView, WorldFrame};
pub use shapes::{dumbbell, linear_trimer, IrregularClump};
pub use sources::{AirDrag, ExternalFields, Field, Gravity};
pub use template::{
    mass_properties, principal, BodyTemplate, ClumpSpec, Integration, MassErrors, MassProperties,
    TemplateError,
};
