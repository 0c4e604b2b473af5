//! Time-stepped particle dynamics.
//!
//! A [`System`] holds the state (particles as a structure of arrays, the
//! time); a [`ForceField`] is a list of [`Interaction`]s that add forces; an
//! [`Integrator`] advances the state with a fixed time step; [`Simulation`]
//! is the single run loop, which hands the state to [`Observer`](mote_run::Observer)s on their
//! schedule. Settings come from a TOML [`scene`] or an MPPphys particle file.

#![allow(clippy::needless_range_loop)] // index loops over parallel arrays read best in numerical code

pub mod boundary;
pub mod brownian;
pub mod domain;
pub mod eos;
pub mod error;
pub mod flow;
pub mod force;
pub mod init;
pub mod integrate;
pub mod magnetic;
pub mod neighbor;
pub mod observe;
pub mod order;
pub mod output;
pub mod particles;
pub mod rigid;
pub mod scene;
pub mod simulation;
pub mod soft_pack;
pub mod thermostat;
pub mod tree;
pub mod units;
pub mod viewer;

pub use boundary::Boundary;
pub use error::MdError;
pub use force::{ForceField, Interaction, State};
pub use integrate::{Integrator, Stepper};
pub use observe::Observables;
pub use particles::{Particles, System};
pub use simulation::{RunLength, RunReport, Simulation};
pub use units::UnitSystem;

pub use glam::DVec3;
