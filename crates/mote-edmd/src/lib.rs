//! Event-driven molecular dynamics of hard spheres (D = 3) and disks (D = 2).
//!
//! One source for both dimensions: [`System<D>`] holds particles with their
//! own radius and mass in a box with hard walls or periodic boundaries per
//! axis, and advances them from event to event (pair collisions, wall
//! collisions, neighbour-list renewals). See [`system`] for the algorithm and its
//! sources, [`scene`] for the settings a scene file gives, [`theory`] for the
//! results the tests compare with, [`pack`] for packings by growth
//! (Lubachevsky–Stillinger) and [`analyse`] for their structure.

// Component loops `for d in 0..D` over several arrays read as the math does.
#![allow(clippy::needless_range_loop)]

pub mod analyse;
#[cfg(target_arch = "x86_64")]
mod avx512;
mod cells;
pub mod init;
pub mod pack;
pub mod queue;
pub mod run;
pub mod scene;
pub mod system;
pub mod theory;
pub mod vecd;

pub use pack::{PackOutcome, PackSettings, Packer, SizeSpec, Stop};
pub use scene::{Run, Scene};
pub use system::{growing_pair_time, pair_time, shell_factor, Boundary, Counters, SimBox, System};

/// Errors of the event-driven engine.
#[derive(Debug, thiserror::Error)]
pub enum EdmdError {
    /// An initial state or setting that cannot be simulated.
    #[error("{0}")]
    Invalid(String),
    /// A packing setting out of its domain, with its key (the caller says
    /// where the value came from).
    #[error("{0}")]
    Setting(pack::SettingError),
    /// A scene file that does not parse, with file and line.
    #[error("{file}:{line}: {message}")]
    Scene {
        file: String,
        line: usize,
        message: String,
    },
    /// Output failed.
    #[error(transparent)]
    Io(#[from] mote_io::IoError),
    /// A signal asked the run to stop; it stopped between events with its
    /// files flushed.
    #[error("the run was interrupted by signal {signal} at t = {time}")]
    Interrupted { signal: i32, time: f64 },
}

impl From<mote_io::ParseError> for EdmdError {
    fn from(e: mote_io::ParseError) -> Self {
        EdmdError::Io(e.into())
    }
}
